//! IR-to-IR transforms that the IR's own users need besides the pass manager: the phase
//! transition parsed → atomised ([`atomise`], SPEC §3) and common-subexpression elimination
//! ([`cse`]). The front ends check their output with the first; the generator counts the ops of
//! a formulation with both. The passes `atomise` and `cse` of `robovec-passes` wrap them (the
//! pass adds the registry entry, the `-time-limit` policy and the stop error).

pub mod atomise;
pub mod cse;
pub mod diff;
