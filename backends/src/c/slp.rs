//! `slp=4`: one-state code with groups of four isomorphic ops computed as one 4-lane vector op
//! (superword-level parallelism, Larsen & Amarasinghe, PLDI 2000; seeded bottom-up from the
//! outputs as LLVM's SLP vectoriser seeds on stores).
//!
//! **Why.** A large one-state function is straight-line code of about three instructions per
//! op, and past the second-level cache its time is instruction fetch (docs/derivatives.md, run
//! J: Talos' `aba_derivatives`). Its derivative matrices are built column by column by the same
//! code on other inputs (the product `−M⁻¹·∂τ` of a limb's columns), so four columns can share
//! one instruction stream.
//!
//! **Packs.** A *pack* is four values in lane order, distinct, each in at most one pack, of one
//! [`Shape`]: the same binary operator in every lane, or else each lane written as `a·b + c`
//! with one rounding (*mixed packs*, below). Seeds are the outputs in their order, four at a
//! time among those named `X[…][j]` that differ in the last index only (a row of a matrix, four
//! consecutive columns), cut at the same columns in every row: the first a multiple of four
//! columns from the first column of any matrix. (A row's run of non-zero entries starts at
//! the first column it depends on; cut from there, rows would group the per-column values
//! they share differently, and a pack of one grouping reads another's lanes only by gathering
//! them.) Before those, *isomorphic seeds* take four columns of one structure wherever they
//! are ([`isomorphic_seeds`]: a quadruped's four legs, whose columns are three apart); the
//! packs are found both ways, with and without them, and the way with more packs is kept.
//! The operands of `+`, `×` and `a·b` are put in the order that lines each lane up with
//! lane 0, by what they are (constant, input, operator) and their names without trailing
//! indices, as LLVM's SLP vectoriser reorders commutative operands. From a pack, each operand position gives four operands: equal ones
//! are *broadcast* (a scalar, which the C vector extensions spread over the lanes), four ops
//! that have a shape become a pack in turn, four constants are one vector constant, and
//! anything else is *gathered* lane by lane. A pack with more than one gathered operand
//! position costs more than its four scalar ops and is dropped (children first, so a parent
//! sees what its children became).
//!
//! **Mixed packs.** `contract` fuses `a·b + c` where the columns' code allows it, and the
//! columns of a derivative differ in which terms are structurally zero, so four columns often
//! hold a fused op beside a product or a sum. Each lane is then one vector FMA's lane:
//! `@fma(a, b, c)` as it is, `@fms(a, b, c)` as `a·b + (−c)`, `@fnma(a, b, c)` as `(−a)·b + c`,
//! `x·y` as `x·y + (−0)`, `x + y` as `x·1 + y` and `x − y` as `x·1 + (−y)` (a sum or a
//! difference either way round, and `a·b` as `b·a`: the orientation most like lane 0's). Each
//! is exact: `x·1` is `x`, negation is exact, and `x·y + (−0)` rounds the exact `x·y` once
//! with the sign of a zero product kept (`+0 + −0 = +0`, `−0 + −0 = −0`; `+0` would turn a
//! `−0` product into `+0`). A pack read with some lanes negated is multiplied by a vector of
//! `±1` first (exact). A mixed pack without a fused lane is written as a vector product then
//! a vector sum, not an FMA: in each lane one of the two is exact (a factor 1, an addend −0),
//! so the bits are the same, and a target without FMA does not call C99 `fma` four times
//! where the scalar code calls it never.
//!
//! **How many** (Talos and Solo-12 on the free flyer after the bench's `atomise,cse,
//! zero-removal,contract,schedule-cpu`, before → after mixed packs, aligned seeds, operand
//! order and isomorphic seeds): Talos' `aba_derivatives` 5,856 → 7,264 packs,
//! `rnea_derivatives` 494 → 1,038, `minv` 480 → 840; Solo-12's `rnea_derivatives` none → 765
//! (its legs), which makes its one state 1.12–1.15× as fast as without `slp` (paired, two
//! invocations of 41 samples).
//!
//! **Order.** A pack is written where its last member is in the body; its members are read as
//! scalars from there on. A pack is kept only when every reader of a member that is not a pack
//! taking the whole pack lane for lane as one operand comes later (in the body, or as a pack,
//! where its own last member is); the others are dissolved, until none is left to dissolve (a
//! dissolved pack's members are scalars again, where they were).
//!
//! **Bits.** Every lane computes the scalar op of its member on that member's operands (in a
//! mixed pack, an FMA of the same bits), so the code computes bit for bit what the one-state
//! code computes (the fused ops through one vector FMA instruction where the target has one,
//! C99 `fma` per lane otherwise).
//!
//! Cost: O(values + operands) to seed and build (each value is claimed once) and to dissolve
//! (each pack is dissolved once; a dissolution looks again at the packs of its members'
//! operands only); the isomorphic seeds add the structure hashes, O(values ×
//! [`STRUCTURE_DEPTH`]), their seeds (four lookups per seed, rows × column groups and back),
//! and a second search.

