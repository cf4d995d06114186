//! Property tests (proptest).
//!
//! 1. Robustness: arbitrary strings/bytes, token soups over a small alphabet of `.rvir` and
//!    Robotran tokens, and mutated small well-formed files go into `robovec_ir::text::parse` and
//!    into each front end (`robovec_front::parse_str` for C, Matlab and Python) without a panic.
//!    When a front end accepts an input, its module must verify, atomise, and the atomised
//!    module must verify.
//! 2. Round trip and atomisation on random well-formed parsed-phase functions (random expression
//!    trees over a few inputs, earlier equations, a trig variable, literals and `@sqrt`):
//!    - the text parses to exactly the tree generated (precedence, unary minus);
//!    - `parse(print(parse(x)))` equals `parse(x)` (spans aside) and prints identically;
//!    - the parsed function, the atomised function and an independent tree evaluator agree
//!      **bit for bit** in f64 and in f32. Inputs are drawn in [0.5, 2]. The one documented
//!      difference — `atomise` computes a unary minus as `0 - t`, so `-t` and `0 - t` differ in
//!      the sign of a zero (and of a NaN) — is excluded by discarding the rare cases where the
//!      operand of a unary minus is ±0 or NaN in the precision being checked.
//!
//! Case counts are modest (64–512) so the suite stays fast.

use proptest::prelude::*;
use proptest::test_runner::Config;
use robovec_front::{parse_str, Language};
use robovec_ir::interp::{self, Float};
use robovec_ir::{text, verifier, BinOp, Callee, Def, Expr, Function, Module, Operand, Phase};
use robovec_passes::atomise::atomise_function;

// ------------------------------------------------------------------------------------------------
// 1. Robustness
// ------------------------------------------------------------------------------------------------

const RVIR_TOKENS: &[&str] = &[
    "%a",
    "%b",
    "%q[1]",
    "%S1",
    "%x.1",
    "=",
    "add",
    "sub",
    "mul",
    "div",
    "call",
    "sin",
    "cos",
    "(",
    ")",
    "-",
    "+",
    "*",
    "/",
    ",",
    "2.0",
    "0",
    "0.5",
    "1e308",
    "1e999",
    "99999999999",
    "func",
    "@f",
    "@g",
    "@sqrt",
    "@user_X.1[3]",
    "{",
    "}",
    "phase",
    "parsed",
    "atomised",
    "equations",
    "3",
    "input",
    "output",
    "Qq[1]",
    "M[1][2]",
    "asap",
    "alap",
    "mobility",
    "asap_cycle",
    "alap_cycle",
    "; comment\n",
    "\n",
    " ",
    "\t",
    "\u{e9}",
    "%",
    "@",
    "[",
    "]",
    ".",
    "%q[",
];

const ROBOTRAN_TOKENS: &[&str] = &[
    "q[1]",
    "qd[2]",
    "qdd[1]",
    "s->",
    "s->dpt[1][2]",
    "s->m[1]",
    "s->g[3]",
    "s->In[1][2]",
    "s.",
    "s.l(2,1)",
    "s.In[1,2]",
    "s.g(3)",
    "q(1)",
    "q[",
    "=",
    ";",
    "\n",
    " ",
    "  ",
    "...",
    "\\",
    " \\\n",
    "case 1:",
    "case 2:",
    "break;",
    "default:",
    "switch(isens)",
    "{",
    "}",
    "(",
    ")",
    "-",
    "+",
    "*",
    "/",
    ",",
    "(2.0)",
    "2.0",
    "1",
    "0",
    "cos(q[1])",
    "sin(q(1))",
    "np.cos(q[1])",
    "sqrt(",
    "user_ExtForces(",
    "Qq[1]",
    "M[1][2]",
    "M(1,2)",
    "Qq(1)",
    "c[1]",
    "X1",
    "X2",
    "C1",
    "S1",
    "#define q s->q",
    "#include \"a.h\"",
    "// c",
    "% c",
    "# c",
    "void mbs_invdyna(double *Qq,\nMbsData *s, double tsim)",
    "function [Qq] = invdyna(s,tsim,usrfun)",
    "def invdyna(phi,s,tsim):",
    "double    X1;",
    "while",
    "if",
    "for",
    "return",
    "int i;",
    "\r",
    "\t",
    "\u{e9}",
    "sens->P[1]",
    "frc = s.frc;",
    "Qq = phi",
    "q = s.q",
    "import numpy as np",
    "%",
    "#",
    "//",
    "@",
];

