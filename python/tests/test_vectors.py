"""The Python package against the command line: bit for bit on the vectors `generate` writes.

Each case writes a configuration (Config.to_toml) and a scene (Scene.to_toml), has the CLI
(RMAPGEN, default target/debug/rmapgen) generate the design from them, and checks:
- every ROM and map the package holds equals the design's $readmemh files;
- shade() and trace() give every line of vectors/rmap_top.hex (the scene's map; with a
  second design of the alternate scene, the lines of the second map), colour included;
- trace()'s sort_shift and zero_detect ports give every line of their own vector files.
"""

import os
import pathlib
import subprocess

import numpy as np
import pytest

import rmapgen

ROOT = pathlib.Path(__file__).resolve().parents[2]
RMAPGEN = os.environ.get("RMAPGEN", str(ROOT / "target" / "debug" / "rmapgen"))

# (name, config fields, map fit): the paper's design; the narrowest gradients (G = 8, R = 6)
# with a minimax fit; colour without interpolation or compensation; a compensation table the
# host loads, fitted to the scene (map_fit table), on G = 8.
CASES = [
    ("paper", {}, "sample"),
    ("g8_minimax", {"grad_bits": 8, "red_bits": 6}, "minimax"),
    ("colour_nearest", {"color": True, "interpolation": False, "interp_bits": 0,
                        "compensation": False}, "lsq"),
    ("g8_table", {"grad_bits": 8, "red_bits": 6, "comp_table": "ram"}, "table"),
]


def generate(tmp, cfg, scene):
    (tmp / "config.toml").write_text(cfg.to_toml())
    (tmp / "scene.toml").write_text(scene.to_toml())
    out = tmp / "design"
    subprocess.run([RMAPGEN, "generate", "--config", str(tmp / "config.toml"), "--scene",
                    str(tmp / "scene.toml"), "--out", str(out)], check=True,
                   capture_output=True)
    return out


def hexfile(path):
    """The whitespace-separated hex fields of a $readmemh or vector file, line by line."""
    rows = [line.split() for line in path.read_text().splitlines()
            if line.strip() and not line.startswith("//")]
    return np.array([[int(x, 16) for x in r] for r in rows], dtype=np.int64)


def signed(x, bits):
    return np.where(x >= 1 << (bits - 1), x - (1 << bits), x).astype(np.int32)


@pytest.fixture(params=CASES, ids=[c[0] for c in CASES])
def case(request, tmp_path):
    name, fields, fit = request.param
    cfg = rmapgen.Config(**fields)
    scene = rmapgen.Scene.standard().with_map_fit(fit)
    return cfg, scene, generate(tmp_path, cfg, scene)


def test_roms_and_maps_are_the_designs_files(case):
    cfg, scene, out = case
    d = rmapgen.Design(cfg, scene)
    assert np.array_equal(hexfile(out / "recip_rom.hex")[:, 0], d.recip_rom)
    # With comp_table = "ram" the position stage is a RAM addressed {buf, u} that holds the
    # scene's table in both buffers out of reset.
    if d.comp_table is not None:
        both = np.concatenate([d.comp_table, d.comp_table])
        assert np.array_equal(hexfile(out / "atan_rom.hex")[:, 0], both)
    elif cfg.compensation:
        assert np.array_equal(hexfile(out / "atan_rom.hex")[:, 0], d.comp_rom)
    else:
        assert d.comp_rom is None and not (out / "atan_rom.hex").exists()
    for k, axis in enumerate("xyz"):
        assert np.array_equal(hexfile(out / f"map_{axis}.hex")[:, 0], d.maps[k]), axis
    if d.comp_table is not None:
        assert np.array_equal(hexfile(out / "map_table.hex")[:, 0], d.comp_table)


def test_shade_and_trace_give_every_top_vector(case):
    cfg, scene, out = case
    g_bits, colour = cfg.grad_bits, cfg.color
    v = hexfile(out / "vectors" / "rmap_top.hex")
    # The second map is the alternate scene, filled as that scene says.
    second = rmapgen.Scene.read(ROOT / "scenes" / "two_lights.toml")
    designs = [rmapgen.Design(cfg, scene), rmapgen.Design(cfg, second)]
    # The second buffer of a comp_table = "ram" design holds the linear index, not a fit.
    bufs = [0] if designs[0].comp_table is not None else [0, 1]
    checked = 0
    for buf in bufs:
        rows = v[v[:, 0] == buf]
        assert len(rows) > 100
        g = signed(rows[:, 1:4], g_bits)
        col = 4
        rgb = None
        if colour:
            rgb, col = rows[:, 4:7], 7
        zero, want = rows[:, col], rows[:, col + 1]
        d = designs[buf]
        assert np.array_equal(d.shade(g), want), f"buffer {buf}"
        t = d.trace(g, rgb)
        assert np.array_equal(t["i_o"], want)
        assert np.array_equal(t["zero_o"], zero)
        assert np.array_equal(t["gx_i"], rows[:, 1])
        if colour:
            for k, c in enumerate("rgb"):
                assert np.array_equal(t[f"{c}_o"], rows[:, col + 2 + k]), c
        checked += len(rows)
    assert checked > 1000


@pytest.mark.parametrize("stage,outs", [
    ("sort_shift", ["axis_o", "s_max_o", "s_u_o", "s_v_o", "m_o", "a_o", "b_o"]),
    ("zero_detect", ["zero_o"]),
])
def test_trace_gives_every_line_of_the_gradient_stages(case, stage, outs):
    cfg, scene, out = case
    v = hexfile(out / "vectors" / f"{stage}.hex")
    t = rmapgen.Design(cfg, scene).trace(signed(v[:, :3], cfg.grad_bits))
    for k, port in enumerate(outs):
        assert np.array_equal(t[f"u_{stage}.{port}"], v[:, 3 + k]), port
