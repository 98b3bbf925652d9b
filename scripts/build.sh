#!/usr/bin/env bash
# Configures and builds hairvox into build/<name> (default: build/release).
#   scripts/build.sh                 optimised (-O2), warnings are errors
#   scripts/build.sh asan            AddressSanitizer + UndefinedBehaviorSanitizer
# Extra arguments after the name go to CMake's configure step.
set -euo pipefail
cd "$(dirname "$0")/.."
name=${1:-release}
shift || true
case "$name" in
  release) config=(-DCMAKE_BUILD_TYPE=Release) ;;
  asan)    config=(-DCMAKE_BUILD_TYPE=Release -DHAIRVOX_SANITIZE=address,undefined
                   -DHAIRVOX_BUILD_BENCH=OFF) ;;
  *) echo "build.sh: unknown build '$name' (release, asan)" >&2; exit 2 ;;
esac
cmake -S . -B "build/$name" -G Ninja -DHAIRVOX_WERROR=ON "${config[@]}" "$@" >/dev/null
cmake --build "build/$name" -j "${HAIRVOX_JOBS:-2}"