use std::collections::HashMap;

use robovec_ir::{BinOp, Def, Function, Intrinsic, Operand, Value};

/// Lanes of a pack.
pub(crate) const LANES: usize = 4;

/// One lane's operand of a pack's vector op: the operand, and whether the op reads it negated.
#[derive(Clone, Copy, PartialEq, Debug)]
pub(crate) struct Arg {
    /// The operand.
    pub x: Operand,
    /// Read as `−x` (exact).
    pub neg: bool,
}

/// The vector op of a pack.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum PackOp {
    /// One binary operator in every lane.
    Binary(BinOp),
    /// `a·b + c`, one rounding, in every lane (module doc, "Mixed packs").
    Fma,
    /// `a·b + c` as a product then a sum, where in every lane one of the two is exact (`a` or
    /// `b` is ±1, or `c` is −0): lanes of `+ − ×` only, the same bits with or without FMA
    /// (module doc, "Mixed packs").
    MulAdd,
}

/// A pack's vector op and its operands: `args[k][l]` is operand position `k` of lane `l`.
#[derive(Clone, Debug)]
pub(crate) struct Shape {
    /// The vector op.
    pub op: PackOp,
    /// Per operand position, its four lanes.
    pub args: Vec<[Arg; LANES]>,
}

impl Shape {
    /// Operand position `k`'s four operands, lane by lane, without their signs.
    pub(crate) fn operands(&self, k: usize) -> [Operand; LANES] {
        self.args[k].map(|a| a.x)
    }
}

/// The packs of one function.
#[derive(Debug, Default)]
pub(crate) struct Packs {
    /// Each live pack's members, lane 0 first.
    pub members: Vec<[Value; LANES]>,
    /// Each live pack's op and operands (beside `members`).
    pub shapes: Vec<Shape>,
    /// By value index: the live pack and lane of a member.
    pub of: HashMap<usize, (usize, usize)>,
}

/// A value's op as `a·b + c` with one rounding and the same bits (module doc, "Mixed packs"):
/// its orientations (a sum has two: either addend may be the product's `a`), or none when it
/// is not a product, sum, difference or fused intrinsic.
fn fma_forms(f: &Function, v: Value) -> Vec<[Arg; 3]> {
    let arg = |x: Operand| Arg { x, neg: false };
    let negated = |x: Operand| Arg { x, neg: true };
    let one = arg(Operand::Const(1.0));
    match &f.value(v).def {
        Def::Binary(BinOp::Mul, a, b) => vec![[arg(*a), arg(*b), arg(Operand::Const(-0.0))]],
        Def::Binary(BinOp::Add, a, b) => vec![[arg(*a), one, arg(*b)], [arg(*b), one, arg(*a)]],
        Def::Binary(BinOp::Sub, a, b) => vec![[arg(*a), one, negated(*b)], [negated(*b), one, arg(*a)]],
        Def::Call(c, x) => match Intrinsic::of(c, x.len()) {
            Some(Intrinsic::Fma) => vec![[arg(x[0]), arg(x[1]), arg(x[2])]],
            Some(Intrinsic::Fms) => vec![[arg(x[0]), arg(x[1]), negated(x[2])]],
            Some(Intrinsic::Fnma) => vec![[negated(x[0]), arg(x[1]), arg(x[2])]],
            _ => Vec::new(),
        },
        _ => Vec::new(),
    }
}

