//! robovec-dynamics: the symbolic generator (issue 14). Equations of motion of a robot
//! ([`robot::Robot`], built by the URDF front end or by a topology family), written as the same
//! parsed-phase IR the Robotran front ends produce, so every pass, report and back end applies
//! unchanged.
//!
//! # Dependencies
//! This crate may import `robovec-ir` (the IR it writes, the `-time-limit` deadline the
//! generator stops at, and the atomise and cse transforms its op counts use); never the passes
//! (the study, which runs pipelines on the robots of [`topology`], is the driver's: `robovec::study`), never the front ends (`robovec-front`, which depends on
//! it: the URDF front end parses into [`robot::Robot`] and calls [`generate`]) nor the driver
//! (`robovec`).
//!
//! # Main modules
//! [`robot`] (the model), [`sym`] (the expression builder), [`rnea`], [`crba`] and [`dirdyna`]
//! (the formulations), [`depth`] (the depth-optimised formulation of `--formulation=depth`), [`lump`] (fixed joints contracted), [`frames`] and [`origins`] (the body
//! frames the generator may choose),
//! [`topology`] (the study's robot families), [`urdf_out`] and [`robotran_c`] (the writers of
//! `robovec-gen`).
//!
//! # What is generated
//! `invdyna`: inverse dynamics `Qq[i]` of a fixed-base tree by the recursive Newton–Euler
//! algorithm ([`rnea`]), symbolic in the joint coordinates `q[i]`, `qd[i]`, `qdd[i]`, the
//! gravity vector `g[1..3]` (Pinocchio's default is `g[3] = −9.81`) and the model parameters.
//! `dirdyna`: direct dynamics `M[i][j]` (by CRBA, [`crba`]), `c[i]` (by RNEA) with
//! `M qdd + c = Qq` ([`dirdyna`]). `fordyna`: forward dynamics `qdd[i]` from `q`, `qd`, `Qq`
//! and `g` (Pinocchio's `aba`; CRBA, then the sparse `LᵀDL` factorisation, [`fordyna`]), written
//! only when asked for. [`generate_with`] writes only the functions a [`Request`]
//! names (`-function`; without it `invdyna` and `dirdyna`) and stops at its deadline (`-time-limit`); the cost of each is linear
//! in the ops it writes, plus `dirdyna`'s `nq²` outputs (issue 28: no table of body pairs, no
//! copy of a link's sums per child).
//! `--floating-base` puts the robot on Robotran's floating base first
//! ([`robot::Robot::with_floating_base`]): six joints `T1`, `T2`, `T3` (prismatic along the
//! world x, y, z) and `R1`, `R2`, `R3` (revolute about x, then the new y, then the new z) are
//! `q[1..6]`, the URDF's moving joints follow. Pinocchio's model with these coordinates is
//! `buildModelFromUrdf(path, JointModelComposite([PX, PY, PZ, RX, RY, RZ]))` (what the oracle
//! tests build); from a `JointModelFreeFlyer` state (position, quaternion, velocity in the base
//! frame) take the position as `q[1..3]`, the quaternion's x-y'-z'' Cardan angles as `q[4..6]`,
//! and map the velocities through the Cardan rates (`ω = E(q) qd[4..6]`, linear velocity
//! rotated to the world frame).
//!
//! `--free-flyer` puts it on Pinocchio's free flyer instead ([`robot::Robot::with_free_flyer`]):
//! `q[1..7]` the base position and unit quaternion `(x, y, z, w)` (not normalised by the
//! equations: the caller's job, as in Pinocchio), `qd[1..6]`, `qdd[1..6]`, `Qq[1..6]` the base's
//! velocity, acceleration and force in its frame (linear, then angular); the joints follow from
//! `q[8]`, `qd[7]` ([`Layout::q_index`], [`Layout::v_index`]). `-gravity=x,y,z`
//! ([`Request::gravity`]) writes `g` as numbers.
//!
//! # Numbering (Pinocchio's)
//! Joints are numbered depth first from the root link, the joints leaving a link taken in
//! byte order of their names (urdfdom's sorted map, which `pinocchio.buildModelFromUrdf`
//! walks). Links on fixed joints are first merged into the link they hang from ([`lump`], as
//! Pinocchio's reader does; the walk keeps its order). Body `b` is the child link of the `b`-th
//! joint of that walk;
//! the moving (revolute, continuous, prismatic) joints are numbered `q[1..nq]` in the same walk,
//! so `q[i]`, `qd[i]`, `qdd[i]` and `Qq[i]` are Pinocchio's entry `i − 1` of a fixed-base model.
//!
//! # Parameters (Robotran's layout, SPEC §2)
//! - `dpt[k][b]`: the origin of joint `b` in its parent link frame (URDF joint `<origin xyz>`), m;
//! - `l[k][b]`: the centre of mass of body `b` in its frame, m; `m[b]`: its mass, kg;
//! - `In[k][b]`: its inertia tensor about the centre of mass in its frame, kg·m², row-major
//!   `k = 1..9`; the tensor is symmetric, so the lower entries read the upper ones' names
//!   (`In[2][b]` stands for both (1,2) and (2,1); `In[4]`, `In[7]`, `In[8]` never appear).
//!
//! A parameter whose URDF value is exactly 0 is a structural zero and folded, as Robotran folds
//! the parameters a model sets to 0; the others stay inputs and their values go to
//! [`Generated::params`] (what `-params-out` writes for `specialize<params=…>` and `-eval`),
//! unless `--fold-params` folds them all. Constant rotations (URDF `rpy`) are numbers. A chain
//! of joints with dense `rpy` may be written in other body frames ([`frames`]), and link
//! frames may be slid along their joint axes ([`origins`]), when that lowers the op count; the
//! parameters of those links are then in these frames.

