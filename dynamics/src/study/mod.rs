//! The study behind `robovec-gen --study` (issue 14): the thesis's study of seed §3.2, Table
//! 3.1, on robovec's topology families — 23, 50, 70, 100, 130 dof × serial, semi-serial,
//! parallel, direct dynamics (`dirdyna`) — run in process through the pass manager.
//!
//! Per case ([`run::run_case`]): ops, ASAP − ASAPCycle and number Y as generated (`atomise`),
//! after `atomise,zero-removal,balance` and after the best rewrite pipeline; placed cycles of
//! `place<pe=N>` at N = 8, 16, 32, 64 after the best pipeline; binary32 bits of error
//! (`accuracy<samples=K>`, mean and max over outputs and samples). Every figure comes from the
//! code behind `robovec-opt`'s `-stats` and report (`robovec_passes::summary::Figures`, the
//! placement's figures, the `accuracy` artifact's report entry), so it is what
//! `robovec-opt FILE.urdf -function=dirdyna -passes=PIPELINE -stats` prints for the URDF
//! `robovec-gen --topology T --dof N --seed S` writes (the tests check it through the binaries).
//!
//! # The best rewrite pipeline
//! [`DEFAULT_BEST`] = `atomise,zero-removal,cse,distribute,balance`. Rule: fewest placed
//! cycles summed over N = 8, 16, 32, 64, at binary32 error no worse than
//! `zero-removal,balance`'s. Measured on the 23-, 70- and 130-dof cases (9 cases, 100
//! samples; sums over the cases; the generator before `crate::origins`):
//!
//! | best pipeline candidate | ops | ASAPCycle | cycles N = 8 / 16 / 32 / 64 (sum) | f32 bits mean / max |
//! |---|---:|---:|---:|---:|
//! | `atomise,zero-removal,balance` (the thesis's rewrites, for reference) | 369 234 | 17 487 | 29 016 / 18 635 / 17 577 / 17 487 (82 715) | 0.88 / 22.2 |
//! | `atomise,cse,zero-removal,balance` | 335 205 | 17 487 | 26 192 / 18 024 / 17 502 / 17 487 (79 205) | 0.88 / 22.0 |
//! | `atomise,zero-removal,cse,distribute,balance` | 361 590 | 13 457 | 27 087 / 15 604 / 13 499 / 13 457 (69 647) | 0.88 / 22.0 |
//! | `atomise,zero-removal,cse,inline<max-uses=3>,balance` | 346 060 | 14 305 | 26 252 / 15 700 / 14 360 / 14 305 (70 617) | 0.88 / 21.4 |
//! | `atomise,zero-removal,cse,distribute,inline<max-uses=3>,balance` | 419 073 | 12 556 | 31 141 / 16 389 / 12 642 / 12 556 (72 728) | 0.88 / 21.4 |
//!
//! `cse` merges the repeated products of the generator's CRBA/RNEA (bit-exact); `distribute`
//! multiplies critical products of sums out (ops budget 1.5×; `max-growth=2` gives the same
//! IR) so that `balance` can reorder the terms: the critical path is 23% shorter than with
//! `cse,zero-removal,balance` for 8% more ops. Only at N = 8, where placement is bound by
//! ops / N, does the smaller IR of `cse,zero-removal,balance` place in fewer cycles (3%).
//! Adding `inline` shortens the critical path further but costs 16% more ops and 15% more
//! cycles at N = 8. `eqsat` windows were not measured on these sizes. `--best PIPELINE` runs
//! another pipeline.
//!
//! This module holds the study's data and computation: the cases ([`cases`]), one case run
//! through the pass manager ([`run::run_case`]) and the table ([`table`]). The command —
//! every case in parallel with a progress bar, the folder, its figures — is the driver's
//! (`robovec::study`).

pub mod cases;
pub mod run;
pub mod table;

/// The default best rewrite pipeline (see the module doc for the choice).
pub const DEFAULT_BEST: &str = "atomise,zero-removal,cse,distribute,balance";

/// The default N of the placements (N ADD + N MULTI PEs).
pub const DEFAULT_NS: [u32; 4] = [8, 16, 32, 64];
