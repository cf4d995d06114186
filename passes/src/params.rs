//! Pass parameters: `pass<k=v;flag;no-flag>` (LLVM `PassBuilder` syntax), declared per pass
//! and checked before the pass is built.

use crate::{PassError, PassInfo};

/// A declared parameter of a pass.
#[derive(Clone, Copy, Debug)]
pub struct ParamInfo {
    /// Name (`lat-add`).
    pub name: &'static str,
    /// Default value as text (`12`), shown by `--print-passes`.
    pub default: &'static str,
    /// What it means, with its unit.
    pub doc: &'static str,
}

/// Checked parameters of one pipeline element: `(name, value)` pairs, each name declared.
#[derive(Clone, Debug, Default)]
pub struct Params {
    pass: &'static str,
    values: Vec<(String, String)>,
}

impl Params {
    /// Checks raw `(key, value)` pairs against `info`: unknown or repeated keys are errors.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] listing the valid parameters.
    pub fn check(info: &PassInfo, raw: &[(String, Option<String>)]) -> Result<Params, PassError> {
        let valid = || {
            if info.params.is_empty() {
                "it takes no parameters".to_string()
            } else {
                format!("valid: {}", info.params.iter().map(|p| p.name).collect::<Vec<_>>().join(", "))
            }
        };
        let mut values: Vec<(String, String)> = Vec::new();
        for (k, v) in raw {
            if !info.params.iter().any(|p| p.name == k) {
                return Err(PassError::BadParameter {
                    pass: info.name.into(),
                    message: format!("unknown parameter `{k}` ({})", valid()),
                });
            }
            if values.iter().any(|(x, _)| x == k) {
                return Err(PassError::BadParameter {
                    pass: info.name.into(),
                    message: format!("parameter `{k}` given twice"),
                });
            }
            let Some(v) = v else {
                return Err(PassError::BadParameter {
                    pass: info.name.into(),
                    message: format!("parameter `{k}` needs a value (`{k}=…`)"),
                });
            };
            values.push((k.clone(), v.clone()));
        }
        Ok(Params { pass: info.name, values })
    }

    /// The raw value of `key`, if given.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.values.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }

    /// The latencies `lat-add`, `lat-mul`, `lat-div`, `lat-call` (cycles, 1..=10000), each
    /// defaulting to SPEC §1's value.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when one is not such an integer.
    pub fn latencies(&self) -> Result<robovec_ir::analysis::Latencies, PassError> {
        let d = robovec_ir::analysis::Latencies::default();
        Ok(robovec_ir::analysis::Latencies {
            add: self.u32_in("lat-add", d.add, 1, 10_000)?,
            mul: self.u32_in("lat-mul", d.mul, 1, 10_000)?,
            div: self.u32_in("lat-div", d.div, 1, 10_000)?,
            call: self.u32_in("lat-call", d.call, 1, 10_000)?,
        })
    }

    /// `key` as a `u32` in `min..=max`, or `default`.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when the value is not such an integer.
    pub fn u32_in(&self, key: &str, default: u32, min: u32, max: u32) -> Result<u32, PassError> {
        match self.get(key) {
            None => Ok(default),
            Some(v) => match v.parse::<u32>() {
                Ok(x) if (min..=max).contains(&x) => Ok(x),
                _ => Err(PassError::BadParameter {
                    pass: self.pass.into(),
                    message: format!("parameter `{key}` must be an integer in {min}..={max}, found `{v}`"),
                }),
            },
        }
    }
}