#![deny(missing_docs)]

pub mod aba;
pub mod crba;
pub mod depth;
pub mod dirdyna;
pub mod fordyna;
pub mod frames;
mod implicit;
pub mod lump;
pub mod origins;
pub mod rnea;
pub mod rnea_derivatives;
pub mod robot;
pub mod robotran_c;

pub mod sym;
pub mod tangent;
pub mod topology;
pub mod urdf_out;

#[cfg(test)]
mod scale_tests;

use std::collections::BTreeMap;

use robovec_ir::time_limit::Deadline;
use robovec_ir::Module;
use rustc_hash::FxHashMap;

use robot::Robot;
use sym::{Builder, Term, ZERO};

/// A robot to generate equations for.
#[derive(Clone, Debug)]
pub struct Model {
    /// The checked kinematic tree.
    pub robot: Robot,
}

/// The numbering and parameter values of a model (see the module doc).
#[derive(Clone, Debug)]
pub struct Layout {
    /// For each joint of the depth-first walk, the index `i` (1-based) of its first velocity
    /// coordinate — `qd[i]`, `qdd[i]`, `Qq[i]`, row and column `i` of `M` — or `None` for a fixed
    /// joint. A free flyer has six from there ([`robot::JointKind::nv`]).
    pub v_index: Vec<Option<usize>>,
    /// For each joint of the walk, the index (1-based) of its first configuration coordinate
    /// `q[i]`, or `None` for a fixed joint (a free flyer has seven; `v_index` plus one for every
    /// joint after it).
    pub q_index: Vec<Option<usize>>,
    /// Velocity coordinates, `nv`.
    pub nv: usize,
    /// Configuration coordinates, `nq` (`nv`, plus one with a free flyer and one per continuous
    /// joint under [`robot::Robot::cos_sin`]).
    pub nq: usize,
    /// Every parameter (canonical name) → value, zeros included.
    pub values: BTreeMap<String, f64>,
}

impl Layout {
    /// Whether each body moves: a moving joint lies on its path from the root (`parent` from
    /// [`Robot::body_parents`]; length `parent.len()`, entry 0 the base's, false). The others
    /// are fixed to the base and bear no joint force.
    pub fn moving_bodies(&self, parent: &[usize]) -> Vec<bool> {
        let mut moves = vec![false; parent.len()];
        for i in 1..parent.len() {
            moves[i] = moves[parent[i]] || self.v_index[i - 1].is_some();
        }
        moves
    }

