#!/usr/bin/python3
"""Fuzz the input reading of rktsph: mutated case files through the real binary.

Usage:
  /usr/bin/python3 scripts/fuzz_inputs.py --binary build/rktsph [--count 4000] [--seed 14]
         [--jobs 2] [--timeout 60] [--work DIR] [--only N ...] [--keep] [--verbose]

Inputs: every thesis case (cases/thesis/*.toml, run with `rktsph run FILE --out DIR --quiet
--threads 1 --set time.end=T --set time.max_steps=1000`, T three of the case's own time steps,
so that a run that gets past the reader is a few steps long, and one whose mutated step is much
shorter is refused by the step guard) and every material-point input (cases/material_point/*.toml,
`rktsph material-point FILE --out DIR --set output.plot=false`). Input N mutates base file
N mod (number of files) with a generator seeded by (seed, N) alone, so any one input can be
made again with --only N. Mutations, one to three per input:
  values   sign flip, zero, 1e300, -1e300, 1e-300, 1e100, nan, inf, -inf, huge and overflowing
           integers, integer <-> float, scaled by 2, 0.5, 1e10, 1e-10; strings empty, with a
           comma, a quote, a newline, a control character, 10 000 characters, another known
           word; booleans flipped; arrays emptied, shortened, lengthened, nested, mixed;
           inline tables emptied, shortened, given an unknown or a duplicate entry
  types    a string, an array, an inline table, a boolean, a date for any value
  keys     deleted, duplicated, misspelt, moved to another table, an unknown key or table
           added, a whole table deleted or duplicated
  syntax   truncation, a deleted bracket, brace, quote or '=', 1-4 random byte flips, random
           bytes inserted, two lines joined, the file doubled
  --set    a key of the file overridden on the command line with a mutated value, trailing
           text, an empty value, a bad key path
The contract checked for every input:
  * exit status 0, 2 or 3; never a signal (crash), a timeout (hang), 1 (an uncaught error) or
    any other status; nothing on stderr from std::terminate, an assertion or a sanitizer;
  * status 2: the message names the input file and a line or a key ("line N", "key '...'",
    "value set on the command line" or the --set argument);
  * status 3 (a valid but unstable or too-stiff case): a solver diagnosis, on stderr or in
    summary.json (status "unstable" and a message).
On failure it prints the seed, the input number, the mutations, the command and the input
(kept under WORK/failures/), and exits 1. `--only N` reruns one input and shows its output.

A script rather than a gtest: the mutations are text edits, the runs are separate processes
(a crash or a hang must not take the test runner with it) run in parallel with a timeout each,
and one input is reproduced from the command line. It needs Debian's /usr/bin/python3 only.
CTest runs it as `fuzz_inputs` (label fuzz, tests/integration.cmake): 4000 inputs, seed 14,
about 27 s on two cores.
"""

import argparse
import concurrent.futures
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

HEADER_RE = re.compile(r"^(\s*)(\[\[?)\s*([A-Za-z0-9_.\-\"]+)\s*(\]\]?)(.*)$")
KV_RE = re.compile(r"^(\s*)([A-Za-z0-9_\-]+)(\s*=\s*)(.*)$")
NUMBER_RE = re.compile(r"^[+-]?(\d[\d_]*)(\.\d[\d_]*)?([eE][+-]?\d+)?$|^[+-]?(inf|nan)$")

WORDS = ["elastic", "perzyna_von_mises", "perzyna_cam_clay", "v1", "v3", "ramp", "step", "sine", "table",
         "constant", "smoothstep", "geostatic", "uniform", "zero", "staggered", "collocated", "jacobi",
         "incomplete_cholesky", "nodes", "stress_points", "additive", "frozen_flux", "power", "exponential",
         "uniaxial_stress", "uniaxial_strain", "simple_shear", "strain_rate", "drained_triaxial",
         "undrained_triaxial", "oedometric", "plane_strain_compression", "vx", "syy", "pw", "eps_vp_eq", "load",
         "cubic_spline", "nope"]


