#!/usr/bin/env bash
# README command 1: install, build and render the embedded default scene to
# out/default.exr and out/default.png; `import hairvox` then works in
# /usr/bin/python3 (scripts/install-python.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh release
bash scripts/install-python.sh
build/release/cli/hairvox render
