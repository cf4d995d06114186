//! Statement AST → IR (`Phase::Parsed`), shared by the three languages.
//!
//! # Lowering rules
//! - One IR function per Robotran function, named without a leading `mbs_`; a sensor file
//!   gives one function per `case N:` (`sensor_N`, `gensensor_N`, see [`super::sensor`]).
//! - **Canonical names** (SPEC §2): `s->`/`s.` dropped, `sens.` kept, 1-based indices in
//!   brackets: `s.dpt(2,4)`, `s.dpt[2,4]`, `s->dpt[2][4]`, `dpt[2][4]` → `dpt[2][4]`.
//! - **Inputs** are created at their first read: any `s->x…`/`s.x…` access, the input arrays
//!   `q qd qdd dpt l m In g frc trq lrod Qq` (and any `X` aliased by `#define X s->X`,
//!   `X = s->X;`, `X = s.X`) read with indices, and `tsim` — unless the location was already
//!   written in this function, in which case the read sees the latest value written.
//! - **Alias and prologue lines are not equations** and define nothing: `q = s->q;`,
//!   `frc = s.frc;`, `Qq = phi` (makes `Qq` an output array when `phi` is an output
//!   parameter), `M = zeros(55,55);`.
//! - **Trig initial variables**: `X = cos(q[i])` / `sin`, `np.cos`, Matlab `cos(q(i))` →
//!   `Def::Trig` of the input; not an equation. `sin`/`cos` anywhere else is an error.
//! - **Temporaries** (scalars `AlF15`, local array elements `PxF1[1]`, `RxF1[2][3]`) →
//!   `Function::define(name, Def::Expr(rhs))`; a second definition is an error.
//! - **Outputs**: left-hand sides whose array is an output of the signature (C `double *`
//!   parameters, Matlab results, Python parameters other than `s`/`tsim`/`usrfun`), an input
//!   array written (`frc[2][11]`), `s->…` (`s->flag_stop` → `flag_stop`) or `sens->…`
//!   (`sens.P[1]`). `out = name` → the value itself; `out = 0`, `(1.0)`, `-(1.0)` → a
//!   constant; anything else → a value named `Function::fresh_name(<output name>)`.
//!   Writing a location twice (read-modify-write of `frc`) defines `frc[2][11].1`, `.2`, …
//!   and the output holds the last one.
//! - **Equations** = assignments except trig initial variables, alias/prologue lines and
//!   vector callback bindings; output copies count.
//! - **Expressions** keep the source tree (see `expr.lalrpop`); literals are non-negative
//!   constants, a minus is `Expr::Neg`.
//! - **Calls**: `sqrt(e)` → `@sqrt`. User callbacks (`user_*`, `user_call_*`, `usrfun.*`) are
//!   opaque calls: the argument `s` is dropped, `tsim` is the input `tsim`, integer literals
//!   are appended to the callee name (`user_LinkForces.1`), a local array name expands to
//!   its elements assigned so far in row-major order. A callback bound to a pointer
//!   (`double *SWr1;`, or any `*ExtForces*` callback) returns a vector: each element read
//!   (`SWr1[3]`) defines, at its first read, a value `SWr1[3]` = `@user_ExtForces.1[3](…)`.
//! - Errors: unknown function, unknown structure, bad index, use before definition,
//!   redefinition. A statement whose lowering failed poisons its left-hand side so that its
//!   later uses do not cascade into more errors.

use std::collections::BTreeMap;

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use robovec_ir::{Callee, Def, Expr as IrExpr, Function, Module, Operand, Phase, Span, TrigFn};

use super::ast::{Expr, FuncAst, Ref, Stmt, Suffix};
use super::clock::Clock;
use super::error::FrontError;
use super::{sensor, Language};
use robovec_ir::span::line_of;

/// Arrays of `MbsData` that Robotran code reads without the `s->` prefix.
const INPUT_ARRAYS: &[&str] = &["q", "qd", "qdd", "dpt", "l", "m", "In", "g", "frc", "trq", "lrod", "Qq"];
const ACCEPTED: &str = "accepted functions: `sqrt(x)`, `sin`/`cos` of a joint coordinate as a whole right-hand side \
                        (`C4 = cos(q[4])`), user callbacks `user_*`, `user_call_*`, `usrfun.*`";

