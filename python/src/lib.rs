//! `rmapgen._rmapgen`: rmapgen's bit-accurate model over numpy arrays (docs/PYTHON.md).
//!
//! Every value here comes from the `rmapgen` crate the command line is built from: the
//! configuration and scene are parsed and validated by the same code as their TOML files, the
//! ROMs and maps are the ones `generate` writes, `shade` is the fast path `render` and `bench`
//! run, `trace` is [`rmapgen::stages::path`] (the ports the per-stage vectors check), and the
//! reference and metrics are `render`'s. This file only converts between Python and Rust;
//! `arrays` reads every array argument exactly or refuses it.

mod arrays;

use arrays::{append, buffer, Arg, IntArg, Ints};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::{PyAttributeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString};
use rayon::prelude::*;
use rmapgen::config::Config as RConfig;
use rmapgen::model::fast::FastShader;
use rmapgen::model::map_fit::MapFit;
use rmapgen::model::{MapSet, Maps, Model};
use rmapgen::reference::Reference;
use rmapgen::scene::Scene as RScene;
use std::path::PathBuf;

/// Most samples one `trace` call takes: it keeps every signal of every sample (about 60
/// 32-bit values each), so 2^20 samples are about 250 MB.
const TRACE_MAX: usize = 1 << 20;
/// Largest side of `sphere`'s image (the command line's `render --size` bound).
const SPHERE_MAX: u32 = 8192;

/// One line, as the command line prints it: rmapgen's own message, then its causes.
fn value_error(e: anyhow::Error) -> PyErr {
    PyValueError::new_err(rmapgen::toml_input::one_line(&format!("{e:#}")))
}

/// A TOML value from a Python keyword argument: bool, int or str (bool first: it is an int).
fn toml_value(key: &str, v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        Ok(toml::Value::Boolean(v.extract()?))
    } else if v.is_instance_of::<PyInt>() {
        let i: i64 = v
            .extract()
            .map_err(|_| PyValueError::new_err(format!("{key} = {v} is out of range")))?;
        Ok(toml::Value::Integer(i))
    } else if v.is_instance_of::<PyString>() {
        Ok(toml::Value::String(v.extract()?))
    } else {
        Err(PyTypeError::new_err(format!(
            "{key}: expected a bool, an int or a str, got {}",
            v.get_type().name()?
        )))
    }
}

/// A Python value from JSON (the figures of `metrics`).
fn from_json<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        serde_json::Value::Null => py.None().into_bound(py),
        serde_json::Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        serde_json::Value::Number(n) => match n.as_u64() {
            Some(u) => u.into_pyobject(py)?.into_any(),
            None => PyFloat::new(py, n.as_f64().unwrap_or(f64::NAN)).into_any(),
        },
        serde_json::Value::String(s) => PyString::new(py, s).into_any(),
        serde_json::Value::Array(a) => {
            let items = a
                .iter()
                .map(|x| from_json(py, x))
                .collect::<PyResult<Vec<_>>>()?;
            PyList::new(py, items)?.into_any()
        }
        serde_json::Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, from_json(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// A Python value from TOML (the fields of a configuration).
fn from_toml<'py>(py: Python<'py>, v: &toml::Value) -> PyResult<Bound<'py, PyAny>> {
    let json = serde_json::to_value(v).map_err(|e| value_error(e.into()))?;
    from_json(py, &json)
}

/// A design's configuration: the fields and the checks of `config.toml`
/// (`Config(grad_bits=8, red_bits=6)`; every field left out has its default, the paper's
/// design). A bad field raises ValueError with the command line's message.
#[pyclass(module = "rmapgen", frozen)]
#[derive(Clone)]
struct Config {
    inner: RConfig,
}

impl Config {
    fn fields(&self) -> toml::Table {
        toml::Table::try_from(&self.inner).expect("a Config serialises")
    }

    fn from_text(text: &str, what: &str) -> PyResult<Config> {
        RConfig::from_toml_named(text, what)
            .map(|inner| Config { inner })
            .map_err(value_error)
    }

