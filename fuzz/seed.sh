#!/usr/bin/env bash
# Builds the seed corpora fuzz/corpus/<target>/ from the shared Robotran corpus, the shipped example
# and robovec's own .rvir files. Nothing here is committed: fuzz/corpus is in .gitignore.
#
#   fuzz/seed.sh            # SHARED=../../shared/corpus/robotran  MAX=8192 by default
#
# Robotran files are cut to their first MAX bytes (banner, prologue, the first statements):
# whole files (up to 460 KB) make every execution slow. A C seed with a header is the .c text, a
# NUL byte, then the .h text (the NUL splits them in fuzz_targets/front_c.rs).
set -euo pipefail
cd "$(dirname "$0")"
SHARED=${SHARED:-../../shared/corpus/robotran}
MAX=${MAX:-8192}
test -d "$SHARED" || { echo "no Robotran corpus at $SHARED (set SHARED=...)" >&2; exit 1; }
mkdir -p corpus/parse_text corpus/roundtrip corpus/front_c corpus/front_matlab corpus/front_python corpus/front_urdf corpus/target_json
cp ../examples/*/*.urdf corpus/front_urdf/
# target descriptions: 4 bytes of PE counts, word and flags, then the JSON
for f in ../examples/targets/*.json; do { printf '\x07\x07\x1a\x01'; cat "$f"; } > "corpus/target_json/$(basename "$f")"; done

for f in "$SHARED"/c/*.c ../examples/*/*.c; do
    b=$(basename "$f" .c)
    head -c "$MAX" "$f" > "corpus/front_c/$b.c"
    h="${f%.c}.h"
    if [ -f "$h" ]; then
        { head -c "$MAX" "$f"; printf '\0'; head -c 2048 "$h"; } > "corpus/front_c/$b.with_h"
    fi
done
for f in "$SHARED"/matlab/*.m; do head -c "$MAX" "$f" > "corpus/front_matlab/$(basename "$f")"; done
for f in "$SHARED"/python/*.py; do head -c "$MAX" "$f" > "corpus/front_python/$(basename "$f")"; done

# .rvir seeds: robovec's IR tests, and the parsed / atomised / timed IR that robovec-opt prints for
# the example and for every corpus file of at most 8 KB (loop files are rejected and skipped).
find ../tests/ir -name '*.rvir' -exec cp {} corpus/parse_text/ \;
cargo build --quiet --release --manifest-path ../Cargo.toml --bin robovec-opt
BIN=../target/release/robovec-opt
for f in ../examples/*/*.c "$SHARED"/c/*.c "$SHARED"/matlab/*.m "$SHARED"/python/*.py; do
    [ "$(stat -c %s "$f")" -le 8192 ] || continue
    for p in "" atomise atomise,asap-alap "atomise,interleave<states=2>"; do
        out="corpus/parse_text/$(basename "$f").${p:-parsed}.rvir"
        "$BIN" "$f" -passes="$p" -o "$out" 2>/dev/null || rm -f "$out"
    done
done
cp corpus/parse_text/* corpus/roundtrip/
for t in corpus/*; do echo "$t: $(ls "$t" | wc -l) seeds"; done
