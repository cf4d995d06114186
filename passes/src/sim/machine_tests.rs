//! The machine program of placed functions (`place`, then `robovec_machine::program::lower`): the
//! lowered verifier on broken programs, the binary32 data words, and the property of issue 12 —
//! random DAGs placed at random N, lowered, encoded, decoded, executed: equal to the
//! interpreter bit for bit in f32 and f64. (The hand-computed lowerings are `robovec-machine`'s
//! own tests; these need the placer.) The helpers are shared with `sim`'s tests.

use proptest::prelude::*;

use robovec_ir::analysis::Latencies;
use robovec_ir::interp::{eval, pseudo_random_input};
use robovec_ir::machine::{MachineProgram, MemWrite, Source};
use robovec_ir::placement::{Load, Pe, PeArray};
use robovec_ir::text::parse;
use robovec_ir::verifier::machine::verify_machine;
use robovec_ir::{Function, Operand, Value};
use robovec_machine::encode::{output_image, pe_image, through_images, Layout};
use robovec_machine::exec::execute;
use robovec_machine::program::lower;

use crate::place::{place_function, try_place_function, PlaceOptions};

pub(crate) fn func(src: &str) -> Function {
    parse(src).unwrap_or_else(|e| panic!("{e:?}")).functions.remove(0)
}

pub(crate) fn v(f: &Function, name: &str) -> Value {
    f.lookup(name).unwrap_or_else(|| panic!("no %{name}"))
}

pub(crate) fn arch(n_add: u32, n_mul: u32) -> PeArray {
    PeArray { n_add, n_mul, lat: Latencies::default(), writes: 2, buffer: true }
}

pub(crate) fn load(f: &Function, pe: Pe, addr: u32, name: &str) -> Load {
    Load { pe, addr, operand: Operand::Value(v(f, name)) }
}

fn input(name: &str) -> f64 {
    pseudo_random_input(name, 5)
}

/// DE10-Nano words: 2048-word PE memories and buffers, 52-bit instructions (seed §1.3.1).
fn de10_layout(m: &MachineProgram) -> Layout {
    Layout::new(m, 2048, 2048, 52).expect("fits")
}

