//! Pass parameters: `pass<k=v;flag;no-flag>` (LLVM `PassBuilder` syntax), declared per pass
//! and checked before the pass is built.
//!
//! Each parameter is declared once, as a [`ParamInfo`] whose [`ParamKind`] holds its type,
//! default and range (issue 10 item 5). The typed getters of [`Params`] (`u32`, `f64`,
//! `choice`, `flag`…) take only the key and read default and range from that declaration, and
//! `--print-passes` prints them from it, so the parser, the defaults and the listing cannot
//! disagree.
//!
//! A pass family (`codegen<c;…>`, `codegen<fpga;…>`) declares a [`ParamKind::Selector`] whose
//! [`Member`]s each declare their own parameters: the parameters of `codegen<c;…>` are the
//! selector and the C back end's, and a parameter of another member is refused naming the
//! member it belongs to. A parameter whose values are words (`abi=plain|robotran`) is read as
//! an enum declared with `word_enum!` (this module), whose words are the
//! declaration's choices.

use robovec_ir::analysis::Latencies;

use crate::{Pass, PassError, PassInfo};

/// The type, default and accepted range of a parameter.
#[derive(Clone, Copy, Debug)]
pub enum ParamKind {
    /// An integer in `min..=max`.
    U32 {
        /// Value when the parameter is not given.
        default: u32,
        /// Smallest accepted value.
        min: u32,
        /// Largest accepted value.
        max: u32,
    },
    /// An integer in `min..=max` whose default is the value of parameter `fallback` (a `U32`).
    U32Or {
        /// The parameter whose value is the default.
        fallback: &'static str,
        /// Smallest accepted value.
        min: u32,
        /// Largest accepted value.
        max: u32,
    },
    /// An integer in `min..=max` whose default is the target's (`-target`): a latency or the
    /// write ports. [`Params::u32`] returns `builtin` (the `de10-nano` value) when it is not
    /// given; passes read the target's through [`Params::latency_override`] /
    /// [`Params::u32_given`] and the pass context.
    U32Target {
        /// The built-in `de10-nano` target's value.
        builtin: u32,
        /// Smallest accepted value.
        min: u32,
        /// Largest accepted value.
        max: u32,
    },
    /// A 64-bit integer in `min..=max`.
    U64 {
        /// Value when the parameter is not given.
        default: u64,
        /// Smallest accepted value.
        min: u64,
        /// Largest accepted value.
        max: u64,
    },
    /// A finite number in `min..=max`.
    F64 {
        /// Value when the parameter is not given.
        default: f64,
        /// Smallest accepted value.
        min: f64,
        /// Largest accepted value.
        max: f64,
    },
    /// One word of `choices`.
    Choice {
        /// The accepted words.
        choices: &'static [&'static str],
        /// The word used when the parameter is not given (one of `choices`).
        default: &'static str,
    },
    /// `on` or `off` (also `true`/`false`, `1`/`0`).
    Flag {
        /// Value when the parameter is not given.
        default: bool,
    },
    /// A file the pass reads; nothing when not given. `robovec-opt` checks it can be opened
    /// before any work.
    Path,
    /// A folder the pass writes files into; nothing when not given. `robovec-opt` checks it
    /// under its output policy before any work, and creates it with the run's other outputs.
    OutputFolder,
    /// A comma-separated, non-empty list of integers, each in `min..=max`.
    U32List {
        /// The list used when the parameter is not given (comma-separated).
        default: &'static str,
        /// Smallest accepted element.
        min: u32,
        /// Largest accepted element.
        max: u32,
    },
    /// A comma-separated, non-empty list of names; `all` (nothing selected) when not given.
    Names,
    /// An integer of the set `allowed` (`batch=1|2|4|8|16`).
    U32Set {
        /// Value when the parameter is not given (one of `allowed`).
        default: u32,
        /// The accepted values, in the order `--print-passes` lists them.
        allowed: &'static [u32],
    },
    /// The member of a pass family (`codegen<c;…>`, `codegen<fpga;…>`): the name of one of
    /// `members`, which may also be given bare, without its key (`codegen<c>` is
    /// `codegen<back-end=c>`; at most one selector per pass). The selected member's parameters
    /// are the pass's too; a parameter of another member is refused naming its member, in the
    /// words of the selector's name (`back-end`: "belongs to back end `fpga`").
    Selector {
        /// The members, in `--print-passes` order.
        members: &'static [Member],
        /// The member used when the parameter is not given (the name of one of `members`).
        default: &'static str,
    },
}