/// The shipped C example: a small well-formed Robotran 6.6 C file to mutate.
const C_SKELETON: &str = include_str!("../examples/double_pendulum/mbs_invdyna_double_pendulum.c");

/// A small Matlab file in Robotran 6.6's format (written here, same model as the C example).
const MATLAB_SKELETON: &str = "%\n%\tROBOTRAN - Version 6.6 (build : february 22, 2008)\n%\n\
function [Qq] = invdyna(s,tsim,usrfun)\n\n Qq = zeros(2,1);\n\nq = s.q; \nqd = s.qd; \nqdd = s.qdd; \n\n\
% Trigonometric Variables  \n\n  C1 = cos(q(1));\n  S1 = sin(q(1));\n  C2 = cos(q(2));\n  S2 = sin(q(2));\n\n\
  ALPHA21 = -s.g(3)*S1;\n  ALPHA31 = -s.g(3)*C1;\n  BS51 = -qd(1)*qd(1);\n\
  ALPHA22 = C2*(ALPHA21+BS51*s.dpt(2,2))+S2*(ALPHA31+qdd(1)*s.dpt(2,2));\n\
  ALPHA32 = C2*(ALPHA31+qdd(1)*s.dpt(2,2))-S2*(ALPHA21+BS51*...\n s.dpt(2,2));\n\
  OM12 = qd(1)+qd(2);\n  OMp12 = qdd(1)+qdd(2);\n  BS52 = -OM12*OM12;\n\
  Fs22 = s.m(2)*(ALPHA22+BS52*s.l(2,2));\n  Fs32 = s.m(2)*(ALPHA32+OMp12*s.l(2,2));\n\
  Cq12 = s.In(1,2)*OMp12+Fs32*s.l(2,2);\n  Fs21 = s.m(1)*(ALPHA21+BS51*s.l(2,1));\n\
  Fs31 = s.m(1)*(ALPHA31+qdd(1)*s.l(2,1));\n\
  Cq11 = Cq12+s.In(1,1)*qdd(1)+Fs31*s.l(2,1)+s.dpt(2,2)*(Fs22*S2+Fs32*C2);\n\n\
  Qq(1) = Cq11;\n  Qq(2) = Cq12;\n\n% ====== END Task 0 ====== \n";

/// A small Python file in Robotran 6.6's numpy format (written here, same model).
const PYTHON_SKELETON: &str = "#\n#\tROBOTRAN - Version 6.6 (build : february 22, 2008)\n#\n\
import numpy as np  \n\ndef invdyna(phi,s,tsim):\n\n  Qq = phi\n  q = s.q\n  qd = s.qd\n  qdd = s.qdd\n\n\
# Trigonometric Variables  \n\n  C1 = np.cos(q[1])\n  S1 = np.sin(q[1])\n  C2 = np.cos(q[2])\n  S2 = np.sin(q[2])\n\n\
  ALPHA21 = -s.g[3]*S1\n  ALPHA31 = -s.g[3]*C1\n  BS51 = -qd[1]*qd[1]\n\
  ALPHA22 = C2*(ALPHA21+BS51*s.dpt[2,2])+S2*(ALPHA31+qdd[1]*s.dpt[2,2])\n\
  ALPHA32 = C2*(ALPHA31+qdd[1]*s.dpt[2,2])-S2*(ALPHA21+BS51*\\\n   s.dpt[2,2])\n\
  OM12 = qd[1]+qd[2]\n  OMp12 = qdd[1]+qdd[2]\n  BS52 = -OM12*OM12\n\
  Fs22 = s.m[2]*(ALPHA22+BS52*s.l[2,2])\n  Fs32 = s.m[2]*(ALPHA32+OMp12*s.l[2,2])\n\
  Cq12 = s.In[1,2]*OMp12+Fs32*s.l[2,2]\n  Fs21 = s.m[1]*(ALPHA21+BS51*s.l[2,1])\n\
  Fs31 = s.m[1]*(ALPHA31+qdd[1]*s.l[2,1])\n\
  Cq11 = Cq12+s.In[1,1]*qdd[1]+Fs31*s.l[2,1]+s.dpt[2,2]*(Fs22*S2+Fs32*C2)\n\n\
  Qq[1] = Cq11\n  Qq[2] = Cq12\n\n# ====== END Task 0 ====== \n";