# --------------------------------------------------------------------------------------------
# A line-level view of a TOML file: headers, key = value lines (with the dotted key they set).

def split_comment(rest):
    """Split 'value  # comment' into (value, '  # comment'), minding quoted strings."""
    quote = None
    i = 0
    while i < len(rest):
        c = rest[i]
        if quote:
            if c == "\\" and quote == '"':
                i += 2
                continue
            if c == quote:
                quote = None
        elif c in "\"'":
            quote = c
        elif c == "#":
            j = i
            while j > 0 and rest[j - 1] in " \t":
                j -= 1
            return rest[:j], rest[j:]
        i += 1
    return rest.rstrip(), rest[len(rest.rstrip()):]


def parse_lines(text):
    """Lines as dicts: kind (header, kv, other), and for kv the key, value, dotted path."""
    out = []
    table = []
    counters = {}
    for line in text.split("\n"):
        m = HEADER_RE.match(line)
        if m and not line.strip().startswith("#"):
            name = m.group(3)
            if m.group(2) == "[[":
                counters[name] = counters.get(name, -1) + 1
                table = name.split(".")[:-1] + [name.split(".")[-1], str(counters[name])]
            else:
                table = name.split(".")
            out.append({"kind": "header", "line": line, "name": name, "array": m.group(2) == "[["})
            continue
        m = KV_RE.match(line)
        if m and not line.strip().startswith("#"):
            value, comment = split_comment(m.group(4))
            out.append({"kind": "kv", "line": line, "indent": m.group(1), "key": m.group(2), "eq": m.group(3),
                        "value": value, "comment": comment, "path": ".".join(table + [m.group(2)])})
            continue
        out.append({"kind": "other", "line": line})
    return out


def join_lines(lines):
    return "\n".join(l["line"] for l in lines)


def kv_line(l, value):
    return f"{l['indent']}{l['key']}{l['eq']}{value}{l['comment']}"


# --------------------------------------------------------------------------------------------
# Value mutations.

def classify(v):
    v = v.strip()
    if v.startswith('"') or v.startswith("'"):
        return "string"
    if v.startswith("["):
        return "array"
    if v.startswith("{"):
        return "table"
    if v in ("true", "false"):
        return "bool"
    if NUMBER_RE.match(v):
        return "number"
    return "other"


def split_items(inner):
    """Top-level comma-separated items of an array or inline table body."""
    items, depth, cur, quote = [], 0, "", None
    for c in inner:
        if quote:
            cur += c
            if c == quote:
                quote = None
            continue
        if c in "\"'":
            quote = c
        elif c in "[{":
            depth += 1
        elif c in "]}":
            depth -= 1
        if c == "," and depth == 0:
            items.append(cur.strip())
            cur = ""
        else:
            cur += c
    if cur.strip():
        items.append(cur.strip())
    return items


def mutate_number(rng, v):
    v = v.strip()
    choices = ["sign", "zero", "huge", "-huge", "tiny", "e100", "nan", "inf", "-inf", "bigint", "overflow", "flip",
               "x2", "x0.5", "x1e10", "x1e-10", "negint"]
    c = rng.choice(choices)
    try:
        f = float(v.replace("_", ""))
    except ValueError:
        f = 1.0
    if c == "sign":
        return v[1:] if v.startswith("-") else "-" + v.lstrip("+")
    if c == "zero":
        return rng.choice(["0", "0.0", "-0.0"])
    if c == "huge":
        return "1e300"
    if c == "-huge":
        return "-1e300"
    if c == "tiny":
        return rng.choice(["1e-300", "-1e-300", "5e-324"])
    if c == "e100":
        return rng.choice(["1e100", "1.0000001e100", "1e99"])
    if c in ("nan", "inf", "-inf"):
        return c
    if c == "bigint":
        return rng.choice(["9223372036854775807", "-9223372036854775808", "2147483648", "4294967297"])
    if c == "overflow":
        return "99999999999999999999"
    if c == "flip":
        if re.match(r"^[+-]?\d+$", v):
            return v + ".0"
        if math.isfinite(f) and f == int(f) and abs(f) < 1e15:
            return str(int(f))
        return "1"
    if c == "negint":
        return "-1"
    factor = {"x2": 2.0, "x0.5": 0.5, "x1e10": 1e10, "x1e-10": 1e-10}[c]
    return repr(f * factor)


