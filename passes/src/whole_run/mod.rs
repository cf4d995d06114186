//! Work over a whole run rather than passes of a pipeline: `-pareto` (several pipelines on
//! the same input, speed against error) and `-check` (the final IR against the input's error
//! budget). They return artifacts or lines like passes do, and fail with a [`Failure`] whose
//! text is ready for stderr. (`robovec-gen --study`, the thesis's study over generated robots,
//! is another thing: `robovec`'s `study`.)

pub mod check;
pub mod pareto;

/// Why work over whole runs failed (`-pareto`, `-check`, a case of `robovec-gen --study`); the
/// text is one or more lines ready for stderr (ending in a newline).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Failure {
    /// Bad usage (exit status 2): a pipeline that does not parse, an unknown pass.
    Usage(String),
    /// Bad input (exit status 1): a pipeline that fails on the input, a violated error budget.
    Input(String),
}
