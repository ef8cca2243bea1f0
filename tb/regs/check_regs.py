#!/usr/bin/env python3
"""Checks the register map's views of bus designs (`rmapgen generate --bus ...`) against one
another, and the generated driver, with the tools of the ecosystem:

1. PeakRDL compiles the design's SystemRDL (<prefix>rmap_regs.rdl) into its own C header and
   HTML; a C file of static assertions, written here from the manifest's register map, must
   compile: every register's offset in PeakRDL's struct, every field's bit position, mask and
   reset value, and every window's offset and size equal rmapgen's header (<prefix>rmap_regs.h).
2. The driver (<prefix>rmap_driver.[ch]) compiles with -Wall -Wextra -Werror -pedantic for the
   host (cc) and for a 32-bit RISC-V (riscv64-unknown-elf-gcc -march=rv32im -mabi=ilp32).
3. The driver runs on the host against a model of the slave's registers (its READ32/WRITE32
   macros over an array): the identification check passes on the design's own values and is
   refused, naming the register, on every other design's given (a driver built for another
   configuration), on a wrong magic and on another register map version; a frame of the
   design's own map stream (`rmapgen maps DIR --format c`) lands entry for entry at its
   window offsets; a write outside the windows is refused and nothing is written; the swap
   waits for FRAMES to change, and times out when it does not.

    check_regs.py DESIGN_DIR... --rmapgen BIN [--build DIR]

Exit 0 when every check passes; the last line is `N passed, M failed`.
"""

import argparse
import json
import shutil
import subprocess
import sys
from pathlib import Path

WARN = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]
RISCV = ["riscv64-unknown-elf-gcc", "-march=rv32im", "-mabi=ilp32", "-ffreestanding", "-Os"]


def sh(cmd, cwd=None):
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))} failed ({r.returncode}):\n{r.stdout}{r.stderr}")
    return r.stdout


class Design:
    def __init__(self, path):
        self.path = path.resolve()
        self.man = json.loads((self.path / "manifest.json").read_text())
        self.bus = self.man["bus"]
        self.map = self.bus["regmap"]
        files = self.bus["files"]
        self.header = next(f for f in files if f.endswith("rmap_regs.h"))
        self.rdl = next(f for f in files if f.endswith(".rdl"))
        self.driver_h = next(f for f in files if f.endswith("rmap_driver.h"))
        self.driver_c = next(f for f in files if f.endswith("rmap_driver.c"))
        self.prefix = self.man["config"].get("prefix", "")
        self.P = self.prefix.upper() + "RMAP_"
        self.f = self.prefix + "rmap_"
        self.stem = self.rdl[: -len(".rdl")]

    def values(self):
        """The identification block's words as the slave reads them: {offset: word}."""
        out = {}
        for r in self.map["regs"]:
            w = 0
            for f in r["fields"]:
                if "const" in f["source"]:
                    w |= f["source"]["const"] << f["lsb"]
            out[r["offset"]] = w
        return out


def check_peakrdl(d, build, venv_bin):
    """PeakRDL's C header and HTML from the .rdl; static assertions against rmapgen's header."""
    out = build / d.path.name
    out.mkdir(parents=True, exist_ok=True)
    peak_h = out / "peakrdl.h"
    peakrdl = str(venv_bin / "peakrdl")
    sh([peakrdl, "c-header", str(d.path / d.rdl), "-o", str(peak_h)])
    sh([peakrdl, "html", str(d.path / d.rdl), "-o", str(out / "html")])
    if not (out / "html" / "index.html").exists():
        raise RuntimeError("peakrdl html wrote no index.html")
    N = d.stem.upper()
    lines = ["#include <stddef.h>", f'#include "{d.path / d.header}"', f'#include "{peak_h}"']
    n = 0

    def eq(a, b):
        nonlocal n
        n += 1
        lines.append(f'_Static_assert(({a}) == ({b}), "{a} == {b}");')

    for r in d.map["regs"]:
        eq(f"offsetof({d.stem}_t, {r['name']})", f"{d.P}{r['name']}_OFFSET")
        for f in r["fields"]:
            p = f"{N}__{r['name']}__{f['name']}"
            q = f"{d.P}{r['name']}_{f['name']}"
            eq(f"{p}_bp", f"{q}_SHIFT")
            eq(f"{p}_bm", f"{q}_MASK")
            if "const" in f["source"]:
                eq(f"{p}_reset", f"{q}_VALUE")
    for w in d.map["windows"]:
        eq(f"offsetof({d.stem}_t, {w['name']})", f"{d.P}{w['name']}_OFFSET")
        eq(f"sizeof((({d.stem}_t *)0)->{w['name']}) / 4", f"{d.P}{w['name']}_ENTRIES")
        eq(f"{N}__{w['name']}__DATA_bm", f"(1u << {d.P}{w['name']}_BITS) - 1u")
    lines.append(f"_Static_assert(sizeof({d.stem}_t) <= {d.P}SPAN, \"span\");")
    src = out / "peakrdl_check.c"
    src.write_text("\n".join(lines) + "\n")
    sh(["cc", "-std=c11", "-Wall", "-Werror", "-c", str(src), "-o", str(out / "peakrdl_check.o")])
    return f"{d.path.name}: PeakRDL's header equals rmapgen's ({n} values), HTML written"


