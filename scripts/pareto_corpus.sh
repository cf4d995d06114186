#!/bin/sh
# Issue 5's table: `-pareto` (ops, critical path, placed cycles at N=16, bits of error in f32 and
# f64 over 100 samples) for every straight-line single-function corpus file, one block per file.
# Sensor files hold several functions: run them by hand with -function=NAME.
# Usage (from the repository, after `cargo build --release`): scripts/pareto_corpus.sh > out.txt
set -u
cd "$(dirname "$0")/.."
P='atomise,place<pe=16>;atomise,zero-removal,place<pe=16>;atomise,zero-removal,swap,place<pe=16>;atomise,balance,place<pe=16>;atomise,inline<max-uses=8>,distribute,balance,place<pe=16>;atomise,balance,eqsat<budget=2>,place<pe=16>'
for f in ../shared/corpus/robotran/c/*.c ../shared/corpus/robotran/matlab/*.m ../shared/corpus/robotran/python/*.py; do
  case "$f" in *accelred*|*invdynared*|*sensor*) continue;; esac
  ./target/release/robovec-opt "$f" -pareto="$P" -pareto-samples=100 -o /dev/null 2>&1 | sed "s|^@|$(basename "$f") @|"
done
