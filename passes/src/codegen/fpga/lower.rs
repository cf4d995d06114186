//! From a placed function to the [`Design`]'s images: the per-PE, per-cycle machine words in the
//! encoding of the `machine` module doc (LSB first), checked against the target's memories.
//!
//! The placement gives issues, loads and writes (`ir/src/placement.rs`); this lowering adds
//! what the hardware needs besides: each operand's read address (the latest write of the value
//! into the issuing PE's memory at a cycle ≤ the issue, as `sim` resolves it), the write-port
//! assignment (a PE memory's writes of one cycle in `Placement::writes` order: port 0, port 1),
//! the crossbar selects, the buffer's store/read instructions and the output captures (an
//! output that an op produces is captured at its arrival into the producing PE's output memory,
//! at the next free address of that memory in output order; an output that is an input, a trig
//! value or a constant is a word of output memory 0's initial contents).

use std::collections::{BTreeMap, HashMap};

use robovec_ir::placement::{Pe, Placement};
use robovec_ir::syntax::{BinOp, Def, Operand, TrigFn};
use robovec_ir::{Function, Value};

use super::design::{addr_bits, Design, LoadWord, OutputWord, PeImages, Source, Widths};
use super::images::Image;

/// The target's limits the design must fit (see `robovec_ir::target`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Words per PE memory (2048 on the DE10-Nano: one M10K-based memory, seed §1.3.1).
    pub pe_words: u32,
    /// Words per buffer memory.
    pub buffer_words: u32,
    /// Instruction memory depth, cycles.
    pub instr_words: u32,
    /// Instruction word bits (52 on the DE10-Nano, seed §1.3.1).
    pub instr_width: u32,
    /// Write ports per PE memory per cycle.
    pub writes: u32,
}

/// What a memory word holds (a value of the function or a constant, by its `f64` bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Key {
    Value(Value),
    Const(u64),
}

fn key_of(o: &Operand) -> Key {
    match o {
        Operand::Value(v) => Key::Value(*v),
        Operand::Const(c) => Key::Const(c.to_bits()),
    }
}

/// binary32 bits of an `f64` literal rounded to nearest (what `-eval-precision=f32` does).
pub fn f32_bits(x: f64) -> u32 {
    (x as f32).to_bits()
}

/// The source of an initial word (input, trig value of an input, constant).
fn source(f: &Function, o: &Operand) -> Result<Source, String> {
    match o {
        Operand::Const(c) => Ok(Source::Const { value: *c, bits: format!("0x{:08x}", f32_bits(*c)) }),
        Operand::Value(v) => match &f.value(*v).def {
            Def::Input => Ok(Source::Input { input: f.name_of(*v).to_string() }),
            Def::Trig(t, a) if matches!(f.value(*a).def, Def::Input) => Ok(Source::Trig {
                name: f.name_of(*v).to_string(),
                trig: match t {
                    TrigFn::Sin => "sin",
                    TrigFn::Cos => "cos",
                },
                of: f.name_of(*a).to_string(),
            }),
            Def::Trig(..) => Err(format!(
                "trig value %{} is loaded but its argument is not an input (the host computes trig values of inputs only)",
                f.name_of(*v)
            )),
            _ => Err(format!("%{} is loaded but is not initial data", f.name_of(*v))),
        },
    }
}

