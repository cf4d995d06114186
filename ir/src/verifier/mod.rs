//! The IR verifier: checks every invariant later passes rely on and collects all violations.
//!
//! Checklist (each item is one [`VerifierError`] message when broken):
//!
//! Structure
//! - every value of `inputs` and `body` indexes the arena, and each arena value appears exactly
//!   once in `inputs ∪ body`;
//! - `inputs` hold exactly the `Def::Input` values;
//! - value names are unique and the name index agrees with the arena;
//! - output names are unique;
//! - `states` (how many states one evaluation computes) is at least 1.
//!
//! SSA
//! - every operand is an input or a body value defined earlier (definition before use);
//! - every output refers to a defined value or is a constant.
//!
//! Types and forms
//! - constants are finite; constants inside expressions are non-negative (a minus is `Neg`);
//! - `sin`/`cos` read an input;
//! - `call @sqrt` has exactly one operand.
//!
//! Phase (SPEC §3, seed §2.1)
//! - `atomised`: no nested expression remains — every body value is `sin`/`cos`, one binary op
//!   or one call on operands.
//! - timing attributes, when present, have `alap ≥ asap`, `mobility = alap − asap` and
//!   `alap_cycle ≥ asap_cycle`.
//!
//! Placement (when the function has one; see [`placement`] for the list): phase, every op
//! issued once on an existing PE of its type, one op per PE per cycle, write cycles, ports and
//! buffer reads, operands present at issue, addresses within the reported memory sizes.
//!
//! Lowered (on a machine program, not on a module: the program is derived, never stored in
//! the IR): see [`machine`] — every read address holds the right value at its cycle, every
//! write source exists, ports within `writes`, addresses within memory sizes, output map
//! complete. The lowering (`robovec_machine::program::lower`) runs it on every program it builds.
//!
//! TODO: types beyond `f64` scalars do not exist yet; nothing to check there.

pub mod machine;
pub mod placement;

use rustc_hash::FxHashSet as HashSet;

use codespan_reporting::diagnostic::{Diagnostic, Label};

use crate::function::{Function, Module};
use crate::intrinsic::Intrinsic;
use crate::span::Span;
use crate::syntax::{Callee, Def, Expr, Operand, Phase};
use crate::Value;

/// Where a verifier error was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// The function as a whole.
    Function,
    /// The definition of a value.
    Value(Value),
    /// Output `i` (index into `Function::outputs`).
    Output(usize),
    /// The placement block (an `issue`, `load` or `write` line, or the block itself).
    Placement,
    /// The machine program lowered from the placement ([`machine`]).
    Machine,
}

/// One broken invariant.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("in @{function}: {message}")]
pub struct VerifierError {
    /// Function name.
    pub function: String,
    /// Where.
    pub location: Location,
    /// The rule broken (lower case).
    pub message: String,
    /// Source span of the offending entity (`Span::DUMMY` if made by a pass).
    pub span: Span,
}

impl VerifierError {
    /// The codespan diagnostic; `when` says when the check ran ("after pass atomise").
    pub fn to_diagnostic<F: Copy>(&self, file: F, when: &str) -> Diagnostic<F> {
        let d = Diagnostic::error().with_message(format!("verifier: {} ({when})", self));
        if self.span == Span::DUMMY {
            d
        } else {
            d.with_labels(vec![Label::primary(file, self.span.range()).with_message(&self.message)])
        }
    }
}

/// The message for a call of an intrinsic's name ([`Intrinsic`]) with `n` operands when that
/// is the wrong number or the call selects a vector element (`@sqrt[2]`): such a call would
/// otherwise be taken for a user callback. `None` for any other call.
fn intrinsic_misuse(c: &Callee, n: usize) -> Option<String> {
    let i = Intrinsic::named(&c.name)?;
    if let Some(e) = c.elem {
        Some(format!("`@{}` is an intrinsic with a scalar result; `@{}[{e}]` selects an element", i.name(), i.name()))
    } else if n != i.arity() {
        Some(format!("`@{}` takes {} operand{}, found {n}", i.name(), i.arity(), if i.arity() == 1 { "" } else { "s" }))
    } else {
        None
    }
}

