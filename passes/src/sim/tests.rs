use super::*;
use robovec_ir::interp::pseudo_random_input;
use robovec_ir::placement::{Issue, Load, Pe, Write};
use robovec_ir::text::parse;
use robovec_ir::{Operand, Value};

use Pe::{Add, Mul};

const SRC: &str = "func @f { phase atomised input %a input %b %x = mul %a, %b %y = add %x, %a output o = %y }";

use super::machine_tests::{arch, func, load, v};

fn direct(f: &Function, name: &str, pe: Pe, addr: u32, cycle: u32) -> Write {
    Write { value: v(f, name), pe, addr, cycle, buffer_addr: None }
}

fn indirect(f: &Function, name: &str, pe: Pe, addr: u32, cycle: u32, buffer_addr: u32) -> Write {
    Write { value: v(f, name), pe, addr, cycle, buffer_addr: Some(buffer_addr) }
}

fn issue(f: &Function, list: &[(&str, Pe, u32)]) -> Vec<Option<Issue>> {
    let mut is = vec![None; f.values.len()];
    for &(name, pe, cycle) in list {
        is[v(f, name).index()] = Some(Issue { pe, cycle });
    }
    is
}

/// The example: mul on mul0 at 0, add on add0 at 7, %x written directly into add0 at 7,
/// %a loaded into mul0 and add0, %b into mul0.
fn base(f: &Function) -> Placement {
    Placement {
        arch: arch(1, 1),
        issue: issue(f, &[("x", Mul(0), 0), ("y", Add(0), 7)]),
        loads: vec![load(f, Mul(0), 0, "a"), load(f, Mul(0), 1, "b"), load(f, Add(0), 0, "a")],
        writes: vec![direct(f, "x", Add(0), 1, 7)],
        pe_words: vec![2, 2],
        buffer_words: vec![0, 0],
        spans: Default::default(),
    }
}

fn input(name: &str) -> f64 {
    pseudo_random_input(name, 7)
}

fn fails(f: &Function, p: &Placement, kind: SimErrorKind, parts: &[&str]) -> SimError {
    let e = simulate::<f64>(f, p, input).expect_err("placement should be rejected");
    let text = e.to_string();
    assert_eq!(e.kind, kind, "{text}");
    for part in parts {
        assert!(text.contains(part), "`{text}` should contain `{part}`");
    }
    e
}

#[test]
fn valid_direct_placement() {
    let f = func(SRC);
    let p = base(&f);
    let o = simulate::<f64>(&f, &p, input).unwrap();
    assert_eq!(o.cycles, 19);
    assert_eq!(o.outputs, robovec_ir::interp::eval::<f64>(&f, input));
    let (a, b) = (input("a"), input("b"));
    assert_eq!(o.outputs[0].1, a * b + a);
    assert_eq!((o.writes_direct, o.writes_indirect), (1, 0));
    assert_eq!(o.max_words_per_memory, vec![2, 2]);
    assert_eq!(o.max_buffer_words, vec![0, 0]);
    let mut add = vec![0; 19];
    add[7] = 1;
    let mut mul = vec![0; 19];
    mul[0] = 1;
    assert_eq!((o.issued_per_cycle_add, o.issued_per_cycle_mul), (add, mul));
    let o32 = simulate::<f32>(&f, &p, input).unwrap();
    assert_eq!(o32.outputs, robovec_ir::interp::eval::<f32>(&f, input));
    let r = verify_with(&f, &p, &[0, 1, 2]).unwrap();
    assert_eq!((r.cycles, r.outputs, r.seeds.len()), (19, 1, 3));
}

