#!/usr/bin/env bash
# Speed from precision (issue 48's goal, docs/accuracy.md "Speed from precision"): robovec's
# best binary64 C at batch=4 against the mixed-precision C that `precision<budget=B>` certifies
# at batch=8 — with double arrays, and with float arrays (`precision=f32` with formats: the
# caller's data already in binary32) — side by side in one process (benches/precision_speed/driver.c: alternating, order
# rotated, medians of ns/state and of paired ratios), on UR5, Panda and Talos over their URDF
# limits, for each function given (default invdyna: RNEA).
#
#   scripts/precision_speed.sh [--budget=1e-5] [--runs=2] [--flags="-O3 -march=native -mno-avx512f"] [--trig=inline|input] [FUNCTION…]
#
# Needs a release robovec-opt (cargo build --release), cc, and the example-robot-data URDFs of
# the Pinocchio venv (target/pinocchio-venv, scripts/test.sh makes it). Prints a Markdown table.
set -euo pipefail
cd "$(dirname "$0")/.."
budget=1e-5
runs=2
flags="-O3 -march=native -mno-avx512f"
trig=inline
functions=()
for a in "$@"; do
  case "$a" in
    --budget=*) budget="${a#*=}" ;;
    --runs=*) runs="${a#*=}" ;;
    --flags=*) flags="${a#*=}" ;;
    --trig=*) trig="${a#*=}" ;;
    -*) echo "unknown option $a" >&2; exit 2 ;;
    *) functions+=("$a") ;;
  esac
done
[ ${#functions[@]} -eq 0 ] && functions=(invdyna)
opt=target/release/robovec-opt
[ -x "$opt" ] || { echo "build first: cargo build --release" >&2; exit 2; }
robots=$(ls -d target/pinocchio-venv/lib/python3*/site-packages/cmeel.prefix/share/example-robot-data/robots 2>/dev/null | head -1)
[ -n "$robots" ] || { echo "no example-robot-data: run scripts/test.sh (it makes target/pinocchio-venv)" >&2; exit 2; }
work=target/precision_speed
mkdir -p "$work"
pipeline='atomise,cse,zero-removal,contract,schedule-cpu'
# The certificate is for the sin/cos the code calls: robovec's own with trig=inline (its binary32
# kernel allowed 1 ulp), the C library's otherwise (trig=input: the caller's, as the library's).
ptrig=libm
[ "$trig" = inline ] && ptrig=inline
echo "| robot | function | precision's choice | certified max_rel | f64 batch=4 ns/state | mixed batch=8 ns/state | mixed, float arrays, batch=8 ns/state | mixed vs f64 | mixed, float arrays vs f64 |"
echo "|---|---|---|---|---|---|---|---|---|"
for robot in ur5:ur_description/urdf/ur5_robot.urdf panda:panda_description/urdf/panda.urdf talos:talos_data/robots/talos_reduced.urdf; do
  name=${robot%%:*}
  urdf=$robots/${robot#*:}
  for fn in "${functions[@]}"; do
    d=$work/$name-$fn
    mkdir -p "$d"
    common=("$urdf" -function="$fn" --fold-params)
    "$opt" "${common[@]}" -passes="$pipeline,codegen<c;abi=plain;batch=4;trig=$trig;name=rv_a>" -o "$d/a.c" 2>/dev/null
    if ! "$opt" "${common[@]}" -passes="$pipeline,precision<budget=$budget;trig=$ptrig>,error-bound<format=mixed;trig=$ptrig>,codegen<c;abi=plain;batch=8;trig=$trig;name=rv_b>" \
      -o "$d/b.c" -report="$d/b.json" 2>"$d/b.err"; then
      echo "| $name | $fn | refused: $(head -1 "$d/b.err") | | | | | | |"
      continue
    fi
    # The same formats with float arrays (precision=f32 with formats: data already in binary32).
    "$opt" "${common[@]}" -passes="$pipeline,precision<budget=$budget;trig=$ptrig>,codegen<c;abi=plain;batch=8;trig=$trig;precision=f32;name=rv_c>" -o "$d/c.c" 2>/dev/null
    ni=$(grep -o 'in\[[0-9]*\]' "$d/a.h" | tr -d 'in[]' | sort -n | tail -1)
    no=$(grep -o 'out\[[0-9]*\]' "$d/a.h" | tr -d 'out[]' | sort -n | tail -1)
    # shellcheck disable=SC2086
    cc $flags -ffp-contract=off -Wno-psabi -DNI=$((ni + 1)) -DNO=$((no + 1)) -o "$d/run" \
      benches/precision_speed/driver.c "$d/a.c" "$d/b.c" "$d/c.c" -lm
    choice=$(grep -o 'precision @[^:]*: [^;]*' "$d/b.err" | sed 's/precision @[^:]*: //')
    bound=$(python3 -c "import json; print('%.2g' % json.load(open('$d/b.json'))['precision']['max_rel_to_range'])")
    for k in $(seq "$runs"); do
      read -r a b c ab ac < <("$d/run")
      echo "| $name | $fn | $choice | $bound | $a | $b | $c | **${ab}×** | ${ac}× |"
    done
  done
done