/// Verifies every function of `m`.
///
/// # Errors
/// All violations found, in function order.
pub fn verify(m: &Module) -> Result<(), Vec<VerifierError>> {
    verify_until(m, &mut || false).expect("never stopped")
}

/// [`verify`] that calls `stop` about once per value and per output (a time limit's clock:
/// the driver verifies its input under `-time-limit`, and a generated function may have
/// millions of outputs, issue 47) and gives up at the first `true`: `None`, nothing said
/// about the module.
///
/// # Errors
/// As [`verify`].
pub fn verify_until(m: &Module, stop: &mut dyn FnMut() -> bool) -> Option<Result<(), Vec<VerifierError>>> {
    let mut errs = Vec::new();
    let mut names = HashSet::default();
    for f in &m.functions {
        if !names.insert(f.name.as_str()) {
            errs.push(VerifierError {
                function: f.name.clone(),
                location: Location::Function,
                message: "function defined twice".into(),
                span: f.span,
            });
        }
        errs.extend(verify_function_until(f, stop)?);
    }
    Some(if errs.is_empty() { Ok(()) } else { Err(errs) })
}

/// Verifies one function; returns every violation (empty when it verifies).
pub fn verify_function(f: &Function) -> Vec<VerifierError> {
    verify_function_until(f, &mut || false).expect("never stopped")
}

