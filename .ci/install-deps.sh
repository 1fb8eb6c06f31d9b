#!/usr/bin/env bash
# Installs the Debian packages autograv needs to build, test and run, only those missing.
# Used by demo/run.sh and tests/run.sh; safe to run again. Needs root (or sudo) and apt.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  ccache                           # tests/run.sh: its builds share objects compiled alike
  dpkg-dev                         # dpkg-shlibdeps: the Debian package's Depends (cpack -G DEB)
  libeigen3-dev                    # maths (autograv::core)
  nlohmann-json3-dev               # map files and reports
  libcli11-dev                     # command-line parsing
  libvtk9-dev mpi-default-dev libx11-dev  # autograv::viz (Debian's VTK config needs MPI C)
  fonts-dejavu-core                # scene and plot text (the goldens were rendered with it)
  libglfw3-dev libosmesa6-dev libgl-dev libpng-dev  # autograv::gl, autograv::image (PNG)
  libgtest-dev libgmock-dev libbenchmark-dev          # tests and benchmarks
  xvfb xauth                       # X server for the VTK screenshot tests
  tmux                             # drives the terminal wizard in its end-to-end test
  clang-format                     # style check
  doxygen                          # API reference (target autograv_docs)
  clang libclang-rt-14-dev         # fuzz targets (libFuzzer, ASan and UBSan runtimes)
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
