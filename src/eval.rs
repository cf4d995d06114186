//! `-eval=FILE` (SPEC §7): the final IR evaluated on given inputs, in binary64 or binary32. (The
//! JSON report of `-report` is built by the driver from the figures of the final IR and the
//! artifacts of the passes.)

use std::collections::BTreeMap;

use robovec_ir::interp::{self, Float};
use robovec_ir::{Def, Function, Operand, Span, TrigFn, Value};
use serde::Serialize;

/// `-eval` output: every input used and every output, in the evaluation precision.
#[derive(Clone, Debug, Serialize)]
pub struct EvalResult {
    /// `f64` or `f32` (`-eval-precision`), or `formats` when the function's values carry
    /// numeric formats ([`evaluate_formats`]).
    pub precision: &'static str,
    /// Input name → value used (in `f32`: the binary32 value, printed as a number).
    pub inputs: BTreeMap<String, f64>,
    /// Output name → value (in `f32`: the binary32 result, printed as a number).
    pub outputs: BTreeMap<String, f64>,
    /// User callbacks evaluated with the interpreter's stand-in (absent when none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub callback_standins: Vec<String>,
    /// The first value that was not finite, when an output is not (the JSON prints such an
    /// output as `null`; the driver warns on stderr, issue 47). Not part of the JSON.
    #[serde(skip)]
    pub non_finite: Option<NonFinite>,
}

/// Where an evaluation first went non-finite ([`EvalResult::non_finite`]): the first value, in
/// program order, whose result is infinite or NaN. Its operands were all finite (inputs and
/// constants are), so it is where the trouble starts: a division by zero (a singular mass
/// matrix: a zero mass given for a link, issue 47), an overflow, `sqrt` of a negative number.
#[derive(Clone, Debug, PartialEq)]
pub struct NonFinite {
    /// The value's name, without `%`.
    pub name: String,
    /// Its definition as the IR text writes it (`1 / %D3`, `div 1, %D3`), cut to about 160
    /// characters.
    pub definition: String,
    /// Its result (`inf`, `-inf`, `NaN`), in `f64`.
    pub value: f64,
    /// The values it reads, in operand order, each once, with their values (at most 6).
    pub reads: Vec<(String, f64)>,
    /// Its definition's span in the input (`Span::DUMMY` when a pass or the generator made it).
    pub span: Span,
    /// The outputs that are not finite, in output order.
    pub outputs: Vec<String>,
}

/// The outputs of `f` from its values `vals` (as [`interp::eval`]), and where the values first
/// went non-finite when an output is not finite.
fn outputs_of<T: Float>(f: &Function, vals: &[T]) -> (Vec<(String, f64)>, Option<NonFinite>) {
    let value = |o: &Operand| match o {
        Operand::Value(v) => vals[v.index()].to_f64(),
        Operand::Const(c) => T::from_f64(*c).to_f64(),
    };
    let outputs: Vec<(String, f64)> = f.outputs.iter().map(|o| (o.name.clone(), value(&o.value))).collect();
    let bad: Vec<String> = outputs.iter().filter(|(_, x)| !x.is_finite()).map(|(n, _)| n.clone()).collect();
    if bad.is_empty() {
        return (outputs, None);
    }
    let first = f.body.iter().copied().find(|v| !vals[v.index()].to_f64().is_finite());
    let non_finite = first.map(|v| {
        let d = f.value(v);
        let mut reads: Vec<(String, f64)> = Vec::new();
        d.def.for_each_value(|a: Value| {
            let name = f.name_of(a).to_string();
            if reads.len() < 6 && !reads.iter().any(|(n, _)| *n == name) {
                reads.push((name, vals[a.index()].to_f64()));
            }
        });
        NonFinite {
            name: d.name.clone(),
            definition: definition_text(f, &d.def),
            value: vals[v.index()].to_f64(),
            reads,
            span: d.span,
            outputs: bad.clone(),
        }
    });
    (outputs, non_finite)
}

