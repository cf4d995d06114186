//! File tests: each `tests/ir/<pass>/*.rvir` starts with `; passes: PIPELINE` and a comment
//! saying why the case matters; the snapshot is the IR after the pipeline. Plus the seed's own
//! example (eq. 2.1 → eq. 2.2) from a tiny Robotran C file.

use robovec_ir::text::parse;
use robovec_ir::{Def, Function, Operand};
use robovec_passes::{Instrumentation, PassContext, PassManager};

fn run(pipeline: &str, m: &mut robovec_ir::Module) {
    let pm = PassManager::with_registry(robovec_backends::REGISTRY, pipeline, Instrumentation::default()).unwrap();
    pm.run(m, &mut PassContext::default(), &mut std::io::sink()).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn ir_file_tests() {
    insta::glob!("ir/**/*.rvir", |path| {
        let src = std::fs::read_to_string(path).unwrap();
        let pipeline = src
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("; passes:"))
            .unwrap_or_else(|| panic!("{}: first line must be `; passes: …`", path.display()))
            .trim();
        let mut m = parse(&src).unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
        run(pipeline, &mut m);
        insta::assert_snapshot!(m.to_string());
    });
}

/// The expansion of an operand as a tree of ops over leaves named as in the source.
fn tree(f: &Function, o: Operand) -> String {
    match o {
        Operand::Const(c) => format!("{c:?}"),
        Operand::Value(v) => match &f.value(v).def {
            Def::Binary(op, a, b) => format!("({} {} {})", op.mnemonic(), tree(f, *a), tree(f, *b)),
            _ => f.name_of(v).to_string(),
        },
    }
}

#[test]
fn seed_example_atomises_to_the_seed_operations() {
    let (mut m, _) = robovec::driver::load("tests/inputs/seed_eq21.c").unwrap_or_else(|f| panic!("{}", f.message()));
    run("atomise", &mut m);
    let ours = &m.functions[0];
    insta::assert_snapshot!(ours.to_string());

    // Seed eq. 2.2, transcribed with the seed's own names (g(3) = %g[3], qp = %qd).
    let seed = parse(
        "func @seed { phase atomised input %q[4] input %q[5] input %q[6] input %g[3] input %qd[4] input %qd[5]
          %C4 = cos %q[4] %S4 = sin %q[4] %C5 = cos %q[5] %S5 = sin %q[5] %C6 = cos %q[6] %S6 = sin %q[6]
          %AF24d = mul %g[3], %S4  %AF24 = sub 0.0, %AF24d
          %AF34d = mul %g[3], %C4  %AF34 = sub 0.0, %AF34d
          %OM15 = mul %qd[4], %C5  %OM35 = mul %qd[4], %S5
          %AF15d = mul %AF34, %S5  %AF15 = sub 0.0, %AF15d
          %AF35 = mul %AF34, %C5
          %OM16d = mul %OM15, %C6  %OM16g = mul %qd[5], %S6  %OM16 = add %OM16g, %OM16d
          %OM26d = mul %OM15, %S6  %OM26g = mul %qd[5], %C6  %OM26 = sub %OM26g, %OM26d
          output Qq[1] = %AF24 output Qq[2] = %AF34 output Qq[3] = %OM15 output Qq[4] = %OM35
          output Qq[5] = %AF15 output Qq[6] = %AF35 output Qq[7] = %OM16 output Qq[8] = %OM26 }",
    )
    .unwrap();
    let seed = &seed.functions[0];
    assert_eq!(ours.op_counts(), seed.op_counts(), "same count (15 ops: 10 mul, 4 sub, 1 add)");
    assert_eq!(seed.op_counts().total, 15);
    for (a, b) in ours.outputs.iter().zip(&seed.outputs) {
        assert_eq!(a.name, b.name);
        assert_eq!(tree(ours, a.value), tree(seed, b.value), "same structure for {}", a.name);
    }
}