/// A member of a pass family: a back end of `codegen` (`codegen<c;…>`). Its parameters are
/// declared here, once: [`Params::check`] accepts them only when this member is selected, the
/// member's [`Member::build`] reads them, and `--print-passes` lists them under the member.
#[derive(Clone, Copy, Debug)]
pub struct Member {
    /// The word that selects it (`c`).
    pub name: &'static str,
    /// One line: what it makes.
    pub doc: &'static str,
    /// Its own parameters (beside the family's selector).
    pub params: &'static [ParamInfo],
    /// Builds the pass from checked parameters (the selector's and this member's).
    ///
    /// # Errors
    /// [`PassError::BadParameter`] for options that cannot go together.
    pub build: fn(&Params) -> Result<Box<dyn Pass>, PassError>,
}

/// A parameter value that is one word of a fixed set (`abi=plain|robotran`), as declared by
/// `word_enum!` (this module).
pub trait Word: Copy + 'static {
    /// Every word, in the order of the variants: the choices of the parameter's declaration.
    const WORDS: &'static [&'static str];
    /// The value's word, as written in a pipeline and in the report.
    fn as_str(self) -> &'static str;
    /// The value written `word`, if any.
    fn from_word(word: &str) -> Option<Self>;
}

/// Declares an enum whose values are the words of a parameter: each variant is written
/// `Variant = "word"`. The enum gets `WORDS` (every word, in variant order: what the
/// parameter's [`ParamKind::Choice`] declares as `choices`), `const fn as_str`, `from_word`,
/// [`Word`] (for [`Params::word`]), and `Serialize` as its word (the report writes `"robotran"`).
macro_rules! word_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident {
            $($(#[$vmeta:meta])* $variant:ident = $word:literal,)+
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum $name {
            $($(#[$vmeta])* $variant,)+
        }

        impl $name {
            /// Every word, in the variants' order: the parameter's choices.
            pub const WORDS: &'static [&'static str] = &[$($word),+];

            /// The value's word, as written in a pipeline and in the report.
            pub const fn as_str(self) -> &'static str {
                match self {
                    $($name::$variant => $word,)+
                }
            }

            /// The value written `word`, if any.
            pub fn from_word(word: &str) -> Option<$name> {
                match word {
                    $($word => Some($name::$variant),)+
                    _ => None,
                }
            }
        }

        impl $crate::params::Word for $name {
            const WORDS: &'static [&'static str] = $name::WORDS;

            fn as_str(self) -> &'static str {
                $name::as_str(self)
            }

            fn from_word(word: &str) -> Option<$name> {
                $name::from_word(word)
            }
        }

        impl serde::Serialize for $name {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(self.as_str())
            }
        }
    };
}
pub(crate) use word_enum;

/// The expected-value text of a parameter with a few accepted words: `` `a` or `b` ``,
/// `` one of `a`, `b`, `c` ``.
fn one_of(words: impl Iterator<Item = String>) -> String {
    let quoted: Vec<String> = words.map(|c| format!("`{c}`")).collect();
    match quoted.as_slice() {
        [a, b] => format!("{a} or {b}"),
        q => format!("one of {}", q.join(", ")),
    }
}

