//! Synthetic straight-line Robotran C files of a chosen size, for the scaling benchmark
//! (`benches/parse_scale.rs`) and the scaling tests.
//!
//! The file has the shape of a ROBOTRAN 6.6 `dirdyna` (GRAMMAR-NOTES §1): a banner comment,
//! `#include`, the signature `void mbs_dirdyna(double **M,double *c,\nMbsData *s, double tsim)`,
//! the `#define q s->q` aliases, trig initial variables `C1 = cos(q[1]);`, then blocks of
//! temporaries `T7 = qd[3]*S2+s->dpt[1][4]*(T5-T2*(2.0));` whose operands are earlier
//! temporaries, trig variables, inputs and parenthesised literals, each block ending in outputs
//! `M[i][j] = T7;`, `c[i] = T7*C3-T6;`. Everything is deterministic (a fixed seed of the
//! workspace's one generator, [`SplitMix64`]), so two calls with the same [`Shape`] give the same
//! bytes.

use std::fmt::Write as _;

use robovec_ir::rng::SplitMix64;

/// What to generate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    /// Approximate file size, bytes (the file stops at the first statement past it).
    pub bytes: usize,
    /// Joint coordinates `q[1..=joints]` (trig variables `C1 S1 …`), joints.
    pub joints: u32,
    /// Temporaries per output, temporaries (1 = every temporary is also written to an output).
    pub temps_per_output: u32,
    /// Binary operators per temporary's right-hand side, ops (≥ 1).
    pub ops_per_temp: u32,
}

impl Shape {
    /// `bytes` of text with one output per temporary (the most outputs per byte: about one
    /// output per 70 bytes, i.e. ~1.4·10⁶ outputs in 100 MB), 30 joints, 5 ops per temporary.
    pub fn many_outputs(bytes: usize) -> Shape {
        Shape { bytes, joints: 30, temps_per_output: 1, ops_per_temp: 5 }
    }
}

/// What was generated, for tests that check a count computed independently of the front end.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Generated {
    /// The C text.
    pub text: String,
    /// Temporaries `T1 …`, values.
    pub temps: u64,
    /// Output locations written (each once), outputs.
    pub outputs: u64,
    /// Binary operators in temporaries and output expressions (= ops after `atomise`, which
    /// folds no operator of this generator: no unary minus, no copies but `M[i][j] = Tk;`), ops.
    pub ops: u64,
}

/// Width of the output matrix `M`: outputs fill `M[1][1..=W]`, `M[2][…]`, … row by row.
const M_WIDTH: u64 = 64;

/// Generates a file of about `shape.bytes` bytes (see the module doc).
pub fn straight_line_c(shape: Shape) -> Generated {
    let mut rng = SplitMix64::new(0x2545_F491_4F6C_DD1D);
    let mut g = Generated { text: String::with_capacity(shape.bytes + 4096), ..Generated::default() };
    let t = &mut g.text;
    t.push_str("//\n//\tROBOTRAN - Version 6.6 (build : february 22, 2008)\n//\tsynthetic straight-line file\n//\n\n");
    t.push_str("#include <math.h>\n\n#include \"mbs_data.h\"\n\n");
    t.push_str("void mbs_dirdyna(double **M,double *c,\nMbsData *s, double tsim)\n\n{\n");
    t.push_str("#define q s->q\n#define qd s->qd\n#define qdd s->qdd\n\n// Trigonometric Variables\n\n");
    let joints = shape.joints.max(1) as u64;
    for j in 1..=joints {
        let _ = writeln!(t, "  C{j} = cos(q[{j}]);\n  S{j} = sin(q[{j}]);");
    }
    t.push_str("\n// = = Block_0_1_0_0_0_1 = =\n\n");
    let ops = shape.ops_per_temp.max(1) as u64;
    let mut c_outputs = 0u64;
    while t.len() < shape.bytes {
        g.temps += 1;
        let k = g.temps;
        let _ = write!(t, "  T{k} = ");
        // `ops + 1` operands joined by `ops` operators; now and then a parenthesised pair.
        operand(t, &mut rng, k, joints);
        let mut written = 0;
        while written < ops {
            t.push(['+', '-', '*'][rng.below(3) as usize]);
            if ops - written >= 2 && rng.below(4) == 0 {
                t.push('(');
                operand(t, &mut rng, k, joints);
                t.push(['+', '-'][rng.below(2) as usize]);
                operand(t, &mut rng, k, joints);
                t.push(')');
                written += 2;
            } else {
                operand(t, &mut rng, k, joints);
                written += 1;
            }
        }
        g.ops += ops;
        t.push_str(";\n");
        if k.is_multiple_of(shape.temps_per_output.max(1) as u64) {
            if rng.below(4) == 0 {
                c_outputs += 1;
                let _ = writeln!(t, "  c[{c_outputs}] = T{k}*C{}-(2.0);", 1 + rng.below(joints));
                g.ops += 2;
            } else {
                let i = g.outputs - c_outputs;
                let _ = writeln!(t, "  M[{}][{}] = T{k};", 1 + i / M_WIDTH, 1 + i % M_WIDTH);
            }
            g.outputs += 1;
        }
    }
    t.push_str("\n// ====== END Task 0 ======\n\n}\n");
    g
}

/// One operand of temporary `k`: an earlier temporary (mostly a recent one), a trig variable,
/// an input or a parenthesised literal.
fn operand(t: &mut String, rng: &mut SplitMix64, k: u64, joints: u64) {
    let j = 1 + rng.below(joints);
    match rng.below(8) {
        0..=3 if k > 1 => {
            let reach = if rng.below(8) == 0 { 4096 } else { 32 };
            let back = 1 + rng.below((k - 1).min(reach));
            let _ = write!(t, "T{}", k - back);
        }
        0 | 4 => {
            let _ = write!(t, "{}{j}", if rng.below(2) == 0 { 'C' } else { 'S' });
        }
        1 | 5 => {
            let _ = write!(t, "s->dpt[{}][{j}]", 1 + rng.below(3));
        }
        2 | 6 => {
            let _ = write!(t, "qd[{j}]");
        }
        _ => t.push_str(["(2.0)", "(0.5)", "s->m[3]", "s->l[2][5]"][rng.below(4) as usize]),
    }
}
