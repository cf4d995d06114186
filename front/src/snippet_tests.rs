//! Small inline programs per language: the lowering rules of `lower.rs`, one by one.

use robovec_ir::{BinOp, Callee, Def, Expr, Function, Module, Operand, TrigFn};

use super::{parse_str, Language};

pub(super) fn parse(lang: Language, src: &str) -> Module {
    parse_str(lang, src.as_bytes(), None).unwrap_or_else(|errs| {
        panic!("unexpected errors:\n{}", errs.iter().map(|e| e.to_string()).collect::<Vec<_>>().join("\n"))
    })
}

fn val(f: &Function, name: &str) -> Expr {
    Expr::Operand(Operand::Value(f.lookup(name).unwrap_or_else(|| panic!("no value `{name}` in\n{f}"))))
}

fn k(x: f64) -> Expr {
    Expr::Operand(Operand::Const(x))
}

fn neg(e: Expr) -> Expr {
    Expr::Neg(Box::new(e))
}

fn bin(op: BinOp, a: Expr, b: Expr) -> Expr {
    Expr::Binary(op, Box::new(a), Box::new(b))
}

fn def<'f>(f: &'f Function, name: &str) -> &'f Def {
    &f.value(f.lookup(name).unwrap_or_else(|| panic!("no value `{name}` in\n{f}"))).def
}

fn expr<'f>(f: &'f Function, name: &str) -> &'f Expr {
    match def(f, name) {
        Def::Expr(e) => e,
        d => panic!("`{name}` is {d:?}, not an expression"),
    }
}

fn output(f: &Function, name: &str) -> Operand {
    f.outputs.iter().find(|o| o.name == name).unwrap_or_else(|| panic!("no output `{name}` in\n{f}")).value
}

pub(super) const C_SAMPLE: &str = C_DIRDYNA;
const C_DIRDYNA: &str = "//\tROBOTRAN - Version 6.6 (build : february 22, 2008)\n\
#include <math.h> \n\
\n\
void mbs_dirdyna(double **M,double *c,\n\
MbsData *s, double tsim)\n\
\n\
// double M[2][2];\n\
{ \n\
#include \"mbs_dirdyna_x.h\" \n\
#define q s->q \n\
\n\
// = = Block_0_0_0_0_0_1 = = \n\
  C4 = cos(q[4]);\n\
  S4 = sin(q[4]);\n\
  A = -s->g[3]*S4+C4;\n\
  B = C4*(-A*S4-C4);\n\
  D = -(A);\n\
  E = -(2.0)*A*S4;\n\
  F = A+\n B*(2.0)/C4;\n\
  M[1][1] = F;\n\
  M[1][2] = D;\n\
  M[2][1] = D;\n\
  M[2][2] = 0;\n\
  c[1] = -(1.0);\n\
  c[2] = -E;\n\
  c[3] = s->In[5][17];\n\
 \n\
// ====== END Task 0 ====== \n\
}\n \n";

#[test]
fn c_expressions_unary_minus_literals_and_outputs() {
    let m = parse(Language::C, C_DIRDYNA);
    let f = &m.functions[0];
    assert_eq!(f.name, "dirdyna");
    assert_eq!(f.equations, Some(12), "5 temporaries + 7 outputs, trig excluded");
    assert_eq!(def(f, "C4"), &Def::Trig(TrigFn::Cos, f.lookup("q[4]").unwrap()));
    assert_eq!(def(f, "S4"), &Def::Trig(TrigFn::Sin, f.lookup("q[4]").unwrap()));
    use BinOp::*;
    // `-a*b+c` is Add(Neg(Mul(a,b)), c)
    assert_eq!(expr(f, "A"), &bin(Add, neg(bin(Mul, val(f, "g[3]"), val(f, "S4"))), val(f, "C4")));
    // unary minus right after `(`
    assert_eq!(expr(f, "B"), &bin(Mul, val(f, "C4"), bin(Sub, neg(bin(Mul, val(f, "A"), val(f, "S4"))), val(f, "C4"))));
    assert_eq!(expr(f, "D"), &neg(val(f, "A")));
    // a literal stays a non-negative constant under the minus
    assert_eq!(expr(f, "E"), &neg(bin(Mul, bin(Mul, k(2.0), val(f, "A")), val(f, "S4"))));
    // continuation line, left-assoc `*` `/`
    assert_eq!(expr(f, "F"), &bin(Add, val(f, "A"), bin(Div, bin(Mul, val(f, "B"), k(2.0)), val(f, "C4"))));
    // outputs: copies, both triangles, zero, -(1.0), a negated name, a bare input read
    assert_eq!(output(f, "M[1][1]"), Operand::Value(f.lookup("F").unwrap()));
    assert_eq!(output(f, "M[1][2]"), output(f, "M[2][1]"));
    assert_eq!(output(f, "M[1][2]"), Operand::Value(f.lookup("D").unwrap()));
    assert_eq!(output(f, "M[2][2]"), Operand::Const(0.0));
    assert_eq!(output(f, "c[1]"), Operand::Const(-1.0));
    assert_eq!(output(f, "c[2]"), Operand::Value(f.lookup("c[2]").unwrap()));
    assert_eq!(expr(f, "c[2]"), &neg(val(f, "E")));
    assert_eq!(output(f, "c[3]"), Operand::Value(f.lookup("In[5][17]").unwrap()));
    assert!(matches!(def(f, "In[5][17]"), Def::Input));
    let c = f.op_counts();
    // A: mul sub add; B: mul sub sub mul; D: sub; E: mul mul (folded); F: mul div add; c[2]: sub
    assert_eq!((c.add, c.sub, c.mul, c.div, c.total), (2, 5, 6, 1, 14));
    robovec_ir::verifier::verify(&m).expect("verifies");
}

