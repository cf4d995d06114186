#!/usr/bin/env python3
"""Pinocchio reference values for robovec's URDF front end (issue 14).

Usage: pinocchio_oracle.py URDF STATES SEED [fixed|floating|free-flyer]

With `floating`, the model is on Robotran's floating base: root joint
`JointModelComposite([PX, PY, PZ, RX, RY, RZ])` (robovec's `--floating-base`, T1-T3 then R1-R3),
whose six coordinates are plain lengths and angles, so q, qd, qdd map one to one.
With `free-flyer`, the root joint is `JointModelFreeFlyer()` (robovec's `--free-flyer`): q starts
with the base position (uniform in [-1, 1]) and a random unit quaternion (x, y, z, w), seven
coordinates for the base's six velocities.

URDF is a path, or `erd:REL` for a file of example-robot-data (`erd:ur_description/urdf/ur5_robot.urdf`),
found under the installed package's share folder. Builds the fixed-base model with
`pinocchio.buildModelFromUrdf` and prints JSON on stdout:
  {"path", "joints": [names in Pinocchio's order], "gravity": [gx, gy, gz],
   "states": [{"q": [...], "qd": [...], "qdd": [...], "tau": [...], "M": [[...]], "nle": [...],
               "aba": [...]}]}
(q: one coordinate per joint, robovec's q[1..]; q_pinocchio: Pinocchio's own configuration vector,
nq long: a continuous joint's (cos, sin))
where tau = rnea(q, qd, qdd), M = crba(q) (Pinocchio fills the upper triangle only: symmetrized
here), nle = nonLinearEffects(q, qd) and aba = aba(q, qd, tau) (forward dynamics: qdd again, as
Pinocchio's own algorithm computes it).
with one angle (or length) per joint: a continuous joint's (cos, sin) pair is built from it.
States are uniform: angles in [-pi, pi], lengths in [-0.2, 0.2], velocities and accelerations in [-2, 2].
"""
import glob
import json
import math
import os
import sys

import numpy as np
import pinocchio as pin


def locate(spec):
    if not spec.startswith("erd:"):
        return spec
    rel = spec[4:]
    roots = glob.glob(os.path.join(sys.prefix, "**", "share", "example-robot-data", "robots"), recursive=True)
    for r in roots:
        p = os.path.join(r, rel)
        if os.path.exists(p):
            return p
    sys.exit(f"example-robot-data file {rel} not found under {sys.prefix}")


def build_model(path, base):
    """Pinocchio's model of the URDF at `path`: fixed base, on the root joint
    JointModelComposite([PX, PY, PZ, RX, RY, RZ]) (`floating`, the layout of robovec's
    --floating-base) or on JointModelFreeFlyer (`free-flyer`, robovec's --free-flyer)."""
    if base == "fixed":
        return pin.buildModelFromUrdf(path)
    if base == "free-flyer":
        return pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
    root = pin.JointModelComposite()
    for j in (pin.JointModelPX(), pin.JointModelPY(), pin.JointModelPZ(),
              pin.JointModelRX(), pin.JointModelRY(), pin.JointModelRZ()):
        root.addJoint(j)
    return pin.buildModelFromUrdf(path, root)


def main():
    path = locate(sys.argv[1])
    n, seed = int(sys.argv[2]), int(sys.argv[3])
    base = sys.argv[4] if len(sys.argv) > 4 else "fixed"
    if base not in ("fixed", "floating", "free-flyer"):
        sys.exit(f"unknown base {base}: expected fixed, floating or free-flyer")
    floating = base == "floating"
    model = build_model(path, base)
    data = model.createData()
    rng = np.random.default_rng(seed)
    joints = list(model.joints)[1:]
    out = {"path": path, "joints": list(model.names)[1:], "gravity": list(map(float, model.gravity.linear)), "states": []}
    for _ in range(n):
        q = pin.neutral(model)
        v = rng.uniform(-2.0, 2.0, model.nv)
        a = rng.uniform(-2.0, 2.0, model.nv)
        coords = []
        for j in joints:
            if base == "free-flyer" and j.id == 1:
                quat = rng.normal(size=4)
                x = np.concatenate([rng.uniform(-1.0, 1.0, 3), quat / np.linalg.norm(quat)])
                coords.extend(map(float, x))
                q[j.idx_q:j.idx_q + 7] = x
                continue
            if floating and j.id == 1:
                x = np.concatenate([rng.uniform(-0.2, 0.2, 3), rng.uniform(-math.pi, math.pi, 3)])
                coords.extend(map(float, x))
                q[j.idx_q:j.idx_q + 6] = x
                continue
            if j.nv != 1:
                sys.exit(f"joint {j.shortname()} has {j.nv} degrees of freedom: not a fixed-base tree of 1-dof joints")
            prismatic = j.shortname().replace("JointModel", "").startswith("P")
            x = rng.uniform(-0.2, 0.2) if prismatic else rng.uniform(-math.pi, math.pi)
            coords.append(x)
            if j.nq == 2:
                q[j.idx_q] = math.cos(x)
                q[j.idx_q + 1] = math.sin(x)
            else:
                q[j.idx_q] = x
        tau = pin.rnea(model, data, q, v, a)
        upper = np.triu(pin.crba(model, data, q))
        mass = upper + np.triu(upper, 1).T
        nle = pin.nonLinearEffects(model, data, q, v)
        aba = pin.aba(model, data, q, v, tau)
        # Derivatives along the tangent space (issue 50): ∂τ/∂q, ∂τ/∂v at (q, v, a), and
        # ∂q̈/∂q, ∂q̈/∂v, M⁻¹ at (q, v, τ) (Pinocchio fills M⁻¹'s upper triangle only).
        dtau_dq, dtau_dv, _ = (np.array(x) for x in pin.computeRNEADerivatives(model, data, q, v, a))
        ddq_dq, ddq_dv, minv = (np.array(x) for x in pin.computeABADerivatives(model, data, q, v, tau))
        minv = np.triu(minv) + np.triu(minv, 1).T
        out["states"].append({
            "q": coords,
            "q_pinocchio": list(map(float, q)),
            "qd": list(map(float, v)),
            "qdd": list(map(float, a)),
            "tau": list(map(float, tau)),
            "M": [list(map(float, row)) for row in mass],
            "nle": list(map(float, nle)),
            "aba": list(map(float, aba)),
            "dtau_dq": [list(map(float, row)) for row in dtau_dq],
            "dtau_dv": [list(map(float, row)) for row in dtau_dv],
            "ddq_dq": [list(map(float, row)) for row in ddq_dq],
            "ddq_dv": [list(map(float, row)) for row in ddq_dv],
            "Minv": [list(map(float, row)) for row in minv],
        })
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
