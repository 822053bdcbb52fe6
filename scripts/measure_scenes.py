#!/usr/bin/python3
"""Measures, from a run's frames, the behaviour each paper scene (thesis §5.6) is about.

Usage: scripts/measure_scenes.py OUTPUT_DIR [--scene NAME] [--scene-file XML] [--json FILE]

NAME is one of the scenes of inputs/scenes/paper/ (default: OUTPUT_DIR's last folder name). The
scene's geometry (nozzle, belt, bullet, grips, ground) is read from XML (default
inputs/scenes/paper/showcase/NAME.xml); --set overrides of a run are not seen, so pass the scene
file the run used. The frames are read with h5py; connected components and neighbour pairs come
from scipy (cKDTree, csgraph). Bad input (an option, a missing directory or scene file, a damaged
frame) ends it with one line on stderr naming what is wrong and exit status 2.

What is measured (doc/scenes.md, "Measured behaviour"):
  weissenberg_sweep  per ball (Wi): lowest height, the rebound (highest top after the lowest), final
                     height / width; both expected to grow with Wi (Figure 5.4)
  viennetta          folds laid on the belt: the landing position of the stream, by emission time,
                     swings back and forth; its swings (reversals), period and wavelength (belt
                     speed x period), and the crests of the deposit's top along the belt (Fig. 5.5)
  shaving_foam,      the stream laid on the ground: its turns around the nozzle's axis (coiling),
  toothpaste         its reversals along the main horizontal direction (S-shaped folding), the
                     pile's height and width, the laid material's median J = det F (crushed by its
                     own weight?) and the falling rope's J in four height bands from the nozzle
                     down (where it is crushed), and the loop-to-loop contacts: where a later
                     turn or fold of the laid rope touches an earlier one, and how many of them
                     fuse (a neck of at least 1.5 rope radii across: merged, not resting on each
                     other as distinct ropes; see loop_contacts) (Figures 5.3, 5.9)
  pie                crust pieces (connected components of crust particles) against the prescored
                     slices (the stiff crust's components at frame 0), slices broken across, the
                     groups of slices each piece holds and whether the crust broke along its cuts
                     (at least 3 pieces, no slice broken across), cream components by frame
                     (splitting), the crust's velocity along the throw by frame (does it reach the
                     head?) (Figures 5.6, 5.8)
  twisting_sponge    separated pieces and torn links (lattice neighbours now far apart: the torn
                     area), the grips' turn, whether it came apart (at least 2 pieces of more
                     than 1 % of the particles each), when it first did, and each piece's height
                     range (torn in the middle or off a grip?) (Figure 5.1)
  shooting_sponge    the sponge's deformation (rms displacement from frame 0: its peak and how far
                     it comes back after the bullet has passed: the recovery), the bullet's tunnel
                     (particles in its path relative to frame 0), pieces, torn links (Figure 5.2)
"""
import argparse
import glob
import json
import math
import os
import re
import sys
import xml.etree.ElementTree as ET

try:
    import h5py
    import numpy as np
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree
except ImportError as missing:
    sys.stderr.write(f"measure_scenes.py: needs the Python module {missing.name} (Debian: python3-h5py, "
                     "python3-numpy, python3-scipy; scripts/setup.sh installs them)\n")
    sys.exit(2)

HERE = os.path.dirname(os.path.abspath(__file__))
PROGRAM = "measure_scenes.py"


class InputError(Exception):
    """A problem with what the user gave (an option, a directory, a frame or scene file): reported
    as one line naming it, exit status 2."""


def fail(message):
    """Ends the program with one line on stderr and exit status 2 (never a traceback)."""
    sys.stderr.write(f"{PROGRAM}: {message}\n")
    sys.exit(2)


class Parser(argparse.ArgumentParser):
    """argparse, but a bad or missing argument is one line (the option and what is wrong), exit 2."""

    def error(self, message):
        fail(f"{message} (see --help)")
SCENES = ["weissenberg_sweep", "viennetta", "shaving_foam", "toothpaste", "pie", "twisting_sponge",
          "shooting_sponge"]


# ---------------------------------------------------------------------------------------------
# Input: frames and the scene file.