fn joined(xs: impl Iterator<Item = String>, sep: &str) -> String {
    xs.collect::<Vec<_>>().join(sep)
}

/// A declared parameter of a pass: name, type with default and range, and doc.
#[derive(Clone, Copy, Debug)]
pub struct ParamInfo {
    /// Name (`lat-add`).
    pub name: &'static str,
    /// Type, default and range.
    pub kind: ParamKind,
    /// What it means, with its unit.
    pub doc: &'static str,
}

impl ParamInfo {
    /// The default as `--print-passes` shows it: a value accepted by the parameter when it
    /// has a literal default (`6`, `on`, `1,2,4`), else a word in words (`none`, `all`, the
    /// name of the parameter it defaults to).
    pub fn default_text(&self) -> String {
        match self.kind {
            ParamKind::U32 { default, .. } => default.to_string(),
            ParamKind::U32Or { fallback, .. } => format!("`{fallback}`"),
            ParamKind::U32Target { builtin, .. } => format!("the target's, de10-nano {builtin}"),
            ParamKind::U64 { default, .. } => default.to_string(),
            ParamKind::F64 { default, .. } => format!("{default}"),
            ParamKind::Choice { default, .. } | ParamKind::Selector { default, .. } => default.to_string(),
            ParamKind::Flag { default } => if default { "on" } else { "off" }.to_string(),
            ParamKind::Path | ParamKind::OutputFolder => "none".to_string(),
            ParamKind::U32List { default, .. } => default.to_string(),
            ParamKind::Names => "all".to_string(),
            ParamKind::U32Set { default, .. } => default.to_string(),
        }
    }

    /// True when [`ParamInfo::default_text`] is a value the parameter accepts (giving it
    /// explicitly changes nothing).
    pub fn default_is_literal(&self) -> bool {
        !matches!(
            self.kind,
            ParamKind::U32Or { .. }
                | ParamKind::U32Target { .. }
                | ParamKind::Path
                | ParamKind::OutputFolder
                | ParamKind::Names
        )
    }

    /// The accepted values, as `--print-passes` shows them (`2..=64`, `on|off`).
    pub fn range_text(&self) -> String {
        match self.kind {
            ParamKind::U32 { min, max, .. }
            | ParamKind::U32Or { min, max, .. }
            | ParamKind::U32Target { min, max, .. } => format!("{min}..={max}"),
            ParamKind::U64 { min, max, .. } => format!("{min}..={max}"),
            ParamKind::F64 { min, max, .. } => format!("{min}..={max}"),
            ParamKind::Choice { choices, .. } => choices.join("|"),
            ParamKind::Selector { members, .. } => joined(members.iter().map(|m| m.name.to_string()), "|"),
            ParamKind::U32Set { allowed, .. } => joined(allowed.iter().map(u32::to_string), "|"),
            ParamKind::Flag { .. } => "on|off".to_string(),
            ParamKind::Path => "path".to_string(),
            ParamKind::OutputFolder => "folder".to_string(),
            ParamKind::U32List { min, max, .. } => format!("list of {min}..={max}"),
            ParamKind::Names => "list of names".to_string(),
        }
    }

    /// The values a test gives one by one to check each is accepted: every choice, member or
    /// allowed integer, `on` and `off` for a flag; nothing for the other kinds.
    pub fn every_value(&self) -> Vec<String> {
        match self.kind {
            ParamKind::Choice { choices, .. } => choices.iter().map(|c| c.to_string()).collect(),
            ParamKind::Selector { members, .. } => members.iter().map(|m| m.name.to_string()).collect(),
            ParamKind::U32Set { allowed, .. } => allowed.iter().map(u32::to_string).collect(),
            ParamKind::Flag { .. } => vec!["on".into(), "off".into()],
            _ => Vec::new(),
        }
    }