/// A small parsed-phase `.rvir` function to mutate.
const RVIR_SKELETON: &str = "func @invdyna {\n  phase parsed\n  equations 2\n  input %q[1]\n  input %g[3]\n\
  %S1 = sin %q[1]\n  %A = -%g[3]*%S1 + (-%q[1]) - (%S1 - 2.0)*(-(%g[3]))\n  %B = %A/%q[1] - @sqrt(%A*%A)\n\
  output Qq[1] = %B\n  output Qq[2] = -1.5\n}\n";

fn soup(alphabet: &'static [&'static str]) -> impl Strategy<Value = String> {
    soup_of(alphabet, 64)
}

/// A few tokens, for small mutations that keep most of a file well formed.
fn pinch(alphabet: &'static [&'static str]) -> impl Strategy<Value = String> {
    soup_of(alphabet, 4)
}

fn soup_of(alphabet: &'static [&'static str], max: usize) -> impl Strategy<Value = String> {
    prop::collection::vec((prop::sample::select(alphabet), prop::sample::select(&["", "", " ", "\n"][..])), 0..max)
        .prop_map(|v| v.into_iter().flat_map(|(t, s)| [t, s]).collect())
}

/// `skeleton` with `del` bytes at `pos` replaced by `insert` (positions taken modulo the length).
fn mutate(skeleton: &str, pos: usize, del: usize, insert: &str) -> Vec<u8> {
    let b = skeleton.as_bytes();
    let pos = pos % (b.len() + 1);
    let end = (pos + del).min(b.len());
    [&b[..pos], insert.as_bytes(), &b[end..]].concat()
}

/// The front-end contract on any bytes: no panic; an accepted module verifies and atomises.
fn check_front(lang: Language, src: &[u8], header: Option<&[u8]>) {
    let Ok(m) = parse_str(lang, src, header) else { return };
    if let Err(e) = robovec_front::verify_accepted(&m) {
        panic!("{lang:?}: {e}");
    }
}

fn check_all_fronts(src: &[u8]) {
    check_front(Language::C, src, None);
    check_front(Language::Matlab, src, None);
    check_front(Language::Python, src, None);
}

