//! Functions and modules: value arena, body order, outputs, and the builder API used by front
//! ends and passes.

use crate::count::{count_expr, OpCounts};
use crate::entities::Value;
use crate::span::Span;
use crate::syntax::{Def, OpKind, Operand, Output, Phase, Timing, ValueData};

mod index;

use index::{name_hash, Formats, NameIndex, OutputIndex, Timings};

/// One Robotran function in SSA form (`dirdyna`, `invdyna`, `sensor_3`, …).
///
/// Values live in an arena indexed by [`Value`]. `inputs` lists the input values; `body` lists
/// every other value in definition (topological) order. Names are unique within the function.
#[derive(Clone, Debug, PartialEq)]
pub struct Function {
    /// Function name without `@` (`dirdyna`, `sensor_2`).
    pub name: String,
    /// Which definition forms are allowed.
    pub phase: Phase,
    /// Number of equations of the source (SPEC §1: assignments except trig initial variables),
    /// carried through passes for reports; `None` when unknown.
    pub equations: Option<u32>,
    /// How many independent states one evaluation computes (≥ 1; 1 unless `interleave`
    /// made copies: state `k ≥ 1`'s inputs, values and outputs carry the suffix `#k`, see
    /// [`state_name`]). Printed as `states K` when K > 1; the verifier rejects 0.
    /// Reports divide a placement's time by it (ns per state).
    pub states: u32,
    /// Value arena: index = `Value::index()`.
    pub values: Vec<ValueData>,
    /// Input values, in first-use order.
    pub inputs: Vec<Value>,
    /// Defined values (trig, ops, expressions), in definition order.
    pub body: Vec<Value>,
    /// Outputs in source order.
    pub outputs: Vec<Output>,
    /// Span of the whole function in its source.
    pub span: Span,
    /// The placement on the PE architecture, when `place` made one (or the text had one).
    pub placement: Option<crate::placement::Placement>,
    /// Schedule attributes by value index ([`Function::timing`]).
    timings: Timings,
    /// Numeric formats by value index ([`Function::format`]).
    formats: Formats,
    names: NameIndex,
    outputs_by_name: OutputIndex,
}

/// The name of `base`'s copy in state `k` of an interleaved function (`interleave`): `base`
/// itself for state 0, `base#k` for `k ≥ 1` (`q[4]#2`, `AF24.1#3`, output `Qq[1]#1`). `#`
/// appears in no Robotran, Matlab, Python or URDF name nor in any name a pass makes, and the
/// `.rvir` lexer accepts one `#k` at the end of a value or output name, so state names never
/// collide with other names. `base` is a name without a suffix ([`split_state`]).
pub fn state_name(base: &str, k: u32) -> String {
    if k == 0 {
        base.to_string()
    } else {
        format!("{base}#{k}")
    }
}

/// A name's base and state: `("q[4]", 2)` for `q[4]#2`, `(name, 0)` for a name without a
/// state suffix (the inverse of [`state_name`]). What the input domain looks a suffixed input
/// up by ([`crate::domain::Domain::get`]).
pub fn split_state(name: &str) -> (&str, u32) {
    if let Some((base, k)) = name.rsplit_once('#') {
        if !base.is_empty() && !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()) {
            if let Ok(k) = k.parse::<u32>() {
                return (base, k);
            }
        }
    }
    (name, 0)
}

/// A set of functions from one input file.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Module {
    /// Functions in source order; names are unique.
    pub functions: Vec<Function>,
}

impl Module {
    /// The function called `name`, if any.
    pub fn function(&self, name: &str) -> Option<&Function> {
        self.functions.iter().find(|f| f.name == name)
    }
}

impl Function {
    /// Values that an output or one of `roots` needs, transitively (indexed by
    /// `Value::index()`): the liveness that dead-code removal keeps. Cost: O(values + operands).
    pub fn live_values(&self, roots: &[Value]) -> Vec<bool> {
        let mut live = vec![false; self.values.len()];
        for v in roots {
            live[v.index()] = true;
        }
        for o in &self.outputs {
            if let Operand::Value(v) = o.value {
                live[v.index()] = true;
            }
        }
        self.mark_operands(&mut live);
        live
    }

    /// Marks in `marked` (indexed by `Value::index()`, `values.len()` entries) every value a
    /// marked value reads, transitively: one backward sweep over the body. Cost:
    /// O(values + operands).
    pub fn mark_operands(&self, marked: &mut [bool]) {
        for &v in self.body.iter().rev() {
            if marked[v.index()] {
                self.value(v).def.for_each_value(|a| marked[a.index()] = true);
            }
        }
    }