/// [`verify_function`] that calls `stop` about once per value and per output and gives up
/// (`None`) at the first `true` ([`verify_until`]).
pub fn verify_function_until(f: &Function, stop: &mut dyn FnMut() -> bool) -> Option<Vec<VerifierError>> {
    let mut errs = Vec::new();
    let mut err = |loc: Location, span: Span, message: String| {
        errs.push(VerifierError { function: f.name.clone(), location: loc, message, span })
    };
    if f.states == 0 {
        err(Location::Function, f.span, "`states 0`: a function computes at least one state".into());
    }
    let n = f.values.len();
    // Structure: indexes first, so later checks can index infallibly.
    let mut placed = vec![false; n];
    for &v in f.inputs.iter().chain(&f.body) {
        if stop() {
            return None;
        }
        if v.index() >= n {
            err(Location::Function, f.span, format!("{v} is out of range ({n} values)"));
            return Some(errs);
        }
        if std::mem::replace(&mut placed[v.index()], true) {
            err(Location::Value(v), f.value(v).span, format!("`%{}` is listed twice", f.name_of(v)));
        }
    }
    for (i, p) in placed.iter().enumerate() {
        if !p {
            let v = Value::with_number(i as u32);
            err(Location::Value(v), f.value(v).span, format!("`%{}` is in no list", f.name_of(v)));
        }
    }
    // A current index maps every name to its own value, so no two values share a name: the
    // set of names seen is only needed (to tell which error) when the index is not current.
    let mut index_current = true;
    for (i, d) in f.values.iter().enumerate() {
        if stop() {
            return None;
        }
        if f.lookup(&d.name) != Some(Value::with_number(i as u32)) {
            index_current = false;
            break;
        }
    }
    let mut seen_names = HashSet::default();
    for (i, d) in f.values.iter().enumerate().filter(|_| !index_current) {
        let v = Value::with_number(i as u32);
        if !seen_names.insert(d.name.as_str()) {
            err(Location::Value(v), d.span, format!("value name `%{}` is used twice", d.name));
        } else if f.lookup(&d.name) != Some(v) {
            err(Location::Value(v), d.span, format!("name index out of date for `%{}`", d.name));
        }
    }
    for &v in &f.inputs {
        if !matches!(f.value(v).def, Def::Input) {
            err(Location::Value(v), f.value(v).span, format!("`%{}` is listed as input but defined", f.name_of(v)));
        }
    }
    // SSA, forms and phase, in definition order.
    let mut defined = vec![false; n];
    for &v in &f.inputs {
        defined[v.index()] = true;
    }
    for &v in &f.body {
        if stop() {
            return None;
        }
        let d = f.value(v);
        let here = |m: String| (Location::Value(v), d.span, m);
        let mut local = Vec::new();
        let check_operand = |o: &Operand, local: &mut Vec<String>, in_expr: bool| match o {
            Operand::Value(x) => {
                if x.index() >= n {
                    local.push(format!("operand {x} is out of range"));
                } else if !defined[x.index()] {
                    local.push(format!("`%{}` is used before its definition", f.name_of(*x)));
                }
            }
            Operand::Const(c) => {
                if !c.is_finite() {
                    local.push(format!("constant {c} is not finite"));
                } else if in_expr && c.is_sign_negative() {
                    local.push(format!("constant {c:?} in an expression must be non-negative (write a negation)"));
                }
            }
        };
        match &d.def {
            Def::Input => local.push("input definition in the body".into()),
            Def::Trig(_, a) => {
                check_operand(&Operand::Value(*a), &mut local, false);
                if a.index() < n && !matches!(f.value(*a).def, Def::Input) {
                    local.push(format!("`sin`/`cos` must read an input, `%{}` is not one", f.name_of(*a)));
                }
            }
            Def::Binary(_, a, b) => {
                check_operand(a, &mut local, false);
                check_operand(b, &mut local, false);
            }
            Def::Call(c, args) => {
                args.iter().for_each(|a| check_operand(a, &mut local, false));
                local.extend(intrinsic_misuse(c, args.len()));
            }
            Def::Expr(e) => {
                if f.phase == Phase::Atomised {
                    local.push("nested expression in an atomised function (run `atomise` first)".into());
                }
                let mut stack = vec![e];
                while let Some(e) = stack.pop() {
                    match e {
                        Expr::Operand(o) => check_operand(o, &mut local, true),
                        Expr::Neg(x) => stack.push(x),
                        Expr::Binary(_, a, b) => {
                            stack.push(b);
                            stack.push(a);
                        }
                        Expr::Call(c, args) => {
                            local.extend(intrinsic_misuse(c, args.len()));
                            stack.extend(args.iter().rev());
                        }
                    }
                }
            }
        }
        if let Some(t) = &f.timing(v) {
            if t.alap < t.asap || t.mobility != t.alap - t.asap || t.alap_cycle < t.asap_cycle {
                local.push(format!("inconsistent timing {t:?}"));
            }
        }
        for m in local {
            let (l, s, m) = here(m);
            err(l, s, m);
        }
        defined[v.index()] = true;
    }
    let mut out_names = HashSet::with_capacity_and_hasher(f.outputs.len(), Default::default());
    for (i, o) in f.outputs.iter().enumerate() {
        if stop() {
            return None;
        }
        if !out_names.insert(o.name.as_str()) {
            err(Location::Output(i), o.span, format!("output `{}` is defined twice", o.name));
        }
        match o.value {
            Operand::Value(x) if x.index() >= n || !defined[x.index()] => {
                err(Location::Output(i), o.span, format!("output `{}` refers to an undefined value", o.name))
            }
            Operand::Const(c) if !c.is_finite() => {
                err(Location::Output(i), o.span, format!("output `{}` is not finite", o.name))
            }
            _ => {}
        }
    }
    if let Some(v) = f.first_formatted().filter(|_| f.phase == Phase::Parsed) {
        // An expression rounds at every node; a format says how one op's result is stored.
        err(
            Location::Value(v),
            f.value(v).span,
            format!(
                "`%{}` has the numeric format {}, but a format needs an atomised function (`phase atomised`: one rounding per op)",
                f.name_of(v),
                f.format(v)
            ),
        );
    }
    if errs.is_empty() {
        errs.extend(placement::verify_placement_until(f, stop)?);
    }
    Some(errs)
}