#[test]
fn valid_indirect_write_with_fan_out() {
    let f = func(SRC);
    let mut p = base(&f);
    p.arch = arch(2, 1);
    p.issue = issue(&f, &[("x", Mul(0), 0), ("y", Add(1), 9)]);
    p.loads = vec![load(&f, Mul(0), 0, "a"), load(&f, Mul(0), 1, "b"), load(&f, Add(1), 0, "a")];
    // %x waits in mul0's buffer from 7; one read at 9 fans out into add0 and add1.
    p.writes = vec![indirect(&f, "x", Add(0), 0, 9, 0), indirect(&f, "x", Add(1), 1, 9, 0)];
    p.pe_words = vec![1, 2, 2];
    p.buffer_words = vec![0, 0, 1];
    let o = simulate::<f64>(&f, &p, input).unwrap();
    assert_eq!(o.cycles, 21);
    assert_eq!(o.outputs, robovec_ir::interp::eval::<f64>(&f, input));
    assert_eq!((o.writes_direct, o.writes_indirect), (0, 2));
    assert_eq!(o.max_buffer_words, vec![0, 0, 1]);
    assert_eq!(o.max_words_per_memory, vec![1, 2, 2]);
    verify_with(&f, &p, &[3, 4]).unwrap();
}

#[test]
fn constants_trig_and_calls_with_three_operands() {
    let f = func(
        "func @f { phase atomised input %q %s = sin %q %x = add %s, 2.0 %z = call @user_g(%x, %q, %s) \
         output o = %z output c = -1.5 output t = %s }",
    );
    let p = Placement {
        arch: arch(1, 0),
        issue: issue(&f, &[("x", Add(0), 0), ("z", Add(0), 12)]),
        loads: vec![
            load(&f, Add(0), 0, "s"),
            Load { pe: Add(0), addr: 1, operand: Operand::Const(2.0) },
            load(&f, Add(0), 2, "q"),
        ],
        // 2.0 is dead after cycle 0: %x reuses its address.
        writes: vec![direct(&f, "x", Add(0), 1, 12)],
        pe_words: vec![3],
        buffer_words: vec![0],
        spans: Default::default(),
    };
    let r = verify_with(&f, &p, &[0, 1, 2]).unwrap();
    assert_eq!(r.cycles, 24);
    assert_eq!(r.max_words_per_memory, vec![3]);
    // Without the constant in memory, the add cannot read it.
    let mut q = p.clone();
    q.loads.remove(1);
    fails(&f, &q, SimErrorKind::ReadMissing, &["cycle 0", "add0", "2.0", "never written or loaded"]);
    // A call reads all its operands: drop %q and the third read fails.
    let mut q = p.clone();
    q.loads.remove(2);
    fails(&f, &q, SimErrorKind::ReadMissing, &["cycle 12", "add0", "%q"]);
}

#[test]
fn op_on_wrong_pe_type() {
    let f = func(SRC);
    let mut p = base(&f);
    p.issue = issue(&f, &[("x", Add(0), 0), ("y", Add(0), 7)]);
    fails(&f, &p, SimErrorKind::WrongPeType, &["cycle 0", "add0", "%x", "wrong type"]);
}

#[test]
fn unknown_pe() {
    let f = func(SRC);
    let mut p = base(&f);
    p.issue = issue(&f, &[("x", Mul(1), 0), ("y", Add(0), 7)]);
    fails(&f, &p, SimErrorKind::NoSuchPe, &["cycle 0", "mul1", "%x", "does not exist"]);
}

#[test]
fn two_ops_on_one_pe_in_one_cycle() {
    let f = func(
        "func @f { phase atomised input %a input %b %x = add %a, %b %y = sub %a, %b output o = %x output p = %y }",
    );
    let p = Placement {
        arch: arch(1, 0),
        issue: issue(&f, &[("x", Add(0), 3), ("y", Add(0), 3)]),
        loads: vec![load(&f, Add(0), 0, "a"), load(&f, Add(0), 1, "b")],
        writes: vec![],
        pe_words: vec![2],
        buffer_words: vec![0],
        spans: Default::default(),
    };
    fails(&f, &p, SimErrorKind::PeBusy, &["cycle 3", "add0", "%y", "same cycle as %x"]);
}

