//! One case of the study, in process: the robot of [`robovec_dynamics::topology::build`], its
//! equations by [`robovec_dynamics::generate`] (symbolic parameters, as `robovec-opt` reads the URDF
//! `robovec-gen` writes), then the pipelines through the pass manager. Every figure is read
//! from the code behind `robovec-opt`'s `-stats` and `-report`: [`Figures::of`] (ops, ASAP,
//! ASAPCycle, Y; the placement's cycles) and the `accuracy` artifact's report entry (bits of
//! error).

use robovec_ir::Module;
use robovec_passes::accuracy::report::AccuracyRun;
use robovec_passes::summary::Figures;
use robovec_passes::whole_run::{self, Failure};
use robovec_passes::{Instrumentation, PassContext, PassManager, Session};
use serde::Serialize;

use super::cases::Case;
use robovec_dynamics::{generate, topology::build, Model};

/// The function of the study: direct dynamics (seed §3.2, Table 3.1).
pub const FUNCTION: &str = "dirdyna";

/// The pipeline "as generated": the equations split into binary ops (SPEC §3).
pub const GENERATED: &str = "atomise";

/// The thesis's rewrites (seed §2.4.1, §2.4.3): zero removal and tree-height balancing.
pub const ZERO_BALANCE: &str = "atomise,zero-removal,balance";

/// What to run on each case.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Seed of the robots' parameters ([`robovec_dynamics::topology::build`]).
    pub seed: u64,
    /// `accuracy<samples=K>`: sampled states (accuracy's own seed stays 1, its default).
    pub samples: u32,
    /// The best rewrite pipeline (from the parsed equations, `atomise` first), in the pass
    /// manager's normalised text (`PassManager::pipeline_text`).
    pub best: String,
    /// N of the placements `place<pe=N>` (N ADD + N MULTI PEs) after the best pipeline.
    pub ns: Vec<u32>,
    /// Also run what the case's report folder needs (see [`run_case`]).
    pub report: bool,
}

/// The figures of one pipeline's final IR (SPEC §7 `stats`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Shape {
    /// Ops (SPEC §1).
    pub ops: u64,
    /// Critical path in unit steps (largest ASAP).
    pub asap: u32,
    /// Critical path in cycles (largest ASAPCycle), de10-nano latencies (add 12, mul 7).
    pub asap_cycle: u32,
    /// Number Y = ops / ASAPCycle (seed §3.2).
    pub y: f64,
}

impl Shape {
    fn of(f: &Figures) -> Shape {
        let s = &f.stats;
        Shape { ops: s.ops.total, asap: s.asap, asap_cycle: s.asap_cycle, y: s.y }
    }
}

/// A placement of the best pipeline's IR.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Placed {
    /// N ADD + N MULTI PEs.
    pub n: u32,
    /// Cycles of the placement.
    pub cycles: u32,
}

/// binary32 bits of error of the best pipeline's IR over every (output, sample) pair.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Bits {
    /// Mean, bits.
    pub mean: f64,
    /// Maximum, bits.
    pub max: f64,
}

/// Everything measured on one case.
#[derive(Clone, Debug, Serialize)]
pub struct CaseResult {
    /// The case.
    #[serde(flatten)]
    pub case: Case,
    /// After [`GENERATED`].
    pub generated: Shape,
    /// After [`ZERO_BALANCE`].
    pub zero_balance: Shape,
    /// After the best pipeline ([`Plan::best`]).
    pub best: Shape,
    /// `place<pe=N>` after the best pipeline, in [`Plan::ns`] order.
    pub placed: Vec<Placed>,
    /// `accuracy<samples=K>` after the best pipeline, binary32.
    pub f32_bits: Bits,
    /// The case's report JSON (SPEC §7) and the rows its figures draw, when [`Plan::report`].
    #[serde(skip)]
    pub report: Option<(String, crate::report_dir::data::ReportData)>,
}

/// The parsed-phase module of `case`: `dirdyna` alone (passes work per function, so its
/// figures are those of the module with `invdyna` too).
pub fn module_of(case: &Case, seed: u64) -> Module {
    let robot = build(case.topology, case.dof, seed);
    let mut m = generate(&Model { robot }, false).module;
    m.functions.retain(|f| f.name == FUNCTION);
    m
}

/// Parses `pipeline` (the input is verified by construction).
///
/// # Errors
/// [`Failure::Usage`] for a pipeline that does not parse or names an unknown pass.
pub fn manager(pipeline: &str) -> Result<PassManager, Failure> {
    PassManager::with_registry(
        robovec_backends::REGISTRY,
        pipeline,
        Instrumentation { input_verified: true, ..Instrumentation::default() },
    )
    .map_err(|e| Failure::Usage(format!("error: {e}\n")))
}

/// A session of `pipeline` on `m` with `cx`, run.
fn run_on(pipeline: &str, m: Module, cx: PassContext, case: &Case) -> Result<Session, Failure> {
    let mut session = Session::new(manager(pipeline)?, m, cx);
    session
        .run_quiet()
        .map_err(|e| Failure::Input(format!("error: {}: pipeline `{pipeline}`: {e}\n", case.label())))?;
    Ok(session)
}

