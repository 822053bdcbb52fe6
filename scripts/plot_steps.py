#!/usr/bin/env python3
"""Plot a viscompm-study steps.csv: wall seconds per frame of each configuration, split into the
phases of the Newton solve (operator preparation, preconditioner set-up, CG, line search) and the
rest of the step, with Newton and CG iteration counts (one bar per configuration and cell size). Usage: plot_steps.py steps.csv steps.png"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

rows = list(csv.DictReader(open(sys.argv[1])))
several_sizes = len({r.get("cell_size") for r in rows}) > 1
labels = [f'{r["configuration"]}, Δx {r["cell_size"]}' if several_sizes else r["configuration"] for r in rows]
frames = [float(r["frames"]) for r in rows]
phases = [("operator_seconds", "operator (assembly / matrix-free set-up)"),
          ("preconditioner_seconds", "preconditioner set-up"), ("cg_seconds", "CG"),
          ("line_search_seconds", "line search")]
fig, ax = plt.subplots(figsize=(max(6, 1.6 * len(rows)), 5))
bottom = [0.0] * len(rows)
for key, name in phases:
    values = [float(r[key]) / f for r, f in zip(rows, frames)]
    ax.bar(labels, values, bottom=bottom, label=name)
    bottom = [b + v for b, v in zip(bottom, values)]
rest = [max(0.0, float(r["seconds_per_frame"]) - b) for r, b in zip(rows, bottom)]
ax.bar(labels, rest, bottom=bottom, label="rest of the step (gradient, transfers, layout)", color="lightgrey")
for k, r in enumerate(rows):
    ax.text(k, float(r["seconds_per_frame"]), f"{r['newton_iterations']} Newton\n{r['cg_iterations']} CG",
            ha="center", va="bottom", fontsize=7)
ax.set_ylabel("wall seconds per frame")
ax.set_title(f"{rows[0]['frames']} frames, {rows[0]['ranks']} rank(s)" if rows else "")
ax.legend(fontsize=7)
plt.setp(ax.get_xticklabels(), rotation=20, ha="right", fontsize=8)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=100)
print("plot:", sys.argv[2])
