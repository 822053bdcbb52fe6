#!/usr/bin/env python3
"""A run killed (SIGKILL) at arbitrary moments, some of them during output, leaves every frame
and checkpoint it had finished readable (files are written under a temporary name and renamed
when complete), and the last checkpoint restarts."""
import glob
import os
import shlex
import shutil
import signal
import subprocess
import sys
import time

import h5py

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, finish, program_arguments  # noqa: E402

args = program_arguments("viscompm", ranks=2).parse_args()
scene = os.path.join(args.inputs, "scenes", "shooting_sponge.xml")
# Heavy output relative to compute: every frame a few steps long, a checkpoint every frame.
options = ["--frames", "200", "--set", "Grid/Cell size=0.045", "--set", "Simulation/Frame rate=600",
           "--set", "Output/Checkpoint every=1"]


shutil.rmtree(args.workdir, ignore_errors=True)
for trial, delay in enumerate([0.0, 0.37, 0.81]):
    out = os.path.join(args.workdir, f"run{trial}")
    command = shlex.split(args.mpiexec) + ["-np", str(args.ranks), args.viscompm, scene, "--output", out, *options]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    # Wait for the first checkpoints (however busy the machine), then kill at an arbitrary moment.
    deadline = time.time() + 300
    while len(glob.glob(os.path.join(out, "checkpoint_*.h5"))) < 2 + trial and time.time() < deadline:
        time.sleep(0.05)
    time.sleep(delay)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    finished = [f for f in glob.glob(os.path.join(out, "*.h5"))]
    frames = sorted(f for f in finished if "frame_" in f)
    checkpoints = sorted(f for f in finished if "checkpoint_" in f)
    check(len(frames) >= 2 and checkpoints, f"trial {trial}: the run wrote frames and checkpoints before the kill")
    for f in finished:
        try:
            with h5py.File(f, "r") as h:
                n = h["particles/id"].shape[0]
                check(n > 0 and h["particles/position"].shape == (n, 3), f"{f} is complete")
        except Exception as e:  # noqa: BLE001
            check(False, f"{f} is readable: {e}")
    if checkpoints:
        restart = subprocess.run(shlex.split(args.mpiexec) + ["-np", str(args.ranks), args.viscompm, scene, "--output",
                                                              out, *options[:1], str(int(checkpoints[-1][-8:-3]) + 1),
                                                              *options[2:], "--restart", checkpoints[-1]],
                                 capture_output=True, text=True, timeout=600)
        check(restart.returncode == 0, f"trial {trial}: restart from {checkpoints[-1]} exits 0: {restart.stderr[-800:]}")
finish()
