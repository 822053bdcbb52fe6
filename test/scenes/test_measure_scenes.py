#!/usr/bin/env python3
"""scripts/measure_scenes.py measures what it claims on frames whose answer is known: synthetic
frames (the HDF5 layout of doc/contracts.md) of a crust cut into six slices that fly apart (six
pieces, none broken across), stay together (one piece), break along the cuts into groups of whole
slices (the groups) or across a slice (one slice broken across), a rope laid in three coils (three
turns) or 1.5 coils beside the nozzle (1.5 turns; its median J), a rope laid back and forth
(reversals, no turns), a rope laid back beside itself fused, touching or apart (fused contacts,
contacts), three balls whose rebound grows with Wi (monotone) or does not (not monotone), and a
sponge torn in two (two pieces, torn links); and bad input (a truncated frame, a missing directory
or scene file, bad options) answered with one line naming it."""
import argparse
import json
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, finish  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--measure", required=True, help="scripts/measure_scenes.py")
parser.add_argument("--inputs", required=True, help="the inputs/ folder")
parser.add_argument("--workdir", required=True)
args = parser.parse_args()
shutil.rmtree(args.workdir, ignore_errors=True)
os.makedirs(args.workdir)


def write_frame(directory, number, time, position, material_id, names, velocity=None, spacing=0.01, ids=None,
                deformation_gradient=None):
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
        if deformation_gradient is not None:
            p["deformation_gradient"] = deformation_gradient


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
slice_of = np.floor(angle / (np.pi / 3)).astype(int) % 6  # the slice (by angle) of each disc particle
# The measure numbers the slices by their first particle's id: the slice (by angle) of each number.
stiff = ~in_cut
numbered = sorted(range(6), key=lambda k: np.nonzero(stiff & (slice_of == k))[0].min())
# Cases: (label, slice groups that fly apart together, slices cut across their middle), and what
# the measure must find: pieces, slices broken across, broken along the cuts.
cases = [("pie_apart", [[k] for k in range(6)], [], 6, 0, True),
         ("pie_together", [list(range(6))], [], 1, 0, False),
         ("pie_three_groups", [[0, 1], [2, 3], [4, 5]], [], 3, 0, True),
         ("pie_two_groups", [[5, 0, 1], [2, 3, 4]], [], 2, 0, False),
         ("pie_broken_across", [[0, 1], [2, 3], [4, 5]], [3], 4, 1, False)]
for label, groups, across, expected_pieces, expected_split, along_cuts in cases:
    d = os.path.join(args.workdir, label)
    write_frame(d, 0, 0.0, position0, material, names, spacing=h)
    moved = position0.copy()
    # Every group of slices (with its slices' halves of the cuts) moves outwards along its middle
    # direction, 50 mm unless it is the whole crust; a slice in `across` has its outer half (beyond
    # half the radius) moved a further 30 mm outwards: a break across the slice, not along a cut.
    for group in groups:
        members = np.isin(slice_of, group)
        middle = np.angle(np.exp(1j * (np.array(group) + 0.5) * np.pi / 3).sum())
        spread = 0.05 if len(group) < 6 else 0.0
        moved[:len(disc)][members, 1] += spread * np.cos(middle)
        moved[:len(disc)][members, 2] += spread * np.sin(middle)
    for k in across:
        outer = (slice_of == k) & (radius > 0.055)
        middle = (k + 0.5) * np.pi / 3
        moved[:len(disc)][outer, 1] += 0.03 * np.cos(middle)
        moved[:len(disc)][outer, 2] += 0.03 * np.sin(middle)
    write_frame(d, 1, 0.05, moved, material, names, spacing=h)
    m = measure(d, "pie", os.path.join(paper, "pie.xml"))
    if m:
        check(m["stiff_crust_slices_at_frame_0"] == 6, f"{label}: 6 prescored slices, got {m['stiff_crust_slices_at_frame_0']}")
        check(m["crust_pieces_frame_0"] == 1, f"{label}: one crust at frame 0, got {m['crust_pieces_frame_0']}")
        check(m["crust_pieces_last"] == expected_pieces,
              f"{label}: {expected_pieces} crust pieces at the end, got {m['crust_pieces_last']}")
        check(m["slices_broken_across"] == expected_split,
              f"{label}: {expected_split} slices broken across, got {m['slices_broken_across']}")
        check(m.get("crust_broken_along_cuts") == along_cuts,
              f"{label}: broken along the cuts is {along_cuts}, got {m.get('crust_broken_along_cuts')}")
        if not across:  # the pieces are the groups of whole slices built here
            found = sorted(sorted(numbered[n] for n in g) for g in m.get("crust_slice_groups", []))
            check(found == sorted(sorted(g) for g in groups), f"{label}: slice groups {sorted(map(sorted, groups))}, got {found}")

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

