#!/bin/sh
# Issue 31's error on hard inputs: `accuracy<mode=hard;samples=1000>` (joint angles at and near
# 0, ±π/2, ±π, large rates, parameters over six orders of magnitude, then hill climbing on the
# f32 error; docs/accuracy.md) after `atomise` and after `atomise,default<depth>`, for every
# `dirdyna`/`invdyna` corpus file; errors against the input's equations. Two lines per file
# and pipeline: the accuracy summary and the worst point.
# Usage (from the repository, after `cargo build --release`): scripts/depth_hard.sh > out.txt
set -u
cd "$(dirname "$0")/.."
for f in $(scripts/dyna_files.sh); do
  for p in 'atomise' 'atomise,default<depth>'; do
    ./target/release/robovec-opt "$f" "-passes=$p,accuracy<mode=hard;samples=1000>" -o /dev/null 2>&1 |
      sed "s|^@|$(basename "$f") $p @|"
  done
done
