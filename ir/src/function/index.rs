//! The indexes a [`Function`](super::Function) keeps beside its values: every value by name,
//! every output by name, and the schedule attributes by value index. Derived from the
//! function's own data (ignored by `==`, except the attributes), rebuilt when they do not match.

use crate::entities::Value;
use crate::format::Format;
use crate::syntax::{Output, Timing, ValueData};

/// Every value by name, holding only the [`Value`]s (the names stay in `values`: one `String`
/// per value, not two — issue 10 §3, memory of large functions). Derived from `values`, so
/// ignored by `==`.
#[derive(Clone, Debug, Default)]
pub(super) struct NameIndex(hashbrown::HashTable<(u32, Value)>);

impl PartialEq for NameIndex {
    fn eq(&self, _: &NameIndex) -> bool {
        true
    }
}

/// Schedule attributes by value index, beside the values rather than in them: an analysis
/// writes them into a compact table, and the passes that never read them (all but `place`'s
/// seed keys and the printer) do not carry 24 bytes per value through the caches (issue 28:
/// `asap-alap` on 2.4M values streamed the whole value table twice). Shorter than `values`
/// when the last values have none; `==` compares the attributes, not the table's length.
#[derive(Clone, Debug, Default)]
pub(super) struct Timings(pub(super) Vec<Option<Timing>>);

impl Timings {
    pub(super) fn get(&self, i: usize) -> Option<Timing> {
        self.0.get(i).copied().flatten()
    }
}

impl PartialEq for Timings {
    fn eq(&self, other: &Timings) -> bool {
        (0..self.0.len().max(other.0.len())).all(|i| self.get(i) == other.get(i))
    }
}

/// The numeric format of each value by index (issue 48), the default ([`Format::Binary64`]) past
/// its end: most functions carry none, and then it is empty.
#[derive(Clone, Debug, Default)]
pub(super) struct Formats(pub(super) Vec<Format>);

impl Formats {
    pub(super) fn get(&self, i: usize) -> Format {
        self.0.get(i).copied().unwrap_or_default()
    }
}

impl PartialEq for Formats {
    fn eq(&self, other: &Formats) -> bool {
        (0..self.0.len().max(other.0.len())).all(|i| self.get(i) == other.get(i))
    }
}

pub(super) fn name_hash(name: &str) -> u64 {
    use std::hash::{BuildHasher, BuildHasherDefault};
    BuildHasherDefault::<rustc_hash::FxHasher>::default().hash_one(name)
}

/// The name index's hash of `name`, folded to 32 bits: stored beside each value, so that
/// growing the table and most mismatches read no name (each name read is a cache miss on
/// large functions: the value table and the strings are far apart; issue 28).
///
/// A name `prefix.k` (k decimal: the names `atomise` and the rewriting passes give an
/// equation's temporaries, `AlF15.1`, `AlF15.2`, …) hashes to `prefix`'s hash plus k, and
/// [`spread`] keeps those bits as the table's bucket: the entries of one equation's values are
/// neighbours in the table, so naming them touches a few cache lines instead of one per value
/// (WALK-MAN × 64, 2.4M values: the table is larger than the L3 cache).
///
/// The suffix is read from the end, byte by byte (at most ten bytes): this runs once per value
/// named and per lookup, and a search of the whole name for its last `.` cost 3 % of a
/// 10,000-joint URDF's load.
#[inline]
fn short_hash(name: &str) -> u32 {
    let fold = |h: u64| (h ^ (h >> 32)) as u32;
    let b = name.as_bytes();
    let digits = b.iter().rev().take(10).take_while(|c| c.is_ascii_digit()).count();
    if (1..=9).contains(&digits) && b.len() > digits && b[b.len() - digits - 1] == b'.' {
        let k = b[b.len() - digits..].iter().fold(0u32, |k, &c| k * 10 + u32::from(c - b'0'));
        return fold(name_hash(&name[..b.len() - digits - 1])).wrapping_add(k);
    }
    fold(name_hash(name))
}

/// A stored short hash as the table's 64-bit hash: the low 32 bits (the bucket) are the short
/// hash itself, so neighbouring short hashes are neighbouring buckets; the high bits (the
/// table's tag) are mixed.
fn spread(h: u32) -> u64 {
    ((h as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) & !0xFFFF_FFFF) | h as u64
}

fn name_is(values: &[ValueData], v: Value, name: &str) -> bool {
    values.get(v.index()).is_some_and(|d| d.name == name)
}

impl NameIndex {
    pub(super) fn get(&self, values: &[ValueData], name: &str) -> Option<Value> {
        let h = short_hash(name);
        self.0.find(spread(h), |&(eh, v)| eh == h && name_is(values, v, name)).map(|&(_, v)| v)
    }

    /// Indexes `v` under its name in `values` (the caller checked it is free).
    pub(super) fn insert(&mut self, values: &[ValueData], v: Value) {
        let h = short_hash(&values[v.index()].name);
        self.0.insert_unique(spread(h), (h, v), |&(eh, _)| spread(eh));
    }

    /// Indexes `next` (the value about to be pushed) under `name` when no value has that
    /// name, with one hash and one probe; `Err(existing)` otherwise.
    pub(super) fn claim(&mut self, values: &[ValueData], name: &str, next: Value) -> Result<(), Value> {
        let h = short_hash(name);
        match self.0.entry(spread(h), |&(eh, v)| eh == h && name_is(values, v, name), |&(eh, _)| spread(eh)) {
            hashbrown::hash_table::Entry::Occupied(e) => Err(e.get().1),
            hashbrown::hash_table::Entry::Vacant(e) => {
                e.insert((h, next));
                Ok(())
            }
        }
    }