/// Lowers placed function `f` (placement `p`) onto `limits`.
///
/// # Errors
/// A diagnostic (one or more lines) with the figures needed and available: an op the PEs do
/// not have (`div`, `call`), `writes` ≠ 2, a latency below 2, a memory beyond the target, or a
/// placement the hardware cannot execute (an operand not in the PE memory at its issue, three
/// writes in one cycle, two buffer reads in one cycle).
pub fn lower(f: &Function, p: &Placement, limits: &Limits) -> Result<Design, String> {
    let arch = p.arch;
    let n = arch.n_pe();
    if p.pe_words.len() != n || p.buffer_words.len() != n {
        return Err(format!("the placement lists {} PE memory and {} buffer sizes for {n} PEs", p.pe_words.len(), p.buffer_words.len()));
    }
    let mut problems: Vec<String> = Vec::new();
    if limits.writes != 2 {
        problems.push(format!(
            "the target has {} write port(s) per PE memory; the instruction word has exactly 2 (write-0, write-1)",
            limits.writes
        ));
    }
    if arch.writes > 2 {
        problems.push(format!("the placement uses {} write ports per PE memory; the hardware has 2", arch.writes));
    }
    for (what, l) in [("ADD", arch.lat.add), ("MULTI", arch.lat.mul)] {
        if l < 2 {
            problems.push(format!(
                "{what} latency is {l} cycles; the hardware needs at least 2 (PE memory read and crossbar registers)"
            ));
        }
    }
    let unsupported: Vec<String> = f
        .body
        .iter()
        .filter(|&&v| matches!(f.value(v).def, Def::Binary(BinOp::Div, ..) | Def::Call(..)))
        .map(|&v| format!("%{}", f.name_of(v)))
        .collect();
    if !unsupported.is_empty() {
        problems.push(format!(
            "{} op(s) need a divider or a function unit, which the PEs lack (ADD: fp_add_sub, MULTI: fp_mul): {}{}",
            unsupported.len(),
            unsupported.iter().take(5).cloned().collect::<Vec<_>>().join(", "),
            if unsupported.len() > 5 { ", …" } else { "" }
        ));
    }
    let cycles = f
        .body
        .iter()
        .filter_map(|&v| Some(p.issue.get(v.index()).copied().flatten()?.cycle + p.latency(f.op_kind(v)?)))
        .max()
        .unwrap_or(0);
    let pe_max = p.pe_words.iter().copied().max().unwrap_or(0);
    if pe_max > limits.pe_words {
        let worst = p.pe_words.iter().position(|&w| w == pe_max).unwrap_or(0);
        problems.push(format!(
            "PE memory of {} needs {pe_max} words; the target has {} words per PE memory",
            pe_name(&arch, worst),
            limits.pe_words
        ));
    }
    let buf_max = p.buffer_words.iter().copied().max().unwrap_or(0);
    if buf_max > limits.buffer_words {
        problems.push(format!(
            "buffer of {} needs {buf_max} words; the target's buffers have {} words",
            pe_name(&arch, p.buffer_words.iter().position(|&w| w == buf_max).unwrap_or(0)),
            limits.buffer_words
        ));
    }
    if u64::from(cycles) + 1 > u64::from(limits.instr_words) {
        problems.push(format!(
            "the program needs {} instruction words per PE (cycles 0..={cycles}); the target's instruction memory has {}",
            u64::from(cycles) + 1,
            limits.instr_words
        ));
    }
    let aw = addr_bits(u64::from(limits.pe_words));
    if 4 * aw + 4 > limits.instr_width {
        problems.push(format!(
            "the instruction word needs {} bits (4 addresses of {aw} bits + 4); the target's is {} bits",
            4 * aw + 4,
            limits.instr_width
        ));
    }
    if !problems.is_empty() {
        return Err(problems.join("\n"));
    }

    if n == 0 {
        return Err("the placement has no PE".into());
    }
    let slot = |pe: Pe| pe.slot(arch.n_add);
    let len = cycles as usize + 1;
    // Outputs an op produces: captured at arrival into the producer's output memory.
    let mut outputs_per_slot = vec![0u32; n];
    let mut captures: HashMap<Value, (usize, u32, u32)> = HashMap::new();
    for o in &f.outputs {
        let Operand::Value(v) = o.value else { continue };
        let Some(kind) = f.op_kind(v) else { continue };
        let is = p.issue[v.index()].ok_or_else(|| format!("op %{} has no issue", f.name_of(v)))?;
        let s = slot(is.pe);
        captures.entry(v).or_insert_with(|| {
            outputs_per_slot[s] += 1;
            (s, is.cycle + p.latency(kind), outputs_per_slot[s] - 1)
        });
    }
    // Outputs that are inputs, trig values or constants: initial words of output memory 0,
    // after its captures.
    let mut outputs = Vec::new();
    let mut output_loads: Vec<LoadWord> = Vec::new();
    let mut initial: HashMap<Key, u32> = HashMap::new();
    for o in &f.outputs {
        let (s, addr) = match o.value {
            Operand::Value(v) if captures.contains_key(&v) => {
                let (s, _, a) = captures[&v];
                (s, a)
            }
            _ => {
                let k = key_of(&o.value);
                let a = match initial.get(&k) {
                    Some(&a) => a,
                    None => {
                        let a = outputs_per_slot[0];
                        outputs_per_slot[0] += 1;
                        initial.insert(k, a);
                        output_loads.push(LoadWord { slot: 0, pe: pe_name(&arch, 0), addr: a, source: source(f, &o.value)? });
                        a
                    }
                };
                (0, a)
            }
        };
        outputs.push(OutputWord { name: o.name.clone(), slot: s, pe: pe_name(&arch, s), addr });
    }
    let ow = addr_bits(u64::from(outputs_per_slot.iter().copied().max().unwrap_or(1).max(1)));
    let bw = addr_bits(u64::from(buf_max.max(1)));
    let sw = addr_bits(2 * n as u64 + 1);
    let cw = addr_bits(u64::from(cycles) + 2);
    let widths = Widths { aw, bw, sw, ow, cw, instr: limits.instr_width };

    let mut instr = vec![vec![0u64; len]; n];
    let mut xbar = vec![vec![0u64; len]; n];
    let mut bufi = vec![vec![0u64; len]; n];
    let mut capt = vec![vec![0u64; len]; n];
    let mut data: Vec<Vec<u64>> = p.pe_words.iter().map(|&w| vec![0u64; w.max(1) as usize]).collect();
    let mut out: Vec<Vec<u64>> = outputs_per_slot.iter().map(|&w| vec![0u64; w.max(1) as usize]).collect();

    // PE memory contents over time: (slot, key) → [(time, addr)], loads at time -1.
    let mut at: HashMap<(usize, Key), Vec<(i64, u32)>> = HashMap::new();
    let mut loads = Vec::new();
    for l in &p.loads {
        let s = slot(l.pe);
        if l.addr >= p.pe_words[s].max(1) {
            return Err(format!("a load into {} uses address {}, beyond the {} words of that PE memory", l.pe, l.addr, p.pe_words[s]));
        }
        let src = source(f, &l.operand)?;
        if let Source::Const { bits, .. } = &src {
            data[s][l.addr as usize] = u64::from_str_radix(&bits[2..], 16).expect("hex bits");
        }
        loads.push(LoadWord { slot: s, pe: pe_name(&arch, s), addr: l.addr, source: src });
        at.entry((s, key_of(&l.operand))).or_default().push((-1, l.addr));
    }
    for l in &output_loads {
        if let Source::Const { bits, .. } = &l.source {
            out[0][l.addr as usize] = u64::from_str_radix(&bits[2..], 16).expect("hex bits");
        }
    }
    // Writes: ports per (slot, cycle); buffer stores at arrival, reads at the write cycle.
    let mut ports: BTreeMap<(usize, u32), u32> = BTreeMap::new();
    let mut buffer_read: HashMap<(usize, u32), u32> = HashMap::new();
    for w in &p.writes {
        let s = slot(w.pe);
        let c = w.cycle as usize;
        if w.addr >= p.pe_words[s].max(1) || c >= len {
            return Err(format!(
                "a write into {} at cycle {} uses address {}, beyond the {} words of that PE memory or the program's {cycles} cycles",
                w.pe, w.cycle, w.addr, p.pe_words[s]
            ));
        }
        let port = ports.entry((s, w.cycle)).or_insert(0);
        if *port >= 2 {
            return Err(format!("PE memory of {} takes three writes at cycle {}; the hardware has 2 write ports", w.pe, w.cycle));
        }
        let is = p.issue[w.value.index()].ok_or_else(|| format!("op %{} has no issue", f.name_of(w.value)))?;
        let ps = slot(is.pe);
        let sel = match w.buffer_addr {
            None => ps as u64 + 1,
            Some(b) => {
                match buffer_read.insert((ps, w.cycle), b) {
                    Some(old) if old != b => {
                        return Err(format!(
                            "buffer of {} is read at addresses {old} and {b} in cycle {}; it has one read per cycle",
                            is.pe, w.cycle
                        ))
                    }
                    _ => {}
                }
                let arrival = is.cycle + p.latency(f.op_kind(w.value).expect("an op"));
                bufi[ps][arrival as usize] |= u64::from(b) | (1 << (2 * bw));
                bufi[ps][c] |= (u64::from(b) << bw) | (1 << (2 * bw + 1));
                (n + ps) as u64 + 1
            }
        };
        let shift = if *port == 0 { 2 * aw } else { 3 * aw };
        instr[s][c] |= (u64::from(w.addr) << shift) | (1 << (4 * aw + *port));
        xbar[s][c] |= sel << (*port * sw);
        *port += 1;
        at.entry((s, Key::Value(w.value))).or_default().push((i64::from(w.cycle), w.addr));
    }
    // Issues: read addresses (latest write of the operand into this PE memory at a cycle ≤ issue).
    for &v in &f.body {
        let Def::Binary(op, a, b) = &f.value(v).def else { continue };
        let is = p.issue[v.index()].ok_or_else(|| format!("op %{} has no issue", f.name_of(v)))?;
        let s = slot(is.pe);
        let c = i64::from(is.cycle);
        let mut addr = [0u32; 2];
        for (i, o) in [a, b].into_iter().enumerate() {
            let found = at
                .get(&(s, key_of(o)))
                .and_then(|l| l.iter().filter(|(t, _)| *t <= c).max_by_key(|(t, _)| *t))
                .map(|&(_, a)| a);
            addr[i] = found.ok_or_else(|| {
                format!("%{} (issued on {} at cycle {c}) reads an operand that is not in that PE memory", f.name_of(v), is.pe)
            })?;
        }
        let cc = is.cycle as usize;
        instr[s][cc] |= u64::from(addr[0])
            | (u64::from(addr[1]) << aw)
            | (1 << (4 * aw + 2))
            | (u64::from(*op == BinOp::Sub) << (4 * aw + 3));
    }
    for (v, &(s, arrival, addr)) in &captures {
        let _ = v;
        capt[s][arrival as usize] = u64::from(addr) | (1 << ow);
    }

    let pes = (0..n)
        .map(|s| {
            let img = |k: &str, width: u32, words: Vec<u64>| Image { name: format!("pe{s}_{k}"), width, words };
            PeImages {
                slot: s,
                pe: pe_name(&arch, s),
                is_mul: s >= arch.n_add as usize,
                instr: img("instr", widths.instr, std::mem::take(&mut instr[s])),
                xbar: img("xbar", widths.xbar(), std::mem::take(&mut xbar[s])),
                bufi: img("bufi", widths.bufi(), std::mem::take(&mut bufi[s])),
                capt: img("capt", widths.capt(), std::mem::take(&mut capt[s])),
                data: img("data", 32, std::mem::take(&mut data[s])),
                out: img("out", 32, std::mem::take(&mut out[s])),
                buffer_words: p.buffer_words[s],
            }
        })
        .collect();
    Ok(Design {
        function: f.name.clone(),
        n_add: arch.n_add,
        n_mul: arch.n_mul,
        lat_add: arch.lat.add,
        lat_mul: arch.lat.mul,
        cycles,
        widths,
        pes,
        inputs: f.inputs.iter().map(|&v| f.name_of(v).to_string()).collect(),
        loads,
        output_loads,
        outputs,
    })
}

/// `add0`, `mul1` for slot `s`.
pub fn pe_name(arch: &robovec_ir::placement::Arch, s: usize) -> String {
    if s < arch.n_add as usize {
        format!("add{s}")
    } else {
        format!("mul{}", s - arch.n_add as usize)
    }
}