class Frames:
    """The frames of an output directory, read on demand: frame(i) -> dict of arrays sorted by id."""

    def __init__(self, output_dir):
        if not os.path.isdir(output_dir):
            raise InputError(f"{output_dir}: no such directory")
        files = [f for f in glob.glob(os.path.join(output_dir, "frame_*.h5")) if re.search(r"frame_(\d+)\.h5$", f)]
        if not files:
            raise InputError(f"{output_dir}: no frame_NNNNN.h5 files")
        self.paths = {int(re.search(r"frame_(\d+)\.h5$", f).group(1)): f for f in files}
        self.numbers = sorted(self.paths)

    def frame(self, number, fields=("id", "position", "velocity", "material_id"), optional=()):
        """The frame's `fields` (required) and those of `optional` that the file holds."""
        path = self.paths[number]
        try:
            with h5py.File(path, "r") as h5:
                p = h5["particles"]
                order = np.argsort(p["id"][...])
                data = {name: p[name][...][order] for name in fields}
                data.update({name: p[name][...][order] for name in optional if name in p})
                data["time"] = float(h5.attrs["time"])
                names = p.attrs.get("material_names", b"")  # the scene's materials, comma-separated
                data["material_names"] = (names.decode() if isinstance(names, bytes) else str(names)).split(",")
                data["volume0_median"] = float(np.median(p["volume0"][...])) if len(order) else 0.0
        except KeyError as e:  # a dataset or attribute of doc/contracts.md missing
            raise InputError(f"{path}: not a viscompm frame: {str(e).strip(chr(39)).strip()}") from None
        except (OSError, ValueError) as e:  # truncated, damaged or not HDF5
            reason = str(e).splitlines()[0] if str(e) else type(e).__name__
            raise InputError(f"{path}: cannot read the frame: {reason}") from None
        return data

    def first(self, **kw):
        return self.frame(self.numbers[0], **kw)

    def last(self, **kw):
        return self.frame(self.numbers[-1], **kw)


class SceneFile:
    """Parameters of a scene XML file by sublist path, e.g. get("Emitters/nozzle/Center")."""

    def __init__(self, path):
        self.path = path
        try:
            self.root = ET.parse(path).getroot()
        except OSError as e:
            raise InputError(f"{path}: cannot read the scene file: {e.strerror or e}") from None
        except ET.ParseError as e:
            raise InputError(f"{path}: not an XML scene file: {e}") from None

    REQUIRED = object()

    def get(self, path, default=REQUIRED):
        """The parameter's value; without a default, a missing or malformed parameter is an
        InputError naming the file and the parameter."""
        node = self.root
        parts = path.split("/")
        for part in parts[:-1]:
            node = next((c for c in node.findall("ParameterList") if c.get("name") == part), None)
            if node is None:
                break
        leaf = None if node is None else next((c for c in node.findall("Parameter") if c.get("name") == parts[-1]), None)
        if leaf is None:
            if default is SceneFile.REQUIRED:
                raise InputError(f"{self.path}: no parameter {path} (the measure of this scene needs it)")
            return default
        value = leaf.get("value", "")
        try:
            if leaf.get("type", "").startswith("Array"):
                return np.array([float(v) for v in value.strip("{} ").split(",")])
            return float(value) if leaf.get("type") in ("double", "int") else value
        except ValueError:
            raise InputError(f"{self.path}: parameter {path}: '{value}' is not a number") from None

    def sublists(self, path):
        node = self.root
        for part in path.split("/"):
            node = next((c for c in node.findall("ParameterList") if c.get("name") == part), None)
            if node is None:
                return []
        return [c.get("name") for c in node.findall("ParameterList")]


def spacing(frame):
    """The particles' lattice spacing h = V0^(1/3)."""
    return frame["volume0_median"] ** (1.0 / 3.0)


def components(positions, link):
    """Connected-component labels of the particles, two linked when closer than `link`."""
    if len(positions) == 0:
        return np.zeros(0, dtype=int), 0
    pairs = cKDTree(positions).query_pairs(link, output_type="ndarray")
    n = len(positions)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    count, labels = connected_components(graph, directed=False)
    return labels, count


def pieces(labels, minimum):
    """Sizes of the components holding at least `minimum` particles, largest first."""
    sizes = np.bincount(labels) if len(labels) else np.zeros(0, dtype=int)
    return sorted((int(s) for s in sizes if s >= minimum), reverse=True)


# ---------------------------------------------------------------------------------------------
# Weissenberg sweep (Figure 5.4).

