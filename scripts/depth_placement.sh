#!/bin/sh
# Issue 31's placement goal on every `dirdyna`/`invdyna` corpus file: `recurrence<pe=N>` then
# `place<pe=N>` at N = 16 and 32 (DE10-Nano latencies), beside the critical path of the placed
# function, `default<depth>`'s critical path, and the resource bound ⌈add-side ops / N⌉,
# ⌈muls / N⌉ of the placed function (`place`'s lower bound is the larger of it and the path).
# Usage (from the repository, after `cargo build --release`): scripts/depth_placement.sh > out.txt
set -u
cd "$(dirname "$0")/.."
echo "file function | N | placed cycles | placed/critical path | critical path | default<depth> critical path | place lower bound | ops"
for f in ../shared/corpus/robotran/c/*.c ../shared/corpus/robotran/matlab/*.m ../shared/corpus/robotran/python/*.py; do
  case "$f" in *accelred*|*invdynared*) continue;; *dyna*) ;; *) continue;; esac
  d=$(./target/release/robovec-opt "$f" -passes='atomise,default<depth>' -stats -o /dev/null 2>&1 \
    | sed -n 's/.*critical path [0-9]* ops \/ \([0-9]*\) cycles.*/\1/p' | tail -1)
  for n in 16 32; do
    out=$(./target/release/robovec-opt "$f" -passes="atomise,cse,zero-removal,balance,cse,recurrence<pe=$n>,cse,place<pe=$n>" -stats -o /dev/null 2>&1)
    cp=$(echo "$out" | sed -n 's/.*critical path [0-9]* ops \/ \([0-9]*\) cycles.*/\1/p' | tail -1)
    ops=$(echo "$out" | sed -n 's/^@[^:]*: equations [0-9]*, ops \([0-9]*\) .*/\1/p' | tail -1)
    pl=$(echo "$out" | sed -n 's/.*PEs: \([0-9]*\) cycles, lower bound \([0-9]*\).*/\1 \2/p' | tail -1)
    set -- $pl
    echo "$(basename "$f") | $n | $1 | $(echo "scale=3; $1 / $cp" | bc) | $cp | $d | $2 | $ops"
  done
done
