#!/bin/sh
# Issue 31: `depth-bound` on every `dirdyna`/`invdyna` corpus file (the `accelred`/`invdynared`
# files hold loops robovec does not read), after `atomise` and after `atomise,default<depth>`:
# the lower bound on the critical path of any `+ − ×` program computing the same outputs, beside
# the critical path reached. One line per file and pipeline.
# Usage (from the repository, after `cargo build --release`): scripts/depth_bound.sh > out.txt
set -u
cd "$(dirname "$0")/.."
for f in $(scripts/dyna_files.sh); do
  for p in 'atomise,depth-bound' 'atomise,default<depth>,depth-bound'; do
    ./target/release/robovec-opt "$f" -passes="$p" -o /dev/null 2>&1 | grep '^depth-bound' | sed "s|^|$(basename "$f") $p: |"
  done
done
