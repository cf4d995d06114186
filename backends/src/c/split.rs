//! `chunk=OPS`: a large function (at least `2·OPS` statements) written as a chain of *parts*,
//! functions of at most `OPS` statements each, that its entry point calls in order (issue 28,
//! item 5).
//!
//! **Why.** GCC's time and memory per function grow faster than its size (register
//! allocation, scheduling and the SSA passes work on the whole function): one 147k-statement
//! function (WALK-MAN × 4) took 260 s and 3.9 GB at `-O2`, and 588k statements did not fit
//! this machine. Cut into parts of a few thousand statements, the same code compiles in time
//! proportional to its size.
//!
//! **The default, `chunk=4000`, by measurement** (gcc 12.2 `-O2 -c`, this 2-core machine,
//! `atomise,cse,codegen<c;abi=plain>`; `/usr/bin/time`, peak of the compiler's processes):
//!
//! | WALK-MAN × 4 (147k statements) | `chunk=0` | 250 | 500 | 1000 | 2000 | 4000 | 16000 |
//! |---|---|---|---|---|---|---|---|
//! | `gcc -O2` time | 159 s | 13.5 s | 14.4 s | 16.2 s | 19.9 s | 24.0 s | 43.6 s |
//! | `gcc -O2` peak memory | 4.1 GB | 337 MB | 358 MB | 336 MB | 332 MB | 353 MB | 624 MB |
//!
//! WALK-MAN × 16 (588k statements, 34.5 MB of C) at `chunk=4000`: 101 s and 973 MB in one
//! translation unit (the goal: under 3 minutes and 4 GB; unsplit it does not fit the
//! machine). Smaller parts compile faster still, but each boundary costs loads and stores of
//! live values at run time; one-state calls against the unsplit function (`cargo bench --bench
//! codegen_c -- m454 jeep coman_longarms --split=1000,4000 --flags=o2`, paired ratios, median
//! of 5 runs, > 1: the split code is faster; m454's 764 statements are never split, so its
//! rows, identical code, show the noise floor):
//!
//! | model, pipeline | `chunk=1000` | `chunk=4000` |
//! |---|---|---|
//! | m454 `dirdyna`, `atomise` (not split) | 0.999× | 0.915× |
//! | Jeep `dirdyna` (10.6k ops), `atomise` | 0.943× | 0.911× |
//! | Jeep, `atomise,cse` | 1.024× | 1.111× |
//! | Jeep, `atomise,cse,schedule-cpu`, `batch=8` | 0.920× | 1.011× |
//! | COMAN `dirdyna` (33.5k ops), `atomise` | 1.171× | 1.155× |
//! | COMAN, `atomise,cse` | 1.021× | 0.969× |
//! | COMAN, `atomise,cse,schedule-cpu`, `batch=8` | 1.022× | 1.033× |
//!
//! 4000 keeps most corpus calls within the noise of the unsplit code and compiles WALK-MAN × 16
//! well inside the goal; Jeep's `atomise`-only code is about 9 % slower split (the run-time
//! price of the live values; `chunk=0` writes one function as before).
//!
//! **A function of fewer than `2·OPS` statements stays whole** (2026-11-29; before, every
//! function of more than `OPS` was cut). Cutting such a function in two saves no compile time
//! that could be measured and can cost a sixth of its run time. The derivative functions of
//! the robots (`rnea_derivatives`, `aba_derivatives`, docs/derivatives.md) compute their
//! per-body and per-column vectors first and pair them last, so 450 to 635 values are live at
//! any cut between a fifth and four fifths of Solo-12's `rnea_derivatives` (6,164 statements
//! after the bench's `atomise,cse,zero-removal,contract,schedule-cpu`). Measured on this
//! machine, whole against two parts (paired medians of 41 alternating samples, `-O3
//! -march=native -ffp-contract=off`, > 1: whole is faster): Solo-12 `rnea_derivatives`
//! 1.03–1.05× one state and 1.14–1.15× at `batch=4`; Panda's 1.03–1.05× and 1.13–1.16×;
//! Panda's `aba_derivatives` at `batch=4` 1.15–1.17×. `gcc -O2`, whole / two parts, two
//! alternating runs each: Solo-12 `rnea_derivatives` 4.9–5.4 / 5.2–5.6 s, WALK-MAN `invdyna`
//! (5,863 ops, `atomise,cse`) 2.3–2.5 / 2.0–2.6 s, the tricycle's `dirdyna` (5,509) 3.3–3.6 /
//! 3.0–3.7 s. Longer functions are cut as before, into `⌈n/OPS⌉` parts of at most `OPS`: parts
//! of up to `2·OPS` would cost compile time where GCC's time grows steeply, as on WALK-MAN ×
//! K. There, `⌊n/OPS⌋` parts of 4.2k statements instead of ten of 3.8k took `gcc -O2` from
//! 11.9 to 16.4 s at × 1 and 41.4 to 57.1 s at × 4 (this machine that evening, which compiled
//! × 16 in 185 s at the default against 101 s on 2026-11-24), and `chunk=8000` (five parts of
//! 7.5k) 16.6 s at × 1.
//!
//! **Live values.** A value computed in one part and read in a later one is *live* across
//! the boundary. It goes through an array `live[]` that the entry point owns on its stack and
//! passes to every part (`T *restrict live`; `T` is `double`, `float` or `robovec_vec`): the
//! part that computes it stores it right after its statement (`live[5] = AlF15;`), each later
//! part that reads it loads it once, just before the first statement that reads it (`const
//! double AlF15 = live[5];`), as the plain ABI reads its inputs. Nothing is static or global:
//! the generated code stays re-entrant and thread-safe. Slots are reused: a value's slot is
//! free again from the part after its last reader, so the array holds the most values live
//! across one boundary, not every value that crosses one.
//!
//! **Linear time.** [`Plan::new`] makes one pass over the statements to record, for each
//! value, the last part that reads it (the last use decides whether a value crosses a
//! boundary and for how long), and one more to hand out slots from a free list, with the
//! slots released by each part bucketed by that part: O(statements + operands).
//!
//! Parts are cut at about equal sizes (`⌈n / ⌈n/OPS⌉⌉` statements), never before an
//! *attached* value ([`super::body::Body::order`]: the second of a fused sin/cos pair, a later
//! element of a native callback), so a part may hold a few statements more than `OPS`. A
//! function of fewer than `2·OPS` statements is written as one function, exactly as with
//! `chunk=0`.

