#!/usr/bin/env bash
# Soak: what a long scan does to memory and to the time per frame. A recording (by default a
# generated full turn of the sphere in the procedural hand, full sensor noise) is replayed by
# `inhandscan replay --loop` as one input of about FRAMES frames, every default term on, as fast
# as it goes; the process's resident memory is sampled every second. Prints, per window of 300
# frames, the tracker and fusion threads' ms per frame and the memory at that point of the run,
# then whether both stay flat after the warm-up (the last window against the second).
#
#   tools/soak.sh [FRAMES] [INPUT] [WORK_DIR]
#
# FRAMES: default 10000; INPUT: an .oni file or TUM folder (default: generated into WORK_DIR);
# WORK_DIR: default /tmp/inhandscan-soak. Set IHS_BUILD_DIR to use another build. Run it alone:
# other work on the machine shows up in the times.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
frames="${1:-10000}"
input="${2:-}"
work="${3:-/tmp/inhandscan-soak}"
build="${IHS_BUILD_DIR:-$root/build}"
[[ "$frames" =~ ^[0-9]+$ && "$frames" -ge 600 ]] || { echo "soak: FRAMES must be >= 600" >&2; exit 2; }
mkdir -p "$work"
if [[ -z "$input" ]]; then
  input="$work/sphere-turn/sequence.oni"
  if [[ ! -f "$input" ]]; then
    echo "soak: generating a full turn of the sphere (240 frames)..." >&2
    "$build/tools/inhandscan-synth" --object sphere --seed 5 --no-tum --out "$work/sphere-turn" \
      --quiet
  fi
fi
count=$("$build/tools/inhandscan-frames" info "$input" | sed -n 's/^depth_frames: *\([0-9]*\).*/\1/p')
[[ -n "$count" && "$count" -gt 0 ]] || { echo "soak: cannot count the frames of $input" >&2; exit 3; }
loops=$(((frames + count - 1) / count))
echo "soak: $input ($count frames) played $loops times..." >&2
rm -rf "$work/scan"
"$build/app/inhandscan" replay "$input" --loop "$loops" --out "$work/scan" --quiet >/dev/null &
pid=$!
start=$(date +%s.%N)
: >"$work/rss.txt"
while kill -0 "$pid" 2>/dev/null; do
  rss=$(sed -n 's/^VmRSS:[[:space:]]*\([0-9]*\) kB/\1/p' "/proc/$pid/status" 2>/dev/null || true)
  [[ -n "$rss" ]] && echo "$(date +%s.%N) $rss" >>"$work/rss.txt"
  sleep 1
done
wait "$pid"

python3 - "$work" "$start" <<'PY'
import json, os, sys
work, start = sys.argv[1], float(sys.argv[2])
stats = json.load(open(os.path.join(work, "scan", "stats.json")))
frames = stats["frames"]
summary = stats["summary"]
samples = [tuple(map(float, line.split())) for line in open(os.path.join(work, "rss.txt"))]
processing = summary["processing_seconds"]
n = len(frames)
print(f"soak: {n} frames, {summary['frames_per_second']:.1f} frames/s, peak memory "
      f"{summary['peak_rss_mib']:.0f} MiB, {summary.get('registered_frames', 0)} registered")
print(f"{'frames':>13} {'tracker ms':>10} {'fusion ms':>9} {'memory MiB':>10}")
window = 300
rows = []
for first in range(0, n - window + 1, window):
    part = frames[first:first + window]
    tracker = sum(f.get("track_ms", 0) + f.get("mask_ms", 0) for f in part) / window
    fusion = sum(f.get("features_ms", 0) + f.get("fusion_ms", 0) for f in part) / window
    # The memory when this window ended, assuming frames went through at an even pace.
    at = start + processing * (first + window) / n
    before = [rss for t, rss in samples if t <= at]
    rss = (before[-1] if before else samples[0][1]) / 1024 if samples else float("nan")
    rows.append((tracker, fusion, rss))
    print(f"{first:>6}-{first + window - 1:<6} {tracker:>10.1f} {fusion:>9.1f} {rss:>10.0f}")
if len(rows) >= 3:
    (t2, f2, m2), (tl, fl, ml) = rows[1], rows[-1]
    print(f"last window against the second: tracker x{tl / t2:.2f}, fusion x{fl / f2:.2f}, "
          f"memory {ml - m2:+.0f} MiB")
PY
