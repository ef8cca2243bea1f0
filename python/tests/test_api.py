"""The package's own contract: validation as the TOML's, bounds, shapes, no silent casts."""

import numpy as np
import pytest

import rmapgen


def test_config_fields_and_validation_are_the_tomls():
    c = rmapgen.Config(grad_bits=8, red_bits=6)
    assert c.grad_bits == 8 and c.red_bits == 6 and c.map_bits == 8
    assert c == rmapgen.Config.from_toml(c.to_toml())
    assert c.replace(index_bits=4).index_bits == 4 and c.index_bits == 3
    assert rmapgen.Config().as_dict()["grad_bits"] == 12
    with pytest.raises(ValueError, match=r"^Config: grad_bits = 40 is out of range; allowed 8..=16$"):
        rmapgen.Config(grad_bits=40)
    with pytest.raises(ValueError, match="unknown field `grad_bitz`"):
        rmapgen.Config(grad_bitz=8)
    with pytest.raises(TypeError, match="grad_bits: expected a bool, an int or a str"):
        rmapgen.Config(grad_bits=8.0)
    with pytest.raises(ValueError, match="comp_table"):
        rmapgen.Config(comp_table="flash")
    with pytest.raises(AttributeError):
        rmapgen.Config().no_such_field


def test_a_scene_reads_and_refuses_as_the_cli():
    s = rmapgen.Scene.standard()
    assert s.map_fit == "sample" and s.with_map_fit("lsq").map_fit == "lsq"
    assert rmapgen.Scene.from_toml(s.to_toml()).to_toml() == s.to_toml()
    with pytest.raises(ValueError, match="map_fit \"best\" is not one of"):
        s.with_map_fit("best")
    with pytest.raises(ValueError, match="has no direction"):
        s.shade(np.array([[0.0, 0.0, 0.0]]))
    # The table fit needs a table the host loads.
    with pytest.raises(ValueError, match="comp-table ram"):
        rmapgen.Design(rmapgen.Config(), s.with_map_fit("table"))


def test_shade_reads_int32_in_place_and_checks_every_other_input():
    d = rmapgen.Design(rmapgen.Config(grad_bits=8, red_bits=6))
    g = np.array([[1, 2, 3], [0, 0, 0], [-128, 127, 5]], dtype=np.int32)
    want = d.shade(g)
    assert want.dtype == np.uint16 and want[1] == 0
    # Other integer dtypes, lists and strided views give the same results.
    assert np.array_equal(d.shade(g.astype(np.int64)), want)
    assert np.array_equal(d.shade(g.tolist()), want)
    wide = np.zeros((3, 6), dtype=np.int32)
    wide[:, ::2] = g
    assert np.array_equal(d.shade(wide[:, ::2]), want)
    # Out of the G-bit range, even where a cast to int32 would wrap into it.
    for bad in ([[128, 0, 0]], [[-129, 0, 0]], [[2**32 + 1, 0, 0]]):
        with pytest.raises(ValueError, match="outside -128..=127"):
            d.shade(np.array(bad, dtype=np.int64))
    with pytest.raises(ValueError, match=r"expected an \(N, 3\) array"):
        d.shade(np.zeros((4, 2), dtype=np.int32))
    with pytest.raises(ValueError, match=r"^g: expected an \(N, 3\) array, got shape \(3,\)$"):
        d.shade(np.zeros(3, dtype=np.int32))
    assert d.shade(np.zeros((0, 3), dtype=np.int32)).shape == (0,)


def test_reference_exact_and_metrics_are_renders():
    d = rmapgen.Design()
    g, xy = rmapgen.sphere(d.config, 64)
    assert g.shape[1] == 3 and xy.shape == (len(g), 2) and g.dtype == np.int32
    ref, exact = d.reference(g), d.exact(g)
    # The quantised reference is the exact light model rounded and clamped to 8 bits.
    assert np.abs(ref - np.clip(exact * 255, 0, 255)).max() <= 0.5 + 1e-9
    m = rmapgen.metrics(d.shade(g), ref, d.peak)
    assert m["pixels"] == len(g) and m["peak"] == 255
    assert sum(m["abs_error_histogram"]) == len(g)
    same = rmapgen.metrics(ref, ref, 255)
    assert same["max_abs_error"] == 0 and same["psnr_db"] is None
    with pytest.raises(ValueError, match="metrics of 2 and 1 samples"):
        rmapgen.metrics([1, 2], [1], 255)
    with pytest.raises(ValueError, match=r"^a\[0\] = -1 is outside 0..=255"):
        rmapgen.metrics([-1], [1], 255)
    with pytest.raises(ValueError, match="size 0 is outside"):
        rmapgen.sphere(d.config, 0)


def test_trace_is_bounded_and_follows_the_pipeline():
    d = rmapgen.Design()
    g = np.array([[300, -1000, 20]], dtype=np.int32)
    t = d.trace(g)
    names = list(t)
    assert names[0].startswith("u_zero_detect.") and names[-1] == "i_o"
    assert t["u_sort_shift.m_o"][0] == t["u_normalise.m_i"][0]
    assert t["u_interpolate.i_o"][0] == t["i_o"][0] == d.shade(g)[0]
    assert t["gy_i"][0] == (-1000) & 0xFFF
    with pytest.raises(ValueError, match="rgb has 2 rows for 1 gradients"):
        d.trace(g, np.zeros((2, 3), dtype=np.int64))
    with pytest.raises(ValueError, match=f"at most {rmapgen.TRACE_MAX} samples"):
        d.trace(np.zeros((rmapgen.TRACE_MAX + 1, 3), dtype=np.int32))
