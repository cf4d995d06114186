//! `parse(print(m)) == m` for every corpus module, before and after `atomise`, with timing
//! attributes and with a placement (Cranelift's `test cat`).

use robovec_ir::text::parse;
use robovec_ir::Module;
use robovec_passes::{Instrumentation, PassContext, PassManager};

use crate::common::{corpus_files, is_loop_file};

fn assert_same(a: &Module, b: &Module, what: &str) {
    assert_eq!(a.functions.len(), b.functions.len(), "{what}");
    for (f, g) in a.functions.iter().zip(&b.functions) {
        assert_eq!((&f.name, f.phase, f.equations), (&g.name, g.phase, g.equations), "{what}");
        assert_eq!((&f.inputs, &f.body), (&g.inputs, &g.body), "{what} @{}", f.name);
        for (i, (x, y)) in f.values.iter().zip(&g.values).enumerate() {
            let v = robovec_ir::Value::with_number(i as u32);
            assert_eq!((&x.name, &x.def, f.timing(v)), (&y.name, &y.def, g.timing(v)), "{what} @{}", f.name);
        }
        let outs = |f: &robovec_ir::Function| f.outputs.iter().map(|o| (o.name.clone(), o.value)).collect::<Vec<_>>();
        assert_eq!(outs(f), outs(g), "{what} @{}", f.name);
        assert_eq!(f.placement, g.placement, "{what} @{}: placement", f.name);
    }
}

#[test]
fn corpus_modules_round_trip_in_every_phase() {
    for p in corpus_files().into_iter().filter(|p| !is_loop_file(p)) {
        let (mut m, _) = robovec::driver::load(p.to_str().unwrap()).unwrap_or_else(|f| panic!("{}", f.message()));
        for pipeline in ["", "atomise", "asap-alap", "place<pe=3;select=naive>"] {
            let pm =
                PassManager::with_registry(robovec_backends::REGISTRY, pipeline, Instrumentation::default()).unwrap();
            pm.run(&mut m, &mut PassContext::default(), &mut std::io::sink()).unwrap();
            // Front ends number values in first-use order; the reader numbers inputs first.
            // Renumbering (inputs, then body) is the canonical form both agree on.
            m.functions.iter_mut().for_each(|f| f.retain(|_, _| true));
            let text = m.to_string();
            let back = parse(&text).unwrap_or_else(|e| panic!("{} after `{pipeline}`: {:?}", p.display(), e[0]));
            assert_same(&m, &back, &format!("{} after `{pipeline}`", p.display()));
            assert_eq!(back.to_string(), text, "printing is deterministic");
        }
    }
}
