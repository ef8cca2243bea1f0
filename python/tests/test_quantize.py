"""rmapgen.quantize: float normals, unit or not, as a design's gradients (docs/PYTHON.md).

Each row is divided by its largest |component| m and multiplied by 2^(G-1) - 1, then rounded to
the nearest integer, halves away from zero: round((c / m) * (2^(G-1) - 1)) in float64."""

import numpy as np
import pytest

import rmapgen

C8 = rmapgen.Config(grad_bits=8, red_bits=6)  # 2^(G-1) - 1 = 127


@pytest.mark.parametrize("normal,want", [
    # 0.5 * 127 = 63.5 exactly: a half, away from zero, on both sides.
    ([2.0, 1.0, 0.0], [127, 64, 0]),
    ([-2.0, -1.0, 0.0], [-127, -64, 0]),
    ([0.5, -1.0, 0.25], [64, -127, 32]),   # 0.25 * 127 = 31.75 up
    # Nearest, not truncated: 0.375 * 127 = 47.625, -0.125 * 127 = -15.875.
    ([8.0, 3.0, -1.0], [127, 48, -16]),
    # 1/3 * 127 = 42.33 down, 2/3 * 127 = 84.67 up.
    ([0.0, 1.0, -3.0], [0, 42, -127]),
    ([0.0, 2.0, 3.0], [0, 85, 127]),
    # The axes and the diagonal: the largest component is 127 whatever the length.
    ([0.0, 0.0, 1.0], [0, 0, 127]),
    ([0.0, -1e-300, 0.0], [0, -127, 0]),
    ([1.0, 1.0, 1.0], [127, 127, 127]),
    ([1.0, 1e-3, 0.0], [127, 0, 0]),        # 0.127 rounds to 0
    ([1.0, 4e-3, 0.0], [127, 1, 0]),        # 0.508 rounds to 1
])
def test_quantize_rounds_as_documented(normal, want):
    g = rmapgen.quantize(np.array([normal]), C8)
    assert g.dtype == np.int32 and g.shape == (1, 3)
    assert g.tolist() == [want]


def test_quantize_ignores_length_and_keeps_symmetry():
    rng = np.random.default_rng(60)
    n = rng.normal(size=(5000, 3))
    unit = n / np.linalg.norm(n, axis=1, keepdims=True)
    for c in (C8, rmapgen.Config(), rmapgen.Config(grad_bits=16)):
        top = 2 ** (c.grad_bits - 1) - 1
        g = rmapgen.quantize(unit, c)
        # Unit or not: scaled by powers of two, the same gradients.
        for k in (-40, -1, 3, 60):
            assert np.array_equal(rmapgen.quantize(unit * 2.0**k, c), g)
        # Mirrored and axis-permuted normals give the mirrored and permuted gradients.
        assert np.array_equal(rmapgen.quantize(-unit, c), -g)
        assert np.array_equal(rmapgen.quantize(unit[:, [2, 0, 1]], c), g[:, [2, 0, 1]])
        # Full scale: the largest |component| is 2^(G-1) - 1, every component within half an
        # LSB of the exact value, so in range and never zero.
        assert (np.abs(g).max(axis=1) == top).all()
        m = np.abs(n).max(axis=1, keepdims=True)
        assert np.abs(g - n / m * top).max() <= 0.5
        # They shade, and the reference is defined for every one.
        d = rmapgen.Design(c)
        assert len(d.shade(g)) == len(g) and len(d.reference(g)) == len(g)


def test_quantize_reads_every_real_input_exactly():
    want = rmapgen.quantize(np.array([[2.0, 1.0, 0.0], [0.0, 0.0, -5.0]]), C8)
    for n in ([[2, 1, 0], [0, 0, -5]], ((2.0, 1, 0), (0, 0, -5.0)),
              np.array([[2, 1, 0], [0, 0, -5]], dtype=np.int8),
              np.array([[2, 1, 0], [0, 0, -5]], dtype=np.float16),
              np.array([[2, 1, 0], [0, 0, -5]], dtype=">f4"),
              np.array([[2, 1, 0], [0, 0, -5]], dtype=np.float64)[:, ::-1][:, ::-1],
              [[np.float32(2), np.int64(1), 0], [0, 0, np.float64(-5)]]):
        assert np.array_equal(rmapgen.quantize(n, C8), want)
    assert rmapgen.quantize(np.zeros((0, 3)), C8).shape == (0, 3)


def test_quantize_refuses_what_has_no_direction_or_no_exact_value():
    for n, err, msg in (
        ([[1, 0, 0], [0.0, 0.0, 0.0]], ValueError, r"^normals\[1\] = \(0, 0, 0\) has no direction "
         r"\(zero, NaN or infinite\)$"),
        ([[float("nan"), 0, 1]], ValueError, r"^normals\[0\] = \(NaN, 0, 1\) has no direction"),
        ([[0, float("-inf"), 1]], ValueError, r"^normals\[0\] = \(0, -inf, 1\) has no direction"),
        (np.array([[True, False, True]]), TypeError, r"^normals: dtype bool is not a real dtype; "
         r"nothing is cast$"),
        (np.array([[1 + 0j, 0, 1]]), TypeError, r"^normals: dtype complex128 is not a real dtype"),
        (np.array([["1", "0", "1"]]), TypeError, r"^normals: dtype <U1 is not a real dtype"),
        (np.array([[1, 0, 1]], dtype=np.longdouble), TypeError, r"^normals: dtype float128 is wider"),
        ([[1, 0, None]], TypeError, r"^normals\[0, 2\] = None is a NoneType, not a real number$"),
        ([[2**53, 1, 0], [-(2**53) - 1, 0, 1]], ValueError, r"^normals\[1, 0\] = -9007199254740993 "
         r"is outside"),
        (np.zeros((2, 2)), ValueError, r"^normals: expected an \(N, 3\) array, got shape \(2, 2\)$"),
    ):
        with pytest.raises(err, match=msg):
            rmapgen.quantize(n, C8)
    with pytest.raises(TypeError):
        rmapgen.quantize([[1.0, 0, 0]], 8)  # a Config, not grad_bits: the design says it


def test_quantize_keeps_the_direction_better_than_the_spheres_unit_scale():
    # sphere() scales unit normals by 2^(G-1) - 1 and keeps their length; quantize scales each
    # to full range. Same directions at the axis; elsewhere quantize's are at least as close.
    c = rmapgen.Config()
    size = 64
    g, xy = rmapgen.sphere(c, size)
    xy = xy.astype(np.float64)  # the sphere's pixel centres, as render places them
    sx = (2 * xy[:, 0] + 1 - size) / size
    sy = (size - 1 - 2 * xy[:, 1]) / size
    n = np.stack([sx, sy, np.sqrt(1 - sx**2 - sy**2)], axis=1)
    q = rmapgen.quantize(n, c)

    def angle(a, b):
        a = a / np.linalg.norm(a, axis=1, keepdims=True)
        b = b / np.linalg.norm(b, axis=1, keepdims=True)
        return np.arccos(np.clip((a * b).sum(axis=1), -1, 1))

    assert angle(q, n).max() <= angle(g, n).max()
    assert angle(q, n).mean() < angle(g, n).mean()
