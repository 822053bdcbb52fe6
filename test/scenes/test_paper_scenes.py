#!/usr/bin/env python3
"""Every scene of inputs/scenes/paper/ runs two frames (coarsened where the default is slow, with
frame rates that reach each scene's event) and its frames are sound: every stored field finite,
ids unique, the mass conserved exactly or grown by exactly what the emitters delivered (the
frames' emitted_mass attribute), colliders written with the frames and indexed by the XDMF file.
"""
import glob
import os
import shlex
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, failures, finish, program_arguments  # noqa: E402

# Per scene: overrides that keep the test short (seconds on 2 cores) while reaching the event.
SETTINGS = {
    "twisting_sponge": ["Grid/Cell size=0.3", "Simulation/Frame rate=8"],        # grips turn 0.19 rad
    "shooting_sponge": ["Simulation/Frame rate=30"],                             # the bullet hits
    "shaving_foam": ["Simulation/Frame rate=12", "Output/Surface voxel size=0.003"],  # the stream falls
    "weissenberg_sweep": ["Grid/Cell size=0.05", "Simulation/Frame rate=10"],    # the balls land
    "viennetta": ["Simulation/Frame rate=6"],                                    # it reaches the belt
    "pie": ["Grid/Cell size=0.04", "Simulation/Frame rate=240"],                 # the pie reaches the head
    "toothpaste": ["Simulation/Frame rate=3"],                                   # it reaches the brush
}


def main():
    args = program_arguments("viscompm", ranks=2).parse_args()
    scenes = sorted(glob.glob(os.path.join(args.inputs, "scenes", "paper", "*.xml")))
    names = [os.path.splitext(os.path.basename(s))[0] for s in scenes]
    check(sorted(names) == sorted(SETTINGS), f"the paper scenes are {sorted(SETTINGS)}, found {names}")
    for scene, name in zip(scenes, names):
        out = os.path.join(args.workdir, name)
        command = shlex.split(args.mpiexec) + ["-np", str(args.ranks), args.viscompm, scene, "--output", out,
                                               "--frames", "2"]
        for s in SETTINGS.get(name, []):
            command += ["--set", s]
        started = time.time()
        result = subprocess.run(command, capture_output=True, text=True)
        elapsed = time.time() - started
        check(result.returncode == 0, f"{name}: exit {result.returncode}: {result.stderr[-1500:]}")
        if result.returncode != 0:
            continue
        has_colliders = "<ParameterList name=\"Colliders\">" in open(scene).read()
        mass0 = None
        for frame in range(3):
            path = os.path.join(out, f"frame_{frame:05d}.h5")
            check(os.path.exists(path), f"{name}: {path} written")
            if not os.path.exists(path):
                continue
            with h5py.File(path, "r") as f:
                p = f["particles"]
                n = p["id"].shape[0]
                check(n > 0, f"{name} frame {frame}: particles")
                for field in p:
                    check(np.all(np.isfinite(p[field][...])), f"{name} frame {frame}: {field} finite")
                ids = p["id"][...]
                check(len(np.unique(ids)) == n, f"{name} frame {frame}: ids unique")
                mass = float(np.sum(p["mass"][...]))
                emitted = float(f.attrs["emitted_mass"])
                if mass0 is None:
                    mass0 = mass - emitted
                check(abs(mass - (mass0 + emitted)) <= 1e-12 * max(mass, 1e-300) * max(n, 1),
                      f"{name} frame {frame}: mass {mass!r} = initial {mass0!r} + emitted {emitted!r}")
                if frame == 2 and "Emitters" in open(scene).read():
                    check(emitted > 0, f"{name}: the emitters delivered mass")
                check(("colliders" in f) == has_colliders, f"{name} frame {frame}: colliders in the frame")
                if "colliders" in f:
                    c = f["colliders"]
                    check(c["triangles"].shape[1] == 3 and c["triangles"][...].max() < c["vertices"].shape[0],
                          f"{name} frame {frame}: collider triangles index its vertices")
        # Surfaces where asked for: an OBJ per frame that encloses volume, and the VDB level set.
        if any(o.startswith("Output/Surface voxel size") for o in SETTINGS[name]):
            for frame in range(3):
                obj, vdb = (os.path.join(out, f"surface_{frame:05d}.{ext}") for ext in ("obj", "vdb"))
                check(os.path.exists(obj) and os.path.exists(vdb), f"{name}: surface_{frame:05d}.obj and .vdb")
                if os.path.exists(obj):
                    lines = open(obj).read().split("\n")
                    v = np.array([[float(t) for t in l.split()[1:]] for l in lines if l.startswith("v ")])
                    f = np.array([[int(t) - 1 for t in l.split()[1:]] for l in lines if l.startswith("f ")])
                    volume = np.sum(np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]]))) / 6 if len(f) else 0
                    check(volume > 0, f"{name}: surface_{frame:05d}.obj encloses volume ({volume})")
        # The XDMF index names datasets that exist, with the right shapes.
        xdmf = os.path.join(out, "particles.xdmf")
        collections = [g.attrib["Name"] for g in ET.parse(xdmf).getroot().findall("./Domain/Grid")]
        check(collections == (["particles", "colliders"] if has_colliders else ["particles"]),
              f"{name}: xdmf collections {collections}")
        for item in ET.parse(xdmf).getroot().iter("DataItem"):
            file_name, dataset = item.text.split(":")
            with h5py.File(os.path.join(out, file_name), "r") as f:
                dims = tuple(int(d) for d in item.attrib["Dimensions"].split())
                check(dataset in f and f[dataset].shape == dims, f"{name}: xdmf item {item.text} {dims}")
        status = "ok" if not any(m.startswith(name) for m in failures) else "FAILED"
        print(f"{name}: {status} ({elapsed:.1f} s)")
    finish("all paper scenes sound")


if __name__ == "__main__":
    main()
