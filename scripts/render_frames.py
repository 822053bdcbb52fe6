"""Renders viscompm frames to PNG with ParaView (run by scripts/render.sh under pvbatch).

Reads OUTPUT_DIR/frame_NNNNN.h5 (the particles, and the colliders' surfaces under /colliders when
the scene has any) and, for --style surface, OUTPUT_DIR/surface_NNNNN.obj (the particle surface
the run wrote with Output/Surface voxel size), and writes OUTPUT_DIR/render/frame_NNNNN.png.

Styles:
  spheres  every particle a shaded sphere coloured by the field
  surface  the particle surface (OpenVDB, written by the run), smoothed (VTK windowed sinc) and
           smooth-shaded, coloured by the field interpolated from the nearest particles
           (Gaussian kernel of two spacings)
  density  the particles splatted into a density field (Gaussian, one spacing) and volume-rendered
           in a sponge colour, as the thesis rendered its sponges
  auto     surface where the run wrote surfaces, else spheres (default)

The default colouring is det b^E (b^E = left_cauchy_green_elastic, (5.5)), centred at 1 as in
Figure 5.7: red above 1, blue below. Other fields: any /particles dataset (vectors and tensors by
their magnitude), or none (one cream colour). Colliders are grey translucent surfaces.

A bad option value, or a frame that cannot be read (cut short by a killed run or a full disk,
without the datasets a frame has), is one line on stderr naming the option or the file, exit 2
(doc/contracts.md).
"""
import argparse
import glob
import math
import os
import re
import sys

try:
    import h5py
    import numpy as np
    from paraview import simple
    from paraview.vtk.util import numpy_support
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    from vtkmodules.vtkFiltersCore import vtkWindowedSincPolyDataFilter
    from vtkmodules.vtkIOGeometry import vtkOBJReader
except ImportError as missing:
    sys.exit(f"render: needs {missing.name} (run under ParaView's pvbatch, as scripts/render.sh does; "
             "Debian: paraview python3-paraview python3-h5py)")

CREAM = [0.95, 0.9, 0.78]
SPONGE = [0.93, 0.78, 0.35]


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, not argparse's usage block
        self.exit(2, f"render: {message} (see scripts/render.sh --help)\n")


def fail(message):
    sys.stderr.write(f"render: {message}\n")
    sys.exit(2)


# The frame file being read, named when it turns out damaged (main).
reading = None


class Frame:
    """A frame file opened for reading, its datasets checked: `with Frame(path) as h5:`."""

    def __init__(self, path, field="none"):
        self.path, self.field = path, field

    def __enter__(self):
        global reading
        reading = self.path
        self.h5 = h5py.File(self.path, "r")
        p = self.h5.get("particles")
        if not isinstance(p, h5py.Group) or "position" not in p:
            raise KeyError("no /particles/position")
        n = p["position"].shape[0] if p["position"].ndim == 2 and p["position"].shape[1:] == (3,) else -1
        if n < 0:
            raise ValueError(f"/particles/position has shape {p['position'].shape}, not (n, 3)")
        needed = ["volume0"] + (["left_cauchy_green_elastic"] if self.field == "det_b_elastic" else [])
        for name in needed:
            if name not in p or p[name].shape[:1] != (n,):
                raise KeyError(f"no /particles/{name} of {n} rows")
        if "time" not in self.h5.attrs:
            raise KeyError("no 'time' attribute")
        return self.h5

    def __exit__(self, kind, value, traceback):
        global reading
        self.h5.close()
        if kind is None:
            reading = None
        return False


def positive_size(text):
    match = re.fullmatch(r"(\d+)x(\d+)", text.lower())
    if not match or int(match.group(1)) == 0 or int(match.group(2)) == 0:
        raise argparse.ArgumentTypeError(f"'{text}' is not WxH (e.g. 1280x720)")
    return int(match.group(1)), int(match.group(2))


def frame_list(text):
    if text in ("all", "last") or re.fullmatch(r"\d+(,\d+)*", text):
        return text
    raise argparse.ArgumentTypeError(f"'{text}' is not all, last or frame numbers separated by commas")


def point(text):
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(f"'{text}' is not X,Y,Z (three finite numbers)")
    return values


def finite(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number")
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"'{text}' is not a finite number")
    return value


def positive(text):
    value = finite(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"'{text}' is not positive")
    return value


