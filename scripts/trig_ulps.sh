#!/usr/bin/env bash
# The allowance error-bound<trig=inline> and precision<trig=inline> give robovec's binary32
# sin/cos (robovec_passes::error_bound::bound::INLINE32_ULPS, 1 ulp on |x| <= 2^11), checked on
# every binary32 argument of that range, both signs, through the three kernels codegen<c> writes,
# compiled for a generic x86-64 (no FMA) and for this host (-march=native: FMA where it has it).
# About 2.3·10⁹ arguments per build, the builds in parallel (a few minutes on this machine).
#
#   scripts/trig_ulps.sh [--cc=gcc]
#
# Needs a release robovec-opt (cargo build --release) and a C compiler. Exit 1 when an error
# reaches 1 ulp or a vector lane differs from the one-state code.
set -euo pipefail
cd "$(dirname "$0")/.."
cc=gcc
for a in "$@"; do
  case "$a" in
    --cc=*) cc="${a#*=}" ;;
    *) echo "unknown option $a" >&2; exit 2 ;;
  esac
done
opt=target/release/robovec-opt
[ -x "$opt" ] || { echo "build first: cargo build --release" >&2; exit 2; }
work=target/trig_ulps
mkdir -p "$work"
ir='func @sc {\n  phase atomised\n  input %%q[1]%s\n  %%S1 = sin %%q[1]%s\n  %%C1 = cos %%q[1]%s\n  output s = %%S1\n  output c = %%C1\n}\n'
printf "$ir" "" "" "" > "$work/sc.rvir"
printf "$ir" " : f32" " : f32" " : f32" > "$work/scm.rvir"
"$opt" "$work/sc.rvir" -passes='codegen<c;precision=f32;trig=inline;name=sc1>' -o "$work/sc1.c"
"$opt" "$work/sc.rvir" -passes='codegen<c;precision=f32;batch=8;trig=inline;name=sc8>' -o "$work/sc8.c"
"$opt" "$work/scm.rvir" -passes='codegen<c;batch=8;trig=inline;name=scm>' -o "$work/scm.c"
status=0
for build in generic native; do
  flags="-O2 -ffp-contract=off -w"
  [ "$build" = native ] && flags="$flags -march=native"
  mkdir -p "$work/$build"
  for s in sc1 sc8 scm; do "$cc" $flags -c "$work/$s.c" -o "$work/$build/$s.o"; done
  "$cc" $flags benches/trig_ulps/harness.c "$work/$build"/sc1.o "$work/$build"/sc8.o "$work/$build"/scm.o -lm -o "$work/$build/h"
  ( "$work/$build/h" > "$work/$build.txt"; echo $? > "$work/$build.rc" ) &
done
wait
for build in generic native; do
  echo "$build ($cc): $(cat "$work/$build.txt")"
  [ "$(cat "$work/$build.rc")" = 0 ] || status=1
done
exit $status
