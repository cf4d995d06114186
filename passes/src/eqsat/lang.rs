//! The window language of `eqsat` (egg's `define_language!`) and its constant-folding
//! analysis (egg `tests/math.rs` `ConstantFold`, NOTES-anchors §3.5).
//!
//! Terms are s-expressions over `+ - *` (binary), `neg` (unary minus) and two kinds of leaf:
//! numeric constants (`2`, `-0.5`, `1e-3`) and window leaves `x0`, `x1`, … (the values a window
//! reads, see [`super::window`]). A `neg` that survives extraction becomes SPEC §3's `0 - x`.

use egg::{merge_option, Analysis, DidMerge, Id, Language, Symbol};

/// A finite `f64` constant usable as an e-node: compared and hashed by its bits, with `-0.0`
/// normalised to `0.0` (the sign of an exact zero is not tracked by the rewrites).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Const(u64);

impl Const {
    /// The constant `x`; `None` when `x` is not finite.
    pub fn new(x: f64) -> Option<Const> {
        x.is_finite().then(|| Const(if x == 0.0 { 0 } else { x.to_bits() }))
    }

    /// The value.
    pub fn get(self) -> f64 {
        f64::from_bits(self.0)
    }
}

impl std::fmt::Display for Const {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // `{:?}` prints the shortest text that reads back to the same bits.
        write!(f, "{:?}", self.get())
    }
}

impl std::str::FromStr for Const {
    type Err = String;
    fn from_str(s: &str) -> Result<Const, String> {
        // Only plain decimal numbers: `inf`, `nan` and names are not constants.
        if !s.bytes().next().is_some_and(|b| b.is_ascii_digit() || b == b'-' || b == b'.') {
            return Err(format!("`{s}` is not a number"));
        }
        let x: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
        Const::new(x).ok_or_else(|| format!("`{s}` is not finite"))
    }
}

mod def {
    #![expect(missing_docs, reason = "`define_language!` takes no variant docs; they are listed on `Arith` below")]
    use super::Const;
    use egg::{define_language, Id, Symbol};

    define_language! {
        /// Window terms (see the variant list in the re-export's doc).
        pub enum Arith {
            "+" = Add([Id; 2]),
            "-" = Sub([Id; 2]),
            "*" = Mul([Id; 2]),
            "neg" = Neg(Id),
            Num(Const),
            Leaf(Symbol),
        }
    }
}

/// Window terms. Variants: `Add` `(+ a b)` and `Sub` `(- a b)` (latency `lat-add`), `Mul`
/// `(* a b)` (latency `lat-mul`), `Neg` `(neg a)` (unary minus, materialised as SPEC §3's
/// `0 - a`, one `sub`), `Num` (a finite constant, ready at cycle 0) and `Leaf` (`x0`, `x1`, …:
/// a value the window reads).
pub use def::Arith;

/// An e-graph over [`Arith`] with constant folding.
pub type EGraph = egg::EGraph<Arith, ConstantFold>;
/// A rewrite over [`Arith`] with constant folding.
pub type Rewrite = egg::Rewrite<Arith, ConstantFold>;

/// Constant folding (egg `tests/math.rs`): an e-class whose value is a known constant carries
/// it; `modify` adds the constant's node to the class and prunes the class to its leaf nodes,
/// which also keeps associativity from multiplying constant sub-terms.
///
/// Folding evaluates in `f64` with one rounding per op, like the IR's interpreter. Two
/// different constants merged into one class (possible only through reassociation of
/// constant sums, whose roundings differ) keep the first one rather than panic.
#[derive(Clone, Copy, Debug, Default)]
pub struct ConstantFold;

impl Analysis<Arith> for ConstantFold {
    type Data = Option<Const>;

    fn make(egraph: &mut EGraph, enode: &Arith, _id: Id) -> Option<Const> {
        let x = |i: &Id| egraph[*i].data.map(Const::get);
        let v = match enode {
            Arith::Num(c) => return Some(*c),
            Arith::Leaf(_) => return None,
            Arith::Add([a, b]) => x(a)? + x(b)?,
            Arith::Sub([a, b]) => x(a)? - x(b)?,
            Arith::Mul([a, b]) => x(a)? * x(b)?,
            Arith::Neg(a) => -x(a)?,
        };
        Const::new(v)
    }

    fn merge(&mut self, to: &mut Option<Const>, from: Option<Const>) -> DidMerge {
        merge_option(to, from, |a, b| DidMerge(false, *a != b))
    }

    fn modify(egraph: &mut EGraph, id: Id) {
        if let Some(c) = egraph[id].data {
            let added = egraph.add(Arith::Num(c));
            egraph.union(id, added);
            egraph[id].nodes.retain(|n| n.is_leaf());
        }
    }
}

/// The name of window leaf `i` (`x0`, `x1`, …).
pub fn leaf_symbol(i: usize) -> Symbol {
    Symbol::from(format!("x{i}"))
}

/// The index of a window leaf name (`x3` → 3), `None` for other names.
pub fn leaf_index(s: Symbol) -> Option<usize> {
    s.as_str().strip_prefix('x')?.parse().ok()
}
