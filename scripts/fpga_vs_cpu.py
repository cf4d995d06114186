#!/usr/bin/env python3
"""Issue 49's proof table: robovec's FPGA designs against robovec's own C, side by side in one run.

    scripts/fpga_vs_cpu.py [--pes=8,16,22,18+26,57+57/19] [--states=1,4] [--recurrence=16] [--rebind=64] [--steal=S] [--windows=W] [--mac] [--pnr] [--yosys] [MODEL...]

For each model (a corpus `dirdyna` named by its file's prefix: `jeep`, `tricycle`, `mazda_mx5`,
`coman_longarms`, `walkman`; default: every corpus `dirdyna` of at least 5k ops, the issue's
set), over the *generous* domain (`q` +-3.2 rad, `qd`, `qdd` +-10, forces +-100, parameters at
points; docs/accuracy.md):

1. the binary32 certified bound of every output (`error-bound<format=f32>`) becomes the budget
   of `precision<budget=FILE;target=mcu;word=W>`, whose fixed-point formats the FPGA runs
   (fixed-point PEs, issue 49 item 1): the design is no less accurate than a binary32 one, and
   the table gives the largest ratio of an output's certified bound to its budget (<= 1: met).
   W is, per target, the narrowest word for which every value gets a fixed-point format (the PE
   array has no floating-point unit beside them): from the one whose products take one DSP
   multiplier (27 bits on the DE10-Nano's Cyclone V, 18 on the ECP5) down to 16 while every
   value stays fixed point (narrower memories, multiplexers and adders), or up to 32 when it
   does not;
2. for each target (`de10-nano` at its declared 120 MHz, `ecp5-85f` at 80 MHz or, with `--pnr`,
   at the Fmax nextpnr measures), each configuration of `--pes` (N: N ADD + N MULTI PEs; A+M:
   A ADD and M MULTI PEs; a `/G` suffix: in G PE clusters, `place<clusters=G>`) and each K of `--states` (`interleave<states=K>`, issue 49 item 3),
   the design placed for the fewest interconnect routes (`place<select=routes>`, rebound for
   `--rebind` rounds: `rebind=R`, 64 by default; with clusters and `--steal=S`, `steal=S`: urgent
   ops may leave their cluster; with clusters and `--windows=W`, `windows=W`: each cluster gets
   its share of the ops of W time windows) with the specialised interconnect: cycles, us
   (latency), ns per state, logic / block RAM / DSP and fit (the analytic estimate; `--yosys`:
   Yosys' count on the DE10-Nano; `--pnr`: nextpnr's on the ECP5);
   With `--mac` the products are fused into their sums after `precision` (`contract`: the MULTI
   PEs compute `a*b +- c` rounded once, issue 49; docs/fpga.md "Fused multiply-adds") and the
   bound/budget column is `error-bound`'s of the fused function;
3. robovec's fastest C of the same model (`atomise,cse,zero-removal,cse,contract,schedule-cpu`,
   `codegen<c;abi=plain;trig=inline>`, binary64, `-O3 -march=native`), one state per call and
   `batch=4`, timed by `-report-dir` on this machine in the same run (src/cpu_time.rs: median
   of 31 repeats) -- the CPU the goals compare with.

Prints a Markdown table; `--json=FILE` also writes the rows. Needs a release `robovec-opt`
(`cargo build --release`), `cc`, and for `--pnr` the YoWASP tools in `target/ecp5-venv`
(scripts/test.sh installs them). Place and route of a large design takes tens of minutes.
"""