def mutate_string(rng, v):
    c = rng.randrange(9)
    if c == 0:
        return '""'
    if c == 1:
        return '"a,b"'
    if c == 2:
        return '"a\\"b"'
    if c == 3:
        return '"a\\nb"'
    if c == 4:
        return '"tab\\there\\u0001"'
    if c == 5:
        return '"' + "x" * 10000 + '"'
    if c == 6:
        return '"\u00fc\u00df\u4e2d"'
    if c == 7:
        return "'" + v.strip().strip("\"'") + "'"
    return '"' + rng.choice(WORDS) + '"'


def mutate_array(rng, v):
    items = split_items(v.strip()[1:-1])
    c = rng.randrange(8)
    if c == 0 or not items:
        return "[]"
    if c == 1:
        items.pop(rng.randrange(len(items)))
    elif c == 2:
        items.append(rng.choice(items))
    elif c == 3:
        i = rng.randrange(len(items))
        items[i] = mutate_value(rng, items[i])
    elif c == 4:
        return "[" + v.strip() + "]"
    elif c == 5:
        items.append('"a"')
    elif c == 6:
        items = items[::-1]
    else:
        items = [mutate_value(rng, x) for x in items]
    return "[" + ", ".join(items) + "]"


def mutate_inline_table(rng, v):
    items = split_items(v.strip()[1:-1])
    c = rng.randrange(6)
    if c == 0 or not items:
        return "{}"
    if c == 1:
        items.pop(rng.randrange(len(items)))
    elif c == 2:
        items.append(rng.choice(["bogus = 1.0", "zz = 1.0", "z = 0.0", "xy = 1.0", "yz = 2.0"]))
    elif c == 3:
        items.append(rng.choice(items))  # a duplicate key: not valid TOML
    else:
        i = rng.randrange(len(items))
        k, _, val = items[i].partition("=")
        items[i] = f"{k.strip()} = {mutate_value(rng, val)}"
    return "{ " + ", ".join(items) + " }"


def change_type(rng, v):
    return rng.choice(['"text"', '"1.0"', "[1.0, 2.0]", "[]", "{ a = 1.0 }", "true", "false",
                       "1979-05-27T07:32:00Z", "07:32:00", "1.5", "3", "[[1.0]]"])


def mutate_value(rng, v):
    kind = classify(v)
    if rng.random() < 0.2:
        return change_type(rng, v)
    if kind == "number":
        return mutate_number(rng, v)
    if kind == "string":
        return mutate_string(rng, v)
    if kind == "array":
        return mutate_array(rng, v)
    if kind == "table":
        return mutate_inline_table(rng, v)
    if kind == "bool":
        return rng.choice(["false" if v.strip() == "true" else "true", '"true"', "1"])
    return change_type(rng, v)


# Value mutations that leave time.end's value as it is (the run would then be the case's full
# length); for that key only the changes below are used, and the run gets no --set time.end.
END_VALUES = ["0", "0.0", "-1.0", "1e300", "1e-300", "nan", "inf", "-inf", "1e100", '"1.0"', "[1.0]",
              "{ a = 1.0 }", "true", "1979-05-27", "1e20", "1e-20"]


# --------------------------------------------------------------------------------------------
# One input.

