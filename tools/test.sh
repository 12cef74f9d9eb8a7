#!/usr/bin/env bash
# The project's test command: installs what is missing (apt-get), builds, runs ctest.
# Takes the environment variables of tools/build.sh; extra arguments go to ctest
# (e.g. `tools/test.sh -L threads`).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/tools/build.sh"
build_dir="${IHS_BUILD_DIR:-build}"
[[ "$build_dir" = /* ]] || build_dir="$root/$build_dir"
cd "$build_dir"
ctest --output-on-failure --parallel "${IHS_JOBS:-$(nproc)}" "$@"