/// What an operand is, for lining up the lanes of a pack (never for what it computes): a
/// constant, an input, a trig variable or an op of one operator or intrinsic, with its name
/// up to its trailing indices (`Va` for `Va2_24`, the body or column index dropped).
fn signature(f: &Function, x: Operand) -> (u32, &str) {
    let Operand::Value(v) = x else { return (0, "") };
    let data = f.value(v);
    let kind = match &data.def {
        Def::Input => 1,
        Def::Trig(..) => 2,
        Def::Binary(op, ..) => 3 + *op as u32,
        Def::Call(c, a) => Intrinsic::of(c, a.len()).map_or(20, |i| 10 + i as u32),
        Def::Expr(_) => 21,
    };
    (kind, data.name.trim_end_matches(|c: char| c.is_ascii_digit() || "_.[]".contains(c)))
}

/// The orientation of lane `form` that matches `reference` in the most operand positions
/// (by [`signature`]); the first of equals.
fn best<'a, const N: usize>(f: &Function, reference: &[Arg; N], forms: &'a [[Arg; N]]) -> &'a [Arg; N] {
    let like = |form: &[Arg; N]| (0..N).filter(|&k| signature(f, form[k].x) == signature(f, reference[k].x)).count();
    forms.iter().rev().max_by_key(|form| like(form)).expect("at least one form")
}

/// The shape of four values as one pack: the same binary operator in every lane, or else, with
/// a fused intrinsic in one lane at least, each lane as `a·b + c`; `None` otherwise. Commutative operands (`+`, `×`, `a·b`)
/// and a sum's addends are put in the order that lines each lane up with lane 0 (as LLVM's
/// SLP vectoriser reorders the operands of commutative ops), so that their operands make
/// packs in turn.
pub(crate) fn shape(f: &Function, lanes: &[Value; LANES]) -> Option<Shape> {
    let binary = |v: Value| match f.value(v).def {
        Def::Binary(op, ..) => Some(op),
        _ => None,
    };
    if let Some(op) = binary(lanes[0]).filter(|&op| lanes.iter().all(|&v| binary(v) == Some(op))) {
        let arg = |x: Operand| Arg { x, neg: false };
        let forms: Vec<Vec<[Arg; 2]>> = lanes
            .iter()
            .map(|&v| {
                let o = f.value(v).def.operands();
                let mut forms = vec![[arg(o[0]), arg(o[1])]];
                if matches!(op, BinOp::Add | BinOp::Mul) {
                    forms.push([arg(o[1]), arg(o[0])]);
                }
                forms
            })
            .collect();
        let chosen: Vec<[Arg; 2]> = forms.iter().map(|x| *best(f, &forms[0][0], x)).collect();
        let args = (0..2).map(|k| [0, 1, 2, 3].map(|l| chosen[l][k])).collect();
        return Some(Shape { op: PackOp::Binary(op), args });
    }
    let fused = |v: Value| matches!(&f.value(v).def, Def::Call(c, a) if Intrinsic::of(c, a.len()).is_some_and(|i| i.is_fused()));
    let mut forms: Vec<Vec<[Arg; 3]>> = lanes.iter().map(|&v| fma_forms(f, v)).collect();
    if forms.iter().any(|x| x.is_empty()) {
        return None;
    }
    // `a·b` commutes; a negation stays with the product: `(−a)·b = (−b)·a`.
    for x in forms.iter_mut() {
        let swapped: Vec<[Arg; 3]> =
            x.iter().map(|[a, b, c]| [Arg { x: b.x, neg: a.neg }, Arg { x: a.x, neg: b.neg }, *c]).collect();
        x.extend(swapped);
    }
    let chosen: Vec<[Arg; 3]> = forms.iter().map(|x| *best(f, &forms[0][0], x)).collect();
    let args = (0..3).map(|k| [0, 1, 2, 3].map(|l| chosen[l][k])).collect();
    // Without a fused lane, a product then a sum (exact in each lane: `fma_forms` writes a
    // binary op with a factor 1 or an addend −0): on a target without FMA a vector FMA would
    // be four calls of C99 `fma`.
    let op = if lanes.iter().any(|&v| fused(v)) { PackOp::Fma } else { PackOp::MulAdd };
    Some(Shape { op, args })
}

/// The output name without its last index (`ddq_dq[3]` for `ddq_dq[3][7]`) and that index,
/// when it ends in `[N]`.
fn row_and_column(name: &str) -> Option<(&str, u64)> {
    let inner = name.strip_suffix(']')?;
    let open = inner.rfind('[')?;
    Some((&name[..open], inner[open + 1..].parse().ok()?))
}

