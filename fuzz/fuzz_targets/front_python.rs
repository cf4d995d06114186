//! Any bytes → the Python front end returns (Ok or errors), never panics; when it returns a module,
//! that module verifies, atomises, and the atomised module verifies.
#![no_main]

use libfuzzer_sys::fuzz_target;
use robovec::front::{parse_str, Language};
use robovec_ir::verifier;
use robovec_passes::atomise::atomise_function;

fuzz_target!(|data: &[u8]| {
    let Ok(m) = parse_str(Language::Python, data, None) else { return };
    if let Err(e) = verifier::verify(&m) {
        panic!("front end returned a module that does not verify: {e:?}");
    }
    for f in &m.functions {
        let a = atomise_function(f);
        let errs = verifier::verify_function(&a);
        assert!(errs.is_empty(), "atomised @{} does not verify: {errs:?}", f.name);
    }
});
