#!/usr/bin/env python3
"""viscompm-study end to end: study.csv has one row per (problem, resolution, configuration) with
the contract's columns and the operator's preparation time, failed configurations are rows with
converged=0 that keep the system's size, a Newton system written to MatrixMarket by a run
reproduces that run's solve when the study reads it back and every assembled solver file
(multigrid included: the dump carries node coordinates) solves it, and the steps mode runs whole
frames per configuration into steps.csv."""
import csv
import os
import shlex
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "support"))
from script_checks import check, finish, program_arguments  # noqa: E402

args = program_arguments("viscompm", "study", ranks=1).parse_args()


def run(program, *extra):
    command = shlex.split(args.mpiexec) + ["-np", str(args.ranks), program, *extra]
    return subprocess.run(command, capture_output=True, text=True, timeout=900)


shutil.rmtree(args.workdir, ignore_errors=True)
os.makedirs(args.workdir)
solvers = os.path.join(args.inputs, "solvers")
configs = ["matrix_free_jacobi_cg.xml", "jacobi_cg.xml", "chebyshev_cg.xml", "muelu_cg.xml"]

# A study of the sponge at two resolutions and two time steps.
study = os.path.join(args.workdir, "study.xml")
with open(study, "w") as f:
    f.write(f"""<ParameterList name="t">
  <Parameter name="Scene" type="string" value="{args.inputs}/scenes/shooting_sponge.xml"/>
  <Parameter name="Cell sizes" type="Array(double)" value="{{0.075, 0.06}}"/>
  <Parameter name="Time steps" type="Array(double)" value="{{2, 20}}"/>
  <Parameter name="Solvers" type="Array(string)" value="{{{', '.join(os.path.join(solvers, c) for c in configs)}}}"/>
  <Parameter name="Plot" type="bool" value="false"/>
</ParameterList>""")
out = os.path.join(args.workdir, "out")
result = run(args.study, study, "--output", out)
check(result.returncode == 0, f"study exits 0: {result.stderr[-1500:]}")
rows = list(csv.DictReader(open(os.path.join(out, "study.csv")))) if result.returncode == 0 else []
check(rows and list(rows[0].keys()) == ["problem", "resolution", "dofs", "nonzeros", "ranks", "preconditioner",
                                        "setup_seconds", "solve_seconds", "iterations", "relative_residual",
                                        "converged", "operator_seconds", "apply_seconds",
                                        "preconditioner_apply_seconds", "peak_memory_mib"], "study.csv columns")
check(all(float(r["operator_seconds"]) > 0.0 for r in rows), "every row counts the operator's preparation")
check(all(float(r["apply_seconds"]) > 0.0 for r in rows), "every row times one application of H")
check(all(float(r["preconditioner_apply_seconds"]) > 0.0 for r in rows),
      "every row (all preconditioned here) times one application of the preconditioner")
check(all(10.0 < float(r["peak_memory_mib"]) < 24 * 1024 for r in rows),
      f"peak memory per rank in MiB: {[r['peak_memory_mib'] for r in rows]}")
keys = [(r["problem"], r["resolution"], r["preconditioner"]) for r in rows]
check(len(rows) == 2 * 2 * len(configs), f"{len(rows)} rows for 2 resolutions x 2 time steps x {len(configs)} solvers")
check(len(set(keys)) == len(keys), "one row per (problem, resolution, preconditioner)")
check(all(r["converged"] == "1" and float(r["relative_residual"]) < 1e-5 for r in rows), "every solve converged")
check(all(int(r["ranks"]) == args.ranks for r in rows), "ranks column")
# The same problem has the same size whatever the configuration.
sizes = {}
for r in rows:
    sizes.setdefault((r["problem"], r["resolution"]), set()).add(r["dofs"])
