//! `-eval=FILE` (SPEC §7): the final IR evaluated on given inputs, in binary64 or binary32. (The
//! JSON report of `-report` is built by the driver from the figures of the final IR and the
//! artifacts of the passes.)

use std::collections::BTreeMap;

use robovec_ir::{interp, Function};
use serde::Serialize;

/// `-eval` output: every input used and every output, in the evaluation precision.
#[derive(Clone, Debug, Serialize)]
pub struct EvalResult {
    /// `f64` or `f32` (`-eval-precision`).
    pub precision: &'static str,
    /// Input name → value used (in `f32`: the binary32 value, printed as a number).
    pub inputs: BTreeMap<String, f64>,
    /// Output name → value (in `f32`: the binary32 result, printed as a number).
    pub outputs: BTreeMap<String, f64>,
    /// User callbacks evaluated with the interpreter's stand-in (absent when none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub callback_standins: Vec<String>,
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

/// [`evaluate`] where inputs not in `given` take `defaults` first ([`EvalInputs`]; see
/// [`not_given`]).
pub fn evaluate_with(
    f: &Function,
    given: &BTreeMap<String, f64>,
    defaults: &BTreeMap<String, f64>,
    single: bool,
) -> EvalResult {
    let mut inputs = BTreeMap::new();
    let value = |name: &str| {
        let stated = given.get(name).or_else(|| defaults.get(name));
        stated.copied().unwrap_or_else(|| interp::pseudo_random_input(name, 0))
    };
    let outputs: BTreeMap<String, f64> = if single {
        interp::eval::<f32>(f, |name| {
            let x = value(name) as f32 as f64;
            inputs.insert(name.to_string(), x);
            x
        })
        .into_iter()
        .map(|(k, v)| (k, v as f64))
        .collect()
    } else {
        interp::eval::<f64>(f, |name| {
            let x = value(name);
            inputs.insert(name.to_string(), x);
            x
        })
        .into_iter()
        .collect()
    };
    EvalResult {
        precision: if single { "f32" } else { "f64" },
        inputs,
        outputs,
        callback_standins: robovec_ir::numerics::Tape::new(f).standin_callees(),
    }
}
