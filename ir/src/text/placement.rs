//! The placement block of the text form: resolution (names → values and PEs) and printing.
//!
//! ```text
//! placement n_add=1 n_mul=1 lat_add=12 lat_mul=7 lat_div=12 lat_call=12 writes=2 buffer=1 {
//!   words add0=2 mul0=2
//!   buffers add0=0 mul0=0
//!   issue %x mul0 0
//!   issue %y add0 7
//!   load mul0 0 %a
//!   load mul0 1 %b
//!   load add0 0 %a
//!   write %x add0 1 7
//! }
//! ```
//! An indirect write ends with `buffer BADDR` (the producer's buffer address).

use std::fmt;

use super::ast::{OperandAst, PlacementAst, PlacementLineAst};
use super::error::ParseError;
use crate::analysis::Latencies;
use crate::function::Function;
use crate::placement::{Issue, Load, Pe, PeArray, Placement, PlacementSpans, Write};
use crate::span::Span;
use crate::syntax::Operand;

fn pe_name(text: &str, arch: &PeArray) -> Option<Pe> {
    let index = |digits: &str| digits.parse::<u32>().ok().filter(|_| digits.bytes().all(|b| b.is_ascii_digit()));
    if let Some(i) = text.strip_prefix("add").and_then(index) {
        (i < arch.n_add).then_some(Pe::Add(i))
    } else {
        text.strip_prefix("mul").and_then(index).filter(|&i| i < arch.n_mul).map(Pe::Mul)
    }
}

/// Resolves a placement block against its function.
pub fn resolve(f: &Function, p: PlacementAst<'_>, errors: &mut Vec<ParseError>) -> Option<Placement> {
    let before = errors.len();
    let key = |k: &str, default: Option<u32>, errors: &mut Vec<ParseError>| match (
        p.arch.iter().find(|(n, _, _)| *n == k),
        default,
    ) {
        (Some(&(_, v, _)), _) => v,
        (None, Some(d)) => d,
        (None, None) => {
            errors.push(ParseError::new(p.span, format!("placement: missing `{k}=…`"), "in this placement"));
            0
        }
    };
    const KEYS: [&str; 8] = ["n_add", "n_mul", "lat_add", "lat_mul", "lat_div", "lat_call", "writes", "buffer"];
    for (k, _, span) in &p.arch {
        if !KEYS.contains(k) {
            errors.push(
                ParseError::new(*span, format!("placement: unknown key `{k}`"), "here")
                    .note(format!("expected one of {}", KEYS.join(", "))),
            );
        }
    }
    let d = Latencies::default();
    let arch = PeArray {
        n_add: key("n_add", None, errors),
        n_mul: key("n_mul", None, errors),
        lat: Latencies {
            add: key("lat_add", Some(d.add), errors),
            mul: key("lat_mul", Some(d.mul), errors),
            div: key("lat_div", Some(d.div), errors),
            call: key("lat_call", Some(d.call), errors),
        },
        writes: key("writes", Some(2), errors),
        buffer: key("buffer", Some(1), errors) != 0,
    };
    if arch.n_add == 0 || arch.n_mul == 0 || arch.n_pe() > 1 << 16 {
        errors.push(ParseError::new(
            p.span,
            "placement: `n_add` and `n_mul` must be in 1..=32768",
            "in this placement",
        ));
        return None;
    }
    let pe = |text: &str, span: Span, errors: &mut Vec<ParseError>| {
        let r = pe_name(text, &arch);
        if r.is_none() {
            errors.push(
                ParseError::new(span, format!("no PE `{text}` on this architecture"), "unknown PE").note(format!(
                    "expected add0…add{} or mul0…mul{}",
                    arch.n_add - 1,
                    arch.n_mul - 1
                )),
            );
        }
        r
    };
    let sizes = |list: &[(&str, u32, Span)], what: &str, errors: &mut Vec<ParseError>| {
        let mut out = vec![None; arch.n_pe()];
        for &(name, v, span) in list {
            if let Some(q) = pe(name, span, errors) {
                if out[q.slot(arch.n_add)].replace(v).is_some() {
                    errors.push(ParseError::new(span, format!("{what}: `{name}` given twice"), "here"));
                }
            }
        }
        if out.iter().any(Option::is_none) {
            errors.push(ParseError::new(p.span, format!("{what}: every PE needs a size"), "in this placement"));
        }
        out.into_iter().map(|x| x.unwrap_or(0)).collect::<Vec<u32>>()
    };
    let pe_words = sizes(&p.words, "words", errors);
    let buffer_words = sizes(&p.buffers, "buffers", errors);
    let value = |name: &str, span: Span, errors: &mut Vec<ParseError>| {
        let v = f.lookup(name).filter(|&v| f.op_kind(v).is_some());
        if v.is_none() {
            errors.push(ParseError::new(span, format!("`%{name}` is not an operation of @{}", f.name), "here"));
        }
        v
    };
    let mut issue = vec![None; f.values.len()];
    let mut loads = Vec::new();
    let mut writes = Vec::new();
    let mut spans = PlacementSpans { block: p.span, issue: vec![Span::DUMMY; f.values.len()], ..Default::default() };
    for line in p.lines {
        match line {
            PlacementLineAst::Issue { value: v, pe: q, cycle, span } => {
                if let (Some(v), Some(q)) = (value(v, span, errors), pe(q, span, errors)) {
                    if issue[v.index()].replace(Issue { pe: q, cycle }).is_some() {
                        errors.push(ParseError::new(span, format!("`%{}` issued twice", f.name_of(v)), "second issue"));
                    }
                    spans.issue[v.index()] = span;
                }
            }
            PlacementLineAst::Load { pe: q, addr, operand, span } => {
                let operand = match operand {
                    OperandAst::Const(c, _) => Some(Operand::Const(c)),
                    OperandAst::Value(n, s) => match f.lookup(n).filter(|&v| f.op_kind(v).is_none()) {
                        Some(v) => Some(Operand::Value(v)),
                        None => {
                            errors.push(ParseError::new(
                                s,
                                format!("`%{n}` is not initial data of @{}", f.name),
                                "here",
                            ));
                            None
                        }
                    },
                };
                if let (Some(q), Some(operand)) = (pe(q, span, errors), operand) {
                    loads.push(Load { pe: q, addr, operand });
                    spans.loads.push(span);
                }
            }
            PlacementLineAst::Write { value: v, pe: q, addr, cycle, via, span } => {
                let buffer_addr = match via {
                    None => None,
                    Some(("buffer", b)) => Some(b),
                    Some((other, _)) => {
                        errors.push(
                            ParseError::new(span, format!("unexpected `{other}`"), "here")
                                .note("expected `buffer ADDR`"),
                        );
                        None
                    }
                };
                if let (Some(v), Some(q)) = (value(v, span, errors), pe(q, span, errors)) {
                    writes.push(Write { value: v, pe: q, addr, cycle, buffer_addr });
                    spans.writes.push(span);
                }
            }
        }
    }
    (errors.len() == before).then_some(Placement { arch, issue, loads, writes, pe_words, buffer_words, spans })
}

