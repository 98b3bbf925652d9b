#!/usr/bin/env bash
# README command 2: install, build (warnings are errors) and run every test
# (ctest labels fast and slow; the Python module's pytest files too), after
# making `import hairvox` work in /usr/bin/python3 (scripts/install-python.sh).
# Exits non-zero on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh release
bash scripts/install-python.sh
ctest --test-dir build/release --output-on-failure -j "${HAIRVOX_JOBS:-2}"
