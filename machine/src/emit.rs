//! The files of a design, as `codegen<fpga>` writes them into its folder (the pass's module
//! doc in `robovec-passes` lists them: images, `hdl/`, `manifest.json`, `simulate`,
//! `resources.json`), and [`emit`], the whole back end for one placed function: design, resource
//! estimate, manifest and files.

use serde::Serialize;

use robovec_ir::placement::Placement;
use robovec_ir::Function;

use crate::design::build::{from_placement_until, DesignError, Limits};
use crate::design::images::Image;
use crate::design::routes::Interconnect;
use crate::design::{Design, PeKind, HDL_LIBRARY, SIMULATE};
use crate::resources::{self, CostModel, Logic, Resources};

/// What `codegen<fpga>` was asked for, beyond the placement and the target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EmitOptions<'a> {
    /// Where the logic ALMs come from (`resources=`).
    pub logic: Logic,
    /// The image formats written: `mif`, `hex` or `both` (`format=`).
    pub format: &'a str,
    /// The interconnect (`interconnect=`; [`crate::design::routes`]).
    pub interconnect: Interconnect,
}

/// One file of a design, its path relative to the function's folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DesignFile {
    /// Path under `DIR` (`hex/pe0_instr.hex`).
    pub path: String,
    /// Content.
    pub bytes: Vec<u8>,
    /// True for `simulate`.
    pub executable: bool,
}

/// The files of a design: `(path relative to DIR, bytes, executable)`; `format` is `mif`, `hex`
/// or `both` (the image formats written).
pub fn design_files(d: &Design, format: &str, r: &Resources, manifest: &str) -> Vec<DesignFile> {
    let mut v: Vec<DesignFile> = Vec::new();
    let mut add = |path: String, bytes: Vec<u8>, executable: bool| v.push(DesignFile { path, bytes, executable });
    for img in d.images() {
        if format != "mif" {
            add(format!("hex/{}.hex", img.name), img.to_hex().into_bytes(), false);
        }
        if format != "hex" {
            add(format!("mif/{}.mif", img.name), img.to_mif().into_bytes(), false);
        }
    }
    for (n, t) in HDL_LIBRARY {
        add(format!("hdl/{n}"), t.as_bytes().to_vec(), false);
    }
    add("hdl/robovec_top.v".into(), d.top("").into_bytes(), false);
    add("hdl/testbench.v".into(), d.testbench().into_bytes(), false);
    add("manifest.json".into(), manifest.as_bytes().to_vec(), false);
    add("simulate".into(), SIMULATE.as_bytes().to_vec(), true);
    let mut res = serde_json::to_string_pretty(r).expect("resources serialise");
    res.push('\n');
    add("resources.json".into(), res.into_bytes(), false);
    v
}

/// One memory in the manifest.
#[derive(Clone, Debug, Serialize)]
struct ManifestMemory {
    file: String,
    words: usize,
    width: u32,
}

#[derive(Clone, Debug, Serialize)]
struct ManifestPe<'a> {
    slot: usize,
    pe: &'a str,
    kind: &'static str,
    /// A MULTI PE with the multiply-add unit (`rv_pe`'s `MAC = 1`; omitted when false).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    mac: bool,
    latency: u32,
    buffer_words: u32,
    memories: std::collections::BTreeMap<&'static str, ManifestMemory>,
    /// The PE's control word (`Design::controls`): the same fields as `instr`, `xbar`, `bufi`,
    /// `capt` and `fix`, one word per cycle at `offset` of the control memory the HDL reads
    /// (`control_lanes`).
    control: crate::design::Control,
}