    fn from_kwargs(base: toml::Table, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Config> {
        let mut t = base;
        if let Some(kw) = kwargs {
            for (k, v) in kw.iter() {
                let k: String = k.extract()?;
                let v = toml_value(&k, &v)?;
                t.insert(k, v);
            }
        }
        let text = toml::to_string(&t).map_err(|e| value_error(e.into()))?;
        // The message names the field; a line of this generated text would mean nothing.
        RConfig::from_toml_named(&text, "Config")
            .map(|inner| Config { inner })
            .map_err(|e| {
                let msg = format!("{e:#}");
                let msg = rmapgen::toml_input::without_place(&msg, "Config");
                PyValueError::new_err(rmapgen::toml_input::one_line(&msg))
            })
    }
}

#[pymethods]
impl Config {
    #[new]
    #[pyo3(signature = (**fields))]
    fn new(fields: Option<&Bound<'_, PyDict>>) -> PyResult<Config> {
        Config::from_kwargs(toml::Table::new(), fields)
    }

    /// A configuration from the text of a `config.toml`.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Config> {
        Config::from_text(text, "config")
    }

    /// A configuration read from a `config.toml` file (a design's `tb/config.toml` too).
    #[staticmethod]
    fn read(path: PathBuf) -> PyResult<Config> {
        RConfig::from_toml_file(&path)
            .map(|inner| Config { inner })
            .map_err(value_error)
    }

    /// This configuration with some fields changed (`cfg.replace(index_bits=4)`).
    #[pyo3(signature = (**fields))]
    fn replace(&self, fields: Option<&Bound<'_, PyDict>>) -> PyResult<Config> {
        Config::from_kwargs(self.fields(), fields)
    }

    /// The TOML `rmapgen generate --config` reads.
    fn to_toml(&self) -> String {
        toml::to_string(&self.inner).expect("a Config serialises")
    }

    /// Every field that differs from its default, as `to_toml` writes it, in a dict.
    fn as_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in self.fields() {
            d.set_item(k, from_toml(py, &v)?)?;
        }
        Ok(d)
    }

    /// A field by name (`cfg.grad_bits`): a width, or a field `to_toml` writes.
    fn __getattr__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        if let Some(v) = self.fields().get(name) {
            return from_toml(py, v);
        }
        if rmapgen::config::RANGES.iter().any(|r| r.0 == name) {
            return Ok(self.inner.field(name).into_pyobject(py)?.into_any());
        }
        Err(PyAttributeError::new_err(format!(
            "Config has no field {name} set (a field at its default is left out of the TOML, \
             the widths excepted; see as_dict)"
        )))
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Config>()
            .map(|o| o.get().inner == self.inner)
            .unwrap_or(false)
    }

    fn __repr__(&self) -> String {
        // In the file's order, as `to_toml` writes them.
        let fields: Vec<String> = self
            .to_toml()
            .lines()
            .filter_map(|l| l.split_once(" = "))
            .map(|(k, v)| {
                let v: toml::Value = toml::from_str(&format!("v = {v}"))
                    .map(|t: toml::Table| t["v"].clone())
                    .expect("a value to_toml wrote");
                format!("{k}={}", py_literal(&v))
            })
            .collect();
        format!("Config({})", fields.join(", "))
    }
}

/// A TOML scalar as a Python literal.
fn py_literal(v: &toml::Value) -> String {
    match v {
        toml::Value::Boolean(b) => if *b { "True" } else { "False" }.to_string(),
        toml::Value::String(s) => format!("{s:?}"),
        other => other.to_string(),
    }
}

/// A scene: material, lights, view and how the host fills the maps (`map_fit`), from the
/// TOML files of `scenes/` (`Scene.read("scenes/grazing.toml")`) or `Scene.standard()`.
#[pyclass(module = "rmapgen", frozen)]
#[derive(Clone)]
struct Scene {
    inner: RScene,
}

