//! `diff<wrt=…>` (issue 50 item 1) on the Robotran corpus: the stiffness `∂Qq/∂q` of every
//! `invdyna` and the Jacobians of every `dirdyna`, in both modes, against central finite
//! differences of the function itself (the interpreter, binary64). The unit tests in
//! `passes/src/diff/tests.rs` cover every rule and random DAGs.

use std::collections::HashMap;

use robovec_ir::interp::{eval, pseudo_random_input};
use robovec_ir::Function;

use crate::common::{corpus_files, is_loop_file, opt_to_ir, tmp};

/// The corpus `invdyna` and `dirdyna` files the front ends read.
fn dynamics_files() -> Vec<std::path::PathBuf> {
    let files: Vec<_> = corpus_files()
        .into_iter()
        .filter(|p| !is_loop_file(p))
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy();
            n.contains("_invdyna_") || n.contains("_dirdyna_")
        })
        .collect();
    assert!(files.len() >= 8, "{files:?}");
    files
}

/// The largest `|d − fd| / (1 + |d|)` over every output of `f` and every `q[i]`, `d` from `g`'s
/// output `d<O>_dq<o's indices>[i]` and `fd` the central difference of `f` with step
/// `1e-6·max(1, |q[i]|)`; also the number of derivatives compared.
fn worst(f: &Function, g: &Function) -> (f64, usize) {
    let x0: HashMap<String, f64> =
        f.inputs.iter().map(|&v| (f.name_of(v).to_string(), pseudo_random_input(f.name_of(v), 3))).collect();
    let d: HashMap<String, f64> = eval::<f64>(g, |n| x0[n]).into_iter().collect();
    let (mut worst, mut n) = (0.0f64, 0);
    for &x in &f.inputs {
        let xn = f.name_of(x);
        let Some(index) = xn.strip_prefix("q[") else { continue };
        let h = 1e-6 * x0[xn].abs().max(1.0);
        let at = |dx: f64| -> HashMap<String, f64> {
            eval::<f64>(f, |m| if m == xn { x0[m] + dx } else { x0[m] }).into_iter().collect()
        };
        let (up, down) = (at(h), at(-h));
        for o in &f.outputs {
            let fd = (up[&o.name] - down[&o.name]) / (2.0 * h);
            let (family, rest) = o.name.split_at(o.name.find('[').unwrap_or(o.name.len()));
            let name = format!("d{family}_dq{rest}[{index}");
            let got = *d.get(&name).unwrap_or_else(|| panic!("no derivative output {name}"));
            worst = worst.max((got - fd).abs() / (1.0 + got.abs()));
            n += 1;
        }
    }
    (worst, n)
}

#[test]
fn corpus_jacobians_match_central_finite_differences_in_both_modes() {
    let dir = tmp("corpus");
    for p in dynamics_files() {
        let file = p.to_str().unwrap();
        let (_, m) = opt_to_ir(&dir, &[file, "-passes=atomise,cse"]);
        let f = &m.functions[0];
        for mode in ["forward", "reverse"] {
            let (r, g) = opt_to_ir(&dir, &[file, &format!("-passes=atomise,cse,diff<wrt=q;mode={mode}>")]);
            let g = &g.functions[0];
            let (w, n) = worst(f, g);
            eprintln!("{} {mode}: {n} derivatives, worst {w:.1e}", p.file_name().unwrap().to_string_lossy());
            assert!(n > 0, "{file}: no derivative compared");
            assert!(w < 1e-6, "{file} {mode}: a derivative {w:e} off the finite difference");
            assert!(r["stats"]["ops"]["total"].as_u64().unwrap() > 0);
        }
    }
}
