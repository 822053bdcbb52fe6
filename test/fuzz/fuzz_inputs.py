#!/usr/bin/env python3
"""Seeded fuzzing of the inputs: mutates the shipped scene and solver files (names misspelled,
types changed, values made negative, zero, huge, tiny, non-finite or words, vectors of the wrong
length, entries and sections deleted, files cut short or pointing nowhere) and runs viscompm on
each variant. Every run must end with exit 0, 2 or 3 within its time limit: exit 2 and 3 with
one line on stderr, no crash, no hang, no "internal error", and every frame it wrote finite. A
valid input may be slow (e.g. a finer grid): at the time limit the run gets SIGTERM and must stop
with exit 4 within the grace period (it did not hang); such runs are counted, not failed.

  fuzz_inputs.py --viscompm build/bin/viscompm --inputs inputs --workdir /tmp/fuzz --seed 1 --variants 5000
"""
import argparse
import concurrent.futures
import glob
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import h5py
import numpy as np

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--viscompm", required=True)
parser.add_argument("--inputs", required=True)
parser.add_argument("--workdir", required=True)
parser.add_argument("--seed", type=int, default=12)
parser.add_argument("--variants", type=int, default=100)
parser.add_argument("--jobs", type=int, default=2)
parser.add_argument("--time-limit", type=float, default=60.0, help="seconds before SIGTERM")
parser.add_argument("--grace", type=float, default=60.0, help="seconds a run may take to stop after SIGTERM")
parser.add_argument("--keep", action="store_true", help="keep the work directory of every variant")
parser.add_argument("--verbose", action="store_true", help="print every variant's outcome")
# Accepted for the common test interface (the runs use one rank, without mpiexec).
parser.add_argument("--ranks", type=int, default=1)
parser.add_argument("--mpiexec", default="")
args = parser.parse_args()

scenes = sorted(glob.glob(os.path.join(args.inputs, "scenes", "*.xml")))
solvers = sorted(glob.glob(os.path.join(args.inputs, "solvers", "*.xml")))
# A cheap scene to run the solver variants with, whose first step solves (the sponge on a coarse
# grid: one Newton iteration, 5-15 CG iterations), so that the preconditioner is set up and applied.
solver_scene = os.path.join(args.inputs, "scenes", "shooting_sponge.xml")
solver_scene_settings = ["--set", "Grid/Cell size=0.06"]

WORDS = ["", "x", "true", "none", "-", "1e", "0x10", "{}", "NaN"]
NUMBERS = ["-1", "0", "1e-300", "1e300", "-1e300", "nan", "inf", "-inf", "1e309", "2147483647", "-2147483648",
           "0.5", "3", "1e-9", "1e9"]


def typo(text, rng):
    if not text:
        return "x"
    i = rng.randrange(len(text))
    kind = rng.randrange(3)
    if kind == 0:
        return text[:i] + text[i + 1:]
    if kind == 1:
        return text[:i] + rng.choice("abcdefghijklmnopqrstuvwxyz ") + text[i:]
    j = min(i + 1, len(text) - 1)
    chars = list(text)
    chars[i], chars[j] = chars[j], chars[i]
    return "".join(chars)


def mutate(root, rng):
    """Applies one mutation to the parsed list; returns a one-line description."""
    parameters = [p for p in root.iter("Parameter")]
    lists = [l for l in root.iter("ParameterList") if l is not root]
    kind = rng.choice(["rename", "retype", "number", "number", "number", "word", "vector", "delete",
                       "delete_list", "rename_list", "typo_value"])
    if kind in ("delete_list", "rename_list") and lists:
        target = rng.choice(lists)
        if kind == "rename_list":
            target.set("name", typo(target.get("name"), rng))
            return f"renamed list to '{target.get('name')}'"
        for parent in root.iter():
            if target in list(parent):
                parent.remove(target)
                return f"deleted list '{target.get('name')}'"
    if not parameters:
        return "nothing to mutate"
    p = rng.choice(parameters)
    name, value, kind_of = p.get("name"), p.get("value", ""), p.get("type", "")
    if kind == "rename":
        p.set("name", typo(name, rng))
        return f"renamed '{name}' to '{p.get('name')}'"
    if kind == "retype":
        p.set("type", rng.choice([t for t in ["double", "int", "string", "bool", "Array(double)"] if t != kind_of]))
        return f"'{name}' type {kind_of} -> {p.get('type')} (value {value})"
    if kind == "number":
        p.set("value", rng.choice(NUMBERS))
        return f"'{name}' = {p.get('value')}"
    if kind == "word":
        p.set("value", rng.choice(WORDS))
        return f"'{name}' = '{p.get('value')}'"
    if kind == "vector":
        p.set("type", "Array(double)")
        p.set("value", rng.choice(["{1, 2}", "{nan, 0, 0}", "{inf, 1, 1}", "{1, 2, 3, 4}", "{}", "{-1, -1, -1}",
                                   "{1e300, 1e300, 1e300}", "{0, 0, 0}"]))
        return f"'{name}' = {p.get('value')}"
    if kind == "typo_value":
        p.set("value", typo(value, rng))
        return f"'{name}' = '{p.get('value')}' (was '{value}')"
    for parent in root.iter():
        if p in list(parent):
            parent.remove(p)
            return f"deleted '{name}'"
    return "nothing"


