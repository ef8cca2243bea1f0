"""What the package refuses (issue 60): every array argument is read exactly or refused, with
one message naming the problem; outputs too large for memory raise MemoryError.

Each case of the issue is here: a float array (100.7 ...), unit normals as floats, np.uint64
2^64 - 1, bool, str and complex arrays, NaN, each through shade, reference, exact, trace and
metrics; an output larger than memory. test_quantize.py has the quantiser."""

import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import rmapgen

# The Design methods that take gradients, each called on one argument.
D12 = rmapgen.Design()
D8 = rmapgen.Design(rmapgen.Config(grad_bits=8, red_bits=6))
GRADIENT_TAKERS = {
    "shade": lambda d, g: d.shade(g),
    "reference": lambda d, g: d.reference(g),
    "exact": lambda d, g: d.exact(g),
    "trace": lambda d, g: d.trace(g),
    "_fast_path_seconds": lambda d, g: rmapgen._rmapgen._fast_path_seconds(d, g, 1),
}
TAKERS = pytest.mark.parametrize("take", GRADIENT_TAKERS.values(), ids=GRADIENT_TAKERS.keys())
QUANTIZE = re.escape("rmapgen.quantize(normals, config) turns float normals into gradients")


@TAKERS
def test_a_float_array_is_refused_not_truncated(take):
    # The issue: [[100.7, 200.2, 300.9]] shaded as (100, 200, 300).
    for dtype in (np.float64, np.float32, np.float16):
        g = np.array([[100.7, 200.2, 300.9]], dtype=dtype)
        with pytest.raises(TypeError, match=rf"^g: dtype {np.dtype(dtype)} is not an integer dtype; "
                           rf"nothing is cast; {QUANTIZE}$"):
            take(D12, g)
    # Integral floats too: the dtype is refused, not the values.
    with pytest.raises(TypeError, match="dtype float64"):
        take(D12, np.array([[100.0, 200.0, 300.0]]))
    # A list of floats is read element by element, and the first float named.
    with pytest.raises(TypeError, match=rf"^g\[0, 0\] = 100.7 is a float, not an integer; {QUANTIZE}$"):
        take(D12, [[100.7, 200.2, 300.9]])
    with pytest.raises(TypeError, match=r"^g\[1, 2\] = 3.0 is a float"):
        take(D12, [[1, 2, 3], [1, 2, 3.0]])


@pytest.mark.parametrize("dtype", [np.bool_, np.str_, np.bytes_, np.complex128, np.complex64,
                                   "datetime64[s]", "timedelta64[s]", "i4,i4,i4", np.object_])
@TAKERS
def test_every_dtype_that_is_not_an_integer_is_refused(take, dtype):
    g = np.array([[1, 0, 1]]).astype(dtype) if dtype != "i4,i4,i4" else np.zeros((1, 3), dtype)
    if dtype is np.object_:
        g = np.array([[1.0, 0, 1]], dtype=object)  # objects that are not ints
        with pytest.raises(TypeError, match=r"^g\[0, 0\] = 1.0 is a float, not an integer"):
            take(D12, g)
        return
    with pytest.raises(TypeError, match=rf"^g: dtype {re.escape(str(g.dtype))} is not an integer dtype"):
        take(D12, g)


@TAKERS
def test_bools_in_a_list_are_refused(take):
    with pytest.raises(TypeError, match=r"^g\[0, 1\] = True is a bool, not an integer"):
        take(D12, [[1, True, 2]])
    with pytest.raises(TypeError, match=r"^g\[0, 0\] = np.True_ is a bool"):
        take(D12, [[np.True_, 1, 2]])


@TAKERS
def test_a_nan_is_refused_as_a_float_never_as_a_huge_component(take):
    # The issue: NaN reported as `component -9223372036854775808`.
    for g in (np.array([[np.nan, 0, 1]]), [[float("nan"), 0, 1]], [[0, 1, float("inf")]]):
        with pytest.raises(TypeError) as e:
            take(D12, g)
        assert "9223372036854775808" not in str(e.value) and "float" in str(e.value)


