#!/usr/bin/env python3
"""Operations of Pinocchio's CppADCodeGen output against robovec's, per robot (issues 30, 50).

Usage: cg_ops.py [ROBOT ...] [--robovec-opt PATH] [--base=free-flyer|composite]
                 [--functions=dynamics|derivatives|all]

ROBOT is a name of the bench's list below (default: all of them). Needs the Pinocchio venv of
`cargo bench --bench pinocchio` (`target/pinocchio-venv`, or ROBOVEC_PINOCCHIO_PYTHON) with
`cmeel-cppad` and `cmeel-cppadcodegen` besides `pin`, `cmeel-eigen` and `example-robot-data`,
and a release `robovec-opt` (`cargo build --release`).

For each robot:
1. `export_model.py` builds Pinocchio's model the oracle's way (fixed base; a floating robot on
   `JointModelFreeFlyer`, robovec's `--free-flyer`, by default, or with `--base=composite` on the
   root joint PX PY PZ RX RY RZ of robovec's `--floating-base`) and saves it;
2. `cg_sources.py`'s helpers (shared with the bench's CG contestants) compile `cg_export.cpp`
   once (cached in `target/pinocchio_bench/` under the hash of its source and flags) and write
   CppADCodeGen's C of `rnea`, `crba` and `aba` (`--functions=dynamics`, the default) and/or of
   `rnea_derivatives`, `aba_derivatives` and `minv` (`--functions=derivatives`);
3. robovec writes `invdyna`, `dirdyna` cut to the upper triangle of `M` (what `crba` fills) and
   `fordyna`, or `rnea_derivatives`, `aba_derivatives` and `minv` cut to the upper triangle of
   `Minv` (what `CodeGenMinv` outputs), with `--fold-params -gravity=0,0,-9.81` (CG's tape holds
   the model's gravity as constants too) and `-stats` gives their ops: the dynamics with
   `-passes=atomise,cse` (issue 30's table), the derivatives also with `atomise,default<ops>`
   (cse, zero-removal, cse: the pipeline of issue 50's goal).

Ops are the binary `+ - * /` of the generated statements: CppADCodeGen's are counted in its
`cg_F_forward_zero.c` (unary minus and `sin`/`cos` calls not counted, `0 - x` and `-1 * x`
counted as written), robovec's are `-stats`' `ops` (add, sub, mul, div; its trig values are
inputs, as CG's `sin`/`cos` calls are not counted). Prints a Markdown table with robovec / CG.
"""
import os
import re
import sys

from cg_sources import ROOT, HERE, WORK, exporter, export, run

# name, example-robot-data file, floating base: the robots of `benches/pinocchio.rs` that
# example-robot-data holds.
ROBOTS = [
    ("ur5", "ur_description/urdf/ur5_robot.urdf", False),
    ("panda", "panda_description/urdf/panda.urdf", False),
    ("solo12", "solo_description/robots/solo12.urdf", True),
    ("talos", "talos_data/robots/talos_reduced.urdf", True),
    ("tiago_pro", "tiago_pro_description/robots/tiago_pro.urdf", True),
]


STATEMENT = re.compile(r"\s*[vy]\[\d+\]\s*=\s*(.*);\s*$")
TOKEN = re.compile(r"[A-Za-z_]\w*\[\d+\]|\d+\.?\d*(?:e[-+]?\d+)?|[-+*/()]|\w+")


def cg_parts(path):
    """A CppADCodeGen function's sources: `cg_F_forward_zero.c` and, for a large function, the
    parts it calls (`cg_F_forward_zero__1.c`, ...)."""
    folder, name = os.path.split(path)
    stem = name[: -len(".c")]
    return [path] + sorted(
        os.path.join(folder, p) for p in os.listdir(folder) if p.startswith(stem + "__") and p.endswith(".c")
    )


def cg_ops(path):
    """Binary + - * / in the statements of a CppADCodeGen function (all its parts)."""
    return sum(file_ops(p) for p in cg_parts(path))


def file_ops(path):
    """Binary + - * / in the statements of one CppADCodeGen source."""
    n = 0
    with open(path) as f:
        for line in f:
            m = STATEMENT.match(line)
            if not m:
                continue
            prev = None
            for t in TOKEN.findall(m.group(1)):
                if t in "+-*/" and not (t == "-" and (prev is None or prev in "+-*/(")):
                    n += 1
                prev = t
    return n


