//! Associative clusters of an atomised function (seed §2.4; SPEC §6).
//!
//! An op is **additive** (`add`, `sub`) or **multiplicative** (`mul`); `div` and `call` are of
//! another kind. A value is **interior** when it is an additive or multiplicative op with exactly
//! one use, that use is an op of the same class, and it is not an output. A **cluster** is a
//! maximal tree of ops joined through interior values: its **root** is an additive or
//! multiplicative op that is not interior; its **leaves** are the operands that are not interior
//! (inputs, constants, values with several uses, outputs, ops of another kind) — the convention
//! of LLVM Reassociate's `LinearizeExprTree` and of `NOTES-anchors.md` §4.2.
//!
//! An additive cluster computes `Σ e_i·x_i` with a coefficient sign `e_i = ±1` per leaf
//! occurrence (the right operand of a `sub` flips the sign of its subtree); a multiplicative
//! cluster computes `Π x_i`. Cost: [`Clusters::new`] is O(values + operands); [`Clusters::tree`]
//! is O(size of the cluster).

use robovec_ir::{BinOp, Def, Function, Operand, Value};

/// The class of an op for clustering.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// `add`, `sub`.
    Additive,
    /// `mul`.
    Multiplicative,
    /// Anything else: inputs, trig variables, `div`, `call`.
    Other,
}

/// The class of a definition.
pub fn class_of(def: &Def) -> Class {
    match def {
        Def::Binary(BinOp::Add | BinOp::Sub, _, _) => Class::Additive,
        Def::Binary(BinOp::Mul, _, _) => Class::Multiplicative,
        _ => Class::Other,
    }
}

/// Use information and cluster membership of every value of one function.
#[derive(Clone, Debug)]
pub struct Clusters {
    /// Uses of each value: operand occurrences in ops plus output references.
    pub uses: Vec<u32>,
    /// True when the value is an output.
    pub is_output: Vec<bool>,
    /// True when the value is read by a `call` (which cannot absorb a sign).
    pub call_arg: Vec<bool>,
    /// Class of each value's definition.
    pub class: Vec<Class>,
    /// True for interior values (see the module doc).
    pub interior: Vec<bool>,
    /// For an additive or multiplicative op: the root of its cluster (itself for a root).
    pub root_of: Vec<Option<Value>>,
    /// Operand occurrences of each value in ops that are not additive (`mul`, `div`, `call`).
    pub non_additive_uses: Vec<u32>,
}

/// One node of a cluster tree, in post-order (children before parents).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TreeNode {
    /// Leaf occurrence `i` (index into [`ClusterTree::leaves`]).
    Leaf(u32),
    /// An op of the cluster: children are node indices; `negate_b` when the op is `sub` (the
    /// right child's subtree enters with a minus).
    Op {
        /// Left child.
        a: u32,
        /// Right child.
        b: u32,
        /// True for `sub`.
        negate_b: bool,
        /// The original value this op defines.
        value: Value,
    },
}

/// One leaf occurrence of a cluster.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeLeaf {
    /// The operand.
    pub operand: Operand,
    /// Coefficient sign in an additive cluster (true = `−`); always false in a product.
    pub negative: bool,
    /// Depth below the root (the root's operands have depth 1), unit steps.
    pub depth: u32,
}

/// The tree of one cluster.
#[derive(Clone, Debug, PartialEq)]
pub struct ClusterTree {
    /// Additive or multiplicative.
    pub class: Class,
    /// Nodes in post-order; the last one is the root op.
    pub nodes: Vec<TreeNode>,
    /// Leaf occurrences, left to right.
    pub leaves: Vec<TreeLeaf>,
}

impl Clusters {
    /// Computes uses, classes, interior values and cluster roots of `f` (atomised, verified).
    pub fn new(f: &Function) -> Clusters {
        let n = f.values.len();
        let mut uses = vec![0u32; n];
        let mut is_output = vec![false; n];
        let mut call_arg = vec![false; n];
        let mut user: Vec<Option<Value>> = vec![None; n];
        let mut class = vec![Class::Other; n];
        let mut non_additive_uses = vec![0u32; n];
        for &v in &f.body {
            let def = &f.value(v).def;
            class[v.index()] = class_of(def);
            let is_call = matches!(def, Def::Call(..));
            let additive = class[v.index()] == Class::Additive;
            def.for_each_value(|a| {
                uses[a.index()] += 1;
                user[a.index()] = Some(v);
                if is_call {
                    call_arg[a.index()] = true;
                }
                if !additive {
                    non_additive_uses[a.index()] += 1;
                }
            });
        }
        for o in &f.outputs {
            if let Operand::Value(v) = o.value {
                uses[v.index()] += 1;
                is_output[v.index()] = true;
            }
        }
        let mut interior = vec![false; n];
        let mut root_of = vec![None; n];
        for &v in f.body.iter().rev() {
            let i = v.index();
            let c = class[i];
            if c == Class::Other {
                continue;
            }
            let u = user[i].filter(|u| uses[i] == 1 && !is_output[i] && class[u.index()] == c);
            match u {
                Some(u) => {
                    interior[i] = true;
                    root_of[i] = root_of[u.index()];
                }
                None => root_of[i] = Some(v),
            }
        }
        Clusters { uses, is_output, call_arg, class, interior, root_of, non_additive_uses }
    }

