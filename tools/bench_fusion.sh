#!/usr/bin/env bash
# The scanner's benchmark (registration and fusion): generator sequences of the paper's four
# objects turned by the paper's four recorded hand motions (full sensor noise), scanned by
# inhandscan-scan with the procedural hand template, the tracker initialising itself. For ours
# (γt = 15) and the baselines — visual only (γt = 0), contacts only, no ICP — prints the paper's
# Table 1 (dimensions: truth, scan, error; mean absolute error over the 8 measures), the sphere's
# volume, Table 2 (pairwise registration error at the fingertips, mean ± std), the surface's
# Chamfer distance and completeness, and ms per frame of the fusion stage and of the export.
#   tools/bench_fusion.sh [FRAMES] [DATA_DIR] [WORK_DIR]
# FRAMES: the first FRAMES frames of each session (default 300; "all" for whole sessions).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
frames="${1:-300}"
data="${2:-$root/../shared/data/hand-iccv15}"
work="${3:-$(mktemp -d)}"
build="${IHS_BUILD_DIR:-$root/build}"
[[ -d "$data/sequences" ]] || { echo "bench_fusion: no hand data in $data" >&2; exit 3; }
range=()
[[ "$frames" == all ]] || range=(--frames "0:$((frames - 1))")
declare -A objects=([001-water-bottle]=water-bottle [002-bowling-pin]=bowling-pin
                    [003-small-bottle]=small-bottle [004-sphere]=sphere)
declare -A flags=([ours]="" [visual-only]="--gamma-t 0" [contacts-only]="--contacts-only"
                  [no-icp]="--no-icp")
methods=(ours visual-only contacts-only no-icp)
for session in 001-water-bottle 002-bowling-pin 003-small-bottle 004-sphere; do
  out="$work/$session"
  "$build/tools/inhandscan-synth" --object "${objects[$session]}" \
    --motion "recorded:$data/sequences/$session" "${range[@]}" --no-tum --out "$out" --quiet
  for method in "${methods[@]}"; do
    # shellcheck disable=SC2086
    "$build/tools/inhandscan-scan" "$out/sequence.oni" --out "$out/$method" --gt "$out/gt" \
      ${flags[$method]} --quiet > "$out/$method.log" 2>&1 ||
      echo "bench_fusion: $session $method failed (see $out/$method.log)" >&2
  done
  rm -f "$out/sequence.oni"
done
python3 - "$work" "${methods[@]}" <<'PY'
import json, os, sys
work, methods = sys.argv[1], sys.argv[2:]
sessions = ["001-water-bottle", "002-bowling-pin", "003-small-bottle", "004-sphere"]
def load(session, method):
    path = os.path.join(work, session, method, "stats.json")
    return json.load(open(path))["summary"] if os.path.exists(path) else None
print("Table 1: dimensions (mm) — truth, then each method's scan and its error")
print("%-18s %-14s %7s" % ("object", "measure", "truth") +
      "".join(" %17s" % m for m in methods))
errors = {m: [] for m in methods}
rows = {}
for session in sessions:
    for method in methods:
        s = load(session, method)
        for d in (s or {}).get("evaluation", {}).get("dimensions", []):
            rows.setdefault((session, d["measure"]), {"truth": d["truth_mm"]})[method] = d["scan_mm"]
for (session, measure), r in rows.items():
    line = "%-18s %-14s %7.1f" % (session, measure, r["truth"])
    for m in methods:
        if m in r:
            line += " %8.1f (%+6.1f)" % (r[m], r[m] - r["truth"])
            errors[m].append(abs(r[m] - r["truth"]))
        else:
            line += " %17s" % "-"
    print(line)
print("%-41s" % "mean absolute error (mm)" +
      "".join(" %17s" % ("%.2f (%d)" % (sum(e) / len(e), len(e)) if e else "-")
              for m, e in errors.items()))
print("%-41s" % "sphere volume error (%)" + "".join(
    " %17s" % ("%+.1f" % (100 * (v["scan"] / v["truth"] - 1))
               if (v := ((load("004-sphere", m) or {}).get("evaluation", {}).get("volume_mm3")))
               else "-") for m in methods))
print()
print("Table 2 and the rest, per session and method")
print("%-18s %-14s %15s %9s %9s %11s %9s %9s %9s" % ("session", "method", "pairwise mm",
      "chamfer", "complete", "registered", "fusion ms", "track ms", "export s"))
for session in sessions:
    for m in methods:
        s = load(session, m)
        if not s:
            print("%-18s %-14s failed" % (session, m))
            continue
        e = s.get("evaluation", {})
        p = e.get("pairwise_error_mm", {})
        print("%-18s %-14s %15s %9.2f %8.1f%% %5d/%-5d %9.1f %9.1f %9.2f" % (
            session, m, "%.2f ± %.2f" % (p.get("mean", 0), p.get("std", 0)),
            e.get("chamfer_mm", float("nan")), 100 * e.get("completeness", 0),
            s["registered_frames"], s["frames"], s["ms_per_frame"]["fusion"],
            s["ms_per_frame"]["track"], s["export_ms"]["total"] / 1000))
PY
