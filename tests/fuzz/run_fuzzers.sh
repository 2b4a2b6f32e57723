#!/usr/bin/env bash
# Runs the libFuzzer targets of tests/fuzz, one after the other, and prints
# for each its runs, speed, coverage and corpus, and any finding.
#
#   tests/fuzz/run_fuzzers.sh SECONDS [TARGET...]
#
# SECONDS per target; 0 only replays the seeds and regression inputs once.
# TARGETs: sweep_csv identify_config set_flag dwell_plan trace_set rig_config
# result_parameters shard_merge uff58 mat_sweeps (default: all).
# The fuzzers are taken from $FUZZ_BUILD_DIR (default build-fuzz), a build
# configured with -DDWELLFIT_BUILD_FUZZERS=ON and built with --target fuzzers.
# Inputs: tests/fuzz/corpus/<target> and tests/fuzz/regressions/<target>
# (committed), the datasets' files, and the inputs found in earlier runs,
# kept in $FUZZ_BUILD_DIR/fuzz/corpus/<target>. A crash, hang, leak or
# sanitizer report is written to $FUZZ_BUILD_DIR/fuzz/findings/<target>/;
# commit it under tests/fuzz/regressions/<target>/ once fixed. Exits non-zero
# when any target had a finding.
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."

if [[ $# -lt 1 || ! "$1" =~ ^[0-9]+$ ]]; then
  echo "usage: $0 SECONDS [TARGET...]" >&2
  exit 2
fi
seconds=$1
shift
targets=("$@")
((${#targets[@]} > 0)) || targets=(sweep_csv identify_config set_flag dwell_plan trace_set
  rig_config result_parameters shard_merge uff58 mat_sweeps)
build_dir=${FUZZ_BUILD_DIR:-build-fuzz}

# Files under datasets/ that seed each target.
dataset_seeds() {
  case "$1" in
    sweep_csv) ls datasets/*/*.csv ;;
    identify_config | dwell_plan | rig_config) ls datasets/*/*.yaml ;;
  esac
}

# ASAN_OPTIONS while a target fuzzes. sweep_csv and trace_set: libfccp's CSVReader
# allocates a fixed 48 MB buffer (3 << 24 bytes) for every file it reads, and
# AddressSanitizer poisons and unpoisons its 6 MB of shadow memory each time:
# about 40 ms per load (25 runs/s). It fuzzes without heap poisoning (stack
# and global checks, leak detection and UBSan stay on; 1000 to 2400 runs/s
# on two shared cores), and every input of its corpus is then replayed once
# with all checks.
fuzzing_asan_options() {
  case "$1" in
    sweep_csv | trace_set) echo "poison_heap=0" ;;
  esac
}

# Prints "field=value" pairs of a finished run from its log.
summarize() {
  local log=$1 status_line runs speed
  status_line=$(grep -E '^#[0-9]+[[:space:]]+(DONE|INITED|pulse|NEW|REDUCE)' "$log" | tail -n 1)
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)
  echo "runs=${runs:-?} exec/s=${speed:-?} $(grep -oE 'cov: [0-9]+ ft: [0-9]+ corp: [^ ]+' \
    <<<"$status_line" | sed 's/: /=/g')"
}

# Runs one target; returns non-zero on a finding.
run_target() {
  local name=$1 fuzzer="${build_dir}/tests/fuzz/fuzz_$1"
  local work="${build_dir}/fuzz/corpus/$1" seeds="${build_dir}/fuzz/seeds/$1"
  local findings="${build_dir}/fuzz/findings/$1" log="${build_dir}/fuzz/$1.log"
  if [[ ! -x "${fuzzer}" ]]; then
    echo "${name}: ${fuzzer} is missing; build it: cmake --build ${build_dir} --target fuzzers" >&2
    return 1
  fi
  mkdir -p "${work}" "${seeds}" "${findings}"
  local seed
  for seed in $(dataset_seeds "${name}"); do
    cp "${seed}" "${seeds}/$(tr / _ <<<"${seed}")"
  done
  local inputs=("${work}" "tests/fuzz/corpus/${name}" "tests/fuzz/regressions/${name}" "${seeds}")
  local dict=tests/fuzz/dict/yaml.dict
  [[ "${name}" != sweep_csv && "${name}" != trace_set ]] || dict=tests/fuzz/dict/csv.dict
  [[ "${name}" != uff58 ]] || dict=tests/fuzz/dict/uff.dict
  [[ "${name}" != mat_sweeps ]] || dict=tests/fuzz/dict/mat.dict
  local options=(-timeout=10 -rss_limit_mb=2048 -max_len=8192 -print_final_stats=1
    -dict="${dict}" -artifact_prefix="${findings}/")
  local asan_options status
  asan_options=$(fuzzing_asan_options "${name}")
  if ((seconds > 0)); then
    ASAN_OPTIONS=${asan_options:-${ASAN_OPTIONS:-}} "${fuzzer}" -max_total_time="${seconds}" "${options[@]}" \
      "${inputs[@]}" >"${log}" 2>&1
    status=$?
    echo "${name}: $(summarize "${log}") time=${seconds}s${asan_options:+ (${asan_options})}"
    report "${name}" "${status}" "${log}" || return 1
  fi
  if ((seconds == 0)) || [[ -n "${asan_options}" ]]; then
    ASAN_OPTIONS= "${fuzzer}" -runs=0 "${options[@]}" "${inputs[@]}" >"${log}.replay" 2>&1
    status=$?
    echo "${name}: replayed with all checks: $(summarize "${log}.replay")"
    report "${name}" "${status}" "${log}.replay" || return 1
  fi
}

# Says what went wrong when a run exited with `status`; returns non-zero then.
report() {
  local name=$1 status=$2 log=$3
  ((status == 0)) && return 0
  echo "${name}: FINDING (exit ${status}): $(ls "${build_dir}/fuzz/findings/${name}" | tr '\n' ' ')"
  grep -E 'ERROR: |SUMMARY: |runtime error|terminate called|what\(\)' "${log}" | head -n 20
  echo "${name}: full log in ${log}"
  return 1
}

failed=0
for target in "${targets[@]}"; do
  run_target "${target}" || failed=1
done
exit "${failed}"