    /// True when `v` is the root of an additive or multiplicative cluster.
    pub fn is_root(&self, v: Value) -> bool {
        self.root_of[v.index()] == Some(v)
    }

    /// True when a value must be handed over with its true sign: an output or a call argument.
    pub fn is_strict(&self, v: Value) -> bool {
        self.is_output[v.index()] || self.call_arg[v.index()]
    }

    /// The tree of the cluster rooted at `root` (a root: see [`Clusters::is_root`]).
    pub fn tree(&self, f: &Function, root: Value) -> ClusterTree {
        let class = self.class[root.index()];
        let mut nodes = Vec::new();
        let mut leaves = Vec::new();
        // Iterative post-order walk: (operand, coefficient sign, depth, expanded?).
        enum Step {
            Visit(Operand, bool, u32),
            Finish(Value, bool),
        }
        let mut stack = vec![Step::Visit(Operand::Value(root), false, 0)];
        let mut done: Vec<u32> = Vec::new();
        while let Some(s) = stack.pop() {
            match s {
                Step::Visit(o, neg, depth) => {
                    let expand = match o {
                        Operand::Value(v) => (v == root || self.interior[v.index()]).then_some(v),
                        Operand::Const(_) => None,
                    };
                    match expand {
                        Some(v) => {
                            let Def::Binary(op, a, b) = f.value(v).def else { unreachable!("cluster ops are binary") };
                            let sub = op == BinOp::Sub;
                            stack.push(Step::Finish(v, sub));
                            stack.push(Step::Visit(b, neg ^ sub, depth + 1));
                            stack.push(Step::Visit(a, neg, depth + 1));
                        }
                        None => {
                            leaves.push(TreeLeaf { operand: o, negative: neg, depth });
                            done.push(nodes.len() as u32);
                            nodes.push(TreeNode::Leaf(leaves.len() as u32 - 1));
                        }
                    }
                }
                Step::Finish(value, negate_b) => {
                    let b = done.pop().expect("right child");
                    let a = done.pop().expect("left child");
                    done.push(nodes.len() as u32);
                    nodes.push(TreeNode::Op { a, b, negate_b, value });
                }
            }
        }
        ClusterTree { class, nodes, leaves }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text::parse;

    #[test]
    fn clusters_stop_at_shared_values_outputs_and_other_kinds() {
        let m = parse(
            "func @f { phase atomised input %a input %b input %c
              %t = mul %a, %b
              %u = sub 0.0, %t
              %s1 = add %u, %c
              %s = sub %s1, %a
              %sh = add %a, %b
              %p = mul %sh, %sh
              %q = add %p, %s
              output o = %q output r = %s1 }",
        )
        .unwrap();
        let f = &m.functions[0];
        let c = Clusters::new(f);
        let v = |n: &str| f.lookup(n).unwrap();
        assert!(!c.interior[v("t").index()], "a product used by a sub is a leaf");
        assert!(c.interior[v("u").index()]);
        assert!(!c.interior[v("s1").index()], "an output is a root");
        assert!(c.interior[v("s").index()]);
        assert!(!c.interior[v("sh").index()], "two uses");
        assert_eq!(c.root_of[v("s").index()], Some(v("q")));
        let t = c.tree(f, v("q"));
        // q = p + (s1 - a): leaves p (+), s1 (+), a (−).
        let leaves: Vec<(String, bool, u32)> = t
            .leaves
            .iter()
            .map(|l| match l.operand {
                Operand::Value(x) => (f.name_of(x).to_string(), l.negative, l.depth),
                Operand::Const(k) => (k.to_string(), l.negative, l.depth),
            })
            .collect();
        assert_eq!(leaves, vec![("p".into(), false, 1), ("s1".into(), false, 2), ("a".into(), true, 2)]);
        let t = c.tree(f, v("s1"));
        // s1 = (0 - t) + c: leaves 0 (+), t (−), c (+).
        assert_eq!(t.leaves.iter().map(|l| l.negative).collect::<Vec<_>>(), vec![false, true, false]);
        assert_eq!(t.nodes.len(), 5);
    }
}
