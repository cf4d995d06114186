//! Lowering on hand-computed tiny placements, the lowered verifier on broken programs, and the
//! property of issue 12: random DAGs placed at random N, lowered, encoded, decoded, executed —
//! equal to the interpreter bit for bit in f32 and f64.

use proptest::prelude::*;

use robovec_ir::analysis::Latencies;
use robovec_ir::interp::{eval, pseudo_random_input};
use robovec_ir::machine::encode::{decode, encode, EncodeError, Layout};
use robovec_ir::machine::{
    BufferOp, Instr, MachineOp, MachineProgram, MemWrite, OutputLoc, PeProgram, Source, Step, Word,
};
use robovec_ir::placement::{Arch, Issue, Load, Pe, Placement, Write};
use robovec_ir::text::parse;
use robovec_ir::verifier::machine::verify_machine;
use robovec_ir::{Function, Operand, Value};

use super::{execute, lower, MachineErrorKind};
use crate::place::{place_function, PlaceOptions};

use Pe::{Add, Mul};

pub(crate) fn func(src: &str) -> Function {
    parse(src).unwrap_or_else(|e| panic!("{e:?}")).functions.remove(0)
}

pub(crate) fn v(f: &Function, name: &str) -> Value {
    f.lookup(name).unwrap_or_else(|| panic!("no %{name}"))
}

pub(crate) fn arch(n_add: u32, n_mul: u32) -> Arch {
    Arch { n_add, n_mul, lat: Latencies::default(), writes: 2, buffer: true }
}

pub(crate) fn load(f: &Function, pe: Pe, addr: u32, name: &str) -> Load {
    Load { pe, addr, operand: Operand::Value(v(f, name)) }
}

fn issues(f: &Function, list: &[(&str, Pe, u32)]) -> Vec<Option<Issue>> {
    let mut is = vec![None; f.values.len()];
    for &(name, pe, cycle) in list {
        is[v(f, name).index()] = Some(Issue { pe, cycle });
    }
    is
}

fn input(name: &str) -> f64 {
    pseudo_random_input(name, 5)
}

fn word(name: &str) -> Option<Word> {
    Some(Word::Input(name.into()))
}

fn idle(pe: Pe, init: Vec<Option<Word>>, cycles: u32) -> PeProgram {
    PeProgram { pe, init, output_init: Vec::new(), steps: vec![Step::default(); cycles as usize + 1] }
}

fn issue(op: MachineOp, a: u32, b: u32) -> Option<Instr> {
    Some(Instr { op, reads: vec![a, b] })
}

/// DE10-Nano words: 2048-word PE memories and buffers, 52-bit instructions (seed §1.3.1).
fn de10_layout(m: &MachineProgram) -> Layout {
    Layout::new(m, 2048, 2048, 52).expect("fits")
}

/// Encodes, decodes and puts the decoded steps back into the program.
fn round_trip(m: &MachineProgram) -> MachineProgram {
    let im = encode(m, &de10_layout(m)).expect("encodes");
    let steps = decode(&im).expect("decodes");
    let mut back = m.clone();
    for (q, s) in back.pes.iter_mut().zip(steps) {
        q.steps = s;
    }
    back
}

#[test]
fn a_lone_add_takes_12_cycles() {
    let f = func("func @f { phase atomised input %a input %b %x = add %a, %b output o = %x }");
    let p = Placement {
        arch: arch(1, 1),
        issue: issues(&f, &[("x", Add(0), 0)]),
        loads: vec![load(&f, Add(0), 0, "a"), load(&f, Add(0), 1, "b")],
        writes: vec![],
        pe_words: vec![2, 0],
        buffer_words: vec![0, 0],
        spans: Default::default(),
    };
    let m = lower(&f, &p).unwrap();
    let mut add0 = idle(Add(0), vec![word("a"), word("b")], 12);
    add0.steps[0].issue = issue(MachineOp::Add, 0, 1);
    add0.steps[12].capture = Some(0);
    add0.output_init = vec![None];
    let expected = MachineProgram {
        arch: arch(1, 1),
        cycles: 12,
        pe_words: vec![2, 0],
        buffer_words: vec![0, 0],
        output_words: vec![1, 0],
        pes: vec![add0, idle(Mul(0), vec![], 12)],
        outputs: vec![OutputLoc { name: "o".into(), slot: 0, addr: 0 }],
        issue_of: {
            let mut i = vec![None; f.values.len()];
            i[v(&f, "x").index()] = Some((0, 0));
            i
        },
    };
    assert_eq!(m, expected);
    let x = execute::<f32>(&m, input).unwrap();
    assert_eq!(x.cycles, 12);
    assert_eq!(x.outputs, vec![("o".to_string(), input("a") as f32 + input("b") as f32)]);
    // The instruction word of cycle 0 (aw = 11): read A = 0, read B = 1 at bit 11, issue
    // valid at bit 46; the capture word of cycle 12 (ow = 1): address 0, enable bit 1.
    let im = encode(&m, &de10_layout(&m)).unwrap();
    assert_eq!(im.instr[0][0], (1 << 11) | (1 << 46));
    assert_eq!(im.capture[0][12], 0b10);
    assert!(im.instr[0][1..].iter().all(|&w| w == 0));
    assert_eq!(round_trip(&m), m);
}

