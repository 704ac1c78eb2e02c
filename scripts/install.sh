#!/usr/bin/env bash
# Installs the abgs C library into PREFIX:
#   PREFIX/lib/libabgs.so, PREFIX/lib/libabgs.a, PREFIX/include/abgs.h,
#   PREFIX/lib/cmake/abgs/abgsConfig.cmake + abgsConfigVersion.cmake,
#   PREFIX/lib/pkgconfig/abgs.pc
# Usage: scripts/install.sh PREFIX
# Environment: ABGS_NO_BUILD=1 installs the existing target/release build without
# running `cargo build --release --workspace --lib` first; DESTDIR=dir stages the
# files under dir (the paths written into abgs.pc stay PREFIX).
# The build unifies features over the workspace, as `cargo build --release
# --workspace`, the Python package's build and bench/paper_tables.sh do: a plain
# `--lib` build resolves the proc-macros' syn without the CLI's features and so
# recompiles every dependency that uses them (tract's crates, about ten minutes
# on 2 cores) after a workspace build, instead of finding it fresh.
set -euo pipefail

if [[ $# -ne 1 || -z $1 ]]; then
  echo "usage: $0 PREFIX" >&2
  exit 2
fi

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
prefix=$1
if [[ $prefix != /* ]]; then
  prefix="$PWD/$prefix"
fi
prefix=${prefix%/}
dest="${DESTDIR:-}${prefix}"

# Version from Cargo.toml's [workspace.package] section.
version=$(awk '
  /^[ \t]*\[/ {
    section = $0; sub(/^[ \t]*\[/, "", section); sub(/\].*$/, "", section)
    gsub(/[ \t]/, "", section); next
  }
  section == "workspace.package" && /^[ \t]*version[ \t]*=/ {
    if (match($0, /"[^"]+"/)) { print substr($0, RSTART + 1, RLENGTH - 2); exit }
  }' "$repo/Cargo.toml")
if [[ ! $version =~ ^[0-9]+\.[0-9]+\.[0-9]+ ]]; then
  echo "install.sh: no [workspace.package] version in $repo/Cargo.toml" >&2
  exit 1
fi

if [[ ${ABGS_NO_BUILD:-0} != 1 ]]; then
  echo "install.sh: cargo build --release --workspace --lib (in $repo)"
  (cd "$repo" && cargo build --release --workspace --lib)
fi
libdir="$repo/target/release"
for f in libabgs.so libabgs.a; do
  if [[ ! -f $libdir/$f ]]; then
    echo "install.sh: $libdir/$f is missing; run cargo build --release --workspace --lib" >&2
    exit 1
  fi
done

echo "install.sh: installing abgs $version into $dest"
install -d "$dest/lib" "$dest/include" "$dest/lib/cmake/abgs" "$dest/lib/pkgconfig"
install -m 755 "$libdir/libabgs.so" "$dest/lib/libabgs.so"
install -m 644 "$libdir/libabgs.a" "$dest/lib/libabgs.a"
install -m 644 "$repo/include/abgs.h" "$dest/include/abgs.h"
install -m 644 "$repo/cmake/abgsConfig.cmake" "$dest/lib/cmake/abgs/abgsConfig.cmake"

# The installed version file carries the version: there is no Cargo.toml there.
sed "s/^set(_abgs_hardcoded_version \"\")\$/set(_abgs_hardcoded_version \"$version\")/" \
  "$repo/cmake/abgsConfigVersion.cmake" > "$dest/lib/cmake/abgs/abgsConfigVersion.cmake"
if ! grep -q "^set(_abgs_hardcoded_version \"$version\")\$" "$dest/lib/cmake/abgs/abgsConfigVersion.cmake"; then
  echo "install.sh: could not hard-code the version in abgsConfigVersion.cmake" >&2
  exit 1
fi
chmod 644 "$dest/lib/cmake/abgs/abgsConfigVersion.cmake"

# Prefixes with sed metacharacters (|, &, \) are escaped for the replacement.
prefix_sed=$(printf '%s' "$prefix" | sed 's/[|&\\]/\\&/g')
sed -e "s|@prefix@|$prefix_sed|g" -e "s|@version@|$version|g" \
  "$repo/cmake/abgs.pc.in" > "$dest/lib/pkgconfig/abgs.pc"
chmod 644 "$dest/lib/pkgconfig/abgs.pc"

echo "install.sh: done:"
find "$dest/lib/libabgs.so" "$dest/lib/libabgs.a" "$dest/include/abgs.h" \
  "$dest/lib/cmake/abgs" "$dest/lib/pkgconfig/abgs.pc" -type f | sed 's/^/  /'