#[test]
fn missing_issue_of_an_output_op() {
    let f = func(SRC);
    let mut p = base(&f);
    p.issue = issue(&f, &[("x", Mul(0), 0)]);
    fails(&f, &p, SimErrorKind::MissingIssue, &["%y", "never issued"]);
}

#[test]
fn issue_or_write_of_a_non_op() {
    let f = func(SRC);
    let mut p = base(&f);
    p.issue[v(&f, "a").index()] = Some(Issue { pe: Add(0), cycle: 1 });
    fails(&f, &p, SimErrorKind::NotAnOp, &["cycle 1", "add0", "%a"]);
    let mut p = base(&f);
    p.writes.push(direct(&f, "b", Add(0), 1, 7));
    fails(&f, &p, SimErrorKind::NotAnOp, &["cycle 7", "add0", "%b"]);
}

#[test]
fn load_of_an_op_result_is_not_a_stale_copy() {
    let f = func(SRC);
    let mut p = base(&f);
    p.loads.push(load(&f, Add(0), 1, "x"));
    fails(&f, &p, SimErrorKind::BadLoad, &["before cycle 0", "add0", "%x", "not initial data"]);
}

#[test]
fn read_of_a_value_never_written() {
    let f = func(SRC);
    let mut p = base(&f);
    p.loads.pop(); // %a never reaches add0
    fails(&f, &p, SimErrorKind::ReadMissing, &["cycle 7", "add0", "%a", "never written or loaded there"]);
}

#[test]
fn read_of_a_value_written_later() {
    let f = func(SRC);
    let mut p = base(&f);
    // %x arrives at 7 and waits in the buffer until 9, but the add issues at 8.
    p.issue = issue(&f, &[("x", Mul(0), 0), ("y", Add(0), 8)]);
    p.writes = vec![indirect(&f, "x", Add(0), 1, 9, 0)];
    p.buffer_words = vec![0, 1];
    fails(&f, &p, SimErrorKind::ReadMissing, &["cycle 8", "add0", "%x", "written there only at cycle 9"]);
}

#[test]
fn read_of_an_overwritten_value_is_address_reuse() {
    let f = func(SRC);
    let mut p = base(&f);
    // %x lands on %a's address of add0 in the cycle %a is read.
    p.writes = vec![direct(&f, "x", Add(0), 0, 7)];
    fails(
        &f,
        &p,
        SimErrorKind::AddressReused,
        &["cycle 7", "add0", "%x", "holds %a, which is read at cycle 7", "still needed"],
    );
}

#[test]
fn op_issued_before_its_operand_arrives() {
    let f = func(SRC);
    let mut p = base(&f);
    p.issue = issue(&f, &[("x", Mul(0), 0), ("y", Add(0), 6)]);
    fails(&f, &p, SimErrorKind::BeforeArrival, &["cycle 6", "add0", "%x", "arrives only at cycle 7"]);
}

#[test]
fn write_ports_over_subscribed() {
    let f = func(SRC);
    let mut p = base(&f);
    p.writes = vec![direct(&f, "x", Add(0), 1, 7), direct(&f, "x", Add(0), 2, 7), direct(&f, "x", Add(0), 3, 7)];
    p.pe_words = vec![4, 2];
    fails(&f, &p, SimErrorKind::WritePorts, &["cycle 7", "add0", "%x", "2 write ports"]);
    p.arch.writes = 3;
    simulate::<f64>(&f, &p, input).unwrap();
}

fn two_products() -> (Function, Placement) {
    let f = func(
        "func @f { phase atomised input %a input %b %x = mul %a, %b %z = mul %b, %b %y = add %x, %z output o = %y }",
    );
    let p = Placement {
        arch: arch(1, 1),
        issue: issue(&f, &[("x", Mul(0), 0), ("z", Mul(0), 1), ("y", Add(0), 10)]),
        loads: vec![load(&f, Mul(0), 0, "a"), load(&f, Mul(0), 1, "b")],
        writes: vec![indirect(&f, "x", Add(0), 0, 9, 0), indirect(&f, "z", Add(0), 1, 10, 1)],
        pe_words: vec![2, 2],
        buffer_words: vec![0, 2],
        spans: Default::default(),
    };
    (f, p)
}

