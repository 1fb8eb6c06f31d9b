#!/bin/sh
# Regenerates the golden pictures of the screenshot regression test
# (tests/viz/visual_regression_test.cpp) and, with --maps, the fixture maps they are drawn from.
#
#   tests/visual/regenerate_goldens.sh [--maps] [BUILD_DIR]
#
# BUILD_DIR is a configured build folder of this checkout (default: ./build). The pictures are
# rendered headless under `xvfb-run -a` (Mesa llvmpipe), like the test renders them.
#
# --maps first remakes the fixture maps from the simulated devices with fixed seeds:
#   omega_map.json is not remade: it is what the calibrator of an earlier release wrote (schema 2,
#     a cube calibrated without exploring the workspace), kept so that the pictures of such maps,
#     as users have them on disk, stay tested.
#   omni_map.json: made by the test itself (AUTOGRAV_UPDATE_FIXTURES=1) from the omni's true
#     field with a small estimation error and a few failed and unvisited vertices, so that the
#     pictures show every kind of marker.
#   falcon_explored_map.json: made by the test too, in milliseconds: the falcon's workspace
#     probed along 26 directions (to the simulator's reach), the grid fitted around it, the measurement
#     plan and the solve, so that the pictures show the explored workspace and every kind of
#     value (measured at the vertex, inside the stops, solved).
#
# The shader renderer's goldens (gl_*.png, tests/gl) are rewritten too when it is built.
#
# Look at the new pictures (and `git diff --stat tests/visual/golden`) before committing them.
set -eu

here=$(cd "$(dirname "$0")" && pwd)
source_dir=$(cd "$here/../.." && pwd)
golden="$here/golden"
maps=0
build=""
for argument in "$@"; do
  case "$argument" in
    --maps) maps=1 ;;
    -h|--help) sed -n '2,24p' "$0"; exit 0 ;;
    *) build="$argument" ;;
  esac
done
build=${build:-$source_dir/build}
if [ ! -f "$build/CMakeCache.txt" ]; then
  echo "regenerate_goldens: $build is not a configured build folder;" >&2
  echo "  configure one first: cmake -S $source_dir -B $build" >&2
  exit 2
fi
command -v xvfb-run >/dev/null 2>&1 || { echo "regenerate_goldens: needs xvfb-run (package xvfb)" >&2; exit 2; }

cmake --build "$build" --target autograv visual_regression_test -j 2

if [ "$maps" = 1 ]; then
  fixtures=1
else
  fixtures=0
fi

# -noreset: Xvfb would otherwise reset each time its last client leaves (see tests/run.sh).
xvfb_args="-screen 0 1280x1024x24 -noreset"
AUTOGRAV_UPDATE_FIXTURES=$fixtures AUTOGRAV_UPDATE_GOLDENS=1 xvfb-run -a -s "$xvfb_args" \
  "$build/tests/visual_regression_test" \
  --gtest_filter='VisualRegressionTest.RendersMatchTheGoldens'
# The fresh goldens must pass their own test, broken renders included.
xvfb-run -a -s "$xvfb_args" "$build/tests/visual_regression_test"

# The shader renderer draws through OSMesa, no display needed. Rewriting a golden counts as a
# failure of that run (so that it is never left on by mistake); the second run must pass.
if cmake --build "$build" --target renderer_test -j 2 >/dev/null 2>&1; then
  AUTOGRAV_UPDATE_GOLDEN=1 "$build/tests/renderer_test" --gtest_filter='*MatchesGolden*' || true
  "$build/tests/renderer_test"
fi
echo "regenerate_goldens: new goldens in $golden; review them before committing"
