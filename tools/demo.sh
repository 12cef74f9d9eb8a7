#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job on the built-in sample. A user's build:
# neither the tests nor the benchmark's Open3D peer (tools/test.sh installs and builds those).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
IHS_TESTS=OFF "$root/tools/build.sh"
build_dir="${IHS_BUILD_DIR:-build}"
[[ "$build_dir" = /* ]] || build_dir="$root/$build_dir"

# The built-in sample: a synthetic sequence of the procedural hand turning a Ø70 mm sphere.
sample="$build_dir/demo-sample"
"$build_dir/tools/inhandscan-synth" --preset demo --out "$sample" --quiet
echo "demo: sample sequence: $sample/sequence.oni (ground truth in $sample/gt/, a look at it:"
echo "demo:   $sample/contact_sheet.png)"

# The application replays it headlessly on its threads (capture → hand tracker → fusion →
# export), the tracker initialising itself as it would live.
scan="$build_dir/demo-scan"
"$build_dir/app/inhandscan" replay "$sample/sequence.oni" --out "$scan" --quiet > "$scan.log"
echo "demo: mesh: $scan/mesh.ply (watertight; the TSDF's own surface: $scan/mesh_tsdf.ply;"
echo "demo:   previews: $scan/preview/, statistics: $scan/stats.json)"
"$build_dir/tools/inhandscan-measure" "$scan/mesh.ply" --object sphere --gt "$sample/gt" \
  > "$scan.measure.log"
grep -E '^(diameter|volume: truth)' "$scan.measure.log" | sed 's/^/demo:   /'
echo "demo: (true sphere: diameter 70 mm; all figures: $scan.measure.log)"