@TAKERS
def test_the_range_is_checked_before_narrowing(take):
    # The issue: np.uint64 2^64 - 1 shaded as -1.
    g = np.array([[2**64 - 1, 0, 0]], dtype=np.uint64)
    with pytest.raises(ValueError, match=r"^g\[0, 0\] = 18446744073709551615 is outside "
                       r"-2048..=2047 \(grad_bits = 12\)$"):
        take(D12, g)
    # The first value out of range, by row and column, whatever wraps into range.
    for bad, at in (([[1, 2, 3], [0, 2**32 - 1, 0]], "[1, 1]"),
                    ([[1, 2, 3], [4, 5, -(2**63)]], "[1, 2]"),
                    ([[2**63, 0, 0]], "[0, 0]"),
                    ([[2**70, 0, 0]], "[0, 0]")):
        value = [v for row in bad for v in row if not -2048 <= v <= 2047][0]
        want = rf"^g\{at[:-1]}\] = {value} is outside -2048..=2047"
        with pytest.raises(ValueError, match=want):
            take(D12, bad)
        if -(2**63) <= value < 2**64:
            a = np.array(bad, dtype=np.int64 if value < 0 or value < 2**63 else np.uint64)
            with pytest.raises(ValueError, match=want):
                take(D12, a)


@pytest.mark.parametrize("dtype", [np.int8, np.int16, np.int32, np.int64,
                                   np.uint8, np.uint16, np.uint32, np.uint64])
def test_every_integer_dtype_reads_exactly_at_the_edges_of_the_range(dtype):
    # G = 8: -128..=127. Each dtype shades what int32 shades, and a value just outside the
    # range is refused wherever the dtype can hold one.
    info = np.iinfo(dtype)
    lo, hi = max(-128, int(info.min)), 127
    g = np.array([[lo, hi, 1], [0, 5, hi], [1, 0, 0]], dtype=dtype)
    want = D8.shade(g.astype(np.int32))
    assert np.array_equal(D8.shade(g), want)
    assert np.array_equal(D8.shade(g.astype(g.dtype.newbyteorder(">"))), want)
    assert np.array_equal(D8.shade(np.asfortranarray(g)), want)
    assert np.array_equal(D8.trace(g)["i_o"], want)
    for v in (128, -129):
        if info.min <= v <= info.max:
            with pytest.raises(ValueError, match=rf"^g\[1, 1\] = {v} is outside -128..=127"):
                D8.shade(np.array([[0, 1, 0], [0, v, 0]], dtype=dtype))


def test_python_ints_lists_tuples_and_numpy_scalars_are_read_exactly():
    g = np.array([[1, -2, 3], [-128, 127, 0]], dtype=np.int32)
    want = D8.shade(g)
    assert np.array_equal(D8.shade([[1, -2, 3], [-128, 127, 0]]), want)
    assert np.array_equal(D8.shade(((1, -2, 3), (-128, 127, 0))), want)
    assert np.array_equal(D8.shade([[np.int8(1), np.int16(-2), 3],
                                    [np.int64(-128), np.uint8(127), 0]]), want)
    assert np.array_equal(D8.shade([np.array([1, -2, 3]), np.array([-128, 127, 0])]), want)
    with pytest.raises(ValueError, match=r"^g\[0, 0\] = 18446744073709551615 is outside"):
        D8.shade([[np.uint64(2**64 - 1), 0, 0]])
    with pytest.raises(ValueError, match=r"^g: expected an \(N, 3\) array, got shape \(0,\)$"):
        D8.shade([])
    with pytest.raises(ValueError, match=r"^g: expected an \(N, 3\) array, got shape \(\)$"):
        D8.shade(5)
    assert D8.shade(np.zeros((0, 3), dtype=np.int16)).shape == (0,)