#[test]
fn two_buffer_reads_in_one_cycle() {
    let (f, mut p) = two_products();
    verify_with(&f, &p, &[0]).unwrap();
    p.writes[1].cycle = 9;
    fails(&f, &p, SimErrorKind::BufferReads, &["cycle 9", "mul0", "%z", "read twice"]);
}

#[test]
fn buffer_address_reused_while_needed() {
    let (f, mut p) = two_products();
    p.writes[1].buffer_addr = Some(0);
    fails(&f, &p, SimErrorKind::AddressReused, &["cycle 8", "mul0", "%z", "holds %x, which is read at cycle 9"]);
    // Once %x has been read out (cycle 7 arrival, read at 7), %z may take its word at 8.
    p.writes[0].cycle = 7;
    p.buffer_words = vec![0, 1];
    let o = simulate::<f64>(&f, &p, input).unwrap();
    assert_eq!(o.max_buffer_words, vec![0, 1]);
}

#[test]
fn value_in_two_buffer_addresses() {
    let f = func(SRC);
    let mut p = base(&f);
    p.arch = arch(2, 1);
    p.pe_words = vec![2, 2, 2];
    p.buffer_words = vec![0, 0, 2];
    p.writes =
        vec![direct(&f, "x", Add(0), 1, 7), indirect(&f, "x", Add(1), 0, 8, 0), indirect(&f, "x", Add(1), 1, 9, 1)];
    fails(&f, &p, SimErrorKind::BufferEntries, &["cycle 7", "mul0", "%x", "two addresses (0 and 1)"]);
}

#[test]
fn indirect_write_without_buffers() {
    let f = func(SRC);
    let mut p = base(&f);
    p.arch.buffer = false;
    p.writes = vec![indirect(&f, "x", Add(0), 1, 8, 0)];
    p.issue = issue(&f, &[("x", Mul(0), 0), ("y", Add(0), 8)]);
    p.buffer_words = vec![0, 1];
    fails(&f, &p, SimErrorKind::NoBuffer, &["cycle 7", "mul0", "%x", "no buffers"]);
}

#[test]
fn direct_write_off_arrival() {
    let f = func(SRC);
    let mut p = base(&f);
    p.writes[0].cycle = 8;
    p.issue = issue(&f, &[("x", Mul(0), 0), ("y", Add(0), 8)]);
    fails(&f, &p, SimErrorKind::DirectWriteCycle, &["cycle 8", "add0", "%x", "arrives at cycle 7"]);
    p.writes[0].cycle = 5;
    fails(&f, &p, SimErrorKind::DirectWriteCycle, &["cycle 5", "add0", "%x"]);
}

#[test]
fn buffer_read_before_arrival() {
    let f = func(SRC);
    let mut p = base(&f);
    p.writes = vec![indirect(&f, "x", Add(0), 1, 5, 0)];
    p.buffer_words = vec![0, 1];
    fails(&f, &p, SimErrorKind::BufferReadBeforeArrival, &["cycle 5", "mul0", "%x", "before it arrives at cycle 7"]);
}

#[test]
fn memory_larger_than_reported() {
    let f = func(SRC);
    let mut p = base(&f);
    p.pe_words = vec![1, 2];
    fails(&f, &p, SimErrorKind::AddressOutOfRange, &["cycle 7", "add0", "%x", "memory larger than reported"]);
    let mut p = base(&f);
    p.pe_words = vec![2, 1];
    fails(&f, &p, SimErrorKind::AddressOutOfRange, &["before cycle 0", "mul0", "%b", "memory larger than reported"]);
    let mut p = base(&f);
    p.writes = vec![indirect(&f, "x", Add(0), 1, 7, 1)];
    p.buffer_words = vec![0, 1];
    fails(&f, &p, SimErrorKind::AddressOutOfRange, &["cycle 7", "mul0", "%x", "buffer", "memory larger than reported"]);
}