def parse():
    ap = Parser(prog="render", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("output_dir")
    ap.add_argument("--field", default="det_b_elastic",
                    help="det_b_elastic (default), a /particles dataset such as velocity or material_id, or none")
    ap.add_argument("--style", default="auto", choices=["auto", "spheres", "surface", "density"])
    ap.add_argument("--size", default="1280x720", type=positive_size, help="image size WxH (default 1280x720)")
    ap.add_argument("--frames", default="all", type=frame_list, help="all (default), last, or frame numbers separated by commas")
    ap.add_argument("--range", nargs=2, type=finite, metavar=("LO", "HI"),
                    help="colour range (default: det_b_elastic 1 ± the 95th percentile of |det b^E - 1| in the "
                         "rendered frames)")
    ap.add_argument("--view", default="iso", choices=["iso", "x", "y", "z"], help="camera direction (default iso)")
    ap.add_argument("--azimuth", type=finite, default=0.0, help="turn the camera about the up axis [degrees]")
    ap.add_argument("--elevation", type=finite, default=0.0, help="raise the camera [degrees]")
    ap.add_argument("--zoom", type=positive, default=1.0, help="> 1 moves the camera closer (default 1)")
    ap.add_argument("--focus", type=point, help="X,Y,Z: the point the camera looks at (default the middle of the particles)")
    ap.add_argument("--clip", choices=["x", "y", "z"],
                    help="show only the particles below the middle of the particles' first frame along this axis "
                         "(a cut through the interior, e.g. the bullet's path in the sponge; spheres only)")
    return ap.parse_args()


def field_values(particles, field):
    n = particles["position"].shape[0]
    if field == "none":
        return np.zeros(n)
    if field == "det_b_elastic":
        b = particles["left_cauchy_green_elastic"][...]
        return np.linalg.det(b) if len(b) else np.zeros(0)
    if field not in particles:
        fail(f"--field: no particle field '{field}' (fields: det_b_elastic, none, {', '.join(particles.keys())})")
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


def smoothed_surface(path):
    """The run's particle surface (a union of spheres, bumpy at the particle spacing) read and
    smoothed by a windowed-sinc filter, which keeps the volume (Taubin's low-pass)."""
    reader = vtkOBJReader()
    reader.SetFileName(path)
    smooth = vtkWindowedSincPolyDataFilter()
    smooth.SetInputConnection(reader.GetOutputPort())
    smooth.SetNumberOfIterations(40)
    smooth.SetPassBand(0.01)
    smooth.NonManifoldSmoothingOn()
    smooth.NormalizeCoordinatesOn()
    smooth.Update()
    surface = vtkPolyData()
    surface.ShallowCopy(smooth.GetOutput())
    return surface


def producer(data):
    source = simple.PVTrivialProducer()
    source.GetClientSideObject().SetOutput(data)
    return source


def select_frames(args):
    if not os.path.isdir(args.output_dir):
        fail(f"{args.output_dir}: no such directory")
    files = sorted(f for f in glob.glob(os.path.join(args.output_dir, "frame_*.h5"))
                   if re.search(r"frame_(\d+)\.h5$", f))
    if not files:
        fail(f"{args.output_dir}: no frame_NNNNN.h5 files")
    numbered = {int(re.search(r"frame_(\d+)\.h5$", f).group(1)): f for f in files}
    frames = sorted(numbered)
    if args.frames == "last":
        frames = frames[-1:]
    elif args.frames != "all":
        wanted = {int(f) for f in args.frames.split(",")}
        frames = [f for f in frames if f in wanted]
        if not frames:
            fail(f"--frames: {args.output_dir} has none of the frames {args.frames}")
    return numbered, frames


def surface_file(output_dir, frame):
    return os.path.join(output_dir, f"surface_{frame:05d}.obj")


def scan(args, numbered, frames, kept):
    """One pass over the frames: the colour range, the particle spacing and the particles' extent
    (2nd to 98th percentile in each direction, so that a few strays do not move the camera)."""
    lo_hi, lows, highs, volume, deviations = [math.inf, -math.inf], [], [], [], []
    for f in frames:
        with Frame(numbered[f], args.field) as h5:
            p = h5["particles"]
            if p["position"].shape[0] == 0:
                continue
            x = p["position"][...]
            values = field_values(p, args.field)[kept(x)]
            x = x[kept(x)]
            if len(x) == 0:
                continue
            lows.append(np.percentile(x, 2, axis=0))
            highs.append(np.percentile(x, 98, axis=0))
            lo_hi = [min(lo_hi[0], values.min()), max(lo_hi[1], values.max())]
            deviations.append(np.percentile(np.abs(values - 1.0), 95))
            volume.append(np.median(p["volume0"][...]))
    if not volume:
        fail(f"{args.output_dir}: the frames hold no particles")
    if args.range:
        lo, hi = args.range
    elif args.field == "det_b_elastic":
        deviation = max(max(deviations), 1e-3)  # the 95th percentile: a few extremes do not wash it out
        lo, hi = 1.0 - deviation, 1.0 + deviation
    else:
        lo, hi = lo_hi if lo_hi[1] > lo_hi[0] else (lo_hi[0], lo_hi[0] + 1.0)
    spacing = float(np.median(volume)) ** (1.0 / 3.0)
    return (lo, hi), spacing, np.min(lows, axis=0), np.max(highs, axis=0)


def make_view(width, height):
    simple._DisableFirstRenderCameraReset()  # the camera is ours (place_camera)
    view = simple.CreateRenderView()
    view.ViewSize = [width, height]
    view.OrientationAxesVisibility = 0
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    view.Background = [1.0, 1.0, 1.0]
    return view


def place_camera(view, args, spacing, bounds_lo, bounds_hi):
    """Looks at the particles' extent (or --focus) from --view, turned by --azimuth and --elevation;
    called after the frame is shown, since showing the first object resets the camera."""
    centre = 0.5 * (bounds_lo + bounds_hi)
    if args.focus:
        centre = np.array(args.focus)
    extent = max(float(np.max(bounds_hi - bounds_lo)), 20 * spacing)
    direction = np.array({"iso": (0.7, 0.45, 1.0), "x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 1e-3), "z": (0.0, 0.0, 1.0)}[args.view])
    direction /= np.linalg.norm(direction)
    view.CameraFocalPoint = list(centre)
    view.CameraPosition = list(centre + 2.1 * extent / args.zoom * direction)
    view.CameraViewUp = [0.0, 0.0, 1.0] if args.view == "y" else [0.0, 1.0, 0.0]
    view.CameraViewAngle = 30
    camera = view.GetActiveCamera()
    camera.Azimuth(args.azimuth)
    camera.Elevation(args.elevation)
    camera.OrthogonalizeViewUp()


def colour_display(display, view, args, lut, lo, hi):
    if args.field == "none":
        display.ColorArrayName = ["POINTS", ""]
        display.AmbientColor = display.DiffuseColor = CREAM
        return
    simple.ColorBy(display, ("POINTS", args.field))
    display.LookupTable = lut
    lut.RescaleTransferFunction(lo, hi)
    display.SetScalarBarVisibility(view, True)
    bar = simple.GetScalarBar(lut, view)
    bar.Title = "det b^E" if args.field == "det_b_elastic" else args.field
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0.1, 0.1, 0.1]


def show_material(style, output_dir, frame, particles, args, view, spacing, lut, lo, hi):
    """Shows the frame's material in the given style; returns the proxies to delete afterwards."""
    if style == "spheres":
        display = simple.Show(particles, view)
        display.SetRepresentationType("Point Gaussian")
        display.GaussianRadius = 0.55 * spacing
        display.ShaderPreset = "Sphere"
        colour_display(display, view, args, lut, lo, hi)
        return []
    if style == "surface":
        reader = producer(smoothed_surface(surface_file(output_dir, frame)))
        interpolated = simple.PointDatasetInterpolator(Input=particles, Source=reader)
        interpolated.Kernel = "GaussianKernel"
        interpolated.Kernel.KernelFootprint = "Radius"
        interpolated.Kernel.Radius = 2.0 * spacing
        interpolated.NullPointsStrategy = "Closest Point"
        normals = simple.GenerateSurfaceNormals(Input=interpolated)
        normals.Splitting = 0
        display = simple.Show(normals, view)
        display.Interpolation = "Gouraud"
        display.Specular = 0.25
        display.SpecularPower = 40.0
        colour_display(display, view, args, lut, lo, hi)
        return [normals, interpolated, reader]
    density = simple.GaussianResampling(Input=particles)
    density.ResampleField = ["POINTS", "ignore arrays"]
    density.GaussianSplatRadius = 1.5 * spacing
    density.ScaleSplats = 0
    density.SplatAccumulationMode = "Sum"
    bounds = particles.GetDataInformation().GetBounds()
    cells = [max(8, int((bounds[2 * i + 1] - bounds[2 * i]) / (0.5 * spacing)) + 4) for i in range(3)]
    density.ResamplingGrid = [min(c, 320) for c in cells]
    density.ExtenttoResample = [bounds[0] - 2 * spacing, bounds[1] + 2 * spacing, bounds[2] - 2 * spacing,
                                bounds[3] + 2 * spacing, bounds[4] - 2 * spacing, bounds[5] + 2 * spacing]
    display = simple.Show(density, view)
    display.SetRepresentationType("Volume")
    simple.ColorBy(display, ("POINTS", "SplatterValues"))
    colours = simple.GetColorTransferFunction("SplatterValues")
    colours.RGBPoints = [0.0] + SPONGE + [1.0] + [0.75 * c for c in SPONGE]
    opacity = simple.GetOpacityTransferFunction("SplatterValues")
    opacity.Points = [0.0, 0.0, 0.5, 0.0, 0.3, 0.0, 0.5, 0.0, 0.6, 0.1, 0.5, 0.0, 1.0, 0.5, 0.5, 0.0]
    colours.RescaleTransferFunction(0.0, 1.0)
    opacity.RescaleTransferFunction(0.0, 1.0)
    display.ScalarOpacityFunction = opacity
    display.ScalarOpacityUnitDistance = 4.0 * spacing  # translucent: tears and thin parts show
    display.SetScalarBarVisibility(view, False)
    return [density]


def render_frame(args, numbered, frame, style, view, kept, spacing, lut, lo_hi, bounds, out_dir, size):
    with Frame(numbered[frame], args.field) as h5:
        p = h5["particles"]
        x = p["position"][...]
        particles = producer(points_polydata(x[kept(x)], field_values(p, args.field)[kept(x)], args.field))
        frame_style = style
        if frame_style == "surface" and (len(x) == 0 or not os.path.exists(surface_file(args.output_dir, frame))):
            frame_style = "spheres"   # frame 0 of an emitting scene: no material, no surface
        shown = show_material(frame_style, args.output_dir, frame, particles, args, view, spacing, lut, *lo_hi)
        shown.append(particles)
        if "colliders" in h5:
            c = h5["colliders"]
            colliders = producer(surface_polydata(c["vertices"][...], c["triangles"][...]))
            shown.append(colliders)
            cd = simple.Show(colliders, view)
            cd.ColorArrayName = ["POINTS", ""]
            cd.AmbientColor = cd.DiffuseColor = [0.5, 0.5, 0.55]
            cd.Opacity = 0.5
        label = simple.Text(Text=f"t = {float(h5.attrs['time']):.3f} s")
        shown.append(label)
        ld = simple.Show(label, view)
        ld.WindowLocation = "Upper Left Corner"
        ld.FontSize = 28
        ld.Color = [0.1, 0.1, 0.1]
        place_camera(view, args, spacing, *bounds)
        simple.Render(view)
        simple.SaveScreenshot(os.path.join(out_dir, f"frame_{frame:05d}.png"), view, ImageResolution=list(size))
        for s in shown:
            simple.Hide(s, view)
        for s in shown:
            simple.Delete(s)


def main():
    args = parse()
    width, height = args.size
    numbered, frames = select_frames(args)
    style = args.style
    if style == "auto":
        style = "surface" if any(os.path.exists(surface_file(args.output_dir, f)) for f in frames) else "spheres"
    if style == "surface" and not any(os.path.exists(surface_file(args.output_dir, f)) for f in frames):
        fail(f"{args.output_dir}: no surface_NNNNN.obj (run with Output/Surface voxel size > 0)")
    out_dir = os.path.join(args.output_dir, "render")
    os.makedirs(out_dir, exist_ok=True)

    axis = {"x": 0, "y": 1, "z": 2}.get(args.clip)
    cut = None
    if axis is not None:
        with Frame(numbered[frames[0]]) as h5:
            x = h5["particles/position"][...]
            cut = 0.5 * (x[:, axis].min() + x[:, axis].max()) if len(x) else 0.0

    def kept(x):
        return np.ones(len(x), dtype=bool) if cut is None else x[:, axis] <= cut

    (lo, hi), spacing, bounds_lo, bounds_hi = scan(args, numbered, frames, kept)
    view = make_view(width, height)
    lut = simple.GetColorTransferFunction(args.field)
    lut.ApplyPreset("Cool to Warm", True)
    lut.RescaleTransferFunction(lo, hi)
    if hasattr(lut, "AutomaticRescaleRangeMode"):
        lut.AutomaticRescaleRangeMode = "Never"
    for f in frames:
        render_frame(args, numbered, f, style, view, kept, spacing, lut, (lo, hi), (bounds_lo, bounds_hi), out_dir,
                     (width, height))
    print(f"render: {len(frames)} frame(s) of {args.output_dir} as {style}, {args.field} in [{lo:.4g}, {hi:.4g}] -> "
          f"{out_dir}/frame_NNNNN.png ({width}x{height})")


if __name__ == "__main__":
    try:
        main()
    except (OSError, KeyError, ValueError, TypeError, IndexError, AttributeError) as e:
        if reading is None:
            raise
        # h5py's messages name HDF5's view of the damage ("truncated file: eof = ..."); one line.
        reason = e.args[0] if isinstance(e, KeyError) and e.args else str(e)
        fail(f"{reading}: cannot read the frame ({' '.join(str(reason).split())})")