/// The manifest (`manifest.json`): everything a host or a script needs to load and read the
/// design. `target` is the target's name, `clock_mhz` its clock.
pub fn manifest(d: &Design, target: &str, clock_mhz: f64, format: &str) -> String {
    let m = |i: &Image| ManifestMemory { file: i.name.clone(), words: i.words.len().max(1), width: i.width };
    let pes: Vec<ManifestPe> = d
        .pes
        .iter()
        .zip(d.controls())
        .map(|(p, c)| {
            let memories = [
                ("instr", m(&p.instr)),
                ("xbar", m(&p.xbar)),
                ("bufi", m(&p.bufi)),
                ("capt", m(&p.capt)),
                ("data", m(&p.data)),
                ("out", m(&p.out)),
            ]
            .into_iter()
            .chain(p.fix.as_ref().map(|i| ("fix", m(i))))
            .collect();
            ManifestPe {
                control: c,
                slot: p.slot,
                pe: &p.pe,
                kind: if p.is_mul { "mul" } else { "add" },
                mac: p.mac,
                latency: if p.is_mul { d.lat_mul } else { d.lat_add },
                buffer_words: p.buffer_words,
                memories,
            }
        })
        .collect();
    let mut hdl: Vec<&str> = HDL_LIBRARY.iter().map(|(n, _)| *n).collect();
    hdl.push("robovec_top.v");
    let w = d.widths;
    let (e, n) = (4 * w.aw, d.n_pe());
    let xbar = match &d.routes {
        None => format!(
            "[0,{s}) port-0 select, [{s},{}) port-1 select: 0 none, 1..={n} result of slot s-1, {}..={} buffer read of slot s-{}",
            2 * w.sw,
            n + 1,
            2 * n,
            n + 1,
            s = w.sw
        ),
        Some(_) => "per PE (its memory's `width`): port-0 select in the low bits (`routes[slot].select_bits[0]`), \
            port-1 select above, then the shared multiplexer's select (`select_bits[2]` bits, none when 0): a port's \
            0 is no write, i its i-th route (`routes[slot].port0` / `port1`, 1-based), one more the shared \
            multiplexer's output when the memory has one; the shared select's i is `routes[slot].shared`'s i-th"
            .to_string(),
    };
    let routes = d.routes.as_ref().map(|r| {
        r.ports
            .iter()
            .enumerate()
            .map(|(slot, ports)| {
                let names = |port: usize| -> Vec<String> {
                    ports[port].iter().map(|&g| r.source_name(g, |k| pe_name_of(d, k))).collect()
                };
                serde_json::json!({
                    "slot": slot,
                    "pe": pe_name_of(d, slot),
                    "port0": names(0),
                    "port1": names(1),
                    "shared": r.shared[slot].iter().map(|&g| r.source_name(g, |k| pe_name_of(d, k))).collect::<Vec<_>>(),
                    "select_bits": [r.select_bits(slot, 0), r.select_bits(slot, 1), r.shared_bits(slot)],
                })
            })
            .collect::<Vec<_>>()
    });
    let layout = serde_json::json!({
        "instr": format!("[0,{a}) read A, [{a},{b}) read B, [{b},{c}) write-0 address, [{c},{e}) write-1 address, \
            bit {e} we0, bit {} we1, bit {} issue valid, bit {} sub (ADD PE: 1 = a - b), zero up to {}",
            e + 1, e + 2, e + 3, w.instr, a = w.aw, b = 2 * w.aw, c = 3 * w.aw),
        "xbar": xbar,
        "bufi": format!("[0,{b}) store address, [{b},{}) read address, bit {} store enable, bit {} read enable",
            2 * w.bw, 2 * w.bw, 2 * w.bw + 1, b = w.bw),
        "capt": format!("[0,{o}) output-memory address, bit {o} enable", o = w.ow),
        "control": "per PE (`control`): one word per cycle, from bit 0: the instruction's four addresses `pa` bits each \
            (read A, read B, write-0, write-1), we0, we1, issue valid, sub; the `xbar` word's selects (port 0, port 1, shared) \
            each one less, 0-based (0 when the port does not write: we0 and we1 say which do), in `control.select_bits` bits each; \
            the `bufi` word with its addresses cut to `pb` bits each (store address, read address, store enable, read enable); the `capt` word with its address cut to `po` \
            bits (address, enable); on fixed-point PEs the `fix` word cut to the PE's shifts (`control.fix`: `floor_bits` of \
            floor r, `align_bits` of alignment, the align-b bit when `align_b`, the rounding shift less `shift_min` in \
            `shift_bits`; zero on a cycle that issues nothing; on ADD PEs, `floors`, the op's floored form: r = min(align, \
            s - 1) for s >= 1 (else 0), the alignment less r, s less r, and an op whose align-b bit is 0 reads A and B \
            swapped, so the finer operand is read at A); at bits [`offset`, `offset` + `width`) of the design's control word \
            (`control_lanes`)",
        "data": match d.pe_kind {
            PeKind::Binary32 => "binary32",
            PeKind::Fixed => "fixed point: the `word_bits`-bit two's complement integer k of a value k·2^-f (each load's and output's `fraction`); out_data sign-extends it to 32 bits",
        },
    });
    let mut layout = layout;
    if d.pes.iter().any(|p| p.mac) {
        // fused multiply-adds (`crate::encode`): three more instruction fields after the seed
        // word's, and the same after the shift word in a MAC PE's control word
        layout["instr"] = serde_json::json!(format!(
            "[0,{a}) read A, [{a},{b}) read B, [{b},{c}) write-0 address, [{c},{e}) write-1 address, \
            bit {e} we0, bit {} we1, bit {} issue valid, bit {} sub (ADD PE: 1 = a - b; MULTI PE with the mac bit: negate the addend), \
            [{},{f}) read C (the addend of a multiply-add), bit {f} negate product, bit {} mac (MULTI PE: ±a·b ± c; 0 = a·b), zero up to {}",
            e + 1, e + 2, e + 3, e + 4, 5 * w.aw + 5, w.instr, a = w.aw, b = 2 * w.aw, c = 3 * w.aw, f = 5 * w.aw + 4
        ));
        layout["control"] = serde_json::json!(
            "per PE (`control`): one word per cycle, from bit 0: the instruction's four addresses `pa` bits each \
            (read A, read B, write-0, write-1), we0, we1, issue valid, sub; the `xbar` word's selects 0-based in \
            `control.select_bits` bits each; the `bufi` word with its addresses cut to `pb` bits each; the `capt` word with its address cut to `po` bits; on fixed-point PEs the `fix` word cut to the PE's \
            shifts (`control.fix`); on PEs with `mac` then read C (`pa` bits), negate product, mac; \
            at bits [`offset`, `offset` + `width`) of the design's control word (`control_lanes`)"
        );
    }
    if d.pe_kind == PeKind::Fixed {
        layout["fix"] = serde_json::json!(
            "per PE and cycle, [0,6) align (bits the aligned operand is shifted left), bit 6 align b (else a), \
            [7,14) s (two's complement): s > 0 rounds (K + 2^(s-1)) >> s, s <= 0 shifts left by -s"
        );
    }
    let v = serde_json::json!({
        "format": "robovec-fpga/1",
        "function": d.function,
        "target": target,
        "clock_mhz": clock_mhz,
        "images": format,
        "cycles": d.cycles,
        "states": d.states,
        "n_add": d.n_add,
        "n_mul": d.n_mul,
        "latency": {"add": d.lat_add, "mul": d.lat_mul},
        "interconnect": d.interconnect().as_str(),
        "pe_kind": d.pe_kind.as_str(),
        "word_bits": d.word_bits,
        "mux_inputs": d.mux_inputs(),
        "widths": w,
        "layout": layout,
        "hdl": hdl,
        "pes": pes,
        "control_lanes": d.control_lanes().iter().map(m).collect::<Vec<_>>(),
        "inputs": d.inputs,
        "loads": d.loads,
        "output_loads": d.output_loads,
        "outputs": d.outputs,
    });
    let mut v = v;
    if d.pe_kind == PeKind::Fixed {
        v["input_fractions"] = serde_json::json!(d.input_fractions);
    }
    if let Some(r) = routes {
        v["routes"] = serde_json::Value::Array(r);
    }
    let mut s = serde_json::to_string_pretty(&v).expect("manifest serialises");
    s.push('\n');
    s
}

