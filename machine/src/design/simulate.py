#!/usr/bin/env python3
"""Run the design robovec's codegen<fpga> wrote in this folder in Icarus Verilog.

Usage: DIR/simulate INPUTS.json   (INPUTS.json: robovec -eval's input format, {"q[1]": 0.25};
                                   `-` reads it from stdin)

Each input is rounded to binary32 (round to nearest, as `-eval-precision=f32` does); inputs not
given get robovec's deterministic pseudo-random value in [-1, 1) (FNV-1a of the name, one
SplitMix64 draw: robovec_ir::interp::pseudo_random_input with seed 0). Trig initial values
(S4 = sin q[4] ...) are computed in binary32 with the C library's sinf/cosf, which is what
robovec's interpreter calls. The words go into the initial PE memory images at the addresses of
manifest.json's load map; the design runs in `iverilog`/`vvp` from `start` to `done`; the output
memories are read back through the manifest's output map.

On fixed-point PEs (manifest "pe_kind": "fixed", issue 49) words are 32-bit two's complement
integers k of values k * 2^-f: each input is stored in its format (k = floor(x * 2^f + 1/2),
exactly, as robovec's `-eval` stores it), a trig value is the C library's binary64 sin/cos of
the stored input, stored in its own format, and each output is k * 2^-f at its "fraction".

Prints on stdout: {"cycles": C, "clocks": K, "outputs": {name: value}, "bits": {name: "0x…"}}
with every output as its binary32 value (on fixed-point PEs, its exact value k * 2^-f) (a JSON number that parses to exactly that value; null
for NaN and infinities, whose bits are in "bits"). Exit status 1 with a message on stderr when
the input file is bad, an input name is unknown, or the simulator is missing or fails.
Needs Python 3 (standard library only) and Icarus Verilog (Debian package `iverilog`).
"""
import ctypes
import ctypes.util
import fractions
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
MASK = (1 << 64) - 1


def fail(msg):
    sys.stderr.write("simulate: error: " + msg + "\n")
    sys.exit(1)


def pseudo_random_input(name, seed=0):
    h = 0xCBF29CE484222325 ^ seed
    for b in name.encode():
        h ^= b
        h = (h * 0x100000001B3) & MASK
    s = (h + 0x9E3779B97F4A7C15) & MASK
    z = s
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    z ^= z >> 31
    return (z >> 11) / float(1 << 53) * 2.0 - 1.0


def f32_bits(x):
    """Bits of x rounded to binary32 (to nearest even; overflow gives infinity, like `as f32`)."""
    if math.isnan(x):
        return 0x7FC00000
    try:
        return struct.unpack("<I", struct.pack("<f", x))[0]
    except OverflowError:
        # struct refuses exactly the values that round to infinity in binary32
        return 0xFF800000 if x < 0 else 0x7F800000


def bits_f32(b):
    return struct.unpack("<f", struct.pack("<I", b))[0]


_LIBM = None


def trig_bits(fn, arg_bits):
    global _LIBM
    if _LIBM is None:
        _LIBM = ctypes.CDLL(ctypes.util.find_library("m") or "libm.so.6")
        for n in ("sinf", "cosf"):
            getattr(_LIBM, n).restype = ctypes.c_float
            getattr(_LIBM, n).argtypes = [ctypes.c_float]
    y = getattr(_LIBM, fn + "f")(bits_f32(arg_bits))
    return struct.unpack("<I", struct.pack("<f", y))[0]


def read_mif(path):
    """The words of an Intel MIF as codegen<fpga> writes it (ADDRESS_RADIX=UNS, DATA_RADIX=HEX)."""
    words, content = [], False
    with open(path) as f:
        for line in f:
            line = line.split("--")[0].strip()
            if not line:
                continue
            up = line.upper()
            if up.startswith("DEPTH"):
                words = [0] * int(up.split("=")[1].strip(" ;"))
            elif up.startswith("CONTENT"):
                content = True
            elif up.startswith("END"):
                break
            elif content:
                a, w = line.rstrip(";").split(":")
                words[int(a)] = int(w, 16)
    return words


def number(b):
    x = bits_f32(b)
    return x if math.isfinite(x) else None


def fix_word(x, f, bits=32):
    """The integer of x stored in fix<bits,f>: floor(x * 2^f + 1/2), exactly (ties toward +inf)."""
    k = math.floor(fractions.Fraction(x) * fractions.Fraction(2) ** f + fractions.Fraction(1, 2))
    if not -(1 << (bits - 1)) <= k < (1 << (bits - 1)):
        fail("%r does not fit a %d-bit word at %d fractional bits" % (x, bits, f))
    return k


def fix_value(k, f):
    """k * 2^-f as a float (exact: |k| < 2^31)."""
    return math.ldexp(k, -f)


def signed32(w):
    return w - (1 << 32) if w & (1 << 31) else w