def robovec_ops(opt, urdf, base_flag, function, passes):
    args = [opt, urdf, f"-function={function}", "--fold-params", "-gravity=0,0,-9.81", f"-passes={passes}", "-stats",
            "-o", os.devnull]
    if base_flag:
        args.append(base_flag)
    out = run(args)
    counts = re.findall(r"ops (\d+) \(", out)
    if not counts:
        sys.exit(f"no op count in robovec-opt's -stats:\n{out}")
    return int(counts[-1])


def rows(nv, functions):
    """(CG's function, robovec's function, robovec's pipelines) of each compared function."""
    def upper(m):
        return ",".join(f"{m}[{i}][{j}]" for i in range(1, nv + 1) for j in range(i, nv + 1))
    dynamics = [
        ("rnea", "invdyna", ["atomise,cse"]),
        ("crba", "dirdyna", [f"atomise,cse,dce<outputs={upper('M')}>"]),
        ("aba", "fordyna", ["atomise,cse"]),
    ]
    derived = ["atomise,cse", "atomise,default<ops>"]
    derivatives = [
        ("rnea_derivatives", "rnea_derivatives", derived),
        ("aba_derivatives", "aba_derivatives", derived),
        ("minv", "minv", [f"atomise,dce<outputs={upper('Minv')}>,{p.split(',', 1)[1]}" for p in derived]),
    ]
    return {"dynamics": dynamics, "derivatives": derivatives, "all": dynamics + derivatives}[functions]


def main():
    args = sys.argv[1:]
    opt = os.path.join(ROOT, "target", "release", "robovec-opt")
    base = "free-flyer"
    functions = "dynamics"
    for a in list(args):
        if a.startswith("--base="):
            base = a.split("=", 1)[1]
            args.remove(a)
        elif a.startswith("--functions="):
            functions = a.split("=", 1)[1]
            args.remove(a)
    if functions not in ("dynamics", "derivatives", "all"):
        sys.exit(f"--functions={functions}: dynamics, derivatives or all")
    if base not in ("free-flyer", "composite"):
        sys.exit(f"--base={base}: free-flyer or composite")
    if "--robovec-opt" in args:
        i = args.index("--robovec-opt")
        opt = args[i + 1]
        del args[i : i + 2]
    if not os.path.exists(opt):
        sys.exit(f"{opt} missing: cargo build --release")
    names = [r[0] for r in ROBOTS]
    for a in args:
        if a not in names:
            sys.exit(f"unknown robot `{a}`; robots: {', '.join(names)}")
    robots = [r for r in ROBOTS if not args or r[0] in args]
    python = os.environ.get("ROBOVEC_PINOCCHIO_PYTHON", os.path.join(ROOT, "target", "pinocchio-venv", "bin", "python"))
    prefix, exe = exporter(python)
    erd = os.path.join(prefix, "share", "example-robot-data", "robots")
    print("| robot | function | CG ops | robovec pipeline | robovec ops | robovec / CG |")
    print("|---|---|---:|---|---:|---:|")
    for name, rel, floating in robots:
        out = os.path.join(WORK, "cg", name)
        run([python, os.path.join(HERE, "export_model.py"), f"erd:{rel}", out, "1", "1"] + ([{"free-flyer": "free-flyer", "composite": "floating"}[base]] if floating else []))
        model = os.path.join(out, "model.txt")
        _, nv, cg = export(exe, model, out, [r[0] for r in rows(0, functions)])
        urdf = os.path.join(erd, rel)
        flag = {"free-flyer": "--free-flyer", "composite": "--floating-base"}[base] if floating else None
        for name_cg, function, pipelines in rows(nv, functions):
            c = cg_ops(cg[name_cg])
            for passes in pipelines:
                r = robovec_ops(opt, urdf, flag, function, passes)
                shown = re.sub(r"dce<outputs=[^>]*>", "dce<outputs=upper>", passes)
                print(f"| {name} | {name_cg} / {function} | {c} | `{shown}` | {r} | {r / c:.2f}× |", flush=True)


if __name__ == "__main__":
    main()
