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
//! **Packs.** A *pack* is four values in lane order, all binary ops of the same operator or all
//! the same fused multiply-add intrinsic (`@fma`, `@fms`, `@fnma`), distinct, each in at most one
//! pack. Seeds are the outputs in their order, four at a time among those named `X[…][j]` that
//! differ in the last index only (a row of a matrix, four consecutive columns). From a pack, each
//! operand position gives four operands: equal ones are *broadcast* (a scalar, which the C
//! vector extensions spread over the lanes), four ops of one kind become a pack in turn, and
//! anything else is *gathered* lane by lane. A pack with more than one gathered operand position
//! costs more than its four scalar ops and is dropped (children first, so a parent sees what its
//! children became).
//!
//! **Order.** A pack is written where its last member is in the body; its members are read as
//! scalars from there on. A pack is kept only when every reader of a member that is not a pack
//! taking the whole pack lane for lane as one operand comes later (in the body, or as a pack,
//! where its own last member is); the others are dissolved, until none is left to dissolve (a
//! dissolved pack's members are scalars again, where they were).
//!
//! **Bits.** Every lane computes the scalar op of its member on that member's operands, so the
//! code computes bit for bit what the one-state code computes (the fused ops through one vector
//! FMA instruction where the target has one, C99 `fma` per lane otherwise).
//!
//! Cost: O(values + operands) to seed and build (each value is claimed once) and to dissolve
//! (each pack is dissolved once; a dissolution looks again at the packs of its members'
//! operands only).

use std::collections::HashMap;

use robovec_ir::{Def, Function, Intrinsic, Operand, Value};

/// Lanes of a pack.
pub(crate) const LANES: usize = 4;

/// The packs of one function.
#[derive(Debug, Default)]
pub(crate) struct Packs {
    /// Each live pack's members, lane 0 first.
    pub members: Vec<[Value; LANES]>,
    /// By value index: the live pack and lane of a member.
    pub of: HashMap<usize, (usize, usize)>,
}

/// What a value's op is, for isomorphism: the binary operator or the fused intrinsic.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    Binary(robovec_ir::BinOp),
    Fused(Intrinsic),
}

fn kind(f: &Function, v: Value) -> Option<Kind> {
    match &f.value(v).def {
        Def::Binary(op, ..) => Some(Kind::Binary(*op)),
        Def::Call(c, args) => Intrinsic::of(c, args.len()).filter(|i| i.is_fused()).map(Kind::Fused),
        _ => None,
    }
}

fn operands(f: &Function, v: Value) -> Vec<Operand> {
    f.value(v).def.operands()
}

/// Operand position `k` of four values, lane by lane.
pub(crate) fn operand_group(f: &Function, lanes: &[Value; LANES], k: usize) -> Vec<Operand> {
    lanes.iter().map(|&v| operands(f, v)[k]).collect()
}

/// The output name without its last index (`ddq_dq[3]` for `ddq_dq[3][7]`) and that index,
/// when it ends in `[N]`.
fn row_and_column(name: &str) -> Option<(&str, u64)> {
    let inner = name.strip_suffix(']')?;
    let open = inner.rfind('[')?;
    Some((&name[..open], inner[open + 1..].parse().ok()?))
}

impl Packs {
    /// The packs of `f` (module doc). Only for one state of `double`s without numeric formats:
    /// the caller checks.
    pub(crate) fn find(f: &Function) -> Packs {
        let n = f.values.len();
        let mut pos = vec![usize::MAX; n];
        for (p, v) in f.body.iter().enumerate() {
            pos[v.index()] = p;
        }
        let mut claimed: Vec<Option<usize>> = vec![None; n];
        let group = |lanes: &[Value; LANES], k: usize| operand_group(f, lanes, k);
        let mut packs: Vec<[Value; LANES]> = Vec::new();
        // A candidate: four distinct ops of one kind, none claimed.
        let fits = |lanes: &[Value; LANES], claimed: &[Option<usize>]| {
            let k = kind(f, lanes[0]);
            k.is_some()
                && lanes
                    .iter()
                    .all(|&v| kind(f, v) == k && claimed[v.index()].is_none() && pos[v.index()] != usize::MAX)
                && (0..LANES).all(|a| (a + 1..LANES).all(|b| lanes[a] != lanes[b]))
        };
        // Seeds: four outputs in a row of a matrix, consecutive columns.
        let mut seeds: Vec<[Value; LANES]> = Vec::new();
        let outs = &f.outputs;
        let mut i = 0;
        while i + LANES <= outs.len() {
            let group: Option<[Value; LANES]> = (|| {
                let (row, c0) = row_and_column(&outs[i].name)?;
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
            if !fits(&lanes, &claimed) {
                continue;
            }
            let id = packs.len();
            for v in lanes {
                claimed[v.index()] = Some(id);
            }
            packs.push(lanes);
            for k in 0..operands(f, lanes[0]).len() {
                let g = group(&lanes, k);
                if g.iter().all(|x| *x == g[0]) {
                    continue;
                }
                if let [Operand::Value(a), Operand::Value(b), Operand::Value(c), Operand::Value(d)] = g[..] {
                    work.push_back([a, b, c, d]);
                }
            }
        }
        // Drop packs with more than one gathered operand position, children (built later) first.
        let mut live = vec![true; packs.len()];
        let is_pack_operand = |group: &[Operand], claimed: &[Option<usize>], live: &[bool]| -> bool {
            let Operand::Value(first) = group[0] else { return false };
            let Some(q) = claimed[first.index()] else { return false };
            live[q] && group.iter().enumerate().all(|(l, x)| *x == Operand::Value(packs[q][l]))
        };
        for id in (0..packs.len()).rev() {
            let gathered = (0..operands(f, packs[id][0]).len())
                .filter(|&k| {
                    let g = group(&packs[id], k);
                    !g.iter().all(|x| *x == g[0]) && !is_pack_operand(&g, &claimed, &live)
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
                            && operands(f, r).iter().enumerate().any(|(k, x)| {
                                *x == Operand::Value(*m) && is_pack_operand(&group(&packs[q], k), &claimed, &live)
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
        for (id, lanes) in packs.into_iter().enumerate() {
            if live[id] {
                let new = out.members.len();
                for (l, v) in lanes.iter().enumerate() {
                    out.of.insert(v.index(), (new, l));
                }
                out.members.push(lanes);
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
        let name = |v: Value| f.value(v).name.clone();
        let sets: Vec<Vec<String>> = p.members.iter().map(|m| m.iter().map(|&v| name(v)).collect()).collect();
        assert!(sets.contains(&vec!["y1".into(), "y2".into(), "y3".into(), "y4".into()]));
        assert!(sets.contains(&vec!["p1".into(), "p2".into(), "p3".into(), "p4".into()]));
        // `p1` read by a scalar op before the products' pack is complete (`p4`): the products are
        // scalars again, the sums stay a pack (one gathered operand).
        let early = t
            .replace("  %y1 = add %p1, %b\n", "  %y1 = add %p1, %b\n  %z = mul %p1, %p1\n")
            .replace("  output y[1][1]", "  output z = %z\n  output y[1][1]");
        let f = parse(&early);
        let p = Packs::find(&f);
        let sets: Vec<Vec<String>> =
            p.members.iter().map(|m| m.iter().map(|&v| f.value(v).name.clone()).collect()).collect();
        assert_eq!(sets, vec![vec!["y1".to_string(), "y2".into(), "y3".into(), "y4".into()]]);
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