#[pymethods]
impl Scene {
    /// The standard scene of the README and the tests (`scenes/standard.toml`).
    #[staticmethod]
    fn standard() -> Scene {
        Scene {
            inner: RScene::standard(),
        }
    }

    /// A scene from the text of a scene file.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Scene> {
        RScene::from_toml_named(text, "scene")
            .map(|inner| Scene { inner })
            .map_err(value_error)
    }

    /// A scene read from a file.
    #[staticmethod]
    fn read(path: PathBuf) -> PyResult<Scene> {
        RScene::from_toml_file(&path)
            .map(|inner| Scene { inner })
            .map_err(value_error)
    }

    /// How the host fills the maps: `sample`, `lsq`, `lsq-plain`, `minimax` or `table`.
    #[getter]
    fn map_fit(&self) -> &'static str {
        self.inner.map_fit.name()
    }

    /// This scene with another map fit (`--map-fit` of the commands).
    fn with_map_fit(&self, map_fit: &str) -> PyResult<Scene> {
        let fit: MapFit = serde_json::from_value(map_fit.into()).map_err(|_| {
            PyValueError::new_err(format!(
                "map_fit {map_fit:?} is not one of sample, lsq, lsq-plain, minimax, table"
            ))
        })?;
        let mut inner = self.inner.clone();
        inner.map_fit = fit;
        Ok(Scene { inner })
    }

    /// The scene file's text.
    fn to_toml(&self) -> String {
        toml::to_string(&self.inner).expect("a Scene serialises")
    }

    /// The float light model at each direction of an (N, 3) real array (normalised here; 1.0
    /// is full scale, before quantising or clamping): the truth every design is measured
    /// against.
    fn shade<'py>(&self, normals: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let py = normals.py();
        let flat = arrays::reals(normals, normals_arg())?;
        let (rows, _) = flat.as_chunks::<3>();
        let p = self.inner.prepared();
        let mut out = buffer(rows.len(), "the intensities")?;
        for (k, row) in rows.iter().enumerate() {
            let u = rmapgen::geometry::unit_direction(glam::DVec3::from_array(*row))
                .ok_or_else(|| no_direction(k, row))?;
            out.push(p.shade(u));
        }
        Ok(out.into_pyarray(py))
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene({} lights, map_fit={:?})",
            self.inner.lights.len(),
            self.inner.map_fit.name()
        )
    }
}

/// Float normals, an (N, 3) real array (Scene.shade, quantize).
fn normals_arg() -> Arg<'static> {
    Arg {
        name: "normals",
        cols: Some(3),
        max_rows: usize::MAX,
    }
}

/// The ValueError of a normal that has no direction.
fn no_direction(k: usize, row: &[f64; 3]) -> PyErr {
    PyValueError::new_err(format!(
        "normals[{k}] = ({}, {}, {}) has no direction (zero, NaN or infinite)",
        row[0], row[1], row[2]
    ))
}

/// What the TypeError of a gradient that is not an integer suggests.
const QUANTIZE_HINT: &str = "rmapgen.quantize(normals, config) turns float normals into gradients";

/// A design: its configuration, its scene, every ROM and map `generate` would write, and the
/// model that shades with them. Building it fits the maps as the scene's `map_fit` says.
#[pyclass(module = "rmapgen", frozen)]
struct Design {
    config: Config,
    scene: Scene,
    model: Model,
    maps: MapSet,
    shader: FastShader,
    reference: Reference,
}

