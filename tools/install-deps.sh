#!/usr/bin/env bash
# Installs the Debian packages that are missing: those of tools/debian-packages.txt (to build and
# run inhandscan) and, with --dev, those of tools/debian-packages-dev.txt (tests, the benchmark's
# Open3D peer, fuzzing). --list prints the packages it would want, " (missing)" after those not
# installed, and installs nothing.
# Runs `apt-get update` only when something has to be installed, so a second run is instant.
#   tools/install-deps.sh [--dev] [--list]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
lists=("$here/debian-packages.txt")
list_only=false
for arg in "$@"; do
  case "$arg" in
    --dev) lists+=("$here/debian-packages-dev.txt") ;;
    --list) list_only=true ;;
    *)
      echo "install-deps: unknown argument '$arg' (use --dev and/or --list)" >&2
      exit 2
      ;;
  esac
done
mapfile -t wanted < <(sed -e 's/#.*//' -e 's/[[:space:]]//g' "${lists[@]}" | grep -v '^$')

missing=()
for pkg in "${wanted[@]}"; do
  status="$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)"
  mark=""
  [[ "$status" == "install ok installed" ]] || { missing+=("$pkg"); mark=" (missing)"; }
  if $list_only; then echo "$pkg$mark"; fi
done
if $list_only; then exit 0; fi
[[ ${#missing[@]} -eq 0 ]] && exit 0

sudo_cmd=()
if [[ "$(id -u)" -ne 0 ]]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo_cmd=(sudo)
  else
    echo "install-deps: missing packages (${missing[*]}) and not root; install them or run as root." >&2
    exit 1
  fi
fi
echo "install-deps: installing ${#missing[@]} package(s): ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
