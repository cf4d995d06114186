#!/usr/bin/env python3
"""Pinocchio's model and the shared random states for `cargo bench --bench pinocchio` (issue 14).

Usage: export_model.py URDF OUTDIR STATES SEED [floating|free-flyer]

URDF is a path or `erd:REL` (a file of example-robot-data), resolved like
`scripts/pinocchio_oracle.py` does; the model is built the oracle's way (fixed base:
`buildModelFromUrdf`; `floating`: root joint `JointModelComposite([PX, PY, PZ, RX, RY, RZ])`, the
layout of robovec's `--floating-base`; `free-flyer`: root joint `JointModelFreeFlyer`, robovec's
`--free-flyer`: `q` = base position, unit quaternion (x, y, z, w), joints; `v` = the base's
linear and angular velocity in its own frame, joints). The C++ harness cannot build it from the URDF itself
(`pinocchio::urdf::buildModel` crashed there: urdfdom ABI), so this script writes:

- `OUTDIR/model.txt`: `model.saveToText` (Boost text archive; the harness's `loadFromText`);
- `OUTDIR/states.txt`, whitespace-separated numbers in `repr` (exact) form:
  `STATES nq nv`, then `gx gy gz`, then per robovec coordinate `i` (`q[i+1]`, Pinocchio's joint
  order, one coordinate per velocity): `idx_q kind` (kind 0: `q[idx_q]` is the coordinate itself;
  1: a continuous joint, `q[idx_q], q[idx_q+1] = cos x, sin x`; 2: one of the free-flyer's six
  velocity coordinates, whose configuration is `q[0..7]` itself: its `x` are the position and
  the rotation vector, for information only), then per state the `nv` coordinates `x`,
  Pinocchio's `nq` configuration, `nv` velocities and `nv` accelerations.

Prints `{"path", "nq", "nv", "joints"}` as JSON on stdout. States are the oracle's distribution:
angles in [-pi, pi], lengths in [-0.2, 0.2], velocities and accelerations in [-2, 2]; the
free-flyer's quaternion uniform on the unit sphere (normalised Gaussian, then rounded).
"""
import json
import math
import os
import sys

import numpy as np
import pinocchio as pin

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
from pinocchio_oracle import build_model, locate  # noqa: E402


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    path = locate(sys.argv[1])
    out_dir, n, seed = sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    base = sys.argv[5] if len(sys.argv) > 5 else "fixed"
    if base not in ("fixed", "floating", "free-flyer"):
        sys.exit(f"base {base}: one of fixed, floating, free-flyer")
    free_flyer = base == "free-flyer"
    floating = base != "fixed"
    model = build_model(path, base)
    os.makedirs(out_dir, exist_ok=True)
    model.saveToText(os.path.join(out_dir, "model.txt"))

    joints = list(model.joints)[1:]
    layout = []  # (idx_q, kind, prismatic) per coordinate
    for j in joints:
        if floating and j.id == 1:
            layout.extend((j.idx_q + k, 2 if free_flyer else 0, k < 3) for k in range(6))
            continue
        if j.nv != 1:
            sys.exit(f"joint {j.shortname()} has {j.nv} degrees of freedom: not a tree of 1-dof joints")
        prismatic = j.shortname().replace("JointModel", "").startswith("P")
        layout.append((j.idx_q, 1 if j.nq == 2 else 0, prismatic))
    assert len(layout) == model.nv

    rng = np.random.default_rng(seed)
    words = [str(n), str(model.nq), str(model.nv)]
    words += [repr(float(g)) for g in model.gravity.linear]
    for idx_q, kind, _ in layout:
        words += [str(idx_q), str(kind)]
    for _ in range(n):
        x = [float(rng.uniform(-0.2, 0.2) if p else rng.uniform(-math.pi, math.pi)) for _, _, p in layout]
        v = rng.uniform(-2.0, 2.0, model.nv)
        a = rng.uniform(-2.0, 2.0, model.nv)
        q = pin.neutral(model)
        if free_flyer:
            quat = rng.normal(size=4)
            quat /= np.linalg.norm(quat)
            q[3:7] = quat
            q[0:3] = x[0:3]
            rot = pin.Quaternion(*(float(t) for t in (quat[3], quat[0], quat[1], quat[2]))).toRotationMatrix()
            x[3:6] = [float(t) for t in pin.log3(rot)]
        for (idx_q, kind, _), xi in zip(layout, x):
            if kind == 2:
                continue
            if kind == 1:
                q[idx_q], q[idx_q + 1] = math.cos(xi), math.sin(xi)
            else:
                q[idx_q] = xi
        words += [repr(xi) for xi in x]
        words += [repr(float(t)) for t in q]
        words += [repr(float(t)) for t in v]
        words += [repr(float(t)) for t in a]
    with open(os.path.join(out_dir, "states.txt"), "w") as f:
        f.write("\n".join(words) + "\n")
    json.dump({"path": path, "nq": model.nq, "nv": model.nv, "joints": list(model.names)[1:]}, sys.stdout)


if __name__ == "__main__":
    main()
