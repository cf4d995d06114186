use super::*;
use crate::Severity;
use robovec_ir::text::parse;

/// Two long-lived chains in derivation order: `x1..x4` are all computed first, then consumed
/// one by one, so four results are live at once; interleaving needs two.
const SRC: &str = "func @f { phase atomised input %a input %b input %q
  %S = sin %q
  %x1 = mul %a, %b %x2 = add %a, %b %x3 = sub %a, %b %x4 = div %a, %b
  %y1 = mul %x1, %S %y2 = mul %x2, %a %y3 = mul %x3, %b %y4 = mul %x4, %S
  %z1 = add %y1, %y2 %z2 = add %y3, %y4 %z = mul %z1, %z2
  %dead = mul %a, %a
  output c[1] = %z output c[2] = %y1 }";

fn names(f: &Function, order: &[Value]) -> Vec<String> {
    order.iter().map(|&v| f.name_of(v).to_string()).collect()
}

fn is_topological(f: &Function, order: &[Value]) -> bool {
    let mut seen = vec![false; f.values.len()];
    f.inputs.iter().for_each(|v| seen[v.index()] = true);
    let mut ok = order.len() == f.body.len();
    for &v in order {
        f.value(v).def.for_each_value(|a| ok &= seen[a.index()]);
        ok &= !seen[v.index()];
        seen[v.index()] = true;
    }
    ok
}

#[test]
fn labels_follow_sethi_ullman() {
    let f = &parse(SRC).unwrap().functions[0];
    let need = sethi_ullman_labels(f);
    let l = |n: &str| need[f.lookup(n).unwrap().index()];
    assert_eq!((l("x1"), l("y1"), l("z1"), l("z")), (1, 1, 2, 3));
    assert_eq!(l("S"), 0, "a trig initial variable is a memory operand");
}

#[test]
fn every_order_is_a_permutation_in_topological_order_and_cuts_pressure() {
    let f = &parse(SRC).unwrap().functions[0];
    let before = pressure::pressure(f, 2);
    assert_eq!(before.max_live, 5, "x1..x4 are live together in the source order, and y1 that reads x1");
    for o in [Order::Dfs, Order::Greedy, Order::Best] {
        let (order, _) = schedule(f, o, 2);
        assert!(is_topological(f, &order), "{o:?}: {:?}", names(f, &order));
        let after = pressure_of_order(f, &order, 2);
        assert!(after.max_live <= 4 && after.excess < before.excess, "{o:?}: {after:?} vs {before:?}");
        assert_eq!(names(f, &order)[0], "S", "trig initial variables first");
        assert_eq!(names(f, &order).last().unwrap(), "dead", "values no output needs go last");
    }
    // dfs: c[1]'s tree first, the operand with the larger need (z1 = 2 ≥ z2 = 2: operand order) first.
    let (order, _) = schedule(f, Order::Dfs, 2);
    assert_eq!(names(f, &order), ["S", "x1", "y1", "x2", "y2", "z1", "x3", "y3", "x4", "y4", "z2", "z", "dead"]);
}

#[test]
fn the_pass_keeps_every_value_bit_for_bit_and_never_raises_the_excess() {
    let mut m = parse(SRC).unwrap();
    let original = m.clone();
    let p = ScheduleCpu { order: Order::Best, registers: 2 };
    let mut cx = PassContext::default();
    p.run(&mut m, &mut cx).unwrap();
    let (f, g) = (&original.functions[0], &m.functions[0]);
    assert!(robovec_ir::verifier::verify_function(g).is_empty());
    assert!(pressure::pressure(g, 2).excess < pressure::pressure(f, 2).excess);
    for seed in 0..4 {
        let input = |n: &str| robovec_ir::interp::pseudo_random_input(n, seed);
        let a = robovec_ir::interp::eval::<f64>(f, input);
        let b = robovec_ir::interp::eval::<f64>(g, input);
        let bits = |v: &[(String, f64)]| v.iter().map(|(n, x)| (n.clone(), x.to_bits())).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b));
    }
    let note = &cx.diagnostics[0];
    assert_eq!(
        (note.severity, note.pass.as_str(), &note.functions[..]),
        (Severity::Remark, "schedule-cpu", &["f".to_string()][..])
    );
    assert!(note.message.starts_with("schedule-cpu: @f max-live 5 -> "), "{}", note.message);
}
