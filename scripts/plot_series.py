#!/usr/bin/env python3
"""Draws PNG plots of fracflow CSV time series; called by ff::plot_series (src/io/plot.cpp).

Usage: plot_series.py SPEC.json   where SPEC.json holds one job object or a list of them:
  {"csv", "png", "title", "xlabel", "ylabel", "y2label", "x", "y": [...], "y2": [...],
   "x_scale", "y_scale", "y2_scale", "reference_csv", "ref_x", "ref_y", "ref_label", "logx", "logy",
   "equal_aspect", "y_labels": [...]}
Exit codes: 0 all written, 1 some job failed, 2 bad usage, 3 matplotlib or numpy missing.
CSV files: comma-separated, one header line; lines starting with '#' are comments; cells that
are not numbers read as NaN (same rules as ff::read_csv).
"""
import json
import math
import sys

try:
    import matplotlib

    matplotlib.use("Agg")  # no display needed
    import matplotlib.pyplot as plt
    import numpy as np
except ImportError as e:  # reported once by the caller as a warning
    print(f"plot_series.py: {e}; install python3-matplotlib and python3-numpy", file=sys.stderr)
    sys.exit(3)


def to_float(cell):
    try:
        return float(cell)
    except ValueError:
        return math.nan


def read_csv(path):
    """Returns {column name: numpy array}; raises ValueError naming file and line on ragged rows."""
    names, rows = None, []
    with open(path, encoding="utf-8", errors="replace") as f:
        for number, line in enumerate(f, 1):
            text = line.strip()
            if not text or text.startswith("#"):
                continue
            cells = [c.strip() for c in text.split(",")]
            if names is None:
                names = [c[1:-1] if len(c) >= 2 and c[0] == c[-1] == '"' else c for c in cells]
                continue
            if len(cells) != len(names):
                raise ValueError(f"{path}:{number}: {len(cells)} fields, but the header has {len(names)} columns")
            rows.append([to_float(c) for c in cells])
    if names is None:
        raise ValueError(f"{path}: no header line")
    data = np.array(rows, dtype=float).reshape(len(rows), len(names))
    return {n: data[:, i] for i, n in enumerate(names)}


# Column names end in their SI unit (fracflow's rule: "axial_stress_Pa", "time_s"); the axis
# labels give the plotted unit (often scaled, e.g. MPa), so legends leave the suffix out.
UNIT_SUFFIXES = ("_m2_per_s2", "_m2_per_s", "_N_per_m", "_m_per_s", "_Pa", "_J", "_s", "_m")


def legend_label(name):
    for suffix in UNIT_SUFFIXES:
        if name.endswith(suffix) and len(name) > len(suffix):
            return name[: -len(suffix)]
    return name


def column(table, name, path):
    if name not in table:
        raise ValueError(f"{path}: no column '{name}' (columns: {', '.join(table)})")
    return table[name]


def plot(job):
    csv = job["csv"]
    table = read_csv(csv)
    x = column(table, job["x"], csv) * job.get("x_scale", 1.0)
    fig, ax = plt.subplots(figsize=(7.0, 4.5))
    colours = plt.rcParams["axes.prop_cycle"].by_key().get("color", ["C0"])
    lines = []
    names = job.get("y_labels") or []
    for k, name in enumerate(job.get("y", [])):
        colour = colours[len(lines) % len(colours)]
        label = names[k] if k < len(names) else legend_label(name)
        lines += ax.plot(x, column(table, name, csv) * job.get("y_scale", 1.0), color=colour, label=label)
    ref = job.get("reference_csv", "")
    if ref:
        rt = read_csv(ref)
        rx = column(rt, job["ref_x"], ref) * job.get("x_scale", 1.0)
        ry = column(rt, job["ref_y"], ref) * job.get("y_scale", 1.0)
        lines += ax.plot(rx, ry, "o", mfc="none", color="black", label=job.get("ref_label") or "reference")
    ax.set_xlabel(job.get("xlabel") or job["x"])
    ax.set_ylabel(job.get("ylabel", ""))
    if job.get("logx"):
        ax.set_xscale("log")
    if job.get("logy"):
        ax.set_yscale("log")
    if job.get("equal_aspect"):
        ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    if job.get("y2"):
        ax2 = ax.twinx()
        for name in job["y2"]:  # colours continue the left axis's cycle; dashed = right axis
            colour = colours[len(lines) % len(colours)]
            lines += ax2.plot(x, column(table, name, csv) * job.get("y2_scale", 1.0), "--", color=colour, label=legend_label(name))
        ax2.set_ylabel(job.get("y2label", ""))
    if lines:
        ax.legend(lines, [l.get_label() for l in lines], loc="best", fontsize="small")
    if job.get("title"):
        ax.set_title(job["title"])
    fig.tight_layout()
    fig.savefig(job["png"], dpi=120)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    with open(sys.argv[1], encoding="utf-8") as f:
        spec = json.load(f)
    jobs = spec if isinstance(spec, list) else [spec]
    failed = 0
    for job in jobs:
        try:
            plot(job)
        except Exception as e:  # one bad figure must not stop the others
            failed += 1
            print(f"plot_series.py: {job.get('png', '?')}: {e}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
