#!/usr/bin/env bash
# Growth of `abgs run` with the input: a synthetic assembly (copies of one
# shared model, apart on a lattice, bench/replicate.py) replicated 1, 4, 16,
# 64 times, and with --big the two largest shared models. Per run: seconds per
# stage (report.json), peak RSS, dense faces, microseconds and bytes per dense
# face, dense faces per second; then the growth of time per dense face from
# the smallest to the largest assembly (the issue's goal: at most 1.3x).
#
# Usage: bench/scale.sh [--big] [--base MODEL] [--counts "1 4 16 64"]
#   MODEL  a shared model (../shared/meshes/MODEL.stl; default occt_crankarm)
# ABGS_MESHES moves ../shared/meshes.
# Each copy keeps the dense grid's resolution of one copy alone: `--relative`
# is 0.01 x (diagonal of one copy / diagonal of the assembly). Sizes and the
# simplifier keep their defaults (relative to the assembly's diagonal).
# Environment: ABGS_SCALE_DIR (default target/scale): the inputs, the run
# folders, scale.md; ABGS_BIN: an abgs binary to use instead of building one.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
big=0 base=occt_crankarm counts="1 4 16 64"
while (($#)); do
  case $1 in
    --big) big=1 ;;
    --base) base=$2; shift ;;
    --counts) counts=$2; shift ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "unknown argument $1" >&2; exit 2 ;;
  esac
  shift
done
out=${ABGS_SCALE_DIR:-$repo/target/scale}
meshes=${ABGS_MESHES:-../shared/meshes}
mkdir -p "$out"
source "$repo/bench/abgs_bin.sh"
runs=()
one() { # one NAME INPUT [abgs run options...]
  local name=$1 input=$2
  shift 2
  echo "== $name" >&2
  /usr/bin/time -f '%e %M' -o "$out/$name.time" \
    "$abgs" run "$input" -o "$out/$name" --no-images "$@" >"$out/$name.log" 2>&1 ||
    { echo "   failed (see $out/$name.log)" >&2; return 0; }
  runs+=("$name")
  tail -1 "$out/$name.log" >&2
}
for n in $counts; do
  info=$(python3 bench/replicate.py "$meshes/$base.stl" "$n" "$out/${base}_x$n.stl")
  rel=$(python3 -c "import json,sys; i=json.loads(sys.argv[1]); print(0.01 * i['diagonal_one'] / i['diagonal'])" "$info")
  one "${base}_x$n" "$out/${base}_x$n.stl" --relative "$rel"
done
if ((big)); then
  for m in trimesh_cycloidal trimesh_fm1_satellite; do
    one "$m" "$meshes/$m.stl"
  done
fi
python3 - "$out" "${runs[@]}" >"$out/scale.md" <<'PY'
import json, sys
out, runs = sys.argv[1], sys.argv[2:]
stages = ["dense grid", "sizes", "simplify", "evaluate", "total"]
print("| run | input faces | dense faces | " + " | ".join(f"{s} s" for s in stages)
      + " | peak RSS MB | µs / dense face | bytes / dense face | dense faces / s |")
print("|---|---:|---:|" + "---:|" * (len(stages) + 4))
per_face = []
for r in runs:
    rep = json.load(open(f"{out}/{r}/report.json"))
    # The peak from report.json (the run's own VmHWM reading). /usr/bin/time
    # is only a fallback for a report without one: binaries before commit
    # 8c0179c reset VmHWM per stage, which lowered what it reported.
    wall, rss_kb = open(f"{out}/{r}.time").read().split()
    peak = (rep.get("memory") or {}).get("peak_rss_bytes") or 1024 * int(rss_kb)
    c, s = rep["counts"], rep["seconds"]
    f = c["dense_faces"]
    us = 1e6 * s["total"] / f
    if "_x" in r:
        per_face.append((f, us, r))
    print(f"| {r} | {c['input_faces']} | {f} | " + " | ".join(f"{s.get(k, 0):.1f}" for k in stages)
          + f" | {peak / 2**20:.0f} | {us:.0f} | {peak / f:.0f} | {f / s['total']:.0f} |")
if len(per_face) >= 2:
    (f0, u0, r0), (f1, u1, r1) = min(per_face), max(per_face)
    print(f"\nTime per dense face, {r1} ({f1} faces) against {r0} ({f0}): x{u1 / u0:.2f} (goal <= 1.3).")
PY
cat "$out/scale.md"
