//! Arrays between Python and Rust: every array argument is read exactly or refused, and every
//! buffer is reserved before it is filled (docs/PYTHON.md, "What the package refuses").
//!
//! - An integer argument (gradients, colours, output values) takes a numpy array of an integer
//!   dtype (signed or unsigned, any width, either byte order, any strides), or a list or tuple
//!   of ints (Python's or numpy's). Each value is checked against the argument's range in its
//!   own type before it is narrowed: a uint64 2^64 - 1 is that number, never -1. Any other
//!   dtype (bool, float, complex, str, bytes, datetime, structured, object holding anything but
//!   ints) is a TypeError that names it; nothing is cast.
//! - A real argument (float normals) takes float16, float32 and float64, and integers that a
//!   float64 holds exactly (|v| <= 2^53); bool, complex, wider floats and the rest are refused
//!   the same way.
//! - A buffer too large for memory is a MemoryError (`try_reserve_exact`), not an abort; a
//!   row count past an argument's bound is refused before anything is converted.

use numpy::{
    PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyMemoryError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat, PyInt, PyList, PyTuple};
use rayon::prelude::*;
use std::fmt::Display;
use std::ops::RangeInclusive;

/// The largest integer below which every integer is a float64 exactly, 2^53.
const EXACT_IN_F64: i64 = 1 << 53;

/// An empty vector with room for `n` values, or MemoryError (`what` names them).
pub fn buffer<T>(n: usize, what: &str) -> PyResult<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| {
        PyMemoryError::new_err(format!(
            "no memory for {what}: {n} values of {} bytes",
            std::mem::size_of::<T>()
        ))
    })?;
    Ok(v)
}

/// Appends `items` to a buffer from [`buffer`] without growing it: a value past its reservation
/// is a bug here (a panic), never a second, infallible allocation that could abort.
pub fn append<T>(v: &mut Vec<T>, items: impl IntoIterator<Item = T>) {
    for x in items {
        assert!(v.len() < v.capacity(), "more values than reserved");
        v.push(x);
    }
}

/// An array argument: its name in messages and its shape.
pub struct Arg<'a> {
    /// `g`, `rgb`, `a`, `normals`.
    pub name: &'a str,
    /// Values per row: `Some(3)` for an (N, 3) array, `None` for a 1-D one.
    pub cols: Option<usize>,
    /// Most rows one call takes, refused before anything is converted.
    pub max_rows: usize,
}

/// An integer argument: the array, the range of its values and what to say about them.
pub struct IntArg<'a> {
    pub arg: Arg<'a>,
    /// Every value's range; it fits an i32.
    pub range: RangeInclusive<i64>,
    /// Where the range comes from, after it in a message (`grad_bits = 8`).
    pub why: String,
    /// After the TypeError of a value that is not an integer: what to use instead.
    pub hint: &'a str,
}

/// An integer argument's values, row-major: read in place (an int32 C-contiguous array) or
/// copied and narrowed.
pub enum Ints<'py> {
    InPlace(PyReadonlyArrayDyn<'py, i32>),
    Owned(Vec<i32>),
}

impl Ints<'_> {
    pub fn as_slice(&self) -> &[i32] {
        match self {
            Ints::InPlace(a) => a.as_slice().expect("read in place only when C-contiguous"),
            Ints::Owned(v) => v,
        }
    }
}

/// The values of an integer argument, checked against its range (the first value outside it
/// is a ValueError naming its index, its value and the range) and narrowed to i32.
pub fn ints<'py>(x: &Bound<'py, PyAny>, spec: &IntArg<'_>) -> PyResult<Ints<'py>> {
    debug_assert!(
        i32::try_from(*spec.range.start()).is_ok() && i32::try_from(*spec.range.end()).is_ok()
    );
    let a = ndarray(x, &spec.arg)?;
    let dtype = a.dtype();
    if dtype.kind() == b'i' && dtype.itemsize() == 4 && dtype.is_native_byteorder() != Some(false) {
        let t = a
            .cast::<PyArrayDyn<i32>>()?
            .try_readonly()
            .map_err(|e| PyValueError::new_err(format!("{}: {e}", spec.arg.name)))?;
        // C order only: a Fortran-ordered array is contiguous too, column by column.
        if let (true, Ok(flat)) = (t.is_c_contiguous(), t.as_slice()) {
            let (lo, hi) = (*spec.range.start(), *spec.range.end());
            // In parallel, in blocks: the first value out of range, if any.
            let bad = x.py().detach(|| {
                flat.par_chunks(1 << 16)
                    .enumerate()
                    .find_map_first(|(b, c)| {
                        c.iter()
                            .position(|&v| !(lo..=hi).contains(&(v as i64)))
                            .map(|k| b * (1 << 16) + k)
                    })
            });
            return match bad {
                Some(k) => Err(out_of_range(spec, k, flat[k])),
                None => Ok(Ints::InPlace(t)),
            };
        }
    }
    read_numbers(&a, spec, "an integer", |v| v as i32, |_| None).map(Ints::Owned)
}

