#!/usr/bin/env python3
"""Seeded fuzzing of the inputs. Each variant is one of these families, run with viscompm (or
viscompm-study):

  scene    a shipped scene (inputs/scenes/ and paper/) with names misspelled, types changed, values
           made negative, zero, huge, tiny, non-finite or words, vectors of the wrong length,
           entries and sections deleted, the file cut short or its solver file pointing nowhere
  solver   the same for a shipped solver file, run on a cheap scene whose first step solves
  list     one item of an Array(double) made nan, inf or 1e400 (must be exit 2: class 1 of issue 17)
  mesh     a collider, body or region mesh with a non-finite, huge or degenerate vertex, collapsed
           or cut short (class 2)
  size     sizes at the ends of their declared ranges: voxels, cells, scales, radii, counts (class 3)
  motion   emitters and motions at their limits: rates, times, nozzles at the grid's edge, speeds
           no time step can follow, keyframes (class 4)
  study    viscompm-study on a small study whose file, scene, solver or MatrixMarket files (matrix,
           right-hand side, coordinates) are cut short or corrupted (class 5)
  options  options repeated or malformed on the command line (class 6)
  parser   a scene, solver or study file nested deeper, named longer or grown larger than the XML
           reader's bounds (or nested up to them with unknown sections): exit 2 (issue 24)

Every run must end with exit 0, 2 or 3 within its time limit, exit 2 and 3 with one line on stderr,
no crash, no hang, no "internal error", every frame it wrote finite, and exit 2 within seconds. The
output directory holds files "an earlier run" left (frames, index, solver log, checkpoint, study
CSVs): a run answered with exit 2 must leave every one of them as it was. A valid input may be slow
(e.g. a finer grid): at the time limit the run gets SIGTERM and must stop with exit 4 within the
grace period (it did not hang); such runs are counted, not failed. Where a family's mutation is
certainly bad input (a non-finite list item, a repeated option, ...), exit 2 is required.

  fuzz_inputs.py --viscompm build/bin/viscompm --study build/bin/viscompm-study --inputs inputs \\
                 --workdir /tmp/fuzz --seed 1 --variants 5000
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
parser.add_argument("--study", default="", help="viscompm-study (the study family is skipped without it)")
parser.add_argument("--inputs", required=True)
parser.add_argument("--workdir", required=True)
parser.add_argument("--seed", type=int, default=12)
parser.add_argument("--variants", type=int, default=100)
parser.add_argument("--jobs", type=int, default=2)
parser.add_argument("--families", default="", help="comma-separated families to draw from (default: all)")
parser.add_argument("--time-limit", type=float, default=60.0, help="seconds before SIGTERM")
parser.add_argument("--grace", type=float, default=60.0, help="seconds a run may take to stop after SIGTERM")
parser.add_argument("--answer-within", type=float, default=20.0, help="seconds an exit 2 may take")
parser.add_argument("--keep", action="store_true", help="keep the work directory of every variant")
parser.add_argument("--verbose", action="store_true", help="print every variant's outcome")
# Accepted for the common test interface (the runs use one rank, without mpiexec).
parser.add_argument("--ranks", type=int, default=1)
parser.add_argument("--mpiexec", default="")
args = parser.parse_args()
# The runs start in their own work directories.
args.viscompm, args.workdir = os.path.abspath(args.viscompm), os.path.abspath(args.workdir)
args.study = os.path.abspath(args.study) if args.study else ""

inputs = os.path.abspath(args.inputs)
scenes = sorted(glob.glob(os.path.join(inputs, "scenes", "*.xml")) + glob.glob(os.path.join(inputs, "scenes", "paper", "*.xml")))
solvers = sorted(glob.glob(os.path.join(inputs, "solvers", "*.xml")))
sponge = os.path.join(inputs, "scenes", "shooting_sponge.xml")
toothpaste = os.path.join(inputs, "scenes", "paper", "toothpaste.xml")
# A cheap scene whose first step solves (one Newton iteration, 5-15 CG iterations), for solver
# variants, meshes, motions and options.
coarse = ["--set", "Grid/Cell size=0.06"]

WORDS = ["", "x", "true", "none", "-", "1e", "0x10", "{}", "NaN"]
NUMBERS = ["-1", "0", "1e-300", "1e300", "-1e300", "nan", "inf", "-inf", "1e309", "2147483647", "-2147483648",
           "0.5", "3", "1e-9", "1e9"]
NON_FINITE = ["nan", "NaN", "inf", "-inf", "Infinity", "1e400", "-1e400", "0x1p2000"]


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


def remove(root, element):
    for parent in root.iter():
        if element in list(parent):
            parent.remove(element)
            return True
    return False


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
        remove(root, target)
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
    remove(root, p)
    return f"deleted '{name}'"


def absolute_files(text, source):
    """The scene's relative files (Solver/File, meshes) resolved against its own folder, so that the
    variant, written elsewhere, still finds them."""
    folder = os.path.dirname(source)
    return re.sub(r'(name="File" type="string" value=")([^"/][^"]*)',
                  lambda m: m.group(1) + os.path.normpath(os.path.join(folder, m.group(2))), text)


class Variant:
    """One run: its family, what was changed, the command, where it writes, the exit codes it may
    end with, the files an earlier run left in its output directory."""

    def __init__(self, index, family, source):
        self.index, self.family, self.source = index, family, os.path.basename(source)
        self.work = os.path.join(args.workdir, f"v{index:05d}")
        self.out = os.path.join(self.work, "out")
        os.makedirs(self.work, exist_ok=True)
        self.mutations, self.command, self.expect = [], [], {0, 2, 3}
        self.sentinels = ["frame_00000.h5", "particles.xdmf", "solver.csv", "checkpoint_00000.h5"]

    def write(self, name, text, mode="w"):
        path = os.path.join(self.work, name)
        with open(path, mode) as f:
            f.write(text)
        return path

    def simulate(self, scene, *extra, frames="1"):
        self.command = [args.viscompm, scene, "--output", self.out, "--frames", frames, *extra]
        if not any("Frame rate" in a for a in extra) and not any("Frame rate" in m for m in self.mutations):
            self.command += ["--set", "Simulation/Frame rate=500"]  # short frames


# ---------------------------------------------------------------------------------------------
# The families.
def scene_variant(v, rng, is_scene):
    source = rng.choice(scenes if is_scene else solvers)
    v.source = os.path.basename(source)
    text = absolute_files(open(source).read(), source)
    if rng.random() < 0.08:
        cut = rng.randrange(len(text))
        text = text[:cut]
        v.mutations.append(f"cut at byte {cut}")
    elif is_scene and rng.random() < 0.05:
        text = re.sub(r'(name="File" type="string" value=")[^"]*(\.xml")', r"\1/nonexistent/solver\2", text)
        v.mutations.append("Solver/File points nowhere")
    else:
        try:
            root = ET.fromstring(text)
            for _ in range(rng.choice([1, 1, 1, 2, 3])):
                v.mutations.append(mutate(root, rng))
            text = ET.tostring(root, encoding="unicode")
        except ET.ParseError:
            v.mutations.append("unparsable")
    path = v.write(os.path.basename(source), text)
    if is_scene:
        v.simulate(path)
    else:
        v.simulate(sponge, "--solver", path, *coarse)


def list_variant(v, rng):
    """One item of an Array(double) parameter replaced by a non-finite token: exit 2, never a run
    with the item silently replaced."""
    source = rng.choice(scenes)
    v.source = os.path.basename(source)
    root = ET.fromstring(absolute_files(open(source).read(), source))
    arrays = [p for p in root.iter("Parameter") if p.get("type") == "Array(double)" and p.get("value", "{}") != "{}"]
    p = rng.choice(arrays)
    items = p.get("value").strip("{} ").split(",")
    k = rng.randrange(len(items))
    items[k] = " " + rng.choice(NON_FINITE) if k else rng.choice(NON_FINITE)
    old = p.get("value")
    p.set("value", "{" + ",".join(items) + "}")
    v.mutations.append(f"'{p.get('name')}' = {p.get('value')} (was {old})")
    v.expect = {2}
    v.simulate(v.write(os.path.basename(source), ET.tostring(root, encoding="unicode")))


def tetrahedron(corners):
    text = "solid t\n"
    for face in ((0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)):
        text += "facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {corners[k]}\n" for k in face) + "endloop\nendfacet\n"
    return text + "endsolid t\n"


def mesh_text(v, rng):
    """A mesh file (OBJ or ASCII STL) with one mutation; returns (file name, text, certainly bad)."""
    corners = ["0 0 0", "1 0 0", "0 1 0", "0 0 1"]
    kind = rng.choice(["nan", "inf", "huge", "collapsed", "flat", "duplicate", "cut", "empty", "word", "obj_nan",
                       "obj_cut", "obj_faces", "fine"])
    head = open(os.path.join(inputs, "meshes", "head.obj")).read().splitlines()
    vertices = [i for i, line in enumerate(head) if line.startswith("v ")]
    if kind in ("nan", "inf", "huge", "word"):
        token = {"nan": "nan", "inf": "inf", "huge": "1e39", "word": "abc"}[kind]
        corners[rng.randrange(4)] = " ".join(token if rng.random() < 0.5 else c for c in ("0", "0", token))
        v.mutations.append(f"an STL vertex with {token}")
        return "mesh.stl", tetrahedron(corners), kind in ("nan", "inf", "huge")
    if kind == "collapsed":
        v.mutations.append("an STL whose vertices are all one point")
        return "mesh.stl", tetrahedron(["0.5 0.5 0.5"] * 4), True
    if kind == "flat":
        v.mutations.append("an STL of a flat (zero-volume) tetrahedron")
        return "mesh.stl", tetrahedron(["0 0 0", "1 0 0", "0 1 0", "1 1 0"]), False
    if kind == "duplicate":
        v.mutations.append("an STL with a repeated corner")
        return "mesh.stl", tetrahedron(["0 0 0", "0 0 0", "0 1 0", "0 0 1"]), False
    if kind == "cut":
        text = tetrahedron(corners)
        cut = rng.randrange(len(text))
        v.mutations.append(f"an STL cut at byte {cut}")
        return "mesh.stl", text[:cut], False
    if kind == "empty":
        v.mutations.append("an empty STL")
        return "mesh.stl", "", True
    if kind == "obj_nan":
        i = rng.choice(vertices)
        parts = head[i].split()
        parts[rng.randrange(1, 4)] = rng.choice(["nan", "inf", "-inf", "1e39"])
        head[i] = " ".join(parts)
        v.mutations.append(f"head.obj with '{head[i]}'")
        return "mesh.obj", "\n".join(head) + "\n", True
    if kind == "obj_cut":
        cut = rng.randrange(len(head))
        v.mutations.append(f"head.obj cut at line {cut}")
        return "mesh.obj", "\n".join(head[:cut]) + "\n", False
    if kind == "obj_faces":
        faces = [i for i, line in enumerate(head) if line.startswith("f ")]
        for i in rng.sample(faces, 10):
            head[i] = "f 1 1 1" if rng.random() < 0.5 else f"f 1 2 {len(vertices) + 5}"
        v.mutations.append("head.obj with degenerate or out-of-range faces")
        return "mesh.obj", "\n".join(head) + "\n", False
    v.mutations.append("head.obj as shipped")
    return "mesh.obj", "\n".join(head) + "\n", False


def mesh_variant(v, rng):
    name, text, bad = mesh_text(v, rng)
    mesh = v.write(name, text)
    role = rng.choice(["Colliders", "Bodies", "Regions"])
    entries = (f'<Parameter name="Shape" type="string" value="mesh"/><Parameter name="File" type="string" value="{mesh}"/>'
               f'<Parameter name="Scale" type="double" value="{rng.choice(["0.1", "0.3", "1e-3", "1e20"])}"/>'
               '<Parameter name="Center" type="Array(double)" value="{0.6, 0.6, 0.36}"/>')
    if role == "Colliders":
        entries += '<Parameter name="Contact" type="string" value="' + rng.choice(["sticky", "slip", "separating"]) + '"/>'
    else:
        entries += '<Parameter name="Material" type="string" value="sponge"/>'
    if role == "Regions":
        entries += '<Parameter name="Body" type="string" value="sponge"/>'
    if rng.random() < 0.3:
        entries += f'<Parameter name="Voxel size" type="double" value="{rng.choice(["1.5e-5", "1e-4", "0.01", "0.5"])}"/>'
    item = f'<ParameterList name="{role}"><ParameterList name="fuzzed">{entries}</ParameterList></ParameterList>'
    text = absolute_files(open(sponge).read(), sponge)
    if f'<ParameterList name="{role}">' in text:
        text = text.replace(f'<ParameterList name="{role}">', item[:-len("</ParameterList>")], 1)
    else:
        text = text.replace('<ParameterList name="Output">', item + '<ParameterList name="Output">', 1)
    v.mutations.append(f"as {role}/fuzzed")
    if bad:
        v.expect = {2}
    v.simulate(v.write("scene.xml", text), *coarse)


SIZES = [  # (scene, parameter, values at or near the ends of their ranges)
    (toothpaste, "Colliders/toothbrush/Voxel size", ["1.5e-5", "2e-5", "1e-4", "1e-6", "1e300", "1e-300"]),
    (toothpaste, "Colliders/toothbrush/Scale", ["1e-300", "1e-20", "1e20", "1e300"]),
    (sponge, "Output/Surface voxel size", ["1.5e-5", "1e-5", "1e-7", "1e-3", "1e300", "1e-300"]),
    (sponge, "Grid/Cell size", ["1e-9", "1e-6", "1e-4", "0.1", "1e300", "5e-324"]),
    (sponge, "Bodies/sponge/Particles per cell", ["8", "1"]),
    (sponge, "Colliders/bullet/Radius", ["1e-300", "1e30", "1e300"]),
    (sponge, "Grid/Padding cells", ["16"]),
    (sponge, "Grid/Padding lookahead", ["1000", "0"]),
    (sponge, "Grid/Wall thickness", ["8", "1"]),
    (sponge, "Grid/Upper corner", ["{1e300, 1e300, 1e300}", "{1e9, 1e9, 1e9}", "{0.5, 0.5, 0.5}"]),
    (sponge, "Simulation/CFL", ["10", "1e-300"]),
    (sponge, "Simulation/Max time step", ["1e300", "1e-300"]),
    (sponge, "Simulation/Min time step", ["1e-300", "4e-3"]),
    (sponge, "Output/Checkpoint wall seconds", ["1e-300"]),
    (sponge, "Output/Matrix Market steps", ["{1e15}", "{1}", "{1, 1, 1}"]),
    (os.path.join(inputs, "scenes", "paper", "pie.xml"), "Regions/scoring/Cut count", ["64", "1"]),
    (os.path.join(inputs, "scenes", "paper", "pie.xml"), "Regions/scoring/Cut width", ["1e-300", "1e300"]),
]


def size_variant(v, rng):
    source, parameter, values = rng.choice(SIZES)
    value = rng.choice(values)
    v.source = os.path.basename(source)
    v.mutations.append(f"{parameter}={value}")
    extra = [] if "Cell size" in parameter or source != sponge else coarse
    v.simulate(source, *extra, "--set", f"{parameter}={value}")


def motion_variant(v, rng):
    """Emitters and motions at their limits: --set on the toothpaste (an emitter and a mesh
    collider) or the sponge (a moving bullet), some of them certainly bad."""
    cases = [
        (toothpaste, "Emitters/nozzle/Mass rate", ["1e300", "1e10", "1e-300", "0"], set()),
        (toothpaste, "Emitters/nozzle/Start time", ["1e30", "0.04"], set()),
        (toothpaste, "Emitters/nozzle/Stop time", ["0"], {2}),  # not after Start time (0)
        (toothpaste, "Emitters/nozzle/Stop time", ["1e-300"], set()),
        (toothpaste, "Emitters/nozzle/Center", ["{1.66, 5, 1}", "{1.66, 3.99, 1}", "{0, 0, 0}", "{1.66, 3.9, 1}"], set()),
        (toothpaste, "Emitters/nozzle/Velocity", ["{0, -1e8, 0}", "{0, -1e-300, 0}", "{0, 0, 0}", "{1e300, 0, 0}"], set()),
        (toothpaste, "Emitters/nozzle/Radius", ["1e-300", "1e30", "1e-4"], set()),
        (toothpaste, "Emitters/nozzle/Particles per cell", ["8"], set()),
        (toothpaste, "Colliders/toothbrush/Angular velocity", ["{0, 1e8, 0}", "{0, 1e3, 0}", "{1e300, 0, 0}"], set()),
        (sponge, "Colliders/bullet/Angular velocity", ["{0, 0, 1e8}", "{0, 0, 1e4}", "{0, 0, 1e-300}"], set()),
        (sponge, "Colliders/bullet/Velocity", ["{1e7, 0, 0}", "{1e300, 0, 0}", "{-4, 0, 0}"], set()),
        (sponge, "Colliders/bullet/Surface velocity", ["{0, 1e7, 0}", "{0, 1e3, 0}"], set()),
        (sponge, "Colliders/bullet/Start time", ["1e30", "0.01"], set()),
        (sponge, "Colliders/bullet/Keyframe times", ["{0, 1e-300}", "{0, 1e30}", "{0, 0.01}"], set()),
        (sponge, "Bodies/sponge/Angular velocity", ["{1e8, 0, 0}", "{0, 0, 100}"], set()),
    ]
    source, parameter, values, expect = rng.choice(cases)
    value = rng.choice(values)
    v.source = os.path.basename(source)
    sets = ["--set", f"{parameter}={value}"]
    v.mutations.append(f"{parameter}={value}")
    if parameter.endswith("Keyframe times"):
        sets += ["--set", "Colliders/bullet/Keyframe positions={0, 0, 0, " + rng.choice(["1, 0, 0", "1e300, 0, 0"]) + "}"]
        v.mutations.append(sets[-1])
    if parameter.endswith("Start time") and source == sponge and rng.random() < 0.5:
        sets += ["--set", "Colliders/bullet/Stop time=" + rng.choice(["0", "1e-300"])]
        v.mutations.append(sets[-1] + " (before Start time)")
        expect = {2}
    if expect:
        v.expect = expect
    v.simulate(source, *(coarse if source == sponge else []), *sets)


def options_variant(v, rng):
    """The command line with an option repeated or malformed."""
    solver = os.path.join(inputs, "solvers", "jacobi_cg.xml")
    kind = rng.choice(["solver", "output", "frames", "restart", "set", "set_option", "frames_word", "set_malformed",
                       "unknown", "missing_value", "two_scenes"])
    extra, expect = [], {2}
    if kind == "solver":
        extra = ["--solver", solver, "--solver=" + os.path.join(inputs, "solvers", "sgs_cg.xml")]
    elif kind == "output":
        extra = ["--output", v.out + "_other"]
    elif kind == "frames":
        extra = ["--frames", "2"]
    elif kind == "restart":
        extra = ["--restart", "a.h5", "--restart", "b.h5"]
    elif kind == "set":
        extra = ["--set", "Grid/Cell size=0.07", "--set", "Grid/Cell size=0.08"]
    elif kind == "set_option":
        extra = ["--set", "Output/Directory=" + v.out + "_other"]
    elif kind == "frames_word":
        extra = ["--frames=" + rng.choice(["abc", "-1", "2.5", "", "1e3", "99999999999"])]
    elif kind == "set_malformed":
        extra = ["--set", rng.choice(["=", "Grid/Cell size", "=1", "Grid/Cell size=0.1=0.2",
                                      "Grid/Cell size=", "/=1", "Materials//Density=1"])]
    elif kind == "unknown":
        extra = [rng.choice(["--bogus", "--Output", "-o"]), "x"]
    elif kind == "missing_value":
        extra = [rng.choice(["--solver", "--set", "--restart"])]
    else:
        extra = [toothpaste]
    v.mutations.append(" ".join(extra)[:120])
    v.expect = expect
    # The repeated options come after the variant's own --output and --frames.
    v.simulate(sponge, *coarse)
    v.command += extra


# viscompm-study: a small study of a MatrixMarket dump (written once, at the start) and of the
# coarse sponge, with its files cut or corrupted.
def study_base():
    base = os.path.join(args.workdir, "study_base")
    if not os.path.exists(os.path.join(base, "newton_step_1.mtx")):
        subprocess.run([args.viscompm, sponge, "--output", base, "--frames", "1", *coarse, "--set",
                        "Output/Matrix Market steps={1}", "--set", "Simulation/Frame rate=500"],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    return base


def corrupt_lines(lines, rng, what):
    """One corruption of a MatrixMarket file's lines; returns (lines, description, certainly bad)."""
    kind = rng.choice(["cut_line", "cut_byte", "word", "nan", "index", "count", "banner", "blank_value", "extra"])
    data = [i for i, line in enumerate(lines) if line and not line.startswith("%")]
    size_line = data[0]
    if kind == "cut_line":
        cut = rng.randrange(size_line + 1, len(lines))
        return lines[:cut], f"{what} cut at line {cut}", True
    if kind == "cut_byte":
        text = "\n".join(lines)
        cut = rng.randrange(len(text))
        return text[:cut].split("\n"), f"{what} cut at byte {cut}", cut < len(text) - 1
    i = rng.choice(data[1:])
    parts = lines[i].split()
    if kind == "word":
        parts[rng.randrange(len(parts))] = "abc"
    elif kind == "nan":
        parts[-1] = rng.choice(["nan", "inf", "1e400"])
    elif kind == "index":
        if len(parts) != 3:  # a dense file's line has one value, no index
            return lines, f"{what}: no index to corrupt", False
        parts[rng.randrange(2)] = rng.choice(["0", "-1", "99999999"])
    elif kind == "count":
        lines[size_line] = " ".join(lines[size_line].split()[:-1] + [str(int(lines[size_line].split()[-1]) + 7)])
        return lines, f"{what} size line announces more", True
    elif kind == "banner":
        lines[0] = rng.choice(["%%MatrixMarket matrix coordinate complex general", "%MatrixMarket", "hello"])
        return lines, f"{what} banner '{lines[0]}'", True
    elif kind == "blank_value":
        parts = parts[:-1]
    elif kind == "extra":
        return lines + ["1 1 1.0"], f"{what} with an extra entry", what == "matrix"
    lines[i] = " ".join(parts)
    return lines, f"{what} line {i}: '{lines[i][:60]}'", True