/// Depth of the structure hashes that compare columns ([`isomorphic_seeds`]): ops this far
/// above an output count. Measured on the bench's robots: at 2, Solo-12's legs are found in
/// `rnea_derivatives` (at 4 no columns are equal any more: mirrored legs differ below).
const STRUCTURE_DEPTH: usize = 2;

/// Per value, a hash of its op tree down to [`STRUCTURE_DEPTH`] ops: at each node its class
/// (an input, a trig variable, a call, a division, or the multiply-add family as one: mirrored
/// limbs differ in signs, `+` for `−`, `@fma` for `@fms`, and a mixed pack takes them all),
/// constants' values and names left out, the operands of the family in any order. Equal trees
/// hash equal; O(values × depth).
fn structure_hashes(f: &Function) -> Vec<u64> {
    use std::hash::{Hash, Hasher};
    let n = f.values.len();
    let base: Vec<u64> = (0..n)
        .map(|i| {
            let v = Value::with_number(i as u32);
            let class = if fma_forms(f, v).is_empty() { signature(f, Operand::Value(v)).0 } else { 100 };
            let mut h = std::collections::hash_map::DefaultHasher::new();
            class.hash(&mut h);
            h.finish()
        })
        .collect();
    let mut hash = base.clone();
    for _ in 0..STRUCTURE_DEPTH {
        let mut next = base.clone();
        for &v in &f.body {
            let def = &f.value(v).def;
            let mut children: Vec<u64> = def
                .operands()
                .iter()
                .map(|x| match x {
                    Operand::Value(w) => hash[w.index()],
                    Operand::Const(_) => 0,
                })
                .collect();
            if !fma_forms(f, v).is_empty() {
                children.sort_unstable();
            }
            let mut h = std::collections::hash_map::DefaultHasher::new();
            (base[v.index()], children).hash(&mut h);
            next[v.index()] = h.finish();
        }
        hash = next;
    }
    hash
}

/// Seeds across isomorphic columns: the legs of a quadruped, the fingers of a hand. A
/// column's *profile* is the structure hashes ([`structure_hashes`]) of its entries in every
/// matrix `X[i][j]` of the outputs; columns of equal profile are taken four at a time in index
/// order as *lane groups* (lane `l` the `l`-th), rows grouped alike. A seed is one entry per
/// lane: `X[r_l][c_l]` for a row group and a column group (the legs' diagonal blocks), then
/// `X[i][c_l]` for every row `i` and `X[r_l][j]` for every column `j` (a value already in a
/// pack is not packed again). Outputs of one index, or columns all different, give none.
fn isomorphic_seeds(f: &Function) -> Vec<[Value; LANES]> {
    let mut at: HashMap<(&str, u64, u64), Value> = HashMap::new();
    let mut entries: Vec<(&str, u64, u64, Value)> = Vec::new();
    for o in &f.outputs {
        let Some((row, j)) = row_and_column(&o.name) else { continue };
        let Some((x, i)) = row_and_column(row) else { continue };
        let Operand::Value(v) = o.value else { continue };
        at.insert((x, i, j), v);
        entries.push((x, i, j, v));
    }
    if entries.is_empty() {
        return Vec::new();
    }
    let hash = structure_hashes(f);
    let mut profile: std::collections::BTreeMap<u64, Vec<(&str, u64)>> = Default::default();
    for &(x, _, j, v) in &entries {
        profile.entry(j).or_default().push((x, hash[v.index()]));
    }
    let mut by_profile: HashMap<Vec<(&str, u64)>, Vec<u64>> = HashMap::new();
    let mut order: Vec<Vec<(&str, u64)>> = Vec::new();
    for (j, mut p) in profile {
        p.sort_unstable();
        if !by_profile.contains_key(&p) {
            order.push(p.clone());
        }
        by_profile.entry(p).or_default().push(j);
    }
    let mut groups: Vec<[u64; LANES]> = Vec::new();
    for p in &order {
        for chunk in by_profile[p].chunks_exact(LANES) {
            groups.push([chunk[0], chunk[1], chunk[2], chunk[3]]);
        }
    }
    if groups.is_empty() {
        return Vec::new();
    }
    let mut matrices: Vec<&str> = entries.iter().map(|e| e.0).collect();
    matrices.sort_unstable();
    matrices.dedup();
    let mut lines: Vec<(&str, u64, bool)> = Vec::new();
    for &(x, i, j, _) in &entries {
        lines.push((x, i, true));
        lines.push((x, j, false));
    }
    lines.sort_unstable();
    lines.dedup();
    let mut seeds = Vec::new();
    let mut push = |x: &str, rows: [u64; LANES], cols: [u64; LANES]| {
        let lanes: Option<Vec<Value>> = (0..LANES).map(|l| at.get(&(x, rows[l], cols[l])).copied()).collect();
        if let Some(l) = lanes {
            seeds.push([l[0], l[1], l[2], l[3]]);
        }
    };
    for &x in &matrices {
        for rows in &groups {
            for cols in &groups {
                push(x, *rows, *cols);
            }
        }
    }
    for &(x, k, is_row) in &lines {
        for g in &groups {
            if is_row {
                push(x, [k; LANES], *g);
            } else {
                push(x, *g, [k; LANES]);
            }
        }
    }
    seeds
}

