//! Placement of corpus files: cycles against the SPEC §4 lower bound.

use robovec_passes::atomise::atomise_function;
use robovec_passes::place::{cycles, lower_bound, place_function, PlaceOptions, Priority, Select};

use crate::common::corpus_dir;

#[test]
fn segway_cycles_against_lower_bound() {
    let (m, _) = robovec::driver::load(corpus_dir().join("c/frank_segway__mbs_dirdyna_Frank_segway.c").to_str().unwrap())
        .unwrap_or_else(|f| panic!("{}", f.message()));
    let f = atomise_function(&m.functions[0]);
    for n in [1, 2, 4, 8, 16, 32, 64] {
        for (priority, select) in [(Priority::Classical, Select::Preferential), (Priority::Mobility, Select::Naive)] {
            let mut o = PlaceOptions::with_pes(n);
            o.priority = priority;
            o.select = select;
            let p = place_function(&f, &o);
            let (c, lb) = (cycles(&f, &p), lower_bound(&f, &o.arch));
            println!("N={n:>2} {priority:?}/{select:?}: cycles {c}, LB {lb}, ratio {:.3}, pe words max {}, buffer max {}", c as f64 / lb as f64, p.pe_words.iter().max().unwrap(), p.buffer_words.iter().max().unwrap());
            assert!(c >= lb);
        }
    }
}
