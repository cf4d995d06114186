//! The dependence structure of a function's ops that the list schedulers ([`super::schedule`],
//! the feeding priority [`super::feed`], the search) share, and their priority [`Key`].
//!
//! Ops are numbered densely as **nodes** `0..len()`, in the order the DAG is built with:
//! [`OpDag::new`] keeps body order, [`OpDag::ordered`] sorts by priority keys. The schedulers
//! keep every per-op array (keys, issue, arrival, pending operands, memories written) indexed
//! by node, so that with [`OpDag::ordered`] by the seed's keys, consecutive ops taken from the
//! ready lists touch neighbouring memory: on 2.4M ops (WALK-MAN × 64) indexing by value made
//! every access to those arrays a cache miss, and the list scheduler's time per op grew 2.7×
//! from 37k ops (issue 28).

use robovec_ir::{Function, OpKind, Operand, Value};

/// A priority key: smaller is scheduled first.
pub type Key = (u32, u32, u32);

/// A dense op number of an [`OpDag`] (`0..OpDag::len()`).
pub type Node = u32;

/// In an operand row: initial data (an input, a trig variable or a constant), not an op.
pub const NO_NODE: Node = Node::MAX;

/// The distinct ops of an operand row, in operand order (initial data, [`NO_NODE`], skipped).
fn distinct(row: &[Node]) -> impl Iterator<Item = Node> + '_ {
    row.iter().enumerate().filter(move |&(i, &a)| a != NO_NODE && !row[..i].contains(&a)).map(|(_, &a)| a)
}

/// The dependence structure the list schedulers need, built once per placement and shared by
/// every forward and backward pass (compressed rows, no per-op allocation). Indexed by
/// [`Node`].
pub struct OpDag {
    /// The value of each node.
    pub ops: Vec<Value>,
    /// The node of each value index ([`NO_NODE`] for values that are not ops).
    node_of: Vec<Node>,
    /// The kind of each node: a byte per op, so the schedulers' accesses do not touch the
    /// function's value table.
    kind: Vec<OpKind>,
    /// `operands[operand_at[j]..operand_at[j + 1]]`: operands of node j by position,
    /// [`NO_NODE`] for initial data.
    operand_at: Vec<u32>,
    operands: Vec<Node>,
    /// `users[user_at[j]..user_at[j + 1]]`: distinct op users of node j, in increasing node
    /// order.
    user_at: Vec<u32>,
    users: Vec<Node>,
    /// Distinct op operands per node.
    pub(crate) n_distinct: Vec<u32>,
    /// PE clusters ([`super::cluster`]; 1 = none).
    clusters: u32,
    /// The cluster each node is bound to (empty with one cluster).
    cluster: Vec<u32>,
    /// `place<steal=S>`: the slack below which a ready op may leave its cluster.
    steal: Option<u32>,
}

impl OpDag {
    /// Builds the structure of `f` (atomised, verified), nodes in body order. Cost:
    /// O(values + operands).
    pub fn new(f: &Function) -> OpDag {
        let ops = f.body.iter().copied().filter(|&v| f.op_kind(v).is_some()).collect();
        OpDag::with_nodes(f, ops)
    }

    /// Builds the structure of `f` (atomised, verified), nodes in increasing `(keys[v], v)`
    /// order (`keys` indexed by value index: the priority the schedules will mostly follow).
    /// Cost: O(values + operands + ops log ops).
    pub fn ordered(f: &Function, keys: &[Key]) -> OpDag {
        let mut ops: Vec<Value> = f.body.iter().copied().filter(|&v| f.op_kind(v).is_some()).collect();
        ops.sort_unstable_by_key(|&v| (keys[v.index()], v.index()));
        OpDag::with_nodes(f, ops)
    }