proptest! {
    #![proptest_config(Config::with_cases(512))]

    #[test]
    fn text_parse_never_panics_on_strings(s in any::<String>()) {
        let _ = text::parse(&s);
    }

    #[test]
    fn text_parse_never_panics_on_token_soup(s in soup(RVIR_TOKENS)) {
        let _ = text::parse(&s);
    }

    #[test]
    fn text_parse_never_panics_on_mutated_functions(pos in any::<usize>(), del in 0usize..8, ins in pinch(RVIR_TOKENS)) {
        let src = String::from_utf8(mutate(RVIR_SKELETON, pos, del, &ins)).expect("ASCII skeleton cut anywhere");
        let _ = text::parse(&src);
    }

    #[test]
    fn fronts_never_panic_on_bytes(b in prop::collection::vec(any::<u8>(), 0..400)) {
        check_all_fronts(&b);
    }

    #[test]
    fn fronts_never_panic_on_strings(s in any::<String>()) {
        check_all_fronts(s.as_bytes());
    }

    #[test]
    fn fronts_never_panic_on_token_soup(s in soup(ROBOTRAN_TOKENS)) {
        check_all_fronts(s.as_bytes());
    }

    #[test]
    fn c_front_never_panics_on_mutated_example(pos in any::<usize>(), del in 0usize..8, ins in pinch(ROBOTRAN_TOKENS),
                                               with_header in any::<bool>()) {
        let header = include_str!("../examples/double_pendulum/mbs_invdyna_double_pendulum.h");
        check_front(Language::C, &mutate(C_SKELETON, pos, del, &ins), with_header.then_some(header.as_bytes()));
    }

    #[test]
    fn c_front_never_panics_on_mutated_header(pos in any::<usize>(), del in 0usize..8, ins in pinch(ROBOTRAN_TOKENS)) {
        let header = include_str!("../examples/double_pendulum/mbs_invdyna_double_pendulum.h");
        check_front(Language::C, C_SKELETON.as_bytes(), Some(&mutate(header, pos, del, &ins)));
    }

    #[test]
    fn matlab_front_never_panics_on_mutated_file(pos in any::<usize>(), del in 0usize..8, ins in pinch(ROBOTRAN_TOKENS)) {
        check_front(Language::Matlab, &mutate(MATLAB_SKELETON, pos, del, &ins), None);
    }

    #[test]
    fn python_front_never_panics_on_mutated_file(pos in any::<usize>(), del in 0usize..8, ins in pinch(ROBOTRAN_TOKENS)) {
        check_front(Language::Python, &mutate(PYTHON_SKELETON, pos, del, &ins), None);
    }
}

/// The unmutated skeletons are accepted (so the mutations above start from well-formed files),
/// and the Matlab and Python versions of the example compute the C version's numbers.
#[test]
fn skeletons_are_accepted_and_agree() {
    let text_m = text::parse(RVIR_SKELETON).expect("rvir skeleton parses");
    verifier::verify(&text_m).expect("rvir skeleton verifies");
    let header = include_str!("../examples/double_pendulum/mbs_invdyna_double_pendulum.h");
    let mods: Vec<(Language, Module)> = [
        (Language::C, C_SKELETON, Some(header.as_bytes())),
        (Language::Matlab, MATLAB_SKELETON, None),
        (Language::Python, PYTHON_SKELETON, None),
    ]
    .into_iter()
    .map(|(lang, src, h)| match parse_str(lang, src.as_bytes(), h) {
        Ok(m) => (lang, m),
        Err(e) => panic!("{lang:?} skeleton rejected: {e:?}"),
    })
    .collect();
    let input = |name: &str| interp::pseudo_random_input(name, 7);
    let reference = interp::eval::<f64>(&mods[0].1.functions[0], input);
    for (lang, m) in &mods {
        verifier::verify(m).unwrap_or_else(|e| panic!("{lang:?} skeleton does not verify: {e:?}"));
        assert_eq!(m.functions.len(), 1, "{lang:?}");
        let got = interp::eval::<f64>(&m.functions[0], input);
        assert_eq!(got, reference, "{lang:?} skeleton computes other numbers than the C example");
    }
}

// ------------------------------------------------------------------------------------------------
// 2. Random well-formed functions: round trip and atomisation
// ------------------------------------------------------------------------------------------------

/// A generated expression; leaves name an available value by index (taken modulo the number of
/// values available where the expression is used).
#[derive(Clone, Debug)]
enum G {
    Leaf(u8),
    Const(f64),
    Neg(Box<G>),
    Bin(BinOp, Box<G>, Box<G>),
    Sqrt(Box<G>),
}

/// Non-zero literals, some round, some arbitrary in [0.5, 2] (printed with all their digits).
fn const_strategy() -> impl Strategy<Value = f64> {
    prop_oneof![prop::sample::select(&[0.5, 1.0, 1.5, 2.0, 3.0, 0.1, 10.0][..]), 0.5f64..2.0]
}