#[test]
fn address_written_twice_in_one_cycle() {
    let (f, mut p) = two_products();
    p.issue = issue(&f, &[("x", Mul(0), 0), ("z", Mul(1), 0), ("y", Add(0), 7)]);
    p.arch = arch(1, 2);
    p.loads = vec![load(&f, Mul(0), 0, "a"), load(&f, Mul(0), 1, "b"), load(&f, Mul(1), 0, "b")];
    p.writes = vec![direct(&f, "x", Add(0), 0, 7), direct(&f, "z", Add(0), 0, 7)];
    p.pe_words = vec![2, 2, 1];
    p.buffer_words = vec![0, 0, 0];
    fails(&f, &p, SimErrorKind::AddressReused, &["cycle 7", "add0", "%z", "written twice in one cycle (%x, then %z)"]);
    p.writes[1].addr = 1;
    verify_with(&f, &p, &[0]).unwrap();
}

#[test]
fn malformed_placements() {
    let f = func(SRC);
    let mut p = base(&f);
    p.pe_words.pop();
    fails(&f, &p, SimErrorKind::Malformed, &["1 PE memory and 2 buffer sizes for 2 PEs"]);
    let mut p = base(&f);
    p.arch.lat.add = 0;
    fails(&f, &p, SimErrorKind::Malformed, &["latency"]);
    let g = func("func @f { input %a %x = %a*%a output o = %x }");
    let p = Placement {
        arch: arch(1, 1),
        issue: vec![],
        loads: vec![],
        writes: vec![],
        pe_words: vec![0, 0],
        buffer_words: vec![0, 0],
        spans: Default::default(),
    };
    fails(&g, &p, SimErrorKind::Malformed, &["%x", "atomise"]);
}

#[test]
fn outputs_of_inputs_and_no_ops() {
    let f = func("func @f { phase atomised input %a output o = %a output c = 3.0 }");
    let p = Placement {
        arch: arch(1, 1),
        issue: vec![],
        loads: vec![],
        writes: vec![],
        pe_words: vec![0, 0],
        buffer_words: vec![0, 0],
        spans: Default::default(),
    };
    let o = simulate::<f32>(&f, &p, input).unwrap();
    assert_eq!(o.cycles, 0);
    assert_eq!(o.outputs, vec![("o".to_string(), input("a") as f32), ("c".to_string(), 3.0)]);
    assert!(o.issued_per_cycle_add.is_empty());
}

#[test]
fn error_display_names_cycle_pe_and_value() {
    let e = SimError::new(SimErrorKind::ReadMissing, "not there").at(When::Cycle(7)).on(Add(3)).of("%AF24");
    assert_eq!(e.to_string(), "cycle 7, add3, %AF24: not there");
}

#[test]
fn pass_needs_placements_and_checks_them() {
    let mut m = parse(SRC).unwrap();
    let pass = (INFO.build)(&Params::defaults(&INFO)).unwrap();
    assert!(INFO.props.preserves_timing && INFO.props.needs_before == Some("place"));
    let e = pass.run(&mut m, &mut PassContext::default()).unwrap_err().to_string();
    assert!(e.contains("run `place` first"), "{e}");
    let p = base(&m.functions[0]);
    m.functions[0].placement = Some(p.clone());
    pass.run(&mut m, &mut PassContext::default()).unwrap();
    assert_eq!(verify_placement(&m.functions[0], &[5]).unwrap().cycles, 19);
    let mut bad = p;
    bad.pe_words = vec![1, 2];
    m.functions[0].placement = Some(bad);
    let e = pass.run(&mut m, &mut PassContext::default()).unwrap_err().to_string();
    assert!(e.starts_with("pass `sim`: @f: cycle 7, add0, %x:"), "{e}");
    assert_eq!(INFO.name, "sim");
    assert_eq!(INFO.params[0].name, "seeds");
}

