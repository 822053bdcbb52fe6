#!/usr/bin/env python3
"""The scripts' contract (doc/contracts.md, issue 24): every script under scripts/ (but
measure_scenes.py and showcase.sh, tested with their own tests) answers a missing or bad argument,
a missing directory and a damaged input file (a frame cut short as by a killed run or a full disk,
a CSV cut short or without its columns) with one line on stderr naming the file or the option and
a non-zero exit (2), never a Python traceback or a bare shell error. The damaged files are the
fuzzer's: files cut at seeded random bytes, emptied, or missing what they must hold. Good inputs
still work (exit 0). The render.sh cases need ParaView's pvbatch and Xvfb; without them they are
skipped (scripts/setup.sh installs them)."""
import argparse
import csv
import os
import random
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, finish  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--scripts", required=True, help="the scripts/ folder")
parser.add_argument("--bench", help="the bench/ folder: its programs answer --help the same way")
parser.add_argument("--workdir", required=True)
parser.add_argument("--seed", type=int, default=24)
args = parser.parse_args()
scripts = os.path.abspath(args.scripts)
work = os.path.abspath(args.workdir)
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
rng = random.Random(args.seed)
python = sys.executable
render_available = shutil.which("pvbatch") is not None and shutil.which("Xvfb") is not None
counted = {"cases": 0, "skipped": 0}

# What a contract answer must not contain: a Python traceback, bash's own errors.
FORBIDDEN = re.compile(r"Traceback|unbound variable|command not found|syntax error|\.sh: line \d+: ")


def run(command, env=None, timeout=120):
    environment = dict(os.environ, **(env or {}))
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=environment, cwd=work)


def bad(what, command, named, env=None, allow_success=False):
    """`command` must exit non-zero (2) with exactly one line on stderr that names `named`, and no
    traceback or shell error; with allow_success, exit 0 is accepted too (a cut that left a whole file)."""
    counted["cases"] += 1
    result = run(command, env)
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    if allow_success and result.returncode == 0:
        check(not FORBIDDEN.search(result.stderr), f"{what}: exit 0 without a traceback: {result.stderr[-800:]}")
        print(f"ok   {what}: exit 0 (the cut left a usable file)")
        return
    check(result.returncode == 2, f"{what}: exit 2, got {result.returncode}: {result.stderr[-1500:]}")
    check(len(lines) == 1, f"{what}: one line on stderr, got {len(lines)}: {result.stderr[-1500:]}")
    check(not FORBIDDEN.search(result.stderr), f"{what}: no traceback or shell error: {result.stderr[-1500:]}")
    check(bool(lines) and named in lines[0], f"{what}: the line names '{named}': {lines[:3]}")
    print(f"{'ok  ' if result.returncode == 2 and len(lines) == 1 else 'FAIL'} {what}: "
          f"{lines[0] if lines else '(no stderr)'}")


def good(what, command, env=None, timeout=120):
    counted["cases"] += 1
    result = run(command, env, timeout)
    check(result.returncode == 0, f"{what}: exit 0, got {result.returncode}: {result.stderr[-1500:]}")
    print(f"{'ok  ' if result.returncode == 0 else 'FAIL'} {what}")


def write(path, data, mode="w"):
    with open(path, mode) as f:
        f.write(data)
    return path


def cuts(data, count):
    """`count` seeded cut positions inside `data` (the fuzzer's "cut at byte k"), the first at 0."""
    return [0] + sorted(rng.sample(range(1, len(data) - 1), count - 1))


a_file = write(os.path.join(work, "a_file"), "not a directory\n")
missing = os.path.join(work, "no_such_dir")

# ---------------------------------------------------------------------------------------------
# check_layers.py: a root that is missing or not a source tree, an unknown option.
check_layers = [python, os.path.join(scripts, "check_layers.py")]
bad("check_layers.py: a missing root", check_layers + [missing], missing)
bad("check_layers.py: a root that is no source tree", check_layers + [work], work)
bad("check_layers.py: an unknown option", check_layers + ["--bogus"], "--bogus")
good("check_layers.py: the source tree", check_layers + [os.path.dirname(scripts)])

