//! Where a sign can go for free: the structural analysis behind carrying signs into consumers
//! (seed §2.4.1 "report the minus sign to the children"; GCC `tree-ssa-reassoc` step 5,
//! re-propagating negates; `NOTES-anchors.md` §4.2).
//!
//! `absorbs[v]` is true when the negation of `v` alone can be handed to every consumer without
//! an extra op: each use of `v` is
//! - a term of an additive cluster that keeps a term with a `+` coefficient (or a constant,
//!   whose sign is free) once `v`'s coefficient flips, or whose root absorbs in turn;
//! - a factor of a product with a constant factor (the constant takes the sign), or whose root
//!   absorbs in turn;
//! - an operand of a `div` whose other operand is a constant, or whose result absorbs in turn;
//!
//! and `v` is neither an output nor a call argument. Negations of other values are ignored
//! (one sign at a time), so a rewrite that trusts `absorbs` still checks its result. A value
//! without uses absorbs trivially. Cost: O(values + operands), one backward sweep.

use robovec_ir::{BinOp, Def, Function, Operand};

use super::cluster::{Class, Clusters};

/// `absorbs[v]` for every value of `f` (see the module doc).
pub fn absorbs(f: &Function, cl: &Clusters) -> Vec<bool> {
    let mut ok: Vec<bool> = (0..f.values.len()).map(|i| !cl.is_output[i] && !cl.call_arg[i]).collect();
    for &v in f.body.iter().rev() {
        match &f.value(v).def {
            Def::Binary(BinOp::Div, a, b) => {
                let here = ok[v.index()];
                for (x, other) in [(a, b), (b, a)] {
                    if let Operand::Value(x) = x {
                        if !(here || matches!(other, Operand::Const(_))) {
                            ok[x.index()] = false;
                        }
                    }
                }
            }
            Def::Binary(..) if cl.is_root(v) => {
                let t = cl.tree(f, v);
                let here = ok[v.index()];
                let free = t.leaves.iter().any(|l| matches!(l.operand, Operand::Const(c) if c != 0.0));
                let positive =
                    t.leaves.iter().filter(|l| !l.negative && matches!(l.operand, Operand::Value(_))).count();
                for l in &t.leaves {
                    let Operand::Value(x) = l.operand else { continue };
                    let absorbed = here
                        || free
                        || match t.class {
                            // Flipping a `−` term makes it `+`; flipping a `+` term needs another.
                            Class::Additive => l.negative || positive > 1,
                            _ => false,
                        };
                    if !absorbed {
                        ok[x.index()] = false;
                    }
                }
            }
            _ => {}
        }
    }
    ok
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text::parse;

    #[test]
    fn signs_stop_at_outputs_and_calls_and_pass_through_products() {
        let m = parse(
            "func @f { phase atomised input %a input %b input %c
              %n1 = sub 0.0, %a
              %p1 = mul %n1, %b
              %s1 = add %p1, %c
              %n2 = sub 0.0, %b
              %p2 = mul %n2, %c
              %n3 = sub 0.0, %c
              %r = call @sqrt(%n3)
              %n4 = sub 0.0, %a
              %p4 = mul %n4, 2.0
              %q = sub 0.0, %s1
              output o1 = %s1 output o2 = %p2 output o3 = %r output o4 = %p4 output o5 = %q }",
        )
        .unwrap();
        let f = &m.functions[0];
        let cl = Clusters::new(f);
        let ab = absorbs(f, &cl);
        let at = |n: &str| ab[f.lookup(n).unwrap().index()];
        assert!(at("n1"), "n1·b is a term of s1 = p1 + c, which keeps c positive");
        assert!(!at("n2"), "n2·c is an output");
        assert!(!at("n3"), "a call argument");
        assert!(at("n4"), "the constant 2.0 takes the sign");
        assert!(!at("s1"), "an output");
    }
}
