#!/usr/bin/env bash
# Rebuild the GCN-ABGS model (models/gcn_abgs.onnx, .json, MODEL_CARD.md) from nothing:
#   venv with pinned packages -> abgs CLI (release) -> CAD-like parts (Gmsh/OCC,
#   seeded train / val / test sets) -> per part: dense grid, sizes, LBO-ABGS
#   trajectory with exact labels (abgs dataset) -> training + ONNX export + checks.
#
# Usage: training/build_model.sh            (from anywhere; 36 min on 2 cores plus the venv)
#
# Environment (all optional):
#   ABGS_VENV   venv path (default training/.venv; reused if it exists)
#   ABGS_WORK   work folder for parts and datasets (default training/work; reused:
#               existing parts sets and dataset files are kept, so a rerun resumes)
#   ABGS_OUT    where the model goes (default models/)
#   ABGS_BIN    an abgs binary to use instead of building one
#   PYTHON      interpreter for the venv (default python3, >= 3.10)
#   TORCH_INDEX_URL  install the pinned torch from this index first, e.g.
#               https://download.pytorch.org/whl/cpu (CPU build, no CUDA libraries)
#   JOBS        parallel parts (default 2); each CLI run gets RAYON_NUM_THREADS=1
#   N_TRAIN N_VAL N_TEST   parts per split (default 120 / 15 / 15)
#   SEED        training seed (default 0)
#   EPOCHS      training epochs (default 30); TRAIN_MIN safety stop in minutes (default 30)
#   THREADS     torch threads for training (default 1: on a shared 2-core machine two
#               threads spin-wait and run several times slower than one)
#   GRID_ARGS   options of `abgs grid` (default "--relative 0.03 --n-circle 16": dense
#               grids of 4-47k faces, 16k on average; edges on fillets 3/4 of the
#               curvature size, so still finer than the sizes)
#   DATASET_ARGS options of `abgs dataset` (default "--snapshots 6")
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
VENV=${ABGS_VENV:-$ROOT/training/.venv}
WORK=${ABGS_WORK:-$ROOT/training/work}
OUT=${ABGS_OUT:-$ROOT/models}
PYTHON=${PYTHON:-python3}
JOBS=${JOBS:-2}
N_TRAIN=${N_TRAIN:-120}
N_VAL=${N_VAL:-15}
N_TEST=${N_TEST:-15}
SEED=${SEED:-0}
EPOCHS=${EPOCHS:-30}
TRAIN_MIN=${TRAIN_MIN:-30}
THREADS=${THREADS:-1}
GRID_ARGS=${GRID_ARGS:---relative 0.03 --n-circle 16}
DATASET_ARGS=${DATASET_ARGS:---snapshots 6}
# part seeds per split: part k of a split uses seed base+k, so the bases are
# further apart than the counts (disjoint parts)
SEED_TRAIN=1000 SEED_VAL=20000 SEED_TEST=30000

# the exact invocation, for the model card: every setting that differs from the default
INVOCATION=""
for v in N_TRAIN N_VAL N_TEST SEED EPOCHS TRAIN_MIN GRID_ARGS DATASET_ARGS JOBS THREADS; do
  case "$v=${!v}" in
    "N_TRAIN=120"|"N_VAL=15"|"N_TEST=15"|"SEED=0"|"EPOCHS=30"|"TRAIN_MIN=30"|"JOBS=2") ;;
    "GRID_ARGS=--relative 0.03 --n-circle 16"|"DATASET_ARGS=--snapshots 6"|"THREADS=1") ;;
    *) INVOCATION+="$v=\"${!v}\" " ;;
  esac
done
INVOCATION+="training/build_model.sh"
REV=$(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown)
if [ -n "$(git -C "$ROOT" status --porcelain -- src cli Cargo.toml Cargo.lock 2>/dev/null)" ]; then
  REV+="+uncommitted"
fi
[ -n "${ABGS_BIN:-}" ] && REV="given binary ABGS_BIN, checkout $REV"

t_all=$(date +%s)
stage() { echo "== $* ($(($(date +%s) - t_all)) s)" >&2; }
declare -A T

# 1. venv
stage "venv $VENV"
t=$(date +%s)
if [ ! -x "$VENV/bin/python" ]; then
  "$PYTHON" -m venv "$VENV"
fi
if [ -n "${TORCH_INDEX_URL:-}" ]; then
  "$VENV/bin/pip" install -q --disable-pip-version-check \
    "$(grep '^torch==' "$ROOT/training/requirements.txt")" --index-url "$TORCH_INDEX_URL"
fi
"$VENV/bin/pip" install -q --disable-pip-version-check -r "$ROOT/training/requirements.txt"
T[venv]=$(($(date +%s) - t))

# 2. CLI
stage "abgs CLI"
t=$(date +%s)
if [ -n "${ABGS_BIN:-}" ]; then
  BIN=$ABGS_BIN