fn pe_name_of(d: &Design, slot: usize) -> String {
    d.pes.get(slot).map(|p| p.pe.clone()).unwrap_or_else(|| format!("pe{slot}"))
}

/// The design, resource estimate and files of function `f` placed by `p`, on a target of
/// `limits` and `model`, as `opts` asks (the logic's source, the image formats, the interconnect).
///
/// # Errors
/// A diagnostic naming the function and the target: what
/// [`crate::design::build::from_placement`] refuses, or a Yosys failure (with
/// [`Logic::Yosys`]: Yosys missing).
pub fn emit(
    f: &Function,
    p: &Placement,
    limits: &Limits,
    model: &CostModel,
    opts: &EmitOptions,
) -> Result<(Design, Resources, Vec<DesignFile>), String> {
    emit_until(f, p, limits, model, opts, &|| false).map_err(|e| e.message)
}

/// `d` with its output memories in LUT RAM only as far as the block RAM needs (issue 49): the
/// smallest depth `t` up to the family's [`Design::out_lutram_words`] (0: every output memory in
/// block RAM) at which the estimate's block RAMs fit `model`'s device, the output memories of
/// at most `t` words built in LUT RAM ([`Design::out_in_lutram`]); the family's depth when none
/// fits. An output memory in the Cyclone V's MLAB costs about 13 ALMs for 26-bit words (Yosys:
/// a `MISTRAL_MLAB` cell a bit, two an ALM) that a spare M10K saves: the MX-5 at 81 + 81 PEs
/// has 106 of them, 1,196 ALMs, and 213 M10K to spare. Cost: an estimate per distinct depth.
fn lutram_where_block_ram_is_short(mut d: Design, model: &CostModel) -> Design {
    let most = d.out_lutram_words;
    let mut depths: Vec<u32> = d.pes.iter().map(|p| p.out.words.len().max(1) as u32).filter(|&w| w <= most).collect();
    depths.sort_unstable();
    depths.dedup();
    for t in std::iter::once(0).chain(depths) {
        d.out_lutram_words = t;
        if t == most || resources::estimate(&d, model, None).m10k <= model.capacity.m10k {
            return d;
        }
    }
    d.out_lutram_words = most;
    d
}

