#!/usr/bin/env bash
# Installs missing dependencies, configures and builds the project.
#   IHS_BUILD_DIR   build folder (default: build)
#   IHS_BUILD_TYPE  CMake build type (default: Release)
#   IHS_SANITIZE    "", "address,undefined" or "thread": a sanitizer build
#   IHS_JOBS        parallel jobs (default: number of cores)
#   IHS_TARGETS     space-separated targets to build (default: all)
#   IHS_TESTS       ON (default): also install the developer's packages (tests, the benchmark's
#                   Open3D peer; tools/debian-packages-dev.txt) and build the tests; OFF
#                   (tools/demo.sh): neither
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
tests="${IHS_TESTS:-ON}"
case "$tests" in
  ON) "$root/tools/install-deps.sh" --dev ;;
  OFF) "$root/tools/install-deps.sh" ;;
  *)
    echo "build: IHS_TESTS must be ON or OFF, got '$tests'" >&2
    exit 2
    ;;
esac

build_dir="${IHS_BUILD_DIR:-build}"
[[ "$build_dir" = /* ]] || build_dir="$root/$build_dir"
build_type="${IHS_BUILD_TYPE:-Release}"
sanitize="${IHS_SANITIZE:-}"
jobs="${IHS_JOBS:-$(nproc)}"
# Paths under the checkout are hashed relative to it: another clone's build (CI's) reuses this
# one's compiled objects.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$root}"

generator=()
if [[ ! -f "$build_dir/CMakeCache.txt" ]] && command -v ninja >/dev/null 2>&1; then
  generator=(-G Ninja)
fi
cmake -S "$root" -B "$build_dir" "${generator[@]}" \
  -DCMAKE_BUILD_TYPE="$build_type" -DIHS_SANITIZE="$sanitize" -DBUILD_TESTING="$tests" >/dev/null
targets=()
for target in ${IHS_TARGETS:-}; do targets+=(--target "$target"); done
cmake --build "$build_dir" --parallel "$jobs" "${targets[@]}"
