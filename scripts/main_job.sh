#!/usr/bin/env bash
# The main job of the README's first command: generate and validate the procedural models, then, where
# there is a display (DISPLAY or WAYLAND_DISPLAY set), open the operator console on the built-in demo;
# otherwise run the demo headless through the emulated device, recording it, print a summary of its
# report, and replay the recording with every collision step's state hash verified; then ten seconds
# against the clock (again at the advised physics rate on a machine too slow for 960 Hz) beside the
# machine's own deadline floor.
set -euo pipefail
bin="$1"
out="${RESECTO_OUT:-out}"
mkdir -p "$out"
"$bin" mesh prostate --triangles 8640 -o "$out/prostate.off" | head -3
"$bin" mesh resectoscope -o "$out/resectoscope.off" | head -1
"$bin" mesh tetra "$out/prostate.off" -o "$out/prostate.vtk" | head -2
echo
if [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; then
  echo "opening the operator console (the demo procedure; close the window to finish)"
  "$bin" console --procedure demo --report "$out/console-report.json"
  echo "the console's report is in $out/console-report.json"
  exit 0
fi
"$bin" run --headless --procedure demo --report "$out/demo-report.json" --trace "$out/demo-trace.json" \
  --record "$out/demo.rsrec"
echo
# The recording re-simulated through the same core: every collision step's hash must match the run's.
"$bin" replay "$out/demo.rsrec" --verify
"$bin" rec info "$out/demo.rsrec" | sed -n '2,5p'
echo
# The same procedure against the clock: ten seconds at 960 Hz, every missed deadline counted.
"$bin" run --headless --realtime --procedure demo --seconds 10 --report "$out/realtime-report.json" \
  --trace "$out/realtime-trace.json"
echo
# A machine too slow for 960 Hz gets the report's advice; the run is then shown at the advised rate.
advised="$(sed -n 's/.*"advised_substeps": *\([0-9][0-9]*\).*/\1/p' "$out/realtime-report.json" | head -1)"
if [ -n "$advised" ]; then
  echo "the same ten seconds at the advised --substeps $advised:"
  "$bin" run --headless --realtime --procedure demo --seconds 10 --substeps "$advised" \
    --report "$out/realtime-advised-report.json" | grep -E 'physics|tick|deadlines'
  echo
fi
# The machine's own floor for that schedule: the same scheduler and priority with ticks that compute
# nothing. Misses it shows too are the machine's (docs/commands.md, "Running the simulator"; benchmarks/results/README.md).
floor="$(dirname "$bin")/../benchmarks/deadline_floor_bench"
if [ -x "$floor" ]; then
  echo "the machine's own floor (the same schedule, each tick only 300 us of busy waiting):"
  "$floor" --benchmark_filter='BM_DeadlineFloor/300/' 2>/dev/null | tail -3
fi
echo
echo "models, reports, traces and the recording are in $out/ (open demo-trace.json or realtime-trace.json in https://ui.perfetto.dev)"