    pub(super) fn reserve(&mut self, additional: usize) {
        self.0.reserve(additional, |&(eh, _)| spread(eh));
    }

    pub(super) fn build(values: &[ValueData]) -> NameIndex {
        NameIndex::build_until(values, &mut || false).expect("never stopped")
    }

    /// [`NameIndex::build`] that calls `stop` once per value and gives up (`None`) at the
    /// first `true` (a time limit, [`super::Function::retain_until`]).
    pub(super) fn build_until(values: &[ValueData], stop: &mut dyn FnMut() -> bool) -> Option<NameIndex> {
        let mut ix = NameIndex(hashbrown::HashTable::with_capacity(values.len()));
        // As a map built by inserting every value in order: the last of equal names wins.
        for (i, d) in values.iter().enumerate() {
            if stop() {
                return None;
            }
            let v = Value::with_number(i as u32);
            let h = short_hash(&d.name);
            match ix.0.find_mut(spread(h), |&(eh, x)| eh == h && name_is(values, x, &d.name)) {
                Some(slot) => slot.1 = v,
                None => ix.insert(values, v),
            }
        }
        Some(ix)
    }
}

/// Position of every output by name, so that [`Function::set_output`] does not scan the
/// outputs (which made building a function with n outputs O(n²)). `outputs` is public and
/// may be edited directly: the index is checked before use and rebuilt when it does not match
/// (the number of outputs differs, the last output is not where the index says, or the entry
/// found names another output; code that renames outputs in place without changing their
/// number calls [`Function::reindex_names`]). Ignored by `==`.
#[derive(Clone, Debug, Default)]
pub(super) struct OutputIndex {
    /// (hash of the name the output had when indexed, position): 16 bytes per output, the
    /// names stay in `outputs` (issue 10 §3).
    pub(super) pos: hashbrown::HashTable<(u64, usize)>,
    /// Outputs compared by name while locating outputs (one per lookup when the index is
    /// current; a rebuild counts every output): the work counter behind
    /// [`Function::output_probes`].
    pub(super) probes: u64,
}

impl PartialEq for OutputIndex {
    fn eq(&self, _: &OutputIndex) -> bool {
        true
    }
}

impl OutputIndex {
    /// The index of `outputs` (the last of equal names wins, as in a map built in order).
    pub(super) fn build(outputs: &[Output]) -> hashbrown::HashTable<(u64, usize)> {
        OutputIndex::build_until(outputs, &mut || false).expect("never stopped")
    }

    /// [`OutputIndex::build`] that calls `stop` once per output and gives up (`None`) at the
    /// first `true` (a time limit, [`super::Function::retain_until`]).
    pub(super) fn build_until(
        outputs: &[Output],
        stop: &mut dyn FnMut() -> bool,
    ) -> Option<hashbrown::HashTable<(u64, usize)>> {
        let mut pos = hashbrown::HashTable::with_capacity(outputs.len());
        for (i, o) in outputs.iter().enumerate() {
            if stop() {
                return None;
            }
            let h = name_hash(&o.name);
            match pos.find_mut(h, |&(eh, j): &(u64, usize)| eh == h && outputs[j].name == o.name) {
                Some(e) => e.1 = i,
                None => {
                    pos.insert_unique(h, (h, i), |&(eh, _)| eh);
                }
            }
        }
        Some(pos)
    }

    /// The position indexed under the name hashed `h` and whether an entry is there.
    pub(super) fn get(&self, h: u64) -> Option<usize> {
        self.pos.find(h, |&(eh, _)| eh == h).map(|&(_, i)| i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The byte scan gives what splitting at the last `.` gave (the definition before it).
    #[test]
    fn short_hash_reads_the_decimal_suffix_as_splitting_at_the_last_dot_does() {
        let by_split = |name: &str| -> u32 {
            let fold = |h: u64| (h ^ (h >> 32)) as u32;
            match name.rsplit_once('.') {
                Some((prefix, k)) if (1..=9).contains(&k.len()) && k.bytes().all(|b| b.is_ascii_digit()) => {
                    fold(name_hash(prefix)).wrapping_add(k.parse::<u32>().unwrap())
                }
                _ => fold(name_hash(name)),
            }
        };
        let names = [
            "AlF15.1",
            "AlF15.12",
            "a.999999999",
            "a.1234567890",
            "x",
            "x.",
            ".5",
            "5",
            "a.b.7",
            "a.7b",
            "q[3]",
            "t.0",
            "t.00",
            "dpt[1][2].3",
            "é.4",
            "a..9",
            "",
        ];
        for n in names {
            assert_eq!(short_hash(n), by_split(n), "{n:?}");
        }
        // Every name of up to four characters over a small alphabet.
        let alphabet = ['a', '.', '1', '9', '0', '['];
        let mut stack = vec![String::new()];
        while let Some(s) = stack.pop() {
            assert_eq!(short_hash(&s), by_split(&s), "{s:?}");
            if s.len() < 4 {
                stack.extend(alphabet.iter().map(|c| format!("{s}{c}")));
            }
        }
    }
}
