# %% [markdown]
# # UR5's dynamics from Python with robovec (docs/python.md)
#
# Notebook-style: each `# %%` cell runs in Jupyter, VS Code or as a plain script
# (`python examples/python/ur5_dynamics.py`). Needs `pip install .` from the clone, and
# Pinocchio with example-robot-data (`pip install pin example-robot-data`) for the robot and the
# comparison.

# %%
import glob
import os
import sys
import time

import numpy as np
import pinocchio as pin

import robovec

# example-robot-data's files, under the environment's share folder (its PyPI package).
(urdf,) = glob.glob(os.path.join(sys.prefix, "**", "example-robot-data", "robots", "ur_description", "urdf",
                                 "ur5_robot.urdf"), recursive=True)[:1]

# %% [markdown]
# Load the robot on Pinocchio's free flyer and look at what the generator wrote.

# %%
m = robovec.load(urdf, free_flyer=True)
print(m.functions)
r = m.run("atomise,default<ops>")
print({f: rep["stats"]["ops"]["total"] for f, rep in r.report.items()}, "ops")

# %% [markdown]
# Compile the inverse dynamics (four states per call, robovec's own sin/cos) and the
# derivatives, and call them on Pinocchio's vectors.

# %%
t = time.perf_counter()
rnea = m.compile("rnea", pipeline="default<ops>", batch=4, trig="inline")
print(f"compiled in {time.perf_counter() - t:.2f} s: {rnea}")
model = pin.buildModelFromUrdf(urdf, pin.JointModelFreeFlyer())
data = model.createData()
rng = np.random.default_rng(0)
B = 1000
Q = np.stack([pin.integrate(model, pin.neutral(model), rng.uniform(-1, 1, model.nv)) for _ in range(B)])
V, A = rng.uniform(-1, 1, (B, model.nv)), rng.uniform(-1, 1, (B, model.nv))
tau = rnea(Q, V, A)  # (B, nv), one call
want = np.stack([pin.rnea(model, data, Q[k], V[k], A[k]) for k in range(B)])
print("worst relative difference against Pinocchio:", np.abs(tau - want).max() / np.abs(want).max())

# %%
dtau_dq, dtau_dv = m.compile("rnea_derivatives")(Q[0], V[0], A[0])
dq, dv, _ = pin.computeRNEADerivatives(model, data, Q[0], V[0], A[0])
print(dtau_dq.shape, np.abs(dtau_dq - dq).max(), np.abs(dtau_dv - dv).max())