def check_compiles(d, build):
    out = build / d.path.name
    out.mkdir(parents=True, exist_ok=True)
    sh(["cc", *WARN, "-c", str(d.path / d.driver_c), "-o", str(out / "driver.o")])
    sh([*RISCV, *WARN, "-c", str(d.path / d.driver_c), "-o", str(out / "driver.rv32.o")])
    size = sh(["riscv64-unknown-elf-size", str(out / "driver.rv32.o")]).splitlines()[-1].split()
    return f"{d.path.name}: the driver compiles for the host and for rv32im ({size[0]} bytes of code)"


def fake_slave_test(d, others, rmapgen, build):
    """The driver against an array that models the slave's registers."""
    out = build / d.path.name
    out.mkdir(parents=True, exist_ok=True)
    maps_c = out / "frame.c"
    sh([rmapgen, "maps", str(d.path), "--format", "c", "--out", str(maps_c), "--force"])
    array = f"{d.man['top']}_map_writes"
    count = f"{d.man['top'].upper()}_MAP_WRITES_COUNT"
    span = 1 << d.map["addr_bits"]
    frames = d.map["regs"][[r["name"] for r in d.map["regs"]].index("FRAMES")]["offset"]
    # Register images: the design's own, each other design's, a wrong magic, another version.
    own = d.values()
    images = [("own", own, "OK")]
    for o in others:
        if o.values() != own:
            images.append((f"built for {o.path.name}", o.values(), "ERR_CONFIG"))
    bad_magic = dict(own)
    bad_magic[0] ^= 1
    images.append(("a wrong magic", bad_magic, "ERR_ID"))
    version = next(r for r in d.map["regs"] if r["name"] == "VERSION")["offset"]
    bad_version = dict(own)
    bad_version[version] ^= 1 << 24
    images.append(("another register map version", bad_version, "ERR_REGMAP"))
    init = "\n".join(
        "static const uint32_t image_%d[%d] = {%s};" % (
            k, span // 4,
            ", ".join(f"[{off // 4}] = 0x{v:x}u" for off, v in sorted(img.items())))
        for k, (_, img, _) in enumerate(images))
    cases = "\n".join(
        f'    expect("{what}", check_image(image_{k}), {d.P}{want});'
        for k, (what, _, want) in enumerate(images))
    prog = f"""
#include <stdio.h>
#include <string.h>
#include <stdint.h>
static uint32_t regs[{span // 4}];
static unsigned long reads_of_frames, frames_after;
static uint32_t fake_read(uintptr_t off)
{{
    if (off == {frames}u && ++reads_of_frames >= frames_after) return regs[off / 4] + 1u;
    return regs[off / 4];
}}
#define {d.P}READ32(base, off) fake_read((uintptr_t)(base) + (off))
#define {d.P}WRITE32(base, off, v) (regs[((uintptr_t)(base) + (off)) / 4] = (uint32_t)(v))
#include "{d.path / d.driver_c}"
#include "{maps_c}"
{init}
static int failed;
static void expect(const char *what, int got, int want)
{{
    if (got != want) {{ printf("FAIL %s: %s, want %s\\n", what, {d.f}strerror(got), {d.f}strerror(want)); failed++; }}
    else printf("ok   %s: %s\\n", what, {d.f}strerror(got));
}}
static int check_image(const uint32_t *img)
{{
    uint32_t reg = 0xffffffffu, got = 0;
    int s;
    memcpy(regs, img, sizeof regs);
    s = {d.f}check(0, &reg, &got);
    if (s != {d.P}OK && regs[reg / 4] != got) {{ printf("FAIL the difference named: register 0x%x\\n", (unsigned)reg); failed++; }}
    return s;
}}
int main(void)
{{
    size_t k, bad = 0;
    uint16_t wrong[2][3];
{cases}
    /* A frame: every write at its window offset, nothing else touched. */
    memset(regs, 0, sizeof regs);
    expect("a frame's load", {d.f}load(0, {array}, {count}, NULL), {d.P}OK);
    for (k = 0; k < {count}; k++) {{
        uint32_t off = (uint32_t){d.P}ENTRY_OFFSET({array}[k][0], {array}[k][1]);
        if (regs[off / 4] != {array}[k][2]) {{ printf("FAIL write %lu not at 0x%x\\n", (unsigned long)k, (unsigned)off); failed++; break; }}
    }}
    /* A write outside the windows: refused, named, nothing written. */
    memset(regs, 0, sizeof regs);
    memcpy(wrong[0], {array}[0], sizeof wrong[0]);
    wrong[1][0] = {array}[0][0]; wrong[1][1] = {array}[0][1]; wrong[1][2] = (uint16_t)(1u << {d.P}MAP_X_BITS);
    expect("an entry too wide", {d.f}load(0, wrong, 2, &bad), {d.P}ERR_WRITE);
    if (bad != 1) {{ printf("FAIL the bad write is %lu, not 1\\n", (unsigned long)bad); failed++; }}
    wrong[1][0] = 3; wrong[1][1] = 0; wrong[1][2] = 0;
    if (!{int("TABLE" in [w["name"] for w in d.map["windows"]])}) expect("a table write without a table", {d.f}load(0, wrong, 2, &bad), {d.P}ERR_WRITE);
    for (k = 0; k < sizeof regs / 4; k++) if (regs[k]) {{ printf("FAIL a refused load wrote\\n"); failed++; break; }}
    /* The swap: requested, and waited for. */
    memset(regs, 0, sizeof regs);
    reads_of_frames = 0; frames_after = 3;
    expect("a swap FRAMES counts on the third read", {d.f}swap(0, 10), {d.P}OK);
    if (regs[{d.P}CONTROL_OFFSET / 4] != {d.P}CONTROL_SWAP_MASK) {{ printf("FAIL CONTROL.SWAP not written\\n"); failed++; }}
    reads_of_frames = 0; frames_after = 1000;
    expect("a swap that never comes", {d.f}swap(0, 10), {d.P}ERR_TIMEOUT);
    printf("%d failed\\n", failed);
    return failed != 0;
}}
"""
    src = out / "driver_test.c"
    src.write_text(prog)
    exe = out / "driver_test"
    sh(["cc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-Wno-unused-function", str(src), "-o", str(exe)])
    said = sh([str(exe)])
    return f"{d.path.name}: the driver on a model of the slave: {len(images)} identification cases, a frame of {said.count('ok')} checks passed"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("designs", type=Path, nargs="+")
    ap.add_argument("--rmapgen", required=True)
    ap.add_argument("--build", type=Path, default=Path("build/regs"))
    a = ap.parse_args()
    venv_bin = Path(sys.executable).parent
    designs = [Design(p) for p in a.designs]
    build = a.build.resolve()
    if build.exists():
        shutil.rmtree(build)
    ok = bad = 0
    for d in designs:
        others = [o for o in designs if o is not d]
        for check in (lambda: check_peakrdl(d, build, venv_bin),
                      lambda: check_compiles(d, build),
                      lambda: fake_slave_test(d, others, a.rmapgen, build)):
            try:
                print(f"check_regs: {check()}", flush=True)
                ok += 1
            except RuntimeError as e:
                print(f"check_regs: FAILED: {e}", flush=True)
                bad += 1
    print(f"{ok} passed, {bad} failed")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
