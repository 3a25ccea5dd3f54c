#!/usr/bin/python3
"""Run two rktsph binaries on the quick validation cases and compare every output number.

Usage:
  /usr/bin/python3 scripts/compare_builds.py OLD_BIN NEW_BIN [--cases 01 02 ...] [--work DIR]
         [--runs] [--run-fraction F] [--jobs N] [--cases-dir DIR] [--tol 1e-12] [--compare-only]

  e.g. scripts/compare_builds.py /work/baseline/build/rktsph build/rktsph --runs

What it runs (cwd = the repository root of this script, the same for both binaries):
  * for each quick validation case ID (default 01 02 03 04 05 06 13 14 15 16 17):
      BIN validate --quick ID --threads 1 --no-plots --cases-dir CASES_DIR --out WORK/{old,new}/ID
    CASES_DIR defaults to cases/thesis of this script's repository, so both binaries read the
    same case files.
  * with --runs, for each case file CASES_DIR/NN_*.toml (those whose NN is in --cases):
      BIN run CASES_DIR/NN_x.toml --out WORK/{old,new}/runs/NN_x --quiet --threads 1
          --set time.end=T --set output.interval=T/2
    with T = F x the case's own time.end (F = --run-fraction, default 0.1), so each run writes
    three ParaView frames (t = 0, T/2, T) plus any output.times before T. Also, as CTest's
    run_default_case does, case 01 to its own end: --out WORK/{old,new}/runs/default_case.
  Old and new jobs are run side by side, --jobs at a time (default 2), longest cases first.
  Logs: WORK/logs/{old,new}-*.log.  --compare-only skips the runs and compares what is in WORK.

What is compared (WORK/old against WORK/new, every file in either tree):
  * a file present in one tree only: failure (except report.md/logs, reported as info).
  * *.csv: column by column by header name (a column in one file only is a failure, as is a
    different number of rows); every numeric cell: max absolute and max relative difference,
    relative to max(|a|, |b|, 1e-300); non-numeric cells must be equal. Also reported, as
    information only: the difference relative to the column's largest magnitude, and whether
    every difference is at most one unit in the last printed digit (the CSVs carry 8-10
    significant digits, so a 1e-16 change can show as a 1e-10 change in the last digit).
  * *.vtu: every DataArray (PointData fields, Points, Cells), decoded from the base64 "binary"
    inline encoding written by src/io/vtu_writer.cpp (UInt32 byte count, then the data); also
    NumberOfPoints. *.pvd: the time step of every frame (numerically) and its file name.
  * summary.json (and any other .json): every numeric field (nested keys flattened with '.'),
    except timing fields (keys containing "seconds", "per_second" or "loop_time": wall_seconds,
    setup_seconds, node_steps_per_second*, pressure_solve.share_of_loop_time, ...); strings and
    null must be equal except git_revision and version (info). The memory fields bytes_* (the
    program's own count of what it holds) are information; what is checked is the peak
    resident memory of every run (os.wait4): new must not exceed old by more than 5 % + 2 MiB.
  * report.md of each validation: the "| metric | value |" rows of each case's table, and the
    case status, are compared as information only (printed with 4 digits, run times differ).
  * other files (case.resolved.toml, plot_input.txt, ...): byte equality, information only.
  * the exit status of every run: old and new must agree.
  Each CSV column / VTU array / JSON field is classified bit-identical (every value equal),
  within TOL (max relative difference <= --tol, default 1e-12), or DIFFERENT.

Bit for bit: GCC fuses a * b + c into one FMA wherever its optimiser sees fit, so two versions
of the code with the same arithmetic round differently once inlining changes. For the claim
"same arithmetic", build both versions without contraction and compare those:
  cmake -S OLD_TREE -B OLD_TREE/build-nofma -DRKTSPH_FP_CONTRACT_OFF=ON   (or CMAKE_CXX_FLAGS=-ffp-contract=off)
  cmake -S .        -B build-nofma          -DRKTSPH_FP_CONTRACT_OFF=ON
  scripts/compare_builds.py OLD_TREE/build-nofma/rktsph build-nofma/rktsph --runs
Compare the default builds as well to see how far round-off alone moves the results.

Output: a summary table on stdout, the full report in WORK/compare.md.
Exit status: 0 if everything is bit-identical or within TOL and nothing is missing;
             1 if anything is DIFFERENT, missing, unreadable, or an exit status differs;
             2 on bad arguments (e.g. a binary that does not exist).
Needs Debian's /usr/bin/python3 with numpy.
"""
import argparse
import base64
import csv
import datetime
import json
import math
import os
import re
import shutil
import subprocess
import sys
import threading
import time
import tomllib
import xml.etree.ElementTree as ET
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
QUICK_CASES = ["01", "02", "03", "04", "05", "06", "13", "14", "15", "16", "17"]
# Rough single-thread seconds of each quick case (17fa763, this 2-core machine): longest first.
COST = {"15": 72, "16": 42, "17": 14, "14": 10, "06": 8, "05": 5, "03": 3, "13": 3, "02": 2,
        "04": 1, "01": 1}
