//! Lowering on hand-computed tiny placements, encoded, decoded and executed. The tests that
//! need a placer (the lowered verifier on broken programs of a placed function, and the
//! property of issue 12: random DAGs placed at random N, lowered, encoded, decoded, executed —
//! equal to the interpreter bit for bit) are `robovec-passes`' (`sim/machine_tests.rs`): `place`
//! is a pass.

use robovec_ir::analysis::Latencies;
use robovec_ir::interp::pseudo_random_input;
use robovec_ir::machine::{
    BufferOp, Instr, MachineOp, MachineProgram, MemWrite, OutputLoc, PeProgram, Source, Step, Word,
};
use robovec_ir::placement::{Issue, Load, Pe, PeArray, Placement, Write};
use robovec_ir::text::parse;
use robovec_ir::{Function, Operand, Value};

use super::{lower, lower_measured, lower_measured_until, MachineError, MachineErrorKind, When};
use crate::encode::{encode, through_images, EncodeError, Layout};
use crate::exec::{execute, execute_until};

use Pe::{Add, Mul};

fn func(src: &str) -> Function {
    parse(src).unwrap_or_else(|e| panic!("{e:?}")).functions.remove(0)
}

fn v(f: &Function, name: &str) -> Value {
    f.lookup(name).unwrap_or_else(|| panic!("no %{name}"))
}

fn arch(n_add: u32, n_mul: u32) -> PeArray {
    PeArray { n_add, n_mul, lat: Latencies::default(), writes: 2, buffer: true }
}

fn load(f: &Function, pe: Pe, addr: u32, name: &str) -> Load {
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
    Some(Instr { op, reads: [a, b].into() })
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
        fixed: None,
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
/// `%x = a * b` on mul0 at 0, written directly into add0 at 7 and through mul0's buffer into
/// add1 at 9; `%y = x + a` on add0 at 7, `%z = x − b` on add1 at 9.
fn direct_and_indirect() -> (Function, Placement) {
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
    (f, p)
}

#[test]
fn direct_and_indirect_writes() {
    let (f, p) = direct_and_indirect();
    let m = lower(&f, &p).unwrap();
    assert_eq!(m.cycles, 21);
    let (add0, add1, mul0) = (&m.pes[0].steps, &m.pes[1].steps, &m.pes[2].steps);
    assert_eq!(mul0[0].issue, issue(MachineOp::Mul, 0, 1));
    assert_eq!(mul0[7].buffer, BufferOp { store: Some(0), read: None });
    assert_eq!(mul0[9].buffer, BufferOp { store: None, read: Some(0) });
    assert_eq!(add0[7].writes[..], [MemWrite { addr: 1, src: Source::Result(2) }]);
    assert_eq!(add0[7].issue, issue(MachineOp::Add, 1, 0));
    assert_eq!(add1[9].writes[..], [MemWrite { addr: 1, src: Source::Buffer(2) }]);
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

/// A `stop` hook that counts its calls and says stop at call `at` (and after).
fn stop_at(at: u64) -> (std::rc::Rc<std::cell::Cell<u64>>, impl Fn() -> bool) {
    let calls = std::rc::Rc::new(std::cell::Cell::new(0u64));
    let c = calls.clone();
    (calls, move || {
        c.set(c.get() + 1);
        c.get() >= at
    })
}

#[test]
fn a_stop_hook_returning_true_stops_the_lowering_wherever_it_is() {
    let (f, p) = direct_and_indirect();
    let (calls, never) = stop_at(u64::MAX);
    let whole = lower_measured_until(&f, &p, &never).expect("lowers");
    assert_eq!(whole, lower_measured(&f, &p).expect("lowers"), "the hook changes nothing when it says go on");
    let n = calls.get();
    // The plan (once, then per op in three loops and per write), the steps (per cycle with
    // events: 0, 7, 9, 19, 21) and the verifier's lowered check (per op, then per cycle
    // 0..=21) all call it.
    assert_eq!(n, (1 + 3 * 3 + 2) + 5 + (3 + 22));
    for at in 1..=n {
        let (calls, stop) = stop_at(at);
        let e = lower_measured_until(&f, &p, &stop).expect_err("stopped");
        assert_eq!(e, MachineError::stopped(), "call {at}");
        assert_eq!((e.kind, e.to_string()), (MachineErrorKind::Stopped, "stopped: time limit".to_string()));
        assert_eq!(calls.get(), at, "stops at the first true");
    }
}

#[test]
fn a_stop_hook_returning_true_stops_the_execution_at_that_cycle() {
    let (f, p) = direct_and_indirect();
    let m = lower(&f, &p).unwrap();
    let (calls, never) = stop_at(u64::MAX);
    assert_eq!(execute_until::<f64>(&m, input, &never), execute::<f64>(&m, input));
    assert_eq!(calls.get(), u64::from(m.cycles) + 1, "once per cycle 0..=cycles");
    for at in 1..=u64::from(m.cycles) + 1 {
        let (_, stop) = stop_at(at);
        let e = execute_until::<f32>(&m, input, &stop).expect_err("stopped");
        assert_eq!(e, MachineError::stopped().at(When::Cycle(at as u32 - 1)));
        assert_eq!(e.to_string(), format!("cycle {}: stopped: time limit", at - 1));
    }
}

/// A write from a buffer after the last arrival (useless, but legal) lengthens the program to
/// its cycle instead of indexing past the steps (it panicked), and the run still computes.
#[test]
fn a_buffer_write_after_the_last_arrival_lengthens_the_program() {
    let (f, mut p) = direct_and_indirect();
    p.pe_words[0] = 3;
    p.writes.push(Write { value: v(&f, "x"), pe: Add(0), addr: 2, cycle: 90, buffer_addr: Some(0) });
    let m = lower(&f, &p).unwrap();
    assert_eq!(m.cycles, 90);
    assert!(m.pes.iter().all(|q| q.steps.len() == 91));
    assert_eq!(m.pes[0].steps[90].writes[..], [MemWrite { addr: 2, src: Source::Buffer(2) }]);
    assert_eq!(m.pes[2].steps[90].buffer.read, Some(0));
    let x = execute::<f64>(&m, input).unwrap();
    assert_eq!(x.cycles, 90);
    let (a, b) = (input("a"), input("b"));
    assert_eq!(x.outputs, vec![("y".to_string(), a * b + a), ("z".to_string(), a * b - b)]);
    assert_eq!(round_trip(&m), m);
}

/// A write past the lowering's cycle bound is refused with a located error, not allocated.
#[test]
fn a_write_past_the_cycle_bound_is_refused() {
    let (f, mut p) = direct_and_indirect();
    p.writes[1].cycle = u32::MAX;
    let e = lower(&f, &p).unwrap_err();
    assert_eq!(e.kind, MachineErrorKind::Malformed, "{e}");
    assert!(e.to_string().contains("too late to lower"), "{e}");
}
