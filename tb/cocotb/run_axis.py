#!/usr/bin/env python3
"""Runs the cocotb AXI4-Stream test (test_axis.py) on a design that `rmapgen generate
--handshake --axis` wrote, in Icarus, through cocotb's Python runner; with --plant, on a copy
of the design (or of its expected values) with a planted fault, and then it passes only if the
test FAILS (every check must be able to fail).

    run_axis.py DESIGN_DIR [--build DIR] [--limit N] [--plant NAME ...]

Plants: expected (one expected intensity flipped in the test), skid-side (tuser/tlast corrupted
on the output queue's skid path), skid-drop (the skid entry never moves to the head: samples
lost under backpressure), skid-dup (the skid entry is never freed: stale or repeated results, or the
stream stalls; its first result is then unknown). The skid plants edit rmap_top.v of the copy; an edit that finds nothing to
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

# name -> (file edit: (old, new) in the top's .v, or None; environment for the test)
PLANTS = {
    "expected": (None, {"RMAP_PLANT": "expected"}),
    "skid-side": (("skid_side_q <= side_in;", "skid_side_q <= ~side_in;"), {}),
    "skid-drop": (("valid_q <= skid_valid_q || push;", "valid_q <= push;"), {}),
    "skid-dup": (("take ? (skid_valid_q && push)", "take ? (skid_valid_q || push)"), {}),
}


def run(design, build, limit, env):
    """One cocotb run of `design`; True when the test passed."""
    man = json.loads((design / "manifest.json").read_text())
    if "axis" not in man:
        sys.exit(f"run_axis: {design} has no AXI4-Stream top (generate it with --handshake --axis)")
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
        runner.test(test_module="test_axis", hdl_toplevel=top, build_dir=build,
                    test_dir=design, results_xml=str(results), extra_env=extra,
                    log_file=build / "test.log", test_args=[], plusargs=[],
                    seed=14)
    except SystemExit:
        return False
    tests, failed = get_results(results)
    return tests > 0 and failed == 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("design", type=Path)
    ap.add_argument("--build", type=Path, default=Path("build/axis"))
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
            f = d / next(m["file"] for m in top["modules"] if m["name"].endswith("rmap_top"))
            text = f.read_text()
            old, new = edit
            if text.count(old) != 1:
                sys.exit(f"run_axis: plant {name}: `{old}` is not in {f} exactly once")
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
        print(f"run_axis: {what}: the test {verdict}{'' if good else ' (WRONG)'} "
              f"({time.time() - t0:.1f} s; log {log})",
              flush=True)
        ok += good
        bad += not good
    print(f"{ok} passed, {bad} failed")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
