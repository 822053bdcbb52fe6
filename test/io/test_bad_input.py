#!/usr/bin/env python3
"""Hostile inputs aimed at the newer features, answered as doc/contracts.md promises (issue 17):
exit 2 within seconds, one line on stderr naming the file and the parameter (or the option), and
every file an earlier run left in the output directory as it was. One case per kind of defect:
non-finite items of lists (class 1), non-finite mesh vertices (2), voxels OpenVDB or the memory
cannot take (3), emitters and motions at their limits (4), repeated or malformed options (6), and
XML files beyond the reader's bounds (issue 24: depth, name length, size).
viscompm-study's inputs (class 5) are checked by test/study/test_study_cli.py."""
import os
import re
import shlex
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, finish, program_arguments  # noqa: E402

args = program_arguments("viscompm", ranks=1).parse_args()
shutil.rmtree(args.workdir, ignore_errors=True)
os.makedirs(args.workdir)
scenes = os.path.join(args.inputs, "scenes")
solvers = os.path.join(args.inputs, "solvers")
sponge = os.path.join(scenes, "shooting_sponge.xml")
toothpaste = os.path.join(scenes, "paper", "toothpaste.xml")


def scene_variant(name, source, replacements):
    """`source` with each (old, new) replaced once (old must occur), written to the work directory
    with its relative files (solver, meshes) made absolute."""
    text = open(source).read()
    for old, new in replacements:
        check(old in text, f"{name}: '{old}' occurs in {source}")
        text = text.replace(old, new, 1)
    folder = os.path.dirname(os.path.abspath(source))
    text = re.sub(r'(name="File" type="string" value=")(\.\.[^"]*)',
                  lambda m: m.group(1) + os.path.normpath(os.path.join(folder, m.group(2))), text)
    path = os.path.join(args.workdir, name + ".xml")
    with open(path, "w") as f:
        f.write(text)
    return path


def mesh_file(name, corner):
    """An ASCII STL tetrahedron (closed, outward) whose first corner is `corner`."""
    v = [corner, "1 0 0", "0 1 0", "0 0 1"]
    text = "solid t\n"
    for face in ((0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)):
        text += "facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {v[k]}\n" for k in face) + "endloop\nendfacet\n"
    path = os.path.join(args.workdir, name)
    with open(path, "w") as f:
        f.write(text + "endsolid t\n")
    return path


def mesh_entries(mesh, extra=""):
    return (f'<Parameter name="Shape" type="string" value="mesh"/><Parameter name="File" type="string" value="{mesh}"/>'
            '<Parameter name="Scale" type="double" value="0.1"/>'
            f'<Parameter name="Center" type="Array(double)" value="{{0.5, 0.5, 0.3}}"/>{extra}')


def deep_file(name, depth):
    """`depth` ParameterLists one inside the other: 10 000 used to crash Teuchos' parser."""
    path = os.path.join(args.workdir, name)
    with open(path, "w") as f:
        f.write("".join(f'<ParameterList name="l{i}">\n' for i in range(depth)) + "</ParameterList>\n" * depth)
    return path


def huge_file(name):
    """The default scene with a 5 MiB comment: beyond the 4 MiB an XML parameter file may have."""
    path = os.path.join(args.workdir, name)
    with open(path, "w") as f:
        f.write(open(sponge).read().replace("<ParameterList", "<!--" + " " * (5 << 20) + "--><ParameterList", 1))
    return path