TINY = 1e-300

# ----------------------------------------------------------------------------------------------
# running


def version_of(binary):
    if not os.access(binary, os.X_OK):
        return "(not an executable)"
    try:
        r = subprocess.run([binary, "--version"], capture_output=True, text=True, timeout=60)
        return (r.stdout or r.stderr).strip()
    except OSError as e:
        return f"(cannot run: {e})"


def short_end(case_file, fraction):
    with open(case_file, "rb") as f:
        doc = tomllib.load(f)
    end = float(doc["time"]["end"])
    return repr(end * fraction), repr(end * fraction / 2.0)


class Job:
    def __init__(self, side, name, group, cmd, cost):
        self.side, self.name, self.group, self.cmd, self.cost = side, name, group, cmd, cost
        self.rc, self.seconds, self.max_rss_kib = None, None, None


def run_jobs(jobs, logs, n_jobs):
    lock = threading.Lock()
    t_start = time.monotonic()

    def one(job):
        log = logs / f"{job.side}-{job.name}.log"
        t0 = time.monotonic()
        with open(log, "w") as f:
            f.write(" ".join(job.cmd) + "\n\n")
            f.flush()
            try:
                # os.wait4 gives this child's own resource usage: its peak resident memory.
                proc = subprocess.Popen(job.cmd, cwd=REPO, stdout=f, stderr=subprocess.STDOUT)
                _, status, usage = os.wait4(proc.pid, 0)
                proc.returncode = os.waitstatus_to_exitcode(status)
                job.rc = proc.returncode
                job.max_rss_kib = usage.ru_maxrss
            except OSError as e:
                f.write(f"cannot run: {e}\n")
                job.rc = -1
        job.seconds = time.monotonic() - t0
        with lock:
            print(f"  [{time.monotonic() - t_start:7.1f} s] {job.side:3} {job.name:40} rc={job.rc} "
                  f"{job.seconds:6.1f} s", file=sys.stderr, flush=True)

    with ThreadPoolExecutor(max_workers=max(1, n_jobs)) as pool:
        list(pool.map(one, jobs))
    return time.monotonic() - t_start


# ----------------------------------------------------------------------------------------------
# comparison results


class Item:
    """One compared quantity (a CSV column, a VTU array, a JSON field, ...)."""

    def __init__(self, group, file, name, status, max_abs=0.0, max_rel=0.0, note="", count=0,
                 info=False, col_rel=None, last_digit=None):
        self.group, self.file, self.name, self.status = group, file, name, status
        self.max_abs, self.max_rel, self.note, self.count = max_abs, max_rel, note, count
        self.info, self.col_rel, self.last_digit = info, col_rel, last_digit

    @property
    def failed(self):
        return not self.info and self.status not in ("identical", "within")


def classify(max_rel, all_equal, tol):
    if all_equal:
        return "identical"
    return "within" if max_rel <= tol else "DIFFERENT"


def numeric_diff(a, b):
    """a, b float arrays of one shape. Returns (all_equal, max_abs, max_rel, n_diff, col_rel)."""
    both_nan = np.isnan(a) & np.isnan(b)
    same = (a == b) | both_nan
    if same.all():
        return True, 0.0, 0.0, 0, 0.0
    with np.errstate(invalid="ignore", over="ignore"):
        d = np.abs(a - b)
        d[same] = 0.0
        d[np.isnan(d)] = math.inf  # nan against a number, or inf against -inf
        scale = np.maximum(np.maximum(np.abs(a), np.abs(b)), TINY)
        rel = d / scale
        rel[same] = 0.0
        rel[np.isnan(rel)] = math.inf
        finite = np.abs(np.where(np.isfinite(a), a, 0.0)).max(initial=0.0)
        finite = max(finite, np.abs(np.where(np.isfinite(b), b, 0.0)).max(initial=0.0), TINY)
    max_abs = float(d.max())
    return False, max_abs, float(rel.max()), int((~same).sum()), max_abs / finite


