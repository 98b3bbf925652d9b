#!/usr/bin/env bash
# CI sanitizer and fuzzing jobs (issue 8), after scripts/test.sh:
#
#   scripts/ci-sanitize.sh [all|tests|fuzz]     (default: all)
#
# One clang build, build/sanitize (or $HAIRVOX_SANITIZE_DIR), with Address-
# Sanitizer + UndefinedBehaviorSanitizer (every report is fatal) and the
# libFuzzer targets of fuzz/:
#   tests  the fast tests (ctest -L fast) under the sanitizers;
#   fuzz   each fuzzer (hair, tfx, obj, mesh, scene, shot) for HAIRVOX_FUZZ_SECONDS (default
#          60) from its committed seed corpus fuzz/corpus/<target>/, two at a
#          time; new corpus entries go to a temporary directory, crashing inputs
#          to <build>/fuzz-findings/.
# Sharing one build for both halves keeps CI under 30 minutes on 2 cores. Clang
# warnings are errors here too, as in the GCC release build; the third-party
# code exempted from a check is in scripts/ci-sanitize-ignorelist.txt.
# Exits non-zero on any test failure, sanitizer report or fuzzer finding.
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-all}
case "$what" in all|tests|fuzz) ;; *) echo "ci-sanitize.sh: unknown job '$what' (all, tests, fuzz)" >&2; exit 2 ;; esac
jobs=${HAIRVOX_JOBS:-2}
build=${HAIRVOX_SANITIZE_DIR:-build/sanitize}
fuzzers=(hair tfx obj mesh scene shot)

stamp() { printf '%s: %s (%d:%02d elapsed)\n' "ci-sanitize" "$1" $((SECONDS / 60)) $((SECONDS % 60)); }

CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DHAIRVOX_SANITIZE=address,undefined -DHAIRVOX_BUILD_FUZZERS=ON \
  -DCMAKE_CXX_FLAGS="-fsanitize-ignorelist=$PWD/scripts/ci-sanitize-ignorelist.txt" \
  -DHAIRVOX_BUILD_TESTS=ON -DHAIRVOX_BUILD_BENCH=OFF -DHAIRVOX_WERROR=ON >/dev/null

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:strict_string_checks=1:check_initialization_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

if [[ $what == all || $what == tests ]]; then
  stamp "building the tests with ASan + UBSan"
  cmake --build "$build" -j "$jobs" --target hairvox_tests hairvox
  stamp "running the fast tests under ASan + UBSan"
  ctest --test-dir "$build" -L fast --output-on-failure -j "$jobs"
fi

if [[ $what == all || $what == fuzz ]]; then
  stamp "building the fuzzers"
  cmake --build "$build" -j "$jobs" --target "${fuzzers[@]/#/fuzz_}"
  seconds=${HAIRVOX_FUZZ_SECONDS:-60}
  findings=$build/fuzz-findings
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  mkdir -p "$findings"
  run_fuzzer() {
    local t=$1 dict=()
    [[ -f fuzz/$t.dict ]] && dict=(-dict="fuzz/$t.dict")
    mkdir -p "$work/$t"
    "$build/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
      -print_final_stats=1 "${dict[@]}" -artifact_prefix="$findings/$t-" \
      "$work/$t" "fuzz/corpus/$t" >"$work/$t.log" 2>&1
  }
  stamp "fuzzing ${fuzzers[*]} for ${seconds} s each"
  failed=()
  for ((i = 0; i < ${#fuzzers[@]}; i += 2)); do
    pids=()
    for t in "${fuzzers[@]:i:2}"; do run_fuzzer "$t" & pids+=("$!"); done
    for k in "${!pids[@]}"; do
      t=${fuzzers[i + k]}
      if wait "${pids[k]}"; then
        runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/$t.log")
        cov=$(grep -o 'DONE *cov: [0-9]*' "$work/$t.log" | grep -o '[0-9]*$' || true)
        echo "fuzz_$t: no findings in ${seconds} s (${runs:-?} inputs, ${cov:-?} coverage points)"
      else
        failed+=("$t")
        echo "fuzz_$t: FINDING (input saved under $findings/):"
        tail -n 60 "$work/$t.log"
      fi
    done
  done
  if ((${#failed[@]})); then
    stamp "fuzzers with findings: ${failed[*]}"
    exit 1
  fi
fi
stamp "done"
