#!/usr/bin/env bash
# Runs fuzz targets of an AUTOGRAV_FUZZ=ON build, each on its seed corpus (corpus/<name>/) for a
# bounded time, and fails on the first finding: a crash, a sanitizer report, a failed invariant, a
# leak, a timeout or running out of memory. The input that caused it is left in
# <build>/fuzz-artifacts/<name>/; reproduce with `<build>/tests/fuzz/<name>_fuzzer <that file>`.
# New inputs the fuzzer finds go to <build>/fuzz-work/<name>/, never into the seed corpus.
# Usage: tests/fuzz/run_fuzzers.sh <build dir> [seconds per target (30)] [name ...]
#   names: map checkpoint cli servo (default: all)
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
build="$(cd "${1:?usage: run_fuzzers.sh <build dir> [seconds] [name ...]}" && pwd)"
seconds="${2:-30}"
shift $(($# < 2 ? $# : 2))
names=("$@")
if ((${#names[@]} == 0)); then names=(map checkpoint cli servo); fi

# Longest input per target: a few grid-3 maps, a long command line, a long servo script.
declare -A max_len=([map]=16384 [checkpoint]=16384 [cli]=1024 [servo]=8192)
declare -A dictionary=([map]=map.dict [checkpoint]=map.dict [cli]=cli.dict)

for name in "${names[@]}"; do
  binary="$build/tests/fuzz/${name}_fuzzer"
  if [[ ! -x "$binary" ]]; then
    echo "run_fuzzers: $binary is missing (build the target autograv_fuzzers first)" >&2
    exit 1
  fi
  work="$build/fuzz-work/$name"
  artifacts="$build/fuzz-artifacts/$name"
  mkdir -p "$work" "$artifacts"
  options=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -seed=1
           -max_len="${max_len[$name]:-4096}" -print_final_stats=1 -artifact_prefix="$artifacts/")
  if [[ -n "${dictionary[$name]:-}" ]]; then options+=(-dict="$here/${dictionary[$name]}"); fi
  log="$build/fuzz-work/$name.log"
  echo "run_fuzzers: $name for ${seconds}s (log: $log)"
  if ! UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ASAN_OPTIONS=detect_leaks=1 \
    "$binary" "${options[@]}" "$work" "$here/corpus/$name" >"$log" 2>&1; then
    tail -n 60 "$log" >&2
    echo "run_fuzzers: $name FOUND A PROBLEM; the input is in $artifacts/" >&2
    exit 1
  fi
  runs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")"
  echo "run_fuzzers: $name ok, ${runs:-?} inputs in ${seconds}s, corpus $(ls "$work" | wc -l) files"
done