fn g_strategy() -> impl Strategy<Value = G> {
    let leaf = prop_oneof![4 => any::<u8>().prop_map(G::Leaf), 1 => const_strategy().prop_map(G::Const)];
    leaf.prop_recursive(5, 32, 2, |inner| {
        let op = prop::sample::select(&[BinOp::Add, BinOp::Sub, BinOp::Mul, BinOp::Div][..]);
        prop_oneof![
            2 => inner.clone().prop_map(|x| G::Neg(Box::new(x))),
            6 => (op, inner.clone(), inner.clone()).prop_map(|(o, a, b)| G::Bin(o, Box::new(a), Box::new(b))),
            1 => inner.prop_map(|x| G::Sqrt(Box::new(x))),
        ]
    })
}

/// A generated function: equations `%T0 … %Tn` and the outputs' value indices.
#[derive(Clone, Debug)]
struct GenFn {
    eqs: Vec<G>,
    outs: Vec<u8>,
    const_output: Option<f64>,
    full_parens: bool,
}

fn genfn_strategy() -> impl Strategy<Value = GenFn> {
    (
        prop::collection::vec(g_strategy(), 1..6),
        prop::collection::vec(any::<u8>(), 1..4),
        prop::option::of(const_strategy()),
        any::<bool>(),
    )
        .prop_map(|(eqs, outs, const_output, full_parens)| GenFn { eqs, outs, const_output, full_parens })
}

const INPUTS: [&str; 3] = ["q[1]", "qd[1]", "g[3]"];

/// Names available to equation `i`: the inputs, the trig variable, earlier equations.
fn available(i: usize) -> Vec<String> {
    let mut v: Vec<String> = INPUTS.iter().map(|s| s.to_string()).collect();
    v.push("S1".into());
    v.extend((0..i).map(|k| format!("T{k}")));
    v
}

fn leaf_name(avail: &[String], k: u8) -> &str {
    &avail[k as usize % avail.len()]
}

/// Fully parenthesised: every binary op is `(a op b)`, every negation `(-x)`.
fn print_full(g: &G, avail: &[String], out: &mut String) {
    match g {
        G::Leaf(k) => {
            out.push('%');
            out.push_str(leaf_name(avail, *k));
        }
        G::Const(c) => out.push_str(&format!("{c:?}")),
        G::Neg(x) => {
            out.push_str("(-");
            print_full(x, avail, out);
            out.push(')');
        }
        G::Bin(op, a, b) => {
            out.push('(');
            print_full(a, avail, out);
            out.push(op.symbol());
            print_full(b, avail, out);
            out.push(')');
        }
        G::Sqrt(x) => {
            out.push_str("@sqrt(");
            print_full(x, avail, out);
            out.push(')');
        }
    }
}

/// Fewest parentheses: sum → product → factor, as Robotran writes (unary minus only at the start
/// of a sum or after `(`).
fn print_min(g: &G, avail: &[String], out: &mut String, level: u8) {
    // level 0: sum position, 1: product position, 2: factor position.
    let own = match g {
        G::Neg(_) | G::Bin(BinOp::Add | BinOp::Sub, ..) => 0,
        G::Bin(BinOp::Mul | BinOp::Div, ..) => 1,
        _ => 2,
    };
    if own < level {
        out.push('(');
        print_min(g, avail, out, 0);
        out.push(')');
        return;
    }
    match g {
        G::Leaf(_) | G::Const(_) => print_full(g, avail, out),
        G::Neg(x) => {
            out.push('-');
            print_min(x, avail, out, 1);
        }
        G::Bin(op @ (BinOp::Add | BinOp::Sub), a, b) => {
            print_min(a, avail, out, 0);
            out.push(op.symbol());
            print_min(b, avail, out, 1);
        }
        G::Bin(op, a, b) => {
            print_min(a, avail, out, 1);
            out.push(op.symbol());
            print_min(b, avail, out, 2);
        }
        G::Sqrt(x) => {
            out.push_str("@sqrt(");
            print_min(x, avail, out, 0);
            out.push(')');
        }
    }
}

