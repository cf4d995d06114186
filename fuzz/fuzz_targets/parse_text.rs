//! Any bytes that are UTF-8 → `robovec_ir::text::parse` returns (Ok or errors), never panics.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(s) = std::str::from_utf8(data) {
        let _ = robovec_ir::text::parse(s);
    }
});
