//! Any UTF-8 bytes → `robovec_machine::target::Target::from_json` (the `-target=FILE.json`
//! reader) returns a target or a located error, never panics; an accepted target's PE arrays,
//! per-width fixed-point costs and latencies, and analytic estimates are computed without a
//! panic for the first bytes' PE counts and word (issue 49's `family`, `pnr` and `pe_word_alm`
//! keys, narrow words).
#![no_main]

use libfuzzer_sys::fuzz_target;
use robovec_machine::design::build::ShiftRanges;
use robovec_machine::resources::{cost_model, fixed_unit};
use robovec_machine::target::Target;

fuzz_target!(|data: &[u8]| {
    if data.len() < 4 {
        return;
    }
    let (head, text) = data.split_at(4);
    let Ok(s) = std::str::from_utf8(text) else { return };
    let Ok(t) = Target::from_json("fuzz.json", s) else { return };
    let (n_add, n_mul) = (u32::from(head[0]) + 1, u32::from(head[1]) + 1);
    let word = u32::from(head[2] % 32) + 1;
    let _ = t.pe_array(n_add, n_mul, head[3] & 1 == 1);
    let _ = t.estimate(n_add, n_mul, u32::from(head[3]) * 16);
    let _ = t.fix_pe.latencies_for(t.family, word, false);
    let _ = t.fix_pe.latencies_for(t.family, word, true);
    let m = cost_model(&t);
    let ranges = ShiftRanges {
        align_max: head[3] % 64,
        shift_min: -((head[3] % 65) as i8),
        shift_max: (head[3] % 63) as i8,
        floor_max: head[3] % 63,
    };
    let _ = fixed_unit(&m, word, head[3] & 2 == 2, word + u32::from(head[3] % 40), ranges);
});
