//! [`Params`]: the parameters of one pipeline element checked against their declarations, and
//! the typed getters that read each value with its declared default and range.

use robovec_ir::analysis::Latencies;

use super::{one_of, LatencyOverride, Member, ParamInfo, ParamKind, Word};
use crate::{Pass, PassError, PassInfo};

/// Checked parameters of one pipeline element: `(name, value)` pairs, each name declared by the
/// pass or by its selected family member.
#[derive(Clone, Debug)]
pub struct Params {
    pass: &'static str,
    decls: &'static [ParamInfo],
    member: Option<&'static Member>,
    values: Vec<(String, String)>,
}

/// The member of `info`'s family selected by `word` (`None`: the default one); `None` when
/// `info` is no family.
///
/// # Errors
/// [`PassError::BadParameter`] when `word` names no member.
fn selected(info: &'static PassInfo, word: Option<&str>) -> Result<Option<&'static Member>, PassError> {
    let Some(sel) = info.params.iter().find(|p| matches!(p.kind, ParamKind::Selector { .. })) else {
        return Ok(None);
    };
    let ParamKind::Selector { members, default } = sel.kind else { unreachable!("found as a selector") };
    let word = word.unwrap_or(default);
    match members.iter().find(|m| m.name == word) {
        Some(m) => Ok(Some(m)),
        None => Err(PassError::BadParameter {
            pass: info.name.into(),
            message: format!(
                "parameter `{}` must be {}, found `{word}`",
                sel.name,
                one_of(members.iter().map(|m| m.name.to_string()))
            ),
        }),
    }
}

impl Params {
    /// Checks raw `(key, value)` pairs against `info` (and, for a pass family, against the
    /// selected member): unknown or repeated keys are errors.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] listing the valid parameters; for a family, a parameter of
    /// another member names the member it belongs to; a selector naming no member lists the
    /// members.
    pub fn check(info: &'static PassInfo, raw: &[(String, Option<String>)]) -> Result<Params, PassError> {
        let bad = |message: String| PassError::BadParameter { pass: info.name.into(), message };
        let selector = info.params.iter().find(|p| matches!(p.kind, ParamKind::Selector { .. }));
        // A bare word naming a member of the pass's selector (`codegen<c>`): `selector=word`.
        let raw: Vec<(&str, Option<&str>)> = raw
            .iter()
            .map(|(k, v)| match selector {
                Some(s)
                    if v.is_none()
                        && s.members().iter().any(|m| m.name == k)
                        && !info.params.iter().any(|q| q.name == k) =>
                {
                    (s.name, Some(k.as_str()))
                }
                _ => (k.as_str(), v.as_deref()),
            })
            .collect();
        let member =
            selected(info, selector.and_then(|s| raw.iter().find(|(k, _)| *k == s.name)).and_then(|(_, v)| *v))?;
        let own = member.map_or(&[][..], |m| m.params);
        let valid = || {
            let names: Vec<&str> = info.params.iter().chain(own).map(|p| p.name).collect();
            if names.is_empty() {
                "it takes no parameters".to_string()
            } else {
                format!("valid: {}", names.join(", "))
            }
        };
        let mut values: Vec<(String, String)> = Vec::new();
        for (k, v) in raw {
            if !info.params.iter().chain(own).any(|p| p.name == k) {
                let owner = selector
                    .and_then(|s| s.members().iter().find(|m| m.params.iter().any(|p| p.name == k)).map(|m| (s, m)));
                return Err(bad(match (owner, member) {
                    (Some((s, m)), Some(selected)) => format!(
                        "parameter `{k}` belongs to {} `{}`, not `{}`",
                        s.name.replace('-', " "),
                        m.name,
                        selected.name
                    ),
                    _ => format!("unknown parameter `{k}` ({})", valid()),
                }));
            }
            if values.iter().any(|(x, _)| x == k) {
                return Err(bad(format!("parameter `{k}` given twice")));
            }
            let Some(v) = v else {
                return Err(bad(format!("parameter `{k}` needs a value (`{k}=…`)")));
            };
            values.push((k.to_string(), v.to_string()));
        }
        Ok(Params { pass: info.name, decls: info.params, member, values })
    }

    /// No parameter given: every getter returns the declared default (a family's default
    /// member).
    pub fn defaults(info: &'static PassInfo) -> Params {
        let member = selected(info, None).expect("a selector's default names one of its members");
        Params { pass: info.name, decls: info.params, member, values: Vec::new() }
    }

    /// The selected member of a pass family (`None` for a pass that is no family).
    pub fn member(&self) -> Option<&'static Member> {
        self.member
    }

    /// The declared properties of the pass these parameters build: the selected member's for
    /// a family, else `info`'s own (`info`: the pass they were checked against).
    pub fn props(&self, info: &PassInfo) -> crate::Props {
        self.member.map_or(info.props, |m| m.props)
    }

    /// Builds the selected member of a pass family: the `build` of a family's [`PassInfo`].
    ///
    /// # Errors
    /// What the member's [`Member::build`] returns.
    pub fn build_member(&self) -> Result<Box<dyn Pass>, PassError> {
        match self.member {
            Some(m) => (m.build)(self),
            None => panic!("pass `{}` builds a family member but declares no selector", self.pass),
        }
    }

    /// The declarations of this element: the pass's, then the selected member's.
    fn declared(&self) -> impl Iterator<Item = &'static ParamInfo> {
        self.decls.iter().chain(self.member.map_or(&[][..], |m| m.params))
    }

    /// The raw value of `key`, if given.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.values.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }

    /// The declaration of `key`; a getter asking for an undeclared key is a bug of the pass.
    fn decl(&self, key: &str) -> ParamKind {
        match self.declared().find(|d| d.name == key) {
            Some(d) => d.kind,
            None => panic!("pass `{}` reads undeclared parameter `{key}`", self.pass),
        }
    }

    fn bad(&self, key: &str, expected: String, found: &str) -> PassError {
        PassError::BadParameter {
            pass: self.pass.into(),
            message: format!("parameter `{key}` must be {expected}, found `{found}`"),
        }
    }

    /// The latencies `lat-add`, `lat-mul`, `lat-div`, `lat-call` (cycles), each from its
    /// declaration ([`super::LAT_ADD`]…); an undeclared one takes SPEC §1's value.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when one is out of range.
    pub fn latencies(&self) -> Result<Latencies, PassError> {
        let d = Latencies::default();
        let get = |key: &str, default: u32| {
            if self.declared().any(|p| p.name == key) {
                self.u32(key)
            } else {
                Ok(default)
            }
        };
        Ok(Latencies {
            add: get("lat-add", d.add)?,
            mul: get("lat-mul", d.mul)?,
            div: get("lat-div", d.div)?,
            call: get("lat-call", d.call)?,
        })
    }

    /// The latencies given explicitly on this pass (`lat-add=6` → `add: Some(6)`); the others
    /// come from the pipeline's current latencies (the target's, `-target`), see
    /// [`crate::PassContext::latencies_for`].
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when one is out of range.
    pub fn latency_override(&self) -> Result<LatencyOverride, PassError> {
        let get = |key: &str| -> Result<Option<u32>, PassError> {
            if self.declared().any(|p| p.name == key) && self.get(key).is_some() {
                self.u32(key).map(Some)
            } else {
                Ok(None)
            }
        };
        Ok(LatencyOverride { add: get("lat-add")?, mul: get("lat-mul")?, div: get("lat-div")?, call: get("lat-call")? })
    }

    /// A `U32` parameter when given explicitly (`None`: not given, the caller takes the
    /// target's value).
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when the value is out of range.
    pub fn u32_given(&self, key: &str) -> Result<Option<u32>, PassError> {
        match (self.get(key), self.decl(key)) {
            (Some(v), ParamKind::U32Opt { min, max }) => match v.parse::<u32>() {
                Ok(x) if (min..=max).contains(&x) => Ok(Some(x)),
                _ => Err(self.bad(key, format!("an integer in {min}..={max}"), v)),
            },
            (Some(_), _) => self.u32(key).map(Some),
            (None, _) => Ok(None),
        }
    }

    /// A `U32` (or `U32Or`, `U32Target`, `U32Set`) parameter: its value, or its declared
    /// default.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when the value is not an integer in the declared range (or
    /// set).
    pub fn u32(&self, key: &str) -> Result<u32, PassError> {
        if let ParamKind::U32Set { default, allowed } = self.decl(key) {
            return match self.get(key) {
                None => Ok(default),
                Some(v) => match v.parse::<u32>() {
                    Ok(x) if allowed.contains(&x) => Ok(x),
                    _ => Err(self.bad(key, one_of(allowed.iter().map(u32::to_string)), v)),
                },
            };
        }
        let (default, min, max) = match self.decl(key) {
            ParamKind::U32 { default, min, max } => (default, min, max),
            ParamKind::U32Target { builtin, min, max } => (builtin, min, max),
            ParamKind::U32Or { fallback, min, max } => (self.u32(fallback)?, min, max),
            k => panic!("parameter `{key}` of `{}` is {k:?}, not an integer", self.pass),
        };
        match self.get(key) {
            None => Ok(default),
            Some(v) => match v.parse::<u32>() {
                Ok(x) if (min..=max).contains(&x) => Ok(x),
                _ => Err(self.bad(key, format!("an integer in {min}..={max}"), v)),
            },
        }
    }

    /// A `U64` parameter: its value, or its declared default.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when the value is not an integer in the declared range.
    pub fn u64(&self, key: &str) -> Result<u64, PassError> {
        let ParamKind::U64 { default, min, max } = self.decl(key) else {
            panic!("parameter `{key}` of `{}` is not a u64", self.pass)
        };
        match self.get(key) {
            None => Ok(default),
            Some(v) => match v.parse::<u64>() {
                Ok(x) if (min..=max).contains(&x) => Ok(x),
                _ => Err(self.bad(key, format!("an integer in {min}..={max}"), v)),
            },
        }
    }

    /// An `F64` parameter: its value, or its declared default.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when the value is not a number in the declared range.
    pub fn f64(&self, key: &str) -> Result<f64, PassError> {
        let ParamKind::F64 { default, min, max } = self.decl(key) else {
            panic!("parameter `{key}` of `{}` is not a number", self.pass)
        };
        match self.get(key) {
            None => Ok(default),
            Some(v) => match v.parse::<f64>() {
                Ok(x) if (min..=max).contains(&x) => Ok(x),
                _ => Err(self.bad(key, format!("a number in {min}..={max}"), v)),
            },
        }
    }

    /// An `F64OrPath` parameter: the number given (or the declared default), or the file
    /// named by a value that does not read as a number.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] for a number outside the declared range or an empty value.
    pub fn f64_or_path(&self, key: &str) -> Result<NumberOrPath, PassError> {
        let ParamKind::F64OrPath { default, min, max } = self.decl(key) else {
            panic!("parameter `{key}` of `{}` is not a number or a path", self.pass)
        };
        match self.get(key) {
            None => Ok(NumberOrPath::Number(default)),
            Some("") => Err(self.bad(key, format!("a number in {min}..={max} or a file"), "")),
            Some(v) => match v.parse::<f64>() {
                Ok(x) if (min..=max).contains(&x) => Ok(NumberOrPath::Number(x)),
                Ok(_) => Err(self.bad(key, format!("a number in {min}..={max} or a file"), v)),
                Err(_) => Ok(NumberOrPath::Path(v.to_string())),
            },
        }
    }

    /// A `Choice` parameter: the word given, or the declared default.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when the word is not one of the choices.
    pub fn choice(&self, key: &str) -> Result<&'static str, PassError> {
        let ParamKind::Choice { choices, default } = self.decl(key) else {
            panic!("parameter `{key}` of `{}` is not a choice", self.pass)
        };
        match self.get(key) {
            None => Ok(default),
            Some(v) => choices
                .iter()
                .find(|c| **c == v)
                .copied()
                .ok_or_else(|| self.bad(key, one_of(choices.iter().map(|c| c.to_string())), v)),
        }
    }

    /// A `Choice` parameter declared with the words of `T` (`choices: Abi::WORDS`), as `T`.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when the word is not one of the choices.
    pub fn word<T: Word>(&self, key: &str) -> Result<T, PassError> {
        let ParamKind::Choice { choices, .. } = self.decl(key) else {
            panic!("parameter `{key}` of `{}` is not a choice", self.pass)
        };
        assert_eq!(
            choices,
            T::WORDS,
            "parameter `{key}` of `{}` is declared with other words than its type's",
            self.pass
        );
        let w = self.choice(key)?;
        Ok(T::from_word(w).unwrap_or_else(|| unreachable!("`{w}` is one of the declared words")))
    }

    /// A `Flag` parameter: `on`/`true`/`1` or `off`/`false`/`0`, or the declared default.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] for any other word.
    pub fn flag(&self, key: &str) -> Result<bool, PassError> {
        let ParamKind::Flag { default } = self.decl(key) else {
            panic!("parameter `{key}` of `{}` is not a flag", self.pass)
        };
        match self.get(key) {
            None => Ok(default),
            Some("on" | "true" | "1") => Ok(true),
            Some("off" | "false" | "0") => Ok(false),
            Some(v) => Err(self.bad(key, "`on` or `off`".into(), v)),
        }
    }

    /// A `Path` or `OutputFolder` parameter: the path given, if any.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when it is empty.
    pub fn path(&self, key: &str) -> Result<Option<String>, PassError> {
        let (ParamKind::Path | ParamKind::OutputFolder) = self.decl(key) else {
            panic!("parameter `{key}` of `{}` is not a path", self.pass)
        };
        match self.get(key) {
            None => Ok(None),
            Some("") => Err(PassError::BadParameter {
                pass: self.pass.into(),
                message: format!("parameter `{key}` needs a file name (`{key}=PATH`)"),
            }),
            Some(v) => Ok(Some(v.to_string())),
        }
    }

    /// A `U32List` parameter: the integers given, or the declared default list.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when the list is empty or an element is out of range.
    pub fn u32_list(&self, key: &str) -> Result<Vec<u32>, PassError> {
        let ParamKind::U32List { default, min, max } = self.decl(key) else {
            panic!("parameter `{key}` of `{}` is not a list of integers", self.pass)
        };
        let text = self.get(key).unwrap_or(default);
        let ns: Result<Vec<u32>, _> = text.split(',').map(|x| x.trim().parse::<u32>()).collect();
        match ns {
            Ok(ns) if !ns.is_empty() && ns.iter().all(|n| (min..=max).contains(n)) => Ok(ns),
            _ => Err(self.bad(key, format!("a comma-separated list of integers in {min}..={max}"), text)),
        }
    }

    /// A `Names` parameter: the names given (trimmed, empty ones dropped), or `None` (all).
    ///
    /// # Errors
    /// [`PassError::BadParameter`] when no name is left.
    pub fn names(&self, key: &str) -> Result<Option<Vec<String>>, PassError> {
        let ParamKind::Names = self.decl(key) else {
            panic!("parameter `{key}` of `{}` is not a name list", self.pass)
        };
        match self.get(key) {
            None => Ok(None),
            Some(v) => {
                let names: Vec<String> = v.split(',').map(|x| x.trim().to_string()).filter(|x| !x.is_empty()).collect();
                if names.is_empty() {
                    Err(self.bad(key, "a comma-separated list of names".into(), v))
                } else {
                    Ok(Some(names))
                }
            }
        }
    }
}

/// The value of an `F64OrPath` parameter ([`Params::f64_or_path`]).
#[derive(Clone, Debug, PartialEq)]
pub enum NumberOrPath {
    /// A number in the declared range.
    Number(f64),
    /// A file the pass reads.
    Path(String),
}
