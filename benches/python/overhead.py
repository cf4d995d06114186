#!/usr/bin/env python3
"""The Python module's costs side by side with C (issue 51's goals; docs/python.md).

Usage: python benches/python/overhead.py [ROBOT] [--function=rnea] [--batch=4] [--trig=inline]
                                         [--rounds=7]

ROBOT is a bench robot (ur5 by default: example-robot-data's file, from the venv's share
folder; free flyer for solo12, talos, tiago_pro) or a URDF path. Needs the wheel installed
(`pip install .`) in an environment with Pinocchio and example-robot-data (scripts/test.sh's
`target/pinocchio-venv` has them) and a C compiler. Measures, in a fresh cache folder:

1. the first `compile` (C written, compiled with compile's default flags, loaded) and a cached
   one in a new process;
2. per call at B = 1: the Python call `f(q, v, a)` against the same one-state C function
   called from C on the same state, and their difference (the per-call overhead);
3. at B = 10^4: the Python call on (B, n) arrays against C calling the same shared object's
   batched function (`layout=rows`: W rows of the (B, n) arrays) over the same states (and the
   one-state function for the remainder), as a C program would.

Python and C alternate at every repetition (`rounds` × 21 of each), in one process: the C
harness is a shared object called through ctypes, once a repetition (1000 calls at B = 1, one
pass over the 10^4 states). Each time is the median of its repetitions; each ratio, C's time
over Python's (1 = as fast as C), is the median of the ratios of the pairs.
"""
import ctypes
import glob
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import robovec

ROBOTS = {
    "ur5": ("ur_description/urdf/ur5_robot.urdf", False),
    "panda": ("panda_description/urdf/panda.urdf", False),
    "solo12": ("solo_description/robots/solo12.urdf", True),
    "talos": ("talos_data/robots/talos_reduced.urdf", True),
    "tiago_pro": ("tiago_pro_description/robots/tiago_pro.urdf", True),
}

HARNESS = r"""
#include <time.h>
typedef void (*f4)(const double *, const double *, const double *, double *);
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec * 1e9 + t.tv_nsec; }
/* ns per call of the one-state function on one state, over `iters` calls. */
double one_state(void *one, const double *q, const double *v, const double *a, double *tau, int iters)
{
    double t = now();
    for (int k = 0; k < iters; k++) ((f4)one)(q, v, a, tau);
    return (now() - t) / iters;
}
/* ns for `b` states of (b, n) arrays: groups of `w` rows through `batched`, the rest through
   `one`, as a C program over its own arrays would. */
double states(void *one, void *batched, const double *q, const double *v, const double *a, double *tau,
              int nq, int nv, int w, int b)
{
    double t = now();
    int s = 0;
    if (w > 1)
        for (; s + w <= b; s += w) ((f4)batched)(q + s * nq, v + s * nv, a + s * nv, tau + s * nv);
    for (; s < b; s++) ((f4)one)(q + s * nq, v + s * nv, a + s * nv, tau + s * nv);
    return now() - t;
}
"""


def erd(rel):
    for root in glob.glob(os.path.join(sys.prefix, "**", "share", "example-robot-data", "robots"), recursive=True):
        p = os.path.join(root, rel)
        if os.path.exists(p):
            return p
    sys.exit(f"example-robot-data file {rel} not found under {sys.prefix}")