bullet_velocity = '<Parameter name="Velocity" type="Array(double)" value="{4, 0, 0}"/>'
colliders = '<ParameterList name="Colliders">'
bodies = '<ParameterList name="Bodies">'
nan_mesh = mesh_file("nan.stl", "nan 0 0")
coarse = ["--set", "Grid/Cell size=0.06"]
# (what, command line after the program, the file the line must name, the parameter or option)
cases = [
    ("a NaN in a collider's Angular velocity",
     [scene_variant("angular_nan", sponge, [(bullet_velocity, bullet_velocity.replace(
         'Velocity" type="Array(double)" value="{4, 0, 0}"',
         'Angular velocity" type="Array(double)" value="{0, nan, 0}"'))])], "angular_nan.xml",
     "'Colliders/bullet/Angular velocity'"),
    ("an overflowing body Velocity",
     [scene_variant("velocity_huge", sponge, [('<Parameter name="Particles per cell" type="int" value="2"/>',
                                               '<Parameter name="Particles per cell" type="int" value="2"/>'
                                               '<Parameter name="Velocity" type="Array(double)" value="{1e400,0,0}"/>')])],
     "velocity_huge.xml", "'Bodies/sponge/Velocity'"),
    ("an infinite keyframe position",
     [scene_variant("keyframe_inf", sponge, [(bullet_velocity,
                                              '<Parameter name="Keyframe times" type="Array(double)" value="{0, 1}"/>'
                                              '<Parameter name="Keyframe positions" type="Array(double)" '
                                              'value="{0, 0, 0, inf, 0, 0}"/>')])],
     "keyframe_inf.xml", "'Colliders/bullet/Keyframe positions'"),
    ("a collider mesh with a NaN vertex",
     [scene_variant("stl_nan", sponge, [(colliders, colliders + '<ParameterList name="plate">' + mesh_entries(nan_mesh) +
                                         "</ParameterList>")])], "stl_nan.xml", "'Colliders/plate/File'"),
    ("a body mesh with a NaN vertex",
     [scene_variant("body_nan", sponge, [(bodies, bodies + '<ParameterList name="blob">' + mesh_entries(nan_mesh) +
                                          '<Parameter name="Material" type="string" value="sponge"/></ParameterList>')])],
     "body_nan.xml", "'Bodies/blob/File'"),
    ("a mesh voxel below OpenVDB's smallest", [toothpaste, "--set", "Colliders/toothbrush/Voxel size=1e-6"],
     toothpaste, "'Colliders/toothbrush/Voxel size'"),
    ("a mesh voxel whose level set cannot fit", [toothpaste, "--set", "Colliders/toothbrush/Voxel size=2e-5"],
     toothpaste, "'Colliders/toothbrush/Voxel size'"),
    ("a surface voxel below OpenVDB's smallest", [sponge, *coarse, "--set", "Output/Surface voxel size=1e-7"],
     sponge, "'Output/Surface voxel size'"),
    ("a surface voxel whose level set cannot fit", [sponge, *coarse, "--set", "Output/Surface voxel size=2e-5"],
     sponge, "'Output/Surface voxel size'"),
    ("an emitter's mass rate beyond memory", [toothpaste, "--set", "Emitters/nozzle/Mass rate=1e300"],
     toothpaste, "'Emitters/nozzle/Mass rate'"),
    ("a nozzle outside the grid", [toothpaste, "--set", "Emitters/nozzle/Center={1.66, 5, 1}"],
     toothpaste, "'Emitters/nozzle/Center'"),
    ("a collider that stops before it starts",
     [sponge, *coarse, "--set", "Colliders/bullet/Start time=2", "--set", "Colliders/bullet/Stop time=1"],
     sponge, "'Colliders/bullet/Stop time'"),
    ("an angular velocity no time step can follow", [sponge, *coarse, "--set", "Colliders/bullet/Angular velocity={0,0,1e8}"],
     sponge, "'Colliders/bullet/Angular velocity'"),
    ("a scene nested 10 000 levels deep", [deep_file("deep_scene.xml", 10000)], "deep_scene.xml",
     "nested more than 32 levels"),
    ("a solver file nested 10 000 levels deep", [sponge, "--solver", deep_file("deep_solver.xml", 10000)],
     "deep_solver.xml", "nested more than 32 levels"),
    ("a scene with a name of 100 000 characters",
     [scene_variant("long_name", sponge, [('<ParameterList name="Output">', '<ParameterList name="' + "O" * 100000 + '">')])],
     "long_name.xml", "a name of 100000 characters, more than the 256"),
    ("a 5 MiB scene", [huge_file("huge_scene.xml")], "huge_scene.xml", "larger than the 4 MiB"),
    ("a gravity no Min time step can follow", [sponge, *coarse, "--set", "Simulation/Gravity={0, -1e300, 0}"],
     sponge, "'Simulation/Gravity'"),
    ("a Lame lambda whose step holds no inertia", [sponge, *coarse, "--set", "Materials/sponge/Lame lambda=1e300"],
     sponge, "'Materials/sponge/Lame lambda'"),
    ("a density below any material's", [sponge, *coarse, "--set", "Materials/sponge/Density=1e-300"],
     sponge, "'Materials/sponge/Density'"),
    ("a Newtonian viscosity whose step holds no inertia",
     [sponge, *coarse, "--set", "Materials/sponge/Newtonian viscosity=1e300"],
     sponge, "'Materials/sponge/Newtonian viscosity'"),
    ("--solver twice", [sponge, "--solver", os.path.join(solvers, "jacobi_cg.xml"), "--solver",
                        os.path.join(solvers, "sgs_cg.xml")], "", "--solver"),
    ("--frames that is not a number", [sponge, "--frames", "abc"], "", "--frames"),
    ("a parameter set twice", [sponge, "--frames", "2", "--set", "Simulation/Frames=3"], "", "'Simulation/Frames'"),
]

# Files an earlier run left: each case must leave them as they were.
out = os.path.join(args.workdir, "out")
os.makedirs(out)
sentinels = {"frame_00000.h5": b"an earlier frame", "particles.xdmf": b"an earlier index",
             "solver.csv": b"an earlier solver log", "checkpoint_00000.h5": b"an earlier checkpoint"}
for name, content in sentinels.items():
    with open(os.path.join(out, name), "wb") as f:
        f.write(content)

for what, command_line, named_file, named in cases:
    command = shlex.split(args.mpiexec) + ["-np", str(args.ranks), args.viscompm, *command_line, "--output", out]
    started = time.time()
    result = subprocess.run(command, capture_output=True, text=True, timeout=300)
    seconds = time.time() - started
    lines = [line for line in result.stderr.splitlines() if line.startswith("viscompm")]
    check(result.returncode == 2, f"{what}: exit 2, got {result.returncode}: {result.stderr[-600:]}")
    check(len(lines) == 1 and named in lines[0] and (not named_file or named_file in lines[0]),
          f"{what}: one line naming {named_file or 'the command line'} and {named}: {lines}")
    check("internal error" not in result.stderr, f"{what}: no internal error")
    check(seconds < 10, f"{what}: answered within seconds ({seconds:.1f} s)")
    intact = all(open(os.path.join(out, n), "rb").read() == c for n, c in sentinels.items())
    check(intact and sorted(os.listdir(out)) == sorted(sentinels), f"{what}: the earlier files are as they were")
    print(f"{what}: {seconds:.1f} s: {lines[0] if lines else result.stderr[-200:]}")

finish(f"{len(cases)} kinds of bad input answered with exit 2 on {args.ranks} rank(s)")