/// The values of a real argument (N, 3) as float64, row-major, each exactly as given.
pub fn reals(x: &Bound<'_, PyAny>, arg: Arg<'_>) -> PyResult<Vec<f64>> {
    debug_assert_eq!(arg.cols, Some(3));
    let a = ndarray(x, &arg)?;
    let dtype = a.dtype();
    Ok(match dtype.kind() {
        b'f' if dtype.itemsize() <= 8 => {
            // float16 and float32 widen to float64 exactly.
            let np = x.py().import("numpy")?;
            let wide = np.call_method1("asarray", (&a, "float64"))?;
            let t = wide
                .cast::<PyArrayDyn<f64>>()?
                .try_readonly()
                .map_err(|e| PyValueError::new_err(format!("{}: {e}", arg.name)))?;
            let view = t.as_array();
            let mut v = buffer(view.len(), arg.name)?;
            append(&mut v, view.iter().copied());
            v
        }
        b'f' => {
            return Err(PyTypeError::new_err(format!(
                "{}: dtype {} is wider than float64; convert it with .astype(np.float64) if \
                 that is what you mean",
                arg.name,
                dtype.str()?
            )))
        }
        b'i' | b'u' | b'O' => {
            let spec = IntArg {
                arg,
                range: -EXACT_IN_F64..=EXACT_IN_F64,
                why: "the integers a float64 holds exactly".into(),
                hint: "",
            };
            read_numbers(&a, &spec, "a real number", |v| v as f64, Some)?
        }
        _ => return Err(not_of_kind(&arg, &dtype, "a real", "")),
    })
}

/// The argument as a numpy array of its shape: an array as it is, a list or tuple as an array
/// of its Python objects (so that numpy does not choose a dtype: `[[2**63, 0, 0]]` would become
/// float64), anything else as numpy reads it.
fn ndarray<'py>(x: &Bound<'py, PyAny>, arg: &Arg<'_>) -> PyResult<Bound<'py, PyUntypedArray>> {
    let a = match x.cast::<PyUntypedArray>() {
        Ok(a) => a.clone(),
        Err(_) => {
            let np = x.py().import("numpy")?;
            let a = if x.is_instance_of::<PyList>() || x.is_instance_of::<PyTuple>() {
                np.call_method1("asarray", (x, "object"))?
            } else {
                np.call_method1("asarray", (x,))?
            };
            a.cast_into::<PyUntypedArray>()?
        }
    };
    let shape = a.shape();
    let ok = match arg.cols {
        None => shape.len() == 1,
        Some(c) => shape.len() == 2 && shape[1] == c,
    };
    if !ok {
        let want = match arg.cols {
            None => "a 1-D array".to_string(),
            Some(c) => format!("an (N, {c}) array"),
        };
        return Err(PyValueError::new_err(format!(
            "{}: expected {want}, got shape {}",
            arg.name,
            py_shape(shape)
        )));
    }
    if shape[0] > arg.max_rows {
        return Err(PyValueError::new_err(format!(
            "{}: at most {} samples a call, got {}",
            arg.name, arg.max_rows, shape[0]
        )));
    }
    Ok(a)
}