    /// The numbering and parameters of `robot`.
    pub fn of(robot: &Robot) -> Layout {
        let order = robot.dfs_joints();
        let mut v_index = Vec::with_capacity(order.len());
        let mut q_index = Vec::with_capacity(order.len());
        let (mut nv, mut nq) = (0, 0);
        let mut values = BTreeMap::new();
        for (i, &j) in order.iter().enumerate() {
            let body = i + 1;
            let joint = &robot.joints[j];
            let kind = joint.kind;
            let kq = if robot.cos_sin && joint.continuous { 2 } else { kind.nq() };
            v_index.push((kind.nv() > 0).then_some(nv + 1));
            q_index.push((kq > 0).then_some(nq + 1));
            nv += kind.nv();
            nq += kq;
            for (k, x) in joint.origin.xyz.iter().enumerate() {
                values.insert(format!("dpt[{}][{body}]", k + 1), *x);
            }
            let inertial = robot.links[joint.child].inertial;
            let (mass, com, inn) = inertial.map_or((0.0, [0.0; 3], [[0.0; 3]; 3]), |x| (x.mass, x.com, x.inertia));
            values.insert(format!("m[{body}]"), mass);
            for (k, x) in com.iter().enumerate() {
                values.insert(format!("l[{}][{body}]", k + 1), *x);
            }
            for (r, row) in inn.iter().enumerate() {
                for (c, x) in row.iter().enumerate().skip(r) {
                    values.insert(Layout::inertia_name(r, c, body), *x);
                }
            }
        }
        Layout { v_index, q_index, nv, nq, values }
    }

    /// `In[k][b]` for row `r`, column `c` (0-based) of body `b`'s tensor: the upper entry's name.
    pub fn inertia_name(r: usize, c: usize, body: usize) -> String {
        let (r, c) = (r.min(c), r.max(c));
        format!("In[{}][{body}]", 3 * r + c + 1)
    }

    /// The term of parameter `name`: a structural zero when its value is 0, else the input
    /// (folded by the builder under `--fold-params`).
    pub fn param(&self, b: &mut Builder, name: &str) -> Term {
        match self.values.get(name) {
            Some(&x) if x != 0.0 => b.input(name),
            _ => ZERO,
        }
    }

    /// The parameters that are inputs (non-zero values).
    pub fn nonzero(&self) -> BTreeMap<String, f64> {
        self.values.iter().filter(|(_, &x)| x != 0.0).map(|(k, &x)| (k.clone(), x)).collect()
    }
}

/// What the generator hands to the front end.
#[derive(Clone, Debug)]
pub struct Generated {
    /// The functions asked for, in [`FUNCTION_NAMES`] order (`invdyna`, then `dirdyna`).
    pub module: Module,
    /// Values of the parameters left as inputs (`None` when they were folded).
    pub params: Option<BTreeMap<String, f64>>,
    /// The first function (by name) whose factorisation of `M` met a pivot that folded to 0 (or
    /// a number whose reciprocal is not finite), and where: `M` is singular whatever the
    /// joint values, and that function holds the constant `inf`, which the verifier rejects.
    /// The front end reports it against the URDF (issue 47); `None` when every pivot is
    /// symbolic or non-zero.
    pub singular: Option<(String, sym::Singular)>,
}

/// What to generate ([`generate_with`]): which functions, folded or not, and by when.
#[derive(Clone, Debug, Default)]
pub struct Request {
    /// Fold every parameter into the equations (`--fold-params`).
    pub fold: bool,
    /// The gravity vector as numbers (m/s², world frame; `-gravity=x,y,z`) instead of the
    /// inputs `g[1..3]`.
    pub gravity: Option<[f64; 3]>,
    /// The functions to write, by name (`-function=NAME`); `None`: `invdyna` and `dirdyna`. Names
    /// the generator does not write are ignored (the driver reports them against
    /// [`FUNCTION_NAMES`] before loading).
    pub functions: Option<Vec<String>>,
    /// `-time-limit`: checked once per body of every recursion and per row of `M`'s outputs,
    /// and every 1024 steps of the passes over a whole function (counting its ops, compacting
    /// it; see [`Stopped`]).
    pub deadline: Option<Deadline>,
    /// Tests: the passes over a whole function stop at this tick of each
    /// ([`sym::Builder::tick_budget`]), whatever the clock says.
    pub tick_budget: Option<u64>,
    /// `--formulation`: the fewest ops (today's, the default) or the shortest dependence depth
    /// ([`depth`]).
    pub formulation: Formulation,
}

/// Which formulation the generator writes (`--formulation=ops|depth`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Formulation {
    /// The fewest ops: body-frame RNEA, CRBA, LᵀDL or ABA ([`rnea`], [`crba`], [`fordyna`]).
    #[default]
    Ops,
    /// The shortest critical path: the world-frame parallel prefixes of [`depth`] (`invdyna`,
    /// and `dirdyna`'s `M` and `c`; `fordyna` factorises those `M` and `c`).
    Depth,
}

