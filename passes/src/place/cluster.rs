//! PE clusters (`place<clusters=G>`): the PEs split into G clusters, the ops partitioned into G
//! parts with few values crossing between them, and each op bound to its part's cluster.
//!
//! Why (issue 49): the specialised interconnect of `codegen<fpga>` has a multiplexer input per
//! route (a source, PE result or buffer read, written into a PE memory). The list scheduler
//! binds each op to whatever PE of its type is free, so on a saturated array every memory ends
//! up receiving from almost every PE: WALK-MAN's `dirdyna` at 29 + 29 PEs had 3,112 inputs for
//! 58 memories, three quarters of the design's logic. Its data-flow graph is local, though: cut
//! into 58 parts by METIS, 86 % of its operand edges stay inside a part and a part reads from
//! 9 others on average. Binding each part to its own PEs makes the interconnect follow that
//! locality — a clustered VLIW's cluster assignment before scheduling (Capitanio, Dutt &
//! Nicolau, MICRO 1992), with a graph partitioner (METIS, Karypis & Kumar 1998) choosing the
//! parts.
//!
//! The partition: ops are the vertices, operand edges (undirected, counted once) the edges;
//! two balance constraints, ADD-side and MULTI-side ops (a fixed-point fused multiply-add is a
//! MULTI op), each part's share that of its cluster's PEs of the side; METIS' k-way
//! partitioning with the minimum-connectivity objective (`MINCONN`: the fewest neighbouring
//! parts, i.e. the fewest sources per memory), a fixed seed (deterministic). Cluster `c` holds
//! the PEs `i` of each side with `⌊i·G/N⌋ = c` ([`pe_cluster`]).
//!
//! Cost: METIS' multilevel partitioning, O(ops + edges) per level; the schedulers then keep a
//! ready list per cluster and side.

use super::dag::{Node, OpDag};

/// The cluster of the `i`-th PE of a side of `n` PEs among `g` clusters (`⌊i·g/n⌋`: the
/// clusters' sizes differ by at most one).
pub fn pe_cluster(i: u32, n: u32, g: u32) -> u32 {
    if n == 0 {
        0
    } else {
        (u64::from(i) * u64::from(g) / u64::from(n)) as u32
    }
}

/// The PEs (indices `i` of a side of `n`) of cluster `c` of `g`: those with
/// [`pe_cluster`]`(i, n, g) = c`, in increasing order.
pub fn pes_in(c: u32, n: u32, g: u32) -> impl Iterator<Item = u32> {
    (0..n).filter(move |&i| pe_cluster(i, n, g) == c)
}

/// Whether `g` clusters fit `n_add` ADD and `n_mul` MULTI PEs: every cluster needs a PE of each
/// side, so `g ≤ min(n_add, n_mul)`.
///
/// # Errors
/// The limit and the PE counts, as text (`clusters=G: at most the smaller side's PEs …`).
pub fn check(g: u32, n_add: u32, n_mul: u32) -> Result<(), String> {
    if g > n_add.min(n_mul) {
        return Err(format!(
            "clusters={g}: at most the smaller side's PEs ({}: add={n_add}, mul={n_mul}); every cluster has an ADD \
             and a MULTI PE",
            n_add.min(n_mul)
        ));
    }
    Ok(())
}

/// The shape of a partition: the PEs of each side, the clusters, and the time windows each
/// cluster's share is balanced over (`place<add=A;mul=M;clusters=G;windows=W>`).
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    /// ADD PEs.
    pub n_add: u32,
    /// MULTI PEs.
    pub n_mul: u32,
    /// Clusters (parts), `G`.
    pub clusters: u32,
    /// Time windows, `W ≥ 1`.
    pub windows: u32,
}

/// METIS' load imbalance tolerance of a side's whole load: its default.
pub const SIDE_IMBALANCE: metis::Real = 1.03;

/// METIS' load imbalance tolerance of a side's ops in one time window: looser than the whole
/// load's, since a window's share need only be about right for the list scheduler to spread it
/// (each cluster's whole load stays within 3 %). On the MX-5's `dirdyna` at 81 + 81 PEs in 27
/// clusters with 4 windows, 1.2 gives 131 cycles and 2,527 multiplexer inputs, 1.5 132 and
/// 2,393; with 2 windows, 140 and 2,173 against 136 and 2,295.
pub const WINDOW_IMBALANCE: metis::Real = 1.2;

/// The time window of each node (`0..windows`): per side, the nodes in increasing latest start
/// (`alap`, indexed by node; ties by node) split into `windows` runs of equal count.
pub fn time_windows(dag: &OpDag, alap: &[u32], windows: u32) -> Vec<u32> {
    let mut window = vec![0u32; dag.len()];
    for mul in [false, true] {
        let mut side: Vec<Node> = (0..dag.len() as Node).filter(|&j| dag.is_mul(j) == mul).collect();
        side.sort_unstable_by_key(|&j| (alap[j as usize], j));
        let m = side.len().max(1) as u64;
        for (i, &j) in side.iter().enumerate() {
            window[j as usize] = (i as u64 * u64::from(windows) / m) as u32;
        }
    }
    window
}

