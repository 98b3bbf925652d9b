#!/usr/bin/env bash
# Makes `import hairvox` work in Debian's Python (/usr/bin/python3, where
# python3-numpy and python3-openvdb live) with the module this checkout built
# in build/release/python: a one-line hairvox.pth in that interpreter's
# site-packages directory names the build's package directory
# (/usr/local/lib/python3.X/dist-packages as root, the user's site directory
# otherwise). Why a .pth rather than a copy: the module imported is always
# the one just built (a rebuild needs no reinstall, no stale copy can
# shadow it), nothing of Debian's is touched, and removing it is deleting one
# file. The checkout must stay where it is; moved, re-run scripts/demo.sh or
# scripts/test.sh. Idempotent: rewrites the file only when it names another
# directory (another checkout: the last one installed wins, and says so).
set -euo pipefail
cd "$(dirname "$0")/.."
python=${HAIRVOX_PYTHON:-/usr/bin/python3}
package_dir=$PWD/build/release/python
if [ ! -f "$package_dir/hairvox/__init__.py" ]; then
  echo "install-python: $package_dir/hairvox is not built (bash scripts/build.sh release)" >&2
  exit 1
fi
if [ "$(id -u)" -eq 0 ]; then
  site=$("$python" -c 'import site; print(site.getsitepackages()[0])')
else
  site=$("$python" -c 'import site; print(site.getusersitepackages())')
fi
pth=$site/hairvox.pth
if [ "$(cat "$pth" 2>/dev/null)" != "$package_dir" ]; then
  mkdir -p "$site"
  [ -f "$pth" ] && echo "install-python: $pth named $(cat "$pth"); now $package_dir"
  printf '%s\n' "$package_dir" >"$pth.tmp.$$"
  mv "$pth.tmp.$$" "$pth"
fi
# Checked from / with a clean environment: what a fresh shell gets.
where=$(cd / && env -u PYTHONPATH "$python" -c 'import hairvox; print(hairvox.__file__)')
echo "install-python: $python imports hairvox from ${where%/__init__.py} ($pth)"