impl Packs {
    /// The packs of `f` (module doc). Only for one state of `double`s without numeric formats:
    /// the caller checks.
    pub(crate) fn find(f: &Function) -> Packs {
        let isomorphic = isomorphic_seeds(f);
        let consecutive = Packs::find_from(f, Vec::new());
        if isomorphic.is_empty() {
            return consecutive;
        }
        let across = Packs::find_from(f, isomorphic);
        if across.members.len() > consecutive.members.len() {
            across
        } else {
            consecutive
        }
    }

    /// [`Packs::find`] from `seeds` first, then the consecutive columns' seeds.
    fn find_from(f: &Function, mut seeds: Vec<[Value; LANES]>) -> Packs {
        let n = f.values.len();
        let mut pos = vec![usize::MAX; n];
        for (p, v) in f.body.iter().enumerate() {
            pos[v.index()] = p;
        }
        let mut claimed: Vec<Option<usize>> = vec![None; n];
        let mut packs: Vec<[Value; LANES]> = Vec::new();
        let mut shapes: Vec<Shape> = Vec::new();
        // A candidate: four distinct ops of one shape, none claimed, in the body.
        let fits = |lanes: &[Value; LANES], claimed: &[Option<usize>]| -> Option<Shape> {
            let free = lanes.iter().all(|&v| claimed[v.index()].is_none() && pos[v.index()] != usize::MAX)
                && (0..LANES).all(|a| (a + 1..LANES).all(|b| lanes[a] != lanes[b]));
            if free {
                shape(f, lanes)
            } else {
                None
            }
        };
        // Seeds: first four isomorphic columns' entries (`isomorphic_seeds`); then four outputs
        // in a row of a matrix, consecutive columns, the first a multiple of
        // four columns from the first column of any matrix (every row cut at the same columns,
        // so that the rows' packs read the same packs of per-column values).
        let outs = &f.outputs;
        let first = outs.iter().filter_map(|o| row_and_column(&o.name)).map(|(_, c)| c).min().unwrap_or(0);
        let mut i = 0;
        while i + LANES <= outs.len() {
            let group: Option<[Value; LANES]> = (|| {
                let (row, c0) = row_and_column(&outs[i].name)?;
                if (c0 - first) % LANES as u64 != 0 {
                    return None;
                }
                let mut lanes = [Value::with_number(0); LANES];
                for (l, lane) in lanes.iter_mut().enumerate() {
                    let (r, c) = row_and_column(&outs[i + l].name)?;
                    if r != row || c != c0 + l as u64 {
                        return None;
                    }
                    let Operand::Value(v) = outs[i + l].value else { return None };
                    *lane = v;
                }
                Some(lanes)
            })();
            match group {
                Some(g) => {
                    seeds.push(g);
                    i += LANES;
                }
                None => i += 1,
            }
        }
        // Build from the seeds, breadth first (no recursion: chains are thousands of ops deep).
        let mut work: std::collections::VecDeque<[Value; LANES]> = seeds.into();
        while let Some(lanes) = work.pop_front() {
            let Some(sh) = fits(&lanes, &claimed) else { continue };
            let id = packs.len();
            for v in lanes {
                claimed[v.index()] = Some(id);
            }
            for k in 0..sh.args.len() {
                let g = sh.operands(k);
                if g.iter().all(|x| *x == g[0]) {
                    continue;
                }
                if let [Operand::Value(a), Operand::Value(b), Operand::Value(c), Operand::Value(d)] = g {
                    work.push_back([a, b, c, d]);
                }
            }
            packs.push(lanes);
            shapes.push(sh);
        }
        // Drop packs with more than one gathered operand position, children (built later) first.
        // Four equal operands are one scalar, four constants one vector constant: neither is
        // gathered.
        let mut live = vec![true; packs.len()];
        let is_pack_operand = |group: &[Operand; LANES], claimed: &[Option<usize>], live: &[bool]| -> bool {
            let Operand::Value(first) = group[0] else { return false };
            let Some(q) = claimed[first.index()] else { return false };
            live[q] && group.iter().enumerate().all(|(l, x)| *x == Operand::Value(packs[q][l]))
        };
        for id in (0..packs.len()).rev() {
            let gathered = (0..shapes[id].args.len())
                .filter(|&k| {
                    let g = shapes[id].operands(k);
                    !g.iter().all(|x| *x == g[0])
                        && !g.iter().all(|x| matches!(x, Operand::Const(_)))
                        && !is_pack_operand(&g, &claimed, &live)
                })
                .count();
            if gathered > 1 {
                live[id] = false;
            }
        }
        // Readers of every value (value index → readers), once.
        let mut readers: Vec<Vec<Value>> = vec![Vec::new(); n];
        for &v in &f.body {
            f.value(v).def.for_each_value(|a| {
                if readers[a.index()].last() != Some(&v) {
                    readers[a.index()].push(v)
                }
            });
        }
        // Dissolve packs read too early, until none is. A worklist: a pack dissolved makes its
        // members read their operands where they stand, so only the packs of those operands are
        // looked at again (each pack is dissolved once: linear in members and their readers).
        let at = |id: usize| packs[id].iter().map(|v| pos[v.index()]).max().expect("four members");
        let mut work: Vec<usize> = (0..packs.len()).filter(|&id| live[id]).collect();
        while let Some(id) = work.pop() {
            if !live[id] {
                continue;
            }
            let here = at(id);
            let early = packs[id].iter().enumerate().any(|(lane, m)| {
                readers[m.index()].iter().any(|&r| {
                    let reader_pack = claimed[r.index()].filter(|&q| live[q]);
                    let when = reader_pack.map_or(pos[r.index()], at);
                    if let Some(q) = reader_pack {
                        // Read lane for lane as a whole operand of pack q: ordered by construction.
                        let lane_of_r = packs[q].iter().position(|x| *x == r).expect("a member");
                        let whole = lane_of_r == lane
                            && (0..shapes[q].args.len()).any(|k| {
                                shapes[q].args[k][lane].x == Operand::Value(*m)
                                    && is_pack_operand(&shapes[q].operands(k), &claimed, &live)
                            });
                        if whole {
                            return false;
                        }
                    }
                    when <= here
                })
            });
            if early {
                live[id] = false;
                for m in packs[id] {
                    f.value(m).def.for_each_value(|x| {
                        if let Some(q) = claimed[x.index()].filter(|&q| live[q]) {
                            work.push(q);
                        }
                    });
                }
            }
        }
        let mut out = Packs::default();
        for ((id, lanes), sh) in packs.into_iter().enumerate().zip(shapes) {
            if live[id] {
                let new = out.members.len();
                for (l, v) in lanes.iter().enumerate() {
                    out.of.insert(v.index(), (new, l));
                }
                out.members.push(lanes);
                out.shapes.push(sh);
            }
        }
        out
    }