def measure_weissenberg(frames, scene):
    ground = scene.get("Colliders/ground/Center")[1]
    series = {}
    for number in frames.numbers:
        f = frames.frame(number)
        for m, name in enumerate(f["material_names"]):
            x = f["position"][f["material_id"] == m]
            if len(x) == 0:
                continue
            s = series.setdefault(name, {"t": [], "top": [], "width": []})
            s["t"].append(f["time"])
            s["top"].append(float(x[:, 1].max() - ground))
            s["width"].append(float(max(np.ptp(x[:, 0]), np.ptp(x[:, 2]))))
    result = {"balls": []}
    for name, s in series.items():
        wi = scene.get(f"Materials/{name}/Weissenberg number")
        top = np.array(s["top"])
        lowest = int(np.argmin(top))
        result["balls"].append({
            "material": name, "Wi": wi, "initial_height": top[0], "lowest_height": float(top[lowest]),
            "lowest_time": s["t"][lowest], "rebound_height": float(top[lowest:].max()),
            "rebound": float(top[lowest:].max() - top[lowest]), "final_height": float(top[-1]),
            "final_height_over_width": float(top[-1] / s["width"][-1]), "final_time": s["t"][-1]})
    balls = sorted(result["balls"], key=lambda b: b["Wi"])
    result["balls"] = balls
    result["rebound_monotone_in_Wi"] = all(a["rebound"] <= b["rebound"] for a, b in zip(balls, balls[1:]))
    result["final_ratio_monotone_in_Wi"] = all(a["final_height_over_width"] <= b["final_height_over_width"]
                                               for a, b in zip(balls, balls[1:]))
    return result


# ---------------------------------------------------------------------------------------------
# Streams laid down: Viennetta (belt), shaving foam and toothpaste (a pile).

