#!/usr/bin/env bash
# The hand tracker's benchmark: generator sequences from the paper's four recorded hand motions
# (full sensor noise), tracked with the procedural template (its scale estimated over the first
# frames) and with the real hand model, both started from the ground truth's first pose. Prints
# the template's scale, joint error, contact error and ms/frame.
#   tools/bench_tracker.sh [FRAMES] [DATA_DIR] [WORK_DIR]
# FRAMES: the first FRAMES frames of each session (default 300; "all" for whole sessions).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
frames="${1:-300}"
data="${2:-$root/../shared/data/hand-iccv15}"
work="${3:-$(mktemp -d)}"
build="${IHS_BUILD_DIR:-$root/build}"
[[ -d "$data/sequences" ]] || { echo "bench_tracker: no hand data in $data" >&2; exit 3; }
range=()
[[ "$frames" == all ]] || range=(--frames "0:$((frames - 1))")
declare -A objects=([001-water-bottle]=water-bottle [002-bowling-pin]=bowling-pin
                    [003-small-bottle]=small-bottle [004-sphere]=sphere)
printf '%-18s %-11s %6s %16s %18s %10s %8s\n' session template scale "joint error (mm)" \
  "contact error (mm)" "ms/frame" lost
for session in 001-water-bottle 002-bowling-pin 003-small-bottle 004-sphere; do
  out="$work/$session"
  "$build/tools/inhandscan-synth" --object "${objects[$session]}" \
    --motion "recorded:$data/sequences/$session" "${range[@]}" --no-tum --out "$out" --quiet
  for template in procedural "$data"; do
    name=$([[ "$template" == procedural ]] && echo procedural || echo real)
    "$build/tools/inhandscan-track" "$out/sequence.oni" --out "$out/track-$name" --gt "$out/gt" \
      --init-from-gt --template "$template" --quiet > /dev/null
    python3 - "$out/track-$name/stats.json" "$session" "$name" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))["summary"]
counts = s["status_counts"]
lost = counts.get("diverged", 0) + counts.get("no_hand", 0)
print("%-18s %-11s %6.3f %16.2f %18s %10.1f %8d" % (sys.argv[2], sys.argv[3], s["hand_scale"],
      s.get("joint_error_mm_mean", float("nan")),
      "%.2f" % s["contact_error_mm_median"] if "contact_error_mm_median" in s else "-", s["ms_mean"], lost))
PY
  done
  rm -f "$out/sequence.oni"
done
echo "work folder: $work"