impl Design {
    /// The gradients of an (N, 3) integer array (at most `max_rows`), each component in the
    /// configuration's range; an int32 C-contiguous array is read in place.
    fn gradients<'py>(&self, g: &Bound<'py, PyAny>, max_rows: usize) -> PyResult<Grads<'py>> {
        let cfg = &self.config.inner;
        let r = cfg.grad_range();
        let spec = IntArg {
            arg: Arg {
                name: "g",
                cols: Some(3),
                max_rows,
            },
            range: *r.start() as i64..=*r.end() as i64,
            why: format!("grad_bits = {}", cfg.grad_bits),
            hint: QUANTIZE_HINT,
        };
        Ok(Grads(arrays::ints(g, &spec)?))
    }

    /// The gradients of `g` for the float reference: none may be zero, which has no direction.
    fn directions<'py>(&self, g: &Bound<'py, PyAny>) -> PyResult<Grads<'py>> {
        let grads = self.gradients(g, usize::MAX)?;
        let gs = grads.as_grads();
        let zero = g
            .py()
            .detach(|| gs.par_iter().position_first(|g| *g == [0, 0, 0]));
        if let Some(k) = zero {
            return Err(PyValueError::new_err(format!(
                "g[{k}] = (0, 0, 0) has no direction, so no reference (shade gives it 0, the \
                 hardware's zero case); leave zero gradients out first: \
                 g[np.any(g != 0, axis=1)]"
            )));
        }
        Ok(grads)
    }
}

/// An (N, 3) integer argument's values, read as N gradients.
struct Grads<'py>(Ints<'py>);

impl Grads<'_> {
    fn as_grads(&self) -> &[[i32; 3]] {
        let (rows, rest) = self.0.as_slice().as_chunks::<3>();
        debug_assert!(rest.is_empty(), "an (N, 3) array");
        rows
    }
}

#[pymethods]
impl Design {
    #[new]
    #[pyo3(signature = (config=None, scene=None))]
    fn new(
        py: Python<'_>,
        config: Option<PyRef<'_, Config>>,
        scene: Option<PyRef<'_, Scene>>,
    ) -> PyResult<Design> {
        let config = config.map(|c| c.clone()).unwrap_or(Config {
            inner: RConfig::default(),
        });
        let scene = scene.map(|s| s.clone()).unwrap_or_else(Scene::standard);
        let cfg = config.inner.clone();
        let sc = scene.inner.clone();
        sc.map_fit.check(&cfg).map_err(value_error)?;
        let (model, maps, shader, reference) = py.detach(move || {
            let model = Model::new(&cfg);
            let maps: Maps = sc.maps(&cfg);
            let shader = FastShader::new(&model, &maps);
            let reference = Reference::new(&cfg, &sc);
            (model, maps, shader, reference)
        });
        Ok(Design {
            config,
            scene,
            model,
            maps: MapSet {
                second: maps.clone(),
                scene: maps,
            },
            shader,
            reference,
        })
    }

    #[getter]
    fn config(&self) -> Config {
        self.config.clone()
    }

    #[getter]
    fn scene(&self) -> Scene {
        self.scene.clone()
    }

