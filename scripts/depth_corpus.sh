#!/bin/sh
# Issue 31's table: `-pareto` (ops, critical path, placed cycles at N=16, bits of error in f32 and
# f64 over 100 samples against the input's equations) for every `dirdyna`/`invdyna` corpus file
# (the `accelred`/`invdynared` files hold loops robovec does not read), for `atomise`, the
# tree-height reduction of every sum (`default<depth>` before issue 31's recurrence pass) and
# `default<depth>` (with `recurrence`). One block per file.
# Usage (from the repository, after `cargo build --release`): scripts/depth_corpus.sh > out.txt
set -u
cd "$(dirname "$0")/.."
P='atomise,place<pe=16>;atomise,cse,zero-removal,balance,cse,place<pe=16>;atomise,cse,zero-removal,balance,cse,recurrence,cse,place<pe=16>'
for f in $(scripts/dyna_files.sh); do
  ./target/release/robovec-opt "$f" -pareto="$P" -pareto-samples=100 -o /dev/null 2>&1 | sed "s|^@|$(basename "$f") @|"
done
