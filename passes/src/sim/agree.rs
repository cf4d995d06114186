//! The verifier's placement checks and the simulator agree (issue 10 item 4): on placements of
//! small generated functions, each mutated in one or two places, a placement `sim` accepts
//! verifies, and one that verifies fails `sim` only for what the verifier leaves to it (a word
//! rewritten while its value is still needed).

use robovec_ir::placement::{Pe, Placement};
use robovec_ir::verifier::placement::verify_placement as verifier_check;
use robovec_ir::Function;

use super::{verify_with, SimErrorKind as K};
use crate::place::{place_function, PlaceOptions};
use robovec_ir::rng::SplitMix64;
use robovec_testkit::dag_gen::generate;

fn placed(n_ops: usize, seed: u64, buffer: bool) -> Function {
    let mut f = generate(n_ops, seed);
    let mut o = PlaceOptions::with_pes(2);
    o.improve = 0;
    o.restarts = 0;
    o.search = 0;
    o.arch.buffer = buffer;
    o.arch.writes = if buffer { 1 + (seed % 2) as u32 } else { 2 };
    f.placement = Some(place_function(&f, &o));
    f
}

fn pick<T>(rng: &mut SplitMix64, v: &[T]) -> Option<usize> {
    (!v.is_empty()).then(|| rng.below(v.len() as u64) as usize)
}

fn jiggle(rng: &mut SplitMix64, x: u32) -> u32 {
    let d = 1 + rng.below(3) as u32;
    if rng.chance(500) {
        x.saturating_sub(d)
    } else {
        x + d
    }
}

fn other_pe(rng: &mut SplitMix64, p: &Placement) -> Pe {
    // One index past the last exists on neither side, to hit that rule too.
    let i = rng.below(p.arch.n_add as u64 + 1) as u32;
    if rng.chance(500) {
        Pe::Add(i)
    } else {
        Pe::Mul(i.min(p.arch.n_mul))
    }
}

fn mutate(rng: &mut SplitMix64, p: &mut Placement) {
    match rng.below(9) {
        0 | 1 => {
            let ops: Vec<usize> = (0..p.issue.len()).filter(|&i| p.issue[i].is_some()).collect();
            if let Some(k) = pick(rng, &ops) {
                let q = other_pe(rng, p);
                let is = p.issue[ops[k]].as_mut().unwrap();
                match rng.below(3) {
                    0 => is.cycle = jiggle(rng, is.cycle),
                    1 => is.pe = q,
                    _ => p.issue[ops[k]] = None,
                }
            }
        }
        2 | 3 => {
            if let Some(k) = pick(rng, &p.writes) {
                let words = p.pe_words.clone();
                let q = other_pe(rng, p);
                let w = &mut p.writes[k];
                match rng.below(5) {
                    0 => w.cycle = jiggle(rng, w.cycle),
                    1 => w.addr = rng.below(words.iter().copied().max().unwrap_or(1) as u64 + 1) as u32,
                    2 => w.pe = q,
                    3 => w.buffer_addr = if w.buffer_addr.is_some() { None } else { Some(rng.below(3) as u32) },
                    _ => {
                        let w = *w;
                        p.writes.push(w);
                    }
                }
            }
        }
        4 | 5 => {
            if let Some(k) = pick(rng, &p.loads) {
                let q = other_pe(rng, p);
                match rng.below(3) {
                    0 => p.loads[k].addr = jiggle(rng, p.loads[k].addr),
                    1 => p.loads[k].pe = q,
                    _ => {
                        p.loads.remove(k);
                    }
                }
            }
        }
        6 => {
            if let Some(k) = pick(rng, &p.pe_words) {
                p.pe_words[k] = p.pe_words[k].saturating_sub(1);
            }
        }
        7 => {
            if let Some(k) = pick(rng, &p.buffer_words) {
                p.buffer_words[k] = p.buffer_words[k].saturating_sub(1);
            }
        }
        _ => p.arch.writes = p.arch.writes.saturating_sub(1).max(1),
    }
}

#[test]
fn verifier_and_simulator_agree_on_mutated_placements() {
    let mut rng = SplitMix64::new(10);
    let (mut both_ok, mut both_bad, mut sim_only) = (0, 0, 0);
    for seed in 0..6u64 {
        let base = placed(40 + 10 * seed as usize, seed, seed % 3 != 2);
        assert!(verifier_check(&base).is_empty(), "{:?}", verifier_check(&base));
        verify_with(&base, base.placement.as_ref().unwrap(), &[0]).expect("the placer's placement simulates");
        for _ in 0..150 {
            let mut f = base.clone();
            let p = f.placement.as_mut().unwrap();
            for _ in 0..1 + rng.below(2) {
                mutate(&mut rng, p);
            }
            let v = verifier_check(&f);
            let s = verify_with(&f, f.placement.as_ref().unwrap(), &[0]);
            match (&s, v.is_empty()) {
                (Ok(_), true) => both_ok += 1,
                (Ok(_), false) => panic!("sim accepts a placement the verifier rejects: {v:?}\n{f}"),
                (Err(_), false) => both_bad += 1,
                (Err(e), true) => {
                    // Left to the simulator: word lifetimes.
                    let lifetime = e.kind == K::AddressReused
                        || (e.kind == K::ReadMissing
                            && (e.message.contains("overwritten") || e.message.contains("no longer holds")));
                    assert!(lifetime, "the verifier accepts a placement sim rejects for a rule both check: {e}\n{f}");
                    sim_only += 1;
                }
            }
        }
    }
    // The mutations exercise every case.
    assert!(both_ok > 0 && both_bad > 100 && sim_only > 0, "{both_ok} {both_bad} {sim_only}");
}
