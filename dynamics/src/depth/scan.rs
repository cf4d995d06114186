//! Parallel prefix networks and the chains of a tree they run along.
//!
//! A prefix (scan) of `x₁, …, x_m` under an associative operation `∘` is the list of
//! `x₁ ∘ ⋯ ∘ x_i` for every `i`. Written as a left-to-right recurrence it has depth `m − 1`;
//! a parallel prefix network has depth about `log₂ m` (R. E. Ladner, M. J. Fischer, "Parallel
//! prefix computation", *J. ACM* 27(4), 1980; R. P. Brent, H. T. Kung, "A regular layout for
//! parallel adders", *IEEE Trans. Computers* C-31(3), 1982). Two networks are written here:
//! - [`Network::Sklansky`] (Ladner–Fischer's `P₀`, J. Sklansky 1960): depth `⌈log₂ m⌉`,
//!   `⌊m/2⌋·⌈log₂ m⌉` operations at most;
//! - [`Network::BrentKung`]: depth `2⌈log₂ m⌉ − 1` at most, fewer than `2m` operations;
//! - [`Network::LadnerFischer`]`(k)` (Ladner–Fischer's `P_k`): `k` levels of Brent–Kung's
//!   pairing around a Sklansky network over the `m / 2^k` pairs' products: depth `⌈log₂ m⌉ + k`
//!   at most, about `m·(2 − 2^{1−k}) + (m / 2^{k+1})·log₂(m / 2^k)` operations — Sklansky's
//!   depth within `k` levels for a fraction of its operations (`k = 0` is Sklansky).
//!
//! The operation is never assumed commutative: `op(a, b)` is `a ∘ b` with `a` the earlier range
//! (3 × 3 rotation products compose in order).
//!
//! A tree is cut into **chains** ([`heavy_chains`], R. E. Tarjan's heavy-path decomposition:
//! each body continues the chain of its child with the largest subtree), so that a path from the
//! root crosses at most `log₂ n` chains; prefixes run along each chain and start from the value
//! of the chain head's parent.

/// A parallel prefix network (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Network {
    /// Depth `⌈log₂ m⌉`, `⌊m/2⌋·⌈log₂ m⌉` operations at most.
    Sklansky,
    /// Depth `2⌈log₂ m⌉ − 1` at most, fewer than `2m` operations.
    BrentKung,
    /// `k` Brent–Kung levels, then Sklansky: depth `⌈log₂ m⌉ + k` at most.
    LadnerFischer(u32),
}

/// The inclusive prefixes `x₁ ∘ ⋯ ∘ x_i` of `xs` (`i = 1..m`, same length as `xs`) by network
/// `net`; `op(a, b)` is `a ∘ b` (associative, `a` the earlier range). Cost: the operations of
/// the module doc, recursion depth `log₂ m`.
pub fn prefix<T: Clone>(xs: &[T], net: Network, op: &mut dyn FnMut(&T, &T) -> T) -> Vec<T> {
    match net {
        Network::Sklansky | Network::LadnerFischer(0) => sklansky(xs, op),
        Network::BrentKung => brent_kung(xs, Network::BrentKung, op),
        Network::LadnerFischer(k) => brent_kung(xs, Network::LadnerFischer(k - 1), op),
    }
}

/// The inclusive suffixes `x_i ∘ ⋯ ∘ x_m` of `xs` (same length), by `net`.
pub fn suffix<T: Clone>(xs: &[T], net: Network, op: &mut dyn FnMut(&T, &T) -> T) -> Vec<T> {
    let rev: Vec<T> = xs.iter().rev().cloned().collect();
    // Reversed, the later range comes first: swap the operands back.
    let mut swapped = |a: &T, b: &T| op(b, a);
    let mut out = prefix(&rev, net, &mut swapped);
    out.reverse();
    out
}

fn sklansky<T: Clone>(xs: &[T], op: &mut dyn FnMut(&T, &T) -> T) -> Vec<T> {
    if xs.len() <= 1 {
        return xs.to_vec();
    }
    // The left half a power of two: every level's totals line up.
    let h = xs.len().next_power_of_two() / 2;
    let mut out = sklansky(&xs[..h], op);
    let right = sklansky(&xs[h..], op);
    let total = out[h - 1].clone();
    out.extend(right.iter().map(|r| op(&total, r)));
    out
}

/// One level of Brent–Kung's pairing: the pairs' products, their prefixes by `inner`, then the
/// even positions fixed up.
fn brent_kung<T: Clone>(xs: &[T], inner: Network, op: &mut dyn FnMut(&T, &T) -> T) -> Vec<T> {
    let m = xs.len();
    if m <= 1 {
        return xs.to_vec();
    }
    let pairs: Vec<T> = (0..m / 2).map(|k| op(&xs[2 * k], &xs[2 * k + 1])).collect();
    let ps = prefix(&pairs, inner, op);
    (0..m)
        .map(|i| match i {
            0 => xs[0].clone(),
            i if i % 2 == 1 => ps[i / 2].clone(),
            i => op(&ps[i / 2 - 1], &xs[i]),
        })
        .collect()
}

