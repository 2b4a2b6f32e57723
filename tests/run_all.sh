#!/usr/bin/env bash
# Every check of the repository, from a fresh Debian 12 machine (as root, or a
# user with sudo), in the order they stop at the first failure:
#   1. the Debian packages that are missing (cmake/install-debian-deps.sh);
#   2. the Release build and its test suite (build/);
#   3. the whole test suite again under AddressSanitizer and
#      UndefinedBehaviorSanitizer (build-sanitize/, DWELLFIT_SANITIZE=ON);
#   4. the libFuzzer targets built with Clang (build-fuzz/): each replays the
#      committed seeds and regression inputs, then fuzzes for
#      $DWELLFIT_FUZZ_SECONDS seconds (default 8; 0: replay only).
#
#   bash tests/run_all.sh      (what .ci/run does)
#
# $DWELLFIT_JOBS sets the build and test parallelism (default 2).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
jobs=${DWELLFIT_JOBS:-2}
fuzz_seconds=${DWELLFIT_FUZZ_SECONDS:-8}

step() { echo "=== run_all: $* ($(date +%T))"; }

step "dependencies"
bash cmake/install-debian-deps.sh

step "Release build and tests"
# Debian's interpreter, whose NumPy and pytest the dependencies install.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DDWELLFIT_PYTHON=ON \
  -DPython3_EXECUTABLE=/usr/bin/python3
cmake --build build -j"${jobs}"
ctest --test-dir build --output-on-failure -j"${jobs}"

step "ASan+UBSan build and tests"
# Benchmarks are left out: they are speed programs, not tests. -O1 with line
# tables (-g1): reports name file and line, and the build takes half the
# time of -O2 -g.
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DDWELLFIT_SANITIZE=ON \
  -DDWELLFIT_BUILD_BENCHMARKS=OFF
cmake --build build-sanitize -j"${jobs}"
# Tests that repeat, over the whole measured beam or hundreds of replicas, code
# that lighter tests run under the sanitizers too (the beam fit on one and three
# threads, the profile of beam-selected.yaml, coverage on a few replicas,
# select_model's verbose run, the model-selection unit tests, the coverage study
# without guesses, two hundred random starts, four merged sensitivity shards,
# the design study's seeds twice over and its tool run: each has a one-replica,
# one-shard or one-arm sibling that runs here), and the packaging
# tests (outside projects built against the install), the browser tests
# (report.html in Chromium, whose writing the identify tests run) and the Python
# tests (Debian's interpreter is given to the Release step; the MAT reader's own
# tests run here) run in the Release step only. Under ASan the two largest took 229 s and 175 s, the rest some 300 s.
heavy='MeasuredBeamFilesAreByteIdenticalOnOneAndTwoThreads|clamped-beam-27C/beam\.yaml|'
heavy+='UncertaintyCoverage\.|IdentifyOnTheMeasuredBeamReportsProfileIntervals|'
heavy+='ModelSelectionBeam\.|method_comparison_reproducible|select_model_verbose_shows_ceres'
heavy+='|WithNoInitialGuessesEveryReplicaConverges|TwoHundredRandomStartsReachTheTruth|'
heavy+='FourMergedShardsEqualOneRun|SameSeedSameStudyAnotherSeedAnother|design_study_virtual_beam'
UBSAN_OPTIONS=print_stacktrace=1 ctest --test-dir build-sanitize --output-on-failure -j"${jobs}" \
  -E "${heavy}" -LE "packaging|browser|python"

step "fuzzers (Clang, libFuzzer, ASan+UBSan)"
cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DDWELLFIT_BUILD_FUZZERS=ON \
  -DDWELLFIT_BUILD_TESTS=OFF -DDWELLFIT_BUILD_BENCHMARKS=OFF
cmake --build build-fuzz -j"${jobs}" --target fuzzers
FUZZ_BUILD_DIR=build-fuzz bash tests/fuzz/run_fuzzers.sh "${fuzz_seconds}"

step "all checks passed"