impl NonFinite {
    /// The warning line(s) for `-eval` on stderr: `warning: @f: %iD3 = 1/%D3 is inf (the first
    /// value that is not finite; %D3 = 0): outputs qdd[1], qdd[3] are not finite`, then
    /// `  --> file:line:col` when `at` (the file's name and text) locates its definition.
    pub fn warning(&self, function: &str, at: Option<(&str, &str)>) -> String {
        let reads: Vec<String> = self.reads.iter().map(|(n, x)| format!("%{n} = {x}")).collect();
        let reads = if reads.is_empty() { String::new() } else { format!("; {}", reads.join(", ")) };
        let shown: Vec<&str> = self.outputs.iter().take(6).map(String::as_str).collect();
        let more = self.outputs.len() - shown.len();
        let more = if more > 0 { format!(" and {more} more") } else { String::new() };
        let mut w = format!(
            "warning: @{function}: %{} = {} is {} (the first value that is not finite{reads}): output{} {}{more} {} not finite\n",
            self.name,
            self.definition,
            self.value,
            if self.outputs.len() == 1 { "" } else { "s" },
            shown.join(", "),
            if self.outputs.len() == 1 { "is" } else { "are" },
        );
        match at {
            Some((file, text)) if self.span != Span::DUMMY && self.span.end as usize <= text.len() => {
                let (line, col) = robovec_ir::span::line_col(text, self.span.start as usize);
                w += &format!("  --> {file}:{line}:{col}\n");
            }
            _ => {}
        }
        w
    }
}

/// `def` as the IR text writes it after `%name = `, cut in the middle beyond 160 characters.
fn definition_text(f: &Function, def: &Def) -> String {
    // The forms of one op as `robovec_ir::text::printer::write_function` writes them; an
    // expression through its `write_expr`.
    let mut out = String::new();
    let op = |o: &Operand| match o {
        Operand::Value(v) => format!("%{}", f.name_of(*v)),
        Operand::Const(c) => {
            let mut s = String::new();
            let _ = robovec_ir::text::write_const(&mut s, *c);
            s
        }
    };
    match def {
        Def::Input => out.push_str("input"),
        Def::Trig(t, a) => {
            let t = if matches!(t, TrigFn::Sin) { "sin" } else { "cos" };
            out += &format!("{t} %{}", f.name_of(*a));
        }
        Def::Binary(b, x, y) => out += &format!("{} {}, {}", b.mnemonic(), op(x), op(y)),
        Def::Call(c, args) => {
            out += &format!("call @{}(", c.name);
            out += &args.iter().map(op).collect::<Vec<_>>().join(", ");
            out.push(')');
        }
        Def::Expr(e) => {
            let _ = robovec_ir::text::printer::write_expr(&mut out, f, e);
        }
    }
    let n = out.chars().count();
    if n > 160 {
        let head: String = out.chars().take(80).collect();
        let tail: String = out.chars().skip(n - 70).collect();
        out = format!("{head} … {tail}");
    }
    out
}

/// The inputs of an `-eval`: those the file gives, then the values the input's conventions
/// give the others (`robovec_front::Loaded::input_defaults`: a URDF's parameters and gravity).
#[derive(Clone, Debug, Default)]
pub struct EvalInputs {
    /// Input name → value, from the `-eval` file.
    pub given: BTreeMap<String, f64>,
    /// Input name → value for inputs the file does not give.
    pub defaults: BTreeMap<String, f64>,
    /// What `defaults` are, for messages.
    pub defaults_source: &'static str,
}

/// Where the values of the inputs the `-eval` file did not give came from (names in the
/// function's input order).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NotGiven {
    /// Took [`EvalInputs::defaults`].
    pub defaulted: Vec<String>,
    /// Took a pseudo-random value in [-1, 1].
    pub random: Vec<String>,
}

/// The inputs of `f` that `inputs.given` lacks, by where their values come from.
pub fn not_given(f: &Function, inputs: &EvalInputs) -> NotGiven {
    let mut n = NotGiven::default();
    for name in f.inputs.iter().map(|&v| f.name_of(v)).filter(|name| !inputs.given.contains_key(*name)) {
        let list = if inputs.defaults.contains_key(name) { &mut n.defaulted } else { &mut n.random };
        list.push(name.to_string());
    }
    n
}