check(all(len(s) == 1 for s in sizes.values()), "dofs agree across configurations of a problem")
# Several scenes, the time step a run takes (particle CFL) and a smallest cell size per scene:
# with the scene's Max time step raised (a study-wide override) the sponge's bullet (4 m/s)
# limits the step, CFL·Δx/|v| at both sizes (∝ Δx), and the entry with Smallest cell size 0.07
# leaves out 0.06.
scenes_study = os.path.join(args.workdir, "scenes.xml")
with open(scenes_study, "w") as f:
    f.write(f"""<ParameterList name="s">
  <Parameter name="Cell sizes" type="Array(double)" value="{{0.075, 0.06}}"/>
  <Parameter name="Time steps" type="Array(double)" value="{{1}}"/>
  <Parameter name="Time step unit" type="string" value="particle CFL"/>
  <Parameter name="Scene overrides" type="Array(string)" value="{{Simulation/Max time step=0.1}}"/>
  <ParameterList name="Scenes">
    <ParameterList name="sponge">
      <Parameter name="Scene" type="string" value="{args.inputs}/scenes/shooting_sponge.xml"/>
    </ParameterList>
    <ParameterList name="sponge moved">
      <Parameter name="Scene" type="string" value="{args.inputs}/scenes/shooting_sponge.xml"/>
      <Parameter name="Smallest cell size" type="double" value="0.07"/>
    </ParameterList>
  </ParameterList>
  <Parameter name="Solvers" type="Array(string)" value="{{{os.path.join(solvers, "jacobi_cg.xml")}}}"/>
  <Parameter name="Plot" type="bool" value="false"/>
</ParameterList>""")
result = run(args.study, scenes_study, "--output", out + "_scenes")
check(result.returncode == 0, f"a study of two scenes exits 0: {result.stderr[-1500:]}")
rows = list(csv.DictReader(open(os.path.join(out + "_scenes", "study.csv")))) if result.returncode == 0 else []
check(sorted((r["problem"].split(" t=")[0], r["resolution"]) for r in rows)
      == [("sponge", "0.06"), ("sponge", "0.075"), ("sponge moved", "0.075")],
      f"one row per scene and cell size, 0.06 left out for the second: {[(r['problem'], r['resolution']) for r in rows]}")
steps = {r["resolution"]: float(r["problem"].split("dt=")[1].split("s")[0]) for r in rows if r["problem"].startswith("sponge t=")}
check(len(steps) == 2 and abs(steps["0.06"] / steps["0.075"] - 0.06 / 0.075) < 0.02,
      f"the particle-CFL step scales with the cell: {steps}")

# Unpreconditioned CG that cannot converge in its iteration budget is a row, not a crash.
budget = os.path.join(args.workdir, "tiny_budget.xml")
with open(budget, "w") as f:
    f.write("""<ParameterList name="tiny"><Parameter name="Label" type="string" value="starved"/>
  <Parameter name="Preconditioner" type="string" value="none"/>
  <ParameterList name="Krylov parameters"><Parameter name="Maximum Iterations" type="int" value="3"/>
  </ParameterList></ParameterList>""")
result = run(args.study, study, "--output", out + "_budget", "--set", f"Solvers={{{budget}}}",
             "--set", "Cell sizes={0.075}", "--set", "Time steps={20}")
check(result.returncode == 0, "a study with a failing configuration still exits 0")
rows = list(csv.DictReader(open(os.path.join(out + "_budget", "study.csv")))) if result.returncode == 0 else []
check(len(rows) == 1 and rows[0]["converged"] == "0", f"the failed solve is a row with converged=0: {rows}")
check(len(rows) == 1 and int(rows[0]["dofs"]) > 0 and int(rows[0]["nonzeros"]) > 0,
      f"the failed row keeps the system's size: {rows}")

# MatrixMarket round trip: a run writes step 2's first Newton system; the study reads it back.
run_dir = os.path.join(args.workdir, "run")
result = run(args.viscompm, os.path.join(args.inputs, "scenes", "shooting_sponge.xml"), "--output", run_dir,
             "--frames", "1", "--set", "Grid/Cell size=0.06", "--set", "Output/Matrix Market steps={2}",
             "--set", "Newton/Linear tolerance=fixed", "--set", "Newton/Hessian update=every iteration",
             "--solver", os.path.join(solvers, "jacobi_cg.xml"))