/// Lowers every scanned function; sensor functions are split per case. Stops at `clock`'s
/// deadline (one tick per statement; the module is then incomplete and the clock says so).
pub fn lower_module(
    src: &str,
    lang: Language,
    funcs: &[FuncAst],
    errors: &mut Vec<FrontError>,
    clock: &Clock,
) -> Module {
    let mut m = Module::default();
    let mut add = |f: Function, span: Span, errors: &mut Vec<FrontError>| {
        if m.function(&f.name).is_some() {
            errors.push(FrontError::new(span, format!("function `{}` defined twice", f.name), "second definition"));
        } else {
            m.functions.push(f);
        }
    };
    for fa in funcs {
        match &fa.cases {
            None => {
                let stmts: Vec<&Stmt> = fa.prefix.iter().chain(&fa.suffix).collect();
                let f = Lower::new(src, lang, fa).run(fa.name.clone(), &stmts, errors, clock);
                add(f, fa.span, errors);
            }
            Some(cases) => {
                for c in cases {
                    let tail: Vec<&Stmt> = c.body.iter().chain(&fa.suffix).collect();
                    let mut stmts = sensor::needed_prefix(&fa.prefix, &tail, &fa.outputs);
                    stmts.extend(tail);
                    let f = Lower::new(src, lang, fa).run(format!("{}_{}", fa.name, c.label), &stmts, errors, clock);
                    add(f, c.span, errors);
                }
            }
        }
    }
    m
}

/// `Err(())`: the error is already reported (or the statement is poisoned).
type R<T> = Result<T, ()>;

fn canon(base: &str, idx: &[u32]) -> String {
    let mut s = base.to_string();
    for i in idx {
        s.push_str(&format!("[{i}]"));
    }
    s
}

fn is_trig(name: &str) -> Option<TrigFn> {
    match name {
        "sin" => Some(TrigFn::Sin),
        "cos" => Some(TrigFn::Cos),
        _ => None,
    }
}

/// The parts of a [`FuncAst`] that lowering reads (not its statements).
struct Header {
    span: Span,
    params: Vec<String>,
    pointers: Vec<String>,
}

/// Lowers the statements of one function, one at a time ([`Lower::stmt`]).
pub(crate) struct Lower<'a> {
    src: &'a str,
    lang: Language,
    fa: Header,
    f: Function,
    /// Errors of this function's statements, appended to the file's by [`Lower::run`] /
    /// [`Lower::finish`] (same order as when pushed directly).
    errors: Vec<FrontError>,
    /// Latest value of every location written or read (temporaries, elements, outputs, inputs).
    current: HashMap<String, Operand>,
    outputs: HashSet<String>,
    aliases: HashMap<String, String>,
    s_arrays: HashSet<String>,
    arrays: HashMap<String, BTreeMap<Vec<u32>, Operand>>,
    vectors: HashMap<String, (String, Vec<IrExpr>)>,
    failed: HashSet<String>,
    equations: u32,
}