    /// How many times each value is read (indexed by `Value::index()`): once per operand of a
    /// body value that names it, and once per output that is it. Cost: O(values + operands).
    pub fn use_counts(&self) -> Vec<u32> {
        let mut uses = vec![0u32; self.values.len()];
        for &v in &self.body {
            self.value(v).def.for_each_value(|a| uses[a.index()] += 1);
        }
        for o in &self.outputs {
            if let Operand::Value(v) = o.value {
                uses[v.index()] += 1;
            }
        }
        uses
    }

    /// An empty function in `phase`.
    pub fn new(name: impl Into<String>, phase: Phase) -> Function {
        Function {
            name: name.into(),
            phase,
            equations: None,
            states: 1,
            values: Vec::new(),
            inputs: Vec::new(),
            body: Vec::new(),
            outputs: Vec::new(),
            span: Span::DUMMY,
            placement: None,
            timings: Timings::default(),
            formats: Formats::default(),
            names: NameIndex::default(),
            outputs_by_name: OutputIndex::default(),
        }
    }

    /// The data of `v`. Panics if `v` is not a value of this function (a verified function only
    /// holds its own values).
    pub fn value(&self, v: Value) -> &ValueData {
        &self.values[v.index()]
    }

    /// The schedule attributes of `v`, when an analysis wrote them (`asap-alap`, or the text's
    /// `{asap=…}`).
    pub fn timing(&self, v: Value) -> Option<Timing> {
        self.timings.get(v.index())
    }

    /// Sets (or, with `None`, removes) the schedule attributes of `v`.
    pub fn set_timing(&mut self, v: Value, t: Option<Timing>) {
        let i = v.index();
        if i >= self.timings.0.len() {
            if t.is_none() {
                return;
            }
            self.timings.0.resize(i + 1, None);
        }
        self.timings.0[i] = t;
    }

    /// The numeric format of `v` (binary64 unless set; [`crate::format`]).
    pub fn format(&self, v: Value) -> crate::format::Format {
        self.formats.get(v.index())
    }

    /// Sets the numeric format of `v`.
    pub fn set_format(&mut self, v: Value, format: crate::format::Format) {
        let i = v.index();
        if i >= self.formats.0.len() {
            if format.is_default() {
                return;
            }
            self.formats.0.resize(i + 1, crate::format::Format::default());
        }
        self.formats.0[i] = format;
    }

    /// Every value back to binary64, the default (the function as it is without formats).
    pub fn clear_formats(&mut self) {
        self.formats = Formats::default();
    }

    /// True when some value has a format other than binary64: passes that do not declare
    /// that they understand formats refuse the function (`Props::formats` in `robovec-passes`).
    pub fn has_formats(&self) -> bool {
        self.formats.0.iter().any(|f| !f.is_default())
    }

    /// The first value, inputs then body, whose format is not binary64 (what a refusal of
    /// formats names).
    pub fn first_formatted(&self) -> Option<Value> {
        if !self.has_formats() {
            return None;
        }
        self.inputs.iter().chain(&self.body).copied().find(|&v| !self.format(v).is_default())
    }

    /// Replaces every value's schedule attributes by `table` (indexed by value index; values
    /// past its end have none).
    pub fn set_timings(&mut self, table: Vec<Option<Timing>>) {
        self.timings = Timings(table);
    }

    /// Mutable data of `v`; the name must not be changed through it (or [`Function::reindex_names`] must follow).
    pub fn value_mut(&mut self, v: Value) -> &mut ValueData {
        &mut self.values[v.index()]
    }

    /// Reserves room for `values` more values, `body` of them definitions, so that a pass that
    /// knows its output's size builds it without growing (a growing vector holds up to twice
    /// its values, and copies them, at each doubling; issue 28 item 4).
    pub fn reserve(&mut self, values: usize, body: usize) {
        self.values.reserve_exact(values);
        self.body.reserve_exact(body);
        self.names.reserve(values);
    }

    /// The value named `name` (without `%`).
    pub fn lookup(&self, name: &str) -> Option<Value> {
        self.names.get(&self.values, name)
    }

    /// The name of `v` (without `%`).
    pub fn name_of(&self, v: Value) -> &str {
        &self.values[v.index()].name
    }

