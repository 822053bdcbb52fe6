#!/usr/bin/python3
"""Writes the meshes of the paper scenes (inputs/meshes/), made here from primitives; nothing is
downloaded. Both are closed, consistently oriented triangle meshes (outward normals), y up.

  head.obj         a stylised mannequin head on a neck (Figure 5.8's target): one star-shaped
                   surface r(direction) around the skull centre, ~0.24 m tall, chin at y = 0
  toothbrush.stl   a toothbrush (Figure 5.9): a handle along x with tufts of bristles on
                   its head, binary STL, ~0.19 m long, handle bottom at y = 0

Usage: scripts/make_meshes.py [OUTPUT_DIR]   (default: inputs/meshes next to this script)

An OUTPUT_DIR that cannot be made or written to is one line on stderr naming it, exit 2.
"""
import argparse
import math
import os
import struct
import sys

try:
    import numpy as np
except ImportError:
    sys.exit("make_meshes.py: needs numpy (Debian: python3-numpy; scripts/setup.sh installs it)")


def sphere_grid(radius_of, rings=48, segments=96, centre=(0.0, 0.0, 0.0)):
    """A closed star-shaped surface: vertex = centre + r(d) d over a UV sphere of directions d
    (y is the polar axis). Returns (vertices, triangles), triangles counter-clockwise outside."""
    c = np.array(centre)
    verts = [c + radius_of(np.array([0.0, -1.0, 0.0])) * np.array([0.0, -1.0, 0.0])]
    for r in range(1, rings):
        polar = math.pi * r / rings
        for k in range(segments):
            a = 2.0 * math.pi * k / segments
            d = np.array([math.sin(polar) * math.cos(a), -math.cos(polar), math.sin(polar) * math.sin(a)])
            verts.append(c + radius_of(d) * d)
    verts.append(c + radius_of(np.array([0.0, 1.0, 0.0])) * np.array([0.0, 1.0, 0.0]))
    top = len(verts) - 1

    def ring(r, k):
        return 1 + (r - 1) * segments + (k % segments)

    tris = []
    for k in range(segments):
        tris.append((0, ring(1, k), ring(1, k + 1)))
        for r in range(1, rings - 1):
            tris.append((ring(r, k), ring(r + 1, k), ring(r + 1, k + 1)))
            tris.append((ring(r, k), ring(r + 1, k + 1), ring(r, k + 1)))
        tris.append((top, ring(rings - 1, k + 1), ring(rings - 1, k)))
    return np.array(verts), tris


def orient_outward(verts, tris):
    """Flips every triangle if the enclosed volume came out negative."""
    v = verts
    vol = sum(np.dot(v[a], np.cross(v[b], v[c])) for a, b, c in tris) / 6.0
    return tris if vol > 0 else [(a, c, b) for a, b, c in tris]


def bump(d, axis, width, height):
    """A smooth radial bump of `height` around unit direction `axis`, angular width `width`."""
    cos_angle = float(np.dot(d, axis))
    return height * math.exp(-(1.0 - cos_angle) / (width * width))


def head():
    """Skull ellipsoid, jaw, nose, brow, ears and a neck, as one radius function (metres)."""
    def radius(d):
        x, y, z = d  # face looks toward -x
        # Ellipsoid skull 0.16 deep (x), 0.2 tall (y), 0.15 wide (z).
        r = 1.0 / math.sqrt((x / 0.085) ** 2 + (y / 0.105) ** 2 + (z / 0.075) ** 2)
        r += bump(d, np.array([-0.55, -0.35, 0.0]) / math.hypot(0.55, 0.35), 0.35, 0.012)  # jaw
        r += bump(d, np.array([-1.0, -0.05, 0.0]), 0.12, 0.022)                            # nose
        r += bump(d, np.array([-0.9, 0.3, 0.0]) / math.hypot(0.9, 0.3), 0.25, 0.006)       # brow
        for side in (-1.0, 1.0):
            r += bump(d, np.array([0.1, 0.0, side]) / math.hypot(0.1, 1.0), 0.15, 0.012)   # ears
        # The neck: a column below the skull (directions pointing down).
        if y < 0.0:
            down = -y
            neck = 0.055 / max(math.sqrt(max(1.0 - down * down, 1e-12)), 1e-6)  # cylinder of radius 0.055
            r = max(r, min(neck, 0.19) * (down ** 8) + r * (1.0 - down ** 8))
        return r

    verts, tris = sphere_grid(radius, rings=64, segments=96)
    verts[:, 1] -= verts[:, 1].min()  # bottom of the neck at y = 0
    return verts, orient_outward(verts, tris)