/// `%x = a·b` on mul0 at 0 (arrives 7): written directly into add0 at 7 (address 1) and,
/// through mul0's buffer (address 0), into add1 at 9 (address 1). `%y = x + a` on add0 at 7,
/// `%z = x − b` on add1 at 9.
#[test]
fn direct_and_indirect_writes() {
    let f = func(
        "func @f { phase atomised input %a input %b %x = mul %a, %b %y = add %x, %a %z = sub %x, %b \
         output y = %y output z = %z }",
    );
    let p = Placement {
        arch: arch(2, 1),
        issue: issues(&f, &[("x", Mul(0), 0), ("y", Add(0), 7), ("z", Add(1), 9)]),
        loads: vec![
            load(&f, Mul(0), 0, "a"),
            load(&f, Mul(0), 1, "b"),
            load(&f, Add(0), 0, "a"),
            load(&f, Add(1), 0, "b"),
        ],
        writes: vec![
            Write { value: v(&f, "x"), pe: Add(0), addr: 1, cycle: 7, buffer_addr: None },
            Write { value: v(&f, "x"), pe: Add(1), addr: 1, cycle: 9, buffer_addr: Some(0) },
        ],
        pe_words: vec![2, 2, 2],
        buffer_words: vec![0, 0, 1],
        spans: Default::default(),
    };
    let m = lower(&f, &p).unwrap();
    assert_eq!(m.cycles, 21);
    let (add0, add1, mul0) = (&m.pes[0].steps, &m.pes[1].steps, &m.pes[2].steps);
    assert_eq!(mul0[0].issue, issue(MachineOp::Mul, 0, 1));
    assert_eq!(mul0[7].buffer, BufferOp { store: Some(0), read: None });
    assert_eq!(mul0[9].buffer, BufferOp { store: None, read: Some(0) });
    assert_eq!(add0[7].writes, vec![MemWrite { addr: 1, src: Source::Result(2) }]);
    assert_eq!(add0[7].issue, issue(MachineOp::Add, 1, 0));
    assert_eq!(add1[9].writes, vec![MemWrite { addr: 1, src: Source::Buffer(2) }]);
    assert_eq!(add1[9].issue, issue(MachineOp::Sub, 1, 0));
    assert_eq!((add0[19].capture, add1[21].capture), (Some(0), Some(0)));
    let busy = m.pes.iter().flat_map(|q| &q.steps).filter(|s| **s != Step::default()).count();
    assert_eq!(busy, 7, "nothing else happens");
    assert_eq!(
        m.outputs,
        vec![OutputLoc { name: "y".into(), slot: 0, addr: 0 }, OutputLoc { name: "z".into(), slot: 1, addr: 0 }]
    );
    let (a, b) = (input("a") as f32, input("b") as f32);
    let x = execute::<f32>(&m, input).unwrap();
    assert_eq!(x.outputs, vec![("y".to_string(), a * b + a), ("z".to_string(), a * b - b)]);
    assert_eq!((m.writes_direct(), m.writes_indirect()), (1, 1));
    // Crossbar (n_pe = 3, sw = 3): add0 port 0 selects result of slot 2 = 3; add1 port 0
    // selects the buffer of slot 2 = 1 + 3 + 2 = 6. Buffer words (bw = 11): store enable bit
    // 22, read address at bit 11 with read enable bit 23.
    let im = encode(&m, &de10_layout(&m)).unwrap();
    assert_eq!((im.crossbar[0][7], im.crossbar[1][9]), (3, 6));
    assert_eq!((im.buffer[2][7], im.buffer[2][9]), (1 << 22, 1 << 23));
    // add1 at 9: read A = 1, B = 0, write-0 address 1 at bit 22, we0 bit 44, valid 46, sub 47.
    assert_eq!(im.instr[1][9], 1 | (1 << 22) | (1 << 44) | (1 << 46) | (1 << 47));
    assert_eq!(round_trip(&m), m);
}

