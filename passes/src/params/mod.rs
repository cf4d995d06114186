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
//! an enum declared with `word_enum!` (`params/words.rs`), whose words are the
//! declaration's choices.

mod latency;
#[cfg(test)]
mod tests;
mod values;
mod words;

pub use latency::{LatencyOverride, LATENCY_PARAMS, LAT_ADD, LAT_CALL, LAT_DIV, LAT_MUL};
pub use values::{NumberOrPath, Params};
pub use words::word_enum;
pub use words::Word;

use crate::{Pass, PassError};

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
    /// An integer in `min..=max`, or nothing when not given (a feature that is off unless a
    /// value is given: `place<steal=S>`); read with [`Params::u32_given`].
    U32Opt {
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
    /// A finite number in `min..=max`, or (any value that does not read as a number) a file
    /// the pass reads (`precision<budget=1e-6>` or `budget=FILE`); `robovec-opt` checks a file
    /// can be opened before any work.
    F64OrPath {
        /// Value when the parameter is not given.
        default: f64,
        /// Smallest accepted number.
        min: f64,
        /// Largest accepted number.
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
    /// Its properties (what the family's own [`crate::PassInfo::props`] would be for it).
    pub props: crate::Props,
}

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
            ParamKind::U32Opt { .. } => "none".to_string(),
            ParamKind::U32Target { builtin, .. } => format!("the target's, de10-nano {builtin}"),
            ParamKind::U64 { default, .. } => default.to_string(),
            ParamKind::F64 { default, .. } | ParamKind::F64OrPath { default, .. } => format!("{default}"),
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
                | ParamKind::U32Opt { .. }
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
            | ParamKind::U32Opt { min, max }
            | ParamKind::U32Target { min, max, .. } => format!("{min}..={max}"),
            ParamKind::U64 { min, max, .. } => format!("{min}..={max}"),
            ParamKind::F64 { min, max, .. } => format!("{min}..={max}"),
            ParamKind::F64OrPath { min, max, .. } => format!("{min}..={max} or path"),
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
            | ParamKind::U32Opt { min, max }
            | ParamKind::U32Target { min, max, .. } => Some((min.to_string(), max.to_string())),
            ParamKind::U64 { min, max, .. } => Some((min.to_string(), max.to_string())),
            ParamKind::F64 { min, max, .. } | ParamKind::F64OrPath { min, max, .. } => {
                Some((format!("{min}"), format!("{max}")))
            }
            _ => None,
        }
    }

    /// Values just outside the range (`min − 1`, `max + 1`) where they are representable.
    pub fn out_of_bounds(&self) -> Vec<String> {
        match self.kind {
            ParamKind::U32 { min, max, .. }
            | ParamKind::U32Or { min, max, .. }
            | ParamKind::U32Opt { min, max }
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
            ParamKind::F64 { min, max, .. } | ParamKind::F64OrPath { min, max, .. } => {
                vec![format!("{}", min - 1.0), format!("{}", max + 1.0)]
            }
            _ => Vec::new(),
        }
    }
}