NUM_RE = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


def last_unit(s):
    """One unit in the last printed digit of the number string s (None if not a plain number)."""
    m = NUM_RE.match(s.strip())
    if not m:
        return None
    mant, exp = m.group(1), int(m.group(2)[1:]) if m.group(2) else 0
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    return 10.0 ** (exp - decimals)


def to_float(s):
    try:
        return float(s)
    except ValueError:
        return None


# ----------------------------------------------------------------------------------------------
# file comparers; each returns a list of Items


def compare_csv(group, rel, pa, pb, tol):
    items = []
    with open(pa, newline="") as f:
        ra = list(csv.reader(f))
    with open(pb, newline="") as f:
        rb = list(csv.reader(f))
    if not ra or not rb:
        st = "identical" if ra == rb else "DIFFERENT"
        return [Item(group, rel, "(file)", st, note="empty file" if st == "identical" else "one file empty")]

    def columns(rows):
        header, cols = [], {}
        for i, h in enumerate(rows[0]):
            key = h if h not in cols else f"{h}#{i}"
            header.append(key)
            cols[key] = [r[i] if i < len(r) else None for r in rows[1:]]
        return header, cols

    ha, ca = columns(ra)
    hb, cb = columns(rb)
    if len(ra) != len(rb):
        items.append(Item(group, rel, "(rows)", "DIFFERENT", note=f"{len(ra) - 1} rows old, {len(rb) - 1} new"))
    ragged = sum(1 for r in ra[1:] if len(r) != len(ra[0])) + sum(1 for r in rb[1:] if len(r) != len(rb[0]))
    if ragged:
        items.append(Item(group, rel, "(rows)", "DIFFERENT", note=f"{ragged} rows with a wrong number of cells"))
    for name in ha + [h for h in hb if h not in ca]:
        if name not in cb or name not in ca:
            items.append(Item(group, rel, name, "MISSING", note="column only in " + ("old" if name in ca else "new")))
            continue
        items.append(compare_cells(group, rel, name, ca[name], cb[name], tol))
    return items


def compare_cells(group, rel, name, xa, xb, tol):
    n = min(len(xa), len(xb))
    fa, fb, text_bad, text_note, last_ok = [], [], 0, "", True
    all_text_equal = True
    for k in range(n):
        sa, sb = xa[k], xb[k]
        if sa != sb:
            all_text_equal = False
        if sa is None or sb is None:
            text_bad += 1
            continue
        va, vb = to_float(sa), to_float(sb)
        if va is None or vb is None:
            if sa != sb:
                text_bad += 1
                text_note = text_note or f"row {k + 1}: {sa!r} vs {sb!r}"
            continue
        fa.append(va)
        fb.append(vb)
        if va != vb and not (math.isnan(va) and math.isnan(vb)):
            ua, ub = last_unit(sa), last_unit(sb)
            if ua is None or ub is None or abs(va - vb) > 1.000001 * max(ua, ub):
                last_ok = False
    a, b = np.array(fa, dtype=float), np.array(fb, dtype=float)
    equal, max_abs, max_rel, n_diff, col_rel = numeric_diff(a, b)
    status = classify(max_rel, equal, tol)
    if text_bad:
        status = "DIFFERENT"
    note = []
    if text_bad:
        note.append(f"{text_bad} non-numeric cells differ" + (f" ({text_note})" if text_note else ""))
    if n_diff:
        note.append(f"{n_diff}/{len(fa)} cells differ")
    elif equal and not all_text_equal and not text_bad:
        note.append("same values, different text")
    return Item(group, rel, name, status, max_abs, max_rel, "; ".join(note), len(fa),
                col_rel=col_rel if n_diff else None, last_digit=(last_ok if n_diff else None))


