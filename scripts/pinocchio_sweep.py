#!/usr/bin/env python3
"""Every URDF of example-robot-data against Pinocchio: robovec's generated functions on robots no
test names (docs/generator.md, "Robots checked").

Usage: pinocchio_sweep.py [REL ...] [--opt PATH] [--states N]

REL is a file under example-robot-data's `robots` folder (`xarm_description/urdf/xarm7.urdf`);
without one, every `.urdf` there. Run with the bench's environment (`target/pinocchio-venv`,
which `scripts/test.sh` installs): `target/pinocchio-venv/bin/python scripts/pinocchio_sweep.py`.
`--opt` is the robovec-opt binary (default `target/release/robovec-opt`; `cargo build --release`).

For each robot, on the fixed base and on Pinocchio's free flyer (`--free-flyer`), both with
`--continuous=cos-sin` (so that `q` is Pinocchio's own vector), N random states (default 2, seed
3, `scripts/pinocchio_oracle.py`): `invdyna` (`Qq` against `pinocchio.rnea`), `fordyna` (`qdd`
against `pinocchio.aba`), `rnea_derivatives`, `aba_derivatives` and `minv` (against
`computeRNEADerivatives`, `computeABADerivatives`, `computeMinverse`), each through
`-passes=default<ops>` and `-eval`, `--fold-params`. Prints one line per robot and base: `ok`
with the worst relative error (∞-norm of the difference over Pinocchio's ∞-norm, or over 1e-6
when that is smaller, per vector or matrix), or what differs by more than 1e-9, and robovec's
diagnostic for a function it refuses (a singular mass matrix; no moving joint on the fixed
base). A relative error above 1e-9 is not always robovec's: `--cond` prints cond(M), which
tells an ill-conditioned model.
Exit 0 always: this is a survey, not a test.
"""
import glob
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

CHECKS = [
    ("invdyna", [("Qq", "tau")]),
    ("fordyna", [("qdd", "aba")]),
    ("rnea_derivatives", [("dtau_dq", "dtau_dq"), ("dtau_dv", "dtau_dv")]),
    ("aba_derivatives", [("ddq_dq", "ddq_dq"), ("ddq_dv", "ddq_dv"), ("Minv", "Minv")]),
    ("minv", [("Minv", "Minv")]),
]


def relative_error(got, prefix, want):
    """∞-norm of got − want over want's (at least 1e-6); inf when an entry is missing or not finite."""
    rows = want if isinstance(want[0], list) else [want]
    norm = max(abs(x) for r in rows for x in r)
    worst = 0.0
    for i, r in enumerate(rows):
        for j, w in enumerate(r):
            name = f"{prefix}[{i + 1}][{j + 1}]" if isinstance(want[0], list) else f"{prefix}[{j + 1}]"
            g = got.get(name)
            if g is None:
                return float("inf")
            worst = max(worst, abs(g - w))
    # A reference that is rounding noise around 0 (Pinocchio's 1e-20 where robovec's is an
    # exact 0: a rotor's ∂τ/∂v, ∂q̈/∂v) is compared with 1e-6 for its norm.
    return worst / max(norm, 1e-6)


def sweep(python, opt, rel, base, states, cond):
    flags = ["--continuous=cos-sin"] + (["--free-flyer"] if base == "free-flyer" else [])
    p = subprocess.run([python, os.path.join(ROOT, "scripts", "pinocchio_oracle.py"), (rel if rel.startswith("/") else "erd:" + rel), str(states), "3", base],
                       capture_output=True, text=True, cwd=ROOT)
    if p.returncode:
        return f"oracle failed: {(p.stderr.strip().splitlines() or ['?'])[-1]}"
    o = json.loads(p.stdout)
    if not o["states"] or not o["states"][0]["qd"]:
        cond = False
    worst, bad, refused = 0.0, [], None
    for k, s in enumerate(o["states"]):
        given = {}
        for family, x in [("g", o["gravity"]), ("q", s["q_pinocchio"]), ("qd", s["qd"]), ("qdd", s["qdd"]), ("Qq", s["tau"])]:
            for i, v in enumerate(x):
                given[f"{family}[{i + 1}]"] = v
        state = os.path.join(ROOT, "target", "tmp", f"pinocchio_sweep_{os.getpid()}.json")
        os.makedirs(os.path.dirname(state), exist_ok=True)
        with open(state, "w") as f:
            json.dump(given, f)
        for function, checks in CHECKS:
            r = subprocess.run([opt, o["path"], "--fold-params", *flags, f"-function={function}", "-passes=default<ops>",
                                f"-eval={state}", "-o", os.devnull], capture_output=True, text=True)
            if r.returncode:
                errors = [l for l in r.stderr.splitlines() if l.startswith("error")]
                refused = refused or f"{function}: {(errors or ['exit ' + str(r.returncode)])[0]}"
                continue
            got = json.loads(r.stdout)["outputs"]
            for prefix, key in filter(lambda c: s[c[1]], checks):
                e = relative_error(got, prefix, s[key])
                worst = max(worst, e)
                if not e <= 1e-9:
                    bad.append(f"state {k} {function} {prefix} {e:.1e}")
    if o["states"]:
        os.remove(state)
    line = f"nv {len(o['states'][0]['qd'])}: "
    line += f"ok, worst {worst:.1e}" if not bad else "differs: " + "; ".join(bad)
    if refused:
        line += f"; refused {refused}"
    if cond:
        import numpy as np
        line += f"; cond(M) {max(np.linalg.cond(np.array(s['M'])) for s in o['states']):.1e}"
    return line


def main():
    args = sys.argv[1:]
    opt = os.path.join(ROOT, "target", "release", "robovec-opt")
    states, cond = 2, False
    if "--opt" in args:
        i = args.index("--opt")
        opt = args[i + 1]
        del args[i:i + 2]
    for a in list(args):
        if a.startswith("--states="):
            states = int(a.split("=", 1)[1])
            args.remove(a)
        elif a == "--cond":
            cond = True
            args.remove(a)
    if not os.path.exists(opt):
        sys.exit(f"{opt} missing: cargo build --release")
    roots = glob.glob(os.path.join(sys.prefix, "**", "share", "example-robot-data", "robots"), recursive=True)
    if not roots:
        sys.exit(f"example-robot-data not found under {sys.prefix}: run with target/pinocchio-venv/bin/python")
    rels = args or sorted(os.path.relpath(p, roots[0]) for p in glob.glob(os.path.join(roots[0], "*", "**", "*.urdf"), recursive=True))
    for rel in rels:
        for base in ("fixed", "free-flyer"):
            print(f"{rel} {base}: {sweep(sys.executable, opt, rel, base, states, cond)}", flush=True)


if __name__ == "__main__":
    main()