/// [`emit`] whose lowering gives up when `stop` returns true ([`from_placement_until`]; the
/// caller's time limit). The encoding, Yosys and the estimate after it are not interrupted.
///
/// # Errors
/// As [`emit`]; when `stop` returned true, the lowering's `stopped: time limit` (the caller
/// knows it from its hook).
pub fn emit_until(
    f: &Function,
    p: &Placement,
    limits: &Limits,
    model: &CostModel,
    opts: &EmitOptions,
    stop: &dyn Fn() -> bool,
) -> Result<(Design, Resources, Vec<DesignFile>), DesignError> {
    let (logic, format) = (opts.logic, opts.format);
    let d = from_placement_until(f, p, limits, stop)
        .map_err(|e| DesignError {
            message: format!("function @{} cannot be emitted for target `{}`:\n{e}", f.name, model.target),
            span: e.span,
        })?
        .with_interconnect(opts.interconnect);
    let d = lutram_where_block_ram_is_short(d, model);
    let cells =
        match logic {
            _ if logic.skips_yosys(d.n_add + d.n_mul) => None,
            Logic::Yosys => Some(resources::yosys_design(&d)?.ok_or(
                "`resources=yosys` but `yosys` cannot be run (Debian package `yosys`); use resources=estimate",
            )?),
            // `auto` within the limit: Yosys when it can be run, else the estimate.
            _ => resources::yosys_design(&d)?,
        };
    let mut r = resources::estimate(&d, model, cells);
    let mut pnr_files = Vec::new();
    if logic == Logic::Pnr {
        let part = crate::pnr::part_of(&model.target, model.pnr.as_ref())?;
        let run = crate::pnr::place_and_route(&d, part, model.clock_mhz)
            .map_err(|e| format!("function @{}: place and route for `{}`: {e}", f.name, model.target))?;
        r = resources::with_pnr(r, model, run.figures);
        pnr_files = run.files;
    }
    let man = manifest(&d, &model.target, r.clock_mhz, format);
    let mut files = design_files(&d, format, &r, &man);
    files.extend(pnr_files.into_iter().map(|(name, bytes)| DesignFile {
        path: format!("pnr/{name}"),
        bytes,
        executable: false,
    }));
    Ok((d, r, files))
}
