//! The built-in rewrites of `eqsat`, named in kebab-case like egg's `tests/math.rs`, and the
//! named conditions that rules may carry (shared with `rules=FILE`, [`super::rules_file`]).
//!
//! Every rule holds over the reals; over floats each changes rounding (SPEC §6) except the
//! commutativity, sign and `neg` rules, which are exact (up to the sign of an exact zero).
//! `eqsat/README.md` states the rule policy.

use egg::{rewrite as rw, Condition, ConditionalApplier, EGraph, Id, Pattern, Subst, Var};

use super::lang::{Arith, ConstantFold, Rewrite};

/// The built-in rules: associativity and commutativity of `+` and `*`, sign rules, the
/// constant identities `x+0`, `x-0`, `x*1`, `x*0`, `x*-1`, and — when `distribute` — the
/// distributivity/factoring rules (which may add or remove multiplies).
pub fn rules(distribute: bool) -> Vec<Rewrite> {
    let mut r: Vec<Rewrite> = vec![
        // Associativity and commutativity (an n-leaf cluster saturates at 2^n − 1 e-classes,
        // NOTES-anchors §3.3: windows keep n small).
        rw!("comm-add"; "(+ ?a ?b)" => "(+ ?b ?a)"),
        rw!("comm-mul"; "(* ?a ?b)" => "(* ?b ?a)"),
        rw!("assoc-add"; "(+ ?a (+ ?b ?c))" => "(+ (+ ?a ?b) ?c)"),
        rw!("assoc-add-rev"; "(+ (+ ?a ?b) ?c)" => "(+ ?a (+ ?b ?c))"),
        rw!("assoc-mul"; "(* ?a (* ?b ?c))" => "(* (* ?a ?b) ?c)"),
        rw!("assoc-mul-rev"; "(* (* ?a ?b) ?c)" => "(* ?a (* ?b ?c))"),
        // Signs: subtraction is addition of a negation (GCC reassoc step 1 and 5).
        rw!("sub-to-add-neg"; "(- ?a ?b)" => "(+ ?a (neg ?b))"),
        rw!("add-neg-to-sub"; "(+ ?a (neg ?b))" => "(- ?a ?b)"),
        rw!("zero-sub"; "(- 0 ?a)" => "(neg ?a)"),
        rw!("neg-neg"; "(neg (neg ?a))" => "?a"),
        rw!("neg-mul"; "(* (neg ?a) ?b)" => "(neg (* ?a ?b))"),
        rw!("neg-mul-rev"; "(neg (* ?a ?b))" => "(* (neg ?a) ?b)"),
        rw!("neg-add"; "(neg (+ ?a ?b))" => "(+ (neg ?a) (neg ?b))"),
        rw!("neg-add-rev"; "(+ (neg ?a) (neg ?b))" => "(neg (+ ?a ?b))"),
        rw!("neg-sub"; "(neg (- ?a ?b))" => "(- ?b ?a)"),
        // Identities with constants (the analysis folds constant sub-terms).
        rw!("add-zero"; "(+ ?a 0)" => "?a"),
        rw!("sub-zero"; "(- ?a 0)" => "?a"),
        rw!("mul-one"; "(* ?a 1)" => "?a"),
        rw!("mul-zero"; "(* ?a 0)" => "0"),
        rw!("mul-minus-one"; "(* ?a -1)" => "(neg ?a)"),
    ];
    if distribute {
        r.extend([
            rw!("distribute"; "(* ?a (+ ?b ?c))" => "(+ (* ?a ?b) (* ?a ?c))"),
            rw!("distribute-sub"; "(* ?a (- ?b ?c))" => "(- (* ?a ?b) (* ?a ?c))"),
            rw!("factor"; "(+ (* ?a ?b) (* ?a ?c))" => "(* ?a (+ ?b ?c))"),
            rw!("factor-sub"; "(- (* ?a ?b) (* ?a ?c))" => "(* ?a (- ?b ?c))"),
        ]);
    }
    r
}

/// A named condition on one pattern variable (the `if` part of a rule, [`super::rules_file`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CondKind {
    /// `const ?x`: the e-class of `?x` has a known constant value.
    Const,
    /// `not-const ?x`: it has none.
    NotConst,
    /// `nonzero ?x`: it is not the constant 0 (a class without a known value counts as nonzero,
    /// as egg's `is_not_zero` in `tests/math.rs`).
    Nonzero,
    /// `is-one ?x`: it is the constant 1.
    IsOne,
}

impl CondKind {
    /// Every condition with its keyword, for parsing and for "expected …" messages.
    pub const ALL: [(&'static str, CondKind); 4] = [
        ("const", CondKind::Const),
        ("not-const", CondKind::NotConst),
        ("nonzero", CondKind::Nonzero),
        ("is-one", CondKind::IsOne),
    ];

    fn holds(self, c: Option<f64>) -> bool {
        match self {
            CondKind::Const => c.is_some(),
            CondKind::NotConst => c.is_none(),
            CondKind::Nonzero => c != Some(0.0),
            CondKind::IsOne => c == Some(1.0),
        }
    }
}

/// All of a rule's conditions, each on one variable; holds when every one holds.
#[derive(Clone, Debug, Default)]
pub struct Conds(pub Vec<(CondKind, Var)>);

impl Condition<Arith, ConstantFold> for Conds {
    fn check(&self, egraph: &mut EGraph<Arith, ConstantFold>, _eclass: Id, subst: &Subst) -> bool {
        self.0.iter().all(|&(k, v)| k.holds(egraph[subst[v]].data.map(|c| c.get())))
    }

    fn vars(&self) -> Vec<Var> {
        self.0.iter().map(|&(_, v)| v).collect()
    }
}

/// Builds a rule `lhs => rhs [if conds]` from pattern texts.
///
/// # Errors
/// egg's message when a pattern does not parse or the right side uses a variable the left side
/// does not bind.
pub fn make_rule(name: &str, lhs: &str, rhs: &str, conds: Conds) -> Result<Rewrite, String> {
    let l: Pattern<Arith> = lhs.parse().map_err(|e| format!("{e}"))?;
    let r: Pattern<Arith> = rhs.parse().map_err(|e| format!("{e}"))?;
    if conds.0.is_empty() {
        Rewrite::new(name, l, r)
    } else {
        Rewrite::new(name, l, ConditionalApplier { condition: conds, applier: r })
    }
}