    /// The reciprocal ROM (`recip_rom.hex`), entry by entry.
    #[getter]
    fn recip_rom<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.model.recip.clone().into_pyarray(py)
    }

    /// The compensation (atan) ROM (`atan_rom.hex`), or None without compensation.
    #[getter]
    fn comp_rom<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<u32>>> {
        self.model.atan.clone().map(|r| r.into_pyarray(py))
    }

    /// The compensation table the host loads with the maps (`comp_table = "ram"`), or None.
    #[getter]
    fn comp_table<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<u32>>> {
        self.maps.scene.table.clone().map(|t| t.into_pyarray(py))
    }

    /// The three maps (`map_x.hex`, `map_y.hex`, `map_z.hex`) as a (3, entries) array.
    #[getter]
    fn maps<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let m = &self.maps.scene;
        let rows: Vec<Vec<u32>> = (0..3).map(|a| m.axis(a).to_vec()).collect();
        PyArray2::from_vec2(py, &rows).map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// The design's intensity for each gradient of an (N, 3) integer array, bit for bit the
    /// hardware's (0 for the zero gradient): the fast path of `render` and `bench`, on every
    /// core, with the interpreter released.
    fn shade<'py>(&self, g: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<u16>>> {
        let py = g.py();
        let grads = self.gradients(g, usize::MAX)?;
        let gs = grads.as_grads();
        let mut out = buffer(gs.len(), "the intensities")?;
        out.resize(gs.len(), 0u16);
        let shader = &self.shader;
        py.detach(|| shader.shade_batch_par(gs, &mut out));
        Ok(out.into_pyarray(py))
    }

    /// Each sample's path through the design (at most 2^20 samples): a dict from Verilog
    /// signal name (`u_sort_shift.m_o`, a stage's port in the top; the top's own ports by
    /// name) to an array of the bits it carries, in pipeline order. `rgb` ((N, 3), 0..255) is
    /// the colour of a `color` design.
    #[pyo3(signature = (g, rgb=None))]
    fn trace<'py>(
        &self,
        g: &Bound<'py, PyAny>,
        rgb: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let py = g.py();
        let grads = self.gradients(g, TRACE_MAX)?;
        let gs = grads.as_grads();
        let colours = match rgb {
            None => None,
            Some(c) => {
                let spec = IntArg {
                    arg: Arg {
                        name: "rgb",
                        cols: Some(3),
                        max_rows: TRACE_MAX,
                    },
                    range: 0..=COLOUR_MAX,
                    why: "8 bits a channel".into(),
                    hint: "",
                };
                let c = arrays::ints(c, &spec)?;
                let (rows, _) = c.as_slice().as_chunks::<3>();
                if rows.len() != gs.len() {
                    return Err(PyValueError::new_err(format!(
                        "rgb has {} rows for {} gradients",
                        rows.len(),
                        gs.len()
                    )));
                }
                Some(c)
            }
        };
        let cs = colours.as_ref().map(|c| c.as_slice());
        let colour = |k: usize| match cs {
            None => [0; 3],
            Some(c) => [c[3 * k] as u32, c[3 * k + 1] as u32, c[3 * k + 2] as u32],
        };
        let (model, maps) = (&self.model, &self.maps);
        let names = rmapgen::stages::path(model, maps, 0, [0; 3], [0; 3]);
        // One column per signal, every one reserved before any is filled.
        let mut columns: Vec<Vec<u32>> = buffer(names.len(), "the trace's signals")?;
        for _ in &names {
            let mut col = buffer(gs.len(), "a traced signal")?;
            col.resize(gs.len(), 0);
            columns.push(col);
        }
        // In blocks of samples, each block with its part of every column.
        const BLOCK: usize = 4096;
        let mut blocks: Vec<Vec<&mut [u32]>> =
            (0..gs.len().div_ceil(BLOCK)).map(|_| Vec::new()).collect();
        for col in &mut columns {
            for (b, part) in blocks.iter_mut().zip(col.chunks_mut(BLOCK)) {
                b.push(part);
            }
        }
        py.detach(|| {
            blocks
                .into_par_iter()
                .enumerate()
                .for_each(|(b, mut cols)| {
                    for k in b * BLOCK..((b + 1) * BLOCK).min(gs.len()) {
                        let path = rmapgen::stages::path(model, maps, 0, gs[k], colour(k));
                        for (col, s) in cols.iter_mut().zip(path) {
                            col[k - b * BLOCK] = s.value as u32;
                        }
                    }
                })
        });
        let d = PyDict::new(py);
        for (s, col) in names.iter().zip(columns) {
            debug_assert!(s.bits <= 32, "{} is {} bits", s.name, s.bits);
            d.set_item(&s.name, col.into_pyarray(py))?;
        }
        Ok(d)
    }

    /// The float reference (the scene's light model at each gradient's exact direction),
    /// quantised to the output's width as `render`'s reference image: the truth. The zero
    /// gradient has no direction and is refused.
    fn reference<'py>(&self, g: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<u16>>> {
        let py = g.py();
        let grads = self.directions(g)?;
        let gs = grads.as_grads();
        let mut out = buffer(gs.len(), "the reference")?;
        out.resize(gs.len(), 0u16);
        let r = &self.reference;
        py.detach(|| {
            out.par_iter_mut()
                .zip(gs)
                .for_each(|(o, &g)| *o = r.intensity(g) as u16)
        });
        Ok(out.into_pyarray(py))
    }

    /// The light model before quantising (1.0 is full scale); the zero gradient is refused.
    fn exact<'py>(&self, g: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let py = g.py();
        let grads = self.directions(g)?;
        let gs = grads.as_grads();
        let mut out = buffer(gs.len(), "the exact intensities")?;
        out.resize(gs.len(), 0.0);
        let r = &self.reference;
        py.detach(|| {
            out.par_iter_mut().zip(gs).for_each(|(o, &g)| {
                *o = r.exact(g).expect("no zero gradient (directions)");
            })
        });
        Ok(out.into_pyarray(py))
    }

    /// The largest output value, 2^map_bits - 1 (the peak of `metrics`' PSNR).
    #[getter]
    fn peak(&self) -> u32 {
        self.config.inner.map_max()
    }

    fn __repr__(&self) -> String {
        format!(
            "Design({}, {})",
            self.config.__repr__(),
            self.scene.__repr__()
        )
    }
}

