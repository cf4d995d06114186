//! The interconnect of a design (issue 49 item 2, `codegen<fpga;interconnect=…>`).
//!
//! The seed's machine (§1.3) has a **crossbar**: each of a PE memory's two write ports selects
//! any of the `2·n_pe` words of a cycle (every PE's arriving result and buffer read), so any
//! program of `n_pe` PEs can be loaded into the same hardware, at `2·n_pe · 2·n_pe` 32-bit
//! multiplexer inputs: the logic that grows as N² and keeps designs beyond 8 + 8 PEs off the
//! DE10-Nano (docs/fpga.md). But a placement is static: a port needs only the sources its
//! program routes to it. The **specialised** interconnect gives each write port a multiplexer
//! over exactly those sources ([`Routes`]), and its crossbar memory a select of
//! `⌈log2(k + 1)⌉` bits for `k` sources (0: no write, `i`: the port's `i`-th source), where the
//! crossbar's select has `⌈log2(2·n_pe + 1)⌉` bits. (These are the `xbar` images' selects; the
//! control word the HDL reads holds each one less, 0-based, in `⌈log2 k⌉` bits:
//! `Design::lane_select_bits`.)
//!
//! A memory whose writes cannot give each source one port (an odd cycle of sources written
//! together) may also have a **shared multiplexer** over some of its sources, whose output is
//! one more input of both ports ([`assign_write_ports`]): two sources written in one cycle then
//! need only differ in port or in being shared, where a source on both ports cost two inputs.
//!
//! Which programs a specialised design accepts ([`Routes::admits`]): one on the same PEs
//! (`n_add`, `n_mul`, latencies) whose every write routes a source the port (or the memory's
//! shared multiplexer, one shared source a cycle) already has, whose
//! memories are within the design's (PE memory, buffer and output memory depths) and whose
//! cycles are within its instruction memories. Another placement of the same function, or
//! another function, generally routes other sources: it needs the crossbar design or a
//! specialised design of its own. Both designs compute the same bits for their program
//! (`tests/fpga.rs` simulates both against `-eval`).

use serde::Serialize;

use super::addr_bits;

/// How the PE memories' write ports are connected (`codegen<fpga;interconnect=…>`; module
/// doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interconnect {
    /// The seed's crossbar: every port selects any of the `2·n_pe` sources (any program of the
    /// same PEs can be loaded).
    Crossbar,
    /// A multiplexer per port over the sources its program routes ([`Routes`]).
    Specialised,
}

impl Interconnect {
    /// Every word of `interconnect=`, in the variants' order.
    pub const WORDS: &'static [&'static str] = &["crossbar", "specialised"];

    /// The value's word.
    pub const fn as_str(self) -> &'static str {
        match self {
            Interconnect::Crossbar => "crossbar",
            Interconnect::Specialised => "specialised",
        }
    }

    /// The value written `word`, if any.
    pub fn from_word(word: &str) -> Option<Interconnect> {
        [Interconnect::Crossbar, Interconnect::Specialised].into_iter().find(|i| i.as_str() == word)
    }
}

/// Per PE memory and write port, the crossbar selects its program routes (the selects of
/// [`crate::encode`]: `1..=n_pe` the result arriving from slot `s − 1`, `n_pe + 1..=2·n_pe`
/// the buffer read of slot `s − n_pe − 1`).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Routes {
    /// PEs of the design (the selects' range is `1..=2·n_pe`).
    pub n_pe: usize,
    /// Per PE slot, per write port (0, 1): the selects routed, ascending, without duplicates,
    /// without the shared ones.
    pub ports: Vec<[Vec<u32>; 2]>,
    /// Per PE slot: the selects routed through its memory's shared multiplexer, ascending
    /// ([`assign_write_ports`]); its output is the last input of both ports. Empty: none.
    pub shared: Vec<Vec<u32>>,
}

/// A crossbar word's two selects (`[0, sw)` port 0, `[sw, 2sw)` port 1).
pub fn selects(word: u64, sw: u32) -> [u64; 2] {
    let mask = (1u64 << sw) - 1;
    [word & mask, (word >> sw) & mask]
}

