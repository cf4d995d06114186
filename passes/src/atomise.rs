//! `atomise`: equations → binary operations (seed §2.1, eq. 2.2; SPEC §3), the phase
//! transition parsed → atomised of [`robovec_ir::transform::atomise`] (whose module doc states
//! the rules, the contract and the cost) run on every function within `-time-limit`.

use std::borrow::Cow;

use robovec_ir::{Function, Module, Phase};

pub use robovec_ir::transform::atomise::{atomise_function, atomise_owned, atomise_until, atomise_within};

use crate::{try_each_function, AtTimeLimit, Before, Params, Pass, PassContext, PassError, PassInfo, Step};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "atomise",
    doc: "split equations into binary operations (SPEC §3: left-to-right cascades, 0 - t, literal folding)",
    params: &[],
    build: |_: &Params| Ok(Box::new(Atomise)),
    props: crate::Props { bit_exact: true, ..crate::Props::DEFAULT },
};

/// The `atomise` pass.
#[derive(Debug)]
pub struct Atomise;

impl Pass for Atomise {
    fn name(&self) -> &'static str {
        "atomise"
    }

    /// `-time-limit`: required (every later pass needs the atomised phase); it ticks once per
    /// equation and a stop ends the run ([`PassError::TimeLimit`]).
    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        try_each_function(
            m,
            cx,
            "atomise",
            AtTimeLimit::Required,
            Before::Ticked,
            |_, _| None,
            |f, _, ticker| {
                let parsed = std::mem::replace(f, Function::new(String::new(), Phase::Atomised));
                let (name, n, seen) = (parsed.name.clone(), parsed.body.len(), ticker.ticks());
                Ok(match atomise_within(Cow::Owned(parsed), ticker) {
                    Some(atomised) => {
                        *f = atomised;
                        Step::Done(())
                    }
                    None => {
                        let done = ticker.ticks().saturating_sub(seen + 1);
                        Step::Stopped { what: format!("in @{name} after {done} of {n} equations"), kept: None }
                    }
                })
            },
        )
        .map(drop)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text::parse;
    use robovec_ir::Operand;

    fn atomised(src: &str) -> Function {
        let m = parse(src).unwrap_or_else(|e| panic!("{e:?}"));
        atomise_function(&m.functions[0])
    }

    fn line_of(f: &Function, name: &str) -> String {
        let text = f.to_string();
        text.lines()
            .find(|l| l.trim_start().starts_with(&format!("%{name} =")))
            .unwrap_or_else(|| panic!("no %{name} in\n{text}"))
            .trim()
            .to_string()
    }

    #[test]
    fn unary_minus_becomes_zero_minus_after_the_term() {
        let f = atomised("func @f { input %g[3] input %S4 %AF24 = -%g[3]*%S4 output o = %AF24 }");
        assert_eq!(line_of(&f, "AF24.1"), "%AF24.1 = mul %g[3], %S4");
        assert_eq!(line_of(&f, "AF24"), "%AF24 = sub 0.0, %AF24.1");
        assert_eq!(f.op_counts().total, 2);
    }

    #[test]
    fn minus_on_a_literal_product_negates_the_literal() {
        let f = atomised("func @f { input %x input %y %a = -2.0*%x*%y %b = -(1.0) %c = %x - %b output a = %a output b = %b output c = %c }");
        assert_eq!(line_of(&f, "a.1"), "%a.1 = mul -2.0, %x");
        assert_eq!(line_of(&f, "a"), "%a = mul %a.1, %y");
        assert!(f.lookup("b").is_none(), "a folded constant is no op");
        assert_eq!(line_of(&f, "c"), "%c = sub %x, -1.0");
        assert_eq!(f.outputs[1].value, Operand::Const(-1.0));
        assert_eq!(f.op_counts().total, 3);
    }

    #[test]
    fn cascades_are_left_to_right_and_copies_vanish() {
        let f = atomised("func @f { input %a input %b input %c %s = %a + %b - %c %p = %a*%b*%c %k = %s output M[1][1] = %k output M[1][2] = %p }");
        assert_eq!(line_of(&f, "s.1"), "%s.1 = add %a, %b");
        assert_eq!(line_of(&f, "s"), "%s = sub %s.1, %c");
        assert_eq!(line_of(&f, "p.1"), "%p.1 = mul %a, %b");
        assert_eq!(line_of(&f, "p"), "%p = mul %p.1, %c");
        assert!(f.lookup("k").is_none());
        assert_eq!(f.to_string().lines().find(|l| l.contains("M[1][1]")).unwrap().trim(), "output M[1][1] = %s");
    }

    #[test]
    fn op_counts_match_the_independent_count_and_atomise_is_idempotent() {
        let src = "func @f { input %a input %b %x = -(%a - 3.0*%b)*(-%a/%b) + @sqrt(%a*%a) - (-4.0)*%a*(%b - %a) output o = %x }";
        let m = parse(src).unwrap();
        let expected = m.functions[0].op_counts();
        let f = atomise_function(&m.functions[0]);
        assert_eq!(f.op_counts(), expected);
        assert!(robovec_ir::verifier::verify_function(&f).is_empty());
        assert_eq!(atomise_function(&f).to_string(), f.to_string());
        let before = robovec_ir::interp::eval::<f64>(&m.functions[0], |n| if n == "a" { 1.25 } else { 0.75 });
        let after = robovec_ir::interp::eval::<f64>(&f, |n| if n == "a" { 1.25 } else { 0.75 });
        assert_eq!(before[0].1.to_bits(), after[0].1.to_bits());
    }

    #[test]
    fn the_consuming_form_gives_the_same_function() {
        let src =
            "func @f { input %a input %b %C1 = cos %a %x = -(%a - 3.0*%b)*(-%a/%b) + @sqrt(%a*%a) %y = %x*%C1 - %x \
                   %z = %y output o = %x output p = %z output q = 2.0 }";
        let m = parse(src).unwrap();
        let f = &m.functions[0];
        let owned = atomise_owned(f.clone());
        let borrowed = atomise_function(f);
        assert_eq!(owned, borrowed);
        assert_eq!(owned.to_string(), borrowed.to_string());
        assert_eq!(owned.lookup("x.1").map(|v| owned.name_of(v).to_string()), Some("x.1".to_string()));
        assert_eq!(owned.outputs.iter().map(|o| o.name.as_str()).collect::<Vec<_>>(), ["o", "p", "q"]);
    }
}
