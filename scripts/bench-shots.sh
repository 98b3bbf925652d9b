#!/usr/bin/env bash
# The farm's figures in docs/farm.md, measured on this machine:
#
#   scripts/bench-shots.sh [RUNS] [SIZE] [FRAMES] [PER_TASK]     (default 3 512 8 2)
#
# A turntable of the default scene (data/shots/turntable.json) at SIZE²,
# frames 1..FRAMES, rendered RUNS times each way, the ways taking turns so
# that a drift in the machine's speed hits them alike:
#   local    hairvox render --frames 1-FRAMES, one process, all CPUs
#   tasks    the same frames as separate processes of PER_TASK frames each,
#            one after another, through a warm shared cache (what a farm task
#            does, without the scheduler): the per-frame overhead of a task
#   cold     the same without the cache: each process splats the grid and
#            prepares the lights for its first frame (what the cache saves)
#   slurm    hairvox submit --per-task PER_TASK --cpus 1 on a private
#            one-node cluster (scripts/slurm-cluster.sh), timed from the
#            submit to the last task's end (squeue polled every 0.1 s)
# Each prints its wall seconds per run, the median and the ratio to local.
# Needs root (the cluster's daemons), a release build and the cluster's packages.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
size=${2:-512}
frames=${3:-8}
per_task=${4:-2}
hairvox=$PWD/build/release/cli/hairvox
[[ -x $hairvox ]] || { echo "bench-shots: build first (bash scripts/build.sh release)" >&2; exit 2; }
work=$(mktemp -d /tmp/hairvox-bench-shots.XXXXXX)
cluster=$work/cluster
trap 'bash scripts/slurm-cluster.sh stop "$cluster" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
bash scripts/slurm-cluster.sh start "$cluster" >/dev/null
# shellcheck disable=SC1091
source "$cluster/env"
export HAIRVOX_CACHE_DIR=$work/tables

shot=$work/shot.json
sed -e "s|\"resolution\": \[1024, 1024\]|\"resolution\": [$size, $size]|" \
    -e "s|\"end\": 240|\"end\": $frames|" \
    -e "s|\"degrees_per_frame\": 1.5|\"degrees_per_frame\": $((360 / frames))|" \
    data/shots/turntable.json >"$shot"
cd "$work"

now() { date +%s.%N; }
since() { awk -v a="$(now)" -v b="$1" 'BEGIN { printf "%.3f", a - b }'; }
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

run_local() {
  "$hairvox" render "$shot" --frames "1-$frames" --force --quiet >/dev/null
}
run_tasks() {
  local first
  for ((first = 1; first <= frames; first += per_task)); do
    "$hairvox" render "$shot" --frames "$first-$((first + per_task - 1 < frames ? first + per_task - 1 : frames))" \
      --force --quiet --cache "$work/cache" >/dev/null
  done
}
run_cold() {
  local first
  for ((first = 1; first <= frames; first += per_task)); do
    "$hairvox" render "$shot" --frames "$first-$((first + per_task - 1 < frames ? first + per_task - 1 : frames))" \
      --force --quiet >/dev/null
  done
}
run_slurm() {
  local id
  id=$("$hairvox" submit "$shot" --per-task "$per_task" --cpus 1 --force --cache "$work/cache" |
    sed -n 's/^hairvox: submitted job \([0-9]*\).*/\1/p')
  local left
  while true; do # (a busy controller may not answer at once: only an answer counts)
    left=$(squeue --noheader --jobs="$id" --format=%T 2>/dev/null) || { sleep 0.1; continue; }
    [[ -z $left ]] && break
    sleep 0.1
  done
  if scontrol show job "$id" | grep 'JobState=' | grep -qv 'JobState=COMPLETED'; then
    scontrol show job "$id" >&2
    cat "$work"/shot.farm/logs/*.err >&2
    exit 1
  fi
}

echo "bench-shots: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) CPUs; load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "bench-shots: $frames frames of ${size}x$size (default scene), $per_task frames a task"
run_tasks # warms the cache and the tables
declare -A seconds
for ((r = 1; r <= runs; r++)); do
  for way in local tasks cold slurm; do
    t=$(now)
    "run_$way"
    seconds[$way]+="$(since "$t") "
  done
done
local_median=$(tr ' ' '\n' <<<"${seconds[local]}" | grep . | median)
for way in local tasks cold slurm; do
  m=$(tr ' ' '\n' <<<"${seconds[$way]}" | grep . | median)
  awk -v w="$way" -v runs="${seconds[$way]% }" -v m="$m" -v l="$local_median" -v f="$frames" \
    'BEGIN { printf "bench-shots: %-6s median %.2f s (runs %s s), %.3f x local, %.3f s a frame\n", w, m, runs, m / l, m / f }'
done
echo "bench-shots: load after $(cut -d' ' -f1-3 /proc/loadavg)"
