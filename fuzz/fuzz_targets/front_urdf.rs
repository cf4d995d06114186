//! Any bytes → the URDF front end (through the front-end registry, symbolic and folded
//! parameters, fixed and floating base, and every function of the depth formulation, `fordyna`
//! included) returns (Ok or errors), never panics; when it returns a module, that module
//! verifies, atomises, and the atomised module verifies.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use robovec_front::{verify_accepted, front_end_for, FrontOptions};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let fe = front_end_for("robot.urdf").expect("the URDF front end is registered");
    let every = Some(robovec_dynamics::FUNCTION_NAMES.map(String::from).to_vec());
    let depth = robovec_dynamics::Formulation::Depth;
    for opts in [
        FrontOptions::default(),
        FrontOptions { fold_params: true, ..FrontOptions::default() },
        FrontOptions { floating_base: true, ..FrontOptions::default() },
        FrontOptions { formulation: depth, functions: every, ..FrontOptions::default() },
    ] {
        let Ok(loaded) = fe.load(Path::new("robot.urdf"), text, &opts) else { return };
        if let Err(e) = verify_accepted(&loaded.module) {
            panic!("{e}");
        }
    }
});
