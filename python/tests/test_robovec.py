"""The Python module against Pinocchio (issue 51): load, run, passes, errors, and the compiled
functions over numpy on the bench's robots, fixed base and free flyer.

Run by scripts/test.sh in the Pinocchio venv after installing the wheel built from this clone.
The C is compiled at -O0 (correctness builds); the cache is a fresh temporary folder.
"""
import glob
import os
import sys

import numpy as np
import pinocchio as pin
import pytest

import robovec

ROBOTS = {
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",
    "solo12": "solo_description/robots/solo12.urdf",
    "talos": "talos_data/robots/talos_reduced.urdf",
    "tiago_pro": "tiago_pro_description/robots/tiago_pro.urdf",
}
HERE = os.path.dirname(os.path.abspath(__file__))
ARM = os.path.join(HERE, "..", "..", "examples", "three_link_arm", "three_link_arm.urdf")


@pytest.fixture(autouse=True, scope="session")
def cache(tmp_path_factory):
    os.environ["ROBOVEC_CACHE_DIR"] = str(tmp_path_factory.mktemp("cache"))


def erd(rel):
    """A file of example-robot-data, under the installed package's share folder."""
    for root in glob.glob(os.path.join(sys.prefix, "**", "share", "example-robot-data", "robots"), recursive=True):
        p = os.path.join(root, rel)
        if os.path.exists(p):
            return p
    raise FileNotFoundError(f"example-robot-data file {rel} under {sys.prefix}")


def pinocchio_model(path, free_flyer):
    if free_flyer:
        return pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
    return pin.buildModelFromUrdf(path)


def has_continuous(model):
    return model.nq > model.nv + (1 if model.joints[1].shortname() == "JointModelFreeFlyer" else 0)


