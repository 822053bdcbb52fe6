#!/usr/bin/env python3
"""The viscompm program end to end, as users and scripts see it (doc/contracts.md):
--help, exit codes with one-line messages, and the output read back with h5py: the HDF5 frame
schema, the XDMF index ParaView opens, and solver.csv."""
import csv
import os
import re
import shlex
import shutil
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, finish, program_arguments  # noqa: E402

args = program_arguments("viscompm", ranks=1).parse_args()

scene = os.path.join(args.inputs, "scenes", "shooting_sponge.xml")


def run(*extra):
    command = shlex.split(args.mpiexec) + ["-np", str(args.ranks), args.viscompm, *extra]
    return subprocess.run(command, capture_output=True, text=True, timeout=600)


def stderr_lines(result):
    # mpiexec may add its own lines when a rank exits non-zero; ours start with "viscompm:".
    return [line for line in result.stderr.splitlines() if line.startswith("viscompm")]


shutil.rmtree(args.workdir, ignore_errors=True)
os.makedirs(args.workdir)

# --help: exit 0, documents the options and the scene parameters.
result = run("--help")
check(result.returncode == 0, f"--help exits 0, got {result.returncode}")
for word in ("--output", "--set", "--solver", "--frames", "Weissenberg number"):
    check(word in result.stdout, f"--help mentions {word}")
check(result.stdout.count("Usage: viscompm") == 1, "--help is printed once (rank 0)")

# Bad input: exit 2 and one line naming the file and the parameter.
result = run("/nonexistent/scene.xml")
check(result.returncode == 2, f"missing scene exits 2, got {result.returncode}")
lines = stderr_lines(result)
check(len(lines) == 1 and "/nonexistent/scene.xml" in lines[0], f"one line naming the file: {lines}")
result = run(scene, "--set", "Materials/sponge/Weissenberg number=-3", "--output", os.path.join(args.workdir, "bad"))
check(result.returncode == 2, f"out-of-range --set exits 2, got {result.returncode}")
lines = stderr_lines(result)
check(len(lines) == 1 and scene in lines[0] and "'Materials/sponge/Weissenberg number'" in lines[0],
      f"one line naming file and parameter: {lines}")
result = run(scene, "--frames", "1", "--solver", os.path.join(args.inputs, "scenes", "shooting_sponge.xml"))
check(result.returncode == 2, f"a scene given as solver file exits 2, got {result.returncode}")
# A scene whose particles cannot fit in memory: exit 2 before sampling, naming the parameter and
# the estimate (the timeout guards against a run that starts sampling 10^11 particles).
started = time.time()
result = run(scene, "--set", "Grid/Cell size=1e-4", "--output", os.path.join(args.workdir, "huge"))
lines = stderr_lines(result)
check(result.returncode == 2, f"a grid too fine for memory exits 2, got {result.returncode}")
check(len(lines) == 1 and "'Grid/Cell size'" in lines[0] and "GiB" in lines[0],
      f"one line naming Grid/Cell size and the memory estimate: {lines}")
print(f"memory estimate answered in {time.time() - started:.2f} s: {lines}")

# A small run of the default scene.
out = os.path.join(args.workdir, "run")
small = ["--set", "Grid/Cell size=0.06", "--set", "Simulation/Frame rate=120"]
result = run(scene, "--output", out, "--frames", "2", *small)
check(result.returncode == 0, f"run exits 0, got {result.returncode}: {result.stderr[-2000:]}")
check(result.stdout.count("frame    2/2") == 1, "a progress line per frame, printed once")
files = sorted(os.listdir(out)) if os.path.isdir(out) else []
check(files == ["frame_00000.h5", "frame_00001.h5", "frame_00002.h5", "particles.xdmf", "solver.csv"],
      f"output files: {files}")

