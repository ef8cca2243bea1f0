#!/usr/bin/env bash
# Runs the self-checking testbenches of one generated directory (rmapgen generate --out DIR)
# under Icarus Verilog and/or Verilator, and the Verilator C++ harness tb/top_stream.cpp on a
# large top-level vector stream.
#
#   tb/run_sims.sh [--icarus] [--verilator] [--stream N] [--build DIR] [--only MODULE] OUT_DIR
#
#   --icarus      every OUT_DIR/tb/*_tb.v under iverilog -g2005 -Wall and vvp -N
#   --verilator   every OUT_DIR/tb/*_tb.v under verilator --binary
#   --stream N    N random top vectors (rmapgen vectors) through the C++ harness (Verilator)
#   --tb-stream N also N random top vectors through rmap_top_tb in each simulator selected,
#                 for a throughput figure of the Verilog testbench (+vectors=FILE)
#   --build DIR   simulator build products [default: build/sim/<name of OUT_DIR>]
#   --only M      only the testbench of module M
#
# Simulations run with OUT_DIR as the working directory, so vectors/ and the $readmemh files
# resolve. A run passes when the simulator exits 0 and its last line is `N passed, 0 failed`
# with N > 0. Every failure prints the command and its output; the script goes on with the
# other testbenches and exits 1 at the end if anything failed. Tool names: IVERILOG, VVP,
# VERILATOR, RMAPGEN (environment).
set -uo pipefail

IVERILOG=${IVERILOG:-iverilog}
VVP=${VVP:-vvp}
VERILATOR=${VERILATOR:-verilator}
REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
RMAPGEN=${RMAPGEN:-$REPO/target/release/rmapgen}
JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}

icarus=0 verilator=0 stream=0 tb_stream=0 build= only= out=
while [ $# -gt 0 ]; do
  case $1 in
    --icarus) icarus=1 ;;
    --verilator) verilator=1 ;;
    --stream) stream=${2:?--stream needs a count}; shift ;;
    --tb-stream) tb_stream=${2:?--tb-stream needs a count}; shift ;;
    --build) build=${2:?--build needs a directory}; shift ;;
    --only) only=${2:?--only needs a module}; shift ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    -*) echo "run_sims: unknown option $1" >&2; exit 2 ;;
    *) [ -z "$out" ] || { echo "run_sims: one OUT_DIR only" >&2; exit 2; }; out=$1 ;;
  esac
  shift
done
[ -n "$out" ] || { echo "usage: tb/run_sims.sh [--icarus] [--verilator] [--stream N] OUT_DIR" >&2; exit 2; }
[ $icarus = 1 ] || [ $verilator = 1 ] || [ "$stream" != 0 ] || { echo "run_sims: nothing to run (--icarus, --verilator, --stream)" >&2; exit 2; }
[ -d "$out/tb" ] || { echo "run_sims: $out/tb missing: generate the design with rmapgen generate --out $out" >&2; exit 2; }
out=$(cd "$out" && pwd)
build=${build:-$REPO/build/sim/$(basename "$out")}
mkdir -p "$build" && build=$(cd "$build" && pwd)

need() { command -v "$1" >/dev/null 2>&1 || { echo "run_sims: $1 not found (make tools installs it)" >&2; exit 2; }; }
[ $icarus = 1 ] && { need "$IVERILOG"; need "$VVP"; }
{ [ $verilator = 1 ] || [ "$stream" != 0 ]; } && need "$VERILATOR"

