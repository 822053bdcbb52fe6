#!/usr/bin/python3
"""Plot a viscompm-study CSV: iterations and time to solution (set-up + solve) against unknowns,
one line per preconditioner and time step. Usage: plot_study.py study.csv study.png

A missing or damaged CSV, a missing column or number, or a PNG that cannot be written is one line
on stderr naming the file, exit 2 (doc/contracts.md)."""
import argparse
import csv
import sys
from collections import defaultdict

INTEGERS = ["dofs", "iterations"]
REALS = ["setup_seconds", "solve_seconds"]


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, not argparse's usage block
        self.exit(2, f"{self.prog}: {message} (see --help)\n")


def fail(message):
    sys.stderr.write(f"plot_study.py: {message}\n")
    sys.exit(2)


def read_rows(path):
    """The rows of study.csv, every column this plot needs present, its numbers numbers."""
    try:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            rows = list(reader)
            columns = reader.fieldnames or []
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        fail(f"{path}: cannot read ({getattr(e, 'strerror', None) or e})")
    missing = [c for c in ["problem", "preconditioner", "converged"] + INTEGERS + REALS if c not in columns]
    if missing:
        fail(f"{path}: not a viscompm-study study.csv (no column {', '.join(missing)})")
    for line, r in enumerate(rows, 2):
        for c, kind in [(c, int) for c in INTEGERS] + [(c, float) for c in REALS]:
            try:
                kind(r[c])
            except (TypeError, ValueError):
                fail(f"{path}: line {line}: column '{c}' is {r[c]!r}, not a number (a damaged file?)")
        if r["problem"] is None or r["preconditioner"] is None or r["converged"] is None:
            fail(f"{path}: line {line}: fewer columns than the header (a damaged file?)")
    return rows


def main():
    parser = Parser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv", help="a viscompm-study study.csv")
    parser.add_argument("png", help="the plot to write")
    args = parser.parse_args()
    rows = read_rows(args.csv)

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        fail("needs matplotlib (Debian: python3-matplotlib; scripts/setup.sh installs it)")

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
    if series:
        ax_it.legend(fontsize=7)
    fig.tight_layout()
    try:
        fig.savefig(args.png, dpi=100)
    except (OSError, ValueError) as e:
        fail(f"{args.png}: cannot write ({getattr(e, 'strerror', None) or e})")
    print("plot:", args.png)


if __name__ == "__main__":
    main()
