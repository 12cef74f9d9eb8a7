#!/usr/bin/env bash
# The benchmark report in one command: installs what is missing, builds, renders the benchmark's
# sequences (cached in $TMPDIR/inhandscan-bench) and writes docs/benchmarks.md with its CSV files
# and pictures in docs/benchmarks/. Uses the paper's four recorded sessions from
# ../shared/data/hand-iccv15 when they are there (the scripted cases otherwise).
#   tools/bench.sh [inhandscan-bench options, e.g. --quick, --frames N, --case NAME, --out DIR]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/tools/build.sh"
build_dir="${IHS_BUILD_DIR:-build}"
[[ "$build_dir" = /* ]] || build_dir="$root/$build_dir"
args=(--out "$root/docs")
data="$root/../shared/data/hand-iccv15"
[[ -d "$data/sequences" ]] && args+=(--data "$data")
IHS_BENCH_COMMAND="tools/bench.sh${*:+ $*}" exec "$build_dir/tools/inhandscan-bench" "${args[@]}" "$@"