else
  (cd "$ROOT" && cargo build --release -q -p abgs-cli)
  BIN=$ROOT/target/release/abgs
fi
"$BIN" --version >&2
T[cli]=$(($(date +%s) - t))

# 3. parts
stage "parts"
t=$(date +%s)
mkdir -p "$WORK"
gen_parts() { # split count seed
  local dir=$WORK/parts/$1
  if [ -f "$dir/parts.json" ] && [ "$(ls "$dir"/part_*.stl 2>/dev/null | wc -l)" -eq "$2" ]; then
    echo "parts $1: reusing $dir" >&2
  else
    rm -rf "$dir"
    "$VENV/bin/python" "$ROOT/training/parts.py" --out "$dir" --count "$2" --seed "$3" --jobs "$JOBS" --quiet
  fi
}
gen_parts train "$N_TRAIN" "$SEED_TRAIN"
gen_parts val "$N_VAL" "$SEED_VAL"
gen_parts test "$N_TEST" "$SEED_TEST"
T[parts]=$(($(date +%s) - t))

# 4. datasets: dense grid -> sizes -> LBO-ABGS trajectory with exact labels
stage "datasets"
t=$(date +%s)
one_part() { # stl -> data/<split>/<name>.safetensors
  local stl=$1 split name tmp out
  split=$(basename "$(dirname "$stl")")
  name=$(basename "$stl" .stl)
  out=$WORK/data/$split/$name.safetensors
  [ -f "$out" ] && return 0
  tmp=$WORK/tmp/$split/$name
  mkdir -p "$tmp" "$WORK/data/$split" "$WORK/logs/$split"
  local log=$WORK/logs/$split/$name.log
  # (the sized grid is named after the part: it is the dataset's "source")
  if RAYON_NUM_THREADS=1 "$BIN" grid "$stl" -o "$tmp/dense.vtk" $GRID_ARGS >"$log" 2>&1 &&
     RAYON_NUM_THREADS=1 "$BIN" size "$tmp/dense.vtk" -o "$tmp/$name.vtk" >>"$log" 2>&1 &&
     RAYON_NUM_THREADS=1 "$BIN" dataset "$tmp/$name.vtk" -o "$tmp/part.safetensors" $DATASET_ARGS >>"$log" 2>&1; then
    mv "$tmp/part.safetensors" "$out"
    rm -rf "$tmp"
  else
    echo "FAILED $split/$name (see $log)" >&2
  fi
  return 0
}
export -f one_part
export BIN WORK GRID_ARGS DATASET_ARGS
ls "$WORK"/parts/{train,val,test}/part_*.stl |
  xargs -P "$JOBS" -I{} bash -c 'one_part "$1"' _ {}
for s in train val test; do
  echo "datasets $s: $(ls "$WORK/data/$s"/*.safetensors 2>/dev/null | wc -l) files" >&2
done
T[datasets]=$(($(date +%s) - t))

# 5. train + export + check
stage "training"
cat >"$WORK/build.json" <<EOF
{"command": $(printf '%s' "$INVOCATION" | "$VENV/bin/python" -c 'import json,sys; print(json.dumps(sys.stdin.read()))'),
 "abgs": "$("$BIN" --version) (source $REV)",
 "seconds_before_training": $(($(date +%s) - t_all)),
 "stages_seconds": {"venv": ${T[venv]}, "cli": ${T[cli]}, "parts": ${T[parts]}, "datasets": ${T[datasets]}},
 "parts": {"train": $N_TRAIN, "val": $N_VAL, "test": $N_TEST,
           "seeds": {"train": $SEED_TRAIN, "val": $SEED_VAL, "test": $SEED_TEST}},
 "grid_args": "$GRID_ARGS", "dataset_args": "$DATASET_ARGS", "jobs": $JOBS,
 "cpu": "$(nproc) cores, $(uname -m)"}
EOF
"$VENV/bin/python" "$ROOT/training/train.py" --data "$WORK/data" --out "$OUT" --seed "$SEED" \
  --epochs "$EPOCHS" --time-budget-min "$TRAIN_MIN" --threads "$THREADS" \
  --build-info "$WORK/build.json" \
  --description "$(printf '%s' "CAD-like parts from training/parts.py (Gmsh $("$VENV/bin/python" -c 'import gmsh; print(gmsh.__version__)') OpenCASCADE; six families; seeds $SEED_TRAIN/$SEED_VAL/$SEED_TEST + k for train/val/test), each remeshed by \`abgs grid $GRID_ARGS\`, sized by \`abgs size\` (defaults) and run through \`abgs dataset $DATASET_ARGS\` (an LBO-ABGS run with the dense grid, intermediate grids and the final grid as snapshots, every edge labelled by the exact estimate).")"
stage "done: $OUT"
echo "total $(($(date +%s) - t_all)) s" >&2