/// A naive placer written here (independent of `place`): 1 ADD + 1 MULTI PE, ops in body
/// order, each as soon as its PE is free and its operands arrived; every operand loaded or
/// written directly into the memory that reads it; addresses reused greedily.
fn naive_placement(f: &Function) -> Placement {
    use std::collections::BTreeMap;
    let a = arch(1, 1);
    let pe_of = |v: Value| if f.op_kind(v) == Some(robovec_ir::OpKind::Mul) { Mul(0) } else { Add(0) };
    let mut issue = vec![None; f.values.len()];
    let mut arrival = vec![0u32; f.values.len()];
    let mut free = [0u32; 2];
    // (pe slot, operand) → (start: -1 for loads, last read)
    let mut words: BTreeMap<(usize, u64, usize), (i64, i64)> = BTreeMap::new();
    for &v in &f.body {
        let Some(kind) = f.op_kind(v) else { continue };
        let pe = pe_of(v);
        let s = pe.slot(1);
        let mut c = free[s];
        f.value(v).def.for_each_value(|u| {
            if f.op_kind(u).is_some() {
                c = c.max(arrival[u.index()]);
            }
        });
        free[s] = c + 1;
        issue[v.index()] = Some(Issue { pe, cycle: c });
        arrival[v.index()] = c + a.lat.of(kind);
        let ops: Vec<Operand> = match &f.value(v).def {
            robovec_ir::Def::Binary(_, x, y) => vec![*x, *y],
            robovec_ir::Def::Call(_, args) => args.clone(),
            _ => unreachable!(),
        };
        for o in ops {
            let (tag, id, start) = match o {
                Operand::Const(k) => (1, k.to_bits() as usize, -1),
                Operand::Value(u) if f.op_kind(u).is_some() => (0, u.index(), arrival[u.index()] as i64),
                Operand::Value(u) => (0, u.index(), -1),
            };
            let e = words.entry((s, tag, id)).or_insert((start, c as i64));
            e.1 = e.1.max(c as i64);
        }
    }
    // Greedy address allocation by start time, per memory.
    let mut by_start: Vec<_> = words.into_iter().collect();
    by_start.sort_by_key(|&((s, _, _), (start, _))| (s, start));
    let (mut loads, mut writes, mut pe_words) = (Vec::new(), Vec::new(), vec![0u32; 2]);
    let mut ends: Vec<Vec<i64>> = vec![Vec::new(); 2];
    for ((s, tag, id), (start, end)) in by_start {
        let addr = match ends[s].iter().position(|&e| e < start) {
            Some(i) => i,
            None => {
                ends[s].push(0);
                ends[s].len() - 1
            }
        };
        ends[s][addr] = end;
        pe_words[s] = ends[s].len() as u32;
        let pe = if s == 0 { Add(0) } else { Mul(0) };
        let operand = if tag == 1 {
            Operand::Const(f64::from_bits(id as u64))
        } else {
            Operand::Value(Value::with_number(id as u32))
        };
        match operand {
            Operand::Value(u) if f.op_kind(u).is_some() => {
                writes.push(Write { value: u, pe, addr: addr as u32, cycle: start as u32, buffer_addr: None })
            }
            _ => loads.push(Load { pe, addr: addr as u32, operand }),
        }
    }
    Placement { arch: a, issue, loads, writes, pe_words, buffer_words: vec![0, 0], spans: Default::default() }
}

const MIXED: &str = "func @f { phase atomised input %q input %m %s = sin %q %c = cos %q \
    %x = mul %s, %m %y = div %x, 3.0 %z = call @sqrt(%m) %w = sub %y, %z %u = call @user_h.2[1](%w, %c, %x, 3.0) \
    %k = add %u, %u %r = mul %k, %c output a = %r output b = %w output c = %q }";