def table_blocks(lines):
    """(start, end) index ranges of each table: a header and the lines up to the next one."""
    starts = [i for i, l in enumerate(lines) if l["kind"] == "header"]
    return [(s, (starts[k + 1] if k + 1 < len(starts) else len(lines))) for k, s in enumerate(starts)]


def mutate_structure(rng, text, notes, state):
    lines = parse_lines(text)
    kvs = [i for i, l in enumerate(lines) if l["kind"] == "kv"]
    blocks = table_blocks(lines)
    c = rng.choice(["value", "value", "value", "value", "type", "delete", "duplicate", "misspell", "move",
                    "unknown_key", "unknown_table", "delete_table", "duplicate_table", "syntax", "syntax", "set"])
    if c in ("value", "type") and kvs:
        i = rng.choice(kvs)
        l = lines[i]
        if l["path"] == "time.end":
            new = rng.choice(END_VALUES)
            state["no_end_override"] = True
        else:
            new = change_type(rng, l["value"]) if c == "type" else mutate_value(rng, l["value"])
        notes.append(f"{c}: {l['path']} = {l['value']} -> {new[:60]}")
        l["line"] = kv_line(l, new)
        return join_lines(lines)
    if c == "delete" and kvs:
        i = rng.choice(kvs)
        notes.append(f"delete key {lines[i]['path']}")
        del lines[i]
        return join_lines(lines)
    if c == "duplicate" and kvs:
        i = rng.choice(kvs)
        notes.append(f"duplicate key {lines[i]['path']}")
        lines.insert(i + 1, dict(lines[i]))
        return join_lines(lines)
    if c == "misspell" and kvs:
        i = rng.choice(kvs)
        l = lines[i]
        new_key = rng.choice([l["key"] + "x", l["key"][:-1], l["key"].upper(), "_" + l["key"]])
        if not new_key:
            new_key = "k"
        notes.append(f"misspell {l['path']} -> {new_key}")
        l["line"] = f"{l['indent']}{new_key}{l['eq']}{l['value']}{l['comment']}"
        return join_lines(lines)
    if c == "move" and kvs and blocks:
        i = rng.choice(kvs)
        l = lines.pop(i)
        blocks = table_blocks(lines)
        if blocks:
            s, _ = rng.choice(blocks)
            lines.insert(s + 1, l)
            notes.append(f"move {l['path']} under [{lines[s]['name']}]")
        else:
            lines.insert(0, l)
            notes.append(f"move {l['path']} to the top")
        return join_lines(lines)
    if c == "unknown_key":
        key = rng.choice(["bogus_key = 1.0", "E2 = 3.0", "end_time = 1.0", "spacing_x = 0.1", "x = [0.0, 1.0]"])
        if blocks and rng.random() < 0.8:
            s, _ = rng.choice(blocks)
            lines.insert(s + 1, {"kind": "other", "line": key})
            notes.append(f"unknown key '{key}' in [{lines[s]['name']}]")
        else:
            lines.insert(0, {"kind": "other", "line": key})
            notes.append(f"unknown key '{key}' at the top")
        return join_lines(lines)
    if c == "unknown_table":
        t = rng.choice(["[bogus]\nx = 1.0", "[[bogus]]\nx = 1.0", "[material.sub]\nx = 1.0", "[functions.extra]\n"
                        "type = \"wobble\"", "[[boundary]]\nx = [1e300, 1e300]\nvelocity = { x = 0.0 }",
                        "[[probe]]\nname = \"p,q\"\nposition = [0.0, 0.0]\nfields = [\"vx\"]",
                        "[[geometry.block]]\nmin = [0.0, 0.0]\nmax = [1e9, 1e9]"])
        notes.append("add table " + t.split("\n")[0])
        return text + "\n" + t + "\n"
    if c == "delete_table" and blocks:
        s, e = rng.choice(blocks)
        notes.append(f"delete table [{lines[s]['name']}]")
        del lines[s:e]
        return join_lines(lines)
    if c == "duplicate_table" and blocks:
        s, e = rng.choice(blocks)
        notes.append(f"duplicate table [{lines[s]['name']}]")
        lines[e:e] = [dict(x) for x in lines[s:e]]
        return join_lines(lines)
    if c == "set" and kvs:
        i = rng.choice(kvs)
        l = lines[i]
        value = mutate_value(rng, l["value"])
        form = rng.randrange(10)
        key = l["path"]
        if form == 0:
            value = l["value"] + rng.choice(["abc", "x", " junk", "]", "}", "\"", ",2"])
        elif form == 1:
            value = l["value"] + rng.choice([" # comment", "\nextra = 1", "\n[material]\nE = 1.0"])
        elif form == 2:
            value = rng.choice(["", " ", "\"", "[1.0", "{x = ", "'a", "=", "==1"])
        elif form == 3:
            key = rng.choice([key + ".sub", key.replace(".", "..", 1), "." + key, key + ".", "boundary.99.x",
                              "boundary.x1.x", "probe.-1.name", "geometry.block.0.min.0", "time.end.x",
                              key.split(".")[0] + ". " + ".".join(key.split(".")[1:]), "a b", "material=E"])
        if key == "time.end":
            key = "time.cfl"  # keep the run short: time.end is set last
        state["sets"].append(f"{key}={value}")
        notes.append(f"--set {key}={value[:60]!r}")
        return text
    # syntax damage (also the fallback)
    data = bytearray(text.encode("utf-8"))
    k = rng.randrange(7)
    if k == 0 and data:
        n = rng.randrange(len(data))
        notes.append(f"truncate at byte {n}")
        return bytes(data[:n])
    if k == 1:
        positions = [i for i, b in enumerate(data) if chr(b) in '[]{}"=']
        if positions:
            p = rng.choice(positions)
            notes.append(f"delete {chr(data[p])!r} at byte {p}")
            del data[p]
            return bytes(data)
    if k == 2 and data:
        flips = rng.randint(1, 4)
        for _ in range(flips):
            data[rng.randrange(len(data))] = rng.randrange(256)
        notes.append(f"{flips} random byte flips")
        return bytes(data)
    if k == 3:
        p = rng.randrange(len(data) + 1)
        junk = bytes(rng.randrange(256) for _ in range(rng.randint(1, 8)))
        data[p:p] = junk
        notes.append(f"insert {len(junk)} random bytes at {p}")
        return bytes(data)
    if k == 4:
        nl = [i for i, b in enumerate(data) if b == 10]
        if nl:
            p = rng.choice(nl)
            del data[p]
            notes.append(f"join two lines at byte {p}")
            return bytes(data)
    if k == 5:
        notes.append("file doubled")
        return text + "\n" + text
    notes.append("swap two lines")
    ls = text.split("\n")
    a, b = rng.randrange(len(ls)), rng.randrange(len(ls))
    ls[a], ls[b] = ls[b], ls[a]
    return "\n".join(ls)


