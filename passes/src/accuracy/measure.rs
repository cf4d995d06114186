//! Bits of error of one function at many input points: binary32 and binary64 evaluations in the
//! IR's own operation order against the certified reference (`robovec_ir::numerics`) of the
//! function as it entered the pipeline, and their statistics; beside the bits, the absolute
//! error of each output: an upper bound of |computed − exact| from the reference's enclosure of
//! the exact value (`robovec_ir::numerics::Enclosure::abs_error_bound`).

use robovec_ir::numerics::{bits_f32, bits_f64, RefValue, Reference, Tape};
use robovec_ir::Function;

/// What is measured: the tape of the function after the pipeline (evaluated in binary32 and
/// binary64) and the tape of the reference function (the same function as it entered the
/// pipeline, whose exact value is the reference), with outputs matched by name and inputs by
/// name over the union of both input lists.
#[derive(Clone, Debug)]
pub struct Subject {
    /// The measured function's tape.
    pub tape: Tape,
    /// The reference function's tape, restricted to the measured outputs in the measured
    /// order (output `k` of both tapes is the same name).
    pub reference: Tape,
    /// Coordinates of a sample point: the reference's inputs, then inputs only the measured
    /// function has.
    pub names: Vec<String>,
    /// For each input of [`Subject::tape`], its coordinate in [`Subject::names`].
    tape_at: Vec<usize>,
    /// For each input of [`Subject::reference`], its coordinate.
    ref_at: Vec<usize>,
}

impl Subject {
    /// Measures `f` against `original` (the same function as it entered the pipeline), or
    /// against itself when `None`.
    ///
    /// # Errors
    /// A message when an output of `f` is not an output of `original`.
    pub fn new(f: &Function, original: Option<&Function>) -> Result<Subject, String> {
        let tape = Tape::new(f);
        let reference = match original {
            None => tape.clone(),
            Some(g) => {
                let mut g = g.clone();
                let mut outs = Vec::with_capacity(f.outputs.len());
                for o in &f.outputs {
                    let Some(x) = g.outputs.iter().find(|x| x.name == o.name) else {
                        return Err(format!(
                            "output `{}` of @{} is not an output of the function as it entered the pipeline \
                             (the error reference)",
                            o.name, f.name
                        ));
                    };
                    outs.push(x.clone());
                }
                g.outputs = outs;
                Tape::new(&g)
            }
        };
        let mut names = reference.inputs.clone();
        for n in &tape.inputs {
            if !names.contains(n) {
                names.push(n.clone());
            }
        }
        let at = |t: &Tape| t.inputs.iter().map(|n| names.iter().position(|m| m == n).expect("union")).collect();
        let (tape_at, ref_at) = (at(&tape), at(&reference));
        Ok(Subject { tape, reference, names, tape_at, ref_at })
    }

    /// Number of outputs measured.
    pub fn n_outputs(&self) -> usize {
        self.tape.outputs.len()
    }
}

/// Per-thread buffers: no allocation per point once warm.
#[derive(Default)]
pub struct Workspace {
    s32: Vec<f32>,
    s64: Vec<f64>,
    x32: Vec<f32>,
    x64: Vec<f64>,
    reference: Reference,
    refs: Vec<RefValue>,
    xt: Vec<f64>,
    xr: Vec<f64>,
}

/// The errors at one point.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointErrors {
    /// Bits of error of each output in binary32 (output order).
    pub f32: Vec<f64>,
    /// Bits of error of each output in binary64.
    pub f64: Vec<f64>,
    /// How each output's reference was obtained: precision in bits (106 double-double, 256,
    /// 1024), whether the bound certified it, and whether the bound reaches zero.
    pub reference: Vec<(u32, bool, bool)>,
    /// Absolute error of each output in binary32, in the output's units: an upper bound of
    /// |computed − exact| rounded upward (the distance to the reference's enclosure of the
    /// exact value plus its radius); `+∞` when the computed value is not finite or the
    /// reference is unbounded.
    pub abs_f32: Vec<f64>,
    /// The same in binary64.
    pub abs_f64: Vec<f64>,
}

impl PointErrors {
    /// The largest binary32 error over the outputs, bits (the hill-climbing objective).
    pub fn max_f32(&self) -> f64 {
        self.f32.iter().copied().fold(0.0, f64::max)
    }

    /// Mean binary32 error over the outputs, bits.
    pub fn mean_f32(&self) -> f64 {
        if self.f32.is_empty() {
            0.0
        } else {
            self.f32.iter().sum::<f64>() / self.f32.len() as f64
        }
    }
}