#[test]
fn naive_placements_verify_and_peaks_match_sizes() {
    let mut fs = vec![func(MIXED)];
    fs.extend((1..4).map(|seed| robovec_testkit::dag_gen::generate(300, seed)));
    for f in &fs {
        let p = naive_placement(f);
        let r = verify_with(f, &p, &[0, 1, 2]).unwrap_or_else(|e| panic!("@{}: {e}", f.name));
        assert_eq!(r.max_words_per_memory, p.pe_words, "@{}", f.name);
        assert_eq!(r.writes_direct as usize, p.writes.len());
        let ops = f.body.iter().filter(|&&v| f.op_kind(v).is_some()).count() as u32;
        let issued: u32 = r.issued_per_cycle_add.iter().chain(&r.issued_per_cycle_mul).sum();
        assert_eq!(issued, ops);
    }
}

#[test]
fn mutants_are_rejected_or_still_exact_and_never_panic() {
    let f = robovec_testkit::dag_gen::generate(200, 7);
    let p0 = naive_placement(&f);
    let mut rng = robovec_ir::rng::SplitMix64::new(3);
    let ops: Vec<usize> = (0..p0.issue.len()).filter(|&i| p0.issue[i].is_some()).collect();
    let mut rejected = 0;
    for _ in 0..600 {
        let mut p = p0.clone();
        let pick = |rng: &mut robovec_ir::rng::SplitMix64, n: usize| rng.below(n as u64) as usize;
        match pick(&mut rng, 6) {
            0 => p.issue[ops[pick(&mut rng, ops.len())]].as_mut().unwrap().cycle ^= 1,
            1 => drop(p.loads.remove(pick(&mut rng, p0.loads.len()))),
            2 => drop(p.writes.remove(pick(&mut rng, p0.writes.len()))),
            3 => p.writes[pick(&mut rng, p0.writes.len())].addr = pick(&mut rng, 4) as u32,
            4 => p.writes[pick(&mut rng, p0.writes.len())].cycle += 1,
            _ => p.loads[pick(&mut rng, p0.loads.len())].addr = pick(&mut rng, 4) as u32,
        }
        if verify_with(&f, &p, &[0]).is_err() {
            rejected += 1;
        }
    }
    assert!(rejected > 400, "only {rejected} of 600 mutants rejected");
}

/// Two placed functions `@f` and `@g` (200 ops each, the naive placer's placements).
fn two_placed() -> Module {
    let functions = [("f", 7), ("g", 8)]
        .map(|(name, seed)| {
            let mut f = robovec_testkit::dag_gen::generate(200, seed);
            f.name = name.into();
            f.placement = Some(naive_placement(&f));
            f
        })
        .into();
    Module { functions }
}

/// Ticks `verify_until` takes on `f` for `seeds` with no limit, and on its lowering alone.
fn ticks_of(f: &Function, seeds: &[u64]) -> (u64, u64) {
    let t = Ticker::default();
    verify_until(f, f.placement.as_ref().unwrap(), seeds, &t).expect("verifies");
    let lowering = Ticker::default();
    lower_measured_until(f, f.placement.as_ref().unwrap(), &|| lowering.tick()).expect("lowers");
    (t.ticks(), lowering.ticks())
}

/// Runs `sim<seeds=3>` on `m` with every ticker stopping at tick `budget`: the notes, the
/// stats line and the report objects of `@f` and `@g`.
fn sim_with_budget(m: &mut Module, budget: u64) -> (Vec<String>, String, [Option<serde_json::Value>; 2]) {
    let before = m.to_string();
    let mut cx = PassContext { tick_budget: Some(budget), ..PassContext::default() };
    Sim { seeds: 3 }.run(m, &mut cx).expect("sim is skippable: a stop is not an error");
    assert_eq!(m.to_string(), before, "sim never changes the module");
    assert!(robovec_ir::verifier::verify(m).is_ok());
    let stats = cx.artifacts().next().expect("the stats");
    let text = stats.stats_text(None);
    let reports = ["f", "g"].map(|name| stats.report(name).map(|e| e.value));
    (cx.stopped(), text, reports)
}