    /// A name not yet used in this function: `base` itself if free, else `base.1`, `base.2`, …
    pub fn fresh_name(&self, base: &str) -> String {
        if self.lookup(base).is_none() {
            return base.to_string();
        }
        (1..).map(|k| format!("{base}.{k}")).find(|n| self.lookup(n).is_none()).expect("unbounded counter")
    }

    fn push_value(&mut self, name: String, def: Def, span: Span) -> Result<Value, Value> {
        let v = Value::with_number(self.values.len() as u32);
        self.names.claim(&self.values, &name, v)?;
        self.values.push(ValueData { name, def, span });
        Ok(v)
    }

    /// Adds an input named `name`.
    ///
    /// # Errors
    /// `Err(existing)` when the name is already taken; nothing is added.
    pub fn add_input(&mut self, name: impl Into<String>, span: Span) -> Result<Value, Value> {
        let v = self.push_value(name.into(), Def::Input, span)?;
        self.inputs.push(v);
        Ok(v)
    }

    /// Appends a definition to the body.
    ///
    /// # Errors
    /// `Err(existing)` when the name is already taken; nothing is added.
    pub fn define(&mut self, name: impl Into<String>, def: Def, span: Span) -> Result<Value, Value> {
        let v = self.push_value(name.into(), def, span)?;
        self.body.push(v);
        Ok(v)
    }

    /// Appends a definition under a fresh name derived from `base` (see [`Function::fresh_name`]).
    pub fn define_fresh(&mut self, base: &str, def: Def, span: Span) -> Value {
        let name = self.fresh_name(base);
        self.define(name, def, span).expect("fresh name is free")
    }

    /// [`Function::define_fresh`] for many values under one `base`: `base`, then `base.1`,
    /// `base.2`, … from where `counter` (start it at 0) left off, so `n` definitions cost O(n)
    /// lookups where `define_fresh`'s search from 1 costs O(n²).
    pub fn define_counted(&mut self, base: &str, counter: &mut u32, def: Def, span: Span) -> Value {
        loop {
            let name = if *counter == 0 { base.to_string() } else { format!("{base}.{counter}") };
            *counter += 1;
            if self.lookup(&name).is_none() {
                return self.define(name, def, span).expect("a free name");
            }
        }
    }

    /// Sets output `name` to `value`, replacing an earlier output of that name (read-modify-write).
    /// Cost: O(1) expected (a hash lookup; see [`Function::output_probes`]).
    pub fn set_output(&mut self, name: impl Into<String>, value: Operand, span: Span) {
        let name = name.into();
        if let Some(i) = self.output_position(&name) {
            let o = &mut self.outputs[i];
            o.value = value;
            o.span = span;
        } else {
            let h = name_hash(&name);
            self.outputs_by_name.pos.insert_unique(h, (h, self.outputs.len()), |&(eh, _)| eh);
            self.outputs.push(Output { name, value, span });
        }
    }

    /// The index in `outputs` of the output called `name`. Cost: O(1) expected; O(outputs)
    /// once after `outputs` was edited directly (the name index is rebuilt).
    pub fn output_position(&mut self, name: &str) -> Option<usize> {
        let idx = &mut self.outputs_by_name;
        let n = self.outputs.len();
        let last_ok = self.outputs.last().is_none_or(|o| idx.get(name_hash(&o.name)) == Some(n - 1));
        if idx.pos.len() != n || !last_ok {
            idx.probes += self.outputs.len() as u64;
            idx.pos = OutputIndex::build(&self.outputs);
        }
        let h = name_hash(name);
        match idx.get(h) {
            Some(i) => {
                idx.probes += 1;
                if self.outputs.get(i).is_some_and(|o| o.name == name) {
                    return Some(i);
                }
                // Stale (an output renamed or reordered in place): rebuild and look again.
                idx.probes += self.outputs.len() as u64;
                idx.pos = OutputIndex::build(&self.outputs);
                idx.get(h).filter(|&i| self.outputs.get(i).is_some_and(|o| o.name == name))
            }
            None => None,
        }
    }

    /// Work counter of output lookups by name: outputs compared by name so far by
    /// [`Function::set_output`] and [`Function::output_position`] (units: comparisons). Linear
    /// in the number of lookups when outputs are only added through `set_output`; tests use it
    /// to check that building a function with n outputs is O(n), not O(n²).
    pub fn output_probes(&self) -> u64 {
        self.outputs_by_name.probes
    }

