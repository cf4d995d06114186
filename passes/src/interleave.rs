//! `interleave<states=K>`: one function that evaluates K independent states (issue 49 item 3,
//! throughput: a placement of the result issues the K states' ops side by side, so the PE array
//! delivers K states per evaluation and fills the slots a single state's critical path leaves
//! idle).
//!
//! Phase: atomised → atomised, any front end's function. State 0 keeps every name; state
//! `k ≥ 1` is a copy of every input, value and output named with the state suffix `#k`
//! ([`robovec_ir::state_name`]: `q[4]#2`, `AF24.1#2`, output `Qq[1]#2`). **Every input is per
//! state**, model constants (`dpt`, `m`, `g`, …) included: right for any function (a state may
//! be another robot of the same structure), at the price of K copies of each constant in the PE
//! memories. A trig input (`%S4 = sin %q[4]`) is copied with its argument renamed
//! (`%S4#1 = sin %q[4]#1`). Formats ([`robovec_ir::Function::format`]) are copied to the
//! copies; timing attributes are cleared and any placement dropped (as other rewrites do). The
//! body is state 0's definitions, then state 1's, …; the outputs likewise (state k's follow
//! state k − 1's, each in the original order). `states` becomes the old `states` × K.
//!
//! On a function that already has S > 1 states (its names carry suffixes `#s`, s < S), copy `c`
//! of a value of state `s` is state `c·S + s` (`#(c·S + s)`): names stay `base#k` with one
//! suffix, and interleaving by K then by L is interleaving by K·L up to the order of the
//! copies. A copy's name that is already taken (a hand-written `.rvir` whose names carry
//! suffixes beyond its `states`) is an error naming it.
//!
//! Contract: bit-exact (state 0's outputs are the original's; state k's are the original
//! function of state k's inputs); K = 1 is the identity. Cost: O(K · (values + operands)).

use robovec_ir::{split_state, state_name, Def, Function, Module, Operand, Phase, Value};

use crate::params::ParamKind;
use crate::{try_each_function, AtTimeLimit, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step};

/// The largest `states=` accepted (the ops grow K-fold).
pub const MAX_STATES: u32 = 1024;

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "interleave",
    doc: "K independent states in one function: state k's inputs, values and outputs copied as `name#k`",
    params: &[ParamInfo {
        name: "states",
        kind: ParamKind::U32 { default: 2, min: 1, max: MAX_STATES },
        doc: "K: states one evaluation computes (1 = no change)",
    }],
    build: |p: &Params| Ok(Box::new(Interleave { states: p.u32("states")? })),
    // Required at the time limit: it changes what the function computes and outputs. Copies
    // compute the same ops on their own inputs, formats included.
    props: crate::Props {
        requires: Some(Phase::Atomised),
        bit_exact: true,
        formats: true,
        exact_in_reals: true,
        ..crate::Props::DEFAULT
    },
};

/// The `interleave` pass.
#[derive(Debug)]
pub struct Interleave {
    /// K: the copies made (state 0 included), 1 ..= [`MAX_STATES`].
    pub states: u32,
}

impl Pass for Interleave {
    fn name(&self) -> &'static str {
        "interleave"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let k = self.states;
        if !(1..=MAX_STATES).contains(&k) {
            return Err(PassError::BadParameter {
                pass: "interleave".into(),
                message: format!("states={k}: expected 1 ..= {MAX_STATES}"),
            });
        }
        if k == 1 {
            return Ok(());
        }
        // One linear sweep per function: the clock is read between functions.
        let parts = try_each_function(
            m,
            cx,
            "interleave",
            AtTimeLimit::Required,
            Before::Clock,
            |_, _| None,
            |f, _, _| {
                let g = interleave_function(f, k)
                    .map_err(|message| PassError::Failed { pass: "interleave".into(), message })?;
                let line = format!(
                    "@{}: states {} -> {}, ops {} -> {}",
                    f.name,
                    f.states,
                    g.states,
                    f.op_counts().total,
                    g.op_counts().total
                );
                *f = g;
                Ok(Step::Done(line))
            },
        )?;
        cx.remark("interleave", m, format!("interleave<states={k}>: {}", parts.join("; ")));
        Ok(())
    }
}

