//! Any bytes → the Matlab front end returns (Ok or errors), never panics; when it returns a module,
//! that module verifies, atomises, and the atomised module verifies.
#![no_main]

use libfuzzer_sys::fuzz_target;
use robovec_front::{verify_accepted, parse_str, Language};

fuzz_target!(|data: &[u8]| {
    let Ok(m) = parse_str(Language::Matlab, data, None) else { return };
    if let Err(e) = verify_accepted(&m) {
        panic!("{e}");
    }
});