# make_meshes.py: an output directory that cannot be made, an extra argument.
make_meshes = [python, os.path.join(scripts, "make_meshes.py")]
bad("make_meshes.py: a directory under a file", make_meshes + [os.path.join(a_file, "meshes")],
    os.path.join(a_file, "meshes"))
bad("make_meshes.py: an extra argument", make_meshes + [os.path.join(work, "m"), "extra"], "extra")
bad("make_meshes.py: an unknown option", make_meshes + ["--bogus"], "--bogus")

# plot_steps.py and plot_study.py: arguments, missing files, damaged CSVs, unwritable plots.
steps_header = ("configuration,solver,frames,steps,newton_iterations,cg_iterations,assemblies,preconditioner_setups,"
                "graph_builds,retries,wall_seconds,seconds_per_frame,operator_seconds,preconditioner_seconds,cg_seconds,"
                "line_search_seconds,ranks,cell_size")
steps_text = steps_header + "\n" + "".join(
    f"config {k},solver.xml,2,6,{10 + k},{120 + k},8,4,1,0,{3.0 + k},{1.5 + k},0.2,0.1,0.8,0.1,2,0.06\n" for k in range(3))
study_header = ("problem,resolution,dofs,nonzeros,ranks,preconditioner,setup_seconds,solve_seconds,iterations,"
                "converged")
study_text = study_header + "\n" + "".join(
    f"sponge dt={dt},{h},{dofs},{dofs * 20},1,{p},0.01,0.{k + 1},{30 + k},{int(k != 1)}\n"
    for k, (p, dt, h, dofs) in enumerate([("Jacobi", 0.01, 0.06, 3000), ("Jacobi", 0.01, 0.04, 9000),
                                          ("MueLu", 0.01, 0.06, 3000), ("MueLu", 0.02, 0.04, 9000)]))
for name, text in (("plot_steps.py", steps_text), ("plot_study.py", study_text)):
    plot = [python, os.path.join(scripts, name)]
    good_csv = write(os.path.join(work, name + ".csv"), text)
    png = os.path.join(work, name + ".png")
    good(f"{name}: a good CSV", plot + [good_csv, png])
    check(os.path.exists(png) and os.path.getsize(png) > 1000, f"{name}: {png} written")
    bad(f"{name}: no arguments", plot, "the following arguments are required")
    bad(f"{name}: no PNG argument", plot + [good_csv], "png")
    bad(f"{name}: an unknown option", plot + [good_csv, png, "--bogus"], "--bogus")
    bad(f"{name}: a missing CSV", plot + [os.path.join(missing, "x.csv"), png], os.path.join(missing, "x.csv"))
    bad(f"{name}: a directory for a CSV", plot + [work, png], work)
    bad(f"{name}: a PNG in a missing directory", plot + [good_csv, os.path.join(missing, "x.png")],
        os.path.join(missing, "x.png"))
    lines = text.splitlines()
    no_column = write(os.path.join(work, name + "_no_column.csv"),
                      "\n".join(",".join(line.split(",")[:-3]) for line in lines) + "\n")
    bad(f"{name}: a CSV without its last columns", plot + [no_column, png], no_column)
    word = write(os.path.join(work, name + "_word.csv"), text.replace(",0.1,", ",abc,", 1))
    bad(f"{name}: a CSV with a word for a number", plot + [word, png], word)
    binary = write(os.path.join(work, name + "_binary.csv"), bytes(range(256)) * 8, "wb")
    bad(f"{name}: a binary file for a CSV", plot + [binary, png], binary)
    for cut in cuts(text, 5):
        damaged = write(os.path.join(work, f"{name}_cut_{cut}.csv"), text[:cut])
        # A cut within the header or a row's numbers is certainly bad; one within the last
        # text column (or at a line's end) may leave a usable file.
        bad(f"{name}: a CSV cut at byte {cut}", plot + [damaged, png], damaged, allow_success=cut >= len(lines[0]) + 1)

