#!/usr/bin/env bash
# Speed and memory of the application, end to end on this machine: a generator sequence of one
# of the paper's recorded hand motions (full sensor noise) is replayed by `inhandscan` (every
# default term on: SIFT, fingertip contacts, ICP, TSDF, previews) as fast as it goes, then at the
# recorded pace (--realtime, dropping like a live camera). Prints frames/s, ms per stage and
# thread, whether the cost per frame stays flat over the sequence, peak memory, and the
# capture-to-fused latency at the recorded pace.
#
#   tools/bench_app.sh [SESSION] [FRAMES] [DATA_DIR] [WORK_DIR]
#
# SESSION: 001-water-bottle, 002-bowling-pin, 003-small-bottle or 004-sphere (default; 1 680
# frames); FRAMES: how many from the start, or all (default). Set IHS_BUILD_DIR to use another
# build.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
session="${1:-004-sphere}"
frames="${2:-all}"
data="${3:-$root/../shared/data/hand-iccv15}"
work="${4:-/tmp/inhandscan-bench-app}"
build="${IHS_BUILD_DIR:-$root/build}"
[[ -d "$data/sequences/$session" ]] || { echo "bench_app: no session $session in $data" >&2; exit 3; }
declare -A objects=([001-water-bottle]=water-bottle [002-bowling-pin]=bowling-pin
                    [003-small-bottle]=small-bottle [004-sphere]=sphere)
range=()
[[ "$frames" == all ]] || range=(--frames "0:$((frames - 1))")

mkdir -p "$work"
if [[ ! -f "$work/seq-$session-$frames/sequence.oni" ]]; then
  echo "bench_app: generating $session ($frames frames)..." >&2
  "$build/tools/inhandscan-synth" --object "${objects[$session]}" \
    --motion "recorded:$data/sequences/$session" "${range[@]}" --no-tum \
    --out "$work/seq-$session-$frames" --quiet
fi
seq="$work/seq-$session-$frames/sequence.oni"
echo "bench_app: replaying as fast as possible..." >&2
"$build/app/inhandscan" replay "$seq" --out "$work/replay" --quiet > /dev/null
echo "bench_app: replaying at the recorded pace..." >&2
"$build/app/inhandscan" replay "$seq" --realtime --out "$work/realtime" --quiet > /dev/null

python3 - "$work" "$session" "$(nproc)" <<'PY'
import json, os, sys
work, session, cores = sys.argv[1], sys.argv[2], sys.argv[3]
def load(name):
    return json.load(open(os.path.join(work, name, "stats.json")))
fast, paced = load("replay"), load("realtime")
s = fast["summary"]
print(f"inhandscan on {session}: {s['frames']} frames, {cores} cores")
print(f"replay (as fast as possible): {s['frames_per_second']:.1f} frames/s end to end "
      f"({s['processing_seconds']:.1f} s), final export {s['export_ms']['total'] / 1000:.1f} s, "
      f"peak memory {s['peak_rss_mib']:.0f} MiB")
ms = s["ms_per_frame"]
tracker = ms.get("track", 0) + ms.get("mask", 0)
fusion = ms.get("features", 0) + ms.get("fusion", 0)
print(f"  tracker thread {tracker:.1f} ms/frame (track {ms.get('track', 0):.1f}: segmentation "
      f"{ms.get('segmentation', 0):.1f}, hand fit {ms.get('hand_fit', 0):.1f}, contacts "
      f"{ms.get('contacts', 0):.1f}; hand mask {ms.get('mask', 0):.1f}); fusion thread {fusion:.1f} ms/frame (SIFT {ms.get('features', 0):.1f}, "
      f"pairwise {ms.get('pairwise', 0):.2f}, raycast {ms.get('raycast', 0):.1f}, ICP "
      f"{ms.get('icp', 0):.1f}, integrate {ms.get('integrate', 0):.1f})")
print(f"  the slowest thread sets the pace: {'tracker' if tracker > fusion else 'fusion'} "
      f"({1000 / max(tracker, fusion):.1f} frames/s if it had a core to itself)")
frames = fast["frames"]
def mean(rows, keys):
    values = [sum(r.get(k, 0) for k in keys) for r in rows if "track_ms" in r]
    return sum(values) / len(values) if values else 0
# The cost per frame over the sequence, in windows of 300 frames: flat when the model's growth
# does not show (the hand's motion and the object's view still move it up and down).
windows = []
for start in range(0, len(frames), 300):
    rows = frames[start:start + 300]
    if len(rows) >= 100:
        windows.append("%d-: %.1f / %.1f" % (start, mean(rows, ["track_ms", "mask_ms"]),
                                             mean(rows, ["features_ms", "fusion_ms"])))
print("  ms/frame tracker / fusion thread by frame window: " + ", ".join(windows))
print(f"  registered {s['registered_frames']}/{s['frames']}, skipped {s['skip_reasons']}")
p = paced["summary"]
lat = p.get("latency_ms", {})
dp = p["dropped_frames"]
print(f"realtime (recorded pace, drops like live): {p['frames']} of "
      f"{p['captured_frames'] + dp['missed_by_source']} frames processed, dropped: capture queue "
      f"full {dp['capture_queue_full']}, passed over for a newer frame {dp['skipped_stale']}, "
      f"missed by the player {dp['missed_by_source']}")
print(f"  latency capture -> fused: p50 {lat.get('p50', 0):.0f} ms, p95 {lat.get('p95', 0):.0f} ms, "
      f"max {lat.get('max', 0):.0f} ms; peak memory {p['peak_rss_mib']:.0f} MiB")
PY
