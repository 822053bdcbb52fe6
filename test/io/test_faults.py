#!/usr/bin/env python3
"""What a batch system does to a run, end to end (doc/contracts.md, "Stopping, failing, restarting"):
- SIGTERM to one rank only, SIGINT to another, SIGUSR1 to mpiexec: exit 4 after a checkpoint,
  one message; --restart continues to the frames of an uninterrupted run, bit for bit.
- SIGUSR1 to one rank only while a mesh's level set is built: every rank stops, exit 4.
- The disk fills during the run (a small tmpfs, else a file-size limit): exit 3 with one line,
  every file written before intact, nothing half-written left.
- The output directory disappears during the run: exit 3, the earlier frames intact.
- A collider spun faster than the material's elastic waves: exit 3 naming its Angular velocity.
- A truncated, foreign or corrupted checkpoint: exit 2 with one line naming it."""
import glob
import os
import resource
import shlex
import shutil
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, finish, program_arguments  # noqa: E402

args = program_arguments("viscompm", ranks=2).parse_args()

scene = os.path.join(args.inputs, "scenes", "shooting_sponge.xml")
# A checkpoint after every step (it resets what the solver reuses across steps, as a restart
# starts afresh), so that the reference and the stopped-and-restarted runs do the same.
small = ["--set", "Grid/Cell size=0.06", "--set", "Simulation/Frame rate=120", "--set", "Newton/Tolerance=1e-10",
         "--set", "Output/Checkpoint wall seconds=1e-9"]


def command(*extra, ranks=None):
    return shlex.split(args.mpiexec) + ["-np", str(ranks or args.ranks), args.viscompm, scene, *small, *extra]


def run(*extra, ranks=None, **kwargs):
    return subprocess.run(command(*extra, ranks=ranks), capture_output=True, text=True, timeout=300, **kwargs)


def our_lines(text):
    return [line for line in text.splitlines() if line.startswith("viscompm")]


def wait_for(path, process, limit=120):
    deadline = time.time() + limit
    while not os.path.exists(path) and process.poll() is None and time.time() < deadline:
        time.sleep(0.02)
    return os.path.exists(path)


def ranks_of(process):
    """The viscompm processes started by mpiexec (its descendants)."""
    children = {}
    for stat in glob.glob("/proc/[0-9]*/stat"):
        try:
            with open(stat) as f:
                fields = f.read().rsplit(")", 1)[1].split()
            children.setdefault(int(fields[1]), []).append(int(stat.split("/")[2]))
        except (OSError, IndexError, ValueError):
            pass
    found, todo = [], [process.pid]
    while todo:
        for child in children.get(todo.pop(), []):
            todo.append(child)
            try:
                with open(f"/proc/{child}/comm") as f:
                    if f.read().strip() == "viscompm":
                        found.append(child)
            except OSError:
                pass
    return sorted(found)


def particles_by_id(path):
    with h5py.File(path, "r") as f:
        p = f["particles"]
        order = np.argsort(p["id"][...])
        return {name: p[name][...][order] for name in p}


def readable(path):
    try:
        with h5py.File(path, "r") as f:
            n = f["particles/id"].shape[0]
            return n > 0 and f["particles/position"].shape == (n, 3) and np.isfinite(f["particles/position"][...]).all()
    except Exception:  # noqa: BLE001
        return False


shutil.rmtree(args.workdir, ignore_errors=True)
os.makedirs(args.workdir)
frames = 6

# The reference: straight through.
reference_dir = os.path.join(args.workdir, "reference")
result = run("--output", reference_dir, "--frames", str(frames))
check(result.returncode == 0, f"reference run exits 0: {result.stderr[-500:]}")
reference = particles_by_id(os.path.join(reference_dir, f"frame_{frames:05d}.h5"))