/// Evaluates the measured tape at `point` (one value per [`Subject::names`]) in binary32 and
/// binary64, and the reference tape at the same point (`skip_big`: see
/// `Reference::eval_with`).
pub fn errors_at(sub: &Subject, point: &[f64], ws: &mut Workspace, skip_big: Option<&[bool]>) -> PointErrors {
    let tape = &sub.tape;
    ws.xt.clear();
    ws.xt.extend(sub.tape_at.iter().map(|&i| point[i]));
    ws.xr.clear();
    ws.xr.extend(sub.ref_at.iter().map(|&i| point[i]));
    tape.eval_into::<f32>(&ws.xt, &mut ws.s32, &mut ws.x32);
    tape.eval_into::<f64>(&ws.xt, &mut ws.s64, &mut ws.x64);
    ws.reference.eval_with(&sub.reference, &ws.xr, &mut ws.refs, skip_big);
    let mut e = PointErrors::default();
    for ((&(_, s), r), x) in tape.outputs.iter().zip(&ws.refs).zip(ws.reference.enclosures()) {
        let (c32, c64) = (ws.s32[s as usize], ws.s64[s as usize]);
        e.f32.push(bits_f32(c32, r.f32));
        e.f64.push(bits_f64(c64, r.f64));
        e.reference.push((r.bits, r.certified, r.near_zero));
        e.abs_f32.push(x.abs_error_bound(c32 as f64));
        e.abs_f64.push(x.abs_error_bound(c64));
    }
    e
}

/// Probe samples measured with the full reference before the others.
pub const PROBES: usize = 32;

/// Outputs for which the 256-bit path is skipped after the probes: on at least 3/4 of the probe
/// samples where it was tried (and on at least one), it left the output uncertified around
/// zero. These are structural zeros (an exact zero reached through inexact steps; some inputs
/// may make every step exact, hence not "all"); skipping saves the slow path on every later
/// sample, and such values are counted in `ReferenceCounts::uncertified` anyway.
pub fn skip_after_probes(probes: &[PointErrors], n_outputs: usize) -> Vec<bool> {
    (0..n_outputs)
        .map(|k| {
            let tried = probes.iter().filter(|e| e.reference[k].0 > 106);
            let (mut zero, mut n) = (0, 0);
            for e in tried {
                let (_, certified, near_zero) = e.reference[k];
                zero += (!certified && near_zero) as u32;
                n += 1;
            }
            zero > 0 && 4 * zero >= 3 * n
        })
        .collect()
}

/// Mean, 95th percentile and maximum of a set of errors, units: bits (Herbie's metric).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BitsSummary {
    /// Mean, bits.
    pub mean_bits: f64,
    /// 95th percentile (nearest rank: the ⌈0.95·n⌉-th smallest), bits.
    pub p95_bits: f64,
    /// Maximum, bits.
    pub max_bits: f64,
}

/// Summary of `xs` (sorted in place); all zeros for an empty set.
pub fn summarise(xs: &mut [f64]) -> BitsSummary {
    if xs.is_empty() {
        return BitsSummary::default();
    }
    xs.sort_by(f64::total_cmp);
    let n = xs.len();
    let rank = ((0.95 * n as f64).ceil() as usize).clamp(1, n);
    BitsSummary { mean_bits: xs.iter().sum::<f64>() / n as f64, p95_bits: xs[rank - 1], max_bits: xs[n - 1] }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skip_rule_needs_three_quarters_of_uncertain_zeros() {
        let pe = |r: &[(u32, bool, bool)]| PointErrors { reference: r.to_vec(), ..Default::default() };
        let zero = (256, false, true);
        let probes = vec![
            pe(&[zero, zero, (106, true, false), (256, true, false)]),
            pe(&[zero, (256, true, false), (106, true, false), (1024, false, false)]),
            pe(&[zero, zero, (106, true, false), (256, true, false)]),
            pe(&[(256, true, false), zero, (106, true, false), (256, true, false)]),
        ];
        // output 0: 3 of 4 tried are uncertain zeros; 1: 3 of 4; 2: never tried; 3: never zero.
        assert_eq!(skip_after_probes(&probes, 4), [true, true, false, false]);
        assert_eq!(skip_after_probes(&probes[1..2], 4), [true, false, false, false]);
    }

    #[test]
    fn nearest_rank_percentile() {
        let mut xs: Vec<f64> = (1..=100).rev().map(|x| x as f64).collect();
        let s = summarise(&mut xs);
        assert_eq!(s, BitsSummary { mean_bits: 50.5, p95_bits: 95.0, max_bits: 100.0 });
        assert_eq!(summarise(&mut [3.0]), BitsSummary { mean_bits: 3.0, p95_bits: 3.0, max_bits: 3.0 });
        assert_eq!(summarise(&mut []), BitsSummary::default());
        // 20 values: rank ⌈19⌉ = 19th smallest.
        let mut xs: Vec<f64> = (0..20).map(|x| x as f64).collect();
        assert_eq!(summarise(&mut xs).p95_bits, 18.0);
    }
}
