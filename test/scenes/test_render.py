#!/usr/bin/env python3
"""scripts/render.sh turns a small run with particle surfaces (Output/Surface voxel size) into
smooth-shaded surface renders of the requested size, coloured around det b^E = 1, with the
collider drawn, a movie, and a gallery strip; a missing directory is a one-line error. Skips
(exit 77) only when ParaView's pvbatch or Xvfb is not installed (scripts/setup.sh installs them)."""
import os
import shutil
import subprocess
import sys

import numpy as np
from PIL import Image

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, finish, program_arguments  # noqa: E402

args = program_arguments("viscompm", "render").parse_args()

if shutil.which("pvbatch") is None or shutil.which("Xvfb") is None:
    print("SKIP: pvbatch or Xvfb is not installed (scripts/setup.sh installs paraview and xvfb)")
    sys.exit(77)

# The Weissenberg sweep, coarse: three balls land on the (grey) ground by frame 2 (t = 0.2 s).
out = os.path.join(args.workdir, "run")
shutil.rmtree(out, ignore_errors=True)
run = subprocess.run([args.viscompm, os.path.join(args.inputs, "scenes", "paper", "weissenberg_sweep.xml"),
                      "--output", out, "--frames", "2", "--set", "Grid/Cell size=0.05",
                      "--set", "Simulation/Frame rate=10", "--set", "Output/Surface voxel size=0.0125"],
                     capture_output=True, text=True)
check(run.returncode == 0, f"the run exits 0: {run.stderr[-1000:]}")
render = subprocess.run([args.render, out, "--style", "surface", "--size", "400x224", "--fps", "2", "--zoom", "1.5",
                         "--strip", "1,2", "--strip-file", os.path.join(out, "strip.png"), "--strip-width", "500"],
                        capture_output=True, text=True)
check(render.returncode == 0, f"render.sh exits 0: {render.stdout[-1000:]} {render.stderr[-2000:]}")
check("as surface" in render.stdout, f"render.sh drew the surfaces: {render.stdout[-500:]}")
for frame in range(3):
    png = os.path.join(out, "render", f"frame_{frame:05d}.png")
    check(os.path.exists(png), f"{png} written")
    if not os.path.exists(png):
        continue
    image = np.asarray(Image.open(png).convert("RGB")).astype(int)
    check(image.shape == (224, 400, 3), f"{png}: 400x224, got {image.shape[1]}x{image.shape[0]}")
    middle = image[56:168, 100:300].reshape(-1, 3)
    colours = len({tuple(p) for p in middle})
    white = np.sum(middle.min(axis=1) > 245)
    grey = np.sum((middle.max(axis=1) - middle.min(axis=1) < 12) & (middle[:, 0] > 60) & (middle[:, 0] < 200))
    reddish = np.sum(middle[:, 0] > middle[:, 2] + 40)
    bluish = np.sum(middle[:, 2] > middle[:, 0] + 40)
    check(colours > 50, f"{png}: not blank, {colours} colours in the middle")
    check(white < 0.9 * len(middle), f"{png}: drawn over the white background in the middle ({white} white pixels)")
    check(grey > 200, f"{png}: the grey ground drawn ({grey} grey pixels in the middle)")
    if frame > 0:  # landed: compressed (blue) or stretched (red) material, shaded
        check(reddish + bluish > 200, f"{png}: coloured material ({reddish} red, {bluish} blue pixels in the middle)")
movie = os.path.join(out, "render", "movie.mp4")
check(os.path.exists(movie) and os.path.getsize(movie) > 1000, f"{movie} written")
strip = os.path.join(out, "strip.png")
check(os.path.exists(strip) and Image.open(strip).size[0] == 500, f"{strip}: 500 pixels wide")
# A directory without frames is a one-line error, exit 2.
bad = subprocess.run([args.render, os.path.join(args.workdir, "no_such_dir")], capture_output=True, text=True)
check(bad.returncode == 2 and "no_such_dir" in bad.stderr, f"a missing directory exits 2: {bad.returncode} {bad.stderr}")
finish("render.sh: 3 surface renders of 400x224, a movie and a strip")
