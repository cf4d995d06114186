//! The data-dependence graph of a function (petgraph): one node per body value, an edge from
//! each operand definition to each of its users (one edge per operand occurrence).

use petgraph::graph::{DiGraph, NodeIndex};
use petgraph::Direction;

use crate::function::Function;
use crate::Value;

/// Dependence graph over the body values of one function. Inputs are not nodes (they are
/// ready before cycle 0).
#[derive(Debug)]
pub struct DepGraph {
    /// Node weight = the value; edge `a → b` when `b` reads `a`.
    pub graph: DiGraph<Value, ()>,
    node: Vec<Option<NodeIndex>>,
}

impl DepGraph {
    /// Builds the graph of `f` (which must verify). Cost: O(values + operands).
    pub fn build(f: &Function) -> DepGraph {
        let mut graph = DiGraph::with_capacity(f.body.len(), f.body.len() * 2);
        let mut node = vec![None; f.values.len()];
        for &v in &f.body {
            node[v.index()] = Some(graph.add_node(v));
        }
        for &v in &f.body {
            let to = node[v.index()].expect("body value has a node");
            f.value(v).def.for_each_value(|a| {
                if let Some(from) = node[a.index()] {
                    graph.add_edge(from, to, ());
                }
            });
        }
        DepGraph { graph, node }
    }

    /// The node of `v`, `None` for inputs.
    pub fn node(&self, v: Value) -> Option<NodeIndex> {
        self.node.get(v.index()).copied().flatten()
    }

    /// Body values that read `v` (with repetition when read twice).
    pub fn users(&self, v: Value) -> impl Iterator<Item = Value> + '_ {
        self.node(v)
            .into_iter()
            .flat_map(move |n| self.graph.neighbors_directed(n, Direction::Outgoing))
            .map(move |n| self.graph[n])
    }

    /// Body values that `v` reads (inputs excluded).
    pub fn operands(&self, v: Value) -> impl Iterator<Item = Value> + '_ {
        self.node(v)
            .into_iter()
            .flat_map(move |n| self.graph.neighbors_directed(n, Direction::Incoming))
            .map(move |n| self.graph[n])
    }
}
