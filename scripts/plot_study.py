#!/usr/bin/env python3
"""Plot a viscompm-study CSV: iterations and time to solution (set-up + solve) against unknowns,
one line per preconditioner and time step. Usage: plot_study.py study.csv study.png"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

rows = list(csv.DictReader(open(sys.argv[1])))
series = defaultdict(list)
for r in rows:
    problem = r["problem"]
    step = problem.split(" dt=")[-1] if " dt=" in problem else problem
    series[(r["preconditioner"], step)].append(
        (int(r["dofs"]), int(r["iterations"]), float(r["setup_seconds"]) + float(r["solve_seconds"]),
         r["converged"] == "1"))

fig, (ax_it, ax_t) = plt.subplots(1, 2, figsize=(12, 5))
# One colour per configuration, one line style per time step.
labels = sorted({label for label, _ in series})
steps = sorted({step for _, step in series})
colours = {label: plt.get_cmap("tab10")(k % 10) for k, label in enumerate(labels)}
styles = {step: ["-", "--", ":", "-."][k % 4] for k, step in enumerate(steps)}
for (label, step), points in sorted(series.items()):
    points.sort()
    dofs = [p[0] for p in points]
    style = dict(marker="o", color=colours[label], linestyle=styles[step], label=f"{label} (dt={step})")
    ax_it.plot(dofs, [p[1] for p in points], **style)
    ax_t.plot(dofs, [p[2] for p in points], **style)
    failed = [p for p in points if not p[3]]
    if failed:
        ax_it.plot([p[0] for p in failed], [p[1] for p in failed], "x", color="red", markersize=10)
for ax, title in ((ax_it, "CG iterations"), (ax_t, "set-up + solve [s]")):
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("unknowns")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
ax_it.legend(fontsize=7)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=100)
print("plot:", sys.argv[2])