/// `f` (atomised, verified) evaluating `k` times its states (see the module doc). `k = 1`
/// returns a copy of `f` without timing or placement.
///
/// # Errors
/// A copy's name is already taken (`f`'s names carry state suffixes beyond its `states`), or
/// `f.states · k` overflows `u32`: the message names it.
pub fn interleave_function(f: &Function, k: u32) -> Result<Function, String> {
    let old = f.states.max(1);
    let states = old.checked_mul(k).ok_or_else(|| format!("@{}: {} states × {k} overflows", f.name, f.states))?;
    let mut out = Function::new(f.name.clone(), f.phase);
    out.equations = f.equations;
    out.states = states;
    out.span = f.span;
    let copies = k as usize;
    out.reserve(f.values.len() * copies, f.body.len() * copies);
    // The name of `name`'s copy `c`: state `c·S + s` of its base.
    let renamed = |name: &str, c: u32| {
        let (base, s) = split_state(name);
        state_name(base, c * old + s)
    };
    let taken = |name: &str| format!("@{}: `{name}`, the name of a state copy, is taken", f.name);
    let mut map: Vec<Value> = vec![Value::with_number(0); f.values.len()];
    for c in 0..k {
        for &v in &f.inputs {
            let d = f.value(v);
            let name = renamed(&d.name, c);
            let nv = out.add_input(name.clone(), d.span).map_err(|_| taken(&name))?;
            out.set_format(nv, f.format(v));
            map[v.index()] = nv;
        }
        for &v in &f.body {
            let d = f.value(v);
            let mut def: Def = d.def.clone();
            def.map_values(&|a: Value| map[a.index()]);
            let name = renamed(&d.name, c);
            let nv = out.define(name.clone(), def, d.span).map_err(|_| taken(&name))?;
            out.set_format(nv, f.format(v));
            map[v.index()] = nv;
        }
        for o in &f.outputs {
            let value = match o.value {
                Operand::Value(v) => Operand::Value(map[v.index()]),
                c @ Operand::Const(_) => c,
            };
            let name = renamed(&o.name, c);
            if c > 0 && out.output_position(&name).is_some() {
                return Err(format!("@{}: output `{name}`, the name of a state copy, is taken", f.name));
            }
            out.set_output(name, value, o.span);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::interp::eval;
    use robovec_ir::text::parse;

    const SRC: &str = "func @f {
  phase atomised
  equations 2
  input %q[1] : f32
  input %g[3]
  %S1 = sin %q[1]
  %x = mul %g[3], %S1 : f32
  %y = sub 0.0, %x {asap=2, alap=2, asap_cycle=19, alap_cycle=19, mobility=0}
  output Qq[1] = %y
  output c[1] = 2.5
}
";

    fn one(k: u32) -> Function {
        let m = parse(SRC).unwrap();
        interleave_function(&m.functions[0], k).unwrap()
    }

    #[test]
    fn copies_are_named_by_state_with_formats_and_without_timing() {
        let g = one(3);
        assert!(robovec_ir::verifier::verify_function(&g).is_empty());
        assert_eq!(g.states, 3);
        assert_eq!(g.equations, Some(2));
        let names: Vec<&str> = g.inputs.iter().map(|&v| g.name_of(v)).collect();
        assert_eq!(names, ["q[1]", "g[3]", "q[1]#1", "g[3]#1", "q[1]#2", "g[3]#2"]);
        let outs: Vec<&str> = g.outputs.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(outs, ["Qq[1]", "c[1]", "Qq[1]#1", "c[1]#1", "Qq[1]#2", "c[1]#2"]);
        let s = g.lookup("S1#2").unwrap();
        assert_eq!(g.value(s).def, Def::Trig(robovec_ir::TrigFn::Sin, g.lookup("q[1]#2").unwrap()));
        assert_eq!(g.format(g.lookup("x#1").unwrap()).to_string(), "f32");
        assert_eq!(g.format(g.lookup("q[1]#2").unwrap()).to_string(), "f32");
        assert!(g.body.iter().all(|&v| g.timing(v).is_none()));
        assert_eq!(g.op_counts().total, 3 * 2);
        // The text form says `states 3` and reads back to the same function.
        let text = Module { functions: vec![g.clone()] }.to_string();
        assert!(text.contains("\n  states 3\n"), "{text}");
        assert_eq!(parse(&text).unwrap().to_string(), text);
    }

    #[test]
    fn each_state_computes_the_original_of_its_inputs() {
        let f = parse(SRC).unwrap().functions.remove(0);
        let g = one(3);
        let input = |n: &str| {
            let (base, s) = split_state(n);
            (if base == "q[1]" { 0.3 } else { -9.81 }) + s as f64
        };
        let got = eval::<f64>(&g, input);
        for s in 0..3u32 {
            let want = eval::<f64>(&f, |n| input(&state_name(n, s)));
            for (n, y) in want {
                let (_, z) = got.iter().find(|(m, _)| *m == state_name(&n, s)).unwrap();
                assert_eq!(y.to_bits(), z.to_bits(), "{n} of state {s}");
            }
        }
    }

    #[test]
    fn one_state_is_the_identity_and_interleaving_composes() {
        let f = parse(SRC).unwrap().functions.remove(0);
        let mut plain = f.clone();
        plain.clear_timing();
        assert_eq!(interleave_function(&f, 1).unwrap().to_string(), plain.to_string());
        let g = interleave_function(&one(2), 3).unwrap();
        assert_eq!(g.states, 6);
        let mut names: Vec<&str> = g.outputs.iter().map(|o| o.name.as_str()).filter(|n| n.starts_with("Qq")).collect();
        names.sort_unstable();
        assert_eq!(names, ["Qq[1]", "Qq[1]#1", "Qq[1]#2", "Qq[1]#3", "Qq[1]#4", "Qq[1]#5"]);
        assert!(robovec_ir::verifier::verify_function(&g).is_empty());
    }

    #[test]
    fn a_taken_copy_name_is_an_error() {
        let m = parse("func @f { phase atomised input %a input %a#1 %x = add %a, %a#1 output y = %x }").unwrap();
        let e = interleave_function(&m.functions[0], 2).unwrap_err();
        assert!(e.contains("`a#1`, the name of a state copy, is taken"), "{e}");
    }
}
