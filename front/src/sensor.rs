//! Sensor files (`mbs_sensor`, `mbs_gensensor`): one IR function per `case N:` of
//! `switch (isens)`. Each gets the statements before the switch that its case transitively
//! reads (found syntactically, by name, walking the prefix backwards), then its case body.

use std::collections::HashSet;

use super::ast::{Expr, Ref, Stmt, Suffix};

/// (full location text, array base) of a reference: `s->dpt[2][4]` → (`dpt[2][4]`, `dpt`).
fn key(r: &Ref) -> (String, String) {
    let mut base = r.name.text.clone();
    if let Some((o, _)) = &r.obj {
        if o.text != "s" {
            base = format!("{}.{}", o.text, base);
        }
    }
    let mut full = base.clone();
    for s in &r.suffix {
        let (Suffix::Bracket(args, _) | Suffix::Paren(args, _)) = s;
        for a in args {
            match a {
                Expr::Num { value, int: true, .. } => full.push_str(&format!("[{value}]")),
                _ => full.push_str("[?]"),
            }
        }
    }
    (full, base)
}

fn reads(e: &Expr, full: &mut HashSet<String>, bases: &mut HashSet<String>) {
    match e {
        Expr::Num { .. } | Expr::Str(_) => {}
        Expr::Neg(x, _) => reads(x, full, bases),
        Expr::Bin(_, a, b) => {
            reads(a, full, bases);
            reads(b, full, bases)
        }
        Expr::Ref(r) => {
            let (f, b) = key(r);
            full.insert(f);
            bases.insert(b);
            for s in &r.suffix {
                let (Suffix::Bracket(args, _) | Suffix::Paren(args, _)) = s;
                args.iter().for_each(|a| reads(a, full, bases));
            }
        }
    }
}

/// The statements of `prefix` that `tail` needs (transitively), in source order. Statements
/// writing through a structure (`s->…`, `sens->…`) or an output parameter, and alias lines
/// (`X = s->X`), are always kept.
pub fn needed_prefix<'s>(prefix: &'s [Stmt], tail: &[&Stmt], outputs: &[String]) -> Vec<&'s Stmt> {
    let mut full = HashSet::new();
    let mut bases = HashSet::new();
    for s in tail {
        reads(&s.rhs, &mut full, &mut bases);
    }
    let mut keep = vec![false; prefix.len()];
    for (i, s) in prefix.iter().enumerate().rev() {
        let (f, b) = key(&s.lhs);
        let alias = matches!(&s.rhs, Expr::Ref(r) if r.obj.is_some() && r.suffix.is_empty());
        let observable = s.lhs.obj.is_some() || outputs.contains(&s.lhs.name.text);
        if alias || observable || full.contains(&f) || bases.contains(&b) {
            keep[i] = true;
            reads(&s.rhs, &mut full, &mut bases);
        }
    }
    prefix.iter().zip(keep).filter(|(_, k)| *k).map(|(s, _)| s).collect()
}