/// The largest output value a channel of colour takes (`trace`'s `rgb`).
const COLOUR_MAX: i64 = 255;

/// The largest `peak` of `metrics`: the largest design's, 2^map_bits - 1 at the widest
/// map_bits.
fn peak_max() -> u32 {
    let (_, widest) = rmapgen::config::range_of("map_bits").expect("map_bits has a range");
    (1 << widest) - 1
}

/// A 1-D array of output values (any integer dtype), each in 0..=peak.
fn samples(x: &Bound<'_, PyAny>, name: &str, peak: u32) -> PyResult<Vec<u32>> {
    let spec = IntArg {
        arg: Arg {
            name,
            cols: None,
            max_rows: usize::MAX,
        },
        range: 0..=peak as i64,
        why: format!("output values, peak = {peak}"),
        hint: "",
    };
    let v = arrays::ints(x, &spec)?;
    let v = v.as_slice();
    let mut out = buffer(v.len(), name)?;
    append(&mut out, v.iter().map(|&x| x as u32));
    Ok(out)
}

/// Error figures of `a` (the design) against `b` (the reference), in output LSBs, as
/// `render`'s metrics.json: max_abs_error, mean_abs_error, mean_error, rmse, psnr_db, the
/// histogram of absolute errors and the first worst sample. Every value is an output value,
/// 0..=peak; no samples is refused (there is nothing to measure).
#[pyfunction]
fn metrics<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    peak: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let most = peak_max();
    if peak.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err("peak: expected an int, got a bool"));
    }
    let peak: i64 = peak.extract()?;
    let peak = u32::try_from(peak)
        .ok()
        .filter(|p| (1..=most).contains(p))
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "peak = {peak} is outside 1..={most} (2^map_bits - 1, map_bits up to \
                 {})",
                most.ilog2() + 1
            ))
        })?;
    let (a, b) = (samples(a, "a", peak)?, samples(b, "b", peak)?);
    if a.len() != b.len() {
        return Err(PyValueError::new_err(format!(
            "metrics of {} and {} samples",
            a.len(),
            b.len()
        )));
    }
    if a.is_empty() {
        return Err(PyValueError::new_err(
            "metrics of no samples: there is nothing to measure",
        ));
    }
    let m = rmapgen::render::metrics::metrics(&a, &b, peak);
    from_json(py, &serde_json::to_value(m).expect("metrics serialise"))
}

