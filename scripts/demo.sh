#!/usr/bin/env bash
# README command 1: install, build and run the main job on the embedded default.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh release
hairvox=build/release/cli/hairvox
mkdir -p out
"$hairvox" generate wavy --strands 20000 --seed 1 -o out/default.hair
"$hairvox" info out/default.hair
echo "demo: the default groom is in out/default.hair"
