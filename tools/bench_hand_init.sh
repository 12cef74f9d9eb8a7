#!/usr/bin/env bash
# The hand tracker's self-initialisation on varied hands (issue 32): COUNT scripted sequences
# whose object, start azimuth about it, hand size and side, camera distance and tilt are drawn
# from SEED, each tracked from its first frame with no help (the procedural template, its scale
# estimated). Prints per sequence what was drawn, the joint error of the first frame and over
# all frames, the scale estimate, the doubtful frames, the frames fitted turned over against the
# truth ("over": palm for back or the thumb's tip nearer the true little fingertip than the true
# thumb tip; "palm": palm for back) and the ms per frame; then the mean, the median, how many
# sequences stay within 10 mm, how many are flipped (over > 10 frames) and how many of those
# palm for back (palm > 10 frames). Draw new seeds to measure a change on hands it was not
# developed on.
#   tools/bench_hand_init.sh [SEED] [COUNT] [FRAMES] [WORK_DIR]
# SEED: default 1000; COUNT: sequences (default 24); FRAMES: frames per sequence from the
# start of a half turn (default 61). Set IHS_BUILD_DIR to use another build, IHS_TRACK_ARGS for
# more arguments to inhandscan-track (e.g. "--set tracker.flip_check_frames=0").
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seed="${1:-1000}"
count="${2:-24}"
frames="${3:-61}"
work="${4:-$(mktemp -d)}"
build="${IHS_BUILD_DIR:-$root/build}"
[[ "$seed" =~ ^[0-9]+$ && "$count" =~ ^[0-9]+$ && "$frames" =~ ^[0-9]+$ ]] ||
  { echo "bench_hand_init: SEED, COUNT and FRAMES must be whole numbers" >&2; exit 2; }
(( count >= 1 && frames >= 2 )) || { echo "bench_hand_init: COUNT >= 1, FRAMES >= 2" >&2; exit 2; }
mkdir -p "$work"

# One line per sequence: name, synth seed and the generator's options, drawn from SEED.
python3 - "$seed" "$count" > "$work/cases.txt" <<'PY'
import random, sys
seed, count = int(sys.argv[1]), int(sys.argv[2])
rng = random.Random(seed)
objects = ["sphere", "box", "small-bottle", "water-bottle", "bowling-pin"]
for k in range(count):
    obj = objects[k % len(objects)] if k < len(objects) else rng.choice(objects)
    options = ["--object", obj, "--seed", str(seed + k),
               "--start-azimuth-deg", "%.0f" % rng.uniform(-90, 120),
               "--hand-scale", "%.2f" % rng.uniform(0.8, 1.2),
               "--distance-mm", "%.0f" % rng.uniform(350, 900),
               "--tilt-deg", "%.0f" % rng.uniform(0, 40)]
    if rng.random() < 0.35:
        options.append("--left-hand")
    print("case%02d" % k, " ".join(options))
PY

run_case() {
  local name="$1"; shift
  local out="$work/$name"
  if [[ ! -f "$out/sequence.oni" ]]; then
    "$build/tools/inhandscan-synth" "$@" --scripted-frames 160 --turns 0.5 \
      --frames "0:$((frames - 1))" --no-tum --out "$out" --quiet ||
      { echo "bench_hand_init: $name: the generator failed" >&2; return 0; }
  fi
  local side=()
  [[ " $* " == *" --left-hand "* ]] && side=(--left-hand)
  rm -rf "$out/track"
  "$build/tools/inhandscan-track" "$out/sequence.oni" --gt "$out/gt" --out "$out/track" \
    "${side[@]}" ${IHS_TRACK_ARGS:-} --quiet > /dev/null || echo "bench_hand_init: $name: the tracker failed" >&2
}
export -f run_case
export work frames build IHS_TRACK_ARGS
echo "bench_hand_init: $count sequences from seed $seed in $work ..." >&2
xargs -P "$(nproc)" -L 1 bash -c 'run_case "$@"' _ < "$work/cases.txt"

python3 - "$work" <<'PY'
import json, os, statistics, sys
work = sys.argv[1]
print("%-7s %-13s %6s %6s %5s %5s %4s %9s %9s %6s %8s %5s %5s %6s" % (
    "case", "object", "az", "hand", "mm", "tilt", "side", "first mm", "mean mm", "scale",
    "doubtful", "over", "palm", "ms"))
means, flipped, palm_for_back = [], 0, 0
for line in open(os.path.join(work, "cases.txt")):
    name, *args = line.split()
    opt = dict(zip(args[0::2], args[1::2]))
    try:
        stats = json.load(open(os.path.join(work, name, "track", "stats.json")))
    except (OSError, ValueError):
        print("%-7s %-13s failed (see the messages above)" % (name, opt["--object"]))
        continue
    s, f = stats["summary"], stats["frames"]
    first = next((x["joint_error_mm"] for x in f if "joint_error_mm" in x), float("nan"))
    mean = s.get("joint_error_mm_mean", float("nan"))
    means.append(mean)
    over = s.get("turned_over_frames", 0)
    flipped += over > 10
    palm_for_back += s.get("palm_reversed_frames", 0) > 10
    print("%-7s %-13s %6s %6s %5s %5s %4s %9.1f %9.1f %6.3f %8d %5d %5d %6.1f" % (
        name, opt["--object"], opt["--start-azimuth-deg"], opt["--hand-scale"],
        opt["--distance-mm"], opt["--tilt-deg"], "L" if "--left-hand" in args else "R", first,
        mean, s["hand_scale"], s.get("doubtful_frames", 0), over,
        s.get("palm_reversed_frames", 0), s["ms_mean"]))
ok = [m for m in means if m == m]
print("joint error over %d sequences: mean %.1f mm, median %.1f mm; %d within 10 mm; "
      "%d flipped (turned over in more than 10 frames), %d of them palm for back" % (
    len(ok), statistics.mean(ok), statistics.median(ok), sum(m <= 10 for m in ok), flipped,
    palm_for_back))
PY
echo "work folder: $work"