# ---------------------------------------------------------------------------------------------
# setup.sh, test.sh, demo.sh: what they check before anything is installed or built.
setup, test_sh, demo = (os.path.join(scripts, s) for s in ("setup.sh", "test.sh", "demo.sh"))
bad("setup.sh: an argument", ["bash", setup, "--bogus"], "--bogus")
bad("setup.sh: VISCOMPM_JOBS not a number", ["bash", setup], "VISCOMPM_JOBS", env={"VISCOMPM_JOBS": "two"})
bad("setup.sh: VISCOMPM_BUILD_DIR under a file", ["bash", setup], "VISCOMPM_BUILD_DIR",
    env={"VISCOMPM_BUILD_DIR": os.path.join(a_file, "build")})
bad("test.sh: a misspelt option", ["bash", test_sh, "--sanitise"], "--sanitise")
bad("test.sh: an unknown short option", ["bash", test_sh, "-Z"], "-Z")
bad("test.sh: VISCOMPM_JOBS not a number", ["bash", test_sh, "-L", "unit"], "VISCOMPM_JOBS", env={"VISCOMPM_JOBS": "0"})
bad("demo.sh: VISCOMPM_RANKS not a number", ["bash", demo], "VISCOMPM_RANKS", env={"VISCOMPM_RANKS": "many"})
bad("demo.sh: VISCOMPM_JOBS not a number", ["bash", demo], "VISCOMPM_JOBS", env={"VISCOMPM_JOBS": "-1"})

# ---------------------------------------------------------------------------------------------
# render.sh (and render_frames.py under pvbatch): options, directories, damaged frames.
render = ["bash", os.path.join(scripts, "render.sh")]
bad("render.sh: no arguments", render, "OUTPUT_DIR")
bad("render.sh: a missing directory", render + [missing], missing)
bad("render.sh: an option for OUTPUT_DIR", render + ["--fps", "2"], "--fps")
frames = os.path.join(work, "frames")
os.makedirs(frames)
bad("render.sh: --fps without a value", render + [frames, "--fps"], "--fps")
bad("render.sh: --fps that is no number", render + [frames, "--fps", "fast"], "--fps")
bad("render.sh: --zoom without a value", render + [frames, "--zoom"], "--zoom")
bad("render.sh: --range with one value", render + [frames, "--range", "1"], "--range")
bad("render.sh: --strip without --strip-file", render + [frames, "--strip", "1,2"], "--strip")
bad("render.sh: --strip that is no frame list", render + [frames, "--strip", "a,b", "--strip-file", "s.png"], "--strip")
bad("render.sh: an unknown option", render + [frames, "--bogus"], "--bogus")


def frame(path, n=300, time=0.0):
    """A frame as viscompm writes it, as far as render_frames.py reads it: a ball of particles."""
    r = np.random.default_rng(int(time * 100))
    x = r.normal(0.5, 0.08, size=(n, 3))
    with h5py.File(path, "w") as f:
        f.attrs["time"] = time
        p = f.create_group("particles")
        p["position"] = x
        p["volume0"] = np.full(n, 1e-5)
        p["velocity"] = np.zeros((n, 3))
        p["left_cauchy_green_elastic"] = np.tile(np.eye(3), (n, 1, 1)) * (1.0 + 0.01 * r.standard_normal((n, 1, 1)))
    return path


if not render_available:
    print("SKIP: the render.sh cases on frames (pvbatch or Xvfb is not installed; scripts/setup.sh installs them)")
    counted["skipped"] += 1