def make_variant(index):
    rng = random.Random(args.seed * 1000003 + index)
    is_scene = rng.random() < 0.6
    source = rng.choice(scenes if is_scene else solvers)
    work = os.path.join(args.workdir, f"v{index:05d}")
    os.makedirs(work, exist_ok=True)
    text = open(source).read()
    if is_scene:
        # The solver file resolves from the shipped folder wherever the variant is written.
        text = text.replace('value="../solvers/', 'value="' + os.path.join(args.inputs, "solvers") + "/")
    mutations = []
    if rng.random() < 0.08:
        cut = rng.randrange(len(text))
        text = text[:cut]
        mutations.append(f"cut at byte {cut}")
    elif is_scene and rng.random() < 0.05:
        text = re.sub(r'(name="File" type="string" value=")[^"]*', r"\1/nonexistent/solver.xml", text)
        mutations.append("Solver/File points nowhere")
    else:
        try:
            root = ET.fromstring(text)
            for _ in range(rng.choice([1, 1, 1, 2, 3])):
                mutations.append(mutate(root, rng))
            text = ET.tostring(root, encoding="unicode")
        except ET.ParseError:
            mutations.append("unparsable")
    path = os.path.join(work, os.path.basename(source))
    with open(path, "w") as f:
        f.write(text)
    out = os.path.join(work, "out")
    command = [args.viscompm, path if is_scene else solver_scene, "--output", out, "--frames", "1"]
    if not is_scene:
        command += ["--solver", path, *solver_scene_settings]
    # Short frames, unless the variant changed the frame rate itself.
    if not any("Frame rate" in m for m in mutations):
        command += ["--set", "Simulation/Frame rate=500"]
    return index, os.path.basename(source), "; ".join(mutations), command, work, out


def frames_finite(out):
    for path in glob.glob(os.path.join(out, "frame_*.h5")):
        with h5py.File(path, "r") as f:
            for name, dataset in f["particles"].items():
                if dataset.dtype.kind == "f" and not np.isfinite(dataset[...]).all():
                    return f"{os.path.basename(path)}: /particles/{name} is not finite"
    return ""


def run(variant):
    index, source, mutation, command, work, out = variant
    start = time.time()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)
    stopped = False
    try:
        _, stderr = process.communicate(timeout=args.time_limit)
    except subprocess.TimeoutExpired:
        stopped = True
        os.killpg(process.pid, signal.SIGTERM)
        try:
            _, stderr = process.communicate(timeout=args.grace)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.communicate()
            return index, "hang", source, mutation, "no exit within the grace period after SIGTERM", time.time() - start
    code = process.returncode
    lines = [line for line in stderr.splitlines() if line.startswith("viscompm")]
    problem = ""
    if stopped:
        outcome = "stopped" if code == 4 else "hang"
        if code != 4:
            problem = f"exit {code} after SIGTERM"
    elif code not in (0, 2, 3):
        outcome, problem = "crash", f"exit {code}: {stderr[-600:]}"
    else:
        outcome = {0: "ran", 2: "rejected", 3: "failed"}[code]
        if code != 0 and len(lines) != 1:
            problem = f"exit {code} without exactly one message line: {stderr[-600:]}"
        if any("internal error" in line for line in lines):
            problem = f"internal error: {lines}"
    if not problem and code in (0, 3, 4) and os.path.isdir(out):
        problem = frames_finite(out)
    if problem:
        outcome = outcome if outcome in ("crash", "hang") else "bad"
    elif not args.keep:
        shutil.rmtree(work, ignore_errors=True)
    return index, outcome, source, mutation, problem or (lines[0] if lines else ""), time.time() - start


shutil.rmtree(args.workdir, ignore_errors=True)
os.makedirs(args.workdir)
# Scenes without a Solver section use ../solvers/jacobi_cg.xml relative to themselves.
os.symlink(os.path.abspath(os.path.join(args.inputs, "solvers")), os.path.join(args.workdir, "solvers"))
started = time.time()
counts, failures = {}, []
with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
    for index, outcome, source, mutation, detail, seconds in pool.map(run, map(make_variant, range(args.variants))):
        counts[outcome] = counts.get(outcome, 0) + 1
        if args.verbose:
            print(f"{index:5d} {outcome:8s} {seconds:5.1f}s {source}: {mutation} -> {detail}", flush=True)
        if outcome in ("crash", "hang", "bad"):
            failures.append(f"variant {index} ({source}: {mutation}): {outcome}: {detail}")
            print("FAIL:", failures[-1], flush=True)
        if not args.verbose and (index + 1) % 250 == 0:
            print(f"{index + 1} of {args.variants} variants in {time.time() - started:.0f} s", flush=True)
elapsed = time.time() - started
summary = ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
print(f"{args.variants} variants (seed {args.seed}) in {elapsed:.0f} s: {summary}")
print(f"{len(failures)} failure(s)")
sys.exit(1 if failures else 0)
