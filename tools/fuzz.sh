#!/usr/bin/env bash
# Fuzzes the readers of untrusted input with libFuzzer (clang, ASan + UBSan): the .oni reader,
# TUM folder lists and their PNG images, the JPEG decoder (.oni colour frames, TUM images), the
# mesh readers (PLY, OBJ, STL) and the config parser. Builds the targets in build-fuzz, runs each
# for SECONDS from a small seed corpus and prints, per target, the executions and the failing
# inputs — crashes, timeouts (20 s), out-of-memory (2 GiB) — kept under
# build-fuzz/tools/fuzz/work/TARGET/crashes: make each one a test. Exit 1 when any input failed.
#   tools/fuzz.sh [SECONDS] [TARGET ...]     (default: 60 s each, every target)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-60}"
[[ $# -gt 0 ]] && shift
targets=("$@")
[[ ${#targets[@]} -eq 0 ]] &&
  targets=(oni_reader_fuzzer tum_folder_fuzzer png_decoder_fuzzer jpeg_decoder_fuzzer
    mesh_reader_fuzzer config_fuzzer)
[[ "$seconds" =~ ^[0-9]+$ && "$seconds" -ge 1 ]] || {
  echo "fuzz: SECONDS must be a positive whole number, got '$seconds'" >&2
  exit 2
}
"$root/tools/install-deps.sh" --dev  # clang and its libFuzzer among them.
command -v clang++ >/dev/null || {
  echo "fuzz: needs clang (apt-get install clang)" >&2
  exit 2
}
build="${IHS_FUZZ_BUILD_DIR:-$root/build-fuzz}"
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DIHS_FUZZ=ON >/dev/null
cmake --build "$build" --parallel "$(nproc)" $(printf -- '--target %s ' "${targets[@]}") >/dev/null

# Seeds: a valid input of each kind (the real recording when ../shared/data is there).
seed() {
  local target="$1" corpus="$2"
  case "$target" in
    oni_reader_fuzzer)
      local real="${IHS_SHARED_DIR:-$root/../shared}/data/oni/kinect1-room-12frames.oni"
      [[ -f "$real" ]] && cp "$real" "$corpus/real.oni"
      printf 'NI10' >"$corpus/header" ;;
    tum_folder_fuzzer)
      printf '# depth\n1.000000 depth/1.png\n1.033333 depth/2.png\n\0001.000100 rgb/1.png\n1.033400 rgb/2.png\n' >"$corpus/lists"
      printf '1.0 depth/1.png\n\0001.0 rgb/1.png\n\0001.0 rgb/1.png 1.0 depth/1.png\n' >"$corpus/associations" ;;
    png_decoder_fuzzer)
      # A 16-bit grey depth PNG and an 8-bit RGB one, 8x6 pixels (first byte: depth or colour).
      python3 - "$corpus" <<'PY'
import struct, sys, zlib
def png(width, height, bit_depth, colour_type, row):
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    header = struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0)
    raw = b"".join(b"\0" + row(y) for y in range(height))
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
depth = png(8, 6, 16, 0, lambda y: b"".join(struct.pack(">H", 500 + 7 * x + y) for x in range(8)))
colour = png(8, 6, 8, 2, lambda y: bytes((30 * x, 40 * y, 200) [c] for x in range(8) for c in range(3)))
open(sys.argv[1] + "/depth", "wb").write(b"\1" + depth)
open(sys.argv[1] + "/colour", "wb").write(b"\0" + colour)
PY
      ;;
    jpeg_decoder_fuzzer)
      # 8x6-pixel JPEGs written by OpenCV: colour, progressive colour, and grey with restart
      # markers.
      base64 -d >"$corpus/colour" <<'B64'
/9j/4AAQSkZJRgABAQAAAQABAAD/2wBDAAIBAQEBAQIBAQECAgICAgQDAgICAgUEBAMEBgUGBgYFBgYGBwkIBgcJBwYGCAsI
CQoKCgoKBggLDAsKDAkKCgr/2wBDAQICAgICAgUDAwUKBwYHCgoKCgoKCgoKCgoKCgoKCgoKCgoKCgoKCgoKCgoKCgoKCgoK
CgoKCgoKCgoKCgoKCgr/wAARCAAGAAgDASIAAhEBAxEB/8QAFQABAQAAAAAAAAAAAAAAAAAAAAf/xAAfEAABAAsAAAAAAAAA
AAAAAAAAAQIEBgcJESNBQ9H/xAAVAQEBAAAAAAAAAAAAAAAAAAAFB//EACIRAAAEBAcAAAAAAAAAAAAAAAABAgYEBQckFBdR
YZGh0f/aAAwDAQACEQMRAD8AorgysIa1UuMeNSeAAMoI9XVl5D3a+tC2FimlQnrizvl8l4P/2Q==
B64
      base64 -d >"$corpus/progressive" <<'B64'
/9j/4AAQSkZJRgABAQAAAQABAAD/2wBDAAIBAQEBAQIBAQECAgICAgQDAgICAgUEBAMEBgUGBgYFBgYGBwkIBgcJBwYGCAsI
CQoKCgoKBggLDAsKDAkKCgr/2wBDAQICAgICAgUDAwUKBwYHCgoKCgoKCgoKCgoKCgoKCgoKCgoKCgoKCgoKCgoKCgoKCgoK
CgoKCgoKCgoKCgoKCgr/wgARCAAGAAgDASIAAhEBAxEB/8QAFQABAQAAAAAAAAAAAAAAAAAAAAb/xAAVAQEBAAAAAAAAAAAA
AAAAAAAEBv/aAAwDAQACEAMQAAABogWx/8QAFxAAAwEAAAAAAAAAAAAAAAAAAAQFB//aAAgBAQABBQJDLJp//8QAGhEAAAcA
AAAAAAAAAAAAAAAAAAEEBQYTM//aAAgBAwEBPwFVIXq3cx//xAAaEQABBQEAAAAAAAAAAAAAAAAFAAEDBhYj/9oACAECAQE/
AaEaK56Pq6//xAAXEAADAQAAAAAAAAAAAAAAAAAAAjGR/9oACAEBAAY/AqmH/8QAFRABAQAAAAAAAAAAAAAAAAAAACH/2gAI
AQEAAT8hnD//2gAMAwEAAgADAAAAEPv/xAAYEQACAwAAAAAAAAAAAAAAAAAAARGx0f/aAAgBAwEBPxCTtWH/xAAYEQACAwAA
AAAAAAAAAAAAAAAAAVFh0f/aAAgBAgEBPxDNcKj/xAAYEAACAwAAAAAAAAAAAAAAAAAAEUFh0f/aAAgBAQABPxBqpPD/2Q==
B64
      base64 -d >"$corpus/grey" <<'B64'
/9j/4AAQSkZJRgABAQAAAQABAAD/2wBDAAIBAQEBAQIBAQECAgICAgQDAgICAgUEBAMEBgUGBgYFBgYGBwkIBgcJBwYGCAsI
CQoKCgoKBggLDAsKDAkKCgr/wAALCAAGAAgBAREA/8QAFAABAAAAAAAAAAAAAAAAAAAABP/EAB0QAAICAgMBAAAAAAAAAAAA
AAECAwQFBgcICSH/3QAEAAH/2gAIAQEAAD8AB4w63xt1q4CznYzeqNu3hNA0+/smZq4mBJLU1WjVktSpCsjojSlImChnRSxA
LKPo/9k=
B64
      ;;
    mesh_reader_fuzzer)
      printf '\000ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >"$corpus/ply"
      printf '\001v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$corpus/obj"
      printf '\002solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n' >"$corpus/stl" ;;
    config_fuzzer)
      printf '# a config\nfusion.pairwise.contact_weight = 2.5\n[tracker.fit]\nouter_iterations = 4\n[]\nfusion.tsdf.color = off\ntracker.segmentation.crop_min_mm = -1,2,300\n' >"$corpus/conf" ;;
  esac
}

status=0
for target in "${targets[@]}"; do
  work="$build/tools/fuzz/work/$target"
  mkdir -p "$work/corpus" "$work/crashes"
  seed "$target" "$work/corpus"
  log="$work/last-run.log"
  # Inputs up to 64 KiB: a recording's headers and first frames (the whole real recording per
  # execution would allow only a few thousand in a minute).
  (cd "$work" && "$build/tools/fuzz/$target" -max_total_time="$seconds" -print_final_stats=1 \
    -max_len=65536 -rss_limit_mb=2048 -timeout=20 -artifact_prefix="$work/crashes/" corpus \
    >"$log" 2>&1) || true
  executions="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  crashes="$(find "$work/crashes" -type f | wc -l)"
  printf '%-20s %10s executions in %s s, %s failing inputs%s\n' "$target" "${executions:-0}" \
    "$seconds" "$crashes" "$([[ $crashes -gt 0 ]] && echo " ($work/crashes)")"
  [[ -z "$executions" ]] && { echo "  (no final stats: see $log)"; status=1; }
  [[ "$crashes" -gt 0 ]] && status=1
done
exit "$status"
