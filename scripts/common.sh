# Shared by scripts/demo.sh and scripts/test.sh: install the Debian packages omnical needs
# (only the missing ones), then configure and build in Release.
# Environment: OMNICAL_BUILD_DIR (default: build/<demo|test>, set by the caller through
# omnical_build_kind), OMNICAL_JOBS (default: nproc).

omnical_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
# demo and test build with different options: separate trees avoid full rebuilds.
build_dir=${OMNICAL_BUILD_DIR:-$omnical_root/build/${omnical_build_kind:-test}}
jobs=${OMNICAL_JOBS:-$(nproc)}

# Why each package is here: see docs/dependencies.md.
omnical_packages=(
  g++ cmake ninja-build pkg-config
  libeigen3-dev libceres-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libboost-dev zlib1g-dev
  libopencv-dev libopencv-contrib-dev libapriltag-dev
  libgtest-dev libgmock-dev libbenchmark-dev python3
  ffmpeg python3-numpy
  python3-dev pybind11-dev python3-pytest python3-matplotlib python3-opencv python3-mrcal
)

install_dependencies() {
  local missing=()
  for package in "${omnical_packages[@]}"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "omnical: installing Debian packages: ${missing[*]}"
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "omnical: need root or sudo to install: ${missing[*]}" >&2; return 1; }
    sudo=sudo
  fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# The Python module is built for Debian's interpreter, the one the python3-* packages above
# are for (another python3 may come first on PATH, e.g. pyenv's).
python_args=()
[ -x /usr/bin/python3 ] && python_args=(-DPython_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3)

configure_and_build() {
  cmake -S "$omnical_root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "${python_args[@]}" "$@"
  cmake --build "$build_dir" -j "$jobs"
}

# The demo tree: Release, no tests or benchmarks; sets $omnical to the CLI binary.
prepare_demo_build() {
  install_dependencies
  configure_and_build -DOMNICAL_BUILD_TESTS=OFF -DOMNICAL_BUILD_BENCHMARKS=OFF
  omnical="$build_dir/tools/omnical"
}