def make_input(seed, index, base_text):
    rng = random.Random(f"{seed}:{index}")
    state = {"sets": [], "no_end_override": False}
    notes = []
    data = base_text
    for _ in range(rng.choice([1, 1, 1, 2, 3])):
        if isinstance(data, bytes):
            try:
                data = data.decode("utf-8")
            except UnicodeDecodeError:
                break  # further line mutations need text; keep the byte damage
        data = mutate_structure(rng, data, notes, state)
    if isinstance(data, str):
        data = data.encode("utf-8")
    return data, notes, state


# --------------------------------------------------------------------------------------------
# Running and checking.

LOCATION_RE = re.compile(r"line \d+|key '|value set on the command line|--set '")
BAD_TEXT = ["terminate called", "Assertion", "AddressSanitizer", "runtime error:", "Segmentation", "Aborted",
            "std::bad_alloc", "what():"]


def command_for(binary, mode, path, out, base_end, state):
    if mode == "run":
        cmd = [binary, "run", str(path), "--out", str(out), "--quiet", "--threads", "1"]
        for s in state["sets"]:
            cmd += ["--set", s]
        if not state["no_end_override"]:
            cmd += ["--set", f"time.end={base_end!r}"]
        # A mutation that shrinks the time step (a stiffer or lighter material) would make even
        # three of the case's own steps a long run: the step guard refuses more than 1000.
        cmd += ["--set", "time.max_steps=1000"]
    else:
        cmd = [binary, "material-point", str(path), "--out", str(out)]
        for s in state["sets"]:
            cmd += ["--set", s]
        cmd += ["--set", "output.plot=false"]
    return cmd