import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OPT = os.path.join(ROOT, "target/release/robovec-opt")
CORPUS = os.path.join(ROOT, "..", "shared", "corpus", "robotran")
MODELS = {
    "jeep": "c/jeep__mbs_dirdyna_Jeep.c",
    "tricycle": "c/tricycle__mbs_dirdyna_tricycle.c",
    "mazda_mx5": "python/mazda_mx5__mbs_dirdyna_Robotran_Mazda_MX5.py",
    "coman_longarms": "c/coman_longarms__mbs_dirdyna_coman_robotran.c",
    "walkman": "matlab/walkman__mbs_dirdyna_walkman_robotran.m",
}
# The fixed-point PEs' latencies (the target's fix_pe) for the rewrites that balance for them.
# `recurrence<pe=R>`: R = 16 by default, `--recurrence=R` to shorten the critical path for more PEs.
def pre(r=16):
    return f"atomise,cse,zero-removal,balance<lat-add=3;lat-mul=3>,cse,recurrence<pe={r};lat-add=3;lat-mul=3>,cse"


# Per target: the widest word whose product takes one DSP multiplier (docs/fpga.md "Narrow words").
ONE_BLOCK_WORD = {"de10-nano": 27, "ecp5-85f": 18}
# The narrowest word tried below a target's one-DSP word.
MIN_WORD = 16


def config(text):
    """`N` (N ADD + N MULTI PEs) or `A+M`, then `/G` for G PE clusters, as (add, mul, clusters)."""
    text, _, g = text.partition("/")
    a, _, m = text.partition("+")
    return (int(a), int(m or a), int(g or 1))
CPU = "atomise,cse,zero-removal,cse,contract,schedule-cpu,sweep<pe=1>"


class Refused(Exception):
    """robovec-opt refused a configuration (exit 1): its diagnostic's last line."""


def run(args, env=None, refusal_ok=False):
    p = subprocess.run([OPT] + args, capture_output=True, text=True, env=env)
    if p.returncode == 1 and refusal_ok:
        raise Refused(p.stderr.strip().splitlines()[-1])
    if p.returncode != 0:
        sys.exit(f"robovec-opt {' '.join(args)}\n{p.stderr}")
    return p


def generous_domain(path, work):
    """Every input of the model: the generous domain of docs/accuracy.md (tests/range.rs)."""
    empty = os.path.join(work, "empty.json")
    with open(empty, "w") as f:
        f.write("{}")
    inputs = json.loads(run([path, "-passes=atomise", f"-eval={empty}", "-o", "/dev/null"]).stdout)["inputs"]
    r = {}
    for n, x in inputs.items():
        fam = n.split("[")[0]
        if fam == "q":
            r[n] = [-3.2, 3.2]
        elif fam in ("qd", "qdd"):
            r[n] = [-10, 10]
        elif fam in ("frc", "trq", "Qq"):
            r[n] = [-100, 100]
        elif fam in ("m", "lrod"):
            r[n] = [1 + abs(x)] * 2
        elif fam == "In" and any(n.startswith(p) for p in ("In[1]", "In[5]", "In[9]")):
            r[n] = [0.1 + abs(x)] * 2
        elif fam == "tsim":
            r[n] = [0, 10]
        else:
            r[n] = [x, x]
    out = os.path.join(work, "ranges.json")
    with open(out, "w") as f:
        json.dump(r, f)
    return out


def report(args, work, name, env=None, refusal_ok=False):
    rep = os.path.join(work, name + ".json")
    run(args + ["-o", "/dev/null", f"-report={rep}"], env, refusal_ok)
    with open(rep) as f:
        return json.load(f)


