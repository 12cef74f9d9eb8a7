#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job on the built-in sample.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/tools/build.sh"
build_dir="${IHS_BUILD_DIR:-build}"
[[ "$build_dir" = /* ]] || build_dir="$root/$build_dir"

if [[ ! -x "$build_dir/app/inhandscan" ]]; then
  cat <<MSG
demo: the build succeeded, but the scanning application (app/inhandscan) does not exist yet:
demo: the sensor, tracker, fusion and application stages are still being built, so there is no
demo: sample scan to run and no mesh to show. What is built so far (in $build_dir):
demo:   tools/inhandscan-frames inspect and convert recordings (.oni, TUM RGB-D folders)
demo:   tools/inhandscan-mesh   inspect and convert meshes (PLY, OBJ, STL)
MSG
  exit 0
fi
