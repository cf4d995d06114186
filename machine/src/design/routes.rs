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
//! crossbar's select has `⌈log2(2·n_pe + 1)⌉` bits.
//!
//! Which programs a specialised design accepts ([`Routes::admits`]): one on the same PEs
//! (`n_add`, `n_mul`, latencies) whose every write routes a source the port already has, whose
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
    /// Per PE slot, per write port (0, 1): the selects routed, ascending, without duplicates.
    pub ports: Vec<[Vec<u32>; 2]>,
}

/// A crossbar word's two selects (`[0, sw)` port 0, `[sw, 2sw)` port 1).
pub fn selects(word: u64, sw: u32) -> [u64; 2] {
    let mask = (1u64 << sw) - 1;
    [word & mask, (word >> sw) & mask]
}

/// Assigns one PE memory's writes to its two write ports so that each source is routed to one
/// port where it can be (`instr`, `xbar`: the PE's instruction and crossbar words, one per
/// cycle, rewritten in place; `aw`, `sw`: the layout's address and select bits). The program
/// says which words a memory receives each cycle, not on which port: a specialised port's
/// multiplexer has an input per source it ever carries, so a source written through both ports
/// costs two inputs where one would do. The sources written in one cycle must take different
/// ports: the ports are a 2-colouring of that conflict graph (breadth first, then improved as
/// a maximum cut is: a source whose same-coloured neighbours outnumber the others changes
/// colour, until none does); where an odd cycle forbids one, the source with the most
/// same-coloured neighbours takes both ports, and so on until every conflict is met. A cycle's writes then go to their sources' ports (a
/// single write may use port 1 alone). The Jeep's `dirdyna` at 32 + 32 PEs: 2,949 multiplexer
/// inputs as the lowering numbered the writes, 1,792 distinct (memory, source) pairs, the
/// floor this reaches when the graphs are bipartite; at 36 + 42 (`recurrence<pe=40>`) the
/// breadth-first colouring gave 2,723 inputs and the local search 2,698 (2,330 pairs). A
/// placement that kept each source on one port of each memory (writes whose port was taken
/// went through the buffer) did not do better: 2,724 inputs, all distinct pairs, as many
/// buffer routes as it had saved duplicates.
pub fn assign_write_ports(instr: &mut [u64], xbar: &mut [u64], aw: u32, sw: u32) {
    let mask = |bits: u32| (1u64 << bits) - 1;
    // per source (a select below 2^sw): its neighbours, whether it takes both ports, its colour
    let n_sel = 1usize << sw;
    let we = |i: u64, p: u32| i >> (4 * aw + p) & 1 == 1;
    // the sources (crossbar selects) written each cycle, in port order
    let writes = |c: usize| -> Vec<u64> {
        let sel = selects(xbar[c], sw);
        (0..2u32).filter(|&p| we(instr[c], p)).map(|p| sel[p as usize]).collect()
    };
    let mut adjacent: Vec<Vec<u64>> = vec![Vec::new(); n_sel];
    let mut used = vec![false; n_sel];
    let mut both = vec![false; n_sel];
    for c in 0..instr.len() {
        let w = writes(c);
        for &g in &w {
            used[g as usize] = true;
        }
        if let [a, b] = w[..] {
            if a == b {
                both[a as usize] = true;
            } else {
                adjacent[a as usize].push(b);
                adjacent[b as usize].push(a);
            }
        }
    }
    // breadth-first 2-colouring, sources in ascending order (deterministic)
    let sources: Vec<u64> = (0..n_sel as u64).filter(|&g| used[g as usize]).collect();
    let mut colour: Vec<Option<u32>> = vec![None; n_sel];
    for &g in &sources {
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
        for &a in &sources {
            let same = adjacent[a as usize].iter().filter(|&&b| colour[b as usize] == colour[a as usize]).count();
            if 2 * same > adjacent[a as usize].len() {
                colour[a as usize] ^= 1;
                flipped = true;
            }
        }
    }
    // conflicts the colouring leaves: both ports for the source in the most of them, repeatedly
    loop {
        let mut worst: Option<(usize, u64)> = None;
        for &a in &sources {
            if both[a as usize] {
                continue;
            }
            let bad = adjacent[a as usize]
                .iter()
                .filter(|&&b| colour[b as usize] == colour[a as usize] && !both[b as usize])
                .count();
            if bad > 0 && worst.is_none_or(|(n, _)| bad > n) {
                worst = Some((bad, a));
            }
        }
        match worst {
            Some((_, a)) => both[a as usize] = true,
            None => break,
        }
    }
    let is_both = |g: u64| both[g as usize];
    let colour = |g: u64| colour[g as usize];
    for c in 0..instr.len() {
        let (i, x) = (instr[c], xbar[c]);
        let sel = selects(x, sw);
        let fields: Vec<(u64, u64)> =
            (0..2u32).filter(|&p| we(i, p)).map(|p| (sel[p as usize], i >> ((2 + p) * aw) & mask(aw))).collect();
        // the port of each write
        let ports: Vec<u32> = match fields[..] {
            [] => continue,
            [(a, _)] => vec![if is_both(a) { 0 } else { colour(a) }],
            [(a, _), (b, _)] => {
                let pa = match (is_both(a), is_both(b)) {
                    (false, _) => colour(a),
                    (true, false) => 1 - colour(b),
                    (true, true) => 0,
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
        instr[c] = i2;
        xbar[c] = x2;
    }
}

impl Routes {
    /// The routes of crossbar images `xbar` (per PE slot, one word per cycle, selects of `sw`
    /// bits) of a design of `n_pe` PEs.
    pub fn of_crossbar(n_pe: usize, sw: u32, xbar: &[&[u64]]) -> Routes {
        let ports = xbar
            .iter()
            .map(|words| {
                let mut used = [Vec::new(), Vec::new()];
                for &w in words.iter() {
                    for (port, sel) in selects(w, sw).into_iter().enumerate() {
                        if sel != 0 {
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
        Routes { n_pe, ports }
    }

    /// Bits of port `port`'s select on PE `slot`: `⌈log2(k + 1)⌉` for `k` sources, at least 1.
    pub fn select_bits(&self, slot: usize, port: usize) -> u32 {
        addr_bits(self.ports[slot][port].len() as u64 + 1)
    }

    /// The specialised select of crossbar select `sel` on `slot`'s port `port`: 0 for 0, `i`
    /// for the port's `i`-th source (1-based); `None` when the port has no such route.
    pub fn local(&self, slot: usize, port: usize, sel: u64) -> Option<u64> {
        if sel == 0 {
            return Some(0);
        }
        let list = &self.ports[slot][port];
        list.binary_search(&u32::try_from(sel).ok()?).ok().map(|i| i as u64 + 1)
    }

    /// The crossbar select of specialised select `local` on `slot`'s port `port` (inverse of
    /// [`Routes::local`]); `None` beyond the port's sources.
    pub fn global(&self, slot: usize, port: usize, local: u64) -> Option<u64> {
        if local == 0 {
            return Some(0);
        }
        let i = usize::try_from(local - 1).ok()?;
        self.ports.get(slot)?.get(port)?.get(i).map(|&s| u64::from(s))
    }

    /// Multiplexer inputs of every port (32-bit words): `Σ k`; a crossbar has `2·n_pe` per port.
    pub fn mux_inputs(&self) -> u64 {
        self.ports.iter().flat_map(|p| p.iter()).map(|l| l.len() as u64).sum()
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
    /// one of these: the interconnect of this design can carry it (module doc).
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
            for port in 0..2 {
                for &sel in &want[port] {
                    if have[port].binary_search(&sel).is_err() {
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

    /// Writes of one PE memory (`aw` = 4, `sw` = 3): `(select, address)` per port, `None`: no
    /// write; the words [`assign_write_ports`] reads.
    fn program_words(cycles: &[[Option<(u64, u64)>; 2]]) -> (Vec<u64>, Vec<u64>) {
        let (aw, sw) = (4, 3);
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
        let (mut instr, mut xbar) = program_words(&cycles);
        let before = (instr.clone(), xbar.clone());
        assign_write_ports(&mut instr, &mut xbar, aw, sw);
        let writes = |i: u64, x: u64| -> Vec<(u64, u64, u32)> {
            (0..2u32)
                .filter(|&p| i >> (4 * aw + p) & 1 == 1)
                .map(|p| (x >> (p * sw) & 7, i >> ((2 + p) * aw) & 15, p))
                .collect()
        };
        let mut ports: Vec<std::collections::BTreeSet<u32>> = vec![Default::default(); 8];
        for c in 0..cycles.len() {
            let (old, new) = (writes(before.0[c], before.1[c]), writes(instr[c], xbar[c]));
            let key = |v: &[(u64, u64, u32)]| {
                let mut k: Vec<(u64, u64)> = v.iter().map(|w| (w.0, w.1)).collect();
                k.sort_unstable();
                k
            };
            assert_eq!(key(&old), key(&new), "cycle {c}: the same writes");
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
        let r = Routes::of_crossbar(2, sw, &[&xbar]);
        assert_eq!(r.ports[0][0].len() + r.ports[0][1].len(), 6, "five sources, one on both ports");
    }

    #[test]
    fn routes_are_the_selects_used_per_port_and_local_selects_invert() {
        // 3 PEs, sw = 3 (selects 0..=6): slot 0 routes 2 and 5 on port 0, 4 on port 1
        let sw = 3;
        let w = |a: u64, b: u64| a | (b << sw);
        let slot0 = [w(2, 0), w(5, 4), w(2, 4), w(0, 0)];
        let slot1 = [w(0, 0)];
        let slot2 = [w(6, 1), w(1, 6)];
        let r = Routes::of_crossbar(3, sw, &[&slot0, &slot1, &slot2]);
        assert_eq!(r.ports[0], [vec![2, 5], vec![4]]);
        assert!(r.ports[1].iter().all(Vec::is_empty));
        assert_eq!(r.ports[2], [vec![1, 6], vec![1, 6]]);
        assert_eq!(r.mux_inputs(), 2 + 1 + 4);
        // k sources need ⌈log2(k + 1)⌉ bits, at least 1
        assert_eq!([r.select_bits(0, 0), r.select_bits(0, 1), r.select_bits(1, 0)], [2, 1, 1]);
        for (slot, port) in [(0, 0), (0, 1), (2, 0), (2, 1)] {
            for &g in &r.ports[slot][port] {
                let l = r.local(slot, port, u64::from(g)).unwrap();
                assert!(l >= 1 && l <= r.ports[slot][port].len() as u64);
                assert_eq!(r.global(slot, port, l), Some(u64::from(g)));
            }
        }
        assert_eq!(r.local(0, 0, 3), None, "select 3 is not routed into slot 0's port 0");
        assert_eq!(r.local(1, 0, 0), Some(0));
        assert_eq!(r.global(0, 1, 2), None);
        assert_eq!(r.source_name(2, |s| format!("pe{s}")), "result pe1");
        assert_eq!(r.source_name(6, |s| format!("pe{s}")), "buffer pe2");
    }

    #[test]
    fn a_design_admits_its_own_routes_and_their_subsets_only() {
        let r = Routes { n_pe: 2, ports: vec![[vec![1, 3], vec![2]], [vec![], vec![4]]] };
        assert!(r.admits(&r).is_ok());
        let sub = Routes { n_pe: 2, ports: vec![[vec![3], vec![]], [vec![], vec![4]]] };
        assert!(r.admits(&sub).is_ok());
        let other = Routes { n_pe: 2, ports: vec![[vec![2], vec![2]], [vec![1], vec![4]]] };
        let e = r.admits(&other).unwrap_err();
        assert!(e.starts_with("2 route(s) missing"), "{e}");
        assert!(e.contains("select 2 into port 0 of PE slot 0"), "{e}");
        let bigger = Routes { n_pe: 3, ports: vec![[vec![], vec![]]; 3] };
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