/// Float normals (an (N, 3) real array, unit or not) as the design's gradients, at full scale:
/// each row divided by its largest |component|, times 2^(G-1) - 1, rounded to the nearest
/// integer, halves away from zero (`rmapgen::geometry::full_scale_gradient`). A row that is
/// zero, NaN or infinite has no direction and is refused.
#[pyfunction]
fn quantize<'py>(
    normals: &Bound<'py, PyAny>,
    config: PyRef<'py, Config>,
) -> PyResult<Bound<'py, PyArray2<i32>>> {
    let py = normals.py();
    let flat = arrays::reals(normals, normals_arg())?;
    let (rows, _) = flat.as_chunks::<3>();
    let cfg = &config.inner;
    let mut out = buffer(3 * rows.len(), "the gradients")?;
    for (k, row) in rows.iter().enumerate() {
        let g = rmapgen::geometry::full_scale_gradient(cfg, glam::DVec3::from_array(*row))
            .ok_or_else(|| no_direction(k, row))?;
        append(&mut out, g);
    }
    let g = Array2::from_shape_vec((rows.len(), 3), out).expect("three per row");
    Ok(g.into_pyarray(py))
}

/// The sphere test image of `render` (the paper's Figures 4-7): every inside pixel of a
/// size x size image, as ((N, 3) int32 gradients, (N, 2) uint32 columns and rows), raster
/// order. `shrink` halves the gradients that many times (`render --shrink`).
#[pyfunction]
#[pyo3(signature = (config, size, shrink=0))]
fn sphere<'py>(
    py: Python<'py>,
    config: PyRef<'py, Config>,
    size: u32,
    shrink: u32,
) -> PyResult<(Bound<'py, PyArray2<i32>>, Bound<'py, PyArray2<u32>>)> {
    let cfg = &config.inner;
    if !(1..=SPHERE_MAX).contains(&size) {
        return Err(PyValueError::new_err(format!(
            "size {size} is outside 1..={SPHERE_MAX}"
        )));
    }
    let max = rmapgen::render::sphere::max_shrink(cfg);
    if shrink > max {
        return Err(PyValueError::new_err(format!(
            "shrink {shrink} exceeds {max} (grad_bits - 1)"
        )));
    }
    // Room for every pixel of the image (about 4/π the inside ones), before any is made.
    let most = size as usize * size as usize;
    let mut g = buffer(3 * most, "the sphere's gradients")?;
    let mut xy = buffer(2 * most, "the sphere's pixels")?;
    for (x, y, grad) in rmapgen::render::sphere::pixels(cfg, size, shrink) {
        append(&mut g, grad);
        append(&mut xy, [x, y]);
    }
    let n = xy.len() / 2;
    let g = Array2::from_shape_vec((n, 3), g).expect("three per pixel");
    let xy = Array2::from_shape_vec((n, 2), xy).expect("two per pixel");
    Ok((g.into_pyarray(py), xy.into_pyarray(py)))
}

/// The benchmark's yardstick (python/bench_shade.py, `make python-bench`): the best of
/// `repeats` wall times, in seconds, of the Rust fast path alone on these gradients (what
/// `Design.shade` calls, without the conversions from Python or the array it returns).
#[pyfunction]
fn _fast_path_seconds(
    design: PyRef<'_, Design>,
    g: &Bound<'_, PyAny>,
    repeats: u32,
) -> PyResult<f64> {
    let py = g.py();
    let grads = design.gradients(g, usize::MAX)?;
    let gs = grads.as_grads();
    let shader = &design.shader;
    let mut out = buffer(gs.len(), "the intensities")?;
    out.resize(gs.len(), 0u16);
    Ok(py.detach(|| {
        (0..repeats.max(1))
            .map(|_| {
                let t = std::time::Instant::now();
                shader.shade_batch_par(gs, &mut out);
                std::hint::black_box(&out);
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    }))
}

#[pymodule]
fn _rmapgen(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Config>()?;
    m.add_class::<Scene>()?;
    m.add_class::<Design>()?;
    m.add_function(wrap_pyfunction!(metrics, m)?)?;
    m.add_function(wrap_pyfunction!(quantize, m)?)?;
    m.add_function(wrap_pyfunction!(sphere, m)?)?;
    m.add_function(wrap_pyfunction!(_fast_path_seconds, m)?)?;
    m.add("TRACE_MAX", TRACE_MAX)?;
    Ok(())
}