    /// The members of a [`ParamKind::Selector`]; none for any other parameter.
    pub fn members(&self) -> &'static [Member] {
        match self.kind {
            ParamKind::Selector { members, .. } => members,
            _ => &[],
        }
    }

    /// The smallest and largest accepted value of a numeric parameter, as text.
    pub fn bounds(&self) -> Option<(String, String)> {
        match self.kind {
            ParamKind::U32 { min, max, .. }
            | ParamKind::U32Or { min, max, .. }
            | ParamKind::U32Target { min, max, .. } => Some((min.to_string(), max.to_string())),
            ParamKind::U64 { min, max, .. } => Some((min.to_string(), max.to_string())),
            ParamKind::F64 { min, max, .. } => Some((format!("{min}"), format!("{max}"))),
            _ => None,
        }
    }

    /// Values just outside the range (`min − 1`, `max + 1`) where they are representable.
    pub fn out_of_bounds(&self) -> Vec<String> {
        match self.kind {
            ParamKind::U32 { min, max, .. }
            | ParamKind::U32Or { min, max, .. }
            | ParamKind::U32Target { min, max, .. } => {
                let mut v: Vec<String> = min.checked_sub(1).map(|x| x.to_string()).into_iter().collect();
                v.push((max as u64 + 1).to_string());
                v
            }
            ParamKind::U64 { min, max, .. } => {
                let mut v: Vec<String> = min.checked_sub(1).map(|x| x.to_string()).into_iter().collect();
                v.push((max as u128 + 1).to_string());
                v
            }
            ParamKind::F64 { min, max, .. } => vec![format!("{}", min - 1.0), format!("{}", max + 1.0)],
            _ => Vec::new(),
        }
    }
}

/// The add/sub latency parameter (SPEC §1), cycles.
pub const LAT_ADD: ParamInfo = ParamInfo {
    name: "lat-add",
    kind: ParamKind::U32Target { builtin: 12, min: 1, max: 10_000 },
    doc: "add/sub latency, cycles; when not given, the pipeline's (-target; de10-nano: 10 pipeline + 2 write)",
};
/// The mul latency parameter (SPEC §1), cycles.
pub const LAT_MUL: ParamInfo = ParamInfo {
    name: "lat-mul",
    kind: ParamKind::U32Target { builtin: 7, min: 1, max: 10_000 },
    doc: "mul latency, cycles; when not given, the pipeline's (-target; de10-nano: 5 pipeline + 2 write)",
};
/// The div latency parameter (SPEC §1), cycles.
pub const LAT_DIV: ParamInfo = ParamInfo {
    name: "lat-div",
    kind: ParamKind::U32Target { builtin: 12, min: 1, max: 10_000 },
    doc: "div latency, cycles (ADD side); when not given, the pipeline's (-target)",
};
/// The call latency parameter (SPEC §1), cycles.
pub const LAT_CALL: ParamInfo = ParamInfo {
    name: "lat-call",
    kind: ParamKind::U32Target { builtin: 12, min: 1, max: 10_000 },
    doc: "call (sqrt, callbacks) latency, cycles (ADD side); when not given, the pipeline's (-target)",
};
/// The four latency parameters, for passes that take only them.
pub const LATENCY_PARAMS: &[ParamInfo] = &[LAT_ADD, LAT_MUL, LAT_DIV, LAT_CALL];

/// Latencies given explicitly on one pass (`lat-add`, `lat-mul`, `lat-div`, `lat-call`), cycles;
/// `None` where not given. An explicit latency overrides the pipeline's latencies (the
/// target's, `-target`) from that pass on: see [`crate::PassContext::latencies_for`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LatencyOverride {
    /// `lat-add`.
    pub add: Option<u32>,
    /// `lat-mul`.
    pub mul: Option<u32>,
    /// `lat-div`.
    pub div: Option<u32>,
    /// `lat-call`.
    pub call: Option<u32>,
}

impl LatencyOverride {
    /// True when no latency was given.
    pub fn is_empty(&self) -> bool {
        *self == LatencyOverride::default()
    }

