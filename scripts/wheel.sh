#!/usr/bin/env bash
# The Python module's wheel, as `pip install` builds it (docs/python.md): `maturin build` of
# `python/Cargo.toml` (release, abi3 for CPython >= 3.9) into `target/wheels`, installed into the
# Pinocchio venv that `scripts/test.sh` makes (`target/pinocchio-venv`), then `python/tests`
# against the installed package. The test command checks the same module built in the tests'
# own Cargo run (`target/python-dev`), not the wheel: run this when `pyproject.toml`,
# `python/Cargo.toml` or the package's layout changes (a release build: about 4 minutes on 2
# cores). Exits non-zero on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."

venv=target/pinocchio-venv
[ -x "$venv/bin/maturin" ] || { echo "run scripts/test.sh first: it makes $venv with maturin and pytest" >&2; exit 1; }
rm -rf target/wheels
"$venv/bin/maturin" build --locked --release --out target/wheels
"$venv/bin/pip" install -q --force-reinstall --no-deps target/wheels/robovec-*.whl
# Outside the repository, so that the installed package is the one imported.
tests="$PWD/python/tests"
cd "$(mktemp -d)"
"$OLDPWD/$venv/bin/python" -m pytest -q "$tests"
