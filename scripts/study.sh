#!/usr/bin/env bash
# The thesis's study (seed §3.2, Table 3.1) on robovec's own topology families, issue 14:
# for each dof and topology, robovec-gen writes the robot (seed 1), robovec-opt runs `dirdyna`
# through three pipelines and prints one markdown row per case:
#   ops, ASAP - ASAPCycle and Y (SPEC: critical path in ops and in cycles, ops / ASAPCycle)
#   as generated (atomise), after zero-removal,balance, and after cse,zero-removal,balance;
#   placed cycles at N = 8, 16, 32, 64 ADD + MULTI PEs (place<pe=N>, on the last pipeline);
#   bits of error in binary32 (accuracy, 200 sampled states: mean / max, on the last pipeline).
# Usage: scripts/study.sh [DOF ...]   (default: 23 50 70 100 130; release binaries via cargo)
# Every figure is read from robovec-opt's -stats lines, so the table follows SPEC's definitions.
set -euo pipefail
cd "$(dirname "$0")/.."
dofs=("$@")
[ ${#dofs[@]} -eq 0 ] && dofs=(23 50 70 100 130)
# ROBOVEC_BIN=DIR uses prebuilt binaries (e.g. target/debug for a quick check).
bin=${ROBOVEC_BIN:-}
if [ -z "$bin" ]; then
    cargo build -q --release --bin robovec-gen --bin robovec-opt
    bin=target/release
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# "ops N … critical path A ops / C cycles, Y = y" of @dirdyna's summary line → "N | A - C | y".
summary() { grep '^@dirdyna: equations' | sed -E 's/.*ops ([0-9]+) .*critical path ([0-9]+) ops \/ ([0-9]+) cycles, Y = ([0-9.]+).*/\1 | \2 - \3 | \4/'; }

echo "| case | ops | ASAP - ASAPCycle | Y | ops (z,b) | ASAP - ASAPCycle (z,b) | Y (z,b) | ops (cse,z,b) | ASAP - ASAPCycle (cse,z,b) | Y (cse,z,b) | cycles N = 8 / 16 / 32 / 64 | f32 bits mean / max |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
for dof in "${dofs[@]}"; do
    for topo in serial semi-serial parallel; do
        urdf="$work/${topo}_${dof}.urdf"
        "$bin/robovec-gen" --topology "$topo" --dof "$dof" --seed 1 -o "$urdf"
        run() { "$bin/robovec-opt" "$urdf" -function=dirdyna "-passes=$1" -stats -o /dev/null 2>&1; }
        gen=$(run atomise | summary)
        zb=$(run atomise,zero-removal,balance | summary)
        best_p=atomise,cse,zero-removal,balance
        best=$(run "$best_p" | summary)
        cycles=()
        for n in 8 16 32 64; do
            cycles+=("$(run "$best_p,place<pe=$n>" | grep '^@dirdyna: placed' | sed -E 's/.*PEs: ([0-9]+) cycles.*/\1/')")
        done
        bits=$(run "$best_p,accuracy<samples=200>" | grep '^@dirdyna: accuracy' | sed -E 's/.*mean\/p95\/max f32 ([0-9.]+)\/[0-9.]+\/([0-9.]+).*/\1 \/ \2/')
        echo "| ${dof}-dof $topo | $gen | $zb | $best | ${cycles[0]} / ${cycles[1]} / ${cycles[2]} / ${cycles[3]} | $bits |"
    done
done