/// Assigns one PE memory's writes to its two write ports so that each source is routed to one
/// port where it can be (`instr`, `xbar`: the PE's instruction and crossbar words, one per
/// cycle, rewritten in place; `aw`, `sw`: the layout's address and select bits); returns the
/// sources (crossbar selects, ascending) that go through the memory's **shared multiplexer**,
/// empty when it has none. The program says which words a memory receives each cycle, not on
/// which port: a specialised port's multiplexer has an input per source it ever carries, so a
/// source written through both ports costs two inputs where one would do. The sources written
/// in one cycle must take different ports: the ports are a 2-colouring of that conflict graph
/// (breadth first, then improved as a maximum cut is: a source whose same-coloured neighbours
/// outnumber the others changes colour, until none does); where an odd cycle forbids one, the
/// source with the most same-coloured neighbours takes both ports, and so on until every
/// conflict is met. A third colour removes those duplicates: a shared multiplexer over some
/// sources whose output is one more input of both ports, so that two sources written in one
/// cycle need only differ in colour (port 0, port 1 or shared; a source written twice in one
/// cycle is shared, both ports taking the shared output). A 3-colouring by saturation (DSatur:
/// the source with the most distinct colours among its neighbours first), the sources it
/// cannot colour on both ports, is kept when its inputs (the shared sources and two for the
/// shared output) are fewer than the 2-colouring's. A cycle's writes then go to their sources'
/// ports (a single write may use port 1 alone). The Jeep's `dirdyna` at 32 + 32 PEs: 2,949
/// multiplexer inputs as the lowering numbered the writes, 1,792 distinct (memory, source)
/// pairs, the floor this reaches when the graphs are bipartite; at 36 + 42
/// (`recurrence<pe=40>`) the breadth-first colouring gave 2,723 inputs and the local search
/// 2,698 (2,330 pairs). A placement that kept each source on one port of each memory (writes
/// whose port was taken went through the buffer) did not do better: 2,724 inputs, all
/// distinct pairs, as many buffer routes as it had saved duplicates.
pub fn assign_write_ports(instr: &mut [u64], xbar: &mut [u64], aw: u32, sw: u32) -> Vec<u32> {
    let mask = |bits: u32| (1u64 << bits) - 1;
    // per source (a select below 2^sw): its neighbours, whether it is written twice in a cycle
    let n_sel = 1usize << sw;
    let we = |i: u64, p: u32| i >> (4 * aw + p) & 1 == 1;
    // the sources (crossbar selects) written each cycle, in port order
    let writes = |c: usize| -> Vec<u64> {
        let sel = selects(xbar[c], sw);
        (0..2u32).filter(|&p| we(instr[c], p)).map(|p| sel[p as usize]).collect()
    };
    let mut adjacent: Vec<Vec<u64>> = vec![Vec::new(); n_sel];
    let mut used = vec![false; n_sel];
    let mut twice = vec![false; n_sel];
    for c in 0..instr.len() {
        let w = writes(c);
        for &g in &w {
            used[g as usize] = true;
        }
        if let [a, b] = w[..] {
            if a == b {
                twice[a as usize] = true;
            } else {
                adjacent[a as usize].push(b);
                adjacent[b as usize].push(a);
            }
        }
    }
    for a in &mut adjacent {
        a.sort_unstable();
        a.dedup();
    }
    let sources: Vec<u64> = (0..n_sel as u64).filter(|&g| used[g as usize]).collect();
    // colours: 0 and 1 the ports, SHARED the shared multiplexer, BOTH both ports
    let two = two_colouring(&sources, &adjacent, &twice);
    let two_cost = inputs(&sources, &two);
    // a shared output costs two inputs: worth trying only where three sources are on both ports
    let colour = match two_cost >= sources.len() + 3 {
        true => {
            let three = three_colouring(&sources, &adjacent, &twice);
            if inputs(&sources, &three) < two_cost {
                three
            } else {
                two
            }
        }
        false => two,
    };
    let c = |g: u64| colour[g as usize];
    for cy in 0..instr.len() {
        let (i, x) = (instr[cy], xbar[cy]);
        let sel = selects(x, sw);
        let fields: Vec<(u64, u64)> =
            (0..2u32).filter(|&p| we(i, p)).map(|p| (sel[p as usize], i >> ((2 + p) * aw) & mask(aw))).collect();
        let port = |g: u64| matches!(c(g), 0 | 1).then(|| c(g));
        // the port of each write
        let ports: Vec<u32> = match fields[..] {
            [] => continue,
            [(a, _)] => vec![port(a).unwrap_or(0)],
            [(a, _), (b, _)] => {
                debug_assert!(!(c(a) == SHARED && c(b) == SHARED && a != b), "two shared sources in a cycle");
                let pa = match (port(a), port(b)) {
                    (Some(p), _) => p,
                    (None, Some(q)) => 1 - q,
                    (None, None) => 0,
                };
                vec![pa, 1 - pa]
            }
            _ => unreachable!("two write ports"),
        };
        let (mut i2, mut x2) = (i, 0u64);
        for p in 0..2u32 {
            i2 &= !(mask(aw) << ((2 + p) * aw));
            i2 &= !(1 << (4 * aw + p));
        }
        for (&(g, addr), &p) in fields.iter().zip(&ports) {
            i2 |= addr << ((2 + p) * aw) | 1 << (4 * aw + p);
            x2 |= g << (p * sw);
        }
        instr[cy] = i2;
        xbar[cy] = x2;
    }
    sources.iter().filter(|&&g| c(g) == SHARED).map(|&g| g as u32).collect()
}