def box(lo, hi):
    v = [np.array([hi[0] if k & 1 else lo[0], hi[1] if k & 2 else lo[1], hi[2] if k & 4 else lo[2]])
         for k in range(8)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = []
    for a, b, c, d in quads:
        tris += [(a, b, c), (a, c, d)]
    return np.array(v), tris


def cylinder(centre, radius, height, segments=12):
    """A closed vertical cylinder standing on `centre` (its bottom)."""
    cx, cy, cz = centre
    v = []
    for end in (0, 1):
        for k in range(segments):
            a = 2.0 * math.pi * k / segments
            v.append(np.array([cx + radius * math.cos(a), cy + end * height, cz + radius * math.sin(a)]))
    v.append(np.array([cx, cy, cz]))
    v.append(np.array([cx, cy + height, cz]))
    b, t = 2 * segments, 2 * segments + 1
    tris = []
    for k in range(segments):
        k1 = (k + 1) % segments
        tris += [(k, segments + k, segments + k1), (k, segments + k1, k1), (b, k, k1), (t, segments + k1, segments + k)]
    return np.array(v), tris


def merge(parts):
    verts, tris = [], []
    for v, t in parts:
        t = orient_outward(np.array(v), t)
        shift = len(verts)
        verts += list(v)
        tris += [(a + shift, b + shift, c + shift) for a, b, c in t]
    return np.array(verts), tris


def toothbrush():
    """Handle 0.19 m along x, 0.012 wide, 0.008 thick; 3 × 8 tufts of bristles (0.011 tall) on its head."""
    parts = [box((0.0, 0.0, -0.006), (0.19, 0.008, 0.006))]  # the handle, bottom at y = 0
    for i in range(8):
        for j in range(3):
            x = 0.140 + 0.006 * i
            z = (j - 1) * 0.0035
            parts.append(cylinder((x, 0.006, z), 0.0013, 0.011, segments=10))
    return merge(parts)


def write_obj(path, verts, tris, comment):
    with open(path, "w") as f:
        f.write(f"# {comment}\n# written by scripts/make_meshes.py\n")
        for v in verts:
            f.write(f"v {v[0]:.6f} {v[1]:.6f} {v[2]:.6f}\n")
        for a, b, c in tris:
            f.write(f"f {a + 1} {b + 1} {c + 1}\n")


def write_binary_stl(path, verts, tris, comment):
    with open(path, "wb") as f:
        f.write(comment.encode("ascii")[:80].ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for a, b, c in tris:
            n = np.cross(verts[b] - verts[a], verts[c] - verts[a])
            n = n / (np.linalg.norm(n) or 1.0)
            f.write(struct.pack("<12fH", *n, *verts[a], *verts[b], *verts[c], 0))


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, not argparse's usage block
        self.exit(2, f"{self.prog}: {message} (see --help)\n")


def fail(message):
    sys.stderr.write(f"make_meshes.py: {message}\n")
    sys.exit(2)


def main():
    parser = Parser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("output_dir", nargs="?",
                        default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "inputs", "meshes"))
    out = parser.parse_args().output_dir
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        fail(f"{out}: cannot make the directory ({e.strerror or e})")
    if not os.access(out, os.W_OK):
        fail(f"{out}: cannot write to the directory")
    v, t = head()
    path = os.path.join(out, "head.obj")
    try:
        write_obj(path, v, t, "stylised mannequin head on a neck, metres, y up, face toward -x")
        v, t = toothbrush()
        path = os.path.join(out, "toothbrush.stl")
        write_binary_stl(path, v, t, "toothbrush, metres, y up, bristles on +y")
    except OSError as e:
        fail(f"{path}: cannot write ({e.strerror or e})")
    print(f"wrote head.obj and toothbrush.stl to {out}")


if __name__ == "__main__":
    main()