/// Writes the placement block of `f` (two-space indented, inside the function).
pub fn write(out: &mut impl fmt::Write, f: &Function, p: &Placement) -> fmt::Result {
    let a = &p.arch;
    writeln!(
        out,
        "  placement n_add={} n_mul={} lat_add={} lat_mul={} lat_div={} lat_call={} writes={} buffer={} {{",
        a.n_add,
        a.n_mul,
        a.lat.add,
        a.lat.mul,
        a.lat.div,
        a.lat.call,
        a.writes,
        u8::from(a.buffer)
    )?;
    for (what, sizes) in [("words", &p.pe_words), ("buffers", &p.buffer_words)] {
        write!(out, "    {what}")?;
        for (q, n) in a.pes().zip(sizes.iter()) {
            write!(out, " {q}={n}")?;
        }
        out.write_char('\n')?;
    }
    for &v in &f.body {
        if let Some(i) = p.issue.get(v.index()).copied().flatten() {
            writeln!(out, "    issue %{} {} {}", f.name_of(v), i.pe, i.cycle)?;
        }
    }
    for l in &p.loads {
        write!(out, "    load {} {} ", l.pe, l.addr)?;
        match l.operand {
            Operand::Value(v) => write!(out, "%{}", f.name_of(v))?,
            Operand::Const(c) => super::write_const(out, c)?,
        }
        out.write_char('\n')?;
    }
    for w in &p.writes {
        write!(out, "    write %{} {} {} {}", f.name_of(w.value), w.pe, w.addr, w.cycle)?;
        if let Some(b) = w.buffer_addr {
            write!(out, " buffer {b}")?;
        }
        out.write_char('\n')?;
    }
    writeln!(out, "  }}")
}
