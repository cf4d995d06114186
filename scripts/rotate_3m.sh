#!/bin/sh
# `rotate-3m` on every `dirdyna`/`invdyna` corpus file: `-pareto` (ops, critical path, placed
# cycles, bits of error in f32 and f64 over 100 samples against the input's equations) for the
# tree-height reduction of every sum, without and with `rotate-3m<pe=N>`, placed at N = 16 and 32.
# One block per file and N; raw output in docs/measurements/rotate-3m.txt.
# Usage (from the repository, after `cargo build --release`): scripts/rotate_3m.sh > out.txt
set -u
cd "$(dirname "$0")/.."
B='atomise,cse,zero-removal,balance,cse'
for f in $(scripts/dyna_files.sh); do
  for n in 16 32; do
    ./target/release/robovec-opt "$f" -pareto="$B,place<pe=$n>;$B,rotate-3m<pe=$n>,place<pe=$n>" -pareto-samples=100 \
      -o /dev/null 2>&1 | sed "s|^@|$(basename "$f") N=$n @|"
  done
done
