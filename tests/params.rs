//! Issue 10 item 5: each parameter's default and range are declared once; `--print-passes`
//! prints them from the declaration. Issue 27: each back end of `codegen` declares its own
//! parameters, and a parameter of the other back end is bad usage naming its back end.

use std::process::Command;

use robovec_backends::REGISTRY as PASSES;

use crate::common::{opt, stderr};

#[test]
fn print_passes_shows_every_declared_default_and_range() {
    let o = Command::new(env!("CARGO_BIN_EXE_robovec-opt")).arg("--print-passes").output().unwrap();
    assert_eq!(o.status.code(), Some(0));
    let text = String::from_utf8(o.stdout).unwrap();
    for info in PASSES {
        for p in info.every_param() {
            let line = format!("      {:<12} (default {}; {}) {}", p.name, p.default_text(), p.range_text(), p.doc);
            assert!(text.lines().any(|l| l == line), "no line `{line}` in:\n{text}");
        }
    }
    // The default eqsat really uses (`--print-passes` said 8 while the code used 6).
    let window = robovec_passes::eqsat::EqsatOptions::default().window;
    assert!(text.contains(&format!("      window       (default {window}; 2..=64)")), "{text}");
    // Each back end's parameters are listed under it.
    let at = |line: &str| text.lines().position(|l| l.starts_with(line)).unwrap_or_else(|| panic!("no `{line}`"));
    let (c, fpga) = (at("    back end c: "), at("    back end fpga: "));
    // (`error-bound` has a `format` too, before the back ends: the fpga's is the one after it.)
    let after = |from: usize, line: &str| {
        from + text.lines().skip(from).position(|l| l.starts_with(line)).unwrap_or_else(|| panic!("no `{line}`"))
    };
    assert!(c < at("      abi ") && at("      name ") < fpga && after(fpga, "      format ") > fpga, "{text}");
    assert!(after(c, "      name ") < fpga, "{text}");
}

const PENDULUM: &str = "examples/double_pendulum/mbs_invdyna_double_pendulum.c";

#[test]
fn a_parameter_of_the_other_back_end_is_bad_usage_naming_its_back_end() {
    for (pipeline, owner) in [
        ("atomise,codegen<c;format=hex>", "`fpga`"),
        ("atomise,codegen<format=both>", "`fpga`"),
        ("atomise,place<pe=2>,codegen<fpga;batch=4>", "`c`"),
        ("atomise,place<pe=2>,codegen<fpga;abi=plain>", "`c`"),
    ] {
        let o = opt(&[PENDULUM, &format!("-passes={pipeline}"), "-o", "/dev/null"]);
        assert_eq!(o.status.code(), Some(2), "{pipeline}: {}", stderr(&o));
        assert!(stderr(&o).contains(&format!("belongs to back end {owner}")), "{pipeline}: {}", stderr(&o));
    }
    let o = opt(&[PENDULUM, "-passes=atomise,codegen<c;format=hex>", "-o", "/dev/null"]);
    assert_eq!(stderr(&o), "error: pass `codegen`: parameter `format` belongs to back end `fpga`, not `c`\n");
    // A parameter no back end has: the valid ones of the selected back end.
    let o = opt(&[PENDULUM, "-passes=atomise,place<pe=2>,codegen<fpga;lanes=4>", "-o", "/dev/null"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("unknown parameter `lanes` (valid: back-end, out, format, resources, interconnect)"),
        "{}",
        stderr(&o)
    );
}
