#!/usr/bin/env bash
# Builds autograv and runs every test: the full suite (VTK scene tests under xvfb-run, the OSMesa
# renderer with no display at all), the CHAI3D bridge against its stand-in headers, then the
# suite again under AddressSanitizer + UndefinedBehaviorSanitizer, then the concurrency tests
# under ThreadSanitizer, and every fuzz target (tests/fuzz) for a bounded time.
# Installs missing Debian packages first. Usage: bash tests/run.sh   (from anywhere)
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
jobs="$(nproc 2>/dev/null || echo 2)"
start_s=$SECONDS
fuzz_seconds=30  # per fuzz target; there are four
cd "$root"

"$root/.ci/install-deps.sh"

# One compiler cache for every build below, kept in build/ (ignored by git): the CHAI3D stand-in
# build compiles core, sim and most of the demo exactly as the release build does, and a second
# run of this script recompiles only what changed. Paths are taken relative to the checkout, so
# objects compiled in build/release serve build/chai3d-mock.
export CCACHE_DIR="$root/build/ccache" CCACHE_BASEDIR="$root" CCACHE_NOHASHDIR=1
export CMAKE_C_COMPILER_LAUNCHER=ccache CMAKE_CXX_COMPILER_LAUNCHER=ccache

step() { printf '\n=== %s (%ds)\n' "$*" $((SECONDS - start_s)); }

# Every build below carries line tables only (-g1): stack traces from the sanitizers and gdb
# still name files and lines, and each build compiles about 40 % faster than with full debug
# information (-g, which also makes the Eigen-heavy objects several times larger), the gold
# linker links the seventy-odd test programs in half the time of the default one. These are
# the test command's builds; a developer's own build keeps CMake's defaults.
release_flags=(-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG"
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG")
gold=(-DCMAKE_EXE_LINKER_FLAGS_INIT=-fuse-ld=gold -DCMAKE_SHARED_LINKER_FLAGS_INIT=-fuse-ld=gold)

step "configure and build (RelWithDebInfo, warnings as errors)"
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAUTOGRAV_WARNINGS_AS_ERRORS=ON \
  "${release_flags[@]}" "${gold[@]}"
cmake --build build/release -j "$jobs"

step "tests that need no display (core, sim, wizard, OSMesa renderer)"
(cd build/release && env -u DISPLAY ctest --output-on-failure -j "$jobs" -LE xvfb)

step "VTK scene tests under xvfb-run"
# One X server for the parallel tests, with -noreset: by default Xvfb resets whenever its last
# client leaves and drops the connections still in their handshake, so a test that connects just
# as another one exits dies of SIGPIPE (or cannot open the display).
(cd build/release && xvfb-run -a -s "-screen 0 1600x1200x24 -noreset" \
  ctest --output-on-failure -j "$jobs" -L xvfb)

step "API reference (Doxygen): an undocumented public member fails the build"
cmake --build build/release --target autograv_docs

step "CHAI3D bridge against the stand-in of CHAI3D 3.3's API (CHAI3D is not packaged in Debian)"
cmake -S . -B build/chai3d-mock -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAUTOGRAV_WARNINGS_AS_ERRORS=ON \
  "${release_flags[@]}" "${gold[@]}" \
  -DAUTOGRAV_CHAI3D_DIR="$root/plugin/chai3d/test_mock" \
  -DAUTOGRAV_BUILD_VIZ=OFF -DAUTOGRAV_BUILD_GL=OFF -DAUTOGRAV_BUILD_DEMO=ON
cmake --build build/chai3d-mock -j "$jobs" --target chai3d_bridge_test chai3d_devices_test autograv \
  demo_session_test
build/chai3d-mock/plugin/chai3d/chai3d_bridge_test
# chai3d:N device names end to end: the registry, and `autograv wizard --device chai3d:0`.
build/chai3d-mock/plugin/chai3d/chai3d_devices_test
# The demo's A key on chai3d:0 gives the map it gives on the simulation behind it.
build/chai3d-mock/tests/demo_session_test --gtest_filter='*Chai3d*'

step "AddressSanitizer + UndefinedBehaviorSanitizer build of core, sim and their tests"
# -O1 with assertions on (Debug's NDEBUG-free flags): the optimisation AddressSanitizer's own
# documentation suggests, several times faster than -O0 on Eigen-heavy simulation code, with
# Eigen's and our own assertions still checked.
cmake -S . -B build/asan -DCMAKE_BUILD_TYPE=Debug -DAUTOGRAV_SANITIZE=ON "${gold[@]}" \
  -DCMAKE_CXX_FLAGS_DEBUG="-g1 -O1" -DCMAKE_C_FLAGS_DEBUG="-g1 -O1" \
  -DAUTOGRAV_BUILD_VIZ=OFF -DAUTOGRAV_BUILD_GL=OFF -DAUTOGRAV_BUILD_DEMO=OFF
cmake --build build/asan -j "$jobs"
# Tests labelled release_only (tests/CMakeLists.txt: whole calibrations and verifications on every
# simulated device, minutes each here) ran in the release stage above; the install tests (label
# install: the installed prefix, the Debian package) too.
(cd build/asan && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --output-on-failure -j "$jobs" -LE "xvfb|release_only|install")

step "libFuzzer targets (clang, ASan + UBSan): each on its seed corpus for ${fuzz_seconds}s"
cmake -S . -B build/fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAUTOGRAV_FUZZ=ON "${release_flags[@]}" \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DAUTOGRAV_WARNINGS_AS_ERRORS=ON \
  -DAUTOGRAV_BUILD_TESTS=OFF -DAUTOGRAV_BUILD_VIZ=OFF -DAUTOGRAV_BUILD_GL=OFF
cmake --build build/fuzz -j "$jobs" --target autograv_fuzzers
tests/fuzz/run_fuzzers.sh build/fuzz "$fuzz_seconds"

if [[ -f tests/core/compensation/gravity_compensated_device_concurrency_test.cpp ]]; then
  step "ThreadSanitizer: map published to a live servo thread, wizard on its own servo thread, calibrate(), the demo's A key"
  cmake -S . -B build/tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS=-fsanitize=thread \
    "${release_flags[@]}" \
    -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread \
    -DAUTOGRAV_BUILD_VIZ=OFF -DAUTOGRAV_BUILD_GL=OFF -DAUTOGRAV_BUILD_DEMO=OFF
  cmake --build build/tsan -j "$jobs" --target gravity_compensated_device_concurrency_test \
    calibration_wizard_test calibrate_test demo_session_test
  TSAN_OPTIONS=halt_on_error=1 build/tsan/tests/gravity_compensated_device_concurrency_test
  TSAN_OPTIONS=halt_on_error=1 build/tsan/tests/calibration_wizard_test --gtest_filter='*OwnThread*'
  TSAN_OPTIONS=halt_on_error=1 build/tsan/tests/calibrate_test
  TSAN_OPTIONS=halt_on_error=1 build/tsan/tests/demo_session_test \
    --gtest_filter='*ServoThread*:*RealTimeThread*'
fi

step "all tests passed"
