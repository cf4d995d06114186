#!/bin/sh
# The corpus's `dirdyna`/`invdyna` files that robovec reads (the `accelred`/`invdynared` files
# hold loops), one path per line, relative to the repository: the files of issue 31's tables
# (`depth_corpus.sh`, `depth_bound.sh`, `depth_placement.sh`).
cd "$(dirname "$0")/.."
for f in ../shared/corpus/robotran/c/*.c ../shared/corpus/robotran/matlab/*.m ../shared/corpus/robotran/python/*.py; do
  case "$f" in *accelred*|*invdynared*) continue;; *dyna*) echo "$f";; esac
done
