//! `abi=robotran`: a drop-in replacement of the Robotran function the IR came from.
use robovec_ir::Function;

use super::CodegenC;
use crate::codegen::Interface;
use crate::PassError;

/// The Robotran symbol of `f` (`dirdyna` → `mbs_dirdyna`).
///
/// # Errors
/// [`PassError::Failed`] for a function kind with no known Robotran signature.
pub fn symbol(f: &Function) -> Result<String, PassError> {
    Err(unknown(f))
}

fn unknown(f: &Function) -> PassError {
    PassError::Failed { pass: "codegen".into(), message: format!("@{}: abi=robotran is not written yet", f.name) }
}

/// The drop-in definition of `f`.
///
/// # Errors
/// [`PassError::Failed`] for a function kind with no known Robotran signature.
pub fn function(_o: &CodegenC, f: &Function, _symbol: &str) -> Result<(String, String, Interface), PassError> {
    Err(unknown(f))
}