ids0 = None
for frame in range(3):
    path = os.path.join(out, f"frame_{frame:05d}.h5")
    if not os.path.exists(path):
        continue
    with h5py.File(path, "r") as f:
        check(f.attrs["frame"] == frame, "frame attribute")
        check(abs(f.attrs["time"] - frame / 120.0) < 1e-12, f"time attribute {f.attrs['time']}")
        check(f.attrs["step"] >= frame, "step attribute")
        p = f["particles"]
        n = p["id"].shape[0]
        expected = {"id": ((n,), np.int64), "position": ((n, 3), np.float64), "velocity": ((n, 3), np.float64),
                    "mass": ((n,), np.float64), "volume0": ((n,), np.float64), "material_id": ((n,), np.int32),
                    "deformation_gradient": ((n, 3, 3), np.float64),
                    "left_cauchy_green_ob": ((n, 3, 3), np.float64),
                    "elastic_deformation_gradient": ((n, 3, 3), np.float64),
                    "plastic_deformation_gradient": ((n, 3, 3), np.float64),
                    "yield_function": ((n,), np.float64), "equivalent_plastic_strain": ((n,), np.float64),
                    "left_cauchy_green_elastic": ((n, 3, 3), np.float64)}
        for name, (shape, dtype) in expected.items():
            check(name in p and p[name].shape == shape and p[name].dtype == dtype,
                  f"frame {frame}: dataset {name} {shape} {dtype}")
        ids = np.sort(p["id"][...])
        check(len(np.unique(ids)) == n, "ids are unique")
        if ids0 is None:
            ids0 = ids
        check(np.array_equal(ids, ids0), "ids are stable across frames")
        # The colliders' surfaces: one collider index per triangle (issue 17, class 9).
        m = f["colliders/triangles"].shape[0]
        check(f["colliders/triangles"].shape == (m, 3) and f["colliders/collider_id"].shape == (m,),
              f"colliders: triangles (m, 3) and collider_id (m), got {f['colliders/triangles'].shape}, "
              f"{f['colliders/collider_id'].shape}")
        check(set(np.unique(f["colliders/collider_id"][...])) == {0, 1, 2}, "every collider has triangles")
        F = p["deformation_gradient"][...]
        bE = p["left_cauchy_green_elastic"][...]
        J = np.linalg.det(F)
        check(np.allclose(np.linalg.det(bE), J * J, rtol=1e-9), "det b^E = J^2 (5.5)")
        check(np.all(p["mass"][...] > 0), "masses are positive")

# The XDMF index: every frame of the particles and of the colliders (grips and bullet), with
# datasets that exist and dimensions that match.
xdmf = os.path.join(out, "particles.xdmf")
if os.path.exists(xdmf):
    grids = ET.parse(xdmf).getroot().findall("./Domain/Grid[@Name='particles']/Grid")
    check(len(grids) == 3, f"xdmf lists 3 frames, got {len(grids)}")
    collider_grids = ET.parse(xdmf).getroot().findall("./Domain/Grid[@Name='colliders']/Grid")
    check(len(collider_grids) == 3, f"xdmf lists the colliders of 3 frames, got {len(collider_grids)}")
    for grid in grids + collider_grids:
        for item in grid.iter("DataItem"):
            file_name, dataset = item.text.split(":")
            with h5py.File(os.path.join(out, file_name), "r") as f:
                dims = tuple(int(d) for d in item.attrib["Dimensions"].split())
                check(dataset in f and f[dataset].shape == dims, f"xdmf item {item.text} {dims}")

# solver.csv: the contract's columns, one row per linear solve.
csv_path = os.path.join(out, "solver.csv")
if os.path.exists(csv_path):
    with open(csv_path) as f:
        reader = csv.reader(f)
        header = next(reader)
        rows = list(reader)
    check(header == ["step", "newton_iteration", "linear_iterations", "relative_residual", "setup_seconds",
                     "solve_seconds", "preconditioner", "ranks", "operator_seconds", "tolerance"],
          f"solver.csv header {header}")
    check(len(rows) > 0, "solver.csv has rows")
    check(all(int(r[7]) == args.ranks for r in rows), "ranks column")
    # Each solve reaches the tolerance it was given (the scene's inexact Newton gives forcing
    # terms below 1: doc/inputs.md, Linear tolerance).
    check(all(0 < float(r[9]) < 1 and float(r[3]) <= float(r[9]) for r in rows),
          "relative residuals meet the solver tolerance of their row: "
          + str([(r[3], r[9]) for r in rows if not float(r[3]) <= float(r[9])][:5]))
    newton_total = int(result.stdout.split("Newton iterations")[0].split(",")[-1]) if "Newton iterations" in result.stdout else -1
    check(len(rows) == newton_total, f"one row per Newton iteration: {len(rows)} vs {newton_total}")