/// The figures of [`FUNCTION`] in `m`.
fn figures(m: &Module, cx: &PassContext) -> Figures {
    let f = m.functions.iter().find(|f| f.name == FUNCTION).expect("the generator writes dirdyna");
    Figures::of(f, cx)
}

/// A context for a pipeline that continues `after`'s (same target and latencies), as if its
/// passes followed in one `-passes` list.
fn continuing(after: &PassContext) -> PassContext {
    PassContext {
        latencies: after.latencies,
        latencies_from: after.latencies_from.clone(),
        ..PassContext::with_target(after.target.clone())
    }
}

/// Measures `case`: [`GENERATED`], [`ZERO_BALANCE`] and the best pipeline from the generated
/// module; then, on the best pipeline's IR, `accuracy<samples=K>` and `place<pe=N>` for each N
/// (each as if appended to the best pipeline in one `robovec-opt -passes` list). With
/// [`Plan::report`], the best pipeline continues with
/// `accuracy<samples=K>,sweep<pe=NS>,place<pe=N0>` (N0 the first N) after a `-pareto` study of
/// the three pipelines (K samples), and the report JSON of that whole run is kept: what
/// `robovec-opt FILE.urdf -function=dirdyna -passes=BEST,accuracy…,place<pe=N0>
/// -pareto=… -report-dir=…` writes.
///
/// # Errors
/// [`Failure::Usage`] for a pipeline that does not parse; [`Failure::Input`] when a pass fails.
pub fn run_case(case: &Case, plan: &Plan) -> Result<CaseResult, Failure> {
    let generated = module_of(case, plan.seed);
    let target = robovec_machine::target::Target::de10_nano();
    let shape_after = |pipeline: &str| -> Result<Shape, Failure> {
        let s = run_on(pipeline, generated.clone(), PassContext::with_target(target.clone()), case)?;
        Ok(Shape::of(&figures(&s.module, &s.cx)))
    };
    let gen_shape = shape_after(GENERATED)?;
    let zb_shape = shape_after(ZERO_BALANCE)?;

    let mut cx = PassContext { original: Some(generated.clone()), ..PassContext::with_target(target.clone()) };
    if plan.report {
        let text = format!("{GENERATED};{ZERO_BALANCE};{}", plan.best);
        let pareto = whole_run::pareto::measure(
            robovec_backends::REGISTRY,
            &generated,
            FUNCTION,
            &text,
            plan.samples,
            1,
            None,
            &cx.target,
            &robovec_passes::progress::Progress::hidden(),
            None,
        )
        .map_err(|f| match f {
            Failure::Input(s) => Failure::Input(format!("{}: {s}", case.label())),
            usage => usage,
        })?;
        cx.emit(pareto);
    }
    let mut session = run_on(&plan.best, generated.clone(), cx, case)?;
    let best_shape = Shape::of(&figures(&session.module, &session.cx));
    let best = session.module.clone();
    let n0 = plan.ns.first().copied();
    let mut tail = format!("accuracy<samples={}>", plan.samples);
    if plan.report {
        let ns: Vec<String> = plan.ns.iter().map(u32::to_string).collect();
        tail += &format!(",sweep<pe={}>", ns.join(","));
        if let Some(n) = n0 {
            tail += &format!(",place<pe={n}>");
        }
    }
    session
        .run_more(manager(&tail)?)
        .map_err(|e| Failure::Input(format!("error: {}: pipeline `{tail}`: {e}\n", case.label())))?;
    let bits = accuracy_bits(&session, case)?;
    let mut placed = Vec::new();
    let mut report = None;
    if plan.report {
        let own = figures(&session.module, &session.cx);
        if let (Some(n), Some(p)) = (n0, &own.placement) {
            placed.push(Placed { n, cycles: p.cycles });
        }
        let (input, pipeline) = (case.urdf_name(plan.seed), format!("{},{tail}", plan.best));
        let text = robovec_passes::report::report_text(&input, &pipeline, session.records(), &session.cx, &own);
        report = Some((text, crate::report_dir::data::ReportData::of(&input, &pipeline, &own, &session.cx)));
    }
    for &n in plan.ns.iter().skip(placed.len()) {
        let s = run_on(&format!("place<pe={n}>"), best.clone(), continuing(&session.cx), case)?;
        let cycles = figures(&s.module, &s.cx).placement.map_or(0, |p| p.cycles);
        placed.push(Placed { n, cycles });
    }
    Ok(CaseResult {
        case: *case,
        generated: gen_shape,
        zero_balance: zb_shape,
        best: best_shape,
        placed,
        f32_bits: bits,
        report,
    })
}

/// binary32 mean / max bits of the last `accuracy` measurement of [`FUNCTION`] (the report's
/// `accuracy.f32`, what `-stats` prints as `f32 mean/p95/max`), read as the pass's own type.
fn accuracy_bits(session: &Session, case: &Case) -> Result<Bits, Failure> {
    let acc = session
        .artifacts_of::<AccuracyRun>()
        .filter_map(|run| run.reports.iter().find(|r| r.function == FUNCTION))
        .last()
        .ok_or_else(|| Failure::Input(format!("error: {}: accuracy reported nothing\n", case.label())))?;
    Ok(Bits { mean: acc.f32.mean_bits, max: acc.f32.max_bits })
}