def check(mode, rc, err, path, out):
    """None when the outcome keeps the contract, else why not."""
    for bad in BAD_TEXT:
        if bad in err:
            return f"stderr has '{bad}'"
    if rc is None:
        return "timeout (a hang)"
    if rc < 0:
        return f"killed by signal {-rc} (a crash)"
    if rc == 0:
        return None
    if rc == 2:
        if str(path) not in err:
            return "exit 2 without the file named"
        if not LOCATION_RE.search(err):
            return "exit 2 without a line or a key"
        return None
    if rc == 3:
        summary = Path(out) / "summary.json"
        if mode == "run" and summary.exists():
            try:
                s = json.loads(summary.read_text())
                if s.get("status") == "unstable" and s.get("message"):
                    return None
            except (ValueError, OSError):
                return "exit 3 with an unreadable summary.json"
        if "error:" in err:
            return None
        return "exit 3 without a diagnosis"
    return f"exit {rc}"


def diagnosis(r):
    """The solver's message of an exit-3 outcome (stderr, or summary.json with --quiet)."""
    return r.get("diagnosis") or r["message"]


def run_one(args, work, index, base, base_text, base_end):
    data, notes, state = make_input(args.seed, index, base_text)
    path = work / f"in_{index:05d}_{base.name}"
    out = work / f"out_{index:05d}"
    path.write_bytes(data)
    mode = "mp" if base.parent.name == "material_point" else "run"
    cmd = command_for(args.binary, mode, path, out, base_end, state)
    env = dict(os.environ, OMP_NUM_THREADS="1", OMP_WAIT_POLICY="passive")
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=args.timeout, env=env,
                           cwd=str(work))
        rc, err = p.returncode, p.stderr.decode("utf-8", "replace")
    except subprocess.TimeoutExpired as e:
        rc, err = None, (e.stderr or b"").decode("utf-8", "replace")
    seconds = time.monotonic() - t0
    why = check(mode, rc, err, path, out)
    result = {"index": index, "base": str(base.relative_to(ROOT)) if base.is_relative_to(ROOT) else str(base),
              "notes": notes, "rc": rc, "err": err, "why": why, "cmd": cmd, "seconds": seconds,
              "message": err.strip().split("\n")[-1][:300] if err.strip() else ""}
    if rc == 3 and (out / "summary.json").exists():
        try:
            result["diagnosis"] = json.loads((out / "summary.json").read_text()).get("message", "")
        except (ValueError, OSError):
            pass
    if why is not None:
        failures = work / "failures"
        failures.mkdir(exist_ok=True)
        shutil.copy(path, failures / path.name)
    if not args.keep or why is None:
        path.unlink(missing_ok=True)
        shutil.rmtree(out, ignore_errors=True)
    return result


