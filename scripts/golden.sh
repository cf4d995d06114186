#!/usr/bin/env bash
# Golden outputs: runs a fixed set of robovec-opt / robovec-gen commands and writes every output
# (generated C and headers, FPGA folders, .rvir, JSON reports, report folders with figures,
# --print-passes, -stats and note lines on stderr) into OUT, so that a restructuring can be
# checked byte for byte: `scripts/golden.sh /tmp/before` on the old commit, `scripts/golden.sh
# /tmp/after` on the new one, then `diff -r /tmp/before /tmp/after`. Wall times (`wall_ms`,
# timing tables) are removed from the reports, as they differ between any two runs.
#
# Usage: scripts/golden.sh OUT [BIN_DIR]   (BIN_DIR: where robovec-opt and robovec-gen are;
# default target/release, built with `cargo build --release --locked` first)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: scripts/golden.sh OUT [BIN_DIR]}
bin=${2:-target/release}
[ -n "${2:-}" ] || cargo build --release --locked --quiet
opt="$(realpath "$bin")/robovec-opt"
gen="$(realpath "$bin")/robovec-gen"
corpus=../shared/corpus/robotran
rm -rf "$out"; mkdir -p "$out"
out=$(realpath "$out")
n=0
# run NAME ARGS…: one robovec-opt run, its stdout, stderr and exit status kept under NAME.
run() {
    local name=$1; shift
    local d="$out/$name"; mkdir -p "$d"
    set +e
    (cd "$d" && "$opt" "$@" >stdout 2>stderr; echo $? >status)
    set -e
    # eqsat's window times are wall times too.
    sed -i -E 's/time [0-9.]+ ms total, [0-9.]+ ms mean \/ [0-9.]+ ms max per window/time (wall)/' "$d/stderr"
    for r in "$d"/*.json "$d"/*/report.json; do
        [ -f "$r" ] && jq 'del(.. | .wall_ms?, .total_ms?, .mean_ms?, .max_ms?)' "$r" >"$r.tmp" 2>/dev/null && mv "$r.tmp" "$r" || true
    done
    n=$((n + 1))
}
pend=$(realpath examples/double_pendulum/mbs_invdyna_double_pendulum.c)
arm=$(realpath examples/three_link_arm/three_link_arm.urdf)
seg=$(realpath $corpus/c/frank_segway__mbs_dirdyna_Frank_segway.c)
knee=$(realpath $corpus/matlab/knee__mbs_dirdyna_Knee.m)
jeep=$(realpath $corpus/c/jeep__mbs_dirdyna_Jeep.c)
tri=$(realpath $corpus/c/tricycle__mbs_gensensor_tricycle.c)

"$opt" --print-passes >"$out/print-passes.txt" 2>&1 || true
run readme-main "$pend" -passes=atomise,asap-alap -stats -report=report.json -o out.rvir
run readme-report-dir "$pend" '-passes=atomise,place<pe=2>,sweep<pe=1,2,4,8,16>' \
    '-pareto=atomise,place<pe=2>;atomise,zero-removal,balance,place<pe=2>;atomise,inline<max-uses=3>,balance,place<pe=2>' \
    -report-dir=report -o /dev/null
run readme-c "$pend" '-passes=atomise,zero-removal,balance,codegen<c;abi=plain>' -report=report.json -o model.c
run readme-fpga "$pend" '-passes=atomise,place<pe=2>,codegen<fpga;out=fpga-out>' -o /dev/null -stats
run readme-time "$pend" -time-limit=1000 '-passes=atomise,balance,accuracy<samples=1000>,place<pe=2>,sim' -o placed.rvir -stats
for f in "$seg" "$knee"; do
    b=$(basename "$f" | sed 's/\..*//')
    run "$b-depth" "$f" '-passes=default<depth>' -stats -report=report.json -o out.rvir
    run "$b-ops" "$f" '-passes=default<ops>' -stats -report=report.json -o out.rvir
    run "$b-place" "$f" '-passes=atomise,zero-removal,balance,asap-alap,place<pe=8>,sim' -stats -report=report.json -o out.rvir
    run "$b-eqsat" "$f" '-passes=atomise,eqsat' -stats -report=report.json -o out.rvir
    run "$b-rot" "$f" '-passes=atomise,balance,rotate-3m<pe=16>,place<pe=16>' -stats -report=report.json -o out.rvir
    run "$b-bound" "$f" '-passes=atomise,depth-bound' -stats -report=report.json -o out.rvir
    run "$b-misc" "$f" '-passes=atomise,cse,dce,inline<max-uses=2>,specialize,distribute,swap,contract,schedule-cpu' -stats -report=report.json -o out.rvir
    run "$b-acc" "$f" '-passes=atomise,balance,accuracy<samples=200>' -stats -report=report.json -o out.rvir
    run "$b-sweep" "$f" '-passes=atomise,sweep<pe=1,4,16>' -stats -sweep-csv=sweep.csv -report=report.json -o out.rvir
    run "$b-c" "$f" '-passes=default<ops>,codegen<c;abi=robotran;trig=inline>' -o model.c
    run "$b-cbatch" "$f" '-passes=atomise,codegen<c;abi=plain;batch=4>' -o model.c
    run "$b-cunits" "$f" '-passes=atomise,codegen<c;abi=plain;units=3>' -o model.c
    run "$b-fpga" "$f" '-passes=atomise,place<pe=4>,codegen<fpga;out=fpga>' -o /dev/null -stats
    run "$b-check" "$f" '-passes=atomise,balance' -check -o out.rvir
    run "$b-pareto" "$f" '-passes=atomise' '-pareto=atomise;atomise,balance;default<depth>' -report-dir=rep -o /dev/null
done
run jeep-recur "$jeep" '-passes=atomise,zero-removal,balance,recurrence' -stats -o out.rvir
run tri-sensor "$tri" '-passes=atomise,zero-removal' -stats -o out.rvir
for fn in invdyna dirdyna fordyna; do
    run "arm-$fn" "$arm" -function=$fn '-passes=atomise,cse,codegen<c;abi=plain>' -stats -o model.c
    run "arm-ff-$fn" "$arm" --free-flyer --fold-params -function=$fn '-passes=atomise,codegen<c;abi=pinocchio>' -o model.c
    run "arm-depth-$fn" "$arm" --formulation=depth -function=$fn '-passes=atomise' -stats -o out.rvir
done
run arm-params "$arm" -params-out=params.json -o out.rvir
echo '{"q[1]": 0.5, "qd[2]": -1.25}' >/tmp/golden-eval-in.json
run arm-eval "$arm" -function=invdyna -passes=atomise -eval=/tmp/golden-eval-in.json -o out.rvir
run pend-eval32 "$pend" -passes=atomise,balance -eval=/tmp/golden-eval-in.json -eval-precision=f32
mkdir -p "$out/gen"
"$gen" --topology serial --dof 23 --seed 1 -o "$out/gen/serial23.urdf"
"$gen" --topology parallel --dof 30 --seed 2 --floating-base -o "$out/gen/par30.urdf"
"$gen" --urdf "$arm" --format c --function dirdyna --params-out "$out/gen/arm-params.json" -o "$out/gen/mbs_dirdyna_arm.c"
run gen-serial "$out/gen/serial23.urdf" -function=dirdyna '-passes=atomise,zero-removal,balance,codegen<c;abi=plain>' -o serial23.c -stats
run gen-armc "$out/gen/mbs_dirdyna_arm.c" -passes=atomise,zero-removal,balance -stats -o out.rvir
# Paths in outputs name the golden folder: the same on both sides.
echo "golden: $n runs in $out" >&2