impl Formulation {
    /// The command-line word: `ops`, `depth`.
    pub fn name(self) -> &'static str {
        match self {
            Formulation::Ops => "ops",
            Formulation::Depth => "depth",
        }
    }
}

impl Request {
    /// Whether function `name` is asked for.
    pub fn wants(&self, name: &str) -> bool {
        match &self.functions {
            Some(fs) => fs.iter().any(|f| f == name),
            None => FUNCTIONS.iter().any(|&(f, _, _, by_default)| f == name && by_default),
        }
    }
}

/// The generation stopped at the time limit ([`Request::deadline`]): nothing is returned,
/// since no pass can run on part of a function (the URDF front end reports it as an error;
/// issue 28 item 3).
#[derive(Clone, Debug, PartialEq)]
pub struct Stopped {
    /// The function being written (`dirdyna`).
    pub function: String,
    /// How far it got.
    pub at: Reached,
    /// The limit, seconds.
    pub seconds: f64,
}

/// Where a generation stopped ([`Stopped::at`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reached {
    /// A body of a recursion: `body` (1-based, in the numbering of the module doc) of `bodies`.
    Body {
        /// The body reached.
        body: usize,
        /// Bodies of the robot.
        bodies: usize,
    },
    /// A row of `M`: of its outputs (`dirdyna`) or of its factorisation and the substitutions
    /// (`fordyna`): `row` (1-based) of `rows` (`nq`).
    Row {
        /// The row reached.
        row: usize,
        /// Rows of `M`.
        rows: usize,
    },
    /// A pass over the whole function once its equations are written (issue 47): `counting its
    /// ops`, `counting its ops after atomise,cse` (to choose a formulation or body frames),
    /// `compacting it` (dropping what no output reads).
    Step(&'static str),
}

impl std::fmt::Display for Stopped {
    /// `time limit of 5 s reached while generating @dirdyna (body 1200 of 4000)`, or
    /// `(… (row 1200 of 4000 of M)`, or `(… (compacting it)`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "time limit of {} s reached while generating @{} ", self.seconds, self.function)?;
        match self.at {
            Reached::Body { body, bodies } => write!(f, "(body {body} of {bodies})"),
            Reached::Row { row, rows } => write!(f, "(row {row} of {rows} of M)"),
            Reached::Step(what) => write!(f, "({what})"),
        }
    }
}

/// Values and outputs from which a function is [large](drop_later).
const LARGE: usize = 100_000;

/// Drops a function no longer needed (a formulation or frame candidate that lost, a copy that
/// was counted). Under a time limit (`limited`) a large one is dropped on a thread of its own
/// (issue 47): freeing the millions of small allocations of a large generated function (names,
/// expression trees) takes about a second per gigabyte, which a run near its limit cannot
/// spend. Without one it is dropped here, as it is cheaper overall (freed by the thread that
/// allocated it: a 5,000-branch star's `dirdyna` took 1-2 s longer, of 15 s, with its losing
/// candidate freed on another thread). Small ones, and any when no thread can be started, are
/// dropped here.
pub(crate) fn drop_later(f: robovec_ir::Function, limited: bool) {
    if limited && f.values.len() + f.outputs.len() >= LARGE {
        // On failure the closure, and `f` with it, is dropped here.
        let _ = std::thread::Builder::new().name("robovec-drop".into()).spawn(move || drop(f));
    }
}

/// Gives up a function the time limit stopped (issue 47): a large one is leaked, not freed.
/// A generation stops at its deadline only for a run that then ends with an error (the URDF
/// front end fails the load, `robovec-opt` exits 1), and the system reclaims a process's
/// memory at once, where freeing it block by block took about a second per gigabyte (after a
/// 10 s limit on a 10,000-joint chain: 0.7 s of the 1 s grace, freed on another thread and
/// collected at exit). Small ones are dropped here.
pub(crate) fn abandon(f: robovec_ir::Function) {
    if f.values.len() + f.outputs.len() >= LARGE {
        std::mem::forget(f);
    }
}

