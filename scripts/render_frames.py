"""Renders viscompm frames to PNG with ParaView (run by scripts/render.sh under pvbatch).

Reads OUTPUT_DIR/frame_NNNNN.h5 (the particles, and the colliders' surfaces under /colliders when
the scene has any), draws the particles as spheres coloured by a field and the colliders as grey
surfaces, and writes OUTPUT_DIR/render/frame_NNNNN.png for each frame.

The default colouring is det b^E (b^E = left_cauchy_green_elastic, (5.5)), centred at 1 as in
Figure 5.7: red above 1, blue below. Other fields: any /particles dataset; vectors and tensors are
coloured by their magnitude.
"""
import argparse
import glob
import math
import os
import re
import sys

import h5py
import numpy as np
from paraview import simple
from paraview.vtk.util import numpy_support
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData


def parse():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("output_dir")
    ap.add_argument("--field", default="det_b_elastic",
                    help="det_b_elastic (default), or a /particles dataset such as velocity or material_id")
    ap.add_argument("--size", default="640x360", help="image size WxH (default 640x360)")
    ap.add_argument("--frames", default="all", help="all (default), last, or frame numbers separated by commas")
    ap.add_argument("--range", nargs=2, type=float, metavar=("LO", "HI"),
                    help="colour range (default: det_b_elastic 1 ± its largest deviation in the rendered frames)")
    ap.add_argument("--view", default="iso", choices=["iso", "x", "y", "z"], help="camera direction (default iso)")
    ap.add_argument("--clip", choices=["x", "y", "z"],
                    help="show only the particles below the middle of the particles' first frame along this axis "
                         "(a cut through the interior, e.g. the bullet's path in the sponge)")
    return ap.parse_args()


def field_values(particles, field):
    if field == "det_b_elastic":
        b = particles["left_cauchy_green_elastic"][...]
        return np.linalg.det(b) if len(b) else np.zeros(0)
    if field not in particles:
        sys.exit(f"render: no particle field '{field}' (fields: det_b_elastic, {', '.join(particles.keys())})")
    v = particles[field][...].astype(np.float64)
    return np.linalg.norm(v.reshape(len(v), -1), axis=1) if v.ndim > 1 else v


def points_polydata(positions, values, name):
    poly = vtkPolyData()
    points = vtkPoints()
    points.SetData(numpy_support.numpy_to_vtk(np.ascontiguousarray(positions, dtype=np.float64), deep=True))
    poly.SetPoints(points)
    verts = vtkCellArray()
    n = len(positions)
    connectivity = np.column_stack([np.ones(n, dtype=np.int64), np.arange(n, dtype=np.int64)]).ravel()
    verts.SetCells(n, numpy_support.numpy_to_vtkIdTypeArray(connectivity, deep=True))
    poly.SetVerts(verts)
    array = numpy_support.numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float64), deep=True)
    array.SetName(name)
    poly.GetPointData().AddArray(array)
    return poly


def surface_polydata(vertices, triangles):
    poly = vtkPolyData()
    points = vtkPoints()
    points.SetData(numpy_support.numpy_to_vtk(np.ascontiguousarray(vertices, dtype=np.float64), deep=True))
    poly.SetPoints(points)
    cells = vtkCellArray()
    m = len(triangles)
    connectivity = np.column_stack([np.full(m, 3, dtype=np.int64), triangles.astype(np.int64)]).ravel()
    cells.SetCells(m, numpy_support.numpy_to_vtkIdTypeArray(connectivity, deep=True))
    poly.SetPolys(cells)
    return poly


def producer(data):
    source = simple.PVTrivialProducer()
    source.GetClientSideObject().SetOutput(data)
    return source


