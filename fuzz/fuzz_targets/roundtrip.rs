//! `.rvir` print/parse round trip: when `parse(s)` succeeds and the module verifies, printing it,
//! parsing the print and printing again gives the same text (and the reparse verifies).
#![no_main]

use libfuzzer_sys::fuzz_target;
use robovec_ir::{text, verifier};

fuzz_target!(|data: &[u8]| {
    let Ok(s) = std::str::from_utf8(data) else { return };
    let Ok(m) = text::parse(s) else { return };
    if verifier::verify(&m).is_err() {
        return;
    }
    let printed = m.to_string();
    let m2 = match text::parse(&printed) {
        Ok(m2) => m2,
        Err(e) => panic!("the printed module does not parse: {e:?}\n--- printed ---\n{printed}"),
    };
    if let Err(e) = verifier::verify(&m2) {
        panic!("the reparsed module does not verify: {e:?}\n--- printed ---\n{printed}");
    }
    let reprinted = m2.to_string();
    assert_eq!(printed, reprinted, "print(parse(print(m))) != print(m)");
});