#[test]
fn verify_until_stops_in_the_lowering_in_the_first_seed_or_between_seeds() {
    let m = two_placed();
    let f = &m.functions[0];
    let p = f.placement.as_ref().unwrap();
    let (one_seed, lowering) = ticks_of(f, &[0]);
    assert!(lowering > 1000 && one_seed > lowering, "{lowering} {one_seed}");
    for budget in [1, lowering / 2, lowering, lowering + 1, one_seed - 1, one_seed] {
        let e = verify_until(f, p, &[0, 1, 2], &Ticker::new(None, Some(budget))).expect_err("stopped");
        assert_eq!((e.kind, e.message.as_str()), (SimErrorKind::Stopped, "stopped: time limit"), "{budget}");
    }
    // Stopped once the first seed completed: the seeds simulated are reported.
    for (budget, done) in [(one_seed + 1, 1), (2 * one_seed - lowering, 1), (2 * one_seed - lowering + 1, 2)] {
        let r = verify_until(f, p, &[0, 1, 2], &Ticker::new(None, Some(budget))).expect("the first seed completed");
        assert_eq!(r.seeds, (0..done).collect::<Vec<u64>>(), "{budget}");
        assert_eq!(r, verify_with(f, p, &r.seeds).unwrap());
    }
}

#[test]
fn time_limit_in_the_lowering_or_the_first_seed_leaves_the_function_unsimulated() {
    let mut m = two_placed();
    let (whole_f, _) = ticks_of(&m.functions[0], &[0, 1, 2]);
    let (_, lowering_g) = ticks_of(&m.functions[1], &[0]);
    // `sim` checks the clock before each function (1 tick), then lowers and simulates it.
    let budget = 1 + whole_f + 1 + lowering_g / 2;
    let (stopped, text, [f, g]) = sim_with_budget(&mut m, budget);
    assert_eq!(
        stopped,
        [format!(
            "sim stopped in @g before its first seed completed (lowering; @g not simulated): tick budget of \
             {budget} steps reached"
        )]
    );
    assert_eq!(text, "sim: simulated 1 placement bit-exact in f32 and f64 (3 seeds)\n");
    let f = f.expect("@f simulated");
    assert_eq!((f["placements"].as_u64(), f["seeds"].as_u64()), (Some(1), Some(3)));
    assert_eq!(f["functions"][0]["function"], "f");
    assert_eq!(g, None, "@g was not simulated: no `sim` object in its report");
    // In `@f`'s first seed (its lowering is done): nothing simulated.
    let (_, lowering_f) = ticks_of(&m.functions[0], &[0]);
    let budget = 1 + lowering_f + 2;
    let (stopped, text, reports) = sim_with_budget(&mut m, budget);
    assert_eq!(
        stopped,
        [format!(
            "sim stopped in @f before its first seed completed (seed 0; @f not simulated): tick budget of \
             {budget} steps reached"
        )]
    );
    assert_eq!(text, "sim: simulated no placement\n");
    assert_eq!(reports, [None, None]);
    // Without a limit both are simulated.
    let (stopped, text, [f, g]) = sim_with_budget(&mut m, u64::MAX);
    assert!(stopped.is_empty(), "{stopped:?}");
    assert_eq!(text, "sim: simulated 2 placements bit-exact in f32 and f64 (3 seeds)\n");
    assert!(f.is_some() && g.is_some());
}

#[test]
fn time_limit_after_the_first_seed_keeps_the_seeds_simulated() {
    let mut m = two_placed();
    let (one_seed, _) = ticks_of(&m.functions[0], &[0]);
    let budget = 1 + one_seed + 1;
    let (stopped, text, [f, g]) = sim_with_budget(&mut m, budget);
    let why = format!("tick budget of {budget} steps reached");
    // One note: the stop ends the loop, so @g does not start.
    assert_eq!(stopped, [format!("sim stopped after 1 of 3 seeds of @f: {why}")]);
    assert_eq!(text, "sim: simulated 1 placement bit-exact in f32 and f64 (1 seed)\n");
    assert_eq!(f.expect("@f simulated")["seeds"].as_u64(), Some(1));
    assert_eq!(g, None);
}