/// The part of each node of `dag` (indexed by [`Node`], `0..G`) for the clusters of `shape`.
/// All zeros for `G = 1` or fewer ops than `2·G`.
///
/// Balance: one constraint per side that has ops, its whole load (within 3 %); with `W > 1`
/// windows also one per side and time window ([`time_windows`] of the nodes' latest starts
/// `alap`, indexed by node) that has ops (within 20 %, [`WINDOW_IMBALANCE`]). Each part's
/// target share of every constraint is its cluster's share of that side's PEs. The windows
/// give a cluster its share of the ops due in each stretch of cycles, so that the ops the list
/// scheduler wants at once do not queue on a few clusters while the others idle, at the price
/// of a partition with more values crossing: the MX-5's `dirdyna` at 81 + 81 PEs in 27
/// clusters (`steal=16`) takes 156 cycles with one window (1,854 multiplexer inputs), 140 with
/// two (2,173), 131 with four (2,527); unclustered, 129 (4,794).
///
/// # Errors
/// [`check`]'s, or METIS' own failure (out of memory, or a graph it rejects), as text.
pub fn partition(dag: &OpDag, alap: &[u32], shape: Shape) -> Result<Vec<u32>, String> {
    let Shape { n_add, n_mul, clusters: g, windows } = shape;
    check(g, n_add, n_mul)?;
    let n = dag.len();
    if g <= 1 || n < 2 * g as usize {
        return Ok(vec![0; n]);
    }
    // Undirected adjacency in compressed rows (METIS wants both directions, no self-loops,
    // no repeated neighbour).
    let mut degree = vec![0 as metis::Idx; n];
    for j in 0..n as Node {
        for a in dag.distinct_operands(j) {
            degree[j as usize] += 1;
            degree[a as usize] += 1;
        }
    }
    let mut xadj = Vec::with_capacity(n + 1);
    xadj.push(0 as metis::Idx);
    for d in &degree {
        xadj.push(xadj.last().copied().unwrap_or(0) + d);
    }
    let mut fill: Vec<metis::Idx> = xadj[..n].to_vec();
    let mut adjncy = vec![0 as metis::Idx; xadj[n] as usize];
    for j in 0..n as Node {
        for a in dag.distinct_operands(j) {
            adjncy[fill[j as usize] as usize] = a as metis::Idx;
            fill[j as usize] += 1;
            adjncy[fill[a as usize] as usize] = j as metis::Idx;
            fill[a as usize] += 1;
        }
    }
    // Balance constraints: per side that has ops, its whole load (`None`), then with windows
    // per side and window that has ops.
    let window = time_windows(dag, alap, windows.max(1));
    let mut cons: Vec<(bool, Option<u32>)> = (0..n as Node)
        .flat_map(|j| {
            let mul = dag.is_mul(j);
            [Some((mul, None)), (windows > 1).then_some((mul, Some(window[j as usize])))]
        })
        .flatten()
        .collect();
    cons.sort_unstable();
    cons.dedup();
    let ncon = cons.len();
    let mut vwgt = vec![0 as metis::Idx; n * ncon];
    for j in 0..n as Node {
        for (k, &(mul, w)) in cons.iter().enumerate() {
            if mul == dag.is_mul(j) && w.is_none_or(|w| w == window[j as usize]) {
                vwgt[j as usize * ncon + k] = 1;
            }
        }
    }
    let mut tpwgts = vec![0.0 as metis::Real; g as usize * ncon];
    for c in 0..g {
        for (k, &(mul, _)) in cons.iter().enumerate() {
            let pes = if mul { n_mul } else { n_add };
            tpwgts[c as usize * ncon + k] = pes_in(c, pes, g).count() as metis::Real / pes as metis::Real;
        }
    }
    let ubvec: Vec<metis::Real> =
        cons.iter().map(|&(_, w)| if w.is_some() { WINDOW_IMBALANCE } else { SIDE_IMBALANCE }).collect();
    let mut part = vec![0 as metis::Idx; n];
    metis::Graph::new(ncon as metis::Idx, g as metis::Idx, &xadj, &adjncy)
        .map_err(|e| format!("METIS: {e}"))?
        .set_vwgt(&vwgt)
        .set_tpwgts(&tpwgts)
        .set_ubvec(&ubvec)
        .set_option(metis::option::MinConn(true))
        .set_option(metis::option::Seed(1))
        .part_kway(&mut part)
        .map_err(|e| format!("METIS: {e}"))?;
    Ok(part.into_iter().map(|p| p as u32).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clusters_split_a_side_within_one_pe() {
        for n in 1..40 {
            for g in 1..=n {
                let sizes: Vec<u32> = (0..g).map(|c| pes_in(c, n, g).count() as u32).collect();
                assert_eq!(sizes.iter().sum::<u32>(), n);
                assert!(sizes.iter().max().unwrap() - sizes.iter().min().unwrap() <= 1, "{n} {g}: {sizes:?}");
            }
        }
    }
}
