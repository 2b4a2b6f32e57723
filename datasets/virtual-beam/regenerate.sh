#!/usr/bin/env bash
# Regenerates the virtual beam from its plan and rig: the time traces (and
# their truth), the dwell points with phase, and the harmonic-balance
# estimates. Run from the repository root after building into build/:
#
#   bash datasets/virtual-beam/regenerate.sh
set -euo pipefail
dir=datasets/virtual-beam
build/tools/simulate_rig --plan "${dir}/plan.yaml" --rig "${dir}/rig.yaml" --out "${dir}/traces"
build/tools/process_traces --rig "${dir}/rig.yaml" --traces "${dir}/traces" \
  --out "${dir}/sweeps.csv" --harmonic_balance "${dir}/harmonic_balance.yaml" --reference_hz 41.5
build/tools/traces_to_uff --traces "${dir}/traces" --out "${dir}/traces-uff/virtual-beam-58b.uff" \
  --index "${dir}/traces-uff/virtual-beam-58b.csv"
build/tools/traces_to_uff --traces "${dir}/traces" --ascii --dwells 4 \
  --out "${dir}/traces-uff/first-dwells-58.uff" --index "${dir}/traces-uff/first-dwells-58.csv"
