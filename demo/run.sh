#!/usr/bin/env bash
# The main job on a simulated device: calibrate, save the map, render the scene to a PNG, check
# the map with a release test, and print the accuracy report. Installs missing Debian packages
# and builds first. Usage: bash demo/run.sh [sim:omni|sim:omega|sim:falcon]   (outputs in ./out/)
set -euo pipefail

device="${1:-sim:omni}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
jobs="$(nproc 2>/dev/null || echo 2)"
out="$root/out"
name="${device#sim:}"
cd "$root"

"$root/.ci/install-deps.sh"
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build/release -j "$jobs" --target autograv
autograv="$root/build/release/demo/autograv"
mkdir -p "$out"

printf '\n=== 1. calibrate %s (5x5x5 grid, simulated time)\n' "$device"
"$autograv" calibrate --device "$device" --grid 5 --out "$out/${name}_map.json" \
  --report "$out/${name}_calibration.json"

printf '\n=== 2. render the map (VTK, headless under xvfb-run)\n'
xvfb-run -a -s "-screen 0 1600x1200x24" "$autograv" render "$out/${name}_map.json" \
  -o "$out/${name}_scene.png" --size-px 1280x960 --truth "$device"
echo "scene: $out/${name}_scene.png"

printf '\n=== 3. verify: release at 100 random points, compensation on and off\n'
"$autograv" verify "$out/${name}_map.json" --device "$device" --report "$out/${name}_verify.json"

printf '\n=== the saved map\n'
"$autograv" inspect "$out/${name}_map.json"
printf '\nReports: %s %s\n' "$out/${name}_calibration.json" "$out/${name}_verify.json"