def states(model, n, seed):
    """`n` random states (q on the configuration manifold: Pinocchio's own vectors)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        q = pin.integrate(model, pin.neutral(model), rng.uniform(-1.5, 1.5, model.nv))
        out.append((q, rng.uniform(-2, 2, model.nv), rng.uniform(-2, 2, model.nv)))
    return out


def sym(m):
    """Pinocchio fills the upper triangle of M and M⁻¹."""
    return np.triu(m) + np.triu(m, 1).T


def expected(name, model, data, q, v, a):
    """Pinocchio's value of the function `name` (a tuple for several outputs); `a` is τ for the
    functions that take τ."""
    if name == "rnea":
        return pin.rnea(model, data, q, v, a).copy()
    if name == "crba":
        return sym(pin.crba(model, data, q).copy())
    if name == "nle":
        return pin.nonLinearEffects(model, data, q, v).copy()
    if name == "aba":
        return pin.aba(model, data, q, v, a).copy()
    if name == "rnea_derivatives":
        dq, dv, _ = pin.computeRNEADerivatives(model, data, q, v, a)
        return dq.copy(), dv.copy()
    if name == "aba_derivatives":
        dq, dv, minv = pin.computeABADerivatives(model, data, q, v, a)
        return dq.copy(), dv.copy(), sym(minv.copy())
    if name == "minv":
        return sym(pin.computeMinverse(model, data, q).copy())
    raise ValueError(name)


def args_of(name, q, v, a):
    return {"crba": (q,), "minv": (q,), "nle": (q, v)}.get(name, (q, v, a))


def relative(got, want):
    got, want = np.atleast_1d(got), np.atleast_1d(want)
    return np.abs(got - want).max() / max(np.abs(want).max(), 1e-300)


def check(robot, free_flyer, functions, batch=4):
    path = erd(ROBOTS[robot]) if robot in ROBOTS else robot
    model = pinocchio_model(path, free_flyer)
    data = model.createData()
    m = robovec.load(path, free_flyer=free_flyer, continuous="cos-sin" if has_continuous(model) else None)
    xs = states(model, 6, 11)
    for name in functions:
        f = m.compile(name, batch=batch, cflags=["-O0"])
        assert (f.nq, f.nv) == (model.nq, model.nv)
        want = [expected(name, model, data, *s) for s in xs]
        # One state a call.
        for s, w in zip(xs, want):
            got = f(*args_of(name, *s))
            for g, x in zip(got if isinstance(got, tuple) else (got,), w if isinstance(w, tuple) else (w,)):
                assert g.shape == x.shape
                assert relative(g, x) <= 1e-9, (robot, free_flyer, name, relative(g, x))
        # All six at once: one full group of 4 lanes and 2 left over.
        stacked = [np.stack(c) for c in zip(*[args_of(name, *s) for s in xs])]
        got = f(*stacked)
        for k, w in enumerate(want):
            gs = got if isinstance(got, tuple) else (got,)
            ws = w if isinstance(w, tuple) else (w,)
            for g, x in zip(gs, ws):
                assert g.shape[0] == len(xs)
                assert relative(g[k], x) <= 1e-9, (robot, free_flyer, name, "batched", k)


ALL = ["rnea", "crba", "nle", "aba", "rnea_derivatives", "aba_derivatives", "minv"]


@pytest.mark.parametrize("free_flyer", [False, True])
def test_every_function_on_ur5_matches_pinocchio(free_flyer):
    check("ur5", free_flyer, ALL)


@pytest.mark.parametrize("robot,free_flyer", [("panda", False), ("solo12", True)])
def test_every_function_on_panda_and_solo_matches_pinocchio(robot, free_flyer):
    check(robot, free_flyer, ALL, batch=2)


@pytest.mark.parametrize("robot", ["talos", "tiago_pro"])
def test_dynamics_of_the_humanoid_and_the_mobile_manipulator_match_pinocchio(robot):
    # Their derivative functions' C takes minutes to compile: the bench covers them.
    check(robot, True, ["rnea", "crba", "aba"], batch=8)


def test_many_states_with_the_default_flags():
    # 101 states: the GIL released (64 states or more), 25 groups of 4 rows and one left over,
    # the C built with compile's default flags (-march=native on x86-64); and 0 states.
    path = erd(ROBOTS["ur5"])
    model = pinocchio_model(path, False)
    data = model.createData()
    rnea = robovec.load(path).compile("rnea", batch=4)
    xs = states(model, 101, 5)
    got = rnea(*[np.stack(c) for c in zip(*xs)])
    assert got.shape == (101, model.nv)
    for k, (q, v, a) in enumerate(xs):
        assert relative(got[k], pin.rnea(model, data, q, v, a)) <= 1e-9, k
    empty = np.zeros((0, model.nq))
    assert rnea(empty, empty, empty).shape == (0, model.nv)


def test_continuous_joints_as_pinocchio_pairs():
    check(ARM, False, ["rnea", "aba", "rnea_derivatives"])


def test_load_run_and_passes():
    m = robovec.load(erd(ROBOTS["ur5"]))
    assert m.functions == ["invdyna", "dirdyna"]
    assert "func @invdyna" in m.ir and m.report is None
    r = m.run("atomise,default<ops>")
    assert r.functions == m.functions
    assert set(r.report) == {"invdyna", "dirdyna"}
    rep = r.report["invdyna"]
    assert rep["function"] == "invdyna" and rep["stats"]["ops"]["total"] > 0
    # A run of a run: the report of the one function asked for.
    one = r.run("dce<outputs=Qq[1]>", function="invdyna")
    assert one.report["function"] == "invdyna"
    assert one.report["stats"]["ops"]["total"] < rep["stats"]["ops"]["total"]
    names = [p["name"] for p in robovec.passes()]
    assert "cse" in names and "codegen" in names
    assert any(q["name"] == "outputs" for p in robovec.passes() if p["name"] == "dce" for q in p["params"])


def test_errors_carry_the_command_lines_diagnostics(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text('<robot name="r">\n  <link name="a"/>\n  <joint name="j" type="revolute">\n</robot>\n')
    with pytest.raises(robovec.InputError) as e:
        robovec.load(str(bad))
    assert e.value.file and e.value.line >= 1 and e.value.column >= 1
    assert str(bad) in e.value.diagnostic
    m = robovec.load(erd(ROBOTS["ur5"]))
    with pytest.raises(robovec.UsageError):
        m.run("no-such-pass")
    with pytest.raises(robovec.UsageError):
        m.compile("no_such_function")
    with pytest.raises(robovec.TimeLimitError):
        robovec.load(erd(ROBOTS["talos"]), free_flyer=True, time_limit=1e-6)
    assert issubclass(robovec.TimeLimitError, robovec.InputError)
    assert issubclass(robovec.UsageError, robovec.Error)


def test_shapes_are_checked_and_other_arrays_converted():
    m = robovec.load(erd(ROBOTS["ur5"]))
    rnea = m.compile("rnea", cflags=["-O0"])
    q = np.array([-1.0, -0.5, -0.25, 0.25, 0.5, 1.0])  # exact in binary32
    want = rnea(q, q, q)
    # float32, a list, a strided view: converted, same values.
    assert relative(rnea(q.astype(np.float32), list(q), np.repeat(q, 2)[::2]), want) == 0
    wide = np.stack([q, q, q]).T.copy().T  # a (3, 6) view that is not C-contiguous
    assert not wide.flags["C_CONTIGUOUS"]
    assert relative(rnea(wide, wide, wide)[1], want) == 0
    with pytest.raises(ValueError):
        rnea(q[:5], q, q)
    with pytest.raises(ValueError):
        rnea(np.stack([q, q]), q, q)
    with pytest.raises(ValueError):
        rnea(q, q)