# Stop requests: SIGTERM to one rank only, SIGINT to rank 0 only, SIGUSR1 to mpiexec.
for name, how in [("sigterm_one_rank", "term"), ("sigint_rank0", "int"), ("sigusr1_mpiexec", "usr1")]:
    out = os.path.join(args.workdir, name)
    process = subprocess.Popen(command("--output", out, "--frames", str(frames)), stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    check(wait_for(os.path.join(out, "frame_00002.h5"), process), f"{name}: frame 2 appeared")
    ranks = ranks_of(process)
    check(len(ranks) == args.ranks, f"{name}: found the {args.ranks} ranks: {ranks}")
    if how == "term" and ranks:
        os.kill(ranks[-1], signal.SIGTERM)
    elif how == "int" and ranks:
        os.kill(ranks[0], signal.SIGINT)
    else:
        process.send_signal(signal.SIGUSR1)
    stdout, stderr = process.communicate(timeout=120)
    check(process.returncode == 4, f"{name}: exit 4, got {process.returncode}: {stderr[-500:]}")
    lines = [line for line in our_lines(stderr) if "stopped by signal" in line]
    check(len(lines) == 1 and "--restart" in lines[0], f"{name}: one line saying how to continue: {our_lines(stderr)}")
    checkpoints = sorted(glob.glob(os.path.join(out, "checkpoint_step_*.h5")))
    check(len(checkpoints) == 1, f"{name}: one checkpoint (each replaces the one before): {checkpoints}")
    check(not glob.glob(os.path.join(out, f"frame_{frames:05d}.h5")), f"{name}: stopped before the end")
    if checkpoints:
        restart = run("--output", out, "--frames", str(frames), "--restart", checkpoints[0])
        check(restart.returncode == 0, f"{name}: restart exits 0: {restart.stderr[-500:]}")
        final = os.path.join(out, f"frame_{frames:05d}.h5")
        if os.path.exists(final):
            continued = particles_by_id(final)
            same = all(np.array_equal(reference[k], continued[k]) for k in reference)
            check(same, f"{name}: the restarted run ends bit for bit where the uninterrupted one does")
        grids = ET.parse(os.path.join(out, "particles.xdmf")).getroot().findall("./Domain/Grid[@Name='particles']/Grid")
        check(len(grids) == frames + 1, f"{name}: the XDMF index lists every frame once: {len(grids)}")

# Issue 24: SIGUSR1 to the last rank only while the ranks build a mesh's level set (the toothbrush
# at fine voxels: seconds), as soon as its handler is installed. Every rank agrees on the request
# after that stage: exit 4 with one line saying nothing was simulated, no frame written, within a
# minute. (The signalled rank used to leave alone and the others to wait at the run's first
# collective until killed.)
def catches(pid, signum):
    """Whether process `pid` has installed a handler for `signum` (/proc/PID/status, SigCgt)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("SigCgt:"):
                    return bool(int(line.split()[1], 16) >> (signum - 1) & 1)
    except OSError:
        pass
    return False


out = os.path.join(args.workdir, "stop_during_level_set")
toothpaste = os.path.join(args.inputs, "scenes", "paper", "toothpaste.xml")
process = subprocess.Popen(shlex.split(args.mpiexec) + ["-np", str(args.ranks), args.viscompm, toothpaste, "--frames", "1",
                                                        "--output", out, "--set", "Colliders/toothbrush/Voxel size=0.0007"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
deadline = time.time() + 30
ranks = []
while time.time() < deadline and process.poll() is None:
    ranks = ranks_of(process)
    if len(ranks) == args.ranks and all(catches(pid, signal.SIGUSR1) for pid in ranks):
        break
    time.sleep(0.01)
check(len(ranks) == args.ranks, f"stop during a level set: found the {args.ranks} ranks: {ranks}")
if ranks:
    os.kill(ranks[-1], signal.SIGUSR1)
try:
    stdout, stderr = process.communicate(timeout=60)
except subprocess.TimeoutExpired:
    for pid in ranks_of(process):
        os.kill(pid, signal.SIGKILL)
    os.killpg(process.pid, signal.SIGKILL)
    stdout, stderr = process.communicate()
    check(False, "stop during a level set: the ranks not signalled were left waiting (killed after 60 s)")
check(process.returncode == 4, f"stop during a level set: exit 4, got {process.returncode}: {stderr[-500:]}")
lines = our_lines(stderr)
check(len(lines) == 1 and "nothing was simulated" in lines[0], f"stop during a level set: one line: {lines}")
check(not glob.glob(os.path.join(out, "frame_*")), "stop during a level set: no frame written")

# The disk fills: a tmpfs that holds frame 0, its checkpoint and frame 1, not more.
frame_bytes = os.path.getsize(os.path.join(reference_dir, "frame_00000.h5"))
full = os.path.join(args.workdir, "full")
os.makedirs(full)
mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={int(3.6 * frame_bytes)}", "tmpfs", full],
                         capture_output=True).returncode == 0
try:
    if mounted:
        out = os.path.join(full, "out")
        result = run("--output", out, "--frames", str(frames), "--set", "Output/Checkpoint every=1")
        limit_kind = "a small filesystem"
    else:
        # Not allowed to mount (not root): a file-size limit below one frame fails the first write.
        out = os.path.join(full, "out")
        limit = int(0.5 * frame_bytes)
        result = run("--output", out, "--frames", str(frames),
                     preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit)))
        limit_kind = "a file-size limit"
    print(f"disk full: {limit_kind}")
    check(result.returncode == 3, f"disk full ({limit_kind}): exit 3, got {result.returncode}: {result.stderr[-800:]}")
    lines = our_lines(result.stderr)
    check(len(lines) == 1 and "cannot write" in lines[0], f"disk full: one line saying what it could not write: {lines}")
    written = sorted(glob.glob(os.path.join(out, "*.h5")))
    check(not glob.glob(os.path.join(out, "*.tmp")), f"disk full: no half-written file: {os.listdir(out)}")
    if mounted:
        check(len(written) >= 2, f"disk full: files were written before the disk filled: {written}")
    for path in written:
        check(readable(path), f"disk full: {path} is intact")
    if os.path.exists(os.path.join(out, "particles.xdmf")):
        grids = ET.parse(os.path.join(out, "particles.xdmf")).getroot().findall("./Domain/Grid[@Name='particles']/Grid")
        check(len(grids) == len(glob.glob(os.path.join(out, "frame_*.h5"))), "disk full: the index lists the frames")
finally:
    if mounted:
        subprocess.run(["umount", full])

# The output directory disappears (moved away, a file in its place) while the run writes.
out = os.path.join(args.workdir, "vanishing")
process = subprocess.Popen(command("--output", out, "--frames", "200"), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           text=True)
check(wait_for(os.path.join(out, "frame_00002.h5"), process), "vanishing: frame 2 appeared")
os.rename(out, out + ".moved")
with open(out, "w") as f:
    f.write("not a directory\n")
stdout, stderr = process.communicate(timeout=120)
check(process.returncode == 3, f"vanishing directory: exit 3, got {process.returncode}: {stderr[-500:]}")
check(len(our_lines(stderr)) == 1, f"vanishing directory: one line: {our_lines(stderr)}")
kept = sorted(glob.glob(os.path.join(out + ".moved", "frame_*.h5")))
check(len(kept) >= 3 and all(readable(p) for p in kept), f"vanishing directory: earlier frames intact: {kept}")

# A sticky grip spun far faster than any elastic wave of the sponge it twists (issue 24): no
# read-time bound holds (every step resolves the motion: the CFL step follows the rim's speed), so
# the run fails at the smallest Δt — exit 3, one line naming the parameter behind it.
spun = subprocess.run(shlex.split(args.mpiexec) + ["-np", str(args.ranks), args.viscompm,
                                                   os.path.join(args.inputs, "scenes", "paper", "twisting_sponge.xml"),
                                                   "--frames", "1", "--output", os.path.join(args.workdir, "spun"),
                                                   "--set", "Colliders/top grip/Angular velocity={0, 1e4, 0}"],
                      capture_output=True, text=True, timeout=300)
lines = our_lines(spun.stderr)
check(spun.returncode == 3, f"spun grip: exit 3, got {spun.returncode}: {spun.stderr[-400:]}")
check(len(lines) == 1 and "'Colliders/top grip/Angular velocity'" in lines[0],
      f"spun grip: one line naming the angular velocity: {lines}")

# Checkpoints that cannot be restarted from: exit 2, one line naming the file.
bad = os.path.join(args.workdir, "bad_checkpoints")
os.makedirs(bad)
good = sorted(glob.glob(os.path.join(args.workdir, "sigterm_one_rank", "checkpoint_step_*.h5")))
if good:
    data = open(good[0], "rb").read()
    cases = {}
    cases["truncated.h5"] = data[: len(data) // 2]
    cases["text.h5"] = b"not an HDF5 file\n"
    for name, content in cases.items():
        with open(os.path.join(bad, name), "wb") as f:
            f.write(content)
    shutil.copy(os.path.join(reference_dir, "frame_00001.h5"), os.path.join(bad, "frame.h5"))
    shutil.copy(good[0], os.path.join(bad, "nan.h5"))
    with h5py.File(os.path.join(bad, "nan.h5"), "r+") as f:
        f["particles/velocity"][0, 1] = np.nan
    shutil.copy(good[0], os.path.join(bad, "material.h5"))
    with h5py.File(os.path.join(bad, "material.h5"), "r+") as f:
        f["particles/material_id"][0] = 7
    with h5py.File(os.path.join(bad, "foreign.h5"), "w") as f:
        f.attrs["time"] = 0.0
        f.create_dataset("particles/id", data=np.arange(4))
    # A checkpoint of another scene: its materials are not the sponge's.
    pie = os.path.join(args.workdir, "pie")
    other = subprocess.run(shlex.split(args.mpiexec) + ["-np", "1", args.viscompm,
                                                        os.path.join(args.inputs, "scenes", "oldroyd_b_pie.xml"),
                                                        "--output", pie, "--frames", "0",
                                                        "--set", "Output/Checkpoint every=1"],
                           capture_output=True, text=True, timeout=300)
    if other.returncode == 0 and os.path.exists(os.path.join(pie, "checkpoint_00000.h5")):
        shutil.copy(os.path.join(pie, "checkpoint_00000.h5"), os.path.join(bad, "other_scene.h5"))
    for path in sorted(glob.glob(os.path.join(bad, "*.h5"))):
        result = run("--output", os.path.join(bad, "out"), "--frames", "1", "--restart", path)
        lines = our_lines(result.stderr)
        check(result.returncode == 2, f"{os.path.basename(path)}: exit 2, got {result.returncode}: {result.stderr[-400:]}")
        check(len(lines) == 1 and path in lines[0], f"{os.path.basename(path)}: one line naming it: {lines}")
else:
    check(False, "no checkpoint to corrupt")

finish()
