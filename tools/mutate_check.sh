#!/usr/bin/env bash
# Damaged recordings through the default readers: a short generated recording gets one byte
# changed at a seeded offset (half of them in its first 64 KiB, where the headers and properties
# are), and each mutant goes through `inhandscan-frames info` and `inhandscan replay` with a 60 s
# limit. Prints how many crashed (a signal), hung (the limit), exited 0 with frames missing and
# nothing said, or were refused with an error; exit 1 unless there were no crashes, hangs or
# silent losses.
#   tools/mutate_check.sh [COUNT] [REPLAYS] [SEED] [WORK]
#   COUNT mutants through `frames info` (default 1000), the first REPLAYS of them also through
#   `inhandscan replay` (default 100: a replay takes seconds), seed 1, work folder /tmp.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
count="${1:-1000}"
replays="${2:-100}"
seed="${3:-1}"
work="${4:-$(mktemp -d /tmp/ihs-mutate-XXXXXX)}"
for n in "$count" "$replays" "$seed"; do
  [[ "$n" =~ ^[0-9]+$ ]] || { echo "mutate_check: COUNT, REPLAYS and SEED are whole numbers" >&2; exit 2; }
done
build="${IHS_BUILD_DIR:-$root/build}"
frames="$build/tools/inhandscan-frames"
app="$build/app/inhandscan"
synth="$build/tools/inhandscan-synth"
[[ -x "$frames" && -x "$app" && -x "$synth" ]] || IHS_TARGETS="inhandscan inhandscan-frames inhandscan-synth" "$root/tools/build.sh"
mkdir -p "$work"
"$synth" --object sphere --motion scripted --frames 0:10 --seed "$seed" --out "$work/seq" \
  --no-tum >/dev/null 2>&1
original="$work/seq/sequence.oni"
intact="$("$frames" info --json "$original" | sed -n 's/.*"depth_frames": *\([0-9]*\).*/\1/p')"
size="$(stat -c %s "$original")"
RANDOM="$seed"
random32() { echo $(((RANDOM << 17) ^ (RANDOM << 2) ^ (RANDOM & 3))); }

declare -A tally=()
count_outcome() { tally["$1 $2"]=$((${tally["$1 $2"]:-0} + 1)); }
classify() {  # tool, exit code, output
  local tool="$1" rc="$2" out="$3"
  if [[ $rc -eq 124 ]]; then count_outcome "$tool" hang; return; fi
  if [[ $rc -ge 128 ]]; then count_outcome "$tool" crash; return; fi
  if [[ $rc -ne 0 ]]; then count_outcome "$tool" refused; return; fi
  if [[ "$tool" == frames ]]; then
    local got skipped recovered
    got="$(sed -n 's/.*"depth_frames": *\([0-9]*\).*/\1/p' <<<"$out")"
    skipped="$(sed -n 's/.*"skipped_frames": *\([0-9]*\).*/\1/p' <<<"$out")"
    recovered="$(sed -n 's/.*"recovered": *\([a-z]*\).*/\1/p' <<<"$out")"
    if [[ "${got:-0}" -lt "$intact" && "${skipped:-0}" -eq 0 && "$recovered" != true ]]; then
      count_outcome "$tool" silent_loss
      echo "silent loss: $tool, mutant $i (offset $offset): $got of $intact frames" >&2
      return
    fi
  fi
  count_outcome "$tool" ok
}

mutant="$work/mutant.oni"
for ((i = 0; i < count; i++)); do
  cp "$original" "$mutant"
  if ((i % 2 == 0)); then offset=$(($(random32) % (size < 65536 ? size : 65536))); else offset=$(($(random32) % size)); fi
  old=$(od -An -tu1 -j "$offset" -N1 "$mutant" | tr -d ' ')
  new=$(((old + 1 + $(random32) % 255) % 256))
  printf "$(printf '\\%03o' "$new")" | dd of="$mutant" bs=1 seek="$offset" conv=notrunc status=none
  set +e
  out="$(timeout 60 "$frames" info --json "$mutant" 2>/dev/null)"
  rc=$?
  set -e
  classify frames "$rc" "$out"
  if ((i < replays)); then
    rm -rf "$work/out"
    set +e
    timeout 60 "$app" replay "$mutant" --out "$work/out" --set pipeline.preview_every=0 -q >/dev/null 2>&1
    rc=$?
    set -e
    classify replay "$rc" ""
  fi
done
rm -f "$mutant"
status=0
for tool in frames replay; do
  line="$tool:"
  for outcome in ok refused crash hang silent_loss; do
    n=${tally["$tool $outcome"]:-0}
    line+=" $outcome $n"
    [[ $outcome =~ ^(crash|hang|silent_loss)$ && $n -gt 0 ]] && status=1
  done
  echo "$line"
done
echo "($count mutants of a $intact-frame recording, $replays replayed, seed $seed; work: $work)"
exit "$status"
