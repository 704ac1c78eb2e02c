#!/usr/bin/env python3
"""Table of bench/gcn_vs_lbo.sh: per model, LBO-ABGS and GCN-ABGS on the same
sized dense grid: faces, reduction, size deviation p95 / max, element-count
change, Hausdorff / diagonal, simplify seconds (wall, from the report), and
the acceptance checks of the GCN-ABGS issue: GCN faces within 20 % of
LBO-ABGS's, GCN size deviation p95 <= 1.2, and on dense grids over 200k faces
a simplify time at least 5x shorter.

Usage: gcn_vs_lbo.py DIR (reads DIR/MODEL/{lbo,gcn}.{report,eval}.json)."""
import json
import sys
from pathlib import Path


def load(p: Path):
    try:
        return json.loads(p.read_text())
    except (OSError, ValueError):
        return None


def main():
    root = Path(sys.argv[1])
    print("| model | dense faces | method | faces | reduction % | size dev p95 | max "
          "| elements Δ % | Hausdorff % diag | simplify s |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|")
    checks = []
    for d in sorted(p for p in root.iterdir() if p.is_dir()):
        res = {}
        for method in ("lbo", "gcn"):
            ev, rep = load(d / f"{method}.eval.json"), load(d / f"{method}.report.json")
            if ev is None or rep is None:
                print(f"| {d.name} | | {method} | failed | | | | | | |")
                continue
            secs = rep["report"]["seconds"]
            res[method] = (ev, secs)
            sd = ev["size_deviation"]
            print(f"| {d.name} | {ev['faces_reference']} | {method} | {ev['faces_candidate']} "
                  f"| {100 * ev['reduction']:.1f} | {sd['p95']:.3f} | {sd['max']:.3f} "
                  f"| {100 * ev['element_count_change']:+.2f} | {100 * ev['hausdorff_relative']:.3f} "
                  f"| {secs:.1f} |")
        if len(res) == 2:
            (el, sl), (eg, sg) = res["lbo"], res["gcn"]
            faces = eg["faces_candidate"] / el["faces_candidate"] - 1
            speed = sl / sg if sg > 0 else float("inf")
            big = el["faces_reference"] > 200_000
            checks.append((d.name, el["faces_reference"], faces, eg["size_deviation"]["p95"], speed, big))
    print("\n| model | dense faces | GCN faces vs LBO | within 20 % | GCN p95 <= 1.2 | speed-up | >= 5x (over 200k) |")
    print("|---|---:|---:|---|---|---:|---|")
    for name, n, faces, p95, speed, big in checks:
        print(f"| {name} | {n} | {100 * faces:+.1f} % | {'yes' if abs(faces) <= 0.2 else 'NO'} "
              f"| {'yes' if p95 <= 1.2 else 'NO'} | ×{speed:.1f} | {('yes' if speed >= 5 else 'NO') if big else '—'} |")


if __name__ == "__main__":
    main()