def main():
    pes, states, pnr, yosys, models, json_out = [(8, 8, 1), (16, 16, 1), (22, 22, 1), (18, 26, 1)], [1], False, False, [], None
    rebind = None
    steal = None
    windows = None
    mac = False
    prefix = pre()
    for a in sys.argv[1:]:
        if a.startswith("--recurrence="):
            prefix = pre(int(a[len("--recurrence="):]))
        elif a.startswith("--pes="):
            pes = [config(x) for x in a[6:].split(",")]
        elif a.startswith("--rebind="):
            rebind = int(a[len("--rebind="):])
        elif a.startswith("--steal="):
            steal = int(a[len("--steal="):])
        elif a.startswith("--windows="):
            windows = int(a[len("--windows="):])
        elif a.startswith("--states="):
            states = [int(x) for x in a[9:].split(",")]
        elif a == "--mac":
            mac = True
        elif a == "--pnr":
            pnr = True
        elif a == "--yosys":
            yosys = True
        elif a.startswith("--json="):
            json_out = a[7:]
        elif a.startswith("-"):
            sys.exit(f"unknown option {a} (see the docstring)")
        elif a in MODELS:
            models.append(a)
        else:
            sys.exit(f"unknown model {a}; models: {', '.join(MODELS)}")
    if not os.access(OPT, os.X_OK):
        sys.exit("build first: cargo build --release")
    env = dict(os.environ)
    venv = os.path.join(ROOT, "target/ecp5-venv/bin")
    env["PATH"] = venv + os.pathsep + env.get("PATH", "")
    rows, refused = [], []
    for model in models or list(MODELS):
        path = os.path.join(CORPUS, MODELS[model])
        work = tempfile.mkdtemp(prefix=f"fpga-vs-cpu-{model}-")
        ranges = generous_domain(path, work)
        eb = report([path, f"-ranges={ranges}", f"-passes={prefix},error-bound<format=f32>"], work, "f32")["error_bound"]
        budget = os.path.join(work, "budget.json")
        with open(budget, "w") as f:
            json.dump({k: {"abs": v["abs"]} for k, v in eb["outputs"].items() if v["abs"] is not None}, f)
        # The narrowest word at which every value is fixed point (each tried once): from the
        # target's one-DSP width down while it holds (a narrower word still takes one DSP
        # multiplier a product, and narrows the memories, multiplexers and adders: coman holds
        # at 25 bits, the MX-5 and WALK-MAN at 26), or up to 32 bits when it does not.
        words, all_fixed = {}, {}

        def fixed(w):
            if w not in all_fixed:
                prec = report(
                    [path, f"-ranges={ranges}", f"-passes={prefix},precision<budget={budget};target=mcu;word={w}>"],
                    work,
                    f"fix{w}",
                )
                all_fixed[w] = all(k.startswith("fix<") for k in prec["precision"]["formats"])
            return all_fixed[w]

        for target, first in ONE_BLOCK_WORD.items():
            if fixed(first):
                w = first
                while w - 1 >= MIN_WORD and fixed(w - 1):
                    w -= 1
                words[target] = w
                continue
            up = [x for x in range(first + 1, 33) if x >= 27 or x in all_fixed]
            found = next((x for x in up if fixed(x)), None)
            if found is None:
                # a row that says so, and the other models' rows still printed
                refused.append(f"{model} {target}: no fixed-point word up to 32 bits meets binary32's bound")
            else:
                # a narrower all-fixed word found for another target serves this one too
                words[target] = min([found] + [x for x, ok in all_fixed.items() if ok and x > first])
        if len(words) < len(ONE_BLOCK_WORD):
            continue
        cpu_dir = os.path.join(work, "cpu")
        run([path, f"-ranges={ranges}", f"-passes={CPU}", f"-report-dir={cpu_dir}", "-o", "/dev/null"])
        with open(os.path.join(cpu_dir, "report.json")) as f:
            cpu = json.load(f)["cpu"]
        one, batched = cpu["one_state_us"] * 1000, cpu["batched_us"] * 1000
        for target in ["de10-nano", "ecp5-85f"]:
            w = words[target]
            with open(os.path.join(work, f"fix{w}.json")) as f:
                prec = json.load(f)
            p = prec["precision"]
            worst = max(o["bound"] / o["budget"] for o in p["outputs"].values() if o.get("budget"))
            formats = ", ".join(sorted({k.split(",")[0] + ",*>" for k in p["formats"]}))
            resources = "estimate"
            if target == "ecp5-85f" and pnr:
                resources = "pnr"
            if target == "de10-nano" and yosys:
                resources = "yosys"
            for k in states:
                for na, nm, g in pes:
                    n = (f"{na}" if na == nm else f"{na}+{nm}") + (f"/{g}" if g > 1 else "")
                    inter = f"interleave<states={k}>," if k > 1 else ""
                    out = os.path.join(work, f"{target}-{n}-{k}")
                    passes = (
                        f"{prefix},precision<budget={budget};target=mcu;word={w}>,{'contract,error-bound,' if mac else ''}{inter}"
                        f"place<add={na};mul={nm};select=routes{'' if rebind is None else f';rebind={rebind}'}"
                        f"{'' if g == 1 else f';clusters={g}'}"
                        f"{'' if g == 1 or steal is None else f';steal={steal}'}"
                        f"{'' if g == 1 or windows is None else f';windows={windows}'}>,"
                        f"codegen<fpga;out={out};resources={resources};interconnect=specialised;format=hex>"
                    )
                    try:
                        fp = report(
                            [path, f"-target={target}", f"-ranges={ranges}", f"-passes={passes}"],
                            work,
                            "fpga",
                            env,
                            refusal_ok=True,
                        )
                    except Refused as why:
                        # a configuration the target cannot hold (a buffer deeper than its
                        # buffers, ...): a row that says so
                        refused.append(f"{model} {target} N={n} K={k}: {why}")
                        print(refused[-1], file=sys.stderr)
                        continue
                    here = worst
                    if mac:
                        # the fused function's own certified bounds against the budget
                        with open(budget) as f:
                            b = json.load(f)
                        out = fp["error_bound"]["outputs"]
                        here = max(out[o]["abs"] / b[o]["abs"] for o in b if out.get(o, {}).get("abs") is not None)
                    fp = fp["fpga"]
                    r = fp["resources"]
                    u = r["units"]
                    us = fp["us"]
                    rows.append(
                        {
                            "model": model,
                            "ops": prec["stats"]["ops"]["total"],
                            "target": target,
                            "formats": formats,
                            "n": n,
                            "states": k,
                            "cycles": fp["cycles"],
                            "clock_mhz": fp["clock_mhz"],
                            "measured_clock": fp.get("fmax_mhz") is not None,
                            "us": us,
                            "ns_per_state": us * 1000 / k,
                            "logic": f"{r['alm']} {u['logic']}",
                            "bram": f"{r['m10k']} {u['bram']}",
                            "dsp": f"{r['dsp']} {u['dsp']}",
                            "fits": r["fits"],
                            "resources": r["logic_from"],
                            "cpu_one_ns": one,
                            "cpu_batch4_ns": batched,
                            "latency_ratio": us * 1000 / one,
                            "throughput_ratio": us * 1000 / k / batched,
                            "f32_bound_max": eb["max_abs"],
                            "bound_over_budget": here,
                        }
                    )
                    print(f"{model} {target} N={n} K={k}: {fp['cycles']} cycles, {us:.3f} us", file=sys.stderr)
    head = (
        "| model (ops) | target | N | states | cycles | clock | µs | ns/state | logic | block RAM | DSP | fits |"
        " C 1 state ns | C batch=4 ns/state | FPGA/C latency | FPGA/C per state | bound/budget |"
    )
    print(head)
    print("|" + "---|" * 17)
    for r in rows:
        clock = f"{r['clock_mhz']:g} MHz" + (" (Fmax)" if r["measured_clock"] else "")
        print(
            f"| {r['model']} ({r['ops']}) | {r['target']} | {r['n']} | {r['states']} | {r['cycles']} | {clock} |"
            f" {r['us']:.2f} | {r['ns_per_state']:.0f} | {r['logic']} | {r['bram']} | {r['dsp']} |"
            f" {'yes' if r['fits'] else 'no'} ({r['resources']}) | {r['cpu_one_ns']:.0f} | {r['cpu_batch4_ns']:.0f} |"
            f" {r['latency_ratio']:.2f} | {r['throughput_ratio']:.2f} | {r['bound_over_budget']:.2g} |"
        )
    for r in refused:
        print(f"\nnot built: {r}")
    if json_out:
        with open(json_out, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
