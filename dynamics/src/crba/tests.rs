//! The CRBA's statement order (module doc, "Order of the statements"): what GCC's register
//! allocator sees, checked by the register-pressure measure of `schedule-cpu`.

use robovec_passes::schedule_cpu::pressure::pressure_of_order;
use robovec_passes::{Instrumentation, PassContext, PassManager};

use crate::topology::{build, Topology};
use crate::{generate, Model};

/// serial30 (the bench's 30-dof chain), `M`'s upper triangle after
/// `atomise,cse,zero-removal,contract` in the generator's order: values live at once, and the
/// column of each carried force's statement (`FM{k}{body}_{col}`, `CM…`) in statement order
/// (a force that `cse` found computed before keeps the earlier name and is not counted).
fn serial30_m() -> (usize, Vec<usize>) {
    let robot = build(Topology::Serial, 30, 1);
    let mut m = generate(&Model { robot }, true).module;
    let upper: Vec<String> = (1..=30).flat_map(|i| (i..=30).map(move |j| format!("M[{i}][{j}]"))).collect();
    let pipeline = format!("atomise,dce<outputs={}>,cse,zero-removal,contract", upper.join(","));
    PassManager::new(&pipeline, Instrumentation::default())
        .expect("pipeline")
        .run(&mut m, &mut PassContext::default(), &mut std::io::sink())
        .expect("runs");
    let f = m.functions.iter().find(|f| f.name == "dirdyna").expect("dirdyna");
    let live = pressure_of_order(f, &f.body, 16).max_live;
    let columns = f
        .body
        .iter()
        .filter_map(|&v| {
            let name = f.name_of(v);
            let rest = name.strip_prefix("FM").or_else(|| name.strip_prefix("CM"))?;
            rest.split('_').nth(1)?.split('.').next()?.parse().ok()
        })
        .collect();
    (live, columns)
}

/// Each column follows its body's composite, so the composites are not all live at once: 26
/// values at most on serial30 before the pairs, 32 with them (153 when every composite came
/// first); checked below 40. Columns go up in pairs: the statements of columns 30 and 29
/// alternate step by step (29 steps of each), and the pair is done before column 28 starts.
#[test]
fn columns_follow_their_composites_in_pairs() {
    let (live, columns) = serial30_m();
    assert!(live < 40, "{live} values live at once");
    let pair = columns.iter().take_while(|&&c| c >= 29).count();
    let turns = columns[..pair].windows(2).filter(|w| w[0] != w[1]).count();
    assert!(turns >= 40, "columns 30 and 29 alternate step by step: {turns} turns in {:?}…", &columns[..pair.min(60)]);
    assert_eq!(columns[pair], 28, "then column 28");
    assert!(columns[pair..].iter().all(|&c| c <= 28), "columns 30 and 29 are complete before 28 starts");
}
