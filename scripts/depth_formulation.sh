#!/usr/bin/env bash
# The depth-optimised formulation (issue 31 item 4) against restructuring after the fact:
# ops and critical path (cycles; add 12, mul 7) of `invdyna`, `dirdyna` and `fordyna` under
# (a) `atomise` on --formulation=ops, (b) `atomise,default<depth>` on it,
# (c) `atomise` on --formulation=depth, (d) `atomise,default<depth>` on it.
# Usage: [FLAGS=--floating-base] scripts/depth_formulation.sh [URDF ...]   (default: the study
# robots below; FLAGS: more robovec-opt options, such as the base)
# Needs target/release (or $CARGO_TARGET_DIR/release) robovec-gen and robovec-opt.
set -euo pipefail
bin="${CARGO_TARGET_DIR:-target}/release"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
robots=("$@")
if [ ${#robots[@]} -eq 0 ]; then
  for t in serial:16 serial:64 serial:130 semi-serial:130 parallel:130; do
    f="$dir/${t%%:*}-${t##*:}.urdf"
    "$bin/robovec-gen" --topology "${t%%:*}" --dof "${t##*:}" --seed 1 -o "$f"
    robots+=("$f")
  done
fi
stat() { # file function formulation pipeline -> "ops cycles"
  "$bin/robovec-opt" "$1" -function="$2" --formulation="$3" -passes="$4" ${FLAGS:-} -stats -o /dev/null 2>&1 \
    | sed -n 's/.* ops \([0-9]*\) .*critical path [0-9]* ops \/ \([0-9]*\) cycles.*/\1 \2/p'
}
echo "robot function | (a) ops cp | (b) ops cp | (c) ops cp | (d) ops cp"
for r in "${robots[@]}"; do
  for fn in invdyna dirdyna fordyna; do
    a=$(stat "$r" $fn ops atomise); b=$(stat "$r" $fn ops 'atomise,default<depth>')
    c=$(stat "$r" $fn depth atomise); d=$(stat "$r" $fn depth 'atomise,default<depth>')
    echo "$(basename "$r" .urdf) $fn | $a | $b | $c | $d"
  done
done