use robovec_ir::{Function, Value};

/// Marks "no part" and "no slot".
const NONE: u32 = u32::MAX;

/// How one function is cut into parts and which values cross a boundary.
#[derive(Clone, Debug)]
pub(crate) struct Plan {
    /// Part `k` writes the statements `order[bounds[k]..bounds[k + 1]]`; `bounds[0] = 0` and
    /// the last bound is the number of statements.
    pub bounds: Vec<usize>,
    /// Value index → 1 + the part whose statements compute it, 0 for a value the entry point
    /// stores before the first part (`pre` of [`Plan::new`]), [`NONE`] for any other value
    /// (inputs each part reads itself).
    defined_in: Vec<u32>,
    /// Value index → its slot in `live[]`, or [`NONE`] when no later part reads it.
    slot: Vec<u32>,
    /// Size of `live[]`: the most values live across one boundary.
    pub slots: usize,
}

impl Plan {
    /// The parts of `order` (the statements in writing order, [`super::body::Body::order`];
    /// `attached[p]` forbids a cut before `order[p]`): for `n ≥ 2·chunk` statements, `⌈n /
    /// chunk⌉` parts of about equal size (at most `chunk` each, plus what is attached to a
    /// part's last statement), otherwise one part (also for `chunk` 0); and the slots of the
    /// values that cross a boundary. `pre`: values the entry point stores into `live[]` before
    /// the first part (the inputs of `abi=robotran`, read before anything else); `end_uses`:
    /// values the last part reads after its statements (`abi=robotran`'s outputs, written
    /// last). O(statements + operands).
    pub fn new(
        f: &Function,
        order: &[Value],
        attached: &[bool],
        chunk: usize,
        pre: &[Value],
        end_uses: &[Value],
    ) -> Plan {
        let n = order.len();
        let mut bounds = vec![0];
        // A function of fewer than `2·chunk` statements stays whole (module doc: there, a
        // boundary's live values cost more run time than the cut saves compile time).
        if chunk > 0 && n >= 2 * chunk {
            let size = n.div_ceil(n.div_ceil(chunk));
            let mut p = size;
            while p < n {
                while p < n && attached[p] {
                    p += 1;
                }
                if p < n {
                    bounds.push(p);
                }
                p += size;
            }
        }
        bounds.push(n);
        let parts = bounds.len() - 1;
        let mut defined_in = vec![NONE; f.values.len()];
        if parts == 1 {
            return Plan { bounds, defined_in, slot: vec![NONE; f.values.len()], slots: 0 };
        }
        for &v in pre {
            defined_in[v.index()] = 0;
        }
        // Pass 1: the part of each statement and the last part that reads each value (0: no
        // part after the one that computes it reads it).
        let mut last = vec![0u32; f.values.len()];
        for k in 0..parts {
            let here = k as u32 + 1;
            for &v in &order[bounds[k]..bounds[k + 1]] {
                defined_in[v.index()] = here;
                f.value(v).def.for_each_value(|a| {
                    let d = defined_in[a.index()];
                    if d != NONE && d < here {
                        last[a.index()] = last[a.index()].max(here);
                    }
                });
            }
        }
        let end = parts as u32;
        for v in end_uses {
            let d = defined_in[v.index()];
            if d != NONE && d < end {
                last[v.index()] = last[v.index()].max(end);
            }
        }
        // Pass 2: slots. A value read up to part `l` frees its slot for values computed from
        // part `l + 1` on (a part reads its live values at first use, which may come after its
        // own stores, so a slot is never handed over within one part).
        let mut slot = vec![NONE; f.values.len()];
        let mut free: Vec<u32> = Vec::new();
        let mut freed_at: Vec<Vec<u32>> = vec![Vec::new(); parts + 2];
        let mut slots = 0u32;
        let mut take = |v: Value, free: &mut Vec<u32>, freed_at: &mut Vec<Vec<u32>>| {
            let l = last[v.index()];
            if l == 0 {
                return;
            }
            let s = free.pop().unwrap_or_else(|| {
                slots += 1;
                slots - 1
            });
            slot[v.index()] = s;
            freed_at[l as usize + 1].push(s);
        };
        for &v in pre {
            take(v, &mut free, &mut freed_at);
        }
        for k in 0..parts {
            let here = k + 1;
            let released = std::mem::take(&mut freed_at[here]);
            free.extend(released);
            for &v in &order[bounds[k]..bounds[k + 1]] {
                take(v, &mut free, &mut freed_at);
            }
        }
        Plan { bounds, defined_in, slot, slots: slots as usize }
    }