/// A source's colour in [`assign_write_ports`]: port 0, port 1, the shared multiplexer, or both
/// ports.
const SHARED: u32 = 2;
const BOTH: u32 = 3;

/// The 2-colouring of [`assign_write_ports`] (breadth first, a maximum cut's local search, then
/// both ports for the sources in the most conflicts left, and for those written twice in a
/// cycle): the colour of each select.
fn two_colouring(sources: &[u64], adjacent: &[Vec<u64>], twice: &[bool]) -> Vec<u32> {
    let mut colour: Vec<Option<u32>> = vec![None; adjacent.len()];
    for &g in sources {
        if colour[g as usize].is_some() {
            continue;
        }
        colour[g as usize] = Some(0);
        let mut queue = std::collections::VecDeque::from([g]);
        while let Some(a) = queue.pop_front() {
            let ca = colour[a as usize].unwrap_or(0);
            for &b in &adjacent[a as usize] {
                if colour[b as usize].is_none() {
                    colour[b as usize] = Some(1 - ca);
                    queue.push_back(b);
                }
            }
        }
    }
    let mut colour: Vec<u32> = colour.into_iter().map(|c| c.unwrap_or(0)).collect();
    // local search (a maximum cut's): flip a source whose same-coloured neighbours outnumber
    // the others; each flip cuts more conflicts, so it ends
    let mut flipped = true;
    while flipped {
        flipped = false;
        for &a in sources {
            let same = adjacent[a as usize].iter().filter(|&&b| colour[b as usize] == colour[a as usize]).count();
            if 2 * same > adjacent[a as usize].len() {
                colour[a as usize] ^= 1;
                flipped = true;
            }
        }
    }
    for &a in sources {
        if twice[a as usize] {
            colour[a as usize] = BOTH;
        }
    }
    // conflicts the colouring leaves: both ports for the source in the most of them, repeatedly
    loop {
        let mut worst: Option<(usize, u64)> = None;
        for &a in sources {
            let ca = colour[a as usize];
            if ca == BOTH {
                continue;
            }
            let bad = adjacent[a as usize].iter().filter(|&&b| colour[b as usize] == ca).count();
            if bad > 0 && worst.is_none_or(|(n, _)| bad > n) {
                worst = Some((bad, a));
            }
        }
        match worst {
            Some((_, a)) => colour[a as usize] = BOTH,
            None => break,
        }
    }
    colour
}

