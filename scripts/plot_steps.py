#!/usr/bin/python3
"""Plot a viscompm-study steps.csv: wall seconds per frame of each configuration, split into the
phases of the Newton solve (operator preparation, preconditioner set-up, CG, line search) and the
rest of the step, with Newton and CG iteration counts (one bar per configuration and cell size). Usage: plot_steps.py steps.csv steps.png

A missing or damaged CSV, a missing column or number, or a PNG that cannot be written is one line
on stderr naming the file, exit 2 (doc/contracts.md)."""
import argparse
import csv
import sys

NUMBERS = ["frames", "seconds_per_frame", "operator_seconds", "preconditioner_seconds", "cg_seconds",
           "line_search_seconds", "newton_iterations", "cg_iterations", "ranks"]


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, not argparse's usage block
        self.exit(2, f"{self.prog}: {message} (see --help)\n")


def fail(message):
    sys.stderr.write(f"plot_steps.py: {message}\n")
    sys.exit(2)


def read_rows(path):
    """The rows of steps.csv, every column this plot needs present and a number."""
    try:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            rows = list(reader)
            columns = reader.fieldnames or []
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        fail(f"{path}: cannot read ({getattr(e, 'strerror', None) or e})")
    missing = [c for c in NUMBERS + ["configuration", "cell_size"] if c not in columns]
    if missing:
        fail(f"{path}: not a viscompm-study steps.csv (no column {', '.join(missing)})")
    for line, r in enumerate(rows, 2):
        for c in NUMBERS:
            try:
                float(r[c])
            except (TypeError, ValueError):
                fail(f"{path}: line {line}: column '{c}' is {r[c]!r}, not a number (a damaged file?)")
        if float(r["frames"]) <= 0:
            fail(f"{path}: line {line}: column 'frames' is {r['frames']}, not a positive number")
    return rows


def main():
    parser = Parser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv", help="a viscompm-study steps.csv")
    parser.add_argument("png", help="the plot to write")
    args = parser.parse_args()
    rows = read_rows(args.csv)

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        fail("needs matplotlib (Debian: python3-matplotlib; scripts/setup.sh installs it)")

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
    try:
        fig.savefig(args.png, dpi=100)
    except (OSError, ValueError) as e:
        fail(f"{args.png}: cannot write ({getattr(e, 'strerror', None) or e})")
    print("plot:", args.png)


if __name__ == "__main__":
    main()