def main(argv):
    if len(argv) != 2:
        fail("usage: simulate INPUTS.json (robovec -eval's input format; - for stdin)")
    with open(os.path.join(HERE, "manifest.json")) as f:
        man = json.load(f)
    try:
        text = sys.stdin.read() if argv[1] == "-" else open(argv[1]).read()
    except OSError as e:
        fail("cannot read `%s`: %s" % (argv[1], e))
    try:
        given = json.loads(text)
    except ValueError as e:
        fail("`%s` is not JSON: %s" % (argv[1], e))
    if not isinstance(given, dict):
        fail("`%s` must be a JSON object {\"name\": number}" % argv[1])
    names = set(man["inputs"])
    for k, v in given.items():
        if k not in names:
            fail("`%s` names input `%s`, which function `%s` does not have (inputs: %s)"
                 % (argv[1], k, man["function"], ", ".join(sorted(names)) or "none"))
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            fail("input `%s` must be a number, found %s" % (k, json.dumps(v)))
    fixed = man.get("pe_kind") == "fixed"
    dw = man.get("word_bits", 32)
    mask = (1 << dw) - 1
    word = {}
    stored = {}
    for n in man["inputs"]:
        x = float(given[n]) if n in given else pseudo_random_input(n)
        if fixed:
            f = man["input_fractions"][n]
            stored[n] = fix_value(fix_word(x, f, dw), f)
        else:
            word[n] = f32_bits(x)

    def load_bits(l):
        if fixed and "input" in l:
            return fix_word(stored[l["input"]], l["fraction"], dw) & mask
        if fixed and "trig" in l:
            y = (math.sin if l["trig"] == "sin" else math.cos)(stored[l["of"]])
            return fix_word(y, l["fraction"], dw) & mask
        if "input" in l:
            return word[l["input"]]
        if "trig" in l:
            return trig_bits(l["trig"], word[l["of"]])
        return int(l["bits"], 16)

    if shutil.which("iverilog") is None or shutil.which("vvp") is None:
        fail("Icarus Verilog is not installed (`iverilog`, `vvp`; Debian package `iverilog`)")
    with tempfile.TemporaryDirectory(prefix="robovec-sim-") as tmp:
        # every PE's memories, then the control memory's lanes the PEs share
        for m in [m for pe in man["pes"] for m in pe["memories"].values()] + man["control_lanes"]:
            src = os.path.join(HERE, "hex", m["file"] + ".hex")
            if os.path.exists(src):
                shutil.copy(src, os.path.join(tmp, m["file"] + ".hex"))
            else:
                words = read_mif(os.path.join(HERE, "mif", m["file"] + ".mif"))
                with open(os.path.join(tmp, m["file"] + ".hex"), "w") as f:
                    f.write("".join("%x\n" % w for w in words))
        images = {}
        for pe in man["pes"]:
            images[pe["slot"]] = {
                "data": [0] * pe["memories"]["data"]["words"],
                "out": [0] * pe["memories"]["out"]["words"],
            }
        for l in man["loads"]:
            images[l["slot"]]["data"][l["addr"]] = load_bits(l)
        for l in man["output_loads"]:
            images[l["slot"]]["out"][l["addr"]] = load_bits(l)
        for pe in man["pes"]:
            for key in ("data", "out"):
                with open(os.path.join(tmp, pe["memories"][key]["file"] + ".hex"), "w") as f:
                    f.write("".join("%0*x\n" % ((dw + 3) // 4, w & mask) for w in images[pe["slot"]][key]))
        # The sources are compiled from copies in the temporary folder, under their own names:
        # iverilog quotes each path in its `line directives, so a folder name holding `"`
        # (or other characters it does not escape) broke the compilation.
        sources = []
        for n in list(man["hdl"]) + ["testbench.v"]:
            shutil.copy(os.path.join(HERE, "hdl", n), os.path.join(tmp, "src-" + os.path.basename(n)))
            sources.append("src-" + os.path.basename(n))
        r = subprocess.run(["iverilog", "-g2005", "-o", "sim.vvp"] + sources,
                           cwd=tmp, capture_output=True, text=True)
        if r.returncode != 0:
            fail("iverilog failed:\n" + r.stderr)
        r = subprocess.run(["vvp", "-n", "sim.vvp"], cwd=tmp, capture_output=True, text=True)
        if r.returncode != 0 or "robovec-done" not in r.stdout:
            fail("the simulation did not reach done:\n" + r.stdout + r.stderr)
        cycles = clocks = None
        for line in r.stdout.splitlines():
            if line.startswith("robovec-done"):
                _, cycles, clocks = line.split()
        outs = {}
        for pe in man["pes"]:
            with open(os.path.join(tmp, "captured%d.hex" % pe["slot"])) as f:
                words = [ln.split("//")[0].strip() for ln in f]
                outs[pe["slot"]] = [int(t, 16) for t in words if t]
    result = {"cycles": int(cycles), "clocks": int(clocks), "outputs": {}, "bits": {}}
    for o in man["outputs"]:
        b = outs[o["slot"]][o["addr"]]
        if fixed:
            # a word of dw bits, sign-extended to 32 (what out_data reads)
            b = (b - (1 << dw) if b >> (dw - 1) & 1 else b) & 0xFFFFFFFF
            result["outputs"][o["name"]] = fix_value(signed32(b), o["fraction"])
        else:
            result["outputs"][o["name"]] = number(b)
        result["bits"][o["name"]] = "0x%08x" % b
    sys.stdout.write(json.dumps(result, indent=1) + "\n")


if __name__ == "__main__":
    main(sys.argv)
