//! `dce<outputs=…>`: dead-code elimination. Keeps the listed outputs (all when `outputs` is
//! not given) and every value they need; drops the rest, unused inputs included.
//!
//! `outputs` is a comma-separated list; an entry names one output (`Qq[1]`) or a whole output
//! array (`c` keeps `c[1]`, `c[2]`, …). An entry that matches no output of any function is an
//! error. Works in both phases; clears timing attributes. Cost: O(values + operands).

use robovec_ir::Module;

use crate::params::ParamKind;
use crate::{try_each_function, AtTimeLimit, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "dce",
    doc: "drop everything the kept outputs do not need",
    params: &[ParamInfo {
        name: "outputs",
        kind: ParamKind::Names,
        doc: "outputs to keep: names (`Qq[1],Qq[2]`) or arrays (`c`), comma-separated",
    }],
    build: |p: &Params| Ok(Box::new(Dce { keep: p.names("outputs")? })),
    // It drops values and keeps the others as they are, formats included.
    props: crate::Props { bit_exact: true, formats: true, ..crate::Props::DEFAULT },
};

/// The `dce` pass.
#[derive(Debug)]
pub struct Dce {
    /// Output names or arrays to keep; `None` keeps all.
    pub keep: Option<Vec<String>>,
}

fn matches(entry: &str, output: &str) -> bool {
    output == entry || (output.starts_with(entry) && output[entry.len()..].starts_with('['))
}

impl Pass for Dce {
    fn name(&self) -> &'static str {
        "dce"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        if let Some(keep) = &self.keep {
            for e in keep {
                if !m.functions.iter().any(|f| f.outputs.iter().any(|o| matches(e, &o.name))) {
                    let mut names: Vec<&str> =
                        m.functions.iter().flat_map(|f| f.outputs.iter().map(|o| o.name.as_str())).collect();
                    names.truncate(12);
                    return Err(PassError::BadParameter {
                        pass: "dce".into(),
                        message: format!("no output matches `{e}` (outputs are like: {})", names.join(", ")),
                    });
                }
            }
        }
        // `-time-limit`: required (it changes what a function outputs and takes); two linear
        // sweeps per function, so the clock is read between functions.
        try_each_function(
            m,
            cx,
            "dce",
            AtTimeLimit::Required,
            Before::Clock,
            |_, _| None,
            |f, _, _| {
                if let Some(keep) = &self.keep {
                    f.outputs.retain(|o| keep.iter().any(|e| matches(e, &o.name)));
                }
                let live = f.live_values(&[]);
                f.retain(|_, v| live[v.index()]);
                f.clear_timing();
                Ok(Step::Done(()))
            },
        )
        .map(drop)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text::parse;

    const SRC: &str = "func @f { input %a input %b input %c %x = %a*%b %y = %x + %c %z = %b*%b output c[1] = %x output c[2] = %y output Qq[1] = %z }";

    fn run(keep: Option<&str>) -> Result<Module, PassError> {
        let mut m = parse(SRC).unwrap();
        let keep = keep.map(|k| k.split(',').map(String::from).collect());
        Dce { keep }.run(&mut m, &mut PassContext::default()).map(|_| m)
    }

    #[test]
    fn keeps_what_the_outputs_need() {
        let m = run(Some("Qq[1]")).unwrap();
        let f = &m.functions[0];
        assert_eq!(f.outputs.len(), 1);
        assert_eq!(f.inputs.len(), 1, "only %b is needed");
        assert_eq!(f.body.len(), 1);
        assert!(robovec_ir::verifier::verify_function(f).is_empty());
        let m = run(Some("c")).unwrap();
        assert_eq!(m.functions[0].outputs.len(), 2);
        assert!(m.functions[0].lookup("z").is_none());
        assert_eq!(run(None).unwrap().functions[0].body.len(), 3);
    }

    #[test]
    fn unknown_output_is_an_error() {
        assert!(matches!(run(Some("M")), Err(PassError::BadParameter { .. })));
    }
}
