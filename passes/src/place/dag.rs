//! The dependence structure of a function's ops that the list schedulers ([`super::schedule`],
//! the feeding priority [`super::feed`], the search) share, and their priority [`Key`].

use robovec_ir::{Function, OpKind, Operand, Value};

/// A priority key: smaller is scheduled first.
pub type Key = (u32, u32, u32);

/// The dependence structure the list schedulers need, built once per placement and shared by
/// every forward and backward pass (compressed rows, no per-op allocation). Indexed by value
/// index.
pub struct OpDag {
    /// Ops in body (topological) order.
    pub ops: Vec<Value>,
    /// The kind of each op (`None` for other values): a byte per value, so the schedulers'
    /// random accesses do not touch the function's value table.
    kind: Vec<Option<OpKind>>,
    /// `operands[operand_at[i]..operand_at[i + 1]]`: op operands of value i by position, `None`
    /// for initial data (inputs, trig variables, constants).
    operand_at: Vec<u32>,
    operands: Vec<Option<Value>>,
    /// `users[user_at[i]..user_at[i + 1]]`: distinct op users of value i.
    pub(crate) user_at: Vec<u32>,
    users: Vec<Value>,
    /// Distinct op operands per value.
    pub(crate) n_distinct: Vec<u32>,
}

impl OpDag {
    /// Builds the structure of `f` (atomised, verified). Cost: O(values + operands).
    pub fn new(f: &Function) -> OpDag {
        let n = f.values.len();
        let is_op = |o: &Operand| match o {
            Operand::Value(x) if f.op_kind(*x).is_some() => Some(*x),
            _ => None,
        };
        let mut dag = OpDag {
            ops: Vec::new(),
            kind: vec![None; n],
            operand_at: Vec::with_capacity(n + 1),
            operands: Vec::new(),
            user_at: Vec::new(),
            users: Vec::new(),
            n_distinct: vec![0; n],
        };
        let mut n_users = vec![0u32; n + 1];
        for (i, val) in f.values.iter().enumerate() {
            dag.operand_at.push(dag.operands.len() as u32);
            let v = Value::with_number(i as u32);
            let Some(k) = f.op_kind(v) else { continue };
            dag.kind[i] = Some(k);
            let start = dag.operands.len();
            match &val.def {
                robovec_ir::Def::Binary(_, a, b) => dag.operands.extend([is_op(a), is_op(b)]),
                robovec_ir::Def::Call(_, args) => dag.operands.extend(args.iter().map(is_op)),
                _ => {}
            }
            for j in start..dag.operands.len() {
                if let Some(a) = dag.operands[j] {
                    if !dag.operands[start..j].contains(&Some(a)) {
                        dag.n_distinct[i] += 1;
                        n_users[a.index()] += 1;
                    }
                }
            }
        }
        dag.operand_at.push(dag.operands.len() as u32);
        dag.ops = f.body.iter().copied().filter(|&v| f.op_kind(v).is_some()).collect();
        // Users: prefix sums, then fill in body order (so each row is in topological order).
        let mut at = 0u32;
        for c in &mut n_users {
            let x = *c;
            *c = at;
            at += x;
        }
        dag.user_at = n_users.clone();
        let mut users = vec![Value::with_number(0); at as usize];
        for &v in &dag.ops {
            let row = dag.operands_of(v);
            for (j, &o) in row.iter().enumerate() {
                if let Some(a) = o {
                    if !row[..j].contains(&Some(a)) {
                        users[n_users[a.index()] as usize] = v;
                        n_users[a.index()] += 1;
                    }
                }
            }
        }
        dag.users = users;
        dag
    }

    /// Op operands of `v` by position (`None` for initial data).
    pub fn operands_of(&self, v: Value) -> &[Option<Value>] {
        &self.operands[self.operand_at[v.index()] as usize..self.operand_at[v.index() + 1] as usize]
    }

    /// Distinct op users of `v`.
    pub fn users_of(&self, v: Value) -> &[Value] {
        &self.users[self.user_at[v.index()] as usize..self.user_at[v.index() + 1] as usize]
    }

    /// Distinct op operands of `v`, in operand order.
    pub fn distinct_operands(&self, v: Value) -> Vec<Value> {
        let row = self.operands_of(v);
        row.iter().enumerate().filter_map(|(j, &o)| o.filter(|a| !row[..j].contains(&Some(*a)))).collect()
    }

    /// True for an op of the MULTI side.
    pub fn is_mul(&self, v: Value) -> bool {
        self.kind[v.index()] == Some(OpKind::Mul)
    }

    /// The kind of op `v`.
    ///
    /// # Panics
    /// When `v` is not an op.
    pub fn kind(&self, v: Value) -> OpKind {
        self.kind[v.index()].expect("an op")
    }
}