fn gen_text(gf: &GenFn) -> String {
    let mut s = format!("func @f {{\n  phase parsed\n  equations {}\n", gf.eqs.len());
    for i in INPUTS {
        s.push_str(&format!("  input %{i}\n"));
    }
    s.push_str("  %S1 = sin %q[1]\n");
    for (i, g) in gf.eqs.iter().enumerate() {
        let avail = available(i);
        s.push_str(&format!("  %T{i} = "));
        if gf.full_parens {
            print_full(g, &avail, &mut s);
        } else {
            print_min(g, &avail, &mut s, 0);
        }
        s.push('\n');
    }
    let all = available(gf.eqs.len());
    for (k, o) in gf.outs.iter().enumerate() {
        s.push_str(&format!("  output Qq[{}] = %{}\n", k + 1, leaf_name(&all, *o)));
    }
    if let Some(c) = gf.const_output {
        s.push_str(&format!("  output c[1] = {c:?}\n"));
    }
    s.push_str("}\n");
    s
}

/// The IR expression the generated text must parse to.
fn to_expr(g: &G, avail: &[String], f: &Function) -> Expr {
    match g {
        G::Leaf(k) => Expr::Operand(Operand::Value(f.lookup(leaf_name(avail, *k)).expect("defined"))),
        G::Const(c) => Expr::Operand(Operand::Const(*c)),
        G::Neg(x) => Expr::Neg(Box::new(to_expr(x, avail, f))),
        G::Bin(op, a, b) => Expr::Binary(*op, Box::new(to_expr(a, avail, f)), Box::new(to_expr(b, avail, f))),
        G::Sqrt(x) => Expr::call(Callee { name: "sqrt".into(), elem: None }, vec![to_expr(x, avail, f)]),
    }
}

/// Independent evaluator of the generated tree in precision `T`; `Err(())` when the operand of
/// a unary minus is ±0 or NaN (where `-t` and `0 - t` legitimately differ).
fn eval_g<T: Float>(g: &G, avail: &[String], env: &std::collections::HashMap<String, T>) -> Result<T, ()> {
    Ok(match g {
        G::Leaf(k) => env[leaf_name(avail, *k)],
        G::Const(c) => T::from_f64(*c),
        G::Neg(x) => {
            let v = eval_g(x, avail, env)?;
            let zero = T::from_f64(0.0);
            if v == zero || v.to_f64().is_nan() {
                return Err(());
            }
            -v
        }
        G::Bin(op, a, b) => {
            let a = eval_g(a, avail, env)?;
            let b = eval_g(b, avail, env)?;
            match op {
                BinOp::Add => a + b,
                BinOp::Sub => a - b,
                BinOp::Mul => a * b,
                BinOp::Div => a / b,
            }
        }
        G::Sqrt(x) => eval_g(x, avail, env)?.sqrt(),
    })
}

/// Everything but spans.
fn same_function(a: &Function, b: &Function) -> bool {
    let vals = |f: &Function| {
        f.values
            .iter()
            .enumerate()
            .map(|(i, v)| (v.name.clone(), v.def.clone(), f.timing(robovec_ir::Value::with_number(i as u32))))
            .collect::<Vec<_>>()
    };
    let outs = |f: &Function| f.outputs.iter().map(|o| (o.name.clone(), o.value)).collect::<Vec<_>>();
    a.name == b.name
        && a.phase == b.phase
        && a.equations == b.equations
        && a.inputs == b.inputs
        && a.body == b.body
        && vals(a) == vals(b)
        && outs(a) == outs(b)
}