/// The multiplexer inputs a colouring of [`assign_write_ports`] costs: one a source, two a
/// source on both ports, and two for the shared output into both ports when a source is shared.
fn inputs(sources: &[u64], colour: &[u32]) -> usize {
    let c = |g: &u64| colour[*g as usize];
    let shared = sources.iter().any(|g| c(g) == SHARED);
    sources.iter().map(|g| if c(g) == BOTH { 2 } else { 1 }).sum::<usize>() + if shared { 2 } else { 0 }
}

/// The 3-colouring of [`assign_write_ports`] by saturation (DSatur, Brélaz 1979): the uncoloured
/// source with the most distinct colours among its neighbours (then the most neighbours, then
/// the lowest select) takes the lowest colour none of them has, a source written twice in a
/// cycle only [`SHARED`]; one that cannot takes both ports. The colour of each select.
fn three_colouring(sources: &[u64], adjacent: &[Vec<u64>], twice: &[bool]) -> Vec<u32> {
    const NONE: u32 = u32::MAX;
    let mut colour = vec![NONE; adjacent.len()];
    // per source: the colours among its coloured neighbours (bit k: colour k)
    let mut seen = vec![0u8; adjacent.len()];
    // buckets by (saturation, degree): a binary heap with lazy deletion keeps it O(E log V)
    let key = |g: u64, seen: &[u8]| (seen[g as usize].count_ones(), adjacent[g as usize].len(), std::cmp::Reverse(g));
    let mut heap: std::collections::BinaryHeap<_> = sources.iter().map(|&g| (key(g, &seen), g)).collect();
    while let Some((k, a)) = heap.pop() {
        if colour[a as usize] != NONE || k != key(a, &seen) {
            continue;
        }
        let options: &[u32] = if twice[a as usize] { &[SHARED] } else { &[0, 1, SHARED] };
        let ca = options.iter().copied().find(|&c| seen[a as usize] >> c & 1 == 0).unwrap_or(BOTH);
        colour[a as usize] = ca;
        if ca == BOTH {
            continue;
        }
        for &b in &adjacent[a as usize] {
            if colour[b as usize] == NONE && seen[b as usize] >> ca & 1 == 0 {
                seen[b as usize] |= 1 << ca;
                heap.push((key(b, &seen), b));
            }
        }
    }
    colour
}

impl Routes {
    /// The routes of crossbar images `xbar` (per PE slot, one word per cycle, selects of `sw`
    /// bits) of a design of `n_pe` PEs, with the selects `shared` of each slot through its
    /// shared multiplexer (none when `shared` is shorter).
    pub fn of_crossbar(n_pe: usize, sw: u32, xbar: &[&[u64]], shared: &[Vec<u32>]) -> Routes {
        let shared: Vec<Vec<u32>> = (0..xbar.len()).map(|s| shared.get(s).cloned().unwrap_or_default()).collect();
        let ports = xbar
            .iter()
            .zip(&shared)
            .map(|(words, sh)| {
                let mut used = [Vec::new(), Vec::new()];
                for &w in words.iter() {
                    for (port, sel) in selects(w, sw).into_iter().enumerate() {
                        if sel != 0 && sh.binary_search(&(sel as u32)).is_err() {
                            used[port].push(sel as u32);
                        }
                    }
                }
                for u in &mut used {
                    u.sort_unstable();
                    u.dedup();
                }
                used
            })
            .collect();
        Routes { n_pe, ports, shared }
    }

    /// Whether PE `slot`'s memory has a shared multiplexer.
    pub fn has_shared(&self, slot: usize) -> bool {
        !self.shared[slot].is_empty()
    }

    /// Multiplexer inputs of port `port` on PE `slot`: its sources and the shared output.
    pub fn port_inputs(&self, slot: usize, port: usize) -> usize {
        self.ports[slot][port].len() + usize::from(self.has_shared(slot))
    }

    /// Bits of port `port`'s select on PE `slot`: `⌈log2(k + 1)⌉` for `k` inputs
    /// ([`Routes::port_inputs`]), at least 1.
    pub fn select_bits(&self, slot: usize, port: usize) -> u32 {
        addr_bits(self.port_inputs(slot, port) as u64 + 1)
    }

