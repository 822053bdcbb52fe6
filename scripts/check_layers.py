#!/usr/bin/python3
"""The layer rule of doc/architecture.md, checked: every #include "viscompm/<folder>/..." in
src/<folder>/, include/viscompm/<folder>/ and apps/ must name a folder that <folder> may include,
and the physics folders include no Trilinos or HDF5 header. Prints one line per violation and
exits 1 if there is any (ctest: test_layers)."""
import argparse
import pathlib
import re
import sys

PHYSICS = ["core", "grid", "geometry", "particles", "materials", "transfer", "boundary", "parallel", "implicit"]

# Which folders each folder may include (besides itself). Bottom to top; the graph is acyclic.
ALLOWED = {
    "core": [],
    "grid": ["core"],
    "geometry": ["core"],
    "particles": ["core", "grid", "geometry"],
    "materials": ["core", "particles"],
    "transfer": ["core", "grid", "particles"],
    "boundary": ["core", "grid", "geometry", "particles"],
    "parallel": ["core", "grid", "particles"],
    "implicit": ["core", "grid", "particles", "materials", "transfer", "boundary", "parallel"],
    # Teuchos parameter lists: below both the scene reader and the solver configurations.
    "params": ["core"],
    "linalg": PHYSICS + ["params"],
    # Newton's method: its settings are plain structs, its loop drives the linear algebra.
    "newton": PHYSICS + ["params", "linalg"],
    "io": PHYSICS + ["linalg"],
    "scene": PHYSICS + ["params", "linalg", "newton"],
    "simulation": PHYSICS + ["params", "linalg", "newton", "io", "scene"],
    "study": PHYSICS + ["params", "linalg", "newton", "io", "scene", "simulation"],
    "app": PHYSICS + ["params", "linalg", "newton", "io", "scene", "simulation", "study"],
    "apps": ["app"],
}

# Headers the physics folders must not include: they build into libviscompm_physics (Eigen, MPI).
FORBIDDEN_IN_PHYSICS = re.compile(
    r"#include\s*[<\"](Teuchos|Tpetra|Kokkos|Belos|MueLu|Ifpack2|Xpetra|Zoltan2|Amesos2|Galeri|hdf5)")
# Violations tolerated while the code that has them is rewritten elsewhere, as (file, the folder
# or library included): reported, not failed. An entry that no longer occurs fails the check, so
# that it is removed here. (None now: the last three went with the Newton rewrite.)
KNOWN = set()

INCLUDE = re.compile(r'^\s*#\s*include\s*"viscompm/([a-z_]+)/')


def folder_of(path, root):
    parts = path.relative_to(root).parts
    if parts[0] == "apps":
        return "apps"
    if parts[0] == "src":
        return parts[1]
    return parts[2]  # include/viscompm/<folder>/


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, not argparse's usage block
        self.exit(2, f"{self.prog}: {message} (see --help)\n")


def fail(message):
    sys.stderr.write(f"check_layers.py: {message}\n")
    sys.exit(2)


def main():
    parser = Parser(description=__doc__ + " A root that is not a viscompm source tree, or a file that "
                    "cannot be read, is one line naming it, exit 2.")
    parser.add_argument("root", nargs="?", default=pathlib.Path(__file__).resolve().parent.parent, type=pathlib.Path)
    root = parser.parse_args().root
    if not root.is_dir():
        fail(f"{root}: no such directory")
    if not (root / "src").is_dir() or not (root / "include" / "viscompm").is_dir():
        fail(f"{root}: not a viscompm source tree (no src/ and include/viscompm/)")
    files = sorted(
        [*root.glob("src/*/**/*.[ch]pp"), *root.glob("include/viscompm/*/**/*.hpp"), *root.glob("apps/*.cpp")])
    violations, known_seen = [], set()

    def report(path, what, message):
        key = (str(path.relative_to(root)), what)
        if key in KNOWN:
            known_seen.add(key)
            print("known:", message)
        else:
            violations.append(message)

    for path in files:
        folder = folder_of(path, root)
        if folder not in ALLOWED:
            violations.append(f"{path.relative_to(root)}: folder '{folder}' is not in the layer table "
                              "(scripts/check_layers.py and doc/architecture.md)")
            continue
        try:
            text = path.read_text(errors="replace")
        except OSError as e:
            fail(f"{path}: cannot read ({e.strerror or e})")
        for number, line in enumerate(text.splitlines(), 1):
            match = INCLUDE.match(line)
            if match and match.group(1) != folder and match.group(1) not in ALLOWED[folder]:
                report(path, match.group(1), f"{path.relative_to(root)}:{number}: {folder}/ may not include "
                       f"{match.group(1)}/ ({line.strip()})")
            forbidden = FORBIDDEN_IN_PHYSICS.search(line)
            if folder in PHYSICS and forbidden:
                report(path, forbidden.group(1), f"{path.relative_to(root)}:{number}: physics folder {folder}/ "
                       f"includes a Trilinos or HDF5 header ({line.strip()})")
    for key in sorted(KNOWN - known_seen):
        violations.append(f"{key[0]}: the known violation ({key[1]}) is gone: remove it from KNOWN in {__file__}")
    for v in violations:
        print(v)
    print(f"{len(files)} files checked, {len(violations)} layer violations, {len(known_seen)} known ones")
    return 1 if violations else 0


if __name__ == "__main__":
    sys.exit(main())