/// Checks one precision: `Ok(false)` when the sample was discarded.
fn check_precision<T: Float>(
    gf: &GenFn,
    parsed: &Function,
    atomised: &Function,
    inputs: &[f64; 3],
) -> Result<bool, String> {
    let mut env = std::collections::HashMap::new();
    for (n, x) in INPUTS.iter().zip(inputs) {
        env.insert(n.to_string(), T::from_f64(*x));
    }
    env.insert("S1".to_string(), T::from_f64(inputs[0]).sin());
    for (i, g) in gf.eqs.iter().enumerate() {
        let Ok(v) = eval_g::<T>(g, &available(i), &env) else { return Ok(false) };
        env.insert(format!("T{i}"), v);
    }
    let input = |name: &str| inputs[INPUTS.iter().position(|n| *n == name).expect("known input")];
    let p = interp::eval::<T>(parsed, input);
    let a = interp::eval::<T>(atomised, input);
    let all = available(gf.eqs.len());
    let mut want: Vec<(String, T)> =
        gf.outs.iter().enumerate().map(|(k, o)| (format!("Qq[{}]", k + 1), env[leaf_name(&all, *o)])).collect();
    if let Some(c) = gf.const_output {
        want.push(("c[1]".into(), T::from_f64(c)));
    }
    let bits = |v: &[(String, T)]| v.iter().map(|(n, x)| (n.clone(), x.to_f64().to_bits())).collect::<Vec<_>>();
    if bits(&p) != bits(&want) {
        return Err(format!("parsed IR {p:?} != tree evaluator {want:?}"));
    }
    if bits(&a) != bits(&p) {
        return Err(format!("atomised IR {a:?} != parsed IR {p:?}"));
    }
    Ok(true)
}

proptest! {
    #![proptest_config(Config::with_cases(256))]

    #[test]
    fn random_functions_round_trip_and_atomise_exactly(gf in genfn_strategy(),
                                                       inputs in prop::array::uniform3(0.5f64..2.0)) {
        let src = gen_text(&gf);
        let m = text::parse(&src).map_err(|e| TestCaseError::fail(format!("generated text rejected: {e:?}\n{src}")))?;
        prop_assert!(verifier::verify(&m).is_ok(), "generated function does not verify:\n{}", src);
        let f = &m.functions[0];
        prop_assert_eq!(f.phase, Phase::Parsed);

        // The text parses to the tree generated.
        for (i, g) in gf.eqs.iter().enumerate() {
            let v = f.lookup(&format!("T{i}")).expect("defined");
            let want = Def::Expr(to_expr(g, &available(i), f));
            let got = &f.value(v).def;
            // A bare leaf or literal equation is still an expression definition.
            prop_assert_eq!(got, &want, "equation T{} of\n{}", i, src);
        }

        // Round trip: parse(print(parse(x))) == parse(x), and printing is a fixed point.
        let printed = m.to_string();
        let m2 = text::parse(&printed).map_err(|e| TestCaseError::fail(format!("printed text rejected: {e:?}\n{printed}")))?;
        prop_assert_eq!(m2.functions.len(), 1);
        prop_assert!(same_function(f, &m2.functions[0]), "round trip changed the function:\n{}\n---\n{}", src, printed);
        prop_assert_eq!(m2.to_string(), printed.clone());

        // Atomisation: verifies, and evaluates bit for bit like the parsed function.
        let a = atomise_function(f);
        prop_assert!(verifier::verify_function(&a).is_empty(), "atomised function does not verify:\n{}", a_text(&a));
        prop_assert_eq!(a.phase, Phase::Atomised);
        let mut checked = false;
        for ok in [check_precision::<f64>(&gf, f, &a, &inputs), check_precision::<f32>(&gf, f, &a, &inputs)] {
            match ok {
                Ok(c) => checked |= c,
                Err(msg) => return Err(TestCaseError::fail(format!("{msg}\n--- source ---\n{src}--- atomised ---\n{}", a_text(&a)))),
            }
        }
        prop_assume!(checked, "a unary minus of ±0 or NaN in both precisions");
    }
}

fn a_text(f: &Function) -> String {
    Module { functions: vec![f.clone()] }.to_string()
}
