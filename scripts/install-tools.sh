#!/usr/bin/env bash
# Installs the simulators and synthesis tools from Debian's packages when any is missing (and
# ccache, which the Makefile's Verilator builds share their runtime objects through);
# WITH_FPGA=1 also nextpnr-ice40 and fpga-icestorm (place and route, make fpga); WITH_FORMAL=1
# also z3 (the SMT solver of make formal's SymbiYosys runs); WITH_DOCS=1 also linkchecker (make
# docs) and chromium (make report-browser, driven by Playwright); WITH_VOLPACK=1 also
# libvolpack1-dev (VolPack and its example MRI head, for make bench-volume only); WITH_SLURM=1
# also slurm-wlm and munge (the one-node cluster of make slurm-test); WITH_SOC=1 also
# gcc-riscv64-unknown-elf (the bus designs' driver built for a RISC-V CPU, make bus-test).
# Fails loudly (exit 1) when it cannot: the tests must never skip a simulator silently.
set -euo pipefail
need=()
for t in iverilog:iverilog vvp:iverilog verilator:verilator yosys:yosys ccache:ccache; do
  bin=${t%%:*}; pkg=${t##*:}
  command -v "$bin" >/dev/null 2>&1 || need+=("$pkg")
done
if [ "${WITH_FPGA:-0}" = 1 ]; then
  command -v nextpnr-ice40 >/dev/null 2>&1 || need+=(nextpnr-ice40)
  command -v icepack >/dev/null 2>&1 || need+=(fpga-icestorm)
fi
if [ "${WITH_DOCS:-0}" = 1 ]; then
  command -v linkchecker >/dev/null 2>&1 || need+=(linkchecker)
  [ -x /usr/bin/chromium ] || need+=(chromium)
fi
if [ "${WITH_FORMAL:-0}" = 1 ]; then
  command -v z3 >/dev/null 2>&1 || need+=(z3)
fi
if [ "${WITH_VOLPACK:-0}" = 1 ]; then
  [ -f /usr/include/volpack.h ] || need+=(libvolpack1-dev)
fi
if [ "${WITH_SLURM:-0}" = 1 ]; then
  for t in sbatch squeue scancel sinfo slurmctld slurmd munged; do
    command -v "$t" >/dev/null 2>&1 || { need+=(slurm-wlm munge); break; }
  done
fi
if [ "${WITH_SOC:-0}" = 1 ]; then
  command -v riscv64-unknown-elf-gcc >/dev/null 2>&1 || need+=(gcc-riscv64-unknown-elf)
fi
if [ ${#need[@]} -eq 0 ]; then
  exit 0
fi
mapfile -t need < <(printf '%s\n' "${need[@]}" | sort -u)
echo "install-tools: installing ${need[*]} with apt-get"
SUDO=
if [ "$(id -u)" != 0 ]; then
  command -v sudo >/dev/null 2>&1 || { echo "install-tools: need root or sudo to install ${need[*]}" >&2; exit 1; }
  SUDO=sudo
fi
$SUDO apt-get update -qq || { echo "install-tools: apt-get update failed" >&2; exit 1; }
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}" >/dev/null \
  || { echo "install-tools: apt-get install ${need[*]} failed" >&2; exit 1; }
check=(iverilog vvp verilator yosys ccache)
[ "${WITH_FPGA:-0}" = 1 ] && check+=(nextpnr-ice40 icepack)
[ "${WITH_FORMAL:-0}" = 1 ] && check+=(z3)
[ "${WITH_DOCS:-0}" = 1 ] && check+=(linkchecker chromium)
[ "${WITH_SLURM:-0}" = 1 ] && check+=(sbatch slurmctld slurmd munged)
if [ "${WITH_VOLPACK:-0}" = 1 ] && [ ! -f /usr/include/volpack.h ]; then
  echo "install-tools: libvolpack1-dev still missing after install" >&2; exit 1
fi
for t in "${check[@]}"; do
  command -v "$t" >/dev/null 2>&1 || { echo "install-tools: $t still missing after install" >&2; exit 1; }
done
echo "install-tools: $(iverilog -V 2>&1 | head -1); $(verilator --version); $(yosys -V)"
if [ "${WITH_FPGA:-0}" = 1 ]; then
  echo "install-tools: $(nextpnr-ice40 --version 2>&1 | head -1)"
fi
