#!/bin/sh
# Issue 31's placement goal on every `dirdyna`/`invdyna` corpus file: `recurrence<pe=N>` then
# `place<pe=N>` at N = 16 and 32 (DE10-Nano latencies). Per file and N: the placed cycles, the
# critical path of the placed function, `place`'s tight lower bound (per PE type the exact
# one-type relaxation with heads and tails: no placement of that function is shorter), and
# `default<depth>`'s critical path (the shortest path, with the most ops).
# Usage (from the repository, after `cargo build --release`; needs python3):
#   scripts/depth_placement.sh > out.txt
set -u
cd "$(dirname "$0")/.."
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "file | N | placed | critical path | tight bound | placed / path | placed / tight bound | default<depth> path | ops"
for f in $(scripts/dyna_files.sh); do
  d=$(./target/release/robovec-opt "$f" -passes='atomise,default<depth>' -stats -o /dev/null 2>&1 \
    | sed -n 's/.*critical path [0-9]* ops \/ \([0-9]*\) cycles.*/\1/p' | tail -1)
  for n in 16 32; do
    ./target/release/robovec-opt "$f" -passes="atomise,cse,zero-removal,balance,cse,recurrence<pe=$n>,cse,place<pe=$n>" \
      -report="$tmp/r.json" -o /dev/null 2>/dev/null
    python3 - "$tmp/r.json" "$(basename "$f")" "$n" "$d" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
p, s = r["placement"], r["stats"]
cp = s["asap_cycle"]
print(f'{sys.argv[2]} | {sys.argv[3]} | {p["cycles"]} | {cp} | {p["tight_lower_bound"]} | '
      f'{p["cycles"] / cp:.3f} | {p["cycles"] / p["tight_lower_bound"]:.3f} | {sys.argv[4]} | {s["ops"]["total"]}')
PY
  done
done