def study_variant(v, rng):
    base = study_base()
    v.sentinels = ["study.csv", "operators.csv", "steps.csv"]
    names = {"matrix": "newton_step_1.mtx", "rhs": "newton_step_1_rhs.mtx", "coordinates": "newton_step_1_coordinates.mtx"}
    for what, name in names.items():
        shutil.copy(os.path.join(base, name), os.path.join(v.work, "problem" + name[len("newton_step_1"):]))
    solver = os.path.join(inputs, "solvers", "jacobi_cg.xml")
    study = (f'<ParameterList name="fuzzed"><Parameter name="Matrix Market files" type="Array(string)" value="{{problem.mtx}}"/>'
             f'<Parameter name="Solvers" type="Array(string)" value="{{{solver}}}"/>'
             '<Parameter name="Plot" type="bool" value="false"/>')
    if rng.random() < 0.3:
        study += (f'<Parameter name="Scene" type="string" value="{sponge}"/>'
                  '<Parameter name="Cell sizes" type="Array(double)" value="{0.08}"/>'
                  '<Parameter name="Time steps" type="Array(double)" value="{3}"/>')
    study += "</ParameterList>"
    kind = rng.choice(["matrix", "matrix", "rhs", "coordinates", "study", "missing", "no_rhs"])
    if kind in names:
        path = os.path.join(v.work, "problem" + names[kind][len("newton_step_1"):])
        lines, description, bad = corrupt_lines(open(path).read().split("\n"), rng, kind)
        v.write(os.path.basename(path), "\n".join(lines))
        v.mutations.append(description)
        if bad:
            v.expect = {2}
    elif kind == "missing":
        target = rng.choice(["problem.mtx", solver, sponge])
        if target in study:
            study = study.replace(target, "problem_missing.mtx" if target == "problem.mtx" else "/nonexistent.xml")
            v.mutations.append(f"{os.path.basename(target)} missing")
            v.expect = {2}
    elif kind == "no_rhs":  # valid: the right-hand side is then all ones
        os.remove(os.path.join(v.work, "problem_rhs.mtx"))
        v.mutations.append("no right-hand side file")
    else:
        root = ET.fromstring(study)
        for _ in range(rng.choice([1, 2])):
            v.mutations.append(mutate(root, rng))
        study = ET.tostring(root, encoding="unicode")
        if rng.random() < 0.1:
            study = study[:rng.randrange(len(study))]
            v.mutations.append("cut")
    v.command = [args.study, v.write("study.xml", study), "--output", v.out]