def emission_bins(f, emitted, size):
    """Groups the emitted particles (mask `emitted` of frame f; ids grow with the emission time) into
    consecutive bins of about `size` particles, several of the nozzle's layers each, so that a bin's
    centre is the stream's centre at that time; returns a list of index arrays, oldest first."""
    index = np.nonzero(emitted)[0]
    index = index[np.argsort(f["id"][index])]
    return [b for b in np.array_split(index, max(2, len(index) // size)) if len(b)]


def reversals(signal, threshold):
    """Indices of the turning points of a sequence, counting only swings larger than `threshold`
    (hysteresis): the maxima and minima between them."""
    turns, direction = [], 0
    high = low = signal[0]
    high_at = low_at = 0
    for i, v in enumerate(signal):
        if v > high:
            high, high_at = v, i
        if v < low:
            low, low_at = v, i
        if direction >= 0 and v < high - threshold:  # fell from a maximum
            if direction > 0:
                turns.append(high_at)
            direction, low, low_at = -1, v, i
        elif direction <= 0 and v > low + threshold:  # rose from a minimum
            if direction < 0:
                turns.append(low_at)
            direction, high, high_at = 1, v, i
    return turns


def measure_viennetta(frames, scene, bin_size):
    belt_speed = float(scene.get("Colliders/belt/Surface velocity")[0])
    belt_top = float(scene.get("Colliders/belt/Upper corner")[1])
    lower, upper = scene.get("Emitters/nozzle/Lower corner"), scene.get("Emitters/nozzle/Upper corner")
    nozzle_x = 0.5 * (lower[0] + upper[0])
    f = frames.last()
    h = spacing(f)
    x, v = f["position"], f["velocity"]
    # On the belt: low, and carried with it (the fresh stream still falls).
    laid = (x[:, 1] < belt_top + 0.5 * (lower[1] - belt_top)) & (np.abs(v[:, 1]) < 0.2 * belt_speed + 0.05)
    n_laid = int(laid.sum())
    result = {"time": f["time"], "particles": len(x), "laid_on_belt": n_laid, "belt_speed": belt_speed}
    if n_laid < 100:
        result["note"] = "too little material on the belt to measure folds"
        return result
    # Emission time of each particle from its place in emission order (the frame is sorted by id;
    # a constant rate from t = 0).
    t_emit = np.linspace(0.0, f["time"], len(x), endpoint=False)
    # Where it landed: the belt has carried it belt_speed * (t - t_emit) less the (constant) fall time.
    landed = x[:, 0] - belt_speed * (f["time"] - t_emit)
    bins = emission_bins(f, laid, bin_size)
    signal = np.array([np.median(landed[b]) for b in bins])
    times = np.array([np.median(t_emit[b]) for b in bins])
    turns = reversals(signal, 1.0 * h)
    result.update({
        "landing_positions_m": [round(float(s - nozzle_x), 4) for s in signal],
        "landing_swing_m": float(np.ptp(signal)), "swing_reversals": len(turns), "folds": len(turns) // 2,
        "particle_spacing": h})
    if len(turns) >= 3:
        period = 2.0 * float(np.mean(np.diff(times[turns])))
        result.update({"fold_period_s": period, "fold_wavelength_m": belt_speed * period})
    result.update(crests_along_belt(x[laid], h, nozzle_x))
    return result


def crests_along_belt(x, h, nozzle_x):
    """Local maxima of the deposit's top along the belt (x), downstream of the nozzle, that rise at
    least one particle spacing above both neighbouring troughs."""
    width = 2.0 * h
    edges = np.arange(nozzle_x, x[:, 0].max() + width, width)
    top = np.full(len(edges) - 1, np.nan)
    which = np.digitize(x[:, 0], edges) - 1
    for i in range(len(top)):
        y = x[which == i, 1]
        if len(y):
            top[i] = y.max()
    top = top[~np.isnan(top)]
    if len(top) < 5:
        return {"crests": 0}
    smooth = np.convolve(top, np.ones(3) / 3, mode="same")
    turns = reversals(smooth, h)
    crests = [i for i in turns if 0 < i < len(smooth) - 1 and smooth[i] >= smooth[i - 1] and smooth[i] >= smooth[i + 1]]
    result = {"crests": len(crests), "deposit_top_profile_m": [round(float(t), 4) for t in top]}
    if len(crests) >= 2:
        result["crest_spacing_m"] = float(np.mean(np.diff(crests))) * width
    return result


def measure_pile(frames, scene, bin_size, link_factor):
    centre = scene.get("Emitters/nozzle/Center")
    speed = float(np.linalg.norm(scene.get("Emitters/nozzle/Velocity")))
    radius = float(scene.get("Emitters/nozzle/Radius"))
    f = frames.frame(frames.numbers[-1], optional=("deformation_gradient",))
    h = spacing(f)
    x, v = f["position"], f["velocity"]
    # Laid: slow compared with the stream (which arrives faster than it left the nozzle).
    laid = np.linalg.norm(v, axis=1) < 0.3 * speed
    base = float(x[laid, 1].min()) if laid.any() else float("nan")
    result = {"time": f["time"], "particles": len(x), "laid": int(laid.sum()), "particle_spacing": h,
              "nozzle_radius": radius}
    if laid.sum() < 100:
        result["note"] = "too little material laid down to measure"
        return result
    offset = x[:, [0, 2]] - centre[[0, 2]]
    result.update({"pile_height_m": float(x[laid, 1].max() - base),
                   "pile_width_m": float(2.0 * np.percentile(np.linalg.norm(offset[laid], axis=1), 95))})
    bins = emission_bins(f, laid, bin_size)
    path = np.array([offset[b].mean(axis=0) for b in bins])
    # Coiling: the laid rope's centre turns about the middle of its path; the turns are the sum of
    # the angle steps between consecutive bins away from the middle (a step across the middle,
    # larger than a right angle, is a fold, not a turn).
    around = path - path.mean(axis=0)
    far = np.linalg.norm(around, axis=1) > 0.5 * radius
    steps = np.arctan2(np.cross(around[:-1], around[1:]), np.einsum("ij,ij->i", around[:-1], around[1:]))
    steps = steps[far[:-1] & far[1:] & (np.abs(steps) < 0.5 * math.pi)]
    turns = float(np.sum(steps) / (2 * math.pi))
    # Folding: it swings back and forth along its main horizontal direction.
    axis = np.linalg.svd(path - path.mean(axis=0), full_matrices=False)[2][0]
    along = path @ axis
    swings = reversals(along, radius)
    result.update({"coil_turns": turns, "coil_radius_m": float(np.median(np.linalg.norm(around, axis=1))),
                   "fold_reversals": len(swings), "fold_amplitude_m": float(np.ptp(along) / 2),
                   "pile_height_by_frame_m": pile_heights(frames, speed)})
    if "deformation_gradient" in f:  # crushed by its own weight? J = det F of the laid material
        J = np.linalg.det(f["deformation_gradient"])
        result["laid_J_median"] = float(np.median(J[laid]))
        # Where it is crushed: J of the falling rope (moving down faster than 0.3 of the nozzle's
        # speed) in four height bands from the nozzle down to the pile's base, the top band first
        # (None: fewer than 10 particles in the band).
        falling = v[:, 1] < -0.3 * speed
        edges = np.linspace(float(centre[1]), base, 5)
        bands = [falling & (x[:, 1] <= top) & (x[:, 1] > bottom) for top, bottom in zip(edges[:-1], edges[1:])]
        result["falling_J_by_height"] = [float(np.median(J[b])) if b.sum() >= 10 else None for b in bands]
    index = np.nonzero(laid)[0]
    rank = np.empty(len(x), dtype=int)
    rank[index] = np.arange(len(index))
    result.update(loop_contacts(x[laid], [rank[b] for b in bins], h, link_factor))
    return result


def loop_contacts(x, bins, h, link_factor, fuse_ratio=1.5, gap_diameters=4.0):
    """Contacts between different laid turns of a rope, and which of them fuse.

    x: the laid particles; bins: index arrays into x, consecutive pieces of the rope in emission
    order. The rope's radius r is the median over the bins of 2 sqrt(the middle eigenvalue of the
    piece's covariance) (a straight piece of a round rope: its two cross-section eigenvalues are
    r^2/4, whether the piece is longer or shorter than wide). Two particles closer than
    link_factor * h belong to a loop-to-loop contact when the rope between their pieces (the path
    of the pieces' centres) is at least `gap_diameters` rope diameters long: a later turn or fold
    laid on or beside an earlier one, not the rope's own neighbours. Per pair of pieces in contact,
    the neck is the extent of the contact's particles (those of each piece within the link of the
    other) across rope a (along n x t_a: n joins the pieces' centres, t_a is rope a's direction),
    plus one spacing. Touching pieces of pairs adjacent in both ropes are one contact; a contact
    fuses when its median neck is at least fuse_ratio * r: the ropes have run into each other over
    most of their width (two round ropes only touching meet over about 2 sqrt(r h), which is less
    than 1.5 r once the rope is more than about 2 spacings thick), rather than resting on each other
    as distinct ropes."""
    bins = [b for b in bins if len(b) >= 4]
    if len(bins) < 3:
        return {"loop_contacts": 0, "loop_contacts_fused": 0, "note_contacts": "too few pieces of rope"}
    centres = np.array([x[b].mean(axis=0) for b in bins])
    radii = [2.0 * math.sqrt(max(np.linalg.eigvalsh(np.cov(x[b].T))[1], 0.0)) for b in bins]
    r = float(np.median(radii))
    along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(centres, axis=0), axis=1))])
    tangent = np.gradient(centres, axis=0)
    tangent /= np.maximum(np.linalg.norm(tangent, axis=1), 1e-300)[:, None]
    piece = np.full(len(x), -1)
    for k, b in enumerate(bins):
        piece[b] = k
    pairs = cKDTree(x).query_pairs(link_factor * h, output_type="ndarray")
    pairs = pairs[(piece[pairs[:, 0]] >= 0) & (piece[pairs[:, 1]] >= 0)]
    a, b = piece[pairs[:, 0]], piece[pairs[:, 1]]
    swap = a > b
    pairs[swap] = pairs[swap][:, ::-1]
    a, b = np.minimum(a, b), np.maximum(a, b)
    apart = along[b] - along[a] >= gap_diameters * 2.0 * r
    pairs, a, b = pairs[apart], a[apart], b[apart]
    result = {"rope_radius_m": r, "loop_gap_m": gap_diameters * 2.0 * r}
    if len(pairs) == 0:
        result.update({"loop_contacts": 0, "loop_contacts_fused": 0})
        return result
    keys = sorted(set(zip(a.tolist(), b.tolist())))
    neck = {}
    for ka, kb in keys:
        mine = (a == ka) & (b == kb)
        touching = np.unique(np.concatenate([pairs[mine, 0], pairs[mine, 1]]))
        n = centres[kb] - centres[ka]
        across = np.cross(n, tangent[ka])
        if np.linalg.norm(across) < 1e-12 * max(np.linalg.norm(n), 1e-300):
            across = np.cross(tangent[kb], tangent[ka])  # the pieces' centres meet: cross the ropes
        across /= max(np.linalg.norm(across), 1e-300)
        neck[(ka, kb)] = float(np.ptp(x[touching] @ across)) + h
    # Contacts: pairs of pieces adjacent in both ropes (parallel or antiparallel) are one contact.
    index = {k: i for i, k in enumerate(keys)}
    rows, cols = [], []
    for (ka, kb), i in index.items():
        for da in (-1, 0, 1):
            for db in (-1, 0, 1):
                j = index.get((ka + da, kb + db))
                if j is not None:
                    rows.append(i)
                    cols.append(j)
    count, labels = connected_components(coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(len(keys),) * 2),
                                         directed=False)
    necks = [float(np.median([neck[k] for k, l in zip(keys, labels) if l == c])) for c in range(count)]
    result.update({"loop_contacts": count,
                   "loop_contacts_fused": int(sum(w >= fuse_ratio * r for w in necks)),
                   "loop_contact_necks_over_rope_radius": sorted((round(w / r, 2) for w in necks), reverse=True)})
    return result