    /// Number of parts (1: the function is not split).
    pub fn parts(&self) -> usize {
        self.bounds.len() - 1
    }

    /// True when part `k` (0-based) reads `v` from `live[]`: `v` was computed (or, for
    /// `pre` values, stored by the entry point) before part `k`.
    pub fn reads_live(&self, v: Value, k: usize) -> bool {
        let d = self.defined_in[v.index()];
        d != NONE && (d as usize) < k + 1 && self.slot[v.index()] != NONE
    }

    /// The slot of `v` in `live[]`, when a later part reads it.
    pub fn slot(&self, v: Value) -> Option<u32> {
        Some(self.slot[v.index()]).filter(|&s| s != NONE)
    }
}

/// The prefix of the parts of the function defined as `defined` (`dirdyna` → `dirdyna_part`,
/// parts `dirdyna_part1`, `dirdyna_part2`, …): the first of `defined_part`,
/// `defined_part1_`, `defined_part2_`, … with which no part name is in `taken` (the file's
/// other global names: every function's symbol, the callbacks). A suffix that starts with `_`
/// never makes a reserved identifier of one that is not.
pub(crate) fn part_prefix(defined: &str, parts: usize, taken: &std::collections::HashSet<String>) -> String {
    (0..)
        .map(|i| if i == 0 { format!("{defined}_part") } else { format!("{defined}_part{i}_") })
        .find(|p| (1..=parts).all(|k| !taken.contains(&format!("{p}{k}"))))
        .expect("unbounded")
}

