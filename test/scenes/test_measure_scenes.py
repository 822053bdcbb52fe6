#!/usr/bin/env python3
"""scripts/measure_scenes.py measures what it claims on frames whose answer is known: synthetic
frames (the HDF5 layout of doc/contracts.md) of a crust cut into six slices that fly apart (six
pieces, none broken across) or stay together (one piece), a rope laid in three coils (three turns),
a rope laid back and forth (reversals, no turns), three balls whose rebound grows with Wi (monotone)
or does not (not monotone), and a sponge torn in two (two pieces, torn links)."""
import argparse
import json
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, finish  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--measure", required=True, help="scripts/measure_scenes.py")
parser.add_argument("--inputs", required=True, help="the inputs/ folder")
parser.add_argument("--workdir", required=True)
args = parser.parse_args()
shutil.rmtree(args.workdir, ignore_errors=True)
os.makedirs(args.workdir)


def write_frame(directory, number, time, position, material_id, names, velocity=None, spacing=0.01, ids=None):
    os.makedirs(directory, exist_ok=True)
    n = len(position)
    with h5py.File(os.path.join(directory, f"frame_{number:05d}.h5"), "w") as h5:
        h5.attrs["time"] = time
        p = h5.create_group("particles")
        p.attrs["material_names"] = np.bytes_(",".join(names))
        p["id"] = np.arange(n, dtype=np.int64) if ids is None else ids
        p["position"] = np.asarray(position, dtype=float)
        p["velocity"] = np.zeros((n, 3)) if velocity is None else velocity
        p["material_id"] = np.asarray(material_id, dtype=np.int32)
        p["volume0"] = np.full(n, spacing ** 3)


def measure(directory, scene, scene_file):
    out = subprocess.run([sys.executable, args.measure, directory, "--scene", scene, "--scene-file", scene_file],
                         capture_output=True, text=True)
    check(out.returncode == 0, f"{scene}: measure_scenes.py exits 0: {out.stderr[-800:]}")
    return json.loads(out.stdout) if out.returncode == 0 else {}


