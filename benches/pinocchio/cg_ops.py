#!/usr/bin/env python3
"""Operations of Pinocchio's CppADCodeGen output against robovec's, per robot (issue 30).

Usage: cg_ops.py [ROBOT ...] [--robovec-opt PATH]

ROBOT is a name of the bench's list below (default: all of them). Needs the Pinocchio venv of
`cargo bench --bench pinocchio` (`target/pinocchio-venv`, or ROBOVEC_PINOCCHIO_PYTHON) with
`cmeel-cppad` and `cmeel-cppadcodegen` besides `pin`, `cmeel-eigen` and `example-robot-data`,
and a release `robovec-opt` (`cargo build --release`).

For each robot:
1. `export_model.py` builds Pinocchio's model the oracle's way (fixed base, or the composite
   root joint PX PY PZ RX RY RZ of robovec's `--floating-base`) and saves it;
2. `cg_export` (`cg_export.cpp`, compiled once with `g++` and cached in
   `target/pinocchio_bench/` under the hash of its source) writes CppADCodeGen's C of `rnea`,
   `crba` and `aba`;
3. robovec writes `invdyna`, `dirdyna` cut to the upper triangle of `M` (what `crba` fills) and
   `fordyna` with `-passes=atomise,cse --fold-params`, and `-stats` gives their ops.

Ops are the binary `+ - * /` of the generated statements: CppADCodeGen's are counted in its
`cg_F_forward_zero.c` (unary minus and `sin`/`cos` calls not counted, `0 - x` and `-1 * x`
counted as written), robovec's are `-stats`' `ops` (add, sub, mul, div; its trig values are
inputs, as CG's `sin`/`cos` calls are not counted). Prints a Markdown table with robovec / CG.
"""
import hashlib
import os
import re
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
HERE = os.path.join(ROOT, "benches", "pinocchio")
WORK = os.path.join(ROOT, "target", "pinocchio_bench")

# name, example-robot-data file, floating base: the robots of `benches/pinocchio.rs` that
# example-robot-data holds.
ROBOTS = [
    ("ur5", "ur_description/urdf/ur5_robot.urdf", False),
    ("panda", "panda_description/urdf/panda.urdf", False),
    ("solo12", "solo_description/robots/solo12.urdf", True),
    ("talos", "talos_data/robots/talos_reduced.urdf", True),
    ("tiago_pro", "tiago_pro_description/robots/tiago_pro.urdf", True),
]


def cxx_flags():
    """-O1 (the exporter runs once per robot), then the bench's shared Pinocchio flags."""
    with open(os.path.join(HERE, "pinocchio_cxx_flags.txt")) as f:
        shared = [l.strip() for l in f if l.strip() and not l.strip().startswith("#")]
    return ["-O1"] + shared


STATEMENT = re.compile(r"\s*[vy]\[\d+\]\s*=\s*(.*);\s*$")
TOKEN = re.compile(r"[A-Za-z_]\w*\[\d+\]|\d+\.?\d*(?:e[-+]?\d+)?|[-+*/()]|\w+")


def cg_ops(path):
    """Binary + - * / in the statements of a CppADCodeGen source."""
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


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stdout}{r.stderr}")
    return r.stdout + r.stderr


def exporter(python):
    prefix = run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]).strip()
    prefix = os.path.join(prefix, "cmeel.prefix")
    for h in ["include/pinocchio/codegen/cppadcg-algo.hpp", "include/cppad/cg.hpp", "include/eigen3/Eigen/Core"]:
        if not os.path.exists(os.path.join(prefix, h)):
            sys.exit(f"{h} missing under {prefix}: {python} -m pip install pin cmeel-eigen cmeel-cppad cmeel-cppadcodegen example-robot-data")
    src = os.path.join(HERE, "cg_export.cpp")
    flags = cxx_flags()
    key = hashlib.sha256((open(src).read() + " ".join(flags) + prefix).encode()).hexdigest()[:16]
    exe = os.path.join(WORK, f"cg_export-{key}")
    if not os.path.exists(exe):
        os.makedirs(WORK, exist_ok=True)
        print(f"compiling {src} (several minutes; cached as {exe})", file=sys.stderr)
        lib = os.path.join(prefix, "lib")
        inc = [f"-I{os.path.join(prefix, 'include')}", f"-I{os.path.join(prefix, 'include', 'eigen3')}"]
        run(["g++", *flags, *inc, src, "-o", exe + ".tmp", f"-L{lib}", f"-Wl,-rpath,{lib}",
             "-lcppad_lib", "-lboost_serialization", "-ldl"])
        os.replace(exe + ".tmp", exe)
    return prefix, exe


def robovec_ops(opt, urdf, floating, function, passes):
    args = [opt, urdf, f"-function={function}", "--fold-params", f"-passes={passes}", "-stats", "-o", os.devnull]
    if floating:
        args.append("--floating-base")
    out = run(args)
    counts = re.findall(r"ops (\d+) \(", out)
    if not counts:
        sys.exit(f"no op count in robovec-opt's -stats:\n{out}")
    return int(counts[-1])


def main():
    args = sys.argv[1:]
    opt = os.path.join(ROOT, "target", "release", "robovec-opt")
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
    print("| robot | function | CG ops | robovec ops | robovec / CG |")
    print("|---|---|---:|---:|---:|")
    for name, rel, floating in robots:
        out = os.path.join(WORK, "cg", name)
        run([python, os.path.join(HERE, "export_model.py"), f"erd:{rel}", out, "1", "1"] + (["floating"] if floating else []))
        nv = int(re.search(r"nv (\d+)", run([exe, os.path.join(out, "model.txt"), out])).group(1))
        upper = ",".join(f"M[{i}][{j}]" for i in range(1, nv + 1) for j in range(i, nv + 1))
        urdf = os.path.join(erd, rel)
        rows = [
            ("rnea", "invdyna", "atomise,cse"),
            ("crba", "dirdyna", f"atomise,cse,dce<outputs={upper}>"),
            ("aba", "fordyna", "atomise,cse"),
        ]
        for cg, function, passes in rows:
            c = cg_ops(os.path.join(out, cg, f"cg_{cg}_forward_zero.c"))
            r = robovec_ops(opt, urdf, floating, function, passes)
            print(f"| {name} | {cg} / {function} | {c} | {r} | {r / c:.2f}× |", flush=True)


if __name__ == "__main__":
    main()