#[test]
fn crlf_and_latin1_bytes_are_accepted_with_offsets_kept() {
    let lf = parse(Language::C, C_DIRDYNA);
    let crlf = parse(Language::C, &C_DIRDYNA.replace('\n', "\r\n"));
    assert_eq!(lf.to_string(), crlf.to_string());
    // A Latin-1 `é` (one byte, invalid UTF-8) in the banner.
    let mut bytes = b"//\tUniversit\xe9 catholique de Louvain\n".to_vec();
    bytes.extend_from_slice(C_DIRDYNA.as_bytes());
    let m = parse_str(Language::C, &bytes, None).expect("parses");
    assert_eq!(m.to_string(), lf.to_string());
    // Spans are byte offsets into the original bytes.
    let mut bad = b"// caf\xe9 \xff\xfe\n".to_vec();
    bad.extend_from_slice(b"void mbs_invdyna(double *Qq, MbsData *s, double tsim)\n{\n  Qq[1] = Undefined1;\n}\n");
    let errs = parse_str(Language::C, &bad, None).expect_err("undefined name");
    let at = bad.windows(10).position(|w| w == b"Undefined1").unwrap();
    assert_eq!(errs[0].span.range(), at..at + 10);
    assert_eq!(super::source_text(&bad).len(), bad.len());
    // A UTF-8 byte-order mark is a blank.
    let bom = parse(Language::C, &format!("\u{FEFF}{C_DIRDYNA}"));
    assert_eq!(bom.to_string(), lf.to_string());
}

#[test]
fn c_read_modify_write_versions() {
    let m = parse(
        Language::C,
        "void mbs_link(double **frc,double **trq,double *Flnk,\nMbsData *s, double tsim)\n{\n\
         \x20 a = s->dpt[1][2];\n\
         \x20 s->frc[2][11] = s->frc[2][11]+a;\n\
         \x20 frc[2][11] = a+s->frc[2][11];\n\
         \x20 b = frc[2][11]*(2.0);\n\
         \x20 trq[1][3] = s->trq[1][3];\n\
         \x20 Flnk[1] = b;\n\
         \x20 s->flag_stop = 1;\n}\n",
    );
    let f = &m.functions[0];
    assert_eq!(f.name, "link");
    assert!(matches!(def(f, "frc[2][11]"), Def::Input));
    assert_eq!(expr(f, "frc[2][11].1"), &bin(BinOp::Add, val(f, "frc[2][11]"), val(f, "a")));
    assert_eq!(expr(f, "frc[2][11].2"), &bin(BinOp::Add, val(f, "a"), val(f, "frc[2][11].1")));
    assert_eq!(expr(f, "b"), &bin(BinOp::Mul, val(f, "frc[2][11].2"), k(2.0)));
    assert_eq!(output(f, "frc[2][11]"), Operand::Value(f.lookup("frc[2][11].2").unwrap()));
    assert_eq!(output(f, "trq[1][3]"), Operand::Value(f.lookup("trq[1][3]").unwrap()));
    assert_eq!(output(f, "flag_stop"), Operand::Const(1.0));
    assert_eq!(f.outputs.len(), 4);
    assert_eq!(f.equations, Some(7));
}

