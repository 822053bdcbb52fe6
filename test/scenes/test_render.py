#!/usr/bin/env python3
"""scripts/render.sh turns a tiny run into one PNG per frame of the requested size, showing
particles coloured around det b^E = 1 and the colliders, and a movie. Skips (exit 77) only when
ParaView's pvbatch is not installed (scripts/setup.sh installs it)."""
import os
import shutil
import struct
import subprocess
import sys
import zlib

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, finish, program_arguments  # noqa: E402

args = program_arguments("viscompm", "render").parse_args()

if shutil.which("pvbatch") is None or shutil.which("Xvfb") is None:
    print("SKIP: pvbatch or Xvfb is not installed (scripts/setup.sh installs paraview and xvfb)")
    sys.exit(77)


def read_png(path):
    """(width, height, rows of RGB bytes) of an 8-bit RGB or RGBA PNG."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, width = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        chunk = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", chunk[:10])
            channels = {2: 3, 6: 4}[colour]
        elif kind == b"IDAT":
            idat += chunk
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = previous[i]
            c = previous[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * channels:x * channels + 3]) for x in range(width)])
        previous = line
    return width, height, rows


out = os.path.join(args.workdir, "run")
shutil.rmtree(out, ignore_errors=True)
run = subprocess.run([args.viscompm, os.path.join(args.inputs, "scenes", "shooting_sponge.xml"), "--output", out,
                      "--frames", "2", "--set", "Grid/Cell size=0.06", "--set", "Simulation/Frame rate=60"],
                     capture_output=True, text=True)
check(run.returncode == 0, f"the run exits 0: {run.stderr[-1000:]}")
render = subprocess.run([args.render, out, "--size", "320x180", "--fps", "2"], capture_output=True, text=True)
check(render.returncode == 0, f"render.sh exits 0: {render.stdout[-1000:]} {render.stderr[-2000:]}")
for frame in range(3):
    png = os.path.join(out, "render", f"frame_{frame:05d}.png")
    check(os.path.exists(png), f"{png} written")
    if not os.path.exists(png):
        continue
    width, height, rows = read_png(png)
    check((width, height) == (320, 180), f"{png}: 320x180, got {width}x{height}")
    pixels = [p for row in rows for p in row]
    white = sum(1 for p in pixels if min(p) > 245)
    reddish = sum(1 for p in pixels if p[0] > p[2] + 40)
    bluish = sum(1 for p in pixels if p[2] > p[0] + 40)
    grey = sum(1 for p in pixels if max(p) - min(p) < 12 and 60 < p[0] < 200)
    check(white > 0.3 * len(pixels), f"{png}: a white background ({white} white pixels)")
    check(reddish + bluish > 500, f"{png}: coloured particles ({reddish} red, {bluish} blue pixels)")
    check(grey > 200, f"{png}: grey colliders ({grey} grey pixels)")
movie = os.path.join(out, "render", "movie.mp4")
check(os.path.exists(movie) and os.path.getsize(movie) > 1000, f"{movie} written")
# A directory without frames is a one-line error, exit 2.
bad = subprocess.run([args.render, os.path.join(args.workdir, "no_such_dir")], capture_output=True, text=True)
check(bad.returncode == 2 and "no_such_dir" in bad.stderr, f"a missing directory exits 2: {bad.returncode} {bad.stderr}")
finish("render.sh: 3 frames of 320x180 and a movie")
