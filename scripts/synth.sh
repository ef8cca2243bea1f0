#!/usr/bin/env bash
# Synthesises rmap_top of a generated directory with Yosys, from inside that directory (so
# $readmemh finds the hex files). Fails on any latch. Logs and the netlist go to LOG_DIR,
# never into the generated directory.
#
#   scripts/synth.sh [--generic] [RTL_DIR [LOG_DIR]]     (YOSYS overrides the tool)
#
# Default: synth_ice40; prints the memory bits (before mapping), the cell count and the block
# RAMs (SB_RAM40_4K).
# --generic: Yosys's generic gate-level synthesis with every memory kept as a memory cell
# ($mem_v2), as an ASIC flow maps them to SRAM macros; for any width, including designs far
# larger than an FPGA. Prints the gate cells and the memories inferred.
set -euo pipefail
generic=0
if [ "${1:-}" = --generic ]; then generic=1; shift; fi
dir=${1:-rtl_out}
logs=${2:-build/synth}
yosys=${YOSYS:-yosys}
[ -f "$dir/rmap_top.v" ] || { echo "synth: no $dir/rmap_top.v; run 'make generate' first" >&2; exit 1; }
mkdir -p "$logs"
logs=$(cd "$logs" && pwd)
# proc turns any incomplete combinational assignment into a $dlatch; the select fails on it.
front="read_verilog *.v; hierarchy -check -top rmap_top; proc; flatten;
tee -q -o $logs/memory.txt stat;
select -assert-none t:\$dlatch t:\$adlatch t:\$dlatchsr t:\$_DLATCH_* t:\$_DLATCHSR_*;"
if [ $generic = 1 ]; then
  # synth's own script without memory_map: the coarse pass infers the memories, the fine
  # steps map everything else to gates.
  script="$front
synth -top rmap_top -run coarse:fine;
opt -fast -full; opt -full; techmap; opt -fast; abc -fast; opt -fast;
tee -q -o $logs/cells.txt stat; check -assert"
else
  script="$front
synth_ice40 -top rmap_top -json $logs/rmap_top.json;
tee -q -o $logs/cells.txt stat"
fi
if ! (cd "$dir" && "$yosys" -q -l "$logs/yosys.log" -p "$script" >/dev/null); then
  grep -E "ERROR|Assertion|Warning" "$logs/yosys.log" >&2 || true
  echo "synth: FAILED (log: $logs/yosys.log)" >&2
  exit 1
fi
bits=$(awk '/Number of memory bits/ {print $NF; exit}' "$logs/memory.txt")
cells=$(awk '/Number of cells/ {n=$NF} END {print n}' "$logs/cells.txt")
sed -n '/Number of cells/,$p' "$logs/cells.txt"
if [ $generic = 1 ]; then
  mems=$(awk '/\$mem_v2/ {n=$NF} END {print n+0}' "$logs/cells.txt")
  echo "synth: rmap_top in $dir (generic): no latches, $cells cells, $bits memory bits in $mems memories"
else
  ebr=$(awk '/SB_RAM40_4K/ {n=$NF} END {print n+0}' "$logs/cells.txt")
  echo "synth: rmap_top in $dir: no latches, $cells cells, $bits memory bits, $ebr SB_RAM40_4K"
fi
