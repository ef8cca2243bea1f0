#!/usr/bin/env python3
"""Runs the cocotb bus test (test_bus.py) on a design that `rmapgen generate --bus
wishbone|axi4-lite` wrote, in Icarus, through cocotb's Python runner; with --plant, on a copy
of the design (or of its expected values) with a planted fault, and then it passes only if the
test FAILS (every check must be able to fail).

    run_bus.py DESIGN_DIR [--build DIR] [--limit N] [--plant NAME ...]

Plants (each an edit of the register block rmap_regs.v of the copy, but `expected`, which
corrupts one expected value in the test): swap-now (the swap does not wait for the frame's
end), no-drain (a window write after a swap does not wait for the samples in flight), no-err
(refused accesses answered OK), magic (the identification word off by one), frames (FRAMES
counts two a swap), clear (CONTROL.CLEAR_ERRORS does nothing). An edit that finds nothing to
change is an error, so a plant cannot silently become a no-op.
Exit 0 when every run did what it should, 1 otherwise; the last line is `N passed, M failed`.
"""

import argparse
import json
import re
import shutil
import sys
import time
from pathlib import Path

from cocotb_tools.check_results import get_results
from cocotb_tools.runner import get_runner

HERE = Path(__file__).resolve().parent

# name -> (file edit: (old, new) in the register block's .v, or None; environment for the test)
PLANTS = {
    "expected": (None, {"RMAP_PLANT": "expected"}),
    "swap-now": (("wire swap     = pending_q && !in_frame_q && !wr_en_q;",
                  "wire swap     = pending_q && !wr_en_q;"), {}),
    "no-drain": (("wire win_wait = draining || pending_q;", "wire win_wait = pending_q;"), {}),
    "no-err": (("err_q    <= done && bad;", "err_q    <= 1'b0;"), {}),
    "magic": (("32'h524d4150", "32'h524d4151"), {}),
    "frames": (("frames_q <= frames_q + 32'd1;", "frames_q <= frames_q + 32'd2;"), {}),
    "clear": (("if (clear_errors)\n", "if (1'b0)\n"), {}),
}


def run(design, build, limit, env):
    """One cocotb run of `design`; True when the test passed."""
    man = json.loads((design / "manifest.json").read_text())
    if "bus" not in man:
        sys.exit(f"run_bus: {design} has no bus slave (generate it with --bus wishbone or --bus axi4-lite)")
    top = man["top"]
    sources = [design / m["file"] for m in man["modules"]]
    runner = get_runner("icarus")
    build.mkdir(parents=True, exist_ok=True)
    runner.build(sources=sources, hdl_toplevel=top, build_dir=build, timescale=("1ns", "1ps"),
                 log_file=build / "build.log")
    extra = dict(env)
    if limit:
        extra["RMAP_LIMIT"] = str(limit)
    results = build / "results.xml"
    try:
        runner.test(test_module="test_bus", hdl_toplevel=top, build_dir=build,
                    test_dir=design, results_xml=str(results), extra_env=extra,
                    log_file=build / "test.log", test_args=[], plusargs=[],
                    seed=61)
    except SystemExit:
        return False
    tests, failed = get_results(results)
    return tests > 0 and failed == 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("design", type=Path)
    ap.add_argument("--build", type=Path, default=Path("build/bus"))
    ap.add_argument("--limit", type=int, default=0, help="samples of each map part (0: all)")
    ap.add_argument("--plant", action="append", default=[], choices=sorted(PLANTS))
    a = ap.parse_args()
    sys.path.insert(0, str(HERE))
    design = a.design.resolve()
    build = a.build.resolve()
    ok = bad = 0
    runs = [(None, None, {})] if not a.plant else [(p, *PLANTS[p]) for p in a.plant]
    for name, edit, env in runs:
        t0 = time.time()
        d = design
        if edit is not None:
            d = build / name / "design"
            if d.exists():
                shutil.rmtree(d)
            shutil.copytree(design, d)
            top = json.loads((d / "manifest.json").read_text())
            f = d / next(m["file"] for m in top["modules"] if m["name"].endswith("rmap_regs"))
            text = f.read_text()
            old, new = edit
            if text.count(old) != 1:
                sys.exit(f"run_bus: plant {name}: `{old}` is not in {f} exactly once")
            f.write_text(text.replace(old, new))
        sim = build / (name or "clean") / "sim"
        passed = run(d, sim, a.limit, env)
        want = name is None
        what = f"cocotb {'clean' if want else 'planted ' + name}"
        # The test's own verdict line (samples), when it got that far.
        log = sim / "test.log"
        counts = [l for l in (log.read_text().splitlines() if log.exists() else [])
                  if re.fullmatch(r"\d+ passed, \d+ failed", l)]
        verdict = ("passed" if passed else "failed") + (f": {counts[-1]}" if counts else "")
        good = passed == want
        print(f"run_bus: {what}: the test {verdict}{'' if good else ' (WRONG)'} "
              f"({time.time() - t0:.1f} s; log {log})",
              flush=True)
        ok += good
        bad += not good
    print(f"{ok} passed, {bad} failed")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