/// The tree's parent array over the coordinates (Featherstone's `λ`, *Rigid Body Dynamics
/// Algorithms* §6.5): entry `i` (velocity coordinate `qd[i]`, 1-based; entry 0 unused) is the
/// coordinate of the nearest moving joint above joint `i`'s, 0 when there is none; a free
/// flyer's six coordinates are a chain (`λ[i + k] = i + k − 1`; its block of `M` is dense) and
/// the joints below it hang from its last. Coordinates are numbered depth first, so `λ[i] < i`.
/// Length `nv + 1`.
pub fn coordinate_parents(model: &Model, layout: &Layout) -> Vec<usize> {
    let robot = &model.robot;
    let order = robot.dfs_joints();
    let link_body = robot.link_bodies(&order);
    // The coordinate of the nearest moving joint at or above each body (0: none).
    let mut up = vec![0usize; order.len() + 1];
    let mut lambda = vec![0usize; layout.nv + 1];
    for (i, &j) in order.iter().enumerate() {
        let p = link_body[robot.joints[j].parent];
        up[i + 1] = match layout.v_index[i] {
            Some(qi) => {
                lambda[qi] = up[p];
                let last = qi + robot.joints[j].kind.nv() - 1;
                for (k, l) in lambda.iter_mut().enumerate().take(last + 1).skip(qi + 1) {
                    *l = k - 1;
                }
                last
            }
            None => up[p],
        };
    }
    lambda
}

/// Writes one function's equations and outputs into the builder; [`Stopped`] at the deadline
/// (the builder's, [`Builder::check`]).
type Writer = fn(&Model, &Layout, &mut Builder) -> Result<(), Stopped>;

/// The functions the generator writes, in module order (`-function=NAME` picks one), their
/// writers under [`Formulation::Ops`] and [`Formulation::Depth`], and whether it
/// writes them without `-function` (Robotran's pair, `invdyna` and `dirdyna`; `fordyna` only
/// when asked for): the one place that selects a formulation per function.
const FUNCTIONS: [(&str, Writer, Writer, bool); 3] = [
    ("invdyna", rnea::invdyna, depth::invdyna, true),
    ("dirdyna", dirdyna::dirdyna, depth::dirdyna, true),
    ("fordyna", fordyna::fordyna, depth::fordyna, false),
];

/// The writer of function entry `f` under `formulation`.
fn writer(f: &(&str, Writer, Writer, bool), formulation: Formulation) -> Writer {
    match formulation {
        Formulation::Ops => f.1,
        Formulation::Depth => f.2,
    }
}

/// The names of the functions the generator writes, in module order: `invdyna`, `dirdyna`,
/// `fordyna`.
pub const FUNCTION_NAMES: [&str; 3] = [FUNCTIONS[0].0, FUNCTIONS[1].0, FUNCTIONS[2].0];

/// One derivative function (issue 50 item 2): its name, the written function it differentiates
/// ([`FUNCTIONS`]), the inputs it differentiates with respect to, and its outputs: each
/// derivative family of [`robovec_ir::transform::diff`] renamed to Pinocchio's (`dQq_dq[i][j]` →
/// `dtau_dq[i][j]`); the function's own outputs are dropped.
type Derived = (&'static str, &'static str, &'static [&'static str], &'static [(&'static str, &'static str)]);

/// The derivative functions, written only when asked for (`-function=NAME`), after the others
/// in module order. Every matrix is `nv × nq`, row `i` the output, column `j` the coordinate
/// (row-major as Pinocchio's); with respect to `q` they are derivatives along robovec's
/// coordinates, which on a fixed base are Pinocchio's tangent space:
/// - `rnea_derivatives`: `invdyna` (`Qq` from `q`, `qd`, `qdd`) with respect to `q, qd`:
///   `dtau_dq` = ∂τ/∂q, `dtau_dv` = ∂τ/∂v (Pinocchio's `computeRNEADerivatives`);
/// - `aba_derivatives`: `fordyna` (`qdd` from `q`, `qd`, `Qq`) with respect to `q, qd, Qq`:
///   `ddq_dq`, `ddq_dv` and `Minv` = ∂q̈/∂τ (`computeABADerivatives`);
/// - `minv`: `fordyna` with respect to `Qq`: `Minv` (`computeMinverse`, both triangles).
const DERIVED: [Derived; 3] = [
    ("rnea_derivatives", "invdyna", &["q", "qd"], &[("dQq_dq", "dtau_dq"), ("dQq_dqd", "dtau_dv")]),
    (
        "aba_derivatives",
        "fordyna",
        &["q", "qd", "Qq"],
        &[("dqdd_dq", "ddq_dq"), ("dqdd_dqd", "ddq_dv"), ("dqdd_dQq", "Minv")],
    ),
    ("minv", "fordyna", &["Qq"], &[("dqdd_dQq", "Minv")]),
];