def main():
    args = parse()
    width, height = (int(v) for v in args.size.lower().split("x"))
    files = sorted(glob.glob(os.path.join(args.output_dir, "frame_*.h5")))
    if not files:
        sys.exit(f"render: {args.output_dir}: no frame_NNNNN.h5 files")
    numbered = {int(re.search(r"frame_(\d+)\.h5$", f).group(1)): f for f in files}
    frames = sorted(numbered)
    if args.frames == "last":
        frames = frames[-1:]
    elif args.frames != "all":
        wanted = {int(f) for f in args.frames.split(",")}
        frames = [f for f in frames if f in wanted]
    out_dir = os.path.join(args.output_dir, "render")
    os.makedirs(out_dir, exist_ok=True)

    axis = {"x": 0, "y": 1, "z": 2}.get(args.clip)
    cut = None
    if axis is not None:
        with h5py.File(numbered[frames[0]], "r") as h5:
            x = h5["particles/position"][...]
            cut = 0.5 * (x[:, axis].min() + x[:, axis].max()) if len(x) else 0.0

    def kept(x):
        return np.ones(len(x), dtype=bool) if cut is None else x[:, axis] <= cut

    # One pass for the colour range, the particle size and the camera.
    lo_hi, bounds_lo, bounds_hi, volume = [math.inf, -math.inf], np.full(3, math.inf), np.full(3, -math.inf), []
    for f in frames:
        with h5py.File(numbered[f], "r") as h5:
            p = h5["particles"]
            if p["position"].shape[0] == 0:
                continue
            x = p["position"][...]
            values = field_values(p, args.field)[kept(x)]
            x = x[kept(x)]
            if len(x) == 0:
                continue
            bounds_lo, bounds_hi = np.minimum(bounds_lo, x.min(axis=0)), np.maximum(bounds_hi, x.max(axis=0))
            lo_hi = [min(lo_hi[0], values.min()), max(lo_hi[1], values.max())]
            volume.append(np.median(p["volume0"][...]))
    if not volume:
        sys.exit("render: the frames hold no particles")
    if args.range:
        lo, hi = args.range
    elif args.field == "det_b_elastic":
        deviation = max(abs(lo_hi[0] - 1.0), abs(lo_hi[1] - 1.0), 1e-3)
        lo, hi = 1.0 - deviation, 1.0 + deviation
    else:
        lo, hi = lo_hi if lo_hi[1] > lo_hi[0] else (lo_hi[0], lo_hi[0] + 1.0)
    radius = 0.55 * float(np.median(volume)) ** (1.0 / 3.0)

    view = simple.CreateRenderView()
    view.ViewSize = [width, height]
    view.OrientationAxesVisibility = 0
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    view.Background = [1.0, 1.0, 1.0]
    centre = 0.5 * (bounds_lo + bounds_hi)
    extent = max(float(np.max(bounds_hi - bounds_lo)), 20 * radius)
    direction = np.array({"iso": (0.7, 0.45, 1.0), "x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 1e-3), "z": (0.0, 0.0, 1.0)}[args.view])
    direction /= np.linalg.norm(direction)
    view.CameraFocalPoint = list(centre)
    view.CameraPosition = list(centre + 2.1 * extent * direction)
    view.CameraViewUp = [0.0, 0.0, 1.0] if args.view == "y" else [0.0, 1.0, 0.0]
    view.CameraViewAngle = 30

    lut = simple.GetColorTransferFunction(args.field)
    lut.ApplyPreset("Cool to Warm", True)
    lut.RescaleTransferFunction(lo, hi)
    if hasattr(lut, "AutomaticRescaleRangeMode"):
        lut.AutomaticRescaleRangeMode = "Never"

    for f in frames:
        with h5py.File(numbered[f], "r") as h5:
            p = h5["particles"]
            x = p["position"][...]
            particles = producer(points_polydata(x[kept(x)], field_values(p, args.field)[kept(x)], args.field))
            shown = [particles]
            display = simple.Show(particles, view)
            display.SetRepresentationType("Point Gaussian")
            display.GaussianRadius = radius
            display.ShaderPreset = "Sphere"
            simple.ColorBy(display, ("POINTS", args.field))
            display.LookupTable = lut
            lut.RescaleTransferFunction(lo, hi)
            display.SetScalarBarVisibility(view, True)
            bar = simple.GetScalarBar(lut, view)
            bar.Title = args.field
            bar.ComponentTitle = ""
            bar.TitleColor = bar.LabelColor = [0.1, 0.1, 0.1]
            if "colliders" in h5:
                c = h5["colliders"]
                colliders = producer(surface_polydata(c["vertices"][...], c["triangles"][...]))
                shown.append(colliders)
                cd = simple.Show(colliders, view)
                cd.ColorArrayName = ["POINTS", ""]
                cd.AmbientColor = cd.DiffuseColor = [0.5, 0.5, 0.55]
                cd.Opacity = 0.5
            simple.Render(view)
            simple.SaveScreenshot(os.path.join(out_dir, f"frame_{f:05d}.png"), view, ImageResolution=[width, height])
            for s in shown:
                simple.Hide(s, view)
                simple.Delete(s)
    print(f"render: {len(frames)} frame(s) of {args.output_dir}, {args.field} in [{lo:.4g}, {hi:.4g}] -> "
          f"{out_dir}/frame_NNNNN.png ({width}x{height})")


if __name__ == "__main__":
    main()
