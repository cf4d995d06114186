#!/usr/bin/env python3
"""The Python module's costs side by side with C (issue 51's goals; docs/python.md).

Usage: python benches/python/overhead.py [ROBOT] [--function=rnea] [--batch=4] [--trig=inline]
                                         [--rounds=7]

ROBOT is a bench robot (ur5 by default: example-robot-data's file, from the venv's share
folder; free flyer for solo12, talos, tiago_pro) or a URDF path. Needs the wheel installed
(`pip install .`) in an environment with Pinocchio and example-robot-data (scripts/test.sh's
`target/pinocchio-venv` has them) and a C compiler. Measures, in a fresh cache folder:

1. the first `compile` (C written, compiled at -O2, loaded) and a cached one in a new process;
2. per call at B = 1: the Python call `f(q, v, a)` against the same one-state C function
   called from C on the same state, and their difference (the per-call overhead);
3. at B = 10^4: the Python call on (B, n) arrays against C calling the same shared object's
   batched function over the same states already in its lane-contiguous layout (and the
   one-state function for the remainder), as a C program would.

Python and C alternate, `rounds` times; each figure is the median over the rounds of the
median of its repetitions; ratios are C's time over Python's (1 = as fast as C).
"""
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
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
typedef void (*f3)(const double *, const double *, const double *, double *);
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec * 1e9 + t.tv_nsec; }
static int cmp(const void *a, const void *b) { double x = *(const double *)a, y = *(const double *)b; return (x > y) - (x < y); }
/* argv: SO SUFFIX NQ NV W B REPS. Prints: ns per one-state call, ns for B states. */
int main(int argc, char **argv)
{
    void *h = dlopen(argv[1], RTLD_NOW);
    if (!h) { fprintf(stderr, "%s\n", dlerror()); return 1; }
    char name[256];
    snprintf(name, sizeof name, "rv1_%s", argv[2]);
    f3 one = (f3)dlsym(h, name);
    snprintf(name, sizeof name, "rvw_%s", argv[2]);
    f3 lanes = (f3)dlsym(h, name);
    int nq = atoi(argv[3]), nv = atoi(argv[4]), w = atoi(argv[5]), b = atoi(argv[6]), reps = atoi(argv[7]);
    if (!one || (w > 1 && !lanes)) { fprintf(stderr, "no symbol\n"); return 1; }
    double *q = malloc(sizeof(double) * nq * b), *v = malloc(sizeof(double) * nv * b), *a = malloc(sizeof(double) * nv * b);
    double *tau = malloc(sizeof(double) * nv * b);
    for (int i = 0; i < nq * b; i++) q[i] = (double)rand() / RAND_MAX - 0.5;
    for (int i = 0; i < nv * b; i++) { v[i] = (double)rand() / RAND_MAX - 0.5; a[i] = (double)rand() / RAND_MAX - 0.5; }
    double *t1 = malloc(sizeof(double) * reps), *tb = malloc(sizeof(double) * reps);
    for (int r = 0; r < reps; r++) {
        double t = now();
        for (int k = 0; k < 1000; k++) one(q, v, a, tau);
        t1[r] = (now() - t) / 1000;
        t = now();
        int s = 0;
        if (w > 1)
            for (; s + w <= b; s += w) lanes(q + s * nq, v + s * nv, a + s * nv, tau + s * nv);
        for (; s < b; s++) one(q + s * nq, v + s * nv, a + s * nv, tau + s * nv);
        tb[r] = now() - t;
    }
    qsort(t1, reps, sizeof(double), cmp);
    qsort(tb, reps, sizeof(double), cmp);
    printf("%.3f %.1f\n", t1[reps / 2], tb[reps / 2]);
    return 0;
}
"""


def erd(rel):
    for root in glob.glob(os.path.join(sys.prefix, "**", "share", "example-robot-data", "robots"), recursive=True):
        p = os.path.join(root, rel)
        if os.path.exists(p):
            return p
    sys.exit(f"example-robot-data file {rel} not found under {sys.prefix}")


def median_time(f, reps, inner):
    ts = []
    for _ in range(reps):
        t = time.perf_counter_ns()
        for _ in range(inner):
            f()
        ts.append((time.perf_counter_ns() - t) / inner)
    return statistics.median(ts)


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
    exe = os.path.join(work, "harness")
    subprocess.run(["cc", "-O2", "-o", exe, os.path.join(work, "harness.c"), "-ldl"], check=True)
    rng = np.random.default_rng(1)
    big = 10_000
    q1, v1, a1 = rng.uniform(-0.5, 0.5, f.nq), rng.uniform(-0.5, 0.5, f.nv), rng.uniform(-0.5, 0.5, f.nv)
    qb, vb, ab = rng.uniform(-0.5, 0.5, (big, f.nq)), rng.uniform(-0.5, 0.5, (big, f.nv)), rng.uniform(-0.5, 0.5, (big, f.nv))
    py1, c1, pyb, cb = [], [], [], []
    for _ in range(rounds):
        py1.append(median_time(lambda: f(q1, v1, a1), 21, 1000))
        pyb.append(median_time(lambda: f(qb, vb, ab), 21, 1))
        out = subprocess.run([exe, str(f.library), function, str(f.nq), str(f.nv), str(batch), str(big), "21"],
                             check=True, capture_output=True, text=True).stdout.split()
        c1.append(float(out[0]))
        cb.append(float(out[1]))
    py1, c1, pyb, cb = (statistics.median(x) for x in (py1, c1, pyb, cb))
    print(f"robot {robot} ({'free flyer' if free else 'fixed base'}), {function}, batch={batch}, trig={trig}, "
          f"nq={f.nq} nv={f.nv}; {rounds} rounds, Python and C alternating")
    print("| measure | Python | C | C ÷ Python |")
    print("|---|---:|---:|---:|")
    print(f"| first compile (write C, cc -O2, load) | {first:.2f} s | | |")
    print(f"| cached compile, new process | {cached * 1e3:.1f} ms | | |")
    print(f"| cached compile, loaded already | {loaded * 1e6:.0f} µs | | |")
    print(f"| one state (B = 1), ns per call | {py1:.0f} | {c1:.0f} | {c1 / py1:.3f} |")
    print(f"| per-call overhead at B = 1 (Python − C) | {py1 - c1:.0f} ns | | |")
    print(f"| B = 10⁴, ns per state | {pyb / big:.1f} | {cb / big:.1f} | {cb / pyb:.3f} |")


if __name__ == "__main__":
    main()