/// Every function name `-function=` accepts for a URDF: [`FUNCTION_NAMES`], then the
/// derivative functions (`rnea_derivatives`, `aba_derivatives`, `minv`).
pub const GENERATED_NAMES: [&str; 6] =
    [FUNCTIONS[0].0, FUNCTIONS[1].0, FUNCTIONS[2].0, DERIVED[0].0, DERIVED[1].0, DERIVED[2].0];

/// Derivative function `d` of `base` (parsed, as written): atomised, common subexpressions
/// merged, differentiated ([`robovec_ir::transform::diff::differentiate`], the mode by its
/// count of terms), its derivative outputs renamed and everything else dropped. `None` at the
/// ticker's stop. With `coords` (a free flyer, `(cos, sin)` pairs: [`tangent::coordinates`])
/// the rows with respect to `q` are mapped to Pinocchio's tangent space
/// ([`tangent::to_tangent`]). `layout` gives each family's length (`q`: `nq`; `qd`, `Qq`:
/// `nv`): a coordinate `base` does not read gets its column of zeros.
fn derive(
    base: &robovec_ir::Function,
    d: &Derived,
    layout: &Layout,
    coords: Option<&[tangent::Coordinate]>,
    ticker: &robovec_ir::time_limit::Ticker,
) -> Option<robovec_ir::Function> {
    use robovec_ir::transform::{atomise, cse, diff};
    let mut f = atomise::atomise_until(base, ticker)?;
    cse::cse_within(&mut f, ticker);
    // Every coordinate of the families differentiated is an input, read or not, so that each
    // matrix is whole (`nv × nv` along the tangent space, as Pinocchio's): a velocity no
    // equation reads (a joint under massless links only) still has its column, of zeros.
    for family in d.2 {
        let n = if *family == "q" { layout.nq } else { layout.nv };
        for k in 1..=n {
            let name = format!("{family}[{k}]");
            if f.lookup(&name).is_none() {
                f.add_input(name, robovec_ir::Span::DUMMY).expect("a free name");
            }
        }
    }
    let wrt: Vec<String> = d.2.iter().map(|s| s.to_string()).collect();
    match diff::differentiate(&mut f, &wrt, None, ticker) {
        Ok(_) => {}
        Err(diff::Failure::Stopped) => return None,
        // The generator writes no callback and no name of the form `d…_d…`.
        Err(diff::Failure::Message(m)) => unreachable!("{}: {m}", d.0),
    }
    if let Some(coords) = coords {
        let along_q: Vec<&str> = d.3.iter().map(|r| r.0).filter(|from| from.ends_with("_dq")).collect();
        tangent::to_tangent(&mut f, &along_q, coords);
    }
    let outputs = std::mem::take(&mut f.outputs);
    for o in outputs {
        let renamed = d.3.iter().find_map(|(from, to)| {
            o.name.strip_prefix(from).filter(|rest| rest.starts_with('[')).map(|rest| format!("{to}{rest}"))
        });
        if let Some(name) = renamed {
            f.set_output(name, o.value, o.span);
        }
    }
    let live = f.live_values(&[]);
    f.retain(|_, v| live[v.index()]);
    f.name = d.0.to_string();
    Some(f)
}

/// Generates `invdyna` and `dirdyna` for `model`; `fold` folds every parameter into the
/// equations. [`generate_with`] with every function and no time limit.
pub fn generate(model: &Model, fold: bool) -> Generated {
    let request = Request { fold, ..Request::default() };
    generate_with(model, &request).expect("no deadline, no stop")
}