def pile_heights(frames, speed):
    heights = []
    for number in frames.numbers[:: max(1, len(frames.numbers) // 12)]:
        f = frames.frame(number, fields=("id", "position", "velocity"))
        laid = np.linalg.norm(f["velocity"], axis=1) < 0.3 * speed
        y = f["position"][laid, 1]
        heights.append([round(f["time"], 3), round(float(np.ptp(y)), 4) if len(y) else 0.0])
    return heights


# ---------------------------------------------------------------------------------------------
# Pie (Figures 5.6, 5.8).

def measure_pie(frames, scene, link_factor):
    first, last = frames.first(), frames.last()
    names = first["material_names"]
    crust, scored, cream = (names.index(n) for n in ("crust", "crust_scored", "cream"))
    h = spacing(first)
    link = link_factor * h
    stiff0 = first["material_id"] == crust
    slice_labels, _ = components(first["position"][stiff0], link)
    slices = pieces(slice_labels, max(10, stiff0.sum() // 100))
    cuts = int(scene.get("Regions/scoring/Cut count", 0))
    result = {"particle_spacing": h, "link_distance": link, "prescored_slices_designed": 2 * cuts,
              "stiff_crust_slices_at_frame_0": len(slices)}
    for label, f in (("frame_0", first), ("last", last)):
        is_crust = np.isin(f["material_id"], [crust, scored])
        labels, _ = components(f["position"][is_crust], link)
        result[f"crust_pieces_{label}"] = len(pieces(labels, max(10, is_crust.sum() // 100)))
        result[f"crust_piece_sizes_{label}"] = pieces(labels, max(10, is_crust.sum() // 100))
        cream_labels, _ = components(f["position"][f["material_id"] == cream], link)
        result[f"cream_pieces_{label}"] = len(pieces(cream_labels, 10))
    # Which slices ended in which piece: the stiff particles keep their ids, so each carries the
    # slice label it had at frame 0.
    is_crust = np.isin(last["material_id"], [crust, scored])
    piece_labels, _ = components(last["position"][is_crust], link)
    stiff_last = last["material_id"][is_crust] == crust
    stiff_ids0 = first["id"][stiff0]
    slice_of_stiff = slice_labels[np.searchsorted(stiff_ids0, last["id"][is_crust][stiff_last])]
    big = {i for i, s in enumerate(np.bincount(slice_labels)) if s >= max(10, stiff0.sum() // 100)}
    split = sum(1 for s in big if len(set(piece_labels[stiff_last][slice_of_stiff == s])) > 1)
    stiff_pieces = piece_labels[stiff_last]
    per_piece = sorted((len({s for s in set(slice_of_stiff[stiff_pieces == q]) if s in big})
                        for q in set(stiff_pieces)), reverse=True)
    result["slices_per_crust_piece"] = [n for n in per_piece if n > 0]
    result.update({"time": last["time"], "slices_broken_across": split})
    # Broken along the cuts: at least 3 pieces, each a group of whole slices (none broken across);
    # the groups, by frame-0 slice number (slices numbered by their first particle's id).
    rename = {s: i for i, s in enumerate(sorted(big, key=lambda s: stiff_ids0[slice_labels == s].min()))}
    groups = sorted(sorted(rename[s] for s in set(slice_of_stiff[stiff_pieces == q]) if s in big)
                    for q in set(stiff_pieces))
    result["crust_slice_groups"] = [g for g in groups if g]
    result["crust_broken_along_cuts"] = bool(split == 0 and len(result["crust_slice_groups"]) >= 3)
    # Whether the crust reaches the head: its mean velocity along the throw, frame by frame.
    throw = first["velocity"][stiff0].mean(axis=0)
    throw /= max(np.linalg.norm(throw), 1e-300)
    result["crust_velocity_along_throw_by_frame"] = [
        [round(f["time"], 4), round(float(f["velocity"][f["material_id"] != cream].mean(axis=0) @ throw), 3)]
        for f in (frames.frame(n) for n in frames.numbers)]
    cream_counts = [len(pieces(components(f["position"][f["material_id"] == cream], link)[0], 10))
                    for f in (frames.frame(n) for n in frames.numbers)]
    result["cream_pieces_by_frame"] = cream_counts
    return result


# ---------------------------------------------------------------------------------------------
# Sponges (Figures 5.1, 5.2).

def torn_links(first, last, h, tear_factor):
    """Lattice neighbours of frame 0 (closer than 1.01 h) now farther apart than tear_factor * h:
    their count, the fraction of all links, and the torn area ~ count * h^2."""
    pairs = cKDTree(first["position"]).query_pairs(1.01 * h, output_type="ndarray")
    distance = np.linalg.norm(last["position"][pairs[:, 0]] - last["position"][pairs[:, 1]], axis=1)
    torn = int(np.sum(distance > tear_factor * h))
    return {"links": len(pairs), "torn_links": torn, "torn_fraction": torn / max(len(pairs), 1),
            "torn_area_m2": torn * h * h}


def measure_sponge_pieces(first, last, link_factor, tear_factor):
    h = spacing(first)
    labels, _ = components(last["position"], link_factor * h)
    big = pieces(labels, max(10, len(labels) // 1000))
    result = {"particle_spacing": h, "time": last["time"], "particles": len(labels),
              "pieces": len(big), "piece_sizes": big[:10],
              "fragments_under_0.1_percent": int(np.sum(np.bincount(labels) < max(10, len(labels) // 1000)))}
    result.update(torn_links(first, last, h, tear_factor))
    return result


def measure_twisting(frames, scene, link_factor, tear_factor):
    first, last = frames.first(), frames.last()
    result = measure_sponge_pieces(first, last, link_factor, tear_factor)
    omega = scene.get("Colliders/top grip/Angular velocity") - scene.get("Colliders/bottom grip/Angular velocity")
    result["relative_twist_rad"] = float(np.linalg.norm(omega) * last["time"])
    result["torn_fraction_by_frame"] = [
        [round(frames.frame(n)["time"], 3), round(torn_links(first, frames.frame(n), spacing(first), tear_factor)["torn_fraction"], 4)]
        for n in frames.numbers[:: max(1, len(frames.numbers) // 8)]]
    # Came apart: at least two pieces of more than 1 % of the particles each (a tear through the
    # whole cross-section leaves two such pieces); the first frame where it holds, and where along
    # the grips' axis (y) each piece of the last frame lies, lowest first.
    link, over_1_percent = link_factor * spacing(first), len(first["position"]) // 100 + 1

    def apart(frame):
        return len(pieces(components(frame["position"], link)[0], over_1_percent)) >= 2

    labels, _ = components(last["position"], link)
    sizes = np.bincount(labels)
    large = [q for q in range(len(sizes)) if sizes[q] >= over_1_percent]
    result["pieces_over_1_percent"] = len(large)
    result["came_apart"] = len(large) >= 2
    result["piece_height_ranges"] = sorted([round(float(last["position"][labels == q, 1].min()), 3),
                                            round(float(last["position"][labels == q, 1].max()), 3)] for q in large)
    result["first_apart_time"] = next((round(float(frames.frame(k)["time"]), 4) for k in frames.numbers
                                       if apart(frames.frame(k))), None)
    return result


def measure_shooting(frames, scene, link_factor, tear_factor):
    first, last = frames.first(), frames.last()
    result = measure_sponge_pieces(first, last, link_factor, tear_factor)
    centre = scene.get("Colliders/bullet/Center")
    radius = float(scene.get("Colliders/bullet/Radius"))
    velocity = scene.get("Colliders/bullet/Velocity")
    direction = velocity / np.linalg.norm(velocity)
    lo, hi = scene.get("Bodies/sponge/Lower corner"), scene.get("Bodies/sponge/Upper corner")
    # The tunnel: the bullet's path through the sponge's initial extent.
    along0, far0 = lo @ direction, hi @ direction

    def in_tunnel(x):
        s = (x - centre) @ direction
        off = np.linalg.norm((x - centre) - np.outer(s, direction), axis=1)
        along = x @ direction
        return (off < radius) & (along > min(along0, far0)) & (along < max(along0, far0))

    count0 = int(in_tunnel(first["position"]).sum())
    series, displacement = [], []
    for n in frames.numbers:
        f = frames.frame(n, fields=("id", "position"))
        series.append([round(f["time"], 4), round(int(in_tunnel(f["position"]).sum()) / max(count0, 1), 3)])
        # The sponge's deformation: the root-mean-square displacement from frame 0 (no particle is
        # added or removed, so the id-sorted arrays match).
        displacement.append(float(np.sqrt(np.mean(np.sum((f["position"] - first["position"]) ** 2, axis=1)))))
    occupancy = np.array([s[1] for s in series])
    lowest = int(np.argmin(occupancy))
    result.update({"tunnel_particles_frame_0": count0, "tunnel_occupancy_by_frame": series,
                   "tunnel_occupancy_lowest": float(occupancy[lowest]), "lowest_time": series[lowest][0],
                   "tunnel_occupancy_final": float(occupancy[-1]),
                   "rms_displacement_by_frame_m": [[s[0], round(d, 4)] for s, d in zip(series, displacement)],
                   "rms_displacement_peak_m": max(displacement),
                   "rms_displacement_peak_time": series[int(np.argmax(displacement))][0],
                   "rms_displacement_final_m": displacement[-1],
                   # It swings back elastically: how far the first return after the peak comes.
                   "rms_displacement_first_return_m": min(displacement[int(np.argmax(displacement)):]),
                   "recovered_fraction_first_return":
                       1.0 - min(displacement[int(np.argmax(displacement)):]) / max(max(displacement), 1e-300),
                   "bullet_exits_sponge_s": float((max(along0, far0) - centre @ direction + radius)
                                                  / np.linalg.norm(velocity))})
    return result


# ---------------------------------------------------------------------------------------------

def positive(kind):
    def read(text):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a{'n integer' if kind is int else ' number'}") from None
        if not value > 0:
            raise argparse.ArgumentTypeError(f"'{text}' is not positive")
        return value
    return read


def main():
    ap = Parser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("output_dir")
    ap.add_argument("--scene", choices=SCENES, help="the scene (default: the output directory's name)")
    ap.add_argument("--scene-file", help="the scene XML the run used (default inputs/scenes/paper/showcase/NAME.xml)")
    ap.add_argument("--link", type=positive(float), default=1.5,
                    help="particles closer than this many particle spacings are connected (default 1.5)")
    ap.add_argument("--tear", type=positive(float), default=3.0,
                    help="a lattice link is torn when longer than this many spacings (default 3)")
    ap.add_argument("--bin", type=positive(int), default=400,
                    help="streams: particles per bin of emission order, several nozzle layers (default 400)")
    ap.add_argument("--json", help="also write the measurements to this JSON file")
    args = ap.parse_args()
    name = args.scene or os.path.basename(os.path.normpath(args.output_dir))
    if name not in SCENES:
        fail(f"{args.output_dir}: unknown scene '{name}' (give --scene, one of {', '.join(SCENES)})")
    try:
        measure_run(args, name)
    except InputError as e:
        fail(str(e))
    except OSError as e:  # writing --json
        fail(f"{e.filename or ''}: {e.strerror or e}")
    except Exception as e:  # noqa: BLE001 - frames that do not fit what the measure expects
        sys.stderr.write(f"{PROGRAM}: {args.output_dir}: cannot measure {name}: {type(e).__name__}: "
                         f"{str(e).splitlines()[0] if str(e) else ''}\n")
        sys.exit(1)


def measure_run(args, name):
    scene_file = args.scene_file or os.path.join(HERE, os.pardir, "inputs", "scenes", "paper", "showcase", name + ".xml")
    scene = SceneFile(scene_file)
    frames = Frames(args.output_dir)
    measure = {
        "weissenberg_sweep": lambda: measure_weissenberg(frames, scene),
        "viennetta": lambda: measure_viennetta(frames, scene, args.bin),
        "shaving_foam": lambda: measure_pile(frames, scene, args.bin, args.link),
        "toothpaste": lambda: measure_pile(frames, scene, args.bin, args.link),
        "pie": lambda: measure_pie(frames, scene, args.link),
        "twisting_sponge": lambda: measure_twisting(frames, scene, args.link, args.tear),
        "shooting_sponge": lambda: measure_shooting(frames, scene, args.link, args.tear),
    }[name]
    result = {"scene": name, "output": args.output_dir, "frames": len(frames.numbers), **measure()}
    # One line per measurement: lists of numbers stay on one line.
    text = "{\n" + ",\n".join(f" {json.dumps(k)}: {json.dumps(v, default=float)}" for k, v in result.items()) + "\n}"
    print(text)
    if args.json:
        with open(args.json, "w") as out:
            out.write(text + "\n")


if __name__ == "__main__":
    main()