def lattice(lo, hi, h):
    axes = [np.arange(a + h / 2, b, h) for a, b in zip(lo, hi)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


paper = os.path.join(args.inputs, "scenes", "paper")

# Pie: the crust of pie.xml (a disc about x) cut by three planes through its axis into six slices.
h = 0.005
centre = np.array([0.2725, 0.42, 0.4])
disc = lattice(centre - [0.0125, 0.11, 0.11], centre + [0.0125, 0.11, 0.11], h)
disc = disc[np.linalg.norm(disc[:, 1:] - centre[1:], axis=1) < 0.11]
angle = np.arctan2(disc[:, 2] - centre[2], disc[:, 1] - centre[1])
radius = np.linalg.norm(disc[:, 1:] - centre[1:], axis=1)
in_cut = np.zeros(len(disc), dtype=bool)
for k in range(3):  # within 6 mm of a plane at 60 degrees k
    normal = np.array([-np.sin(k * np.pi / 3), np.cos(k * np.pi / 3)])
    in_cut |= np.abs((disc[:, 1:] - centre[1:]) @ normal) < 0.006
cream = centre + [0.03, 0, 0] + lattice([0, -0.03, -0.03], [0.02, 0.03, 0.03], h)
names = ["cream", "crust", "crust_scored"]
material = np.concatenate([np.where(in_cut, 2, 1), np.zeros(len(cream), dtype=int)])
position0 = np.concatenate([disc, cream])
for label, spread in (("pie_apart", 0.05), ("pie_together", 0.0)):
    d = os.path.join(args.workdir, label)
    write_frame(d, 0, 0.0, position0, material, names, spacing=h)
    moved = position0.copy()
    # Every slice (and its half of the cuts) moves outwards along its middle direction.
    slice_angle = (np.floor(angle / (np.pi / 3)) + 0.5) * (np.pi / 3)
    moved[:len(disc), 1] += spread * np.cos(slice_angle)
    moved[:len(disc), 2] += spread * np.sin(slice_angle)
    write_frame(d, 1, 0.05, moved, material, names, spacing=h)
    m = measure(d, "pie", os.path.join(paper, "pie.xml"))
    if m:
        check(m["stiff_crust_slices_at_frame_0"] == 6, f"{label}: 6 prescored slices, got {m['stiff_crust_slices_at_frame_0']}")
        check(m["crust_pieces_frame_0"] == 1, f"{label}: one crust at frame 0, got {m['crust_pieces_frame_0']}")
        expected = 6 if spread > 0 else 1
        check(m["crust_pieces_last"] == expected, f"{label}: {expected} crust pieces at the end, got {m['crust_pieces_last']}")
        check(m["slices_broken_across"] == 0, f"{label}: no slice broken across, got {m['slices_broken_across']}")

# Toothpaste: a rope laid at rest under the nozzle of toothpaste.xml, its centre turning three
# times around the nozzle's axis in emission order (coiling), or swinging along x (folding).
nozzle = np.array([1.66, 1.5, 1.0])
layers, per_layer = 600, 40
k = np.repeat(np.arange(layers), per_layer)
rng = np.random.default_rng(1)
jitter = rng.normal(scale=0.01, size=(len(k), 3))
for label, path in (("coil", lambda s: 0.05 * np.stack([np.cos(6 * np.pi * s), np.sin(6 * np.pi * s)], axis=1)),
                    ("fold", lambda s: np.stack([0.08 * np.cos(7 * np.pi * s), 0.0 * s], axis=1))):
    s = k / layers
    xz = path(s)
    position = np.stack([nozzle[0] + xz[:, 0], 1.0 + 0.1 * s, nozzle[2] + xz[:, 1]], axis=1) + jitter
    d = os.path.join(args.workdir, label)
    write_frame(d, 0, 0.0, position[:0], [], ["toothpaste"], spacing=0.01)
    write_frame(d, 1, 2.0, position, np.zeros(len(k)), ["toothpaste"], spacing=0.01)
    m = measure(d, "toothpaste", os.path.join(paper, "toothpaste.xml"))
    if m and label == "coil":
        check(abs(abs(m["coil_turns"]) - 3) < 0.3, f"coil: 3 turns, got {m['coil_turns']}")
    if m and label == "fold":
        check(abs(m["coil_turns"]) < 0.3, f"fold: no turns, got {m['coil_turns']}")
        check(m["fold_reversals"] == 6, f"fold: 3.5 swings = 6 reversals, got {m['fold_reversals']}")

# Weissenberg sweep: three balls (materials wi_10, wi_0.5, wi_0.02) whose tops fall, then rise back
# by amounts given per case.
ground = 0.1
ball = lattice([-0.12] * 3, [0.12] * 3, 0.02)
ball = ball[np.linalg.norm(ball, axis=1) < 0.12]
for label, rebound, monotone in (("sweep_monotone", (0.1, 0.05, 0.0), True), ("sweep_not", (0.0, 0.05, 0.1), False)):
    d = os.path.join(args.workdir, label)
    tops = [0.37, 0.2, None]
    for frame, top in enumerate(tops):
        position, material = [], []
        for b, r in enumerate(rebound):
            t = (0.2 + r) if top is None else top
            position.append(ball * [1, (t - ground) / 0.24, 1] + [0.3 + 0.45 * b, ground + (t - ground) / 2, 0.2])
            material.append(np.full(len(ball), b))
        write_frame(d, frame, 0.1 * frame, np.concatenate(position), np.concatenate(material),
                    ["wi_10", "wi_0.5", "wi_0.02"], spacing=0.02)
    m = measure(d, "weissenberg_sweep", os.path.join(paper, "weissenberg_sweep.xml"))
    if m:
        check(m["rebound_monotone_in_Wi"] == monotone, f"{label}: rebound monotone in Wi is {monotone}")

# Twisting sponge: a block whose upper half moves up by 3 spacings (torn across one plane).
h = 0.0625
block = lattice([3.7335, 3, 3.7335], [5.2335, 5.5, 5.2335], h)
d = os.path.join(args.workdir, "sponge")
write_frame(d, 0, 0.0, block, np.zeros(len(block)), ["sponge"], spacing=h)
torn = block.copy()
upper = torn[:, 1] > 4.25
torn[upper, 1] += 3 * h
write_frame(d, 1, 1.0, torn, np.zeros(len(block)), ["sponge"], spacing=h)
m = measure(d, "twisting_sponge", os.path.join(paper, "twisting_sponge.xml"))
if m:
    across = int(np.sum(~upper & (block[:, 1] > 4.25 - h)))  # one link across the plane per column
    check(m["pieces"] == 2, f"sponge: 2 pieces, got {m['pieces']}")
    check(m["torn_links"] == across, f"sponge: {across} torn links, got {m['torn_links']}")
finish("measure_scenes.py: pieces, slices, coils, folds, rebound order and torn links as constructed")
