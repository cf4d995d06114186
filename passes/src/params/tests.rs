//! The declarations of every registered pass against the parser and the getters.

use super::*;
use crate::{PassInfo, PASSES};
use robovec_ir::analysis::Latencies;

fn build(info: &'static PassInfo, raw: &[(&str, String)]) -> Result<String, PassError> {
    let raw: Vec<(String, Option<String>)> = raw.iter().map(|(k, v)| (k.to_string(), Some(v.clone()))).collect();
    let p = Params::check(info, &raw)?;
    Ok(format!("{:?}", (info.build)(&p)?))
}

/// One way to build a pass: the parameters that select it, and its declarations.
type Variant = (Vec<(&'static str, String)>, Vec<&'static ParamInfo>);

/// Each way to build `info` ([`Variant`]): the pass, or for a family each member with the
/// selector given.
fn variants(info: &'static PassInfo) -> Vec<Variant> {
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
    for info in PASSES.iter() {
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
                // (`F64OrPath` reads a word that is not a number as a file name.)
                if !matches!(
                    p.kind,
                    ParamKind::Path | ParamKind::OutputFolder | ParamKind::Names | ParamKind::F64OrPath { .. }
                ) {
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
fn option_defaults_come_from_the_declarations() {
    // Window 6 is what eqsat uses; `--print-passes` printed 8 before the declarations.
    let eqsat = crate::PASSES.get("eqsat").unwrap();
    let window = eqsat.params.iter().find(|p| p.name == "window").unwrap();
    assert_eq!(window.default_text(), crate::eqsat::EqsatOptions::default().window.to_string());
    assert_eq!(
        build(eqsat, &[]).unwrap(),
        format!("{:?}", crate::eqsat::Eqsat { opts: crate::eqsat::EqsatOptions::default(), lat: Default::default() })
    );
    let place = crate::PASSES.get("place").unwrap();
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
    let accuracy = crate::PASSES.get("accuracy").unwrap();
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