/// The heavy-path chains of a tree given by `parent` (index = body `1..=n`, entry 0 unused;
/// `parent[b] < b`, 0 the base): every body in exactly one chain, top to bottom, each chain
/// continued by the child with the largest subtree (the first such in body order). Chains are
/// listed by their head, ascending, so a chain's head's parent lies in an earlier chain (or is
/// the base). Also returns, per body, whether it heads its chain. Cost: O(n).
pub fn heavy_chains(parent: &[usize]) -> (Vec<Vec<usize>>, Vec<bool>) {
    let n = parent.len().saturating_sub(1);
    let mut size = vec![1usize; n + 1];
    for b in (1..=n).rev() {
        if parent[b] != 0 {
            size[parent[b]] += size[b];
        }
    }
    let mut heavy = vec![0usize; n + 1];
    for b in 1..=n {
        let p = parent[b];
        if p != 0 && (heavy[p] == 0 || size[b] > size[heavy[p]]) {
            heavy[p] = b;
        }
    }
    let mut head = vec![true; n + 1];
    for b in 1..=n {
        if parent[b] != 0 && heavy[parent[b]] == b {
            head[b] = false;
        }
    }
    let mut chains = Vec::new();
    for b in (1..=n).filter(|&b| head[b]) {
        let mut chain = vec![b];
        let mut x = b;
        while heavy[x] != 0 {
            x = heavy[x];
            chain.push(x);
        }
        chains.push(chain);
    }
    (chains, head)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Prefixes of strings under concatenation (associative, not commutative), within each
    /// network's depth and operation bounds for 0–39 elements; and the depth and operations of
    /// 16 elements counted by hand: Sklansky 4 levels of 8 (32), Brent–Kung 8 pairs, 11 ops for
    /// the 8 pairs' prefixes (depth 4) and 7 fix-ups (26 ops, depth 6), `P₁` 8 pairs, Sklansky
    /// over them (12 ops, depth 3) and 7 fix-ups (27 ops, depth 5).
    #[test]
    fn networks_give_the_prefixes_in_order_at_their_depth() {
        for m in 0..40usize {
            let xs: Vec<(String, u32)> = (0..m).map(|i| (char::from(b'a' + (i % 26) as u8).to_string(), 0)).collect();
            let want: Vec<String> = (1..=m).map(|i| xs[..i].iter().map(|x| x.0.as_str()).collect()).collect();
            for net in [Network::Sklansky, Network::BrentKung, Network::LadnerFischer(1), Network::LadnerFischer(2)] {
                let mut ops = 0;
                let mut op = |a: &(String, u32), b: &(String, u32)| {
                    ops += 1;
                    (format!("{}{}", a.0, b.0), a.1.max(b.1) + 1)
                };
                let got = prefix(&xs, net, &mut op);
                assert_eq!(got.iter().map(|x| x.0.clone()).collect::<Vec<_>>(), want, "{net:?} {m}");
                let depth = got.iter().map(|x| x.1).max().unwrap_or(0);
                let lg = m.next_power_of_two().trailing_zeros();
                match net {
                    Network::Sklansky => {
                        assert!(depth <= lg, "{net:?} {m}: depth {depth}");
                        assert!(ops <= (m / 2) * lg as usize, "{net:?} {m}: {ops} ops");
                    }
                    Network::BrentKung => {
                        assert!(depth <= (2 * lg).saturating_sub(1), "{net:?} {m}: depth {depth}");
                        assert!(ops < 2 * m.max(1), "{net:?} {m}: {ops} ops");
                    }
                    Network::LadnerFischer(k) => {
                        assert!(depth <= lg + k, "{net:?} {m}: depth {depth}");
                        // k pairing levels (< 2m ops together), then Sklansky over ⌊m/2^k⌋.
                        let rest = m >> k;
                        assert!(ops < 2 * m.max(1) + (rest / 2) * lg as usize, "{net:?} {m}: {ops} ops");
                    }
                }
                let mut op = |a: &(String, u32), b: &(String, u32)| (format!("{}{}", a.0, b.0), 0);
                let suf = suffix(&xs, net, &mut op);
                for (i, s) in suf.iter().enumerate() {
                    assert_eq!(s.0, xs[i..].iter().map(|x| x.0.as_str()).collect::<String>());
                }
            }
        }
    }

    #[test]
    fn networks_of_sixteen_counted_by_hand() {
        let xs: Vec<u32> = vec![0; 16];
        for (net, want) in [
            (Network::Sklansky, (4, 32)),
            (Network::BrentKung, (6, 26)),
            (Network::LadnerFischer(1), (5, 27)),
            (Network::LadnerFischer(2), (6, 26)),
        ] {
            let mut ops = 0;
            let got = prefix(&xs, net, &mut |a: &u32, b: &u32| {
                ops += 1;
                a.max(b) + 1
            });
            assert_eq!((*got.iter().max().unwrap(), ops), want, "{net:?}");
        }
    }

    /// A chain with a two-body branch off its second body: the long branch is the heavy one.
    #[test]
    fn heavy_chains_by_hand() {
        // 1 → 2 → 3 → 4, and 2 → 5 → 6.
        let parent = [0, 0, 1, 2, 3, 2, 5];
        let (chains, head) = heavy_chains(&parent);
        assert_eq!(chains, vec![vec![1, 2, 3, 4], vec![5, 6]]);
        assert_eq!(head, vec![true, true, false, false, false, true, false]);
        // Two chains from the base.
        let (chains, _) = heavy_chains(&[0, 0, 1, 0, 3, 4]);
        assert_eq!(chains, vec![vec![1, 2], vec![3, 4, 5]]);
    }
}
