//! Random `+ − ×` expression DAGs (built from the bytes by `robovec_testkit::expr_gen`) through a
//! random pipeline of registered passes: the module verifies after every pass and every output
//! stays within the error budget of the exact value (bit-exact for passes that must not change
//! values); see `robovec_testkit::numeric_check`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use robovec_ir::rng::SplitMix64;
use robovec_testkit::{expr_gen, numeric_check};

fuzz_target!(|data: &[u8]| {
    // Byte 0: pipeline length 1–4; bytes 1–4: passes; the rest: the function.
    let names = numeric_check::checked_passes();
    let len = 1 + data.first().copied().unwrap_or(0) as usize % 4;
    let picks: Vec<&str> =
        (0..len).map(|i| names[data.get(1 + i).copied().unwrap_or(0) as usize % names.len()]).collect();
    let f = expr_gen::from_bytes(data.get(5..).unwrap_or(&[]));
    let mut rng = SplitMix64::new(
        data.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x1_0000_0001_b3)),
    );
    let points: Vec<Vec<f64>> = (0..3).map(|_| expr_gen::point(&f, &mut rng)).collect();
    let pipeline = numeric_check::pipeline_text(&picks);
    if let Err(e) = numeric_check::check(&f, &pipeline, &points) {
        panic!("{e}\n--- function ---\n{}", robovec_ir::Module { functions: vec![f] });
    }
});