/// The program the DE10-Nano images of `m` carry back.
fn round_trip(m: &MachineProgram) -> MachineProgram {
    through_images(m, &de10_layout(m)).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_lowered_verifier_finds_broken_programs() {
    let f = func("func @f { phase atomised input %a input %b %x = mul %a, %b %y = add %x, %a output o = %y }");
    let p = place_function(&f, &PlaceOptions::with_pes(1));
    let m = lower(&f, &p).unwrap();
    assert!(verify_machine(&f, &m).is_empty());
    let fails = |m: &MachineProgram, part: &str| {
        let errs = verify_machine(&f, m);
        assert!(errs.iter().any(|e| e.to_string().contains(part)), "`{part}` not in {errs:?}");
    };
    // Swap the operands of the add: the reads no longer hold %x then %a.
    let mut bad = m.clone();
    let (s, c) = m.issue_of[v(&f, "y").index()].unwrap();
    bad.pes[s].steps[c as usize].issue.as_mut().unwrap().reads.reverse();
    fails(&bad, "operand 0 of %y reads address");
    // Drop every write: %x never reaches the add's memory.
    let mut bad = m.clone();
    bad.pes.iter_mut().flat_map(|q| &mut q.steps).for_each(|s| s.writes.clear());
    fails(&bad, "holds nothing instead of %x");
    // A write source that carries nothing this cycle.
    let mut bad = m.clone();
    bad.pes[0].steps[1].writes.push(MemWrite { addr: 0, src: Source::Result(1) });
    fails(&bad, "carries nothing");
    // An address beyond the memory and an incomplete output map.
    let mut bad = m.clone();
    bad.pes[s].steps[c as usize].issue.as_mut().unwrap().reads[1] = 99;
    bad.outputs.clear();
    fails(&bad, "read address 99");
    fails(&bad, "0 output locations for 1 outputs");
    // Three writes on a two-port memory.
    let mut bad = m.clone();
    bad.arch.writes = 1;
    let w = MemWrite { addr: 0, src: Source::Result(0) };
    bad.pes[0].steps[0].writes = [w, w].into();
    fails(&bad, "2 writes, 1 write ports");
}

/// Random DAGs (testkit's `dag_gen`), placed at random N with or without buffers, lowered,
/// encoded, decoded and executed: the outputs equal the interpreter's bit for bit in f32 and
/// f64 (the FP ops are the same IEEE operations in the same order, so equality is exact).
fn lowered_encoded_decoded_equals_interp(n_ops: usize, seed: u64, n: u32, buffer: bool) {
    let f = robovec_testkit::dag_gen::generate(n_ops, seed);
    let mut o = PlaceOptions::with_pes(n);
    o.improve = 0;
    o.restarts = 0;
    o.search = 0;
    o.arch.buffer = buffer;
    // Without buffers a placement may get stuck (a result can only be written at its arrival):
    // that is a documented refusal, not a wrong program; with buffers one always exists.
    let p = match try_place_function(&f, &o) {
        Ok(p) => p,
        Err(e) if !buffer => return assert!(e.contains("use buffer=on"), "{e}"),
        Err(e) => panic!("with buffers a placement always exists: {e}"),
    };
    let m = lower(&f, &p).unwrap_or_else(|e| panic!("{e}"));
    let back = round_trip(&m);
    assert_eq!(back, m);
    let input = |name: &str| pseudo_random_input(name, seed);
    let x32 = execute::<f32>(&back, input).unwrap();
    let x64 = execute::<f64>(&back, input).unwrap();
    let bits32 = |v: &[(String, f32)]| v.iter().map(|(n, x)| (n.clone(), x.to_bits())).collect::<Vec<_>>();
    let bits64 = |v: &[(String, f64)]| v.iter().map(|(n, x)| (n.clone(), x.to_bits())).collect::<Vec<_>>();
    assert_eq!(bits32(&x32.outputs), bits32(&eval::<f32>(&f, input)));
    assert_eq!(bits64(&x64.outputs), bits64(&eval::<f64>(&f, input)));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn random_dags_lower_encode_decode_and_execute_like_interp(
        n_ops in 1usize..120,
        seed in 0u64..1_000_000,
        n in 1u32..=4,
        buffer in any::<bool>(),
    ) {
        lowered_encoded_decoded_equals_interp(n_ops, seed, n, buffer);
    }
}

/// The binary32 data words are what `interp` computes in f32: an input rounded to nearest, a
/// trig value in f32 of the rounded input, a constant rounded (0.1 is not exact in binary32).
#[test]
fn data_words_are_interp_binary32() {
    let f = func(
        "func @f { phase atomised input %q %s = cos %q %x = mul %s, 0.1 output o = %x output a = %q \
         output c = 0.1 output t = %s }",
    );
    let p = place_function(&f, &PlaceOptions::with_pes(1));
    let m = lower(&f, &p).unwrap();
    let expected = eval::<f32>(&f, input);
    let out = output_image(&m, 0, input);
    for (loc, (name, x)) in m.outputs.iter().zip(&expected).skip(1) {
        assert_eq!(&loc.name, name);
        assert_eq!((loc.slot, out[loc.addr as usize]), (0, x.to_bits()), "output `{name}`");
    }
    assert_eq!(out[m.outputs[2].addr as usize], 0.1f32.to_bits());
    // The multiplier reads cos q and 0.1 from its memory image.
    let mul = &m.pes[1];
    let image = pe_image(&m, 1, input);
    let reads = &mul.steps.iter().find_map(|s| s.issue.as_ref()).unwrap().reads;
    let (cos_q, tenth) = (image[reads[0] as usize], image[reads[1] as usize]);
    assert_eq!(cos_q, (input("q") as f32).cos().to_bits());
    assert_eq!(tenth, 0.1f32.to_bits());
}
