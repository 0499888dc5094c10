#!/usr/bin/env bash
# One-command set-up for a Debian 12 machine (as root): installs the Debian packages that are missing,
# configures and builds a preset, then runs the main job ("run") or the whole test suite ("test").
# Idempotent: a second run installs nothing and rebuilds only what changed.
set -euo pipefail
cd "$(dirname "$0")/.."

mode="${1:-run}"
preset="${RESECTO_PRESET:-release}"
packages=(
  build-essential cmake pkg-config
  libglfw3-dev libglm-dev libopenmesh-dev libtet1.5-dev libhidapi-dev libdraco-dev libimgui-dev libstb-dev
  libgl-dev libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev libfcl-dev
  xvfb xauth libgl1-mesa-dri zlib1g-dev draco
  chromium parallel
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

jobs="$(nproc)"
[ -f "build/$preset/CMakeCache.txt" ] || cmake --preset "$preset" >/dev/null
mkdir -p "build/$preset"
if ! cmake --build --preset "$preset" -j "$jobs" >"build/$preset/build.log" 2>&1; then
  grep -E 'error|Error' -A3 "build/$preset/build.log" | head -60 >&2
  echo "setup: build failed; full log in build/$preset/build.log" >&2
  exit 1
fi

bin="build/$preset/console/resecto"
case "$mode" in
  run)
    bash scripts/main_job.sh "$bin"
    ;;
  test)
    ctest --preset "$preset" -j "$jobs"
    ;;
  *)
    echo "usage: scripts/setup.sh [run|test]" >&2
    exit 2
    ;;
esac