/// A shape as Python prints it: `(3,)`, `(4, 2)`.
fn py_shape(s: &[usize]) -> String {
    match s {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            s.iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The values of an integer-dtype array (`i`, `u`) or an object array, each checked against
/// the range and converted by `conv`; in an object array a float is taken by `float` (None:
/// refused as not `want`). Any other dtype is not an integer dtype.
fn read_numbers<O>(
    a: &Bound<'_, PyUntypedArray>,
    spec: &IntArg<'_>,
    want: &str,
    conv: impl Fn(i64) -> O,
    float: impl Fn(f64) -> Option<O>,
) -> PyResult<Vec<O>> {
    let dtype = a.dtype();
    let a = if dtype.is_native_byteorder() == Some(false) {
        // The same values in this machine's byte order (exact).
        a.call_method1("astype", (dtype.call_method1("newbyteorder", ("=",))?,))?
            .cast_into::<PyUntypedArray>()?
    } else {
        a.clone()
    };
    match (dtype.kind(), dtype.itemsize()) {
        (b'i', 1) => typed::<i8, O>(&a, spec, conv),
        (b'i', 2) => typed::<i16, O>(&a, spec, conv),
        (b'i', 4) => typed::<i32, O>(&a, spec, conv),
        (b'i', 8) => typed::<i64, O>(&a, spec, conv),
        (b'u', 1) => typed::<u8, O>(&a, spec, conv),
        (b'u', 2) => typed::<u16, O>(&a, spec, conv),
        (b'u', 4) => typed::<u32, O>(&a, spec, conv),
        (b'u', 8) => typed::<u64, O>(&a, spec, conv),
        (b'O', _) => objects(&a, spec, want, conv, float),
        _ => Err(not_of_kind(&spec.arg, &dtype, "an integer", spec.hint)),
    }
}

/// The values of an array of one integer type, checked in that type (widened to i128, which
/// holds every one) and converted.
fn typed<T, O>(
    a: &Bound<'_, PyUntypedArray>,
    spec: &IntArg<'_>,
    conv: impl Fn(i64) -> O,
) -> PyResult<Vec<O>>
where
    T: numpy::Element + Copy + Into<i128>,
{
    let t = a
        .cast::<PyArrayDyn<T>>()?
        .try_readonly()
        .map_err(|e| PyValueError::new_err(format!("{}: {e}", spec.arg.name)))?;
    let view = t.as_array();
    let mut out = buffer(view.len(), spec.arg.name)?;
    let (lo, hi) = (*spec.range.start() as i128, *spec.range.end() as i128);
    // The view's own order is row-major whatever the strides.
    for (k, &v) in view.iter().enumerate() {
        let v: i128 = v.into();
        if v < lo || v > hi {
            return Err(out_of_range(spec, k, v));
        }
        out.push(conv(v as i64));
    }
    Ok(out)
}

/// The values of an object array (a list or tuple read by [`ndarray`]): each an int (Python's
/// or numpy's; not a bool), or a float where `float` takes it; anything else is not `want`.
fn objects<O>(
    a: &Bound<'_, PyUntypedArray>,
    spec: &IntArg<'_>,
    want: &str,
    conv: impl Fn(i64) -> O,
    float: impl Fn(f64) -> Option<O>,
) -> PyResult<Vec<O>> {
    let py = a.py();
    let np = py.import("numpy")?;
    let (np_int, np_float) = (np.getattr("integer")?, np.getattr("floating")?);
    let t = a
        .cast::<PyArrayDyn<Py<PyAny>>>()?
        .try_readonly()
        .map_err(|e| PyValueError::new_err(format!("{}: {e}", spec.arg.name)))?;
    let view = t.as_array();
    let mut out = buffer(view.len(), spec.arg.name)?;
    for (k, e) in view.iter().enumerate() {
        let e = e.bind(py);
        let is_int = (e.is_instance_of::<PyInt>() && !e.is_instance_of::<PyBool>())
            || e.is_instance(&np_int)?;
        if is_int {
            // Only an int beyond i64 fails here, and i64 holds every range.
            match e.extract::<i64>() {
                Ok(v) if spec.range.contains(&v) => out.push(conv(v)),
                Ok(v) => return Err(out_of_range(spec, k, v)),
                Err(_) => return Err(out_of_range(spec, k, e.str()?)),
            }
            continue;
        }
        // A Python float (numpy's float64 is one), float32 and float16: a float64 exactly.
        let exact_float = e.is_instance_of::<PyFloat>()
            || (e.is_instance(&np_float)? && e.getattr("itemsize")?.extract::<usize>()? <= 8);
        let taken = if exact_float {
            float(e.extract::<f64>()?)
        } else {
            None
        };
        match taken {
            Some(v) => out.push(v),
            None => {
                let hint = if spec.hint.is_empty() {
                    String::new()
                } else {
                    format!("; {}", spec.hint)
                };
                return Err(PyTypeError::new_err(format!(
                    "{}{} = {} is {}, not {want}{hint}",
                    spec.arg.name,
                    index(spec.arg.cols, k),
                    e.repr()?,
                    a_type(e)?,
                )));
            }
        }
    }
    Ok(out)
}

/// `a float`, `an int`, `a bool_`: the type of a value, with its article.
fn a_type(e: &Bound<'_, PyAny>) -> PyResult<String> {
    let name = e.get_type().name()?.to_string();
    let article = if name.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    };
    Ok(format!("{article} {name}"))
}

/// The TypeError of an array whose dtype is not of the kind the argument takes.
fn not_of_kind(arg: &Arg<'_>, dtype: &dyn Display, kind: &str, hint: &str) -> PyErr {
    let hint = if hint.is_empty() {
        String::new()
    } else {
        format!("; {hint}")
    };
    PyTypeError::new_err(format!(
        "{}: dtype {dtype} is not {kind} dtype; nothing is cast{hint}",
        arg.name
    ))
}

/// `[k]` of a 1-D argument, `[row, column]` of a 2-D one, for the k-th value row-major.
fn index(cols: Option<usize>, k: usize) -> String {
    match cols {
        None => format!("[{k}]"),
        Some(c) => format!("[{}, {}]", k / c, k % c),
    }
}

/// The ValueError of the k-th value (row-major), outside the argument's range.
fn out_of_range(spec: &IntArg<'_>, k: usize, v: impl Display) -> PyErr {
    PyValueError::new_err(format!(
        "{}{} = {v} is outside {}..={} ({})",
        spec.arg.name,
        index(spec.arg.cols, k),
        spec.range.start(),
        spec.range.end(),
        spec.why
    ))
}