def per_call(f, calls):
    """ns per call of `f` over `calls` calls."""
    t = time.perf_counter_ns()
    for _ in range(calls):
        f()
    return (time.perf_counter_ns() - t) / calls


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    opts = dict(a[2:].split("=", 1) for a in sys.argv[1:] if a.startswith("--"))
    robot = args[0] if args else "ur5"
    function, batch = opts.get("function", "rnea"), int(opts.get("batch", "4"))
    trig, rounds = opts.get("trig", "inline"), int(opts.get("rounds", "7"))
    if function != "rnea":
        sys.exit("the C harness calls rnea-shaped functions (q, v, a -> tau): --function=rnea")
    path, free = ROBOTS[robot] if robot in ROBOTS else (robot, False)
    urdf = erd(path) if robot in ROBOTS else path
    cache = tempfile.mkdtemp(prefix="robovec-bench-cache-")
    os.environ["ROBOVEC_CACHE_DIR"] = cache
    m = robovec.load(urdf, free_flyer=free)
    t = time.perf_counter()
    f = m.compile(function, batch=batch, trig=trig)
    first = time.perf_counter() - t
    # A cached compile in a new process (the object is on disk, not yet loaded).
    code = (
        "import time, robovec; m = robovec.load(%r, free_flyer=%r); t = time.perf_counter(); "
        "m.compile(%r, batch=%d, trig=%r); print(time.perf_counter() - t)" % (urdf, free, function, batch, trig)
    )
    cached = float(subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout)
    t = time.perf_counter()
    m.compile(function, batch=batch, trig=trig)
    loaded = time.perf_counter() - t
    work = tempfile.mkdtemp(prefix="robovec-bench-")
    with open(os.path.join(work, "harness.c"), "w") as h:
        h.write(HARNESS)
    so = os.path.join(work, "harness.so")
    subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", so, os.path.join(work, "harness.c")], check=True)
    harness = ctypes.CDLL(so)
    p = ctypes.POINTER(ctypes.c_double)
    harness.one_state.restype = harness.states.restype = ctypes.c_double
    harness.one_state.argtypes = [ctypes.c_void_p, p, p, p, p, ctypes.c_int]
    harness.states.argtypes = [ctypes.c_void_p, ctypes.c_void_p, p, p, p, p] + [ctypes.c_int] * 4
    lib = ctypes.CDLL(str(f.library))
    one = ctypes.cast(getattr(lib, f"rv1_{function}"), ctypes.c_void_p)
    batched = ctypes.cast(getattr(lib, f"rvw_{function}"), ctypes.c_void_p) if batch > 1 else None
    rng = np.random.default_rng(1)
    big = 10_000
    q1, v1, a1 = rng.uniform(-0.5, 0.5, f.nq), rng.uniform(-0.5, 0.5, f.nv), rng.uniform(-0.5, 0.5, f.nv)
    qb, vb, ab = rng.uniform(-0.5, 0.5, (big, f.nq)), rng.uniform(-0.5, 0.5, (big, f.nv)), rng.uniform(-0.5, 0.5, (big, f.nv))
    tau1, taub = np.empty(f.nv), np.empty((big, f.nv))
    ptr = lambda x: x.ctypes.data_as(p)
    # Python and C alternate at every repetition, in one process: each pair sees the same
    # machine state. A repetition at B = 1 is 1000 calls.
    py1, c1, pyb, cb = [], [], [], []
    for _ in range(rounds * 21):
        py1.append(per_call(lambda: f(q1, v1, a1), 1000))
        c1.append(harness.one_state(one, ptr(q1), ptr(v1), ptr(a1), ptr(tau1), 1000))
        pyb.append(per_call(lambda: f(qb, vb, ab), 1))
        cb.append(harness.states(one, batched, ptr(qb), ptr(vb), ptr(ab), ptr(taub), f.nq, f.nv, batch, big))
    ratio1 = statistics.median(c / p for c, p in zip(c1, py1))
    ratiob = statistics.median(c / p for c, p in zip(cb, pyb))
    py1, c1, pyb, cb = (statistics.median(x) for x in (py1, c1, pyb, cb))
    print(f"robot {robot} ({'free flyer' if free else 'fixed base'}), {function}, batch={batch}, trig={trig}, "
          f"nq={f.nq} nv={f.nv}; {rounds * 21} repetitions, Python and C alternating")
    print("| measure | Python | C | C ÷ Python |")
    print("|---|---:|---:|---:|")
    print(f"| first compile (write C, cc with the default flags, load) | {first:.2f} s | | |")
    print(f"| cached compile, new process | {cached * 1e3:.1f} ms | | |")
    print(f"| cached compile, loaded already | {loaded * 1e6:.0f} µs | | |")
    print(f"| one state (B = 1), ns per call | {py1:.0f} | {c1:.0f} | {ratio1:.3f} |")
    print(f"| per-call overhead at B = 1 (Python − C) | {py1 - c1:.0f} ns | | |")
    print(f"| B = 10⁴, ns per state | {pyb / big:.1f} | {cb / big:.1f} | {ratiob:.3f} |")


if __name__ == "__main__":
    main()
