#!/usr/bin/env bash
# README command 1: install, build and render the embedded default scene to
# out/default.exr and out/default.png.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh release
build/release/cli/hairvox render
