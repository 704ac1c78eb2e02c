#!/usr/bin/env bash
# CI step of the Python package and the FreeCAD macro, from a fresh machine:
#   1. a venv under target/pyvenv with the pinned test requirements
#      (pytest, numpy);
#   2. the package installed with the one documented command, `pip install ./python`
#      (scikit-build-core runs `cargo build --release --locked --lib`; a no-op when
#      target/release is up to date);
#   3. the CLI (target/release/abgs) built if missing: the tests compare with it;
#   4. FreeCAD 0.20 from Debian (apt-get install freecad) when freecadcmd is
#      missing, and the abgs and gmsh==4.15.2 packages for its Python (Debian's
#      python3) in the prefix target/freecad-site (numpy is Debian's);
#   5. pytest python/tests, FreeCAD test included and required.
# Usage: python/ci.sh [--no-freecad]   (--no-freecad: steps 4 and the FreeCAD
# test left out). Prints the seconds of each step.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
freecad=1
case ${1:-} in
  --no-freecad) freecad=0 ;;
  "") ;;
  *) echo "usage: python/ci.sh [--no-freecad]" >&2; exit 2 ;;
esac

venv=target/pyvenv
site=target/freecad-site
t_all=$SECONDS
t=$SECONDS
lap() { echo "-- $1: $((SECONDS - t)) s"; t=$SECONDS; }
apt_install() {
  if [[ $(id -u) -ne 0 ]] || ! command -v apt-get >/dev/null; then
    echo "missing: $*; install them (apt-get install -y $*)" >&2
    exit 2
  fi
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >/dev/null
}

echo "== venv $venv with the pinned test requirements"
if [[ ! -x $venv/bin/python ]]; then
  python3 -m venv "$venv" 2>/dev/null || { apt_install python3-venv; python3 -m venv "$venv"; }
fi
"$venv/bin/pip" install -q --disable-pip-version-check -r python/requirements-test.txt
lap "venv"

echo "== pip install ./python (builds libabgs with cargo)"
"$venv/bin/pip" install -q --disable-pip-version-check ./python
"$venv/bin/python" -c 'import abgs; print("abgs", abgs.version(), "from", abgs.library_path())'
lap "pip install ./python"

if [[ ! -x target/release/abgs ]]; then
  echo "== CLI (the tests compare with it)"
  cargo build --release --locked -p abgs-cli
  lap "cargo build -p abgs-cli"
fi

if ((freecad)); then
  echo "== FreeCAD (Debian) and the packages for its Python in $site"
  if ! command -v freecadcmd >/dev/null; then
    apt_install freecad
    lap "apt-get install freecad"
  fi
  rm -rf "$site"
  # --prefix, not --target: with --target pip drops the wheel's lib/ (libgmsh.so);
  # --ignore-installed: else pip removes the venv's own abgs.
  "$venv/bin/pip" install -q --disable-pip-version-check --no-deps --ignore-installed --prefix "$site" ./python gmsh==4.15.2
  site_packages=$(compgen -G "$site/lib/python3*/site-packages" | head -1)
  if ! /usr/bin/python3 -c 'import numpy' 2>/dev/null; then
    "$venv/bin/pip" install -q --disable-pip-version-check --no-deps --ignore-installed --prefix "$site" numpy==2.4.6
  fi
  gmsh_lib=$(compgen -G "$site/lib/libgmsh.so*" | head -1 || true)
  [[ -n $gmsh_lib ]] || { echo "no libgmsh.so* in $site/lib after installing gmsh" >&2; exit 2; }
  if ldd "$gmsh_lib" | grep -q 'not found'; then
    apt_install libglu1-mesa libgl1 libxcursor1 libxft2 libxinerama1 libxrender1 libxfixes3 libxext6 \
      libfontconfig1 libx11-6 libgomp1
  fi
  lap "packages for FreeCAD's Python"
  export ABGS_REQUIRE_FREECAD=1 ABGS_SITE="$repo/$site_packages"
fi

echo "== pytest python/tests"
"$venv/bin/python" -m pytest -q -p no:cacheprovider python/tests
lap "pytest"
echo "-- python/ci.sh total: $((SECONDS - t_all)) s"