#[test]
fn c_callbacks_vectors_and_local_arrays() {
    let m = parse(
        Language::C,
        "void mbs_extforces(double **frc,double **trq,\nMbsData *s, double tsim)\n{\n\
         double PxF1[4];\ndouble RxF1[4][4];\ndouble *SWr1;\n#define q s->q\n\
         \x20 RxF1[2][1] = q[3];\n  RxF1[1][2] = q[2];\n  PxF1[1] = q[1];\n\
         \x20 SWr1 = user_ExtForces(PxF1,RxF1,s,tsim,1);\n\
         \x20 x = SWr1[3]*SWr1[1]+SWr1[3];\n\
         \x20 Z1 = sqrt(x);\n\
         \x20 F1 = user_LinkForces(Z1,x,s,tsim,2);\n\
         \x20 frc[1][2] = s->frc[1][2]+F1;\n}\n",
    );
    let f = &m.functions[0];
    let args = vec![val(f, "PxF1[1]"), val(f, "RxF1[1][2]"), val(f, "RxF1[2][1]"), val(f, "tsim")];
    let call = |elem| Expr::call(Callee { name: "user_ExtForces.1".into(), elem: Some(elem) }, args.clone());
    assert_eq!(expr(f, "SWr1[3]"), &call(3));
    assert_eq!(expr(f, "SWr1[1]"), &call(1));
    assert!(f.lookup("SWr1[2]").is_none(), "only used elements are defined");
    assert_eq!(
        expr(f, "x"),
        &bin(BinOp::Add, bin(BinOp::Mul, val(f, "SWr1[3]"), val(f, "SWr1[1]")), val(f, "SWr1[3]"))
    );
    assert_eq!(expr(f, "Z1"), &Expr::call(Callee { name: "sqrt".into(), elem: None }, vec![val(f, "x")]));
    assert_eq!(
        expr(f, "F1"),
        &Expr::call(
            Callee { name: "user_LinkForces.2".into(), elem: None },
            vec![val(f, "Z1"), val(f, "x"), val(f, "tsim")]
        )
    );
    // 3 array elements + x + Z1 + F1 + frc output; the SWr1 binding is not an equation.
    assert_eq!(f.equations, Some(7));
    assert_eq!(f.op_counts().call, 4);
}

#[test]
fn c_sensor_switch_is_split_per_case() {
    let m = parse(
        Language::C,
        "void  mbs_sensor(MbsSensor *sens, \n              MbsData *s,\n              int isens)\n{ \n\
         #include \"mbs_sensor_x.h\" \n#define q s->q \n\
         \x20 C1 = cos(q[1]);\n  S1 = sin(q[1]);\n  X = C1*s->dpt[1][1];\n  Y = S1*(2.0);\n\
         switch(isens)\n{\n \n// \nbreak;\ncase 1:\n\
         \x20   sens->P[1] = X;\n    sens->R[1][1] = (1.0);\n    sens->R[2][1] = -S1;\n\
         break;\ncase 2:\n    Z = Y+S1;\n    sens->P[1] = Z;\n\
         break;\ndefault:\nbreak;\n}\n}\n",
    );
    let names: Vec<&str> = m.functions.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["sensor_1", "sensor_2"]);
    let f1 = &m.functions[0];
    assert!(f1.lookup("Y").is_none() && f1.lookup("C1").is_some() && f1.lookup("X").is_some());
    assert_eq!(f1.equations, Some(4), "X + 3 outputs");
    assert_eq!(output(f1, "sens.R[1][1]"), Operand::Const(1.0));
    assert_eq!(expr(f1, "sens.R[2][1]"), &neg(val(f1, "S1")));
    let f2 = &m.functions[1];
    assert!(f2.lookup("X").is_none() && f2.lookup("C1").is_none() && f2.lookup("Y").is_some());
    assert_eq!(f2.equations, Some(3), "Y, Z, sens.P[1]");
    robovec_ir::verifier::verify(&m).expect("verifies");
}