# Toothpaste: 1.5 turns of a coil of radius 0.04 around a point 0.1 m beside the nozzle, rising as
# it is laid, compressed to J = 0.5 (F = diag(1, 0.5, 1)) or not: the turns and the median J. The
# crushed one has a rope falling onto it from the nozzle (1.5 m, at 0.8 m/s down), 50 particles at
# the middle of each of the four height bands between the nozzle and the pile's base, with
# J = 1, 0.9, 0.8, 0.7 from the top: the falling rope's J by height.
for label, squash in (("coil_offset", 1.0), ("coil_crushed", 0.5)):
    s = k / layers
    position = np.stack([nozzle[0] + 0.1 + 0.04 * np.cos(3 * np.pi * s), 1.0 + 0.1 * s,
                         nozzle[2] + 0.04 * np.sin(3 * np.pi * s)], axis=1) + 0.3 * jitter
    F = np.tile(np.diag([1.0, squash, 1.0]), (len(k), 1, 1))
    velocity = np.zeros((len(k), 3))
    falling_J = [1.0, 0.9, 0.8, 0.7] if squash < 1 else []
    if falling_J:
        edges = np.linspace(nozzle[1], position[:, 1].min(), 5)
        rope_y = np.repeat(0.5 * (edges[:-1] + edges[1:]), 50) + np.tile(np.linspace(-0.02, 0.02, 50), 4)
        rope = np.stack([np.full(len(rope_y), nozzle[0]), rope_y, np.full(len(rope_y), nozzle[2])], axis=1)
        position = np.concatenate([position, rope])
        F = np.concatenate([F, np.array([np.diag([1.0, j, 1.0]) for j in np.repeat(falling_J, 50)])])
        velocity = np.concatenate([velocity, np.tile([0.0, -0.8, 0.0], (len(rope), 1))])
    d = os.path.join(args.workdir, label)
    write_frame(d, 0, 0.0, position[:0], [], ["toothpaste"], spacing=0.01)
    write_frame(d, 1, 2.0, position, np.zeros(len(position)), ["toothpaste"], velocity=velocity, spacing=0.01,
                deformation_gradient=F)
    m = measure(d, "toothpaste", os.path.join(paper, "toothpaste.xml"))
    if m:
        check(abs(abs(m["coil_turns"]) - 1.5) < 0.3, f"{label}: 1.5 turns, got {m['coil_turns']}")
        check(abs(m.get("laid_J_median", 0) - squash) < 1e-9, f"{label}: median J {squash}, got {m.get('laid_J_median')}")
        expected, got = falling_J or [None] * 4, m.get("falling_J_by_height") or []
        same = lambda e, g: (e is None) == (g is None) and (e is None or abs(e - g) < 1e-9)
        check(len(got) == 4 and all(map(same, expected, got)), f"{label}: falling rope's J by height {expected}, got {got}")

# Shaving foam: a rope of radius r = 5 spacings laid along x, turned around and laid back beside
# itself (a racetrack: two straight arms 60 spacings long joined by a half circle), the arms'
# axes dc apart, sampled on one lattice (the particles within r of the rope's axis, in emission
# order along it). dc = r: the arms have run into each other (one contact, fused); dc = 2r: they
# touch as two round ropes (one contact, not fused); dc = 2r + 3 spacings: apart (no contact).
h = 0.002
r = 5 * h
foam_nozzle = np.array([0.24415, 0.03, 0.24415])
for label, dc, contacts, fused in (("ropes_fused", r, 1, 1), ("ropes_touching", 2 * r, 1, 0),
                                   ("ropes_apart", 2 * r + 3 * h, 0, 0)):
    length = 60 * h
    t = np.linspace(0.0, 1.0, 2000)
    arm1 = np.stack([foam_nozzle[0] - length / 2 + length * t, 0 * t, -dc / 2 + 0 * t], axis=1)
    bend = np.stack([foam_nozzle[0] + length / 2 + dc / 2 * np.sin(np.pi * t), 0 * t, -dc / 2 * np.cos(np.pi * t)], axis=1)
    axis_points = np.concatenate([arm1, bend[1:], arm1[::-1][1:] * [1, 1, -1]]) + [0, foam_nozzle[1] + r, foam_nozzle[2]]
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(axis_points, axis=0), axis=1))])
    box = lattice(axis_points.min(axis=0) - r, axis_points.max(axis=0) + r, h)
    distance, nearest = cKDTree(axis_points).query(box)
    rope = box[distance < r]
    order = np.argsort(arc[nearest[distance < r]], kind="stable")
    d = os.path.join(args.workdir, label)
    write_frame(d, 0, 0.0, rope[:0], [], ["foam"], spacing=h)
    write_frame(d, 1, 2.0, rope[order], np.zeros(len(rope)), ["foam"], spacing=h)
    m = measure(d, "shaving_foam", os.path.join(paper, "shaving_foam.xml"))
    if m:
        check(abs(m.get("rope_radius_m", 0) - r) < 0.25 * r, f"{label}: rope radius {r}, got {m.get('rope_radius_m')}")
        check(m.get("loop_contacts") == contacts, f"{label}: {contacts} loop-to-loop contacts, got {m.get('loop_contacts')}")
        check(m.get("loop_contacts_fused") == fused, f"{label}: {fused} fused, got {m.get('loop_contacts_fused')} "
              f"(necks / r {m.get('loop_contact_necks_over_rope_radius')})")

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
    check(m["came_apart"] and m["pieces_over_1_percent"] == 2, f"sponge: came apart in 2 pieces: {m}")
    check(m["first_apart_time"] == 1.0, f"sponge: first apart at 1.0 s, got {m['first_apart_time']}")
    check(m["piece_height_ranges"][0][1] < 4.25 < m["piece_height_ranges"][1][0],
          f"sponge: the pieces lie on either side of the plane: {m['piece_height_ranges']}")