def base_time_step(binary, base, work):
    """The case's own time step (one step run), for a --set time.end of three steps."""
    out = work / f"base_{base.stem}"
    cmd = [binary, "run", str(base), "--out", str(out), "--quiet", "--threads", "1", "--set", "time.end=1e-12"]
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=300,
                       env=dict(os.environ, OMP_NUM_THREADS="1"))
    if p.returncode != 0:
        sys.exit(f"fuzz_inputs: the unmutated case {base} does not run (exit {p.returncode}): "
                 f"{p.stderr.decode(errors='replace')}")
    dt = json.loads((out / "summary.json").read_text())["dt"]
    shutil.rmtree(out, ignore_errors=True)
    return 3.0 * dt


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", required=True)
    ap.add_argument("--cases", default=str(ROOT / "cases"), help="folder with thesis/ and material_point/")
    ap.add_argument("--count", type=int, default=4000)
    ap.add_argument("--seed", type=int, default=14)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per input before it counts as a hang")
    ap.add_argument("--work", default=None, help="work folder (default: a fresh one under /tmp)")
    ap.add_argument("--only", type=int, nargs="*", help="run only these input numbers, verbosely")
    ap.add_argument("--keep", action="store_true", help="keep every input and output folder")
    ap.add_argument("--verbose", action="store_true", help="print every input's outcome")
    args = ap.parse_args()
    args.binary = str(Path(args.binary).resolve())

    cases = Path(args.cases)
    bases = sorted((cases / "thesis").glob("*.toml")) + sorted((cases / "material_point").glob("*.toml"))
    if not bases:
        sys.exit(f"fuzz_inputs: no case files under {cases}")
    work = Path(args.work) if args.work else Path("/tmp") / f"rktsph_fuzz_{os.getpid()}"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)

    t0 = time.monotonic()
    texts = {b: b.read_text() for b in bases}
    ends = {}
    for b in bases:
        ends[b] = base_time_step(args.binary, b, work) if b.parent.name == "thesis" else None
    indices = args.only if args.only else list(range(args.count))
    results = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = []
        for i in indices:
            b = bases[i % len(bases)]
            futures.append(pool.submit(run_one, args, work, i, b, texts[b], ends[b]))
        for f in concurrent.futures.as_completed(futures):
            r = f.result()
            results.append(r)
            if args.verbose or args.only:
                print(f"[{r['index']}] {r['base']}: exit {r['rc']} in {r['seconds']:.2f} s; {'; '.join(r['notes'])}\n"
                      f"    {r['message']}")
    seconds = time.monotonic() - t0
    results.sort(key=lambda r: r["index"])

    by_rc = {}
    for r in results:
        by_rc[r["rc"]] = by_rc.get(r["rc"], 0) + 1
    failed = [r for r in results if r["why"] is not None]
    slowest = max(results, key=lambda r: r["seconds"])
    print(f"fuzz_inputs: {len(results)} inputs from {len(bases)} files, seed {args.seed}, {args.jobs} jobs, "
          f"{seconds:.1f} s; exit statuses: "
          + ", ".join(f"{k}: {v}" for k, v in sorted(by_rc.items(), key=lambda kv: (kv[0] is None, kv[0] or 0)))
          + f"; slowest input {slowest['index']} ({slowest['seconds']:.2f} s)")
    threes = [r for r in results if r["rc"] == 3 and r["why"] is None]
    if threes:
        print(f"exit 3, a solver diagnosis of a case the reader accepts ({len(threes)}):")
        for r in threes[:40]:
            print(f"  [{r['index']}] {r['base']}: {'; '.join(r['notes'])[:200]}\n      {diagnosis(r)[:200]}")
    for r in failed:
        print(f"\nFAILED input {r['index']} (seed {args.seed}; rerun: {sys.argv[0]} --binary {args.binary} "
              f"--seed {args.seed} --only {r['index']}): {r['why']}")
        print(f"  base: {r['base']}\n  mutations: {'; '.join(r['notes'])}")
        shown = [c if len(c) <= 200 else c[:200] + f"...({len(c)} characters)" for c in r["cmd"]]
        print(f"  command: {' '.join(repr(c) if (' ' in c or chr(10) in c) else c for c in shown)}")
        print(f"  input kept in: {work / 'failures'}")
        print("  stderr:\n    " + "\n    ".join(r["err"].strip().split("\n")[-15:]))
    if not failed and not args.keep:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
