#!/usr/bin/env bash
# Fidelity per cell on the shared models: runs `abgs run` (dense grid → sizes →
# LBO-ABGS → evaluation) per model and configuration, then writes one markdown
# table per configuration and a before/after comparison (bench/fidelity.py).
#
# Usage: bench/fidelity.sh [--big] [--config NAME=ARGS]... [MODEL ...]
#   MODEL     a file name under ../shared/meshes without extension
#             (default: every STL/OBJ/OFF there, the two largest only with --big)
#   --big     include trimesh_fm1_satellite and trimesh_cycloidal (~40 min each)
#   --config  NAME=ARGS: extra `abgs run` arguments under a name; repeatable
#             (default: "paper=--tau-d 0.05 --clearance 0" — the fixed rule
#             of the paper, as main had it before the derived envelope — and
#             "default=" — the library's defaults)
# Environment: ABGS_FIDELITY_DIR (default target/fidelity): results per
# configuration and model (report.json), and fidelity.md.
# Each run is single-threaded-independent (its results are the same bits for
# any thread count), so runs go one after another, each with every core.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
big=0 configs=() models=()
while (($#)); do
  case $1 in
    --big) big=1 ;;
    --config) configs+=("$2"); shift ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    -*) echo "unknown option $1" >&2; exit 2 ;;
    *) models+=("$1") ;;
  esac
  shift
done
((${#configs[@]})) || configs=("paper=--tau-d 0.05 --clearance 0" "default=")
source bench/models.sh
((${#models[@]})) || mapfile -t models < <(shared_models "$big")
out=${ABGS_FIDELITY_DIR:-$repo/target/fidelity}
mkdir -p "$out"
cargo build --release -q -p abgs-cli
abgs=$repo/target/release/abgs
names=()
for c in "${configs[@]}"; do
  name=${c%%=*} args=${c#*=}
  names+=("$name")
  for m in "${models[@]}"; do
    f=$(model_file "$m")
    dir=$out/$name/$m
    mkdir -p "$dir"
    echo "== $name: $m" >&2
    # shellcheck disable=SC2086
    /usr/bin/time -f '%e s %M KB' -o "$dir/time.txt" \
      "$abgs" run "$f" -o "$dir" --no-images $args >"$dir/log.txt" 2>&1 ||
      echo "   failed (see $dir/log.txt)" >&2
    tail -2 "$dir/log.txt" | head -1 >&2
  done
done
python3 bench/fidelity.py "$out" "${names[@]}" >"$out/fidelity.md"
echo "wrote $out/fidelity.md" >&2