    /// The operation kind of `v`'s definition as a PE array runs it, or `None` for inputs,
    /// trig variables and (parsed-phase) expressions: [`Def::op_kind`], except that a fused
    /// multiply-add in fixed point ([`Function::is_fixed_mac`]) is a `Mul`, the op of a MULTI
    /// PE with its addend (issue 49: a multiply-accumulate PE). Op counts (SPEC §3) keep
    /// [`Def::op_kind`]'s `call`.
    pub fn op_kind(&self, v: Value) -> Option<OpKind> {
        if self.is_fixed_mac(v) {
            return Some(OpKind::Mul);
        }
        self.value(v).def.op_kind()
    }

    /// True when `v` is a fused multiply-add (`fma`, `fms`, `fnma`: `contract`'s ops) whose
    /// result is fixed point: a MULTI PE computes it, the product of its first two operands
    /// plus or minus the third aligned to it, rounded once (`robovec_machine`'s fixed-point
    /// PEs; [`crate::format::integer_op`]).
    pub fn is_fixed_mac(&self, v: Value) -> bool {
        match &self.value(v).def {
            Def::Call(c, args) => {
                matches!(self.format(v), crate::format::Format::Fix { .. })
                    && matches!(
                        crate::intrinsic::Intrinsic::of(c, args.len()),
                        Some(
                            crate::intrinsic::Intrinsic::Fma
                                | crate::intrinsic::Intrinsic::Fms
                                | crate::intrinsic::Intrinsic::Fnma
                        )
                    )
            }
            _ => false,
        }
    }

    /// Counts the operations of the function; expressions count as SPEC §3 atomises them.
    pub fn op_counts(&self) -> OpCounts {
        let mut c = OpCounts::default();
        for &v in &self.body {
            match &self.value(v).def {
                Def::Expr(e) => count_expr(e, &mut c),
                d => {
                    if let Some(k) = d.op_kind() {
                        c.bump(k)
                    }
                }
            }
        }
        c
    }

    /// Removes every schedule attribute and the placement (call after a change that
    /// invalidates them).
    pub fn clear_timing(&mut self) {
        self.timings = Timings::default();
        self.placement = None;
    }

    /// Rebuilds the name indexes (values and outputs); for code that edits `values` or renames
    /// `outputs` directly.
    pub fn reindex_names(&mut self) {
        self.outputs_by_name.pos = OutputIndex::build(&self.outputs);
        self.names = NameIndex::build(&self.values);
    }

    /// Keeps only the body values for which `keep` is true, renumbering values densely and
    /// rewriting every reference; `keep` is asked about inputs too. `retain(|_, _| true)`
    /// renumbers into the canonical order (inputs, then body) that the text reader produces.
    ///
    /// The caller guarantees that no kept value refers to a dropped one. The kept values are
    /// moved, not copied (issue 28: copying every expression doubled the peak memory of the
    /// URDF generator, which compacts each function it writes).
    pub fn retain(&mut self, keep: impl FnMut(&Function, Value) -> bool) {
        let done = self.retain_until(keep, &mut || false);
        debug_assert!(done, "never stopped");
    }