#[test]
fn matlab_function_aliases_continuations_and_callbacks() {
    let src = "%\tROBOTRAN - Version 6.6\n%\n\
               function [frc,trq,Flnk] = link(s,tsim,usrfun)\n\n frc = zeros(3,6);\n trq = zeros(3,6);\n\n\
               q = s.q; \nfrc = s.frc; \n\n% = = Block = = \n\
               \x20 C2 = cos(q(2));\n\
               \x20 A = s.dpt(2,4)*C2+...\n s.m(3)-(0.50)*q(2);\n\
               \x20 Flink1 = usrfun.flink(A,C2,s,tsim,1);\n\
               \x20 frc(2,1) = s.frc(2,1)+Flink1;\n\
               \x20 frc(2,1) = frc(2,1)+A;\n\
               \x20 trq(1,1) = -(1.0);\n\
               \x20 Flnk(1) = Flink1;\n";
    let m = parse(Language::Matlab, src);
    let f = &m.functions[0];
    assert_eq!(f.name, "link");
    use BinOp::*;
    assert_eq!(
        expr(f, "A"),
        &bin(
            Sub,
            bin(Add, bin(Mul, val(f, "dpt[2][4]"), val(f, "C2")), val(f, "m[3]")),
            bin(Mul, k(0.5), val(f, "q[2]"))
        )
    );
    assert_eq!(
        expr(f, "Flink1"),
        &Expr::call(
            Callee { name: "usrfun.flink.1".into(), elem: None },
            vec![val(f, "A"), val(f, "C2"), val(f, "tsim")]
        )
    );
    assert_eq!(expr(f, "frc[2][1].2"), &bin(Add, val(f, "frc[2][1].1"), val(f, "A")));
    assert_eq!(output(f, "frc[2][1]"), Operand::Value(f.lookup("frc[2][1].2").unwrap()));
    assert_eq!(output(f, "trq[1][1]"), Operand::Const(-1.0));
    assert_eq!(output(f, "Flnk[1]"), Operand::Value(f.lookup("Flink1").unwrap()));
    assert_eq!(f.equations, Some(6));
    // CRLF gives the same module.
    assert_eq!(parse(Language::Matlab, &src.replace('\n', "\r\n")).to_string(), m.to_string());
}

#[test]
fn python_aliases_continuations_and_zero_outputs() {
    for indent in ["  ", "    "] {
        let src = format!(
            "#\tMBsysTran - Release 8.1\n##\nfrom math import sin, cos\nimport numpy as np  \n\n\
             def invdyna(phi,s,tsim):\n{i}Qq = phi  # compatibility with symbolic generation\n{i}q = s.q\n{i}frc = s.frc\n\
             {i}S4 = np.sin(q[4])\n{i}C4 = cos(q[4])\n\
             {i}A = s.dpt[2,1]*S4+ \\\n \t  s.In[1,22]*(-C4+frc[1,3])\n\
             {i}B = -(A)*\\\n   (2.0)\n\
             {i}Qq[1] = A\n{i}Qq[2] = 0\n{i}Qq[3] = -B\n\n# Number of continuation lines = 2\n",
            i = indent
        );
        let m = parse(Language::Python, &src);
        let f = &m.functions[0];
        assert_eq!(f.name, "invdyna");
        use BinOp::*;
        assert_eq!(
            expr(f, "A"),
            &bin(
                Add,
                bin(Mul, val(f, "dpt[2][1]"), val(f, "S4")),
                bin(Mul, val(f, "In[1][22]"), bin(Add, neg(val(f, "C4")), val(f, "frc[1][3]")))
            )
        );
        assert_eq!(expr(f, "B"), &neg(bin(Mul, val(f, "A"), k(2.0))));
        assert_eq!(output(f, "Qq[1]"), Operand::Value(f.lookup("A").unwrap()));
        assert_eq!(output(f, "Qq[2]"), Operand::Const(0.0));
        assert_eq!(expr(f, "Qq[3]"), &neg(val(f, "B")));
        assert_eq!(f.equations, Some(5));
        assert_eq!(parse(Language::Python, &src.replace('\n', "\r\n")).to_string(), m.to_string());
    }
}

#[test]
fn python_outputs_are_parameters() {
    let m = parse(
        Language::Python,
        "def cons_hJ(h, Jac, s):\n    q = s.q\n    h[1] = q[1]\n    Jac[1,1] = 0\n    Jac[1,2] = (1.0)\n",
    );
    let f = &m.functions[0];
    assert_eq!(f.name, "cons_hJ");
    assert_eq!(output(f, "Jac[1][2]"), Operand::Const(1.0));
    assert_eq!(output(f, "h[1]"), Operand::Value(f.lookup("q[1]").unwrap()));
    assert_eq!(f.equations, Some(3));
}