    /// `base` with the given latencies replaced.
    pub fn apply(&self, base: &Latencies) -> Latencies {
        Latencies {
            add: self.add.unwrap_or(base.add),
            mul: self.mul.unwrap_or(base.mul),
            div: self.div.unwrap_or(base.div),
            call: self.call.unwrap_or(base.call),
        }
    }

    /// The parameters as written in a pipeline (`lat-add=6;lat-mul=4`).
    pub fn text(&self) -> String {
        let parts = [("lat-add", self.add), ("lat-mul", self.mul), ("lat-div", self.div), ("lat-call", self.call)];
        parts.iter().filter_map(|(k, v)| v.map(|v| format!("{k}={v}"))).collect::<Vec<_>>().join(";")
    }
}

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
    /// declaration ([`LAT_ADD`]…); an undeclared one takes SPEC §1's value.
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
        match self.get(key) {
            Some(_) => self.u32(key).map(Some),
            None => Ok(None),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PASSES;

    fn build(info: &'static PassInfo, raw: &[(&str, String)]) -> Result<String, PassError> {
        let raw: Vec<(String, Option<String>)> = raw.iter().map(|(k, v)| (k.to_string(), Some(v.clone()))).collect();
        let p = Params::check(info, &raw)?;
        Ok(format!("{:?}", (info.build)(&p)?))
    }

    /// Each way to build `info`: `(parameters that select it, its declarations)`: the pass, or
    /// for a family each member with the selector given.
    fn variants(info: &'static PassInfo) -> Vec<(Vec<(&'static str, String)>, Vec<&'static ParamInfo>)> {
        let selector = info.params.iter().find(|p| !p.members().is_empty());
        match selector {
            None => vec![(Vec::new(), info.params.iter().collect())],
            Some(s) => s
                .members()
                .iter()
                .map(|m| (vec![(s.name, m.name.to_string())], info.params.iter().chain(m.params).collect()))
                .collect(),
        }
    }

    #[test]
    fn every_declared_default_is_the_default_and_every_range_is_enforced() {
        for info in PASSES {
            build(info, &[]).unwrap_or_else(|e| panic!("{}: {e}", info.name));
            for (select, decls) in variants(info) {
                let with = |extra: &[(&'static str, String)]| {
                    let mut raw = select.clone();
                    raw.extend(extra.iter().filter(|(k, _)| !select.iter().any(|(s, _)| s == k)).cloned());
                    build(info, &raw)
                };
                let none = with(&[]).unwrap_or_else(|e| panic!("{} {select:?}: {e}", info.name));
                let given: Vec<(&str, String)> =
                    decls.iter().filter(|p| p.default_is_literal()).map(|p| (p.name, p.default_text())).collect();
                let all = with(&given).unwrap_or_else(|e| panic!("{} {select:?}: {e}", info.name));
                assert_eq!(none, all, "{} {select:?}: no parameters vs every printed default", info.name);
                for p in decls.iter().filter(|p| p.members().is_empty()) {
                    let ok = |v: &str| with(&[(p.name, v.to_string())]);
                    if let Some((lo, hi)) = p.bounds() {
                        for v in [&lo, &hi] {
                            ok(v).unwrap_or_else(|e| panic!("{} {}={v}: {e}", info.name, p.name));
                        }
                        for v in p.out_of_bounds() {
                            assert!(
                                matches!(ok(&v), Err(PassError::BadParameter { .. })),
                                "{} {}={v} accepted",
                                info.name,
                                p.name
                            );
                        }
                    }
                    for c in p.every_value() {
                        ok(&c).unwrap_or_else(|e| panic!("{} {}={c}: {e}", info.name, p.name));
                    }
                    if !matches!(p.kind, ParamKind::Path | ParamKind::OutputFolder | ParamKind::Names) {
                        assert!(ok("x").is_err(), "{} {}=x accepted", info.name, p.name);
                    }
                }
            }
            // The selector: each member builds; a word that names none is refused.
            for s in info.params.iter().filter(|p| !p.members().is_empty()) {
                for c in s.every_value() {
                    build(info, &[(s.name, c.clone())]).unwrap_or_else(|e| panic!("{} {}={c}: {e}", info.name, s.name));
                }
                assert!(build(info, &[(s.name, "x".into())]).is_err(), "{} {}=x accepted", info.name, s.name);
            }
        }
    }

    #[test]
    fn a_set_parameter_takes_only_its_values() {
        let info = crate::pass_info("codegen").unwrap();
        let batch = info.param("batch").unwrap();
        assert_eq!((batch.default_text(), batch.range_text()), ("1".to_string(), "1|2|4|8|16".to_string()));
        for bad in ["0", "3", "32", "-1", "x"] {
            let e = build(info, &[("batch", bad.into())]).unwrap_err().to_string();
            assert_eq!(
                e,
                format!("pass `codegen`: parameter `batch` must be one of `1`, `2`, `4`, `8`, `16`, found `{bad}`")
            );
        }
    }

    #[test]
    fn word_parameters_are_read_as_their_enums() {
        use crate::codegen::c::{Abi, Precision, Trig};
        use crate::codegen::fpga::{Format, ResourceSource};
        fn round_trip<T: Word + PartialEq + std::fmt::Debug>(all: &[T]) {
            assert_eq!(all.len(), T::WORDS.len());
            for (x, w) in all.iter().zip(T::WORDS) {
                assert_eq!((x.as_str(), T::from_word(w)), (*w, Some(*x)));
            }
            assert_eq!(T::from_word("x"), None);
        }
        round_trip(&[Abi::Plain, Abi::Robotran]);
        round_trip(&[Precision::F64, Precision::F32]);
        round_trip(&[Trig::Libm, Trig::Input, Trig::Inline]);
        round_trip(&[Format::Both, Format::Mif, Format::Hex]);
        round_trip(&[ResourceSource::Auto, ResourceSource::Yosys, ResourceSource::Estimate]);
        assert_eq!(serde_json::to_string(&Abi::Robotran).unwrap(), "\"robotran\"");
    }

    #[test]
    fn option_defaults_come_from_the_declarations() {
        // Window 6 is what eqsat uses; `--print-passes` printed 8 before the declarations.
        let eqsat = crate::pass_info("eqsat").unwrap();
        let window = eqsat.params.iter().find(|p| p.name == "window").unwrap();
        assert_eq!(window.default_text(), crate::eqsat::EqsatOptions::default().window.to_string());
        assert_eq!(
            build(eqsat, &[]).unwrap(),
            format!(
                "{:?}",
                crate::eqsat::Eqsat { opts: crate::eqsat::EqsatOptions::default(), lat: Default::default() }
            )
        );
        let place = crate::pass_info("place").unwrap();
        assert_eq!(
            build(place, &[]).unwrap(),
            format!(
                "{:?}",
                crate::place::Place {
                    opts: crate::place::PlaceOptions::with_pes(4),
                    lat: Default::default(),
                    writes: None
                }
            )
        );
        let accuracy = crate::pass_info("accuracy").unwrap();
        assert_eq!(
            build(accuracy, &[]).unwrap(),
            format!("{:?}", crate::accuracy::Accuracy { opts: crate::accuracy::Options::default() })
        );
        // The latencies default to the target's; the declared built-in values are de10-nano's.
        let d = robovec_machine::target::Target::de10_nano().latencies;
        assert_eq!(d, Latencies::default());
        let lat: Vec<String> = LATENCY_PARAMS.iter().map(ParamInfo::default_text).collect();
        assert_eq!(lat, [d.add, d.mul, d.div, d.call].map(|x| format!("the target's, de10-nano {x}")));
    }
}