/// The name of part `k` (0-based) under `prefix`.
pub(crate) fn part_name(prefix: &str, k: usize) -> String {
    format!("{prefix}{}", k + 1)
}

/// `(void)p;` for every parameter of the C function signature `sig` (`… NAME(T *restrict a,
/// T b)`), one line, indented: a function that reads none of some parameter (a part that
/// writes no output, a Robotran function that never reads `tsim`) is then warning-free under
/// `-Wextra` (`-Wunused-parameter`). Empty for `(void)` or no parameters.
pub(crate) fn void_params(sig: &str) -> String {
    let (Some(open), Some(close)) = (sig.find('('), sig.rfind(')')) else { return String::new() };
    let names: Vec<&str> = sig[open + 1..close]
        .split(',')
        .filter_map(|p| {
            let name = p.trim().rsplit(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).next()?;
            (!name.is_empty() && p.trim() != "void").then_some(name)
        })
        .collect();
    if names.is_empty() {
        return String::new();
    }
    let casts: Vec<String> = names.iter().map(|n| format!("(void){n};")).collect();
    format!("  {}\n", casts.join(" "))
}

/// One part of a split function, without storage class: the file assembler makes it `static`
/// in the file of its entry point and external in another unit (`units=K`).
#[derive(Clone, Debug)]
pub(crate) struct Part {
    /// `ROBOVEC_NOINLINE void NAME(PARAMS)`.
    pub signature: String,
    /// Its statements, without the braces (the file assembler writes those, and the `(void)`
    /// casts of [`void_params`] first).
    pub body: String,
    /// Its statements (ops).
    pub ops: usize,
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text::parse;

    fn plan(text: &str, chunk: usize) -> (Function, Plan) {
        let f = parse(text).unwrap().functions.remove(0);
        let order = f.body.clone();
        let attached = vec![false; order.len()];
        let p = Plan::new(&f, &order, &attached, chunk, &[], &[]);
        (f, p)
    }

    #[test]
    fn void_params_names_every_parameter() {
        assert_eq!(
            void_params(
                "ROBOVEC_NOINLINE void f_part1(double **M, double *c, MbsData *s, double tsim, double *restrict live)"
            ),
            "  (void)M; (void)c; (void)s; (void)tsim; (void)live;\n"
        );
        assert_eq!(void_params("void g(const float *restrict in, float *restrict out)"), "  (void)in; (void)out;\n");
        assert_eq!(void_params("void h(void)"), "");
        assert_eq!(void_params("void h()"), "");
    }

    fn value(f: &Function, name: &str) -> Value {
        f.body.iter().copied().find(|&v| f.name_of(v) == name).unwrap()
    }

    const CHAIN: &str = "func @f {\n  phase atomised\n  input %x\n  %a = mul %x, %x\n  %b = add %a, %x\n  \
                         %c = mul %b, %a\n  %d = add %c, %x\n  %e = mul %d, %a\n  output y = %e\n}\n";