# A scene of a plastic model: the frame shows its state (doc/materials.md). The snowball of
# svd_plasticity on a coarse grid, two frames to the middle of its impact: F = F_E F_P, the
# singular values of F_E clamped to [1 - c, 1 + s], plastic flow (yield function > 0) and
# compression (J_P < 1), and b^E = F_E F_E^T.
snow_out = os.path.join(args.workdir, "snowball")
snow_scene = os.path.join(args.inputs, "scenes", "svd_plasticity_snowball.xml")
result = run(snow_scene, "--output", snow_out, "--frames", "2", "--set", "Grid/Cell size=0.06",
             "--set", "Simulation/Frame rate=24")
check(result.returncode == 0, f"snowball run exits 0, got {result.returncode}: {result.stderr[-2000:]}")
snow_frame = os.path.join(snow_out, "frame_00002.h5")
if os.path.exists(snow_frame):
    with h5py.File(snow_frame, "r") as f:
        p = f["particles"]
        F, F_E, F_P = (p[name][...] for name in ("deformation_gradient", "elastic_deformation_gradient",
                                                 "plastic_deformation_gradient"))
        check(np.allclose(F, F_E @ F_P, rtol=0, atol=1e-10 * np.abs(F).max()), "F = F_E F_P")
        sigma = np.linalg.svd(F_E, compute_uv=False)
        check(sigma.min() >= 1 - 2.5e-2 - 1e-12 and sigma.max() <= 1 + 7.5e-3 + 1e-12,
              f"singular values of F_E in [1 - c, 1 + s]: {sigma.min()}, {sigma.max()}")
        check((p["yield_function"][...] > 0).any(), "the snowball flows plastically on impact (t = 1/12 s)")
        check(np.linalg.det(F_P).min() < 0.99, "plastic compression: J_P < 1")
        check(np.allclose(p["left_cauchy_green_elastic"][...], F_E @ np.transpose(F_E, (0, 2, 1)), atol=1e-12),
              "b^E = F_E F_E^T")

# The measured choice: the summary says, once, how many Newton systems each candidate solved, and
# they add up to the run's Newton iterations; solver.csv names each solve's candidate: the first
# step solving anything is the first candidate's trial, the next starts the second's.
choice_out = os.path.join(args.workdir, "choice")
result = run(scene, "--output", choice_out, "--frames", "2", *small, "--solver",
             os.path.join(args.inputs, "solvers", "measured_choice_cg.xml"))
check(result.returncode == 0, f"measured choice run exits 0, got {result.returncode}: {result.stderr[-2000:]}")
summary = [line for line in result.stdout.splitlines() if line.startswith("measured-choice:")]
check(len(summary) == 1, f"one summary line of the measured choice: {summary}")
if len(summary) == 1 and "Newton iterations" in result.stdout:
    counts = re.findall(r"(matrix-free-jacobi|gmg-lean-deflated) (\d+) systems", summary[0])
    newton_total = int(result.stdout.split("Newton iterations")[0].split(",")[-1])
    check(len(counts) == 2 and all(int(n) >= 1 for _, n in counts) and sum(int(n) for _, n in counts) == newton_total,
          f"both candidates solved systems, {newton_total} in all: {summary[0]}")
    with open(os.path.join(choice_out, "solver.csv")) as f:
        rows = list(csv.DictReader(f))
    steps = sorted({int(r["step"]) for r in rows})
    first = [r["preconditioner"] for r in rows if int(r["step"]) == steps[0]]
    second = [r["preconditioner"] for r in rows if len(steps) > 1 and int(r["step"]) == steps[1]]
    check(set(first) == {"gmg-lean-deflated"} and second[:1] == ["matrix-free-jacobi"],
          f"the trials: a step of the first candidate, then the second's: {first}, {second}")

# A run that fails keeps the frames written so far: exit 3.
failed_out = os.path.join(args.workdir, "failed")
result = run(scene, "--output", failed_out, "--frames", "2", *small, "--set", "Newton/Max iterations=1",
             "--set", "Newton/Tolerance=1e-14", "--set", "Simulation/Min time step=0.004")
check(result.returncode == 3, f"failed simulation exits 3, got {result.returncode}")
check(len(stderr_lines(result)) == 1, f"one line on stderr: {stderr_lines(result)}")
frame0 = os.path.join(failed_out, "frame_00000.h5")
check(os.path.exists(frame0), "frame 0 of the failed run is intact")
if os.path.exists(frame0):
    with h5py.File(frame0, "r") as f:
        check(f["particles/position"].shape[0] > 0, "frame 0 is readable")

finish()