    /// Bits of PE `slot`'s shared multiplexer select: `⌈log2(k + 1)⌉` for `k` shared sources,
    /// 0 without one.
    pub fn shared_bits(&self, slot: usize) -> u32 {
        match self.shared[slot].len() {
            0 => 0,
            k => addr_bits(k as u64 + 1),
        }
    }

    /// Bits of PE `slot`'s specialised crossbar word: port 0's select, port 1's, the shared one.
    pub fn word_bits(&self, slot: usize) -> u32 {
        self.select_bits(slot, 0) + self.select_bits(slot, 1) + self.shared_bits(slot)
    }

    /// The specialised crossbar word of crossbar selects `[g0, g1]` (port 0, port 1) on `slot`:
    /// each port's select (0 none, `i` its `i`-th source, `k + 1` the shared output), then the
    /// shared select (`i`: the `i`-th shared source; 0 when no write takes it). `None` when a
    /// port has no such route or the writes need two shared sources.
    pub fn encode(&self, slot: usize, [g0, g1]: [u64; 2]) -> Option<u64> {
        let sh = &self.shared[slot];
        let mut shared = 0u64;
        let mut local = |port: usize, g: u64| -> Option<u64> {
            if g == 0 {
                return Some(0);
            }
            let g32 = u32::try_from(g).ok()?;
            if let Ok(i) = sh.binary_search(&g32) {
                if shared != 0 && shared != i as u64 + 1 {
                    return None;
                }
                shared = i as u64 + 1;
                return Some(self.ports[slot][port].len() as u64 + 1);
            }
            self.ports[slot][port].binary_search(&g32).ok().map(|i| i as u64 + 1)
        };
        let (l0, l1) = (local(0, g0)?, local(1, g1)?);
        let (b0, b1) = (self.select_bits(slot, 0), self.select_bits(slot, 1));
        Some(l0 | l1 << b0 | shared << (b0 + b1))
    }

    /// The three selects of specialised word `word` on `slot` as [`Routes::encode`] packs them:
    /// port 0's and port 1's route index (0 none, `i` the `i`-th route, `k + 1` the shared
    /// output) and the shared select (0 none, `i` the `i`-th shared source).
    pub fn fields(&self, slot: usize, word: u64) -> [u64; 3] {
        let (b0, b1) = (self.select_bits(slot, 0), self.select_bits(slot, 1));
        [word & ((1 << b0) - 1), word >> b0 & ((1 << b1) - 1), word >> (b0 + b1)]
    }

    /// The crossbar selects `[g0, g1]` of specialised word `word` on `slot` (inverse of
    /// [`Routes::encode`]); `None` beyond a port's inputs or the shared sources.
    pub fn decode(&self, slot: usize, word: u64) -> Option<[u64; 2]> {
        if word >> self.word_bits(slot) != 0 {
            return None;
        }
        let [l0, l1, ls] = self.fields(slot, word);
        let global = |port: usize, l: u64| -> Option<u64> {
            let list = self.ports.get(slot)?.get(port)?;
            match l {
                0 => Some(0),
                l if l as usize <= list.len() => Some(u64::from(list[l as usize - 1])),
                l if l as usize == list.len() + 1 && ls >= 1 => {
                    self.shared[slot].get(ls as usize - 1).map(|&g| u64::from(g))
                }
                _ => None,
            }
        };
        Some([global(0, l0)?, global(1, l1)?])
    }

    /// Multiplexer inputs of every port and shared multiplexer (words): `Σ k`; a crossbar has
    /// `2·n_pe` per port.
    pub fn mux_inputs(&self) -> u64 {
        (0..self.ports.len())
            .map(|s| (self.port_inputs(s, 0) + self.port_inputs(s, 1) + self.shared[s].len()) as u64)
            .sum()
    }

    /// The name of select `sel` in the design (`result add0`, `buffer mul1`), PE names by
    /// `name(slot)`.
    pub fn source_name(&self, sel: u32, name: impl Fn(usize) -> String) -> String {
        let s = sel as usize;
        if s <= self.n_pe {
            format!("result {}", name(s - 1))
        } else {
            format!("buffer {}", name(s - self.n_pe - 1))
        }
    }

