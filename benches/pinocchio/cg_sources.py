#!/usr/bin/env python3
"""Pinocchio's CppADCodeGen C sources of one model (issue 30), for `cargo bench --bench pinocchio`
(its CG contestants) and `cg_ops.py` (their operation counts).

Usage: cg_sources.py MODEL.txt OUTDIR [FUNCTION ...]   (run with the Pinocchio venv's Python)

MODEL.txt is `model.saveToText` of `export_model.py`; FUNCTION one of `FUNCTIONS` (default:
`rnea crba aba`). `cg_export` (`cg_export.cpp`, compiled once with `g++ -O1` and the bench's
shared Pinocchio flags, `pinocchio_cxx_flags.txt`, and cached in
`target/pinocchio_bench/cg_export-HASH` under the hash of its source, flags and the venv's
prefix: 5-9 min) writes CppADCodeGen's library sources of each FUNCTION into OUTDIR/FUNCTION;
the function of each is `cg_F_forward_zero.c` (see `cg_export.cpp` for its signature and
layout). A function is skipped when OUTDIR/FUNCTION/stamp names the same model text and
exporter. Prints `{"nq", "nv", F: path of cg_F_forward_zero.c, ...}` as JSON.

Needs `cmeel-cppad` and `cmeel-cppadcodegen` (CppAD's and CppADCodeGen's headers, CppAD's
`libcppad_lib`) besides `pin`, `cmeel-eigen` and `example-robot-data`.
"""
import hashlib
import json
import os
import re
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
HERE = os.path.join(ROOT, "benches", "pinocchio")
WORK = os.path.join(ROOT, "target", "pinocchio_bench")
FUNCTIONS = ["rnea", "crba", "aba", "minv", "rnea_derivatives", "aba_derivatives"]
DEFAULT = ["rnea", "crba", "aba"]
PACKAGES = "pin cmeel-eigen cmeel-cppad cmeel-cppadcodegen example-robot-data"


def cxx_flags():
    """-O1 (the exporter runs once per robot), then the bench's shared Pinocchio flags."""
    with open(os.path.join(HERE, "pinocchio_cxx_flags.txt")) as f:
        shared = [l.strip() for l in f if l.strip() and not l.strip().startswith("#")]
    return ["-O1"] + shared


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stdout}{r.stderr}")
    return r.stdout + r.stderr


def exporter(python):
    """The venv's `cmeel.prefix` and the cached `cg_export` (compiled here when missing)."""
    prefix = run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]).strip()
    prefix = os.path.join(prefix, "cmeel.prefix")
    for h in ["include/pinocchio/codegen/cppadcg-algo.hpp", "include/cppad/cg.hpp", "include/eigen3/Eigen/Core"]:
        if not os.path.exists(os.path.join(prefix, h)):
            sys.exit(f"{h} missing under {prefix}: {python} -m pip install {PACKAGES}")
    src = os.path.join(HERE, "cg_export.cpp")
    flags = cxx_flags()
    key = hashlib.sha256((open(src).read() + " ".join(flags) + prefix).encode()).hexdigest()[:16]
    exe = os.path.join(WORK, f"cg_export-{key}")
    if not os.path.exists(exe):
        os.makedirs(WORK, exist_ok=True)
        print(f"compiling {src} (5-9 min; cached as {exe})", file=sys.stderr)
        lib = os.path.join(prefix, "lib")
        inc = [f"-I{os.path.join(prefix, 'include')}", f"-I{os.path.join(prefix, 'include', 'eigen3')}"]
        run(["g++", *flags, *inc, src, "-o", exe + ".tmp", f"-L{lib}", f"-Wl,-rpath,{lib}",
             "-lcppad_lib", "-lboost_serialization", "-ldl"])
        os.replace(exe + ".tmp", exe)
    return prefix, exe


def export(exe, model, out, functions=DEFAULT):
    """Writes CppADCodeGen's sources of each of `functions` for `model` (a saveToText file) into
    `out`/F unless its stamp says they are there; returns (nq, nv) and {F: path of
    cg_F_forward_zero.c}. The stamp also holds the exporter's wall time (s)."""
    with open(model, "rb") as f:
        stamp = hashlib.sha256(f.read() + exe.encode()).hexdigest()
    paths, dims = {}, None
    for fn in functions:
        if fn not in FUNCTIONS:
            sys.exit(f"unknown function `{fn}`; functions: {' '.join(FUNCTIONS)}")
        stamp_path = os.path.join(out, fn, "stamp")
        path = os.path.join(out, fn, f"cg_{fn}_forward_zero.c")
        try:
            with open(stamp_path) as f:
                old = f.read().split()
        except OSError:
            old = []
        if len(old) >= 3 and old[0] == stamp and os.path.exists(path):
            nq, nv = int(old[1]), int(old[2])
        else:
            os.makedirs(os.path.join(out, fn), exist_ok=True)
            t0 = time.monotonic()
            m = re.search(r"nq (\d+) nv (\d+)", run([exe, model, out, fn]))
            seconds = time.monotonic() - t0
            nq, nv = int(m.group(1)), int(m.group(2))
            with open(stamp_path, "w") as f:
                f.write(f"{stamp} {nq} {nv} {seconds:.1f}\n")
        paths[fn] = path
        dims = (nq, nv)
    return dims[0], dims[1], paths


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    _, exe = exporter(sys.executable)
    nq, nv, paths = export(exe, sys.argv[1], sys.argv[2], sys.argv[3:] or DEFAULT)
    json.dump({"nq": nq, "nv": nv, **paths}, sys.stdout)


if __name__ == "__main__":
    main()
