//! Inputs shared by the benches (included with `#[path = "common.rs"] mod common;`; with
//! `autobenches = false` this file is not a bench target of its own).

use std::path::PathBuf;

use robovec_ir::Function;
use robovec_passes::atomise::atomise_function;

/// WALK-MAN's direct dynamics, the corpus's largest single-function Matlab file.
pub const WALKMAN: &str = "../shared/corpus/robotran/matlab/walkman__mbs_dirdyna_walkman_robotran.m";

/// The atomised WALK-MAN direct dynamics (37,579 ops); panics when `../shared` is missing.
pub fn walkman() -> Function {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(WALKMAN);
    let (m, _) = robovec::driver::load(&p.to_string_lossy())
        .unwrap_or_else(|e| panic!("cannot load {} (the corpus must sit at ../shared): {}", p.display(), e.message()));
    assert_eq!(m.functions.len(), 1, "{WALKMAN} holds one function");
    atomise_function(&m.functions[0])
}
