#!/usr/bin/env bash
# Synthesises rmap_top of a generated directory for the iCE40 with Yosys, from inside that
# directory (so $readmemh finds the hex files). Fails on any latch. Prints the memory bits
# (before mapping), the cell count and the block RAMs (SB_RAM40_4K) after synth_ice40.
# Logs and the netlist go to LOG_DIR, never into the generated directory.
# Usage: scripts/synth.sh [RTL_DIR [LOG_DIR]]     (YOSYS overrides the tool)
set -euo pipefail
dir=${1:-rtl_out}
logs=${2:-build/synth}
yosys=${YOSYS:-yosys}
[ -f "$dir/rmap_top.v" ] || { echo "synth: no $dir/rmap_top.v; run 'make generate' first" >&2; exit 1; }
mkdir -p "$logs"
logs=$(cd "$logs" && pwd)
# proc turns any incomplete combinational assignment into a $dlatch; the select fails on it.
script="read_verilog *.v; hierarchy -check -top rmap_top; proc; flatten;
tee -q -o $logs/memory.txt stat;
select -assert-none t:\$dlatch t:\$adlatch t:\$dlatchsr t:\$_DLATCH_* t:\$_DLATCHSR_*;
synth_ice40 -top rmap_top -json $logs/rmap_top.json;
tee -q -o $logs/cells.txt stat"
if ! (cd "$dir" && "$yosys" -q -l "$logs/yosys.log" -p "$script" >/dev/null); then
  grep -E "ERROR|Assertion" "$logs/yosys.log" >&2 || true
  echo "synth: FAILED (log: $logs/yosys.log)" >&2
  exit 1
fi
bits=$(awk '/Number of memory bits/ {print $NF; exit}' "$logs/memory.txt")
cells=$(awk '/Number of cells/ {n=$NF} END {print n}' "$logs/cells.txt")
ebr=$(awk '/SB_RAM40_4K/ {n=$NF} END {print n+0}' "$logs/cells.txt")
sed -n '/Number of cells/,$p' "$logs/cells.txt"
echo "synth: rmap_top in $dir: no latches, $cells cells, $bits memory bits, $ebr SB_RAM40_4K"
