//! Any bytes → the C front end returns (Ok or errors), never panics; when it returns a module,
//! that module verifies, atomises, and the atomised module verifies.
#![no_main]

use libfuzzer_sys::fuzz_target;
use robovec_front::{verify_accepted, parse_str, Language};

fuzz_target!(|data: &[u8]| {
    // A NUL byte (never in a Robotran file) splits the input into the .c text and the
    // companion .h text, so the header path is fuzzed too.
    let (src, header) = match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], Some(&data[i + 1..])),
        None => (data, None),
    };
    let Ok(m) = parse_str(Language::C, src, header) else { return };
    if let Err(e) = verify_accepted(&m) {
        panic!("{e}");
    }
});