/// Evaluates `f` on `given` inputs in binary64, or in binary32 when `single` (inputs rounded
/// to binary32 first, every operation in binary32 in the IR's order, as the FPGA computes);
/// inputs not given get deterministic pseudo-random values in [-1, 1]
/// (`robovec_ir::interp::pseudo_random_input` with seed 0).
pub fn evaluate(f: &Function, given: &BTreeMap<String, f64>, single: bool) -> EvalResult {
    evaluate_with(f, given, &BTreeMap::new(), single)
}

/// The value of input `name`: `given`, else `defaults`, else pseudo-random in [-1, 1] (seed 0).
fn input_value(given: &BTreeMap<String, f64>, defaults: &BTreeMap<String, f64>, name: &str) -> f64 {
    let stated = given.get(name).or_else(|| defaults.get(name));
    stated.copied().unwrap_or_else(|| interp::pseudo_random_input(name, 0))
}

/// [`evaluate_with`] for a function whose values carry numeric formats (issue 48,
/// `robovec_ir::format`): every value computed in its format, as the back ends must
/// (`robovec_ir::format::eval_values`); `precision` is `formats`.
///
/// # Errors
/// The message of the first value, in program order, whose result its fixed-point format cannot
/// hold (`error: @f: %x = 40.3 overflows fix<8,2> (values -32 ..= 31.75)`, with `  --> file:line:col`
/// when `at` (file name, text) locates its definition).
pub fn evaluate_formats(
    f: &Function,
    given: &BTreeMap<String, f64>,
    defaults: &BTreeMap<String, f64>,
    at: Option<(&str, &str)>,
) -> Result<EvalResult, String> {
    let mut inputs = BTreeMap::new();
    let vals = robovec_ir::format::eval_values(f, |name| {
        let x = input_value(given, defaults, name);
        inputs.insert(name.to_string(), x);
        x
    })
    .map_err(|e| {
        let format = f.format(e.value);
        let what = match e.error {
            robovec_ir::format::StoreError::Overflow => {
                let (lo, hi) = format.fix_range().unwrap_or((f64::NAN, f64::NAN));
                format!("overflows {format} (values {lo} ..= {hi})")
            }
            robovec_ir::format::StoreError::NotFinite => format!("is not finite, which {format} cannot hold"),
        };
        let mut m = format!("error: @{}: %{} = {} {what}\n", f.name, f.name_of(e.value), e.result);
        let span = f.value(e.value).span;
        if let Some((file, text)) = at.filter(|(_, t)| span != Span::DUMMY && span.end as usize <= t.len()) {
            let (line, col) = robovec_ir::span::line_col(text, span.start as usize);
            m += &format!("  --> {file}:{line}:{col}\n");
        }
        m
    })?;
    let (outputs, non_finite) = outputs_of(f, &vals);
    Ok(EvalResult {
        precision: "formats",
        inputs,
        outputs: outputs.into_iter().collect(),
        callback_standins: robovec_ir::numerics::Tape::new(f).standin_callees(),
        non_finite,
    })
}

/// [`evaluate`] where inputs not in `given` take `defaults` first ([`EvalInputs`]; see
/// [`not_given`]).
pub fn evaluate_with(
    f: &Function,
    given: &BTreeMap<String, f64>,
    defaults: &BTreeMap<String, f64>,
    single: bool,
) -> EvalResult {
    let mut inputs = BTreeMap::new();
    let value = |name: &str| input_value(given, defaults, name);
    let (outputs, non_finite) = if single {
        let vals = interp::eval_values::<f32>(f, |name| {
            let x = value(name) as f32 as f64;
            inputs.insert(name.to_string(), x);
            x
        });
        outputs_of(f, &vals)
    } else {
        let vals = interp::eval_values::<f64>(f, |name| {
            let x = value(name);
            inputs.insert(name.to_string(), x);
            x
        });
        outputs_of(f, &vals)
    };
    EvalResult {
        precision: if single { "f32" } else { "f64" },
        inputs,
        outputs: outputs.into_iter().collect(),
        callback_standins: robovec_ir::numerics::Tape::new(f).standin_callees(),
        non_finite,
    }
}