check(result.returncode == 0, f"run with a MatrixMarket dump exits 0: {result.stderr[-1500:]}")
logged = [r for r in csv.DictReader(open(os.path.join(run_dir, "solver.csv")))
          if r["step"] == "2" and r["newton_iteration"] == "1"] if result.returncode == 0 else []
mm_study = os.path.join(args.workdir, "mm.xml")
assembled = ["jacobi_cg.xml"] + sorted(f for f in os.listdir(solvers)
                                       if f.endswith(".xml") and f != "jacobi_cg.xml" and "matrix_free" not in f
                                       and "Choose between" not in open(os.path.join(solvers, f)).read())
with open(mm_study, "w") as f:
    f.write(f"""<ParameterList name="mm">
  <Parameter name="Matrix Market files" type="Array(string)" value="{{{run_dir}/newton_step_2.mtx}}"/>
  <Parameter name="Solvers" type="Array(string)" value="{{{', '.join(os.path.join(solvers, c) for c in assembled)}}}"/>
  <Parameter name="Plot" type="bool" value="false"/>
</ParameterList>""")
check(os.path.exists(os.path.join(run_dir, "newton_step_2_coordinates.mtx")), "the dump carries node coordinates")
result = run(args.study, mm_study, "--output", out + "_mm")
check(result.returncode == 0, f"MatrixMarket study exits 0: {result.stderr[-1500:]}")
rows = list(csv.DictReader(open(os.path.join(out + "_mm", "study.csv")))) if result.returncode == 0 else []
if logged and rows:
    check(abs(int(rows[0]["iterations"]) - int(logged[0]["linear_iterations"])) <= 1,
          f"the read-back system takes the run's iterations: {rows[0]['iterations']} vs {logged[0]['linear_iterations']}")
    check(abs(float(rows[0]["relative_residual"]) - float(logged[0]["relative_residual"]))
          <= 0.05 * float(logged[0]["relative_residual"]),
          f"and reaches the run's residual: {rows[0]['relative_residual']} vs {logged[0]['relative_residual']}")
    check(len(rows) == len(assembled) and all(r["converged"] == "1" for r in rows),
          f"every assembled solver file solves the dump: {[(r['preconditioner'], r['converged']) for r in rows]}")
    check(all(int(r["dofs"]) == int(rows[0]["dofs"]) > 0 and int(r["nonzeros"]) > 0 for r in rows), "sizes")
else:
    check(False, "MatrixMarket round trip produced rows")

# Bad input (issue 17, class 5): exit 2 within seconds, one line naming the file and the parameter,
# and the results of the run before (study.csv, operators.csv of out_mm) left as they were.
def stderr_lines(result):
    return [line for line in result.stderr.splitlines() if line.startswith("viscompm-study")]


def previous_results(directory):
    names = ("study.csv", "operators.csv")
    return {n: open(os.path.join(directory, n)).read() for n in names if os.path.exists(os.path.join(directory, n))}


before = previous_results(out + "_mm")
check(len(before) == 2, "the MatrixMarket study left study.csv and operators.csv")
cut = os.path.join(args.workdir, "cut")
os.makedirs(cut, exist_ok=True)
with open(os.path.join(run_dir, "newton_step_2.mtx")) as f:
    matrix = f.read().splitlines()
with open(os.path.join(run_dir, "newton_step_2_rhs.mtx")) as f:
    rhs = f.read().splitlines()
