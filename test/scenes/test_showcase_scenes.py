#!/usr/bin/env python3
"""Every showcase scene (inputs/scenes/paper/showcase/) is its paper scene at another size: it reads
and validates (viscompm --frames 0 exits 0), and it differs from inputs/scenes/paper/NAME.xml only
in the parameters doc/scenes.md names (Grid/Cell size, Simulation/Frames, Solver/File, Newton's
strategy: Linear tolerance, Hessian update, Hessian projection, Preconditioner update; Output's
Directory and Surface voxel size), its meshes and
solver file being the same files."""
import glob
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, finish, program_arguments  # noqa: E402

ALLOWED = {"Grid/Cell size", "Simulation/Frames", "Solver/File", "Newton/Linear tolerance", "Newton/Hessian update",
           "Newton/Hessian projection", "Newton/Preconditioner update",
           "Output/Directory", "Output/Surface voxel size"}


def parameters(path):
    """{sublist path/name: value} of a scene file, file names resolved against its folder."""
    found = {}

    def walk(node, prefix):
        for child in node:
            name = child.get("name")
            if child.tag == "ParameterList":
                walk(child, f"{prefix}{name}/")
            elif child.tag == "Parameter":
                value = child.get("value")
                if name == "File":
                    value = os.path.normpath(os.path.join(os.path.dirname(path), value))
                found[prefix + name] = value

    walk(ET.parse(path).getroot(), "")
    return found


args = program_arguments("viscompm").parse_args()
showcase = sorted(glob.glob(os.path.join(args.inputs, "scenes", "paper", "showcase", "*.xml")))
paper = sorted(glob.glob(os.path.join(args.inputs, "scenes", "paper", "*.xml")))
check([os.path.basename(s) for s in showcase] == [os.path.basename(p) for p in paper],
      f"one showcase per paper scene: {[os.path.basename(s) for s in showcase]}")
for scene in showcase:
    name = os.path.basename(scene)
    run = subprocess.run([args.viscompm, scene, "--frames", "0", "--output", os.path.join(args.workdir, name)],
                         capture_output=True, text=True)
    check(run.returncode == 0, f"{name}: validates (exit {run.returncode}: {run.stderr.strip()[:300]})")
    ours, theirs = parameters(scene), parameters(os.path.join(os.path.dirname(scene), os.pardir, name))
    differing = {k for k in set(ours) | set(theirs) if ours.get(k) != theirs.get(k)}
    check(differing <= ALLOWED, f"{name}: differs from the paper scene only as documented, also in {sorted(differing - ALLOWED)}")
    check("Grid/Cell size" in differing, f"{name}: a showcase size of its own")
finish(f"{len(showcase)} showcase scenes: valid, the paper scenes at other sizes")