    #[test]
    fn a_value_read_in_a_later_part_has_a_slot_and_one_read_in_its_own_part_none() {
        // Parts of 2: [a b] [c d] [e]. a is read by c (part 1) and e (part 2); b by c; c by d
        // (same part); d by e.
        let (f, p) = plan(CHAIN, 2);
        assert_eq!(p.bounds, [0, 2, 4, 5]);
        let [a, b, c, d, e] = ["a", "b", "c", "d", "e"].map(|n| value(&f, n));
        assert!(p.slot(a).is_some() && p.slot(b).is_some() && p.slot(d).is_some());
        assert_eq!((p.slot(c), p.slot(e)), (None, None));
        assert!(p.reads_live(a, 1) && p.reads_live(a, 2) && !p.reads_live(a, 0));
        assert!(!p.reads_live(c, 1), "c is computed in part 1");
        // a lives to part 2 and b dies in part 1: two slots across the first boundary; d (from
        // part 1) cannot take b's slot in part 1 (a part reads at first use), so 3 in all.
        assert_eq!(p.slots, 3);
        // Inputs are read by each part itself.
        assert!(!p.reads_live(f.inputs[0], 2));
    }

    #[test]
    fn a_slot_is_reused_from_the_part_after_its_last_reader() {
        // Parts of 1: a → b (part 1); b → c; c → d; … each value read only by the next part,
        // except a (read up to e's part) and x. b's slot is free from part 3 on.
        let (f, p) = plan(CHAIN, 1);
        assert_eq!(p.parts(), 5);
        let [a, b, c, d] = ["a", "b", "c", "d"].map(|n| value(&f, n));
        assert_eq!(p.slot(b), Some(1));
        assert_eq!(p.slot(c), Some(2), "b is still read in part 2, where c is computed");
        assert_eq!(p.slot(d), Some(1), "b's slot, free from part 3");
        assert_eq!(p.slot(a), Some(0));
        assert_eq!(p.slots, 3);
    }

    #[test]
    fn a_short_function_or_chunk_zero_is_one_part() {
        // 5 statements: chunk 3 would cut them, before, into parts of 3 and 2.
        for chunk in [0, 3, 5, 100] {
            let (_, p) = plan(CHAIN, chunk);
            assert_eq!((p.parts(), p.slots), (1, 0), "chunk={chunk}");
        }
    }

    #[test]
    fn parts_have_about_equal_sizes_and_no_cut_before_an_attached_value() {
        let f = parse(CHAIN).unwrap().functions.remove(0);
        // 5 statements, chunk 3: fewer than 2·3, one part. Chunk 2: ⌈5/2⌉ = 3 parts of
        // ⌈5/3⌉ = 2 statements, the last one shorter.
        let none = vec![false; 5];
        assert_eq!(Plan::new(&f, &f.body, &none, 3, &[], &[]).bounds, [0, 5]);
        assert_eq!(Plan::new(&f, &f.body, &none, 2, &[], &[]).bounds, [0, 2, 4, 5]);
        // Chunk 2 cuts at 2 and 4; with c (position 2) attached to b, the first cut moves to 3
        // and the next one (3 + 2) is the end.
        let mut att = none.clone();
        att[2] = true;
        assert_eq!(Plan::new(&f, &f.body, &att, 2, &[], &[]).bounds, [0, 3, 5]);
    }

    #[test]
    fn pre_values_and_end_uses_cross_every_boundary_up_to_their_reader() {
        let f = parse(CHAIN).unwrap().functions.remove(0);
        let x = f.inputs[0];
        let [a, e] = ["a", "e"].map(|n| value(&f, n));
        let none = vec![false; 5];
        // x stored by the entry point (read by parts 0 and 1); a read after the last part's
        // statements (an output written last).
        let p = Plan::new(&f, &f.body, &none, 2, &[x], &[a]);
        assert!(p.reads_live(x, 0) && p.reads_live(x, 2));
        assert!(p.slot(x).is_some() && p.slot(a).is_some());
        assert!(p.reads_live(a, 2));
        assert_eq!(p.slot(e), None, "e is computed in the last part");
    }
}
