#!/usr/bin/env python3
"""Tables of bench/fidelity.sh: one row per model and configuration (faces,
elements per cell, size deviation p95/p99/max, wrong-sheet share, Hausdorff /
diagonal, element-count change, simplify seconds), the median elements per
cell, and the ratio of each configuration's cells to the first one's.

Usage: fidelity.py DIR CONFIG... (reads DIR/CONFIG/MODEL/report.json)."""
import json
import statistics
import sys
from pathlib import Path


def load(d: Path):
    try:
        return json.loads((d / "report.json").read_text())
    except (OSError, ValueError):
        return None


def row(m, r):
    e = r["metrics"]
    sd = e["size_deviation"]
    simp = r["seconds"].get("simplify", float("nan"))
    return (f"| {m} | {e['faces_reference']} | {e['faces_candidate']} | {e['elements_per_cell']:.1f} "
            f"| {sd['p95']:.3f} | {sd['p99']:.3f} | {sd['max']:.3f} | {e['wrong_sheet']:.1e} "
            f"| {100 * e['hausdorff_relative']:.3f} | {100 * e['element_count_change']:+.2f} | {simp:.1f} |")


def main():
    root, configs = Path(sys.argv[1]), sys.argv[2:]
    models = sorted({p.name for c in configs for p in (root / c).iterdir() if p.is_dir()})
    cells = {}
    for c in configs:
        print(f"## {c}\n")
        print("| model | dense faces | faces | elements/cell | size dev p95 | p99 | max | wrong sheet "
              "| Hausdorff % diag | elements Δ % | simplify s |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for m in models:
            r = load(root / c / m)
            if r is None:
                print(f"| {m} | failed | | | | | | | | | |")
                continue
            print(row(m, r))
            cells[(c, m)] = r["metrics"]["elements_per_cell"]
        vals = [cells[(c, m)] for m in models if (c, m) in cells]
        if vals:
            print(f"\nmedian elements per cell: {statistics.median(vals):.1f} over {len(vals)} models\n")
    if len(configs) > 1:
        base = configs[0]
        print(f"## elements per cell against {base}\n")
        print("| model | " + " | ".join(configs) + " | " + " | ".join(f"{c}/{base}" for c in configs[1:]) + " |")
        print("|---|" + "---:|" * (2 * len(configs) - 1))
        for m in models:
            v = [cells.get((c, m)) for c in configs]
            ratios = [f"{x / v[0]:.2f}" if x and v[0] else "" for x in v[1:]]
            print(f"| {m} | " + " | ".join(f"{x:.1f}" if x else "" for x in v) + " | " + " | ".join(ratios) + " |")


if __name__ == "__main__":
    main()