# The same block with only a column of particles along one edge (under 1 % of them) torn off at 0.5 s and
# the whole cut at 1.0 s: it came apart, first at 1.0 s; with no cut at all it did not.
d = os.path.join(args.workdir, "sponge_sliver")
write_frame(d, 0, 0.0, block, np.zeros(len(block)), ["sponge"], spacing=h)
sliver = block.copy()
top = (sliver[:, 0] > 5.2335 - h) & (sliver[:, 2] > 5.2335 - h)
sliver[top, 0] += 3 * h
write_frame(d, 1, 0.5, sliver, np.zeros(len(block)), ["sponge"], spacing=h)
write_frame(d, 2, 1.0, torn, np.zeros(len(block)), ["sponge"], spacing=h)
m = measure(d, "twisting_sponge", os.path.join(paper, "twisting_sponge.xml"))
if m:
    check(0 < top.sum() < len(block) // 100, "sponge: the sliver is under 1 % of the particles")
    check(m["first_apart_time"] == 1.0, f"sponge: a sliver torn off is not apart; first apart at 1.0 s, got {m['first_apart_time']}")
d = os.path.join(args.workdir, "sponge_whole")
write_frame(d, 0, 0.0, block, np.zeros(len(block)), ["sponge"], spacing=h)
write_frame(d, 1, 1.0, sliver, np.zeros(len(block)), ["sponge"], spacing=h)
m = measure(d, "twisting_sponge", os.path.join(paper, "twisting_sponge.xml"))
if m:
    check(not m["came_apart"] and m["first_apart_time"] is None and m["pieces_over_1_percent"] == 1,
          f"sponge: with a sliver torn off it did not come apart: {m}")
# The error contract: a bad or missing argument, a missing directory or scene file and a damaged
# frame are each answered with one line on stderr naming the option or the file, a non-zero exit
# and nothing on stdout (no traceback).
damaged = os.path.join(args.workdir, "damaged")
shutil.copytree(os.path.join(args.workdir, "pie_apart"), damaged)
truncated = os.path.join(damaged, "frame_00001.h5")
with open(truncated, "r+b") as frame_file:
    frame_file.truncate(os.path.getsize(truncated) // 2)
pie_file = os.path.join(paper, "pie.xml")
not_xml = os.path.join(args.workdir, "not_a_scene.xml")
with open(not_xml, "w") as out:
    out.write("<ParameterList name='x'><Parameter")
missing = os.path.join(args.workdir, "no_such_run")
for label, argv, named in (
        ("truncated frame", [damaged, "--scene", "pie", "--scene-file", pie_file], truncated),
        ("missing directory", [missing, "--scene", "pie", "--scene-file", pie_file], missing),
        ("missing scene file", [damaged, "--scene", "pie", "--scene-file", missing + ".xml"], missing + ".xml"),
        ("scene file not XML", [damaged, "--scene", "pie", "--scene-file", not_xml], not_xml),
        ("no output directory", [], "output_dir"),
        ("unknown option", [damaged, "--scene", "pie", "--bogus"], "--bogus"),
        ("bad number", [damaged, "--scene", "pie", "--link", "-1"], "--link"),
        ("bad scene name", [damaged, "--scene", "cake"], "--scene")):
    out = subprocess.run([sys.executable, args.measure, *argv], capture_output=True, text=True)
    lines = out.stderr.strip().splitlines()
    check(out.returncode != 0, f"{label}: a non-zero exit, got {out.returncode}")
    check(len(lines) == 1 and named in lines[0] and "Traceback" not in out.stderr,
          f"{label}: one line naming {named}, got {len(lines)} lines: {out.stderr[-600:]}")
    check(out.stdout == "", f"{label}: nothing on stdout, got {out.stdout[:200]}")

finish("measure_scenes.py: pieces, slice groups, coils, folds, fused contacts, J, rebound order and torn "
       "links as constructed; one line for each bad input")
