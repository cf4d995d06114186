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

/// Evaluates `f` on `given` inputs in binary64, or in binary32 when `single` (inputs rounded
/// to binary32 first, every operation in binary32 in the IR's order, as the FPGA computes);
/// inputs not given get deterministic pseudo-random values in [-1, 1]
/// (`robovec_ir::interp::pseudo_random_input` with seed 0).
pub fn evaluate(f: &Function, given: &BTreeMap<String, f64>, single: bool) -> EvalResult {
    let mut inputs = BTreeMap::new();
    let value = |name: &str| given.get(name).copied().unwrap_or_else(|| interp::pseudo_random_input(name, 0));
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