else:
    good_frames = os.path.join(work, "good_frames")
    os.makedirs(good_frames)
    for k in range(2):
        frame(os.path.join(good_frames, f"frame_{k:05d}.h5"), time=0.1 * k)
    good("render.sh: good frames", render + [good_frames, "--style", "spheres", "--size", "64x48", "--no-movie"],
         timeout=300)
    check(os.path.exists(os.path.join(good_frames, "render", "frame_00001.png")), "render.sh: frame_00001.png written")
    bad("render.sh: an empty directory", render + [frames, "--no-movie"], frames)
    bad("render.sh: --size that is no size", render + [good_frames, "--size", "big"], "--size")
    bad("render.sh: --frames that is no list", render + [good_frames, "--frames", "1;2"], "--frames")
    bad("render.sh: --focus of two numbers", render + [good_frames, "--focus", "1,2"], "--focus")
    bad("render.sh: --zoom of zero", render + [good_frames, "--zoom", "0"], "--zoom")
    bad("render.sh: a field the frames lack", render + [good_frames, "--field", "pressure"], "--field")
    intact = open(frame(os.path.join(work, "intact.h5")), "rb").read()

    def damaged(name, data=None, build=None):
        """A directory with a good frame 0 and a damaged frame 1; returns (directory, frame 1)."""
        directory = os.path.join(work, name)
        os.makedirs(directory)
        frame(os.path.join(directory, "frame_00000.h5"))
        path = os.path.join(directory, "frame_00001.h5")
        if build:
            build(path)
        else:
            write(path, data, "wb")
        return directory, path

    def without_volume(path):
        frame(path)
        with h5py.File(path, "a") as f:
            del f["particles/volume0"]

    def flat_positions(path):
        with h5py.File(path, "w") as f:
            f.attrs["time"] = 0.0
            f.create_dataset("particles/position", data=np.zeros((4, 2)))

    cases = [(f"a frame cut at byte {cut}", f"cut_{cut}", intact[:cut], None) for cut in cuts(intact, 4)]
    cases += [("a frame of text", "text", b"an earlier frame\n", None),
              ("a frame with a byte flipped in its superblock", "flipped", intact[:8] + bytes([intact[8] ^ 0xFF]) + intact[9:], None),
              ("a frame without particles", "no_particles", None, lambda p: h5py.File(p, "w").close()),
              ("a frame without volume0", "no_volume", None, without_volume),
              ("a frame whose positions are not (n, 3)", "bad_shape", None, flat_positions)]
    for what, name, data, build in cases:
        directory, path = damaged(name, data, build)
        bad(f"render.sh: {what}", render + [directory, "--style", "spheres", "--size", "64x48", "--no-movie"], path)

# ---------------------------------------------------------------------------------------------
# Every program under scripts/ (and bench/) runs by its own name, as the docs write it (scripts/NAME --help):
# executable, its interpreter the one scripts/setup.sh installs the modules for (Debian's
# /usr/bin/python3, not the first python3 on PATH), and --help answered with its usage, exit 0,
# nothing built (a build directory given in the environment is not made).
not_built = os.path.join(work, "no_build_for_help")
programs = [os.path.join(scripts, name) for name in sorted(os.listdir(scripts))]
if args.bench:
    programs += [os.path.join(os.path.abspath(args.bench), name) for name in sorted(os.listdir(args.bench))]
for path in programs:
    name = os.path.relpath(path, os.path.dirname(scripts))
    if not os.path.isfile(path):
        continue
    with open(path, "rb") as f:
        first_line = f.readline().decode(errors="replace").strip()
    if not first_line.startswith("#!"):
        continue  # a module run by another program (render_frames.py under pvbatch)
    counted["cases"] += 1
    check(os.access(path, os.X_OK), f"{name}: executable (it starts with '{first_line}')")
    if name.endswith(".py"):
        check(first_line == "#!/usr/bin/python3", f"{name}: runs under /usr/bin/python3, not '{first_line}'")
    result = run([path, "--help"], env={"VISCOMPM_BUILD_DIR": not_built}, timeout=60)
    exits_0, usage, nothing_built = (result.returncode == 0, len(result.stdout.strip().splitlines()) >= 2,
                                     not os.path.exists(not_built))
    check(exits_0, f"{name} --help: exit 0, got {result.returncode}: {result.stderr[-800:]}")
    check(usage, f"{name} --help: its usage on stdout: {result.stdout[-400:]}")
    check(nothing_built, f"{name} --help: nothing built")
    print(f"{'ok  ' if exits_0 and usage and nothing_built else 'FAIL'} {name} --help by its own name")

finish(f"{counted['cases']} script cases answered as the contract says"
       + (" (render.sh on frames skipped)" if counted["skipped"] else ""))
