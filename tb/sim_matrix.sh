#!/usr/bin/env bash
# Generates the design for each configuration of the list below into build/matrix/<name> and
# runs every testbench there under Icarus and Verilator, plus the Verilator C++ harness on a
# large top-level stream (tb/run_sims.sh). Exits 1 if any configuration fails.
#
#   tb/sim_matrix.sh [NAME...]      (default: all; STREAM=N vectors for the harness)
#
# The list is chosen for coverage: the paper's default, each optional stage off or on, and
# the widest and narrowest widths the configuration allows.
set -uo pipefail
REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
RMAPGEN=${RMAPGEN:-$REPO/target/release/rmapgen}
STREAM=${STREAM:-1000000}
TB_STREAM=${TB_STREAM:-0}
MATRIX=${MATRIX:-$REPO/build/matrix}

configs=(
  "default|"
  "no_compensation|--no-compensation"
  "no_interpolation|--no-interpolation"
  "color|--color"
  "bare_color|--no-compensation --no-interpolation --color"
  "wide|--grad-bits 16 --red-bits 12 --frac-bits 12 --recip-bits 14 --index-bits 6 --interp-bits 5 --map-bits 12"
  "narrow|--grad-bits 8 --red-bits 6 --frac-bits 4 --recip-bits 5 --index-bits 2 --interp-bits 1 --map-bits 6"
  "narrow_bare_color|--grad-bits 8 --red-bits 6 --frac-bits 4 --recip-bits 5 --index-bits 2 --no-interpolation --no-compensation --map-bits 6 --color"
)

[ -x "$RMAPGEN" ] || { echo "sim_matrix: $RMAPGEN not built (cargo build --release)" >&2; exit 2; }
failed=()
for entry in "${configs[@]}"; do
  name=${entry%%|*}
  flags=${entry#*|}
  if [ $# -gt 0 ] && [[ " $* " != *" $name "* ]]; then continue; fi
  echo "==== $name: rmapgen generate $flags"
  # shellcheck disable=SC2086  # flags are words
  if ! "$RMAPGEN" generate --out "$MATRIX/$name" $flags; then
    failed+=("$name (generate)"); continue
  fi
  "$REPO/tb/run_sims.sh" --icarus --verilator --stream "$STREAM" --tb-stream "$TB_STREAM" "$MATRIX/$name" \
    || failed+=("$name")
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "sim_matrix: FAILED: ${failed[*]}"
  exit 1
fi
echo "sim_matrix: every configuration passed"