    /// [`Function::retain`] that calls `stop` about once per value and per output (a time
    /// limit's clock, issue 47: the URDF generator compacts functions of millions of values
    /// and outputs) and gives up at the first `true`: it then returns false and leaves the
    /// function in an unspecified state that does not verify, still holding every output and
    /// every value it keeps (those are not freed: freeing millions of them takes seconds, which
    /// the caller may not want to spend). Returns true when done. Cost: as
    /// [`Function::retain`].
    #[must_use]
    pub fn retain_until(
        &mut self,
        mut keep: impl FnMut(&Function, Value) -> bool,
        stop: &mut dyn FnMut() -> bool,
    ) -> bool {
        let n = self.values.len();
        let mut map: Vec<Option<Value>> = vec![None; n];
        let order: Vec<Value> = self.inputs.iter().chain(self.body.iter()).copied().collect();
        let mut kept: Vec<Value> = Vec::new();
        for v in order {
            if stop() {
                return false;
            }
            if keep(self, v) {
                kept.push(v);
            }
        }
        let mut new_values = Vec::with_capacity(kept.len());
        let mut slots: Vec<Option<ValueData>> = std::mem::take(&mut self.values).into_iter().map(Some).collect();
        let mut new_inputs = Vec::new();
        let mut new_body = Vec::new();
        let mut new_timings = Vec::new();
        let mut new_formats = Vec::new();
        for v in kept {
            if stop() {
                // Every value back in the arena, moved, not freed.
                self.values = new_values;
                self.values.extend(slots.into_iter().flatten());
                return false;
            }
            let nv = Value::with_number(new_values.len() as u32);
            map[v.index()] = Some(nv);
            if let Some(t) = self.timings.get(v.index()) {
                new_timings.resize(nv.index(), None);
                new_timings.push(Some(t));
            }
            let format = self.formats.get(v.index());
            if !format.is_default() {
                new_formats.resize(nv.index(), crate::format::Format::default());
                new_formats.push(format);
            }
            let d = slots[v.index()].take().expect("inputs and body name each value once");
            if matches!(d.def, Def::Input) {
                new_inputs.push(nv);
            } else {
                new_body.push(nv);
            }
            new_values.push(d);
        }
        drop(slots);
        let remap = |v: Value| map[v.index()].expect("kept value refers to a dropped value");
        let mut remapped = true;
        for d in &mut new_values {
            if stop() {
                remapped = false;
                break;
            }
            d.def.map_values(&remap);
        }
        if !remapped {
            self.values = new_values;
            return false;
        }
        for o in &mut self.outputs {
            if let Operand::Value(v) = o.value {
                o.value = Operand::Value(remap(v));
            }
        }
        if let Some(p) = &mut self.placement {
            // Renumbering keeps a placement valid only if every value it names is kept.
            let kept = |v: Value| map[v.index()].is_some();
            let names_kept = p.writes.iter().all(|w| kept(w.value))
                && p.loads.iter().all(|l| !matches!(l.operand, Operand::Value(v) if !kept(v)))
                && p.issue.iter().enumerate().all(|(i, x)| x.is_none() || map[i].is_some());
            if names_kept {
                let mut issue = vec![None; new_values.len()];
                for (i, x) in p.issue.iter().enumerate() {
                    if let (Some(x), Some(nv)) = (x, map[i]) {
                        issue[nv.index()] = Some(*x);
                    }
                }
                p.issue = issue;
                if !p.spans.issue.is_empty() {
                    let mut spans = vec![crate::span::Span::DUMMY; new_values.len()];
                    for (i, s) in p.spans.issue.iter().enumerate() {
                        if let Some(nv) = map.get(i).copied().flatten() {
                            spans[nv.index()] = *s;
                        }
                    }
                    p.spans.issue = spans;
                }
                p.writes.iter_mut().for_each(|w| w.value = remap(w.value));
                for l in &mut p.loads {
                    if let Operand::Value(v) = l.operand {
                        l.operand = Operand::Value(remap(v));
                    }
                }
            } else {
                self.placement = None;
            }
        }
        self.values = new_values;
        self.timings = Timings(new_timings);
        self.formats = Formats(new_formats);
        self.inputs = new_inputs;
        self.body = new_body;
        let indexed = OutputIndex::build_until(&self.outputs, stop)
            .and_then(|pos| Some((pos, NameIndex::build_until(&self.values, stop)?)));
        match indexed {
            Some((pos, names)) => {
                self.outputs_by_name.pos = pos;
                self.names = names;
                true
            }
            None => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::syntax::Expr;

    fn out(f: &Function) -> Vec<(String, Operand)> {
        f.outputs.iter().map(|o| (o.name.clone(), o.value)).collect()
    }

    #[test]
    fn name_index_finds_values_and_the_verifier_tells_a_stale_index_from_a_duplicate_name() {
        let mut f = Function::new("f", Phase::Parsed);
        let a = f.add_input("a", Span::DUMMY).unwrap();
        let b = f.add_input("b", Span::DUMMY).unwrap();
        assert_eq!((f.lookup("a"), f.lookup("b"), f.lookup("c")), (Some(a), Some(b), None));
        assert_eq!(f.add_input("a", Span::DUMMY), Err(a));
        assert_eq!(f.fresh_name("a"), "a.1");
        assert!(crate::verifier::verify_function(&f).is_empty());
        // `b` renamed to `a` behind the index: a duplicate name.
        f.value_mut(b).name = "a".into();
        let msgs =
            |f: &Function| crate::verifier::verify_function(f).into_iter().map(|e| e.message).collect::<Vec<_>>();
        assert_eq!(msgs(&f), ["value name `%a` is used twice"]);
        // Rebuilt, the last of equal names wins (as a map filled in order): `a`'s entry is stale.
        f.reindex_names();
        assert_eq!(f.lookup("a"), Some(b));
        assert_eq!(msgs(&f), ["name index out of date for `%a`", "value name `%a` is used twice"]);
        // Renamed back and reindexed: verifies again.
        f.value_mut(b).name = "b".into();
        f.reindex_names();
        assert!(crate::verifier::verify_function(&f).is_empty());
    }

    /// Issue 47: `retain_until` and `verify_until` call their `stop` once per element of each
    /// loop and give up at the first `true`; a stopped `retain_until` keeps every value and
    /// output (nothing freed), a completed one is `retain`.
    #[test]
    fn retain_and_verify_stop_when_told_and_lose_nothing() {
        let text = "func @f { phase atomised input %x input %y input %z \
             %a = mul %x, %y  %dead = add %x, %z  %b = add %a, %z  %c = sub %b, %x \
             output p = %b  output q = %c  output r = 2.0 }";
        let f = crate::text::parse(text).unwrap().functions.remove(0);
        let keep = |f: &Function, v: Value| f.name_of(v) != "dead";
        // Walk of inputs and body (7), kept moved (6) and renumbered (6), output index (3),
        // name index (6).
        let calls = 7 + 6 + 6 + 3 + 6;
        let mut reference = f.clone();
        reference.retain(keep);
        for k in 1..=calls + 1 {
            let mut g = f.clone();
            let mut n = 0;
            let done = g.retain_until(keep, &mut || {
                n += 1;
                n == k
            });
            assert_eq!(done, k > calls, "stop at call {k}");
            if done {
                assert_eq!(g, reference);
                assert!(crate::verifier::verify_function(&g).is_empty());
            } else {
                assert!(g.values.len() >= 6, "call {k}: every value kept is still there");
                assert_eq!(g.outputs.len(), 3);
            }
        }
        // The verifier: inputs and body, the name index, the body, the outputs.
        let calls = 7 + 7 + 4 + 3;
        let m = Module { functions: vec![f] };
        for k in 1..=calls + 1 {
            let mut n = 0;
            let verdict = crate::verifier::verify_until(&m, &mut || {
                n += 1;
                n == k
            });
            assert_eq!(verdict.is_some(), k > calls, "stop at call {k}");
        }
        assert_eq!(crate::verifier::verify_until(&m, &mut || false), Some(Ok(())));
    }

    /// Issue 10 §3: a large function is mostly value records and, parsed, expression nodes.
    #[test]
    fn value_records_and_expression_nodes_stay_small() {
        use std::mem::size_of;
        assert_eq!(size_of::<Expr>(), 24, "an expression node (a call boxes its callee and arguments)");
        assert_eq!(size_of::<Def>(), 40, "a definition (a call boxes its callee)");
        assert_eq!(size_of::<ValueData>(), 72, "name 24 + definition 40 + span 8 (timing beside: issue 28)");
    }

    #[test]
    fn set_output_replaces_by_name_even_after_direct_edits_of_outputs() {
        let mut f = Function::new("f", Phase::Parsed);
        for i in 0..100 {
            f.set_output(format!("y[{i}]"), Operand::Const(i as f64), Span::DUMMY);
        }
        f.set_output("y[7]", Operand::Const(-7.0), Span::DUMMY);
        assert_eq!(f.outputs.len(), 100);
        assert_eq!(f.outputs[7].value, Operand::Const(-7.0));
        // 101 lookups, one name compared each (plus none for the new names).
        assert!(f.output_probes() <= 101, "{}", f.output_probes());
        // Removed behind the index's back (as `dce` does), then set again.
        f.outputs.retain(|o| o.name != "y[3]" && o.name != "y[50]");
        f.set_output("y[51]", Operand::Const(51.5), Span::DUMMY);
        f.set_output("y[3]", Operand::Const(3.5), Span::DUMMY);
        let o = out(&f);
        assert_eq!(o.len(), 99);
        assert_eq!(o.iter().filter(|(n, _)| n == "y[51]").count(), 1);
        assert_eq!(o.iter().find(|(n, _)| n == "y[51]").unwrap().1, Operand::Const(51.5));
        assert_eq!(o.last().unwrap(), &("y[3]".to_string(), Operand::Const(3.5)));
        // Reordered behind its back: still found, never duplicated.
        f.outputs.reverse();
        f.set_output("y[0]", Operand::Const(0.5), Span::DUMMY);
        assert_eq!(f.outputs.len(), 99);
        assert_eq!(f.outputs.iter().find(|o| o.name == "y[0]").unwrap().value, Operand::Const(0.5));
        assert_eq!(f.output_position("y[99]"), f.outputs.iter().position(|o| o.name == "y[99]"));
        assert_eq!(f.output_position("nope"), None);
    }
}
