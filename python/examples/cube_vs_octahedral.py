"""The paper's cube map against an octahedral map at equal memory, scene by scene.

The cube map is rmapgen's design, shaded bit for bit as the hardware does (no normalisation,
a reciprocal ROM and an atan compensation ROM). The octahedral map is written here in numpy
the way a researcher would try it: the gradient normalised in floating point, folded onto the
octahedron |x| + |y| + |z| = 1 and unfolded onto a square, an S x S map sampled from the same
light model at the grid points and interpolated bilinearly, with S^2 as close as it gets to
the cube's 3 x 2^(2 index_bits) entries of the same width. Both are measured against the
float reference on the sphere image, in output LSBs.

    .venv/bin/python python/examples/cube_vs_octahedral.py [--size 512] [scenes/*.toml]
"""

import argparse
import pathlib

import numpy as np

import rmapgen

ROOT = pathlib.Path(__file__).resolve().parents[2]


def encode(n):
    """Unit normals (N, 3) to square coordinates in [-1, 1]^2."""
    p = n[:, :2] / np.abs(n).sum(axis=1, keepdims=True)
    lower = n[:, 2] < 0
    s = np.where(p >= 0, 1.0, -1.0)
    folded = (1.0 - np.abs(p[:, ::-1])) * s
    return np.where(lower[:, None], folded, p)


def decode(e):
    """Square coordinates (N, 2) to unit normals."""
    z = 1.0 - np.abs(e).sum(axis=1)
    t = np.maximum(-z, 0.0)
    xy = e - t[:, None] * np.where(e >= 0, 1.0, -1.0)
    n = np.column_stack([xy, z])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def octahedral(scene, side, peak):
    """The S x S map of the scene's light model at the grid points, quantised."""
    at = -1.0 + 2.0 * np.arange(side) / (side - 1)
    e = np.column_stack([np.repeat(at, side), np.tile(at, side)])
    return np.clip(np.rint(scene.shade(decode(e)) * peak), 0, peak).reshape(side, side)


def shade_octahedral(m, g, peak):
    """Bilinear interpolation of the map at each gradient's float-normalised direction."""
    side = m.shape[0]
    n = g / np.linalg.norm(g, axis=1, keepdims=True)
    f = (encode(n) + 1.0) * 0.5 * (side - 1)
    i = np.clip(np.floor(f).astype(int), 0, side - 2)
    w = f - i
    a, b = i[:, 0], i[:, 1]
    top = m[a, b] * (1 - w[:, 1]) + m[a, b + 1] * w[:, 1]
    bot = m[a + 1, b] * (1 - w[:, 1]) + m[a + 1, b + 1] * w[:, 1]
    return np.clip(np.rint(top * (1 - w[:, 0]) + bot * w[:, 0]), 0, peak).astype(np.int64)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", type=pathlib.Path,
                    default=sorted((ROOT / "scenes").glob("*.toml")))
    ap.add_argument("--size", type=int, default=512, help="sphere image side (default 512)")
    args = ap.parse_args()

    cfg = rmapgen.Config()  # the paper's design: 3 maps of 512 entries of 8 bits
    entries = rmapgen.Design(cfg).maps.size
    side = int(round(np.sqrt(entries)))
    g, _ = rmapgen.sphere(cfg, args.size)
    print(f"sphere {args.size}^2 ({len(g)} pixels); cube: 3 x {entries // 3} entries; "
          f"octahedral: {side} x {side} = {side * side} entries; {cfg.map_bits} bits each")
    print(f"{'scene':<16} {'map_fit':<8} {'cube max':>8} {'rmse':>6} {'psnr':>6}   "
          f"{'oct max':>7} {'rmse':>6} {'psnr':>6}")
    for path in args.scenes:
        scene = rmapgen.Scene.read(path)
        if scene.map_fit == "table":
            scene = scene.with_map_fit("minimax")
        d = rmapgen.Design(cfg, scene)
        assert d.maps.size == entries, "equal memory: the cube's entries"
        ref = d.reference(g)
        cube = rmapgen.metrics(d.shade(g), ref, d.peak)
        oct_ = rmapgen.metrics(shade_octahedral(octahedral(scene, side, d.peak), g, d.peak),
                               ref, d.peak)
        cells = [f"{m['max_abs_error']:>8} {m['rmse']:>6.2f} {m['psnr_db'] or float('inf'):>6.1f}"
                 for m in (cube, oct_)]
        print(f"{path.stem:<16} {scene.map_fit:<8} {cells[0]}   {cells[1][1:]}")


if __name__ == "__main__":
    main()