    fn with_nodes(f: &Function, ops: Vec<Value>) -> OpDag {
        let n = ops.len();
        let mut node_of = vec![NO_NODE; f.values.len()];
        for (j, &v) in ops.iter().enumerate() {
            node_of[v.index()] = j as Node;
        }
        let node = |o: &Operand| match o {
            Operand::Value(x) => node_of[x.index()],
            Operand::Const(_) => NO_NODE,
        };
        let mut kind = Vec::with_capacity(n);
        let mut operand_at = Vec::with_capacity(n + 1);
        let mut operands = Vec::with_capacity(2 * n);
        let mut n_distinct = vec![0u32; n];
        let mut n_users = vec![0u32; n + 1];
        for (j, &v) in ops.iter().enumerate() {
            operand_at.push(operands.len() as u32);
            kind.push(f.op_kind(v).expect("an op"));
            let start = operands.len();
            match &f.value(v).def {
                robovec_ir::Def::Binary(_, a, b) => operands.extend([node(a), node(b)]),
                robovec_ir::Def::Call(_, args) => operands.extend(args.iter().map(node)),
                _ => {}
            }
            for a in distinct(&operands[start..]) {
                n_distinct[j] += 1;
                n_users[a as usize] += 1;
            }
        }
        operand_at.push(operands.len() as u32);
        // Users: prefix sums, then fill in node order (so each row is in increasing node order).
        let mut at = 0u32;
        for c in &mut n_users {
            let x = *c;
            *c = at;
            at += x;
        }
        let user_at = n_users.clone();
        let mut users = vec![0; at as usize];
        for j in 0..n {
            for a in distinct(&operands[operand_at[j] as usize..operand_at[j + 1] as usize]) {
                users[n_users[a as usize] as usize] = j as Node;
                n_users[a as usize] += 1;
            }
        }
        OpDag {
            ops,
            node_of,
            kind,
            operand_at,
            operands,
            user_at,
            users,
            n_distinct,
            clusters: 1,
            cluster: Vec::new(),
            steal: None,
        }
    }

    /// Number of ops (nodes).
    pub fn len(&self) -> usize {
        self.ops.len()
    }

    /// True without ops.
    pub fn is_empty(&self) -> bool {
        self.ops.is_empty()
    }

    /// The node of value `v`, `None` when it is not an op.
    pub fn node(&self, v: Value) -> Option<Node> {
        self.node_of.get(v.index()).copied().filter(|&j| j != NO_NODE)
    }

    /// `by_value` (indexed by value index) gathered per node.
    pub fn gather<T: Copy>(&self, by_value: &[T]) -> Vec<T> {
        self.ops.iter().map(|v| by_value[v.index()]).collect()
    }

    /// Operands of node `j` by position ([`NO_NODE`] for initial data).
    pub fn operands_of(&self, j: Node) -> &[Node] {
        &self.operands[self.operand_at[j as usize] as usize..self.operand_at[j as usize + 1] as usize]
    }

    /// Distinct op users of node `j`, in increasing node order.
    pub fn users_of(&self, j: Node) -> &[Node] {
        &self.users[self.user_at[j as usize] as usize..self.user_at[j as usize + 1] as usize]
    }

    /// Number of distinct op users of node `j`.
    pub fn n_users(&self, j: Node) -> u32 {
        self.user_at[j as usize + 1] - self.user_at[j as usize]
    }

    /// Distinct op operands of node `j`, in operand order.
    pub fn distinct_operands(&self, j: Node) -> impl Iterator<Item = Node> + '_ {
        distinct(self.operands_of(j))
    }

    /// True for an op of the MULTI side.
    pub fn is_mul(&self, j: Node) -> bool {
        self.kind[j as usize] == OpKind::Mul
    }

    /// Binds the nodes to `clusters` PE clusters, `part` (indexed by node, each `< clusters`)
    /// giving each node's ([`super::cluster::partition`]).
    ///
    /// # Panics
    /// If `part` is not one cluster per node below `clusters`.
    pub fn set_clusters(&mut self, clusters: u32, part: Vec<u32>) {
        assert!(part.len() == self.len() && part.iter().all(|&c| c < clusters.max(1)));
        self.clusters = clusters.max(1);
        self.cluster = if self.clusters == 1 { Vec::new() } else { part };
    }

    /// Lets a ready op whose first key component (its latest start, in cycles: the ALAP cycle
    /// or the backward pass's) is at most `slack` cycles after the current cycle issue on a PE
    /// its own cluster leaves idle in another cluster (`place<steal=S>`; `None`: never). Only
    /// with more than one cluster.
    pub fn set_steal(&mut self, slack: Option<u32>) {
        self.steal = slack;
    }

    /// The slack of [`OpDag::set_steal`] (`None` with one cluster).
    pub fn steal(&self) -> Option<u32> {
        self.steal.filter(|_| self.clusters > 1)
    }

    /// Number of PE clusters (1 without `place<clusters=G>`).
    pub fn clusters(&self) -> u32 {
        self.clusters
    }

    /// The PE cluster node `j` is bound to (0 with one cluster).
    pub fn cluster(&self, j: Node) -> u32 {
        self.cluster.get(j as usize).copied().unwrap_or(0)
    }

    /// The kind of node `j`.
    pub fn kind(&self, j: Node) -> OpKind {
        self.kind[j as usize]
    }
}