#[test]
fn outputs_that_are_inputs_or_constants_are_loaded_into_slot_0() {
    let f = func("func @f { phase atomised input %a output o = %a output c = 3.0 output d = %a }");
    let p = Placement {
        arch: arch(1, 1),
        issue: vec![None; f.values.len()],
        loads: vec![],
        writes: vec![],
        pe_words: vec![0, 0],
        buffer_words: vec![0, 0],
        spans: Default::default(),
    };
    let m = lower(&f, &p).unwrap();
    assert_eq!(m.cycles, 0);
    assert_eq!(m.pes[0].output_init, vec![word("a"), Some(Word::Const(3.0))]);
    let at = |slot, addr| (slot, addr);
    assert_eq!(m.outputs.iter().map(|o| at(o.slot, o.addr)).collect::<Vec<_>>(), vec![(0, 0), (0, 1), (0, 0)]);
    let x = execute::<f64>(&m, input).unwrap();
    assert_eq!(x.outputs.iter().map(|o| o.1).collect::<Vec<_>>(), vec![input("a"), 3.0, input("a")]);
    assert_eq!(round_trip(&m), m);
}

#[test]
fn div_and_call_lower_but_do_not_encode() {
    let f = func("func @f { phase atomised input %a input %b %x = div %a, %b output o = %x }");
    let p = Placement {
        arch: arch(1, 1),
        issue: issues(&f, &[("x", Add(0), 0)]),
        loads: vec![load(&f, Add(0), 0, "a"), load(&f, Add(0), 1, "b")],
        writes: vec![],
        pe_words: vec![2, 0],
        buffer_words: vec![0, 0],
        spans: Default::default(),
    };
    let m = lower(&f, &p).unwrap();
    assert_eq!(execute::<f64>(&m, input).unwrap().outputs[0].1, input("a") / input("b"));
    let e = encode(&m, &de10_layout(&m)).unwrap_err();
    assert_eq!(e, EncodeError::NoUnit { slot: 0, cycle: 0, op: "div".into() });
    assert!(e.to_string().contains("no unit on the FPGA"), "{e}");
}

#[test]
fn results_colliding_on_one_pe_are_rejected() {
    // div latency 5, add 12: %y = a + b issued at 0 and %x = a / b at 7 both arrive at 12.
    let f = func(
        "func @f { phase atomised input %a input %b %y = add %a, %b %x = div %a, %b output o = %x output p = %y }",
    );
    let mut a = arch(1, 1);
    a.lat.div = 5;
    let p = Placement {
        arch: a,
        issue: issues(&f, &[("y", Add(0), 0), ("x", Add(0), 7)]),
        loads: vec![load(&f, Add(0), 0, "a"), load(&f, Add(0), 1, "b")],
        writes: vec![],
        pe_words: vec![2, 0],
        buffer_words: vec![0, 0],
        spans: Default::default(),
    };
    let e = lower(&f, &p).unwrap_err();
    assert_eq!(e.kind, MachineErrorKind::ResultCollision, "{e}");
    assert!(e.to_string().contains("cycle 12, add0, %x"), "{e}");
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
    bad.pes[0].steps[0].writes = vec![w, w];
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
    let p = place_function(&f, &o);
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
    let out = m.output_image(0, input);
    for (loc, (name, x)) in m.outputs.iter().zip(&expected).skip(1) {
        assert_eq!(&loc.name, name);
        assert_eq!((loc.slot, out[loc.addr as usize]), (0, x.to_bits()), "output `{name}`");
    }
    assert_eq!(out[m.outputs[2].addr as usize], 0.1f32.to_bits());
    // The multiplier reads cos q and 0.1 from its memory image.
    let mul = &m.pes[1];
    let image = m.pe_image(1, input);
    let reads = &mul.steps.iter().find_map(|s| s.issue.as_ref()).unwrap().reads;
    let (cos_q, tenth) = (image[reads[0] as usize], image[reads[1] as usize]);
    assert_eq!(cos_q, (input("q") as f32).cos().to_bits());
    assert_eq!(tenth, 0.1f32.to_bits());
}
