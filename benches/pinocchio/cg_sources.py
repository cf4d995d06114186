#!/usr/bin/env python3
"""Pinocchio's CppADCodeGen C sources of one model (issue 30), for `cargo bench --bench pinocchio`
(its CG contestants) and `cg_ops.py` (their operation counts).

Usage: cg_sources.py MODEL.txt OUTDIR   (run with the Pinocchio venv's Python)

MODEL.txt is `model.saveToText` of `export_model.py`. `cg_export` (`cg_export.cpp`, compiled once
with `g++ -O1` and the bench's shared Pinocchio flags, `pinocchio_cxx_flags.txt`, and cached in
`target/pinocchio_bench/cg_export-HASH` under the hash of its source, flags and the venv's
prefix: 5-9 min) writes CppADCodeGen's library sources of `rnea`, `crba` and `aba` into
OUTDIR/rnea, OUTDIR/crba, OUTDIR/aba; the function of each is `cg_F_forward_zero.c` (see
`cg_export.cpp` for its signature and layout). Skipped when OUTDIR/stamp names the same model
text and exporter. Prints `{"nq", "nv", "rnea", "crba", "aba"}` as JSON (the three paths of
`cg_F_forward_zero.c`).

Needs `cmeel-cppad` and `cmeel-cppadcodegen` (CppAD's and CppADCodeGen's headers, CppAD's
`libcppad_lib`) besides `pin`, `cmeel-eigen` and `example-robot-data`.
"""
import hashlib
import json
import os
import re
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
HERE = os.path.join(ROOT, "benches", "pinocchio")
WORK = os.path.join(ROOT, "target", "pinocchio_bench")
FUNCTIONS = ["rnea", "crba", "aba"]
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


def export(exe, model, out):
    """Writes CppADCodeGen's sources of `model` (a saveToText file) into `out` unless its stamp
    says they are there; returns (nq, nv) and the paths of the three `cg_F_forward_zero.c`."""
    with open(model, "rb") as f:
        stamp = hashlib.sha256(f.read() + exe.encode()).hexdigest()
    stamp_path = os.path.join(out, "stamp")
    paths = {f: os.path.join(out, f, f"cg_{f}_forward_zero.c") for f in FUNCTIONS}
    try:
        with open(stamp_path) as f:
            old = f.read().split()
    except OSError:
        old = []
    if len(old) == 3 and old[0] == stamp and all(os.path.exists(p) for p in paths.values()):
        nq, nv = int(old[1]), int(old[2])
    else:
        os.makedirs(out, exist_ok=True)
        m = re.search(r"nq (\d+) nv (\d+)", run([exe, model, out]))
        nq, nv = int(m.group(1)), int(m.group(2))
        with open(stamp_path, "w") as f:
            f.write(f"{stamp} {nq} {nv}\n")
    return nq, nv, paths


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    _, exe = exporter(sys.executable)
    nq, nv, paths = export(exe, sys.argv[1], sys.argv[2])
    json.dump({"nq": nq, "nv": nv, **paths}, sys.stdout)


if __name__ == "__main__":
    main()
