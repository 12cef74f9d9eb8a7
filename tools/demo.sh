#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job on the built-in sample.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/tools/build.sh"
build_dir="${IHS_BUILD_DIR:-build}"
[[ "$build_dir" = /* ]] || build_dir="$root/$build_dir"

# The built-in sample: a synthetic sequence of the procedural hand turning a Ø70 mm sphere.
sample="$build_dir/demo-sample"
"$build_dir/tools/inhandscan-synth" --preset demo --out "$sample" --quiet
echo "demo: sample sequence: $sample/sequence.oni (ground truth in $sample/gt/, a look at it:"
echo "demo:   $sample/contact_sheet.png)"

if [[ ! -x "$build_dir/app/inhandscan" ]]; then
  cat <<MSG
demo: the scanning application (app/inhandscan) does not exist yet: fusion and the application
demo: are still being built, so there is no mesh to show. What is built so far
demo: (in $build_dir):
demo:   tools/inhandscan-synth  render ground-truthed synthetic scanning sequences
demo:   tools/inhandscan-track  track the hand (joints, fingertip contacts) through a recording
demo:   tools/inhandscan-frames inspect and convert recordings (.oni, TUM RGB-D folders)
demo:   tools/inhandscan-mesh   inspect and convert meshes (PLY, OBJ, STL)
MSG
  exit 0
fi
