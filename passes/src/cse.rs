//! `cse`: common-subexpression elimination by local value numbering, the transform of
//! [`robovec_ir::transform::cse`] (whose module doc states why it is exact and its cost) run on
//! every function within `-time-limit`.

use robovec_ir::Module;

pub use robovec_ir::transform::cse::{cse_drops_until, cse_function, cse_within};

use crate::{each_function, Before, Params, Pass, PassContext, PassError, PassInfo, Step};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "cse",
    doc: "common-subexpression elimination: an op equal to an earlier one (same operator, same operands; + and * commutative) is dropped, its users read the earlier one (bit-exact)",
    params: &[],
    build: |_: &Params| Ok(Box::new(Cse)),
    props: crate::Props { at_time_limit: crate::AtTimeLimit::Skip, exact_in_reals: true, ..crate::Props::DEFAULT },
};

/// The `cse` pass.
#[derive(Debug)]
pub struct Cse;

impl Pass for Cse {
    fn name(&self) -> &'static str {
        "cse"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let skipped = |f: &robovec_ir::Function, _| Some(format!("before @{}", f.name));
        each_function(m, cx, "cse", Before::Ticked, skipped, |f, _, ticker| {
            let (seen, n) = (ticker.ticks(), f.body.len() as u64);
            cse_within(f, ticker);
            if ticker.stopped() {
                let done = ticker.ticks().saturating_sub(seen + 1);
                let what = format!("in @{} after {done} of {n} values (merges found kept)", f.name);
                return Step::Stopped { what, kept: None };
            }
            Step::Done(())
        });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Ticker;
    use robovec_ir::text::parse;
    use robovec_ir::{BinOp, Def, Operand};

    fn run(src: &str) -> Module {
        let mut m = parse(src).unwrap();
        Cse.run(&mut m, &mut PassContext::default()).unwrap();
        for f in &m.functions {
            assert!(
                robovec_ir::verifier::verify_function(f).is_empty(),
                "{:?}",
                robovec_ir::verifier::verify_function(f)
            );
        }
        m
    }

    #[test]
    fn commuted_sums_and_products_merge_and_their_users_follow() {
        // x*y and y*x are one product; then p1+z and z+p2 become one sum; q = s1 - z stays.
        let m = run("func @f { phase atomised input %x input %y input %z \
             %p1 = mul %x, %y  %p2 = mul %y, %x  %s1 = add %p1, %z  %s2 = add %z, %p2 \
             %q = sub %s2, %z  output a = %s1  output b = %s2  output c = %q }");
        let f = &m.functions[0];
        assert_eq!(f.body.len(), 3, "p2 and s2 merge into p1 and s1");
        let s1 = f.lookup("s1").unwrap();
        assert_eq!(f.outputs[1].value, Operand::Value(s1), "output b reads s1");
        match &f.value(f.lookup("q").unwrap()).def {
            Def::Binary(BinOp::Sub, Operand::Value(a), _) => assert_eq!(*a, s1),
            d => panic!("{d:?}"),
        }
    }

    #[test]
    fn subtraction_order_calls_and_constant_bits_are_kept_apart() {
        let m = run("func @f { phase atomised input %x input %y \
             %d1 = sub %x, %y  %d2 = sub %y, %x  %z1 = mul %x, 0.0  %z2 = mul %x, -0.0 \
             %c1 = call @sqrt(%x)  %c2 = call @sqrt(%x) \
             output a = %d1  output b = %d2  output c = %z1  output d = %z2  output e = %c1  output f = %c2 }");
        assert_eq!(m.functions[0].body.len(), 6, "nothing merges");
    }

    /// `cse_drops_until` counts what `cse_function` drops (merged trig variables are no op) and
    /// stops at a tick budget.
    #[test]
    fn the_drop_count_is_what_cse_drops() {
        let src = "func @f { phase atomised input %x input %y input %z              %c1 = cos %x  %c2 = cos %x  %p1 = mul %c1, %y  %p2 = mul %y, %c2  %s1 = add %p1, %z              %s2 = add %z, %p2  %d = sub %s1, %s2  %e = sub %s2, %s1              output a = %d  output b = %e }";
        let f = &parse(src).unwrap().functions[0];
        let drops = cse_drops_until(f, &Ticker::default()).expect("no limit");
        let mut g = f.clone();
        let dropped = cse_function(&mut g);
        // s2 merged into s1, `e` is `d`.
        assert_eq!(dropped, 4, "c2, p2, s2, e");
        assert_eq!(drops, 3, "p2, s2 and e are ops; c2 is a trig variable");
        assert_eq!(f.op_counts().total - drops, g.op_counts().total);
        assert_eq!(cse_drops_until(f, &Ticker::new(None, Some(4))), None, "the 4th of 8 values stops it");
    }
}