/// Generates the functions `request` asks for. The robot is written in its own frames, in the
/// body frames of [`frames::reframe`], or in either with the origins of [`origins::slide`]:
/// whichever gives the functions asked for together the fewest ops (the first of equals in
/// that order; then the parameters of the links they move are in those frames). With every
/// function asked for, that is both functions together, as before `-function` reached the
/// generator; with one, its own count decides, so `-function=invdyna` may pick other frames
/// than a run of both (the same `Qq`; `-params-out` then has that run's parameters).
///
/// Cost: up to four generations of the functions asked for, each linear in the ops it writes
/// plus, for `dirdyna`, its `nq²` outputs (issue 28: no per-pair structure where `M` is
/// sparse).
///
/// # Errors
/// [`Stopped`] once `request.deadline` is reached (checked per body and per row of outputs).
pub fn generate_with(model: &Model, request: &Request) -> Result<Generated, Stopped> {
    // Links on fixed joints merged into their parents ([`lump`]); a stop names the body of the
    // robot as given.
    let (own, body_of) = match lump::contract_fixed(&model.robot) {
        Some((robot, body_of)) => (robot, Some(body_of)),
        None => (model.robot.clone(), None),
    };
    let bodies = model.robot.joints.len();
    let renumber = |mut stop: Stopped| {
        if let (Reached::Body { body, .. }, Some(map)) = (stop.at, &body_of) {
            stop.at = Reached::Body { body: map.get(body).copied().unwrap_or(body), bodies };
        }
        stop
    };
    let mut robots = vec![own];
    robots.extend(frames::reframe(&model.robot));
    for i in 0..robots.len() {
        robots.extend(origins::slide(&robots[i]));
    }
    // The ops of each candidate, counted at the deadline's pace (a 10,000-joint chain's
    // `fordyna` takes 0.8 s to count); under a limit the candidates that lose are dropped on a
    // thread of their own ([`drop_later`]), those a stop leaves are abandoned ([`abandon`]).
    let ticker = robovec_ir::time_limit::Ticker::new(request.deadline, request.tick_budget);
    let limited = request.deadline.is_some();
    let drop_all = |g: Generated| g.module.functions.into_iter().for_each(|f| drop_later(f, limited));
    let abandon_all = |g: Generated| g.module.functions.into_iter().for_each(abandon);
    let mut best: Option<(u64, Generated)> = None;
    for robot in robots {
        let g = match generate_in_frames(&Model { robot }, request) {
            Ok(g) => g,
            Err(stop) => {
                if let Some((_, g)) = best {
                    abandon_all(g);
                }
                return Err(renumber(stop));
            }
        };
        let mut n = 0;
        for f in &g.module.functions {
            match sym::op_counts_until(f, &ticker) {
                Some(c) => n += c.total,
                None => {
                    let stop = Stopped {
                        function: f.name.clone(),
                        at: Reached::Step("counting its ops"),
                        seconds: request.deadline.map_or(0.0, |d| d.seconds),
                    };
                    abandon_all(g);
                    if let Some((_, g)) = best {
                        abandon_all(g);
                    }
                    return Err(stop);
                }
            }
        }
        if best.as_ref().is_none_or(|(m, _)| n < *m) {
            if let Some((_, old)) = best.replace((n, g)) {
                drop_all(old);
            }
        } else {
            drop_all(g);
        }
    }
    Ok(best.expect("the robot's own frames are a candidate").1)
}