def parser_variant(v, rng):
    """A file beyond (or, with unknown sections, at) the XML reader's bounds: 32 levels, 256
    characters per name, 4 MiB. Every such file is bad input: exit 2 within seconds."""
    role = rng.choice(["scene", "solver", "study"] if args.study else ["scene", "solver"])
    kind = rng.choice(["deep", "deep", "at_depth", "long_name", "long_tag", "large", "large_sparse"])
    text = absolute_files(open(sponge).read(), sponge)
    if kind in ("deep", "at_depth"):
        depth = rng.randint(33, 20000) if kind == "deep" else rng.randint(2, 31)
        inner = "".join(f'<ParameterList name="n{i}">' for i in range(depth)) + "</ParameterList>" * depth
        text = text.replace("<ParameterList name=\"Output\">", inner + "<ParameterList name=\"Output\">", 1)
        v.mutations.append(f"{depth} nested lists")
    elif kind in ("long_name", "long_tag"):
        length = rng.choice([257, 1000, 100000, 3000000])
        name = "".join(rng.choice("abcdefgh ") for _ in range(min(length, 64))) * (length // 64 + 1)
        name = name[:length]
        text = (text.replace('name="Output"', f'name="{name}"', 1) if kind == "long_name"
                else text.replace("<Parameter ", f"<P{name.replace(' ', 'x')} ", 1))
        v.mutations.append(f"a{' tag' if kind == 'long_tag' else ''} name of {length} characters")
    path = os.path.join(v.work, f"{role}.xml")
    if role == "solver":
        text = text if kind not in ("deep", "at_depth") else open(os.path.join(inputs, "solvers", "jacobi_cg.xml")).read().replace(
            "</ParameterList>", inner + "</ParameterList>", 1)
    if role == "study" and kind in ("deep", "at_depth"):
        text = ('<ParameterList name="fuzzed"><Parameter name="Scene" type="string" value="' + sponge + '"/>' +
                inner + "</ParameterList>")
    with open(path, "w") as f:
        f.write(text)
    if kind == "large":
        with open(path, "a") as f:
            f.write("<!--" + "x" * rng.randint(4 << 20, 6 << 20) + "-->")
        v.mutations.append("grown beyond 4 MiB by a comment")
    elif kind == "large_sparse":
        os.truncate(path, rng.choice([(4 << 20) + 1, 1 << 30, 1 << 34]))  # holes: no disk space
        v.mutations.append(f"{os.path.getsize(path)} bytes, mostly holes")
    v.mutations[-1] += f" in the {role} file"
    v.expect = {2}
    if role == "scene":
        v.simulate(path)
    elif role == "solver":
        v.simulate(sponge, "--solver", path, *coarse)
    else:
        v.sentinels = ["study.csv", "operators.csv", "steps.csv"]
        v.command = [args.study, path, "--output", v.out]


FAMILIES = {"scene": 36, "solver": 16, "list": 8, "mesh": 9, "size": 8, "motion": 8, "study": 8, "options": 7,
            "parser": 4}


def make_variant(index):
    rng = random.Random(args.seed * 1000003 + index)
    chosen = [f for f in (args.families.split(",") if args.families else FAMILIES) if f != "study" or args.study]
    family = rng.choices(chosen, weights=[FAMILIES[f] for f in chosen])[0]
    v = Variant(index, family, sponge)
    {"scene": lambda: scene_variant(v, rng, True), "solver": lambda: scene_variant(v, rng, False),
     "list": lambda: list_variant(v, rng), "mesh": lambda: mesh_variant(v, rng), "size": lambda: size_variant(v, rng),
     "motion": lambda: motion_variant(v, rng), "study": lambda: study_variant(v, rng),
     "options": lambda: options_variant(v, rng), "parser": lambda: parser_variant(v, rng)}[family]()
    # Files an earlier run left in the output directory (a frame that reads back as finite).
    os.makedirs(v.out, exist_ok=True)
    for name in v.sentinels:
        path = os.path.join(v.out, name)
        if name.endswith(".h5"):
            with h5py.File(path, "w") as f:
                f.create_dataset("particles/position", data=np.zeros((1, 3)))
        else:
            with open(path, "w") as f:
                f.write(f"an earlier {name}\n")
    v.before = {name: open(os.path.join(v.out, name), "rb").read() for name in v.sentinels}
    return v


# ---------------------------------------------------------------------------------------------
def frames_finite(out):
    for path in glob.glob(os.path.join(out, "frame_*.h5")):
        with h5py.File(path, "r") as f:
            for name, dataset in f["particles"].items():
                if dataset.dtype.kind == "f" and not np.isfinite(dataset[...]).all():
                    return f"{os.path.basename(path)}: /particles/{name} is not finite"
    return ""


def earlier_files_changed(v):
    changed = [n for n in v.sentinels
               if not os.path.exists(os.path.join(v.out, n)) or open(os.path.join(v.out, n), "rb").read() != v.before[n]]
    return f"exit 2 changed the earlier {', '.join(changed)}" if changed else ""


def judge(v, code, stopped, stderr, seconds):
    """The outcome and, if the contract was broken, the problem."""
    lines = [line for line in stderr.splitlines() if line.startswith("viscompm")]
    if stopped:
        return ("stopped", "") if code == 4 else ("hang", f"exit {code} after SIGTERM")
    if code not in (0, 2, 3):
        return "crash", f"exit {code}: {stderr[-600:]}"
    outcome = {0: "ran", 2: "rejected", 3: "failed"}[code]
    if code != 0 and len(lines) != 1:
        return outcome, f"exit {code} without exactly one message line: {stderr[-600:]}"
    if any("internal error" in line for line in lines):
        return outcome, f"internal error: {lines}"
    if code not in v.expect:
        return outcome, f"exit {code}, expected {sorted(v.expect)}: {lines[0] if lines else ''}"
    if code == 2 and seconds > args.answer_within:
        return outcome, f"exit 2 after {seconds:.0f} s (bad input is answered within seconds)"
    if code == 2:
        return outcome, earlier_files_changed(v)
    return outcome, frames_finite(v.out) if v.family != "study" and os.path.isdir(v.out) else ""


def run(v):
    start = time.time()
    process = subprocess.Popen(v.command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                               start_new_session=True, cwd=v.work)
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
            return v, "hang", "no exit within the grace period after SIGTERM", time.time() - start
    seconds = time.time() - start
    outcome, problem = judge(v, process.returncode, stopped, stderr, seconds)
    if problem:
        outcome = outcome if outcome in ("crash", "hang") else "bad"
    elif not args.keep:
        shutil.rmtree(v.work, ignore_errors=True)
    lines = [line for line in stderr.splitlines() if line.startswith("viscompm")]
    return v, outcome, problem or (lines[0] if lines else ""), seconds


shutil.rmtree(args.workdir, ignore_errors=True)
os.makedirs(args.workdir)
if args.study and (not args.families or "study" in args.families):
    study_base()
started = time.time()
counts, failures, slowest_answer = {}, [], 0.0
with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
    for v, outcome, detail, seconds in pool.map(run, map(make_variant, range(args.variants))):
        key = f"{v.family}:{outcome}"
        counts[key] = counts.get(key, 0) + 1
        if outcome == "rejected":
            slowest_answer = max(slowest_answer, seconds)
        mutation = "; ".join(v.mutations)
        if args.verbose:
            print(f"{v.index:5d} {v.family:7s} {outcome:8s} {seconds:5.1f}s {v.source}: {mutation} -> {detail}", flush=True)
        if outcome in ("crash", "hang", "bad"):
            failures.append(f"variant {v.index} ({v.family}, {v.source}: {mutation}): {outcome}: {detail}")
            print("FAIL:", failures[-1], flush=True)
        if not args.verbose and (v.index + 1) % 250 == 0:
            print(f"{v.index + 1} of {args.variants} variants in {time.time() - started:.0f} s", flush=True)
elapsed = time.time() - started
summary = ", ".join(f"{k} {n}" for k, n in sorted(counts.items()))
print(f"{args.variants} variants (seed {args.seed}) in {elapsed:.0f} s: {summary}")
print(f"slowest exit 2: {slowest_answer:.1f} s")
print(f"{len(failures)} failure(s)")
sys.exit(1 if failures else 0)
