#!/usr/bin/env bash
# Installs the Debian 12 packages dwellfit needs to build, test, fuzz, benchmark
# and plot. Idempotent: when every package is already installed it only says so and
# never calls apt-get (no network, under a second).
#
#   bash cmake/install-debian-deps.sh
#
# Runs as root, or through sudo when run as another user.
set -euo pipefail

packages=(
  build-essential
  make
  cmake
  pkg-config
  libceres-dev
  libeigen3-dev
  libgoogle-glog-dev
  libgflags-dev
  libyaml-cpp-dev
  libgtest-dev
  libgmock-dev
  libbenchmark-dev
  libfccp-dev
  libboost-dev
  libtbb-dev
  # MATLAB MAT files (estimator/matfile); SciPy writes and reads them in the tests.
  libmatio-dev
  python3-scipy
  gnuplot-nox
  # The library-state check (tests/check_library_state.py).
  python3
  # The browser test of report.html (tests/run/report_in_browser.py).
  chromium
  # The Python module (python/, -DDWELLFIT_PYTHON=ON), its tests and example.
  pybind11-dev
  python3-dev
  python3-numpy
  python3-pytest
  python3-matplotlib
  # The fuzzers (tests/fuzz): Clang with its libFuzzer and sanitizer runtimes.
  clang-14
  libclang-rt-14-dev
)

is_installed() {
  [[ "$(dpkg-query -W -f='${db:Status-Status}' "$1" 2>/dev/null || true)" == "installed" ]]
}

missing=()
for package in "${packages[@]}"; do
  if ! is_installed "${package}"; then
    missing+=("${package}")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "install-debian-deps: all ${#packages[@]} packages already installed; nothing to do."
  exit 0
fi

if [[ "$(id -u)" -eq 0 ]]; then
  sudo=()
elif command -v sudo >/dev/null 2>&1; then
  sudo=(sudo)
else
  echo "install-debian-deps: missing ${missing[*]}, and not root and no sudo: install them as root." >&2
  exit 1
fi

echo "install-debian-deps: installing ${#missing[@]} missing package(s): ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive \
  apt-get install -y --no-install-recommends "${missing[@]}"

still_missing=()
for package in "${missing[@]}"; do
  if ! is_installed "${package}"; then
    still_missing+=("${package}")
  fi
done
if ((${#still_missing[@]} > 0)); then
  echo "install-debian-deps: still not installed: ${still_missing[*]}" >&2
  exit 1
fi
echo "install-debian-deps: done."