/// [`generate_with`] in the robot's own frames.
fn generate_in_frames(model: &Model, request: &Request) -> Result<Generated, Stopped> {
    let layout = Layout::of(&model.robot);
    let consts: FxHashMap<String, f64> =
        if request.fold { layout.nonzero().into_iter().collect() } else { FxHashMap::default() };
    // `-gravity`: the inputs `g[1..3]` folded to numbers as the parameters are.
    let consts: FxHashMap<String, f64> = consts
        .into_iter()
        .chain(request.gravity.iter().flat_map(|g| (0..3).map(|k| (format!("g[{}]", k + 1), g[k]))))
        .collect();
    let mut functions: Vec<robovec_ir::Function> = Vec::new();
    let mut singular = None;
    // One function written by `write` under `name` (parsed, compacted).
    let write_one = |name: &str, write: Writer| -> Result<(robovec_ir::Function, Option<sym::Singular>), Stopped> {
        let mut b = Builder::new(name, consts.clone());
        b.deadline = request.deadline;
        b.tick_budget = request.tick_budget;
        match write(model, &layout, &mut b) {
            Ok(()) => {
                let s = b.singular;
                b.finish_until().map(|f| (f, s))
            }
            Err(stop) => {
                abandon(b.f);
                Err(stop)
            }
        }
    };
    let derived: Vec<&Derived> = DERIVED.iter().filter(|d| request.wants(d.0)).collect();
    // The written functions the derivative functions asked for need, not kept themselves.
    let mut bases: Vec<robovec_ir::Function> = Vec::new();
    // `aba_derivatives` is also tried through `invdyna`'s partials ([`implicit`]).
    let needed = |f: &str| derived.iter().any(|d| d.1 == f || (d.0 == DERIVED[1].0 && f == FUNCTIONS[0].0));
    for f in FUNCTIONS.iter().filter(|f| request.wants(f.0) || needed(f.0)) {
        let (name, write) = (f.0, writer(f, request.formulation));
        let written = match write_one(name, write) {
            Ok((f, s)) => {
                if singular.is_none() {
                    singular = s.map(|s| (name.to_string(), s));
                }
                Ok(f)
            }
            Err(stop) => Err(stop),
        };
        match written {
            Ok(f) if request.wants(name) => functions.push(f),
            Ok(f) => bases.push(f),
            Err(stop) => {
                functions.into_iter().chain(bases).for_each(abandon);
                return Err(stop);
            }
        }
    }
    let ticker = robovec_ir::time_limit::Ticker::new(request.deadline, request.tick_budget);
    let coords = tangent::coordinates(&model.robot, &layout);
    let coords = coords.as_deref();
    // Each derivative function by its formulations, the fewer ops after `atomise,cse` kept
    // (`diff`'s on a tie): `diff` on the written function ([`derive`]); for `rnea_derivatives`
    // the analytical recursions ([`rnea_derivatives`]); for `aba_derivatives` −M⁻¹·∂τ_ID
    // ([`implicit`], from the `rnea_derivatives` kept); for `minv` the inverted `LᵀDL` factors
    // ([`fordyna::minv`]). `None`: the ticker stopped.
    let fewer = |a: Option<robovec_ir::Function>, b: Option<robovec_ir::Function>| match (a, b) {
        (Some(a), Some(b)) if b.op_counts().total < a.op_counts().total => Some(b),
        (a, _) => a,
    };
    let find = |fs: &[robovec_ir::Function], bs: &[robovec_ir::Function], name: &str| -> robovec_ir::Function {
        fs.iter().chain(bs).find(|f| f.name == name).expect("written above").clone()
    };
    let mut rnea_kept: Option<robovec_ir::Function> = None;
    for d in derived {
        let base = find(&functions, &bases, d.1);
        let best = |f: Option<robovec_ir::Function>| -> Result<Option<robovec_ir::Function>, Stopped> {
            let Some(f) = f else { return Ok(None) };
            let other = match d.0 {
                "rnea_derivatives" => {
                    implicit::compact(&write_one(d.0, rnea_derivatives::rnea_derivatives)?.0, &ticker)
                }
                "aba_derivatives" => {
                    let partials = match rnea_kept.clone() {
                        Some(p) => Some(p),
                        None => {
                            let by_diff = derive(
                                &find(&functions, &bases, FUNCTIONS[0].0),
                                &DERIVED[0],
                                &layout,
                                coords,
                                &ticker,
                            );
                            let analytical = write_one(DERIVED[0].0, rnea_derivatives::rnea_derivatives)?.0;
                            fewer(by_diff, implicit::compact(&analytical, &ticker))
                        }
                    };
                    // `fordyna` in the body frames, or in the analytical partials' world frame
                    // (their kinematics and inertias then shared): the fewer ops.
                    let solved = write_one(d.0, fordyna::fordyna_and_inverse)?.0;
                    let world = write_one(d.0, fordyna::world_fordyna_and_inverse)?.0;
                    partials.and_then(|p| {
                        fewer(
                            implicit::aba_derivatives(&p, &solved, &ticker),
                            implicit::aba_derivatives(&p, &world, &ticker),
                        )
                    })
                }
                "minv" => implicit::compact(&write_one(d.0, fordyna::minv)?.0, &ticker),
                _ => None,
            };
            Ok(fewer(Some(f), other))
        };
        let written = match best(derive(&base, d, &layout, coords, &ticker)) {
            Ok(w) => w,
            Err(stop) => {
                functions.into_iter().chain(bases).for_each(abandon);
                return Err(stop);
            }
        };
        match written {
            Some(f) => {
                if d.0 == DERIVED[0].0 {
                    rnea_kept = Some(f.clone());
                }
                functions.push(f);
            }
            None => {
                functions.into_iter().chain(bases).for_each(abandon);
                return Err(Stopped {
                    function: d.0.to_string(),
                    at: Reached::Step("differentiating"),
                    seconds: request.deadline.map_or(0.0, |d| d.seconds),
                });
            }
        }
    }
    bases.into_iter().for_each(|f| drop_later(f, request.deadline.is_some()));
    let params = (!request.fold).then(|| {
        // Only the parameters some function reads.
        layout.nonzero().into_iter().filter(|(k, _)| functions.iter().any(|f| f.lookup(k).is_some())).collect()
    });
    Ok(Generated { module: Module { functions }, params, singular })
}
