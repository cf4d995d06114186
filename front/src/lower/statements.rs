//! Lowering of one statement: alias / prologue / trig / callback-binding forms, temporaries
//! and outputs (rules in the parent module doc).

use robovec_ir::{Def, Expr as IrExpr, Operand, Span};

use super::{canon, is_trig, Lower, R};
use crate::ast::{Expr, Ref, Stmt, Suffix};
use crate::error::FrontError;
use crate::Language;

impl Lower<'_> {
    /// Lowers one statement (errors kept until [`Lower::finish`]).
    pub(crate) fn stmt(&mut self, s: &Stmt) {
        let lhs = &s.lhs;
        if let Some((o, _)) = &lhs.obj {
            let prefix = match o.text.as_str() {
                "s" => "",
                "sens" => "sens.",
                other => {
                    let msg = format!("unknown structure `{other}`");
                    self.err(
                        FrontError::new(o.span, msg, "not a Robotran structure")
                            .note("expected `s->x`, `s.x` or `sens->x` on a left-hand side"),
                    );
                    return;
                }
            };
            let Ok(idx) = self.indices(&lhs.suffix) else { return };
            let name = format!("{prefix}{}", canon(&lhs.name.text, &idx));
            self.output(name, &s.rhs, s.span);
            return;
        }
        let x = lhs.name.text.as_str();
        if lhs.suffix.is_empty() {
            if self.special(x, s) {
                return;
            }
            if self.outputs.contains(x) {
                self.output(x.to_string(), &s.rhs, s.span);
            } else {
                self.temp(x.to_string(), None, &s.rhs, s.span, lhs.name.span);
            }
            return;
        }
        if self.lang != Language::Matlab && lhs.suffix.iter().any(|s| matches!(s, Suffix::Paren(..))) {
            self.err(
                FrontError::new(lhs.span, "a call cannot be assigned to", "not a location")
                    .note("expected a name or an element such as `M[1][2]`"),
            );
            return;
        }
        let Ok(idx) = self.indices(&lhs.suffix) else {
            self.failed.insert(x.to_string());
            return;
        };
        let base = self.aliases.get(x).cloned().unwrap_or_else(|| x.to_string());
        let full = canon(&base, &idx);
        if self.outputs.contains(x) || self.outputs.contains(&base) || self.is_input_array(&base) {
            self.output(full, &s.rhs, s.span);
        } else {
            self.temp(full, Some((x, idx)), &s.rhs, s.span, lhs.span);
        }
    }

    /// Alias, prologue, trig and vector-callback lines; true when `s` was one of them.
    fn special(&mut self, x: &str, s: &Stmt) -> bool {
        let Expr::Ref(r) = &s.rhs else { return false };
        match (&r.obj, r.suffix.as_slice()) {
            // `q = s->q;`, `frc = s.frc`
            (Some((o, _)), []) if o.text == "s" => {
                self.aliases.insert(x.to_string(), r.name.text.clone());
                self.s_arrays.insert(r.name.text.clone());
                true
            }
            // `Qq = phi`
            (None, []) if self.fa.params.contains(&r.name.text) && self.outputs.contains(&r.name.text) => {
                self.outputs.insert(x.to_string());
                true
            }
            // `M = zeros(55,55);`
            (None, [Suffix::Paren(..)]) if r.name.text == "zeros" => true,
            (obj, [Suffix::Paren(args, _)])
                if is_trig(&r.name.text).is_some()
                    && obj.as_ref().is_none_or(|(o, _)| o.text == "np" || o.text == "math") =>
            {
                self.trig(x, r, args, s.span);
                true
            }
            (_, [Suffix::Paren(..)])
                if Self::callee_kind(r).is_some()
                    && (self.fa.pointers.iter().any(|p| p == x) || r.name.text.contains("ExtForces")) =>
            {
                if self.check_fresh(x, s.span, s.lhs.name.span) {
                    match self.callback_parts(r) {
                        Ok(parts) => {
                            self.vectors.insert(x.to_string(), parts);
                        }
                        Err(()) => {
                            self.failed.insert(x.to_string());
                        }
                    }
                }
                true
            }
            _ => false,
        }
    }

    fn trig(&mut self, x: &str, r: &Ref, args: &[Expr], span: Span) {
        let f = is_trig(&r.name.text).expect("checked by caller");
        let arg = match args {
            [a] => self.expr(a).ok(),
            _ => None,
        };
        let input = match arg {
            Some(IrExpr::Operand(Operand::Value(v))) if matches!(self.f.value(v).def, Def::Input) => v,
            _ => {
                let name = &r.name.text;
                self.err(
                    FrontError::new(
                        r.span,
                        format!("argument of `{name}` must be a joint coordinate"),
                        "not a joint coordinate",
                    )
                    .note(format!("expected a trig initial variable such as `C4 = {name}(q[4])`")),
                );
                self.failed.insert(x.to_string());
                return;
            }
        };
        if !self.check_fresh(x, span, span) {
            return;
        }
        if let Ok(v) = self.f.define(x, Def::Trig(f, input), span) {
            self.current.insert(x.to_string(), Operand::Value(v));
        }
    }

    /// False (and an error) when `name` is already defined.
    fn check_fresh(&mut self, name: &str, span: Span, label_span: Span) -> bool {
        let first = match self.f.lookup(name) {
            Some(v) => Some(self.f.value(v).span),
            None if self.vectors.contains_key(name) => Some(Span::DUMMY),
            None => None,
        };
        let Some(first) = first else { return true };
        let mut e = FrontError::new(
            label_span.to(Span::new(span.start as usize, span.start as usize)),
            format!("value `{name}` defined twice"),
            "second definition",
        );
        e = if first == Span::DUMMY {
            e.note("first defined earlier in this function")
        } else {
            let line = super::line_of(self.src, first.start as usize);
            e.note(format!("first defined at line {line}; Robotran straight-line code assigns each temporary once"))
        };
        self.err(e);
        false
    }

    /// A temporary (scalar or local array element).
    fn temp(&mut self, name: String, elem: Option<(&str, Vec<u32>)>, rhs: &Expr, span: Span, label_span: Span) {
        if !self.check_fresh(&name, span, label_span) {
            return;
        }
        let Ok(e) = self.expr(rhs) else {
            self.failed.insert(name);
            return;
        };
        if let Ok(v) = self.f.define(name.clone(), Def::Expr(e), span) {
            self.equations += 1;
            self.current.insert(name, Operand::Value(v));
            if let Some((base, idx)) = elem {
                self.arrays.entry(base.to_string()).or_default().insert(idx, Operand::Value(v));
            }
        }
    }

    /// An output location written: see the module doc for the operand forms.
    fn output(&mut self, name: String, rhs: &Expr, span: Span) {
        let op: R<Operand> = match rhs {
            Expr::Num { value, .. } => Ok(Operand::Const(*value)),
            Expr::Neg(x, _) if matches!(**x, Expr::Num { .. }) => match **x {
                Expr::Num { value, .. } => Ok(Operand::Const(-value)),
                _ => Err(()),
            },
            _ => match self.expr(rhs) {
                Ok(IrExpr::Operand(o)) => Ok(o),
                Ok(e) => Ok(Operand::Value(self.f.define_fresh(&name, Def::Expr(e), span))),
                Err(()) => Err(()),
            },
        };
        match op {
            Ok(op) => {
                self.equations += 1;
                self.f.set_output(name.clone(), op, span);
                self.current.insert(name, op);
            }
            Err(()) => {
                self.failed.insert(name);
            }
        }
    }
}