# The design: every generated module (the testbenches are in tb/).
mapfile -t design < <(ls "$out"/*.v)
[ ${#design[@]} -gt 0 ] || { echo "run_sims: no design files in $out" >&2; exit 2; }
mapfile -t tbs < <(ls "$out"/tb/*_tb.v | sort)
if [ -n "$only" ]; then
  tbs=("$out/tb/${only}_tb.v")
  [ -f "${tbs[0]}" ] || { echo "run_sims: no testbench $only in $out/tb" >&2; exit 2; }
fi

failures=() summary=()
now() { date +%s.%N; }

# make_stream COUNT FILE LOG: a top vector stream of this directory's configuration and maps.
make_stream() {
  if [ ! -x "$RMAPGEN" ]; then
    echo "FAIL: $RMAPGEN not built (cargo build --release)"; failures+=("rmapgen vectors"); return 1
  fi
  run_step "rmapgen vectors --count $1" "$3" \
    "$RMAPGEN" vectors --config "$out/tb/config.toml" --maps "$out" --count "$1" --out "$2"
}

# run_step NAME LOG CMD...: runs CMD (output to LOG); on failure prints it and records NAME.
run_step() {
  local name=$1 log=$2; shift 2
  if ! "$@" >"$log" 2>&1; then
    echo "FAIL: $name"
    echo "  command: $*"
    sed 's/^/  | /' "$log" | tail -n 60
    failures+=("$name")
    return 1
  fi
}

# check_run NAME LOG T0 T1 RC: a simulation passes with exit 0 and `N passed, 0 failed` last.
check_run() {
  local name=$1 log=$2 t0=$3 t1=$4 rc=$5 cmd=$6 last
  last=$(tail -n 1 "$log")
  if [ "$rc" = 0 ] && [[ $last =~ ^([0-9]+)\ passed,\ 0\ failed$ ]] && [ "${BASH_REMATCH[1]}" -gt 0 ]; then
    local n=${BASH_REMATCH[1]}
    local rate
    rate=$(awk -v n="$n" -v a="$t0" -v b="$t1" 'BEGIN { d = b - a; if (d <= 0) d = 1e-6; printf "%.0f", n / d }')
    summary+=("$(printf '%-30s %9s vectors  %10s vectors/s' "$name" "$n" "$rate")")
    echo "ok:   $name: $last ($rate vectors/s)"
  else
    echo "FAIL: $name (exit $rc, last line: $last)"
    echo "  command: (cd $out && $cmd)"
    sed 's/^/  | /' "$log" | tail -n 60
    failures+=("$name")
  fi
}

tbvec=
if [ "$tb_stream" != 0 ]; then
  tbvec=$build/tb_stream.hex
  make_stream "$tb_stream" "$tbvec" "$build/tb_stream.log" || tbvec=
fi

for tb in "${tbs[@]}"; do
  m=$(basename "$tb" .v)
  if [ $icarus = 1 ]; then
    mkdir -p "$build/icarus"
    vvp_file=$build/icarus/$m.vvp
    if run_step "icarus $m (compile)" "$build/icarus/$m.compile.log" \
        "$IVERILOG" -g2005 -Wall -Wno-timescale -s "$m" -o "$vvp_file" "$tb" "${design[@]}"; then
      [ -s "$build/icarus/$m.compile.log" ] && sed 's/^/  iverilog: /' "$build/icarus/$m.compile.log"
      t0=$(now); (cd "$out" && "$VVP" -N "$vvp_file") >"$build/icarus/$m.log" 2>&1; rc=$?; t1=$(now)
      check_run "icarus $m" "$build/icarus/$m.log" "$t0" "$t1" "$rc" "$VVP -N $vvp_file"
      if [ "$m" = rmap_top_tb ] && [ -n "$tbvec" ]; then
        t0=$(now); (cd "$out" && "$VVP" -N "$vvp_file" +vectors="$tbvec") >"$build/icarus/$m.stream.log" 2>&1; rc=$?; t1=$(now)
        check_run "icarus $m (stream)" "$build/icarus/$m.stream.log" "$t0" "$t1" "$rc" "$VVP -N $vvp_file +vectors=$tbvec"
      fi
    fi
  fi
  if [ $verilator = 1 ]; then
    mdir=$build/verilator/$m
    mkdir -p "$mdir"
    if run_step "verilator $m (build)" "$mdir/build.log" \
        "$VERILATOR" --binary -j "$JOBS" --top-module "$m" --Mdir "$mdir" -o sim \
        "$tb" "${design[@]}" "$REPO/tb/vl_user.cpp" -CFLAGS -DVL_USER_FINISH -CFLAGS -DVL_USER_STOP; then
      t0=$(now); (cd "$out" && "$mdir/sim") >"$mdir/run.log" 2>&1; rc=$?; t1=$(now)
      check_run "verilator $m" "$mdir/run.log" "$t0" "$t1" "$rc" "$mdir/sim"
      if [ "$m" = rmap_top_tb ] && [ -n "$tbvec" ]; then
        t0=$(now); (cd "$out" && "$mdir/sim" +vectors="$tbvec") >"$mdir/stream.log" 2>&1; rc=$?; t1=$(now)
        check_run "verilator $m (stream)" "$mdir/stream.log" "$t0" "$t1" "$rc" "$mdir/sim +vectors=$tbvec"
      fi
    fi
  fi
done

if [ "$stream" != 0 ]; then
  sdir=$build/verilator/top_stream
  mkdir -p "$sdir"
  vec=$build/top_stream.hex
  if make_stream "$stream" "$vec" "$sdir/vectors.log" \
     && run_step "verilator top_stream (build)" "$sdir/build.log" \
        "$VERILATOR" --cc --exe --build -j "$JOBS" -O3 --x-assign fast --x-initial fast --noassert \
        --top-module rmap_top --Mdir "$sdir" -o top_stream "${design[@]}" "$REPO/tb/top_stream.cpp" \
        -CFLAGS "-O2 -I$out/tb"; then
    t0=$(now); (cd "$out" && "$sdir/top_stream" "$vec") >"$sdir/run.log" 2>&1; rc=$?; t1=$(now)
    grep -h "vectors/s" "$sdir/run.log" | sed 's/^/  /'
    check_run "verilator top_stream (C++)" "$sdir/run.log" "$t0" "$t1" "$rc" "$sdir/top_stream $vec"
  fi
fi

echo "---- $(basename "$out"): $(head -n 2 "$out/tb/rmap_top_tb.v" | tail -n 1 | sed 's#^// Configuration: ##')"
for s in "${summary[@]}"; do echo "  $s"; done
if [ ${#failures[@]} -gt 0 ]; then
  echo "run_sims: ${#failures[@]} FAILED in $out:"
  for f in "${failures[@]}"; do echo "  $f"; done
  exit 1
fi
echo "run_sims: all passed in $out"
