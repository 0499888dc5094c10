#!/usr/bin/env bash
# The main job of the README's first command: generate the procedural models, validate them, build the
# volumetric tissue model, and print their statistics. Later the simulator itself runs here.
set -euo pipefail
bin="$1"
out="${RESECTO_OUT:-out}"
mkdir -p "$out"
"$bin" mesh prostate --triangles 8640 -o "$out/prostate.off"
echo
"$bin" mesh resectoscope -o "$out/resectoscope.off"
echo
"$bin" mesh tetra "$out/prostate.off" -o "$out/prostate.vtk"
echo
echo "models written to $out/ (open the .off and .vtk files in ParaView, MeshLab or 3D Slicer)"