with open(os.path.join(cut, "short.mtx"), "w") as f:  # the size line promises more entries
    f.write("\n".join(matrix[:len(matrix) // 2]) + "\n")
with open(os.path.join(cut, "bad_rhs.mtx"), "w") as f:  # a right-hand side with a word in it
    f.write("\n".join(matrix) + "\n")
with open(os.path.join(cut, "bad_rhs_rhs.mtx"), "w") as f:
    f.write("\n".join(rhs[:10] + ["abc"] + rhs[11:]) + "\n")
with open(os.path.join(cut, "short_rhs_rhs.mtx"), "w") as f:  # a right-hand side cut short
    f.write("\n".join(rhs[:len(rhs) // 2]) + "\n")
os.link(os.path.join(cut, "bad_rhs.mtx"), os.path.join(cut, "short_rhs.mtx"))
with open(mm_study) as f:
    mm_text = f.read()
cases = [("a missing scene", [f"Scene={args.workdir}/no_such_scene.xml", "Cell sizes={0.06}"], mm_study, "'Scene'"),
         ("a missing solver file", [f"Solvers={{{solvers}/no_such_solver.xml}}"], mm_study, "'Solvers'"),
         ("a measured choice of solvers", [f"Solvers={{{solvers}/measured_choice_cg.xml}}"], mm_study, "'Solvers'"),
         ("a missing MatrixMarket file", [f"Matrix Market files={{{cut}/none.mtx}}"], mm_study,
          "'Matrix Market files'"),
         ("a matrix cut short", [f"Matrix Market files={{{cut}/short.mtx}}"], os.path.join(cut, "short.mtx"),
          "announces"),
         ("a malformed right-hand side", [f"Matrix Market files={{{cut}/bad_rhs.mtx}}"],
          os.path.join(cut, "bad_rhs_rhs.mtx"), "right-hand side"),
         ("a right-hand side cut short", [f"Matrix Market files={{{cut}/short_rhs.mtx}}"],
          os.path.join(cut, "short_rhs_rhs.mtx"), "right-hand side")]
for what, sets, named_file, named_parameter in cases:
    started = time.time()
    result = run(args.study, mm_study, "--output", out + "_mm", *[a for s_ in sets for a in ("--set", s_)])
    lines = stderr_lines(result)
    check(result.returncode == 2, f"{what}: exit 2, got {result.returncode}: {result.stderr[-800:]}")
    check(len(lines) == 1 and named_file in lines[0] and named_parameter in lines[0],
          f"{what}: one line naming {named_file} and {named_parameter}: {lines}")
    check(time.time() - started < 10, f"{what}: answered within seconds ({time.time() - started:.1f} s)")
    check(previous_results(out + "_mm") == before, f"{what}: the earlier study.csv and operators.csv are intact")

# A study file, or a solver file it lists, nested 10 000 levels deep: exit 2 naming the file and the
# bound (issue 24: Teuchos' parser used to overflow its stack).
deep = os.path.join(args.workdir, "deep.xml")
with open(deep, "w") as f:
    f.write("".join(f'<ParameterList name="l{i}">\n' for i in range(10000)) + "</ParameterList>\n" * 10000)
for what, command in (("a deep study file", [deep]),
                      ("a deep solver file", [mm_study, "--set", f"Solvers={{{deep}}}"])):
    started = time.time()
    result = run(args.study, *command, "--output", out + "_mm")
    lines = stderr_lines(result)
    check(result.returncode == 2 and len(lines) == 1 and deep in lines[0] and "nested more than 32 levels" in lines[0],
          f"{what}: exit 2 and one line naming {deep} and the bound, got {result.returncode}: {result.stderr[-800:]}")
    check(time.time() - started < 10, f"{what}: answered within seconds ({time.time() - started:.1f} s)")
    check(previous_results(out + "_mm") == before, f"{what}: the earlier study.csv and operators.csv are intact")

# The steps mode: two frames of the coarse sponge per configuration, exact and lagged Newton.
steps_study = os.path.join(args.workdir, "steps.xml")
with open(steps_study, "w") as f:
    f.write(f"""<ParameterList name="steps">
  <Parameter name="Mode" type="string" value="steps"/>
  <Parameter name="Scene" type="string" value="{args.inputs}/scenes/shooting_sponge.xml"/>
  <Parameter name="Frames" type="int" value="2"/>
  <Parameter name="Scene overrides" type="Array(string)" value="{{Grid/Cell size=0.06}}"/>
  <Parameter name="Plot" type="bool" value="false"/>
  <ParameterList name="Configurations">
    <ParameterList name="exact Newton">
      <Parameter name="Solver" type="string" value="{solvers}/jacobi_cg.xml"/>
      <Parameter name="Newton" type="Array(string)" value="{{Linear tolerance=fixed, Hessian update=every iteration}}"/>
    </ParameterList>
    <ParameterList name="once per step">
      <Parameter name="Solver" type="string" value="{solvers}/jacobi_cg.xml"/>
      <Parameter name="Newton" type="Array(string)" value="{{Linear tolerance=fixed, Hessian update=every step}}"/>
    </ParameterList>
    <ParameterList name="paper">
      <Parameter name="Solver" type="string" value="{solvers}/matrix_free_jacobi_cg.xml"/>
      <Parameter name="Newton" type="Array(string)" value="{{Linear tolerance=fixed, Hessian update=every iteration}}"/>
    </ParameterList>
  </ParameterList>
</ParameterList>""")
result = run(args.study, steps_study, "--output", out + "_steps")
check(result.returncode == 0, f"steps study exits 0: {result.stderr[-1500:]}")
rows = list(csv.DictReader(open(os.path.join(out + "_steps", "steps.csv")))) if result.returncode == 0 else []
check([r["configuration"] for r in rows] == ["exact Newton", "once per step", "paper"], f"steps.csv rows {rows}")
if len(rows) == 3:
    exact, once, paper = rows
    check(int(exact["assemblies"]) >= int(exact["newton_iterations"]) > 0, "exact Newton assembles every iteration")
    check(int(once["assemblies"]) < int(once["newton_iterations"]), "once per step keeps H within a step")
    check(int(once["assemblies"]) >= int(once["steps"]), "and assembles at least once per step")
    check(exact["steps"] == paper["steps"], "the same steps whatever the operator")
    for r in rows:
        phases = sum(float(r[k]) for k in ("operator_seconds", "preconditioner_seconds", "cg_seconds",
                                          "line_search_seconds"))
        check(0.0 < phases <= float(r["wall_seconds"]) * 1.001, f"phases within the wall time: {r}")
        check(abs(float(r["seconds_per_frame"]) * 2 - float(r["wall_seconds"])) < 1e-7 * float(r["wall_seconds"]),
              "seconds per frame")
    check(all(float(r["cell_size"]) == 0.06 for r in rows), "cell_size: the scene override's")
# The steps mode at two cell sizes: one row per configuration and size, the size as asked (a
# Cell sizes entry overrides the scene overrides' Grid/Cell size).
result = run(args.study, steps_study, "--output", out + "_sizes", "--set", "Cell sizes={0.06, 0.075}",
             "--set", "Frames=1")
check(result.returncode == 0, f"steps study at two sizes exits 0: {result.stderr[-1500:]}")
rows = list(csv.DictReader(open(os.path.join(out + "_sizes", "steps.csv")))) if result.returncode == 0 else []
check([(r["configuration"], float(r["cell_size"])) for r in rows] ==
      [(c, h) for h in (0.06, 0.075) for c in ("exact Newton", "once per step", "paper")], f"steps.csv rows {rows}")
if len(rows) == 6:
    check(int(rows[0]["cg_iterations"]) != int(rows[3]["cg_iterations"]), "the sizes are different problems")
# A steps study whose configuration names a Newton parameter that does not exist is bad input.
with open(steps_study) as f:
    bad = f.read().replace("Hessian update=every step", "Hessian updates=every step")
with open(steps_study, "w") as f:
    f.write(bad)
result = run(args.study, steps_study, "--output", out + "_bad")
check(result.returncode == 2 and "Hessian updates" in result.stderr, f"bad Newton override: {result.stderr[-500:]}")

finish()