    /// True when `group` (one operand position of a pack's four members) is live pack `q`'s
    /// members lane for lane; `Some(q)` then.
    pub(crate) fn whole(&self, group: &[Operand]) -> Option<usize> {
        let Operand::Value(first) = group[0] else { return None };
        let &(q, 0) = self.of.get(&first.index())? else { return None };
        group.iter().enumerate().all(|(l, x)| *x == Operand::Value(self.members[q][l])).then_some(q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Function {
        let m = robovec_ir::text::parse(text).expect("valid text");
        m.functions.into_iter().next().expect("one function")
    }

    /// The names of each pack's members, lane 0 first.
    fn member_names(f: &Function, p: &Packs) -> Vec<Vec<String>> {
        p.members.iter().map(|m| m.iter().map(|&v| f.value(v).name.clone()).collect()).collect()
    }

    /// Four columns of `y = a·x + b` (shared `a`, `b`): one pack of the sums whose products are
    /// a pack too, `a` and `b` broadcast.
    #[test]
    fn isomorphic_columns_pack_and_an_early_reader_dissolves() {
        let mut t = String::from("func @f {\n  phase atomised\n  input %a\n  input %b\n");
        for j in 1..=4 {
            t += &format!("  input %x{j}\n");
        }
        for j in 1..=4 {
            t += &format!("  %p{j} = mul %a, %x{j}\n  %y{j} = add %p{j}, %b\n");
        }
        for j in 1..=4 {
            t += &format!("  output y[1][{j}] = %y{j}\n");
        }
        t += "}\n";
        let f = parse(&t);
        let p = Packs::find(&f);
        assert_eq!(p.members.len(), 2, "{p:?}");
        let sets = member_names(&f, &p);
        assert!(sets.contains(&vec!["y1".into(), "y2".into(), "y3".into(), "y4".into()]));
        assert!(sets.contains(&vec!["p1".into(), "p2".into(), "p3".into(), "p4".into()]));
        // `p1` read by a scalar op before the products' pack is complete (`p4`): the products are
        // scalars again, the sums stay a pack (one gathered operand).
        let early = t
            .replace("  %y1 = add %p1, %b\n", "  %y1 = add %p1, %b\n  %z = mul %p1, %p1\n")
            .replace("  output y[1][1]", "  output z = %z\n  output y[1][1]");
        let f = parse(&early);
        let p = Packs::find(&f);
        let sets = member_names(&f, &p);
        assert_eq!(sets, vec![vec!["y1".to_string(), "y2".into(), "y3".into(), "y4".into()]]);
    }

    /// Four columns whose ops differ (a fused multiply-add, a product, a sum, a difference) have
    /// one shape of `a·b + c` forms: the product with `−0`, the sum and the difference through
    /// `1`, a difference's subtrahend negated; with a division they have none. (Packed only
    /// where their operands are packs too: `tests/codegen_c.rs` runs such code.)
    #[test]
    fn mixed_columns_pack_as_fused_multiply_adds() {
        let text = "func @f {\n  phase atomised\n  input %a\n  input %c\n  input %x1\n  input %x2\n  \
                    input %x3\n  input %x4\n  %y1 = call @fma(%a, %x1, %c)\n  %y2 = mul %a, %x2\n  \
                    %y3 = add %x3, %c\n  %y4 = sub %x4, %c\n  output y[1][1] = %y1\n  output y[1][2] = %y2\n  \
                    output y[1][3] = %y3\n  output y[1][4] = %y4\n}\n";
        let f = parse(text);
        let lanes = |f: &Function| ["y1", "y2", "y3", "y4"].map(|y| f.lookup(y).expect("a value"));
        let sh = shape(&f, &lanes(&f)).expect("one shape");
        assert_eq!(sh.op, PackOp::Fma);
        let v = |name: &str| Operand::Value(f.lookup(name).expect("a value"));
        let arg = |x: Operand, neg: bool| Arg { x, neg };
        let k = |c: f64| Operand::Const(c);
        // The sum and the difference as `1·x + …`: their `x` lines up with lane 0's `x1`.
        assert_eq!(sh.args[0], [arg(v("a"), false), arg(v("a"), false), arg(k(1.0), false), arg(k(1.0), false)]);
        assert_eq!(sh.args[1], [arg(v("x1"), false), arg(v("x2"), false), arg(v("x3"), false), arg(v("x4"), false)]);
        assert_eq!(sh.args[2][..2], [arg(v("c"), false), arg(k(-0.0), false)]);
        assert!(matches!(sh.args[2][1].x, Operand::Const(z) if z == 0.0 && z.is_sign_negative()), "−0, not +0");
        assert_eq!(sh.args[2][2..], [arg(v("c"), false), arg(v("c"), true)]);
        let f = parse(&text.replace("%y4 = sub %x4, %c", "%y4 = div %x4, %c"));
        assert!(shape(&f, &lanes(&f)).is_none());
    }

    /// Two rows over the same per-column products `p_j`: row 1 from column 1, row 2 from
    /// column 2. Seeds are cut at columns 1 and 5 in both rows, so row 2's pack of columns
    /// 5..8 reads the products' pack of row 1 whole (cut from column 2, it would gather
    /// `p2..p5`); in row 2 the product's operands are written the other way round in two
    /// lanes and are lined up with lane 0.
    #[test]
    fn rows_are_cut_at_the_same_columns_and_commutative_operands_line_up() {
        let mut t = String::from("func @f {\n  phase atomised\n  input %a\n  input %b\n");
        for j in 1..=8 {
            t += &format!("  input %x{j}\n  %p{j} = mul %x{j}, %a\n  %y{j} = add %p{j}, %a\n");
        }
        for j in 2..=8 {
            let z = if j % 2 == 0 { format!("mul %b, %p{j}") } else { format!("mul %p{j}, %b") };
            t += &format!("  %z{j} = {z}\n");
        }
        for j in 1..=8 {
            t += &format!("  output y[1][{j}] = %y{j}\n");
        }
        for j in 2..=8 {
            t += &format!("  output y[2][{j}] = %z{j}\n");
        }
        t += "}\n";
        let f = parse(&t);
        let p = Packs::find(&f);
        let name = |v: Value| f.value(v).name.clone();
        let sets = member_names(&f, &p);
        let want = |xs: [&str; 4]| xs.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        for set in [["y1", "y2", "y3", "y4"], ["y5", "y6", "y7", "y8"], ["z5", "z6", "z7", "z8"]] {
            assert!(sets.contains(&want(set)), "{sets:?}");
        }
        assert!(sets.contains(&want(["p5", "p6", "p7", "p8"])), "{sets:?}");
        let z = sets.iter().position(|s| s[0] == "z5").expect("the pack of z5..z8");
        let sh = &p.shapes[z];
        let (products, scalars) =
            if matches!(sh.args[0][0].x, Operand::Value(v) if name(v) == "p5") { (0, 1) } else { (1, 0) };
        assert!(p.whole(&sh.operands(products)).is_some(), "{sh:?}");
        assert!(sh.operands(scalars).iter().all(|x| matches!(x, Operand::Value(v) if name(*v) == "b")), "{sh:?}");
        assert!(!sets.iter().any(|s| s.contains(&"z2".to_string())), "z2..z4 is three columns");
    }

    /// Columns that alternate between two structures (a product, a quotient): four
    /// consecutive ones are no pack, the odd and the even columns are (isomorphic seeds).
    #[test]
    fn isomorphic_columns_pack_across_the_row() {
        let mut t = String::from("func @f {\n  phase atomised\n  input %a\n");
        for j in 1..=8 {
            let op = if j % 2 == 1 { format!("mul %a, %x{j}") } else { format!("div %x{j}, %a") };
            t += &format!("  input %x{j}\n  %y{j} = {op}\n");
        }
        for j in 1..=8 {
            t += &format!("  output y[1][{j}] = %y{j}\n");
        }
        t += "}\n";
        let f = parse(&t);
        let p = Packs::find(&f);
        let sets = member_names(&f, &p);
        assert_eq!(sets.len(), 2, "{sets:?}");
        for set in [["y1", "y3", "y5", "y7"], ["y2", "y4", "y6", "y8"]] {
            assert!(sets.contains(&set.iter().map(|x| x.to_string()).collect()), "{sets:?}");
        }
    }

    /// Different operators, or fewer than four columns in a row, make no pack.
    #[test]
    fn no_pack_without_four_isomorphic_columns() {
        let f = parse(
            "func @f {\n  phase atomised\n  input %a\n  input %x1\n  input %x2\n  input %x3\n  input %x4\n  \
             %y1 = mul %a, %x1\n  %y2 = mul %a, %x2\n  %y3 = add %a, %x3\n  %y4 = mul %a, %x4\n  \
             output y[1][1] = %y1\n  output y[1][2] = %y2\n  output y[1][3] = %y3\n  output y[1][4] = %y4\n}\n",
        );
        assert!(Packs::find(&f).members.is_empty());
        let f = parse(
            "func @f {\n  phase atomised\n  input %a\n  input %x1\n  input %x2\n  input %x3\n  input %x4\n  \
             %y1 = mul %a, %x1\n  %y2 = mul %a, %x2\n  %y3 = mul %a, %x3\n  %y4 = mul %a, %x4\n  \
             output y[1][1] = %y1\n  output y[1][2] = %y2\n  output y[2][3] = %y3\n  output y[2][4] = %y4\n}\n",
        );
        assert!(Packs::find(&f).members.is_empty());
    }
}