impl<'a> Lower<'a> {
    /// A lowering of `fa`'s statements with its header (parameters, outputs, pointers,
    /// defines, poisoned names) as it is now.
    pub(crate) fn new(src: &'a str, lang: Language, fa: &FuncAst) -> Lower<'a> {
        let aliases = fa.defines.iter().map(|d| (d.clone(), d.clone())).collect();
        Lower {
            src,
            lang,
            fa: Header { span: fa.span, params: fa.params.clone(), pointers: fa.pointers.clone() },
            f: Function::new(String::new(), Phase::Parsed),
            errors: Vec::new(),
            current: HashMap::default(),
            outputs: fa.outputs.iter().cloned().collect(),
            aliases,
            s_arrays: fa.defines.iter().cloned().collect(),
            arrays: HashMap::default(),
            vectors: HashMap::default(),
            failed: fa.poisoned.iter().map(|n| n.strip_prefix("s.").unwrap_or(n).to_string()).collect(),
            equations: 0,
        }
    }

    fn run(mut self, name: String, stmts: &[&Stmt], errors: &mut Vec<FrontError>, clock: &Clock) -> Function {
        for s in stmts {
            if clock.tick(s.span.start as usize) {
                break;
            }
            self.stmt(s);
        }
        self.finish(name, errors)
    }

    /// Sets the function's span (the streaming line path knows it only at the function's end).
    pub(crate) fn set_span(&mut self, span: Span) {
        self.fa.span = span;
    }

    /// The lowered function, named `name`; its errors are appended to `errors`.
    pub(crate) fn finish(mut self, name: String, errors: &mut Vec<FrontError>) -> Function {
        self.f.name = name;
        self.f.span = self.fa.span;
        self.f.equations = Some(self.equations);
        errors.append(&mut self.errors);
        self.f
    }

    fn err(&mut self, e: FrontError) {
        self.errors.push(e);
    }

    fn is_input_array(&self, base: &str) -> bool {
        INPUT_ARRAYS.contains(&base) || self.s_arrays.contains(base)
    }

    fn is_array(&self, name: &str) -> bool {
        self.aliases.contains_key(name)
            || self.is_input_array(name)
            || self.outputs.contains(name)
            || self.arrays.contains_key(name)
            || self.vectors.contains_key(name)
    }

    /// Integer indices of `suffix` (`[2][4]`, `[2,4]`, `(2,4)`).
    fn indices(&mut self, suffix: &[Suffix]) -> R<Vec<u32>> {
        let mut out = Vec::new();
        let mut ok = true;
        for s in suffix {
            let (Suffix::Bracket(args, span) | Suffix::Paren(args, span)) = s;
            if args.is_empty() {
                self.err(
                    FrontError::new(*span, "empty index", "no index here")
                        .note("expected a positive integer literal such as `q[4]`"),
                );
                ok = false;
            }
            for a in args {
                match a {
                    Expr::Num { value, int: true, span } => match u32::try_from(*value as u64) {
                        Ok(0) | Err(_) => {
                            self.err(
                                FrontError::new(*span, format!("index `{value}` is out of range"), "bad index")
                                    .note("expected a 1-based index between 1 and 4294967295"),
                            );
                            ok = false;
                        }
                        Ok(i) => out.push(i),
                    },
                    other => {
                        self.err(
                            FrontError::new(
                                other.span(),
                                "index must be a positive integer literal",
                                "not an integer literal",
                            )
                            .note("expected an index such as `q[4]` or `s->dpt[2][4]`"),
                        );
                        ok = false;
                    }
                }
            }
        }
        if ok {
            Ok(out)
        } else {
            Err(())
        }
    }

    fn undefined(&mut self, name: &str, span: Span) -> R<IrExpr> {
        self.err(
            FrontError::new(span, format!("use of `{name}` before its definition"), "not defined yet")
                .note("expected a temporary assigned earlier in this function, an input (`q[4]`, `s->dpt[1][2]`, `tsim`…) or a trig variable"),
        );
        Err(())
    }

    fn input(&mut self, name: &str, span: Span) -> Operand {
        if let Some(&o) = self.current.get(name) {
            return o;
        }
        let v = match self.f.add_input(name, span) {
            Ok(v) | Err(v) => v,
        };
        self.current.insert(name.to_string(), Operand::Value(v));
        Operand::Value(v)
    }

    /// A read of a name, element, structure member or call.
    fn read(&mut self, r: &Ref) -> R<IrExpr> {
        let call_like = matches!(r.suffix.as_slice(), [Suffix::Paren(..)]);
        if let Some((o, _)) = &r.obj {
            return match o.text.as_str() {
                "s" => {
                    let idx = self.indices(&r.suffix)?;
                    let name = canon(&r.name.text, &idx);
                    Ok(IrExpr::Operand(self.input(&name, r.span)))
                }
                "sens" => {
                    let idx = self.indices(&r.suffix)?;
                    let name = format!("sens.{}", canon(&r.name.text, &idx));
                    match self.current.get(&name) {
                        Some(&o) => Ok(IrExpr::Operand(o)),
                        None => self.undefined(&name, r.span),
                    }
                }
                "usrfun" if call_like => self.callback(r),
                "np" | "math" if call_like => self.call(r),
                other => {
                    let msg = format!("unknown structure `{other}`");
                    self.err(
                        FrontError::new(o.span, msg, "not a Robotran structure")
                            .note("expected `s->x`, `s.x`, `sens->x`, `np.cos`, `usrfun.f(…)`"),
                    );
                    Err(())
                }
            };
        }
        let name = r.name.text.as_str();
        if call_like && (self.lang != Language::Matlab || !self.is_array(name)) {
            return self.call(r);
        }
        if r.suffix.is_empty() {
            if let Some(&o) = self.current.get(name) {
                return Ok(IrExpr::Operand(o));
            }
            if self.failed.contains(name) {
                return Err(());
            }
            if name == "tsim" {
                return Ok(IrExpr::Operand(self.input("tsim", r.span)));
            }
            if self.arrays.contains_key(name) || self.vectors.contains_key(name) {
                let msg = format!("array `{name}` used as a number");
                self.err(FrontError::new(r.span, msg, "a whole array").note(
                    "expected an element such as `PxF1[1]`; a whole local array may only be passed to a user callback",
                ));
                return Err(());
            }
            return self.undefined(name, r.span);
        }
        let idx = self.indices(&r.suffix)?;
        let base = self.aliases.get(name).cloned().unwrap_or_else(|| name.to_string());
        let full = canon(&base, &idx);
        if let Some(&o) = self.current.get(&full) {
            return Ok(IrExpr::Operand(o));
        }
        if self.failed.contains(&full) || self.failed.contains(&base) {
            return Err(());
        }
        if let Some((callee, args)) = self.vectors.get(&base).cloned() {
            if let [i] = idx[..] {
                let def = Def::Expr(IrExpr::call(Callee { name: callee, elem: Some(i) }, args));
                let v = self.f.define_fresh(&full, def, r.span);
                self.current.insert(full, Operand::Value(v));
                return Ok(IrExpr::Operand(Operand::Value(v)));
            }
        }
        if self.is_input_array(&base) {
            return Ok(IrExpr::Operand(self.input(&full, r.span)));
        }
        self.undefined(&full, r.span)
    }

    fn callee_kind(r: &Ref) -> Option<&str> {
        match &r.obj {
            None if r.name.text.starts_with("user_") => Some("callback"),
            Some((o, _)) if o.text == "usrfun" => Some("callback"),
            _ => None,
        }
    }

    /// `sqrt(e)`, a user callback, or an unknown / misplaced function.
    fn call(&mut self, r: &Ref) -> R<IrExpr> {
        let name = r.name.text.as_str();
        let [Suffix::Paren(args, _)] = r.suffix.as_slice() else { return Err(()) };
        if Self::callee_kind(r).is_some() {
            return self.callback(r);
        }
        if name == "sqrt" {
            if let [a] = args.as_slice() {
                let e = self.expr(a)?;
                return Ok(IrExpr::call(Callee { name: "sqrt".into(), elem: None }, vec![e]));
            }
            self.err(
                FrontError::new(r.span, "`sqrt` takes one argument", "wrong number of arguments")
                    .note("expected `sqrt(x)`"),
            );
            return Err(());
        }
        let (msg, note) = if is_trig(name).is_some() {
            (
                format!("`{name}` is accepted only as a whole right-hand side"),
                "expected a trig initial variable such as `C4 = cos(q[4])`".to_string(),
            )
        } else if name == "zeros" {
            (
                "`zeros` is accepted only in a pre-allocation line".to_string(),
                "expected `M = zeros(55,55);`".to_string(),
            )
        } else {
            (format!("unknown function `{name}`"), ACCEPTED.to_string())
        };
        self.err(FrontError::new(r.name.span, msg, "in this call").note(note));
        Err(())
    }

    /// Callee name and operands of a user callback (see the module doc).
    fn callback_parts(&mut self, r: &Ref) -> R<(String, Vec<IrExpr>)> {
        let mut name = match &r.obj {
            Some((o, _)) => format!("{}.{}", o.text, r.name.text),
            None => r.name.text.clone(),
        };
        let [Suffix::Paren(args, _)] = r.suffix.as_slice() else { return Err(()) };
        let mut out = Vec::new();
        let mut ok = true;
        for a in args {
            match a {
                Expr::Num { value, int: true, .. } => name.push_str(&format!(".{value}")),
                Expr::Ref(x) if x.obj.is_none() && x.suffix.is_empty() && x.name.text == "s" => {}
                Expr::Ref(x) if x.obj.is_none() && x.suffix.is_empty() && self.arrays.contains_key(&x.name.text) => {
                    out.extend(self.arrays[&x.name.text].values().map(|&o| IrExpr::Operand(o)));
                }
                e => match self.expr(e) {
                    Ok(e) => out.push(e),
                    Err(()) => ok = false,
                },
            }
        }
        if ok {
            Ok((name, out))
        } else {
            Err(())
        }
    }

    fn callback(&mut self, r: &Ref) -> R<IrExpr> {
        let (name, args) = self.callback_parts(r)?;
        Ok(IrExpr::call(Callee { name, elem: None }, args))
    }

    fn expr(&mut self, e: &Expr) -> R<IrExpr> {
        match e {
            Expr::Num { value, .. } => Ok(IrExpr::Operand(Operand::Const(*value))),
            Expr::Str(span) => {
                self.err(
                    FrontError::new(*span, "string literal in an expression", "a string")
                        .note("expected a number or a name"),
                );
                Err(())
            }
            Expr::Ref(r) => self.read(r),
            Expr::Neg(x, _) => Ok(IrExpr::Neg(Box::new(self.expr(x)?))),
            Expr::Bin(op, a, b) => {
                let (a, b) = (self.expr(a), self.expr(b));
                Ok(IrExpr::Binary(*op, Box::new(a?), Box::new(b?)))
            }
        }
    }
}

mod statements;
