#!/usr/bin/env python3
"""How `rmapgen prove` scales with shards (make prove-scaling, a benchmark; figures in
docs/VERIFICATION.md "On a cluster").

Usage: prove-scaling.py RMAPGEN DESIGN BUILD [N ...]   (default N: 1 2 4 8)

Builds once (`prove --build-only`), then for each N runs the N shards of the proof one after
another on this machine, each with `--reuse` of that build (as the array tasks of
`prove --slurm` do), and merges them: a cluster of N nodes of this machine's kind would take
about the largest shard's time (plus the build and the merge, listed apart). Each shard's
wall time is measured around its process; the parts' own times come from its report.

Prints, and writes to BUILD/scaling.md, a table: for each N measured, the largest and smallest
shard and their sum; for every N up to 1,000 (Slurm's array limit) a model, t(N) = R + W / N,
with R what every shard repeats whatever N (measured: shard 1 of a 2^20-way split, the structure included, whose own
inputs take microseconds: the process, loading the build, enumerating the states) and W the
work that divides (the largest measured run's sum less N x R); and the speed-up of the
largest shard against one node (N = 1 measured, else the model's R + W).

Exit 0 when every merge said PROVEN; else 1 (the first failure's output is printed).
"""

import json
import os
import subprocess
import sys
import time


def run(cmd, log):
    t0 = time.monotonic()
    with open(log, "w") as f:
        status = subprocess.call(cmd, stdout=f, stderr=subprocess.STDOUT)
    return status, time.monotonic() - t0


def main():
    if len(sys.argv) < 4:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    rmapgen, design, build = sys.argv[1:4]
    counts = [int(n) for n in sys.argv[4:]] or [1, 2, 4, 8]
    name = os.path.basename(os.path.normpath(design))
    os.makedirs(build, exist_ok=True)
    built = os.path.join(build, f"{name}-build")
    status, secs = run([rmapgen, "prove", design, "--build-only", "--build", build, "--force"],
                       os.path.join(build, "build.log"))
    if status != 0:
        print(open(os.path.join(build, "build.log")).read(), end="")
        return 1
    print(f"prove-scaling: built once in {secs:.1f} s", flush=True)
    rows = []
    for n in counts:
        shards = []
        reports = []
        for k in range(1, n + 1):
            report = os.path.join(build, f"shard-{k}-of-{n}.json")
            log = os.path.join(build, f"shard-{k}-of-{n}.log")
            status, secs = run([rmapgen, "prove", design, "--shard", f"{k}/{n}", "--reuse", built,
                                "--build", os.path.join(build, "shards"), "--report", report,
                                "--force"], log)
            if status != 0:
                print(open(log).read(), end="")
                return 1
            r = json.load(open(report))
            parts = {p["name"]: p["seconds"] for p in r["parts"]}
            divided = parts.get("front", 0.0) + parts.get("states", 0.0)
            shards.append((secs, divided))
            reports.append(report)
            print(f"prove-scaling: shard {k}/{n}: {secs:.1f} s (front and states {divided:.1f} s)",
                  flush=True)
        log = os.path.join(build, f"merge-{n}.log")
        status, merge_secs = run([rmapgen, "prove", "--merge", *reports], log)
        text = open(log).read()
        if status != 0 or "PROVEN" not in text:
            print(text, end="")
            return 1
        walls = [s for s, _ in shards]
        rows.append({"n": n, "max": max(walls), "min": min(walls), "sum": sum(walls),
                     "merge": merge_secs, "shards": shards})
    # What every shard repeats whatever N (its start, loading the build, enumerating the
    # states, the structure in shard 1, the largest): shard 1 of a 2^20-way split, whose own inputs take
    # microseconds. Measured, not assumed.
    log = os.path.join(build, "fixed.log")
    status, fixed = run([rmapgen, "prove", design, "--shard", "1/1048576", "--reuse", built,
                         "--build", os.path.join(build, "shards"), "--force"], log)
    if status != 0:
        print(open(log).read(), end="")
        return 1
    big = max(rows, key=lambda r: r["n"])
    # The work that divides by N: the largest run's shards less what each repeats.
    work = big["sum"] - big["n"] * fixed
    measured = {r["n"]: r for r in rows}
    lines = [f"What every shard repeats (shard 1 of 2^20, the structure included): {fixed:.1f} s; the work that divides "
             f"by N (the {big['n']}-shard run's sum less that): {work:.1f} s.", "",
             "| shards | largest shard, measured (s) | smallest (s) | sum (s) | model: repeated + work / N (s) | speed-up of the largest shard |",
             "|---:|---:|---:|---:|---:|---:|"]
    for n in sorted(set(counts) | {1, 2, 4, 8, 16, 64, 256, 1000}):
        model = fixed + work / n
        r = measured.get(n)
        one = measured[1]["max"] if 1 in measured else fixed + work
        if r is None:
            lines.append(f"| {n} | | | | {model:.1f} | {one / model:.1f} |")
        else:
            lines.append(f"| {n} | {r['max']:.1f} | {r['min']:.1f} | {r['sum']:.1f} | {model:.1f} | {one / r['max']:.1f} |")
    lines.append(f"\nA merge took {big['merge']:.1f} s; the build, once, is apart.")
    table = "\n".join(lines) + "\n"
    print(table, end="")
    with open(os.path.join(build, "scaling.md"), "w") as f:
        f.write(table)
    return 0


if __name__ == "__main__":
    sys.exit(main())