VTK_TYPES = {"Float64": "<f8", "Float32": "<f4", "Int64": "<i8", "Int32": "<i4", "UInt64": "<u8",
             "UInt32": "<u4", "Int16": "<i2", "UInt16": "<u2", "Int8": "i1", "UInt8": "u1"}


def read_vtu(path):
    """{array key: numpy array}, plus {'(NumberOfPoints)': ...} for one VTU file."""
    root = ET.parse(path).getroot()
    if root.get("compressor"):
        raise ValueError("compressed VTU not supported")
    header_type = root.get("header_type", "UInt32")
    hsize = np.dtype(VTK_TYPES[header_type]).itemsize
    big = root.get("byte_order", "LittleEndian") == "BigEndian"
    out = {}
    for piece_no, piece in enumerate(root.iter("Piece")):
        pre = f"piece{piece_no}/" if piece_no else ""
        out[pre + "(NumberOfPoints)"] = np.array([float(piece.get("NumberOfPoints", "nan"))])
        out[pre + "(NumberOfCells)"] = np.array([float(piece.get("NumberOfCells", "nan"))])
        for section in piece:
            for da in section.iter("DataArray"):
                key = pre + section.tag + ("/" + da.get("Name") if da.get("Name") else "")
                while key in out:
                    key += "'"
                dt = np.dtype(VTK_TYPES[da.get("type")])
                if big:
                    dt = dt.newbyteorder(">")
                text = "".join((da.text or "").split())
                fmt = da.get("format", "ascii")
                if fmt == "binary":
                    hlen = 4 * ((hsize + 2) // 3)
                    nbytes = int(np.frombuffer(base64.b64decode(text[:hlen]), dtype=VTK_TYPES[header_type])[0])
                    raw = base64.b64decode(text[hlen:])
                    if len(raw) < nbytes:
                        raise ValueError(f"{key}: {len(raw)} bytes for a header of {nbytes}")
                    arr = np.frombuffer(raw[:nbytes], dtype=dt)
                elif fmt == "ascii":
                    arr = np.array((da.text or "").split(), dtype=dt)
                else:
                    raise ValueError(f"{key}: format {fmt} not supported")
                ncomp = int(da.get("NumberOfComponents", "1"))
                out[key] = arr.reshape(-1, ncomp) if ncomp > 1 and arr.size % ncomp == 0 else arr
    return out


def compare_arrays(group, rel, da, db, tol):
    items = []
    for key in list(da) + [k for k in db if k not in da]:
        if key not in da or key not in db:
            items.append(Item(group, rel, key, "MISSING", note="array only in " + ("old" if key in da else "new")))
            continue
        a, b = da[key], db[key]
        if a.shape != b.shape:
            items.append(Item(group, rel, key, "DIFFERENT", note=f"shape {a.shape} old, {b.shape} new"))
            continue
        if a.tobytes() == b.tobytes():
            items.append(Item(group, rel, key, "identical", count=a.size))
            continue
        equal, max_abs, max_rel, n_diff, col_rel = numeric_diff(a.astype(float).ravel(), b.astype(float).ravel())
        status = classify(max_rel, equal, tol)
        note = f"{n_diff}/{a.size} values differ" if n_diff else "same values, different bits (e.g. -0.0 / 0.0)"
        items.append(Item(group, rel, key, status, max_abs, max_rel, note, a.size, col_rel=col_rel if n_diff else None))
    return items


def compare_pvd(group, rel, pa, pb, tol):
    def read(p):
        ds = list(ET.parse(p).getroot().iter("DataSet"))
        return [float(d.get("timestep")) for d in ds], [d.get("file") for d in ds]
    ta, fa = read(pa)
    tb, fb = read(pb)
    items = []
    if fa != fb:
        items.append(Item(group, rel, "file", "DIFFERENT", note=f"{len(fa)} frames old, {len(fb)} new" if len(fa) != len(fb) else "file names differ"))
    else:
        items.append(Item(group, rel, "file", "identical", count=len(fa)))
    if len(ta) == len(tb):
        equal, max_abs, max_rel, n_diff, col_rel = numeric_diff(np.array(ta), np.array(tb))
        items.append(Item(group, rel, "timestep", classify(max_rel, equal, tol), max_abs, max_rel,
                          f"{n_diff}/{len(ta)} differ" if n_diff else "", len(ta)))
    return items


TIMING_KEY = re.compile(r"seconds|per_second|loop_time")
INFO_KEYS = {"git_revision", "version"}


def flatten(obj, prefix=""):
    if isinstance(obj, dict):
        out = {}
        for k, v in obj.items():
            out.update(flatten(v, f"{prefix}{k}."))
        return out
    if isinstance(obj, list):
        out = {}
        for i, v in enumerate(obj):
            out.update(flatten(v, f"{prefix}{i}."))
        return out
    return {prefix[:-1]: obj}


def compare_json(group, rel, pa, pb, tol):
    with open(pa) as f:
        ja = flatten(json.load(f))
    with open(pb) as f:
        jb = flatten(json.load(f))
    items = []
    for key in list(ja) + [k for k in jb if k not in ja]:
        leaf = key.rsplit(".", 1)[-1]
        if TIMING_KEY.search(key):
            continue
        if key not in ja or key not in jb:
            items.append(Item(group, rel, key, "MISSING", note="field only in " + ("old" if key in ja else "new")))
            continue
        a, b = ja[key], jb[key]
        num = lambda v: isinstance(v, (int, float)) and not isinstance(v, bool)
        if leaf in INFO_KEYS:
            items.append(Item(group, rel, key, "identical" if a == b else "differs", note="" if a == b else f"{a!r} vs {b!r}", info=True))
        elif num(a) and num(b):
            equal, max_abs, max_rel, _, _ = numeric_diff(np.array([float(a)]), np.array([float(b)]))
            if leaf.startswith("bytes"):
                # The program's own accounting of what it holds: information. What it really
                # holds, the peak resident memory of the run, is checked below (rss_items).
                items.append(Item(group, rel, key, "identical" if equal else ("lower" if b < a else "higher"),
                                  max_abs, max_rel, "" if equal else f"{a} -> {b} (counted memory)", 1, info=True))
            else:
                items.append(Item(group, rel, key, classify(max_rel, equal, tol), max_abs, max_rel,
                                  "" if equal else f"{a!r} vs {b!r}", 1))
        else:
            items.append(Item(group, rel, key, "identical" if a == b else "DIFFERENT", note="" if a == b else f"{a!r} vs {b!r}", count=1))
    return items


# Peak resident memory may grow by allocator noise and the binary's size, not more.
RSS_SLACK_KIB, RSS_SLACK_REL = 2048, 0.05


def rss_items(jobs):
    """Peak resident memory of each run, old against new: HIGHER fails."""
    items = []
    by_name = {(j.side, j.name): j for j in jobs}
    for j in jobs:
        if j.side != "old":
            continue
        n = by_name.get(("new", j.name))
        if n is None or j.max_rss_kib is None or n.max_rss_kib is None:
            continue
        a, b = j.max_rss_kib, n.max_rss_kib
        note = f"{a / 1024:.1f} -> {b / 1024:.1f} MiB"
        if b > a * (1 + RSS_SLACK_REL) + RSS_SLACK_KIB:
            items.append(Item(j.group, "(process)", "peak RSS", "HIGHER", b - a, (b - a) / a, note + " (memory must not grow)", 1))
        else:
            items.append(Item(j.group, "(process)", "peak RSS", "identical" if a == b else "within", 0.0, 0.0, note, 0, info=True))
    return items


def parse_report(path):
    """{(section, metric): value string} and {(section, 'status'): ...} from a validation report.md."""
    out, section, in_metrics, in_cases = {}, "", False, False
    with open(path) as f:
        for line in f:
            line = line.rstrip("\n")
            if line.startswith("## "):
                section, in_metrics, in_cases = line[3:].strip(), False, False
                continue
            if not line.startswith("|"):
                in_metrics = in_cases = False
                continue
            inner = line.strip()[1:]
            inner = inner[:-1] if inner.endswith("|") else inner
            parts = [p.strip() for p in inner.split(" | ")]
            if parts[:2] == ["metric", "value"]:
                in_metrics = True
                continue
            if parts[:2] == ["case", "status"]:
                in_cases = True
                continue
            if set(inner.replace("|", "").strip()) <= set("-: "):
                continue
            if in_cases and len(parts) >= 2:
                out[("cases", parts[0] + " [status]")] = parts[1]
            elif in_metrics:
                # metric names may contain '|' (e.g. max |sigma|): the value is the first part after
                # the name that starts like a number
                i = next((i for i in range(1, len(parts)) if re.match(r"^[-+]?(\d|\.\d|nan|inf)", parts[i])), 1)
                key = (section, " | ".join(parts[:i]))
                while key in out:
                    key = (key[0], key[1] + "'")
                out[key] = parts[i] if i < len(parts) else ""
    return out


def compare_report(group, rel, pa, pb):
    ra, rb = parse_report(pa), parse_report(pb)
    items = []
    for key in list(ra) + [k for k in rb if k not in ra]:
        name = f"{key[0][:30]}: {key[1]}"
        if key not in ra or key not in rb:
            items.append(Item(group, rel, name, "only " + ("old" if key in ra else "new"), info=True))
            continue
        a, b = ra[key], rb[key]
        if a == b:
            items.append(Item(group, rel, name, "identical", count=1, info=True))
            continue
        na, nb = to_float(a.split()[0]) if a else None, to_float(b.split()[0]) if b else None
        if na is not None and nb is not None:
            _, max_abs, max_rel, _, _ = numeric_diff(np.array([na]), np.array([nb]))
            items.append(Item(group, rel, name, "differs", max_abs, max_rel, f"{a} vs {b}", 1, info=True))
        else:
            items.append(Item(group, rel, name, "differs", note=f"{a} vs {b}", count=1, info=True))
    return items


def compare_trees(old, new, tol):
    files_a = {p.relative_to(old).as_posix() for p in old.rglob("*") if p.is_file()}
    files_b = {p.relative_to(new).as_posix() for p in new.rglob("*") if p.is_file()}
    items = []
    for rel in sorted(files_a | files_b):
        parts = rel.split("/")
        group = "/".join(parts[:2]) if parts[0] == "runs" else parts[0]
        pa, pb = old / rel, new / rel
        name = parts[-1]
        soft = name == "report.md"
        if rel not in files_a or rel not in files_b:
            items.append(Item(group, rel, "(file)", "MISSING", note="file only in " + ("old" if rel in files_a else "new"), info=soft))
            continue
        try:
            if name.endswith(".csv"):
                items += compare_csv(group, rel, pa, pb, tol)
            elif name.endswith(".vtu"):
                items += compare_arrays(group, rel, read_vtu(pa), read_vtu(pb), tol)
            elif name.endswith(".pvd"):
                items += compare_pvd(group, rel, pa, pb, tol)
            elif name.endswith(".json"):
                items += compare_json(group, rel, pa, pb, tol)
            elif name == "report.md":
                items += compare_report(group, rel, pa, pb)
            else:
                same = pa.read_bytes() == pb.read_bytes()
                items.append(Item(group, rel, "(bytes)", "identical" if same else "differs", info=True))
        except Exception as e:  # an unreadable file is a failure, not a crash
            items.append(Item(group, rel, "(file)", "UNREADABLE", note=f"{type(e).__name__}: {e}"))
    return items


# ----------------------------------------------------------------------------------------------
# report


def g(x):
    return "" if x is None else f"{x:.3g}"


def item_row(it):
    ld = "" if it.last_digit is None else ("yes" if it.last_digit else "no")
    return (f"| {it.group} | {it.file} | {it.name} | {it.status}{' (info)' if it.info else ''} | {g(it.max_abs) if it.max_abs else ''} | "
            f"{g(it.max_rel) if it.max_rel else ''} | {g(it.col_rel)} | {ld} | {it.note} |")


ITEM_HEAD = ("| group | file | column / array / field | status | max abs diff | max rel diff | "
             "rel to column max | last digit only | note |\n|---|---|---|---|---|---|---|---|---|")


def summarise(items, jobs, tol):
    groups = {}
    for it in items:
        groups.setdefault(it.group, []).append(it)
    rc_fail = {}
    for j in jobs:
        rc_fail.setdefault(j.group, {})[j.side] = j.rc
    rows = []
    for grp in sorted(set(groups) | set(rc_fail)):
        its = [i for i in groups.get(grp, []) if not i.info]
        rcs = rc_fail.get(grp, {})
        rc_text = "" if not rcs else f"{rcs.get('old')}/{rcs.get('new')}"
        n_files = len({i.file for i in groups.get(grp, [])})
        ident = sum(i.status == "identical" for i in its)
        within = sum(i.status == "within" for i in its)
        bad = sum(i.failed for i in its)
        rc_bad = bool(rcs) and rcs.get("old") != rcs.get("new")
        info_diff = sum(1 for i in groups.get(grp, []) if i.info and i.status not in ("identical",))
        max_rel = max((i.max_rel for i in its), default=0.0)
        verdict = ("DIFFERENT" if bad or rc_bad or not its else
                   "within tol" if within else "bit-identical")
        rows.append((grp, rc_text, n_files, len(its), ident, within, bad, info_diff, max_rel, verdict))
    return rows


def table(rows):
    head = ("| group | rc old/new | files | compared | bit-identical | within tol | DIFFERENT/missing | "
            "info diffs | max rel diff | verdict |\n|---|---|---|---|---|---|---|---|---|---|")
    lines = [head]
    for r in rows:
        lines.append(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]} | {r[4]} | {r[5]} | {r[6]} | {r[7]} | {g(r[8]) if r[8] else '0'} | {r[9]} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="See the top of this file for what is compared and the exit status.")
    ap.add_argument("old_bin")
    ap.add_argument("new_bin")
    ap.add_argument("--cases", nargs="+", default=QUICK_CASES, metavar="ID")
    ap.add_argument("--work", default=str(REPO / "build-compare"), help="output folder (default: REPO/build-compare)")
    ap.add_argument("--cases-dir", default=str(REPO / "cases" / "thesis"))
    ap.add_argument("--runs", action="store_true", help="also run every thesis case file for a short time")
    ap.add_argument("--run-fraction", type=float, default=0.1, help="fraction of each case's time.end for --runs (0.1)")
    ap.add_argument("--jobs", type=int, default=2, help="binaries run side by side (2)")
    ap.add_argument("--tol", type=float, default=1e-12, help="relative tolerance (1e-12)")
    ap.add_argument("--compare-only", action="store_true", help="do not run; compare what is in WORK/old and WORK/new")
    args = ap.parse_args()

    work = Path(args.work).resolve()
    old_bin, new_bin = (str(Path(b).resolve()) for b in (args.old_bin, args.new_bin))
    cases_dir = Path(args.cases_dir).resolve()
    for b in (old_bin, new_bin):
        if not args.compare_only and not os.access(b, os.X_OK):
            ap.error(f"not an executable: {b}")
    if not cases_dir.is_dir():
        ap.error(f"no cases folder: {cases_dir}")
    try:  # the case paths as the binaries see them (cwd = REPO): relative when inside REPO
        cases_arg = cases_dir.relative_to(REPO).as_posix()
    except ValueError:
        cases_arg = str(cases_dir)

    sides = {"old": old_bin, "new": new_bin}
    versions = {s: version_of(b) for s, b in sides.items()}
    jobs = []
    for cid in sorted(args.cases, key=lambda c: -COST.get(c, 10)):
        for side, b in sides.items():
            jobs.append(Job(side, f"validate-{cid}", cid,
                            [b, "validate", "--quick", cid, "--threads", "1", "--no-plots",
                             "--cases-dir", cases_arg, "--out", str(work / side / cid)], COST.get(cid, 10)))
    if args.runs:
        run_jobs_list = []
        for f in sorted(cases_dir.glob("[0-9][0-9]*_*.toml")):
            if f.name[:2] not in args.cases:
                continue
            end, interval = short_end(f, args.run_fraction)
            for side, b in sides.items():
                run_jobs_list.append(Job(side, f"run-{f.stem}", f"runs/{f.stem}",
                                         [b, "run", f"{cases_arg}/{f.name}", "--out", str(work / side / "runs" / f.stem),
                                          "--quiet", "--threads", "1", "--set", f"time.end={end}",
                                          "--set", f"output.interval={interval}"], 0))
        default = cases_dir / "01_elastic_bar_1d.toml"
        if "01" in args.cases and default.exists():  # CTest's run_default_case: case 01 to its end
            for side, b in sides.items():
                run_jobs_list.append(Job(side, "run-default-case", "runs/default_case", [
                    b, "run", f"{cases_arg}/{default.name}", "--out", str(work / side / "runs" / "default_case"),
                    "--quiet", "--threads", "1"], 0))
        jobs = jobs[:2] + run_jobs_list + jobs[2:]  # the short runs fill the gaps of the longest case

    wall = None
    if not args.compare_only:
        for side in sides:
            shutil.rmtree(work / side, ignore_errors=True)
            (work / side).mkdir(parents=True)
        logs = work / "logs"
        shutil.rmtree(logs, ignore_errors=True)
        logs.mkdir(parents=True)
        print(f"running {len(jobs)} jobs, {args.jobs} at a time; logs in {logs}", file=sys.stderr, flush=True)
        wall = run_jobs(jobs, logs, args.jobs)
    else:
        jobs = []

    t0 = time.monotonic()
    items = compare_trees(work / "old", work / "new", args.tol) + rss_items(jobs)
    cmp_seconds = time.monotonic() - t0
    rows = summarise(items, jobs, args.tol)
    failed = [i for i in items if i.failed]
    rc_bad = [j for j in jobs if j.side == "old" and next((k.rc for k in jobs if k.side == "new" and k.name == j.name), None) != j.rc]
    nonzero = [j for j in jobs if j.rc != 0]
    ok = not failed and not rc_bad and bool(items)

    counts = {s: sum(1 for i in items if not i.info and i.status == s) for s in ("identical", "within")}
    verdict = (f"PASS: {counts['identical']} bit-identical, {counts['within']} within {args.tol:g} relative"
               if ok else f"FAIL: {len(failed)} DIFFERENT or missing, {len(rc_bad)} exit-status mismatches"
               f" ({counts['identical']} bit-identical, {counts['within']} within {args.tol:g})")

    md = [f"# compare_builds: {datetime.datetime.now().isoformat(timespec='seconds')}", "",
          f"- old: `{old_bin}` — {versions['old']}", f"- new: `{new_bin}` — {versions['new']}",
          f"- cases: {' '.join(args.cases)}; cases dir: `{cases_dir}`; runs: "
          f"{'yes, time.end = ' + str(args.run_fraction) + ' x the case end' if args.runs else 'no'}",
          f"- tolerance: {args.tol:g} relative, per value, to max(|old|, |new|, {TINY:g})",
          f"- wall time: {'%.1f s' % wall if wall is not None else 'not run (--compare-only)'} for the runs "
          f"({args.jobs} jobs at a time), {cmp_seconds:.1f} s for the comparison", "",
          f"**{verdict}**", "", "## Summary", "", table(rows), ""]
    if nonzero:
        md += ["Non-zero exit statuses: " + ", ".join(f"{j.side} {j.name} rc={j.rc}" for j in nonzero), ""]
    md += ["## DIFFERENT or missing", ""]
    md += ([ITEM_HEAD] + [item_row(i) for i in failed]) if failed else ["none"]
    md += ["", "## Within tolerance (not bit-identical)", ""]
    within = [i for i in items if not i.info and i.status == "within"]
    md += ([ITEM_HEAD] + [item_row(i) for i in within]) if within else ["none"]
    md += ["", "## Information (report.md metrics, memory reductions, other files) that differ", ""]
    info = [i for i in items if i.info and i.status != "identical"]
    md += ([ITEM_HEAD] + [item_row(i) for i in info]) if info else ["none"]
    md += ["", "## Jobs", "", "| side | job | rc | seconds | command |", "|---|---|---|---|---|"]
    md += [f"| {j.side} | {j.name} | {j.rc} | {j.seconds:.1f} | `{' '.join(j.cmd)}` |" for j in jobs]
    md += ["", "## Everything compared", "", ITEM_HEAD] + [item_row(i) for i in items]
    work.mkdir(parents=True, exist_ok=True)
    (work / "compare.md").write_text("\n".join(md) + "\n")

    print(f"old: {versions['old']}  ({old_bin})\nnew: {versions['new']}  ({new_bin})")
    print(table(rows))
    for i in failed[:40]:
        print(f"  DIFFERENT {i.file} :: {i.name}: {i.status} max_abs={g(i.max_abs)} max_rel={g(i.max_rel)} {i.note}")
    if len(failed) > 40:
        print(f"  ... and {len(failed) - 40} more (see compare.md)")
    for j in rc_bad:
        print(f"  exit status differs: {j.name}")
    if wall is not None:
        print(f"wall time {wall:.1f} s ({args.jobs} jobs at a time), comparison {cmp_seconds:.1f} s")
    print(verdict)
    print(f"report: {work / 'compare.md'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
