"""Design.shade from Python against the Rust fast path it calls, side by side in one run.

    make python-bench     (builds the extension with --release first)

Times one call on 2^20 (default) uniform gradients of the paper's design, best of R, and the
same gradients through the Rust fast path alone (rmapgen._rmapgen._fast_path_seconds: no
conversion from Python, no returned array), and prints both rates and their ratio.
"""

import argparse
import time

import numpy as np

import rmapgen
from rmapgen import _rmapgen


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=1 << 20)
    ap.add_argument("--repeats", type=int, default=15)
    args = ap.parse_args()
    d = rmapgen.Design()
    h = 1 << (d.config.grad_bits - 1)
    g = np.random.default_rng(1).integers(-h, h, size=(args.samples, 3), dtype=np.int32)
    d.shade(g)  # warm-up: pages, threads
    rows = []
    for what in ("python", "rust", "python", "rust"):  # interleaved: a noisy machine hits both
        if what == "python":
            best = float("inf")
            for _ in range(args.repeats):
                t = time.perf_counter()
                d.shade(g)
                best = min(best, time.perf_counter() - t)
        else:
            best = _rmapgen._fast_path_seconds(d, g, args.repeats)
        rows.append((what, best))
    py = min(t for w, t in rows if w == "python")
    rs = min(t for w, t in rows if w == "rust")
    n = args.samples
    print(f"{n} gradients, best of {args.repeats} (x2, interleaved):")
    print(f"  Design.shade from Python  {py * 1e3:8.2f} ms  {n / py / 1e6:8.1f} M samples/s")
    print(f"  Rust fast path alone      {rs * 1e3:8.2f} ms  {n / rs / 1e6:8.1f} M samples/s")
    print(f"  ratio (Python / Rust)     {py / rs:8.3f}")


if __name__ == "__main__":
    main()
