#!/usr/bin/env python3
"""The resolution benchmark's two smallest sizes with the stiff default (inputs/studies/resolution.xml,
cells 0.02 and 0.01, gmg_lean_deflated_cg.xml, 2 ranks): each Newton system is the size
doc/performance.md gives, its time step is the particle CFL's (halved with the cell unless the
scene's Max time step caps it), it converges, its CG count is within 15 % of the documented one,
and the count grows at most 1.3x from 0.02 to 0.01. The issue's other target, at most 30 CG per
system at every size, is not met at these sizes (118, 48, 44, 56) and is not asserted here."""
import csv
import os
import shlex
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, finish, program_arguments  # noqa: E402

args = program_arguments("study", ranks=2).parse_args()
shutil.rmtree(args.workdir, ignore_errors=True)
os.makedirs(args.workdir)

# doc/performance.md, "Resolution: the stiff scenes toward Table 5.1's cell": unknowns and CG
# iterations of gmg-lean-deflated per (scene, cell).
documented = {("pie impact", 0.02): (4470, 118), ("pie impact", 0.01): (19626, 48),
              ("stiff inclusions", 0.02): (14094, 44), ("stiff inclusions", 0.01): (85158, 56)}

out = os.path.join(args.workdir, "out")
command = shlex.split(args.mpiexec) + ["-np", str(args.ranks), args.study,
                                       os.path.join(args.inputs, "studies", "resolution.xml"),
                                       "--set", "Cell sizes={0.02, 0.01}",
                                       "--set", "Solvers={../solvers/gmg_lean_deflated_cg.xml}",
                                       "--set", "Plot=false", "--output", out]
result = subprocess.run(command, capture_output=True, text=True, timeout=600)
check(result.returncode == 0, f"the study exits 0: {result.stderr[-1500:]}")
rows = list(csv.DictReader(open(os.path.join(out, "study.csv")))) if result.returncode == 0 else []
found = {}
for row in rows:
    scene = row["problem"].split(" t=")[0]
    found[(scene, float(row["resolution"]))] = row
check(sorted(found) == sorted(documented), f"one row per scene and cell: {sorted(found)}")

iterations = {}
for key, (dofs, cg) in documented.items():
    row = found.get(key)
    if row is None:
        continue
    label = f"{key[0]} at {key[1]}"
    check(int(row["dofs"]) == dofs, f"{label}: {dofs} unknowns, got {row['dofs']}")
    check(row["converged"] == "1", f"{label}: converged")
    iterations[key] = int(row["iterations"])
    check(abs(iterations[key] - cg) <= 0.15 * cg, f"{label}: {cg} CG iterations within 15 %, got {iterations[key]}")
    print(f"{label}: {dofs} unknowns, {iterations[key]} CG iterations (documented {cg})")


def time_step(scene, cell):
    return float(found[(scene, cell)]["problem"].split("dt=")[1].split("s")[0])


for scene in ("pie impact", "stiff inclusions"):
    if (scene, 0.02) in iterations and (scene, 0.01) in iterations:
        growth = iterations[(scene, 0.01)] / iterations[(scene, 0.02)]
        check(growth <= 1.3, f"{scene}: CG grows at most 1.3x per halving of the cell, got {growth:.2f}")
        coarse, fine = time_step(scene, 0.02), time_step(scene, 0.01)
        check(fine < coarse, f"{scene}: the particle-CFL step shrinks with the cell ({coarse} -> {fine})")
# The stiff inclusions' step reaches no cap at these cells: it is proportional to the cell.
if ("stiff inclusions", 0.02) in found and ("stiff inclusions", 0.01) in found:
    ratio = time_step("stiff inclusions", 0.02) / time_step("stiff inclusions", 0.01)
    check(abs(ratio - 2) < 1e-6, f"stiff inclusions: the step halves with the cell, ratio {ratio}")
finish("resolution benchmark, cells 0.02 and 0.01: sizes, CFL steps and the stiff default's CG counts as documented")