def test_unit_normals_as_floats_never_read_as_a_perfect_match():
    # The issue: unit normals truncated to zero vectors, shade and reference both 0, and
    # metrics reporting max error 0. Now the floats are refused everywhere, ...
    rng = np.random.default_rng(60)
    n = rng.normal(size=(1000, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    for f in (D12.shade, D12.reference, D12.exact):
        with pytest.raises(TypeError, match=QUANTIZE):
            f(n)
    with pytest.raises(TypeError, match="dtype float64"):
        rmapgen.metrics(n[:, 0], n[:, 1], D12.peak)
    # ... the truncation written out is zero vectors, which have no reference, ...
    cast = n.astype(np.int32)
    assert not cast.any()
    assert not D12.shade(cast).any()
    for f in (D12.reference, D12.exact):
        with pytest.raises(ValueError, match=r"^g\[0\] = \(0, 0, 0\) has no direction"):
            f(cast)
    # ... metrics of nothing is refused, ...
    with pytest.raises(ValueError, match="^metrics of no samples"):
        rmapgen.metrics([], [], D12.peak)
    # ... and quantised they shade as the design does: the reference differs somewhere.
    g = rmapgen.quantize(n, D12.config)
    m = rmapgen.metrics(D12.shade(g), D12.reference(g), D12.peak)
    assert m["pixels"] == 1000 and m["max_abs_error"] > 0 and m["psnr_db"] is not None


def test_a_zero_gradient_has_no_reference_but_shades_to_zero():
    g = np.array([[1, 2, 3], [0, 0, 0], [4, 5, 6]], dtype=np.int32)
    assert D12.shade(g)[1] == 0 and D12.trace(g)["i_o"][1] == 0
    for f in (D12.reference, D12.exact):
        with pytest.raises(ValueError, match=r"^g\[1\] = \(0, 0, 0\) has no direction, so no "
                           r"reference .*g\[np.any\(g != 0, axis=1\)\]$"):
            f(g)
        # The way the message gives works.
        assert len(f(g[np.any(g != 0, axis=1)])) == 2


def test_trace_reads_rgb_exactly():
    d = rmapgen.Design(rmapgen.Config(color=True))
    g = [[300, -1000, 20]]
    want = d.trace(g, np.array([[10, 20, 255]], dtype=np.int64))
    for rgb in ([[10, 20, 255]], np.array([[10, 20, 255]], dtype=np.uint8),
                np.array([[10, 20, 255]], dtype=">u2")):
        got = d.trace(g, rgb)
        assert all(np.array_equal(got[k], want[k]) for k in want)
    # Each channel reaches its own port: the colour reversed, the ports reversed.
    back = d.trace(g, [[255, 20, 10]])
    assert [want[f"{c}_i"][0] for c in "rgb"] == [10, 20, 255]
    assert [back[f"{c}_o"][0] for c in "rgb"] == [want[f"{c}_o"][0] for c in "bgr"]
    assert want["r_o"][0] < want["g_o"][0] < want["b_o"][0]
    with pytest.raises(TypeError, match=r"^rgb: dtype float64 is not an integer dtype; nothing is cast$"):
        d.trace(g, np.array([[10.5, 20, 255]]))
    with pytest.raises(TypeError, match=r"^rgb: dtype bool"):
        d.trace(g, np.array([[True, False, True]]))
    with pytest.raises(ValueError, match=r"^rgb\[0, 2\] = 256 is outside 0..=255"):
        d.trace(g, [[10, 20, 256]])
    with pytest.raises(ValueError, match=r"^rgb\[0, 0\] = 18446744073709551615 is outside 0..=255"):
        d.trace(g, np.array([[2**64 - 1, 0, 0]], dtype=np.uint64))


def test_a_long_trace_is_every_samples_path():
    # The trace fills its columns in blocks of 4096 samples: three blocks and a part, each
    # sample's column entries those of its own trace, at the blocks' edges too.
    g, _ = rmapgen.sphere(D12.config, 128)
    g = g[: 3 * 4096 + 5]
    t = D12.trace(g)
    assert np.array_equal(t["i_o"], D12.shade(g))
    for k in (0, 4095, 4096, 8191, 8192, 12287, 12288, len(g) - 1):
        one = D12.trace(g[k : k + 1])
        assert all(t[name][k] == one[name][0] for name in one), k


def test_metrics_reads_output_values_exactly():
    a = np.array([3, 0, 255], dtype=np.uint8)
    want = rmapgen.metrics(a, [1, 0, 250], 255)
    assert want["max_abs_error"] == 5 and want["pixels"] == 3
    for b in ([1, 0, 250], (1, 0, 250), np.array([1, 0, 250], dtype=np.uint64),
              np.array([1, 0, 250], dtype=">i8")):
        assert rmapgen.metrics(a, b, 255) == want
    for bad, err, msg in (
        (np.array([1.0, 0, 250]), TypeError, r"^b: dtype float64 is not an integer dtype"),
        (np.array([1, 0, 250], dtype=np.complex64), TypeError, r"^b: dtype complex64"),
        (np.array([True, False, True]), TypeError, r"^b: dtype bool"),
        (np.array(["1", "0", "250"]), TypeError, r"^b: dtype <U3"),
        ([1, 0, 250.0], TypeError, r"^b\[2\] = 250.0 is a float, not an integer$"),
        ([1, 0, float("nan")], TypeError, r"^b\[2\] = nan is a float"),
        ([1, 0, 256], ValueError, r"^b\[2\] = 256 is outside 0..=255 \(output values, peak = 255\)$"),
        # This one made a 32 GB histogram and aborted the interpreter.
        ([1, 0, 2**32 - 1], ValueError, r"^b\[2\] = 4294967295 is outside 0..=255"),
        (np.array([1, 0, 2**64 - 1], dtype=np.uint64), ValueError, r"^b\[2\] = 18446744073709551615 "),
        ([[1, 0, 250]], ValueError, r"^b: expected a 1-D array, got shape \(1, 3\)$"),
    ):
        with pytest.raises(err, match=msg):
            rmapgen.metrics(a, bad, 255)
    # peak is a design's, 1..=2^12 - 1: it bounds the histogram.
    assert rmapgen.metrics([4095], [0], 4095)["max_abs_error"] == 4095
    for peak in (0, 4096, 2**32, -1):
        with pytest.raises(ValueError, match=rf"^peak = {peak} is outside 1..=4095"):
            rmapgen.metrics([0], [0], peak)
    with pytest.raises(TypeError, match="^peak: expected an int, got a bool$"):
        rmapgen.metrics([0], [0], True)
    with pytest.raises(TypeError):
        rmapgen.metrics([0], [0], 255.0)


def test_scene_shade_reads_real_normals_exactly():
    s = rmapgen.Scene.standard()
    want = s.shade(np.array([[0.0, 0.0, 1.0], [1.0, 2.0, 3.0]]))
    for n in ([[0, 0, 1], [1, 2, 3]], np.array([[0, 0, 1], [1, 2, 3]], dtype=np.int16),
              np.array([[0, 0, 1], [1, 2, 3]], dtype=np.float32), [[0.0, 0, 1], (1, 2.0, 3)]):
        assert np.array_equal(s.shade(n), want)
    for n, err, msg in (
        (np.array([[True, False, True]]), TypeError, r"^normals: dtype bool is not a real dtype"),
        (np.array([[1j, 0, 1]]), TypeError, r"^normals: dtype complex128 is not a real dtype"),
        (np.array([[1, 0, 1]], dtype=np.longdouble), TypeError, r"^normals: dtype float128 is wider "
         r"than float64"),
        ([[0, 0, "1"]], TypeError, r"^normals\[0, 2\] = '1' is a str, not a real number$"),
        ([[0, 0, True]], TypeError, r"^normals\[0, 2\] = True is a bool, not a real number$"),
        ([[2**53 + 1, 0, 1]], ValueError, r"^normals\[0, 0\] = 9007199254740993 is outside "
         r"-9007199254740992..=9007199254740992 \(the integers a float64 holds exactly\)$"),
        ([[0, 0, 0]], ValueError, r"^normals\[0\] = \(0, 0, 0\) has no direction"),
        ([[0, float("nan"), 1]], ValueError, r"^normals\[0\] = \(0, NaN, 1\) has no direction"),
    ):
        with pytest.raises(err, match=msg):
            s.shade(n)


# ---- Memory: a view of 2^61 rows takes no memory; reading it needs 2^61 * 3 values, more than
# the address space, so the reservation fails at once whatever the machine's overcommit.
HUGE = np.broadcast_to(np.zeros((1, 3), dtype=np.int8), (2**61, 3))


@TAKERS
def test_a_buffer_larger_than_memory_is_a_memory_error(take):
    if take is GRADIENT_TAKERS["trace"]:
        # The trace's bound comes first: nothing is converted.
        with pytest.raises(ValueError, match=rf"^g: at most {rmapgen.TRACE_MAX} samples a call, "
                           rf"got {2**61}$"):
            take(D12, HUGE)
        return
    with pytest.raises(MemoryError, match=rf"^no memory for g: {3 * 2**61} values of 4 bytes$"):
        take(D12, HUGE)


def test_the_other_arguments_larger_than_memory_are_memory_errors():
    with pytest.raises(MemoryError, match="^no memory for normals"):
        rmapgen.quantize(HUGE, D12.config)
    with pytest.raises(MemoryError, match="^no memory for normals"):
        rmapgen.Scene.standard().shade(HUGE)
    with pytest.raises(MemoryError, match="^no memory for a"):
        rmapgen.metrics(HUGE[:, 0], HUGE[:, 1], 255)


def run_short_of_memory(setup, call, spare_mb):
    """Runs `call` in a fresh interpreter whose address space is limited to what it uses after
    `setup` plus `spare_mb`: the output's allocation is what fails. Returns its stdout; the
    interpreter must end normally (an abort is exit 134)."""
    code = textwrap.dedent(f"""
        import resource, numpy as np, rmapgen
        {setup}
        vm = int(open("/proc/self/status").read().split("VmSize:")[1].split()[0]) * 1024
        resource.setrlimit(resource.RLIMIT_AS, (vm + {spare_mb} * 2**20, resource.RLIM_INFINITY))
        try:
            {call}
            print("no error")
        except MemoryError as e:
            print("MemoryError:", e)
    """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, f"exit {r.returncode}: {r.stderr[-2000:]}"
    return r.stdout.strip()


# Each case: the set-up (a design and an input that exist before the limit), the call whose
# output does not fit, and what it could not allocate.
SHORT = {
    # The input (2^24 gradients, int32, 192 MB) read in place; the output needs 32 MB.
    "shade": ("d = rmapgen.Design(); g = np.ones((2**24, 3), dtype=np.int32); d.shade(g[:10])",
              "d.shade(g)", "the intensities"),
    "reference": ("d = rmapgen.Design(); g = np.ones((2**24, 3), dtype=np.int32); "
                  "d.reference(g[:10])", "d.reference(g)", "the reference"),
    "exact": ("d = rmapgen.Design(); g = np.ones((2**23, 3), dtype=np.int32); d.exact(g[:10])",
              "d.exact(g)", "the exact intensities"),
    # 60-odd signals of 2^20 samples, 4 MB each: the columns stop at the limit.
    "trace": ("d = rmapgen.Design(); g = np.ones((2**20, 3), dtype=np.int32); d.trace(g[:10])",
              "d.trace(g)", "a traced signal"),
    # 2^23 float normals: reading them needs 192 MB.
    "quantize": ("c = rmapgen.Config(); n = np.ones((2**23, 3)); rmapgen.quantize(n[:10], c)",
                 "rmapgen.quantize(n, c)", "normals"),
    # The largest sphere, 8192^2 pixels: 805 MB of gradients.
    "sphere": ("c = rmapgen.Config(); rmapgen.sphere(c, 16)", "rmapgen.sphere(c, 8192)",
               "the sphere's gradients"),
}


@pytest.mark.parametrize("case", SHORT.values(), ids=SHORT.keys())
def test_an_output_larger_than_memory_is_a_memory_error_not_an_abort(case):
    setup, call, what = case
    out = run_short_of_memory(setup, call, spare_mb=16)
    assert out.startswith(f"MemoryError: no memory for {what}"), out


def test_quantizes_output_larger_than_memory_is_a_memory_error():
    # 2^22 normals: reading them takes 96 MB of the 120 spare, the gradients need 48 MB more.
    out = run_short_of_memory(
        "c = rmapgen.Config(); n = np.ones((2**22, 3)); rmapgen.quantize(n[:10], c)",
        "rmapgen.quantize(n, c)", spare_mb=120)
    assert out.startswith("MemoryError: no memory for the gradients"), out