    /// `Ok` when every route of `program` (the routes of another program on the same PEs) is
    /// one of these, a source of the port or of the memory's shared multiplexer (a shared
    /// source of `program` on both ports): the interconnect of this design can carry it (module
    /// doc) if, as [`Routes::encode`] checks word by word, no cycle of `program` writes two of
    /// this design's shared sources into one memory.
    ///
    /// # Errors
    /// The first route missing (PE slot, port, select) and how many are missing, or a
    /// different number of PEs.
    pub fn admits(&self, program: &Routes) -> Result<(), String> {
        if program.n_pe != self.n_pe || program.ports.len() != self.ports.len() {
            return Err(format!("the program has {} PEs; the design has {}", program.n_pe, self.n_pe));
        }
        let mut missing = Vec::new();
        for (slot, (have, want)) in self.ports.iter().zip(&program.ports).enumerate() {
            let has = |port: usize, sel: &u32| {
                have[port].binary_search(sel).is_ok() || self.shared[slot].binary_search(sel).is_ok()
            };
            for (port, wanted) in want.iter().enumerate() {
                for &sel in wanted.iter().chain(&program.shared[slot]) {
                    if !has(port, &sel) {
                        missing.push((slot, port, sel));
                    }
                }
            }
        }
        match missing.first() {
            None => Ok(()),
            Some(&(slot, port, sel)) => Err(format!(
                "{} route(s) missing from the specialised interconnect; first: select {sel} into port {port} of PE slot {slot}",
                missing.len()
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Writes of one PE memory (`aw` address bits, `sw` select bits): `(select, address)` per
    /// port, `None`: no write; the words [`assign_write_ports`] reads.
    fn program_words(cycles: &[[Option<(u64, u64)>; 2]], aw: u32, sw: u32) -> (Vec<u64>, Vec<u64>) {
        cycles
            .iter()
            .map(|ports| {
                let (mut i, mut x) = (0u64, 0u64);
                for (p, w) in ports.iter().enumerate() {
                    if let Some((g, a)) = w {
                        i |= a << ((2 + p as u32) * aw) | 1 << (4 * aw + p as u32);
                        x |= g << (p as u32 * sw);
                    }
                }
                (i, x)
            })
            .unzip()
    }

    /// The writes of instruction word `i` and crossbar word `x`: `(select, address, port)`.
    fn writes_of(i: u64, x: u64, aw: u32, sw: u32) -> Vec<(u64, u64, u32)> {
        (0..2u32)
            .filter(|&p| i >> (4 * aw + p) & 1 == 1)
            .map(|p| (x >> (p * sw) & ((1 << sw) - 1), i >> ((2 + p) * aw) & ((1 << aw) - 1), p))
            .collect()
    }

    /// The `(select, address)` pairs of [`writes_of`], sorted: what a memory receives whatever
    /// the ports.
    fn received(i: u64, x: u64, aw: u32, sw: u32) -> Vec<(u64, u64)> {
        let mut k: Vec<(u64, u64)> = writes_of(i, x, aw, sw).iter().map(|w| (w.0, w.1)).collect();
        k.sort_unstable();
        k
    }

    #[test]
    fn write_ports_take_one_source_each_where_the_cycles_allow() {
        let (aw, sw) = (4, 3);
        // sources 1, 2, 3 written in pairs around an odd cycle (1-2, 2-3, 3-1), 4 with 1 and
        // alone on port 1, 5 alone: a 2-colouring fails on the triangle, so one of 1, 2, 3
        // takes both ports, every other source one
        let w = |g, a| Some((g, a));
        let cycles = [
            [w(1, 1), w(2, 2)],
            [w(3, 3), w(2, 4)],
            [w(1, 5), w(3, 6)],
            [w(4, 7), w(1, 8)],
            [None, w(4, 9)],
            [w(5, 10), None],
            [None, None],
        ];
        let (mut instr, mut xbar) = program_words(&cycles, aw, sw);
        let before = (instr.clone(), xbar.clone());
        assert!(assign_write_ports(&mut instr, &mut xbar, aw, sw).is_empty(), "a shared output costs two inputs");
        let mut ports: Vec<std::collections::BTreeSet<u32>> = vec![Default::default(); 8];
        for c in 0..cycles.len() {
            let new = writes_of(instr[c], xbar[c], aw, sw);
            assert_eq!(
                received(before.0[c], before.1[c], aw, sw),
                received(instr[c], xbar[c], aw, sw),
                "cycle {c}: the same writes"
            );
            if let [a, b] = new[..] {
                assert_ne!(a.2, b.2, "cycle {c}: two writes, two ports");
            }
            for (g, _, p) in new {
                ports[g as usize].insert(p);
            }
        }
        let on_both: Vec<usize> = (1..6).filter(|&g| ports[g].len() == 2).collect();
        assert_eq!(on_both.len(), 1, "{ports:?}");
        assert!(on_both[0] <= 3, "a source of the triangle: {ports:?}");
        let r = Routes::of_crossbar(2, sw, &[&xbar], &[]);
        assert_eq!(r.ports[0][0].len() + r.ports[0][1].len(), 6, "five sources, one on both ports");
    }

    /// Four triangles of sources written in pairs and a source written twice in a cycle: a
    /// 2-colouring puts one source of each triangle and the twice-written one on both ports
    /// (5 inputs more than the 13 sources), a 3-colouring none, with a shared multiplexer (2
    /// more): the shared one is kept, no cycle takes two shared sources, and the specialised
    /// words encode and decode the same writes.
    #[test]
    fn a_shared_multiplexer_takes_the_sources_of_odd_cycles() {
        let (aw, sw) = (5, 4);
        let w = |g, a| Some((g, a));
        let mut cycles = Vec::new();
        for t in 0..4u64 {
            let (a, b, c) = (3 * t + 1, 3 * t + 2, 3 * t + 3);
            cycles.extend([[w(a, 1), w(b, 2)], [w(b, 3), w(c, 4)], [w(c, 5), w(a, 6)]]);
        }
        cycles.push([w(13, 7), w(13, 8)]);
        cycles.push([w(13, 9), w(1, 10)]);
        let (mut instr, mut xbar) = program_words(&cycles, aw, sw);
        let before = (instr.clone(), xbar.clone());
        let shared = assign_write_ports(&mut instr, &mut xbar, aw, sw);
        assert!(shared.contains(&13), "written twice in a cycle: shared ({shared:?})");
        let r = Routes::of_crossbar(1, sw, &[&xbar], std::slice::from_ref(&shared));
        assert_eq!(r.mux_inputs(), 13 + 2, "each source once, and the shared output into both ports");
        for p in 0..2 {
            assert!(r.ports[0][p].iter().all(|g| !shared.contains(g)), "a shared source is on no port");
        }
        for c in 0..cycles.len() {
            assert_eq!(
                received(instr[c], xbar[c], aw, sw),
                received(before.0[c], before.1[c], aw, sw),
                "cycle {c}: the same writes"
            );
            let sel = selects(xbar[c], sw);
            let word = r.encode(0, sel).expect("every cycle encodes: at most one shared source");
            assert!(word >> r.word_bits(0) == 0);
            let back = r.decode(0, word).unwrap();
            // a port without a write encodes 0 whatever the crossbar word held
            for p in 0..2 {
                if instr[c] >> (4 * aw + p as u32) & 1 == 1 {
                    assert_eq!(back[p], sel[p], "cycle {c} port {p}");
                }
            }
        }
        // two different shared sources in one cycle do not encode
        if let [a, b, ..] = shared[..] {
            assert_eq!(r.encode(0, [u64::from(a), u64::from(b)]), None);
        } else {
            panic!("more than one shared source expected: {shared:?}");
        }
    }

    #[test]
    fn routes_are_the_selects_used_per_port_and_local_selects_invert() {
        // 3 PEs, sw = 3 (selects 0..=6): slot 0 routes 2 and 5 on port 0, 4 on port 1
        let sw = 3;
        let w = |a: u64, b: u64| a | (b << sw);
        let slot0 = [w(2, 0), w(5, 4), w(2, 4), w(0, 0)];
        let slot1 = [w(0, 0)];
        let slot2 = [w(6, 1), w(1, 6)];
        let r = Routes::of_crossbar(3, sw, &[&slot0, &slot1, &slot2], &[]);
        assert_eq!(r.ports[0], [vec![2, 5], vec![4]]);
        assert!(r.ports[1].iter().all(Vec::is_empty));
        assert_eq!(r.ports[2], [vec![1, 6], vec![1, 6]]);
        assert_eq!(r.mux_inputs(), 2 + 1 + 4);
        // k sources need ⌈log2(k + 1)⌉ bits, at least 1
        assert_eq!([r.select_bits(0, 0), r.select_bits(0, 1), r.select_bits(1, 0)], [2, 1, 1]);
        assert_eq!(r.shared_bits(0), 0);
        for (slot, words) in [(0, &slot0[..]), (2, &slot2[..])] {
            for &w in words {
                let sel = selects(w, sw);
                let l = r.encode(slot, sel).unwrap();
                assert!(l >> r.word_bits(slot) == 0);
                assert_eq!(r.decode(slot, l), Some(sel));
            }
        }
        assert_eq!(r.encode(0, [3, 0]), None, "select 3 is not routed into slot 0's port 0");
        assert_eq!(r.encode(1, [0, 0]), Some(0));
        assert_eq!(r.decode(0, 2 << 2), None, "port 1 of slot 0 has one route: a 1-bit select");
        // slot 2 with source 6 shared: off both ports, the ports' last input, its own select
        let r = Routes::of_crossbar(3, sw, &[&slot0, &slot1, &slot2], &[vec![], vec![], vec![6]]);
        assert_eq!(r.ports[2], [vec![1], vec![1]]);
        assert_eq!(r.mux_inputs(), 2 + 1 + (2 + 2 + 1));
        assert_eq!([r.select_bits(2, 0), r.shared_bits(2)], [2, 1]);
        assert_eq!(r.encode(2, [6, 1]), Some(2 | 1 << 2 | 1 << 4));
        assert_eq!(r.decode(2, 2 | 1 << 2 | 1 << 4), Some([6, 1]));
        assert_eq!(r.source_name(2, |s| format!("pe{s}")), "result pe1");
        assert_eq!(r.source_name(6, |s| format!("pe{s}")), "buffer pe2");
    }

    #[test]
    fn a_design_admits_its_own_routes_and_their_subsets_only() {
        let none = || vec![vec![]; 2];
        let r = Routes { n_pe: 2, ports: vec![[vec![1, 3], vec![2]], [vec![], vec![4]]], shared: none() };
        assert!(r.admits(&r).is_ok());
        let sub = Routes { n_pe: 2, ports: vec![[vec![3], vec![]], [vec![], vec![4]]], shared: none() };
        assert!(r.admits(&sub).is_ok());
        let other = Routes { n_pe: 2, ports: vec![[vec![2], vec![2]], [vec![1], vec![4]]], shared: none() };
        let e = r.admits(&other).unwrap_err();
        assert!(e.starts_with("2 route(s) missing"), "{e}");
        assert!(e.contains("select 2 into port 0 of PE slot 0"), "{e}");
        // a shared source serves both ports; a program's shared source needs both
        let sh = Routes { n_pe: 2, ports: vec![[vec![1], vec![]], [vec![], vec![4]]], shared: vec![vec![2], vec![]] };
        assert!(sh.admits(&other).is_err());
        let wants = Routes { n_pe: 2, ports: vec![[vec![2], vec![2]], [vec![], vec![4]]], shared: none() };
        assert!(sh.admits(&wants).is_ok());
        let wants = Routes { shared: vec![vec![1], vec![]], ..wants };
        assert!(sh.admits(&wants).unwrap_err().contains("select 1 into port 1 of PE slot 0"));
        let bigger = Routes { n_pe: 3, ports: vec![[vec![], vec![]]; 3], shared: vec![vec![]; 3] };
        assert!(r.admits(&bigger).unwrap_err().contains("3 PEs"));
    }

    #[test]
    fn words() {
        for w in Interconnect::WORDS {
            assert_eq!(Interconnect::from_word(w).unwrap().as_str(), *w);
        }
        assert_eq!(Interconnect::from_word("mesh"), None);
    }
}
