//! Python bindings of ccpp: the `ccpp._ccpp` extension module, re-exported by the `ccpp`
//! package (`python/ccpp/__init__.py`).
//!
//! Every run goes through [`ccpp_io::scenario::Scenario`]: the keyword options of `ccpp.run`
//! become scenario fields, and the scenario validates them once. Errors are raised as
//! `ccpp.CcppError` with the one-line message the command line prints (without its `error: `
//! prefix).

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use ccpp_core::exec::{Execution, PidOptions};
use ccpp_core::grid::{Cell, MapFrame};
use ccpp_core::metrics::{self, Metrics, Sweeper};
use ccpp_core::planner::{KnownMap, Sensor, Step};
use ccpp_core::planners::{PlannerConfig, PlannerKind, CATALOG};
use ccpp_core::rng::SplitMix64;
use ccpp_core::route::{Route, DEFAULT_TOLERANCE_M};
use ccpp_core::sim::{RunOutput, SimConfig, Simulator, StopReason};
use ccpp_core::trace::{Cursor, Entry, Event, Record, Trace};
use ccpp_core::world::{Robot, World};
use ccpp_core::zones::ZoneMasks;
use ccpp_core::Point;
use ccpp_io::execution::{exec_choice, execution, ExecAsk, Names};
use ccpp_io::export::{render_exports, zone_features, ExportFormat, ExportMeta};
use ccpp_io::scenario::{MapRecipe, PreparedMap, Scenario, ScenarioError};
use ccpp_io::zones::ZoneSpec;
use fixedbitset::FixedBitSet;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde_json::Value;

create_exception!(
    ccpp,
    CcppError,
    PyException,
    "A ccpp error: invalid options, a map that cannot be loaded, a run that cannot be done. \
     The message is the one-line message of the command line."
);

/// The error and its causes as the command line's one-line message
/// ([`ccpp_io::message::one_line`]: each cause once, no YAML snippet or library advice).
fn err(e: &(dyn std::error::Error + 'static)) -> PyErr {
    CcppError::new_err(ccpp_io::message::one_line(e))
}

/// A `CcppError` with this message, on one line with the characters a terminal acts on made
/// visible ([`ccpp_io::message::visible`]), as every error from [`err`] is: an option key or
/// value holding an escape sequence and a line break was raised raw.
fn msg(m: impl Into<String>) -> PyErr {
    CcppError::new_err(ccpp_io::message::visible(&m.into()))
}

// ---------------------------------------------------------------------------------------------
// JSON <-> Python
// ---------------------------------------------------------------------------------------------

fn json_to_py(py: Python<'_>, v: &Value) -> PyResult<Py<PyAny>> {
    Ok(match v {
        Value::Null => py.None(),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any().unbind(),
        Value::Number(n) => {
            if let Some(i) = n.as_i64() {
                i.into_pyobject(py)?.into_any().unbind()
            } else if let Some(u) = n.as_u64() {
                u.into_pyobject(py)?.into_any().unbind()
            } else {
                n.as_f64()
                    .unwrap_or(f64::NAN)
                    .into_pyobject(py)?
                    .into_any()
                    .unbind()
            }
        }
        Value::String(s) => s.into_pyobject(py)?.into_any().unbind(),
        Value::Array(a) => {
            let items = a
                .iter()
                .map(|x| json_to_py(py, x))
                .collect::<PyResult<Vec<_>>>()?;
            PyList::new(py, items)?.into_any().unbind()
        }
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, json_to_py(py, x)?)?;
            }
            d.into_any().unbind()
        }
    })
}

/// Deepest nesting of lists and dicts an option value may have: a zone file's polygons nest
/// four deep, and a value that refers to itself (`l = []; l.append(l)`) nests forever (the
/// recursion used to overflow the native stack and kill the interpreter).
const MAX_OPTION_DEPTH: usize = 64;

fn py_to_json(o: &Bound<'_, PyAny>) -> PyResult<Value> {
    py_to_json_at(o, 0)
}

/// [`py_to_json`] of a value nested `depth` deep.
fn py_to_json_at(o: &Bound<'_, PyAny>, depth: usize) -> PyResult<Value> {
    if depth > MAX_OPTION_DEPTH {
        return Err(msg(format!(
            "option value is nested more than {MAX_OPTION_DEPTH} deep (does it hold itself?)"
        )));
    }
    if o.is_none() {
        return Ok(Value::Null);
    }
    if o.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(o.extract()?));
    }
    if o.is_instance_of::<PyInt>() {
        // Seeds reach 2^64 - 1.
        if let Ok(u) = o.extract::<u64>() {
            return Ok(Value::from(u));
        }
        return o
            .extract::<i64>()
            .map(Value::from)
            .map_err(|_| msg(format!("option value {} is out of range", repr(o))));
    }
    if o.is_instance_of::<PyFloat>() {
        let f: f64 = o.extract()?;
        return serde_json::Number::from_f64(f)
            .map(Value::Number)
            .ok_or_else(|| msg(format!("option values must be finite numbers, got {f}")));
    }
    if o.is_instance_of::<PyString>() {
        // A path from `os.fsdecode` of bytes that are not UTF-8 holds surrogates: named as
        // such (a raw UnicodeEncodeError before), as a map path is.
        return o.extract().map(Value::String).map_err(|_| {
            msg(format!(
                "{}: not valid UTF-8 (ccpp records paths as text, in run.json and the exports); rename it",
                repr(o)
            ))
        });
    }
    if let Ok(d) = o.cast::<PyDict>() {
        let mut m = serde_json::Map::new();
        for (k, v) in d.iter() {
            let key = k
                .extract::<String>()
                .map_err(|_| msg(format!("option names must be strings, got {}", repr(&k))))?;
            m.insert(key, py_to_json_at(&v, depth + 1)?);
        }
        return Ok(Value::Object(m));
    }
    if o.is_instance_of::<PyList>() || o.is_instance_of::<PyTuple>() {
        let mut a = Vec::new();
        for x in o.try_iter()? {
            a.push(py_to_json_at(&x?, depth + 1)?);
        }
        return Ok(Value::Array(a));
    }
    // A path (`pathlib.Path`, any `os.PathLike`) as its text, as map and folder arguments.
    if o.hasattr("__fspath__")? {
        let p = o.call_method0("__fspath__")?;
        if p.is_instance_of::<PyString>() {
            return Ok(Value::String(p.extract()?));
        }
    }
    // numpy arrays and scalars as the Python lists and numbers they hold (`np.int64(3)` is a
    // whole number, not 3.0; an array of four numbers is a rectangle).
    if o.hasattr("tolist")? {
        let plain = o.call_method0("tolist")?;
        if !plain.hasattr("tolist")? {
            return py_to_json_at(&plain, depth + 1);
        }
    }
    // Other numbers.
    if let Ok(f) = o.extract::<f64>() {
        return serde_json::Number::from_f64(f)
            .map(Value::Number)
            .ok_or_else(|| msg(format!("option values must be finite numbers, got {f}")));
    }
    Err(msg(format!(
        "cannot use {} as an option value",
        o.get_type().name()?
    )))
}

fn to_py<T: serde::Serialize>(py: Python<'_>, v: &T) -> PyResult<Py<PyAny>> {
    let v = serde_json::to_value(v).map_err(|e| err(&e))?;
    json_to_py(py, &v)
}

/// A bitset in image layout (row 0 = the image's top row) as a `bool` array `(height, width)`.
fn mask<'py>(py: Python<'py>, frame: &MapFrame, bits: &FixedBitSet) -> Bound<'py, PyArray2<bool>> {
    let (w, h) = (frame.width, frame.height);
    let mut a = Array2::from_elem((h, w), false);
    for i in bits.ones() {
        if i < w * h {
            a[(i / w, i % w)] = true;
        }
    }
    a.into_pyarray(py)
}

// ---------------------------------------------------------------------------------------------
// Map
// ---------------------------------------------------------------------------------------------

/// An occupancy-grid map, loaded and prepared (overrides, georeference, inflation applied).
#[pyclass(module = "ccpp", frozen)]
pub struct Map {
    map: PreparedMap,
    /// The memory limit it was loaded within when one was given (`load_map(...,
    /// max_memory_mb=)`, an `Env`'s): the default of the runs, plans and environments made on
    /// it (a limit given to them wins).
    max_memory_mb: Option<u64>,
}

#[pymethods]
impl Map {
    /// Short name used in reports (the file stem unless given).
    #[getter]
    fn name(&self) -> String {
        self.map.name.clone()
    }

    /// The map file.
    #[getter]
    fn path(&self) -> String {
        self.map.source.display().to_string()
    }

    /// Image width, pixels.
    #[getter]
    fn width(&self) -> usize {
        self.map.grid.frame().width
    }

    /// Image height, pixels.
    #[getter]
    fn height(&self) -> usize {
        self.map.grid.frame().height
    }

    /// `(width, height)` in pixels.
    #[getter]
    fn size(&self) -> (usize, usize) {
        let f = self.map.grid.frame();
        (f.width, f.height)
    }

    /// `(width, height)` in metres.
    #[getter]
    fn size_m(&self) -> (f64, f64) {
        let f = self.map.grid.frame();
        (f.width_m(), f.height_m())
    }

    /// Metres per pixel.
    #[getter]
    fn resolution(&self) -> f64 {
        self.map.grid.frame().resolution
    }

    /// `(x, y, yaw)` of the image's bottom-left corner in the world frame (ROS convention).
    #[getter]
    fn origin(&self) -> (f64, f64, f64) {
        let o = self.map.grid.frame().origin;
        (o.x, o.y, o.theta)
    }

    /// Occupancy in image layout (row 0 = top), `uint8` `(height, width)`:
    /// 0 free, 1 occupied, 2 unknown.
    #[getter]
    fn occupancy<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u8>> {
        let f = self.map.grid.frame();
        let cells: Vec<u8> = self.map.grid.cells().iter().map(|&c| c as u8).collect();
        Array2::from_shape_vec((f.height, f.width), cells)
            .unwrap_or_else(|_| Array2::zeros((f.height, f.width)))
            .into_pyarray(py)
    }

    /// The world coordinates `(x, y)` of the centre of pixel `(col, row)` (column from the
    /// left, row from the top); `IndexError` outside the image.
    fn pixel_center(&self, col: &Bound<'_, PyAny>, row: &Bound<'_, PyAny>) -> PyResult<(f64, f64)> {
        let f = self.map.grid.frame();
        // A negative index is outside too (as `usize` it raised OverflowError), and so is an
        // int beyond 64 bits (as `i64` it raised OverflowError); not an int: TypeError.
        let inside = |v: &Bound<'_, PyAny>, n: usize| -> PyResult<Option<usize>> {
            // (a bool is no index, as `radius=True` is no radius)
            if is_bool(v) {
                return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                    "a pixel index must be an int, got {}",
                    repr(v)
                )));
            }
            match v.extract::<i64>() {
                Ok(i) => Ok(usize::try_from(i).ok().filter(|&i| i < n)),
                // (an int of any kind, a numpy uint64 too, beyond 64 signed bits)
                Err(e) if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(v.py()) => Ok(None),
                Err(e) => Err(e),
            }
        };
        let (Some(c), Some(r)) = (inside(col, f.width)?, inside(row, f.height)?) else {
            return Err(pyo3::exceptions::PyIndexError::new_err(format!(
                "pixel ({}, {}) is outside the map's {} x {} px",
                repr(col),
                repr(row),
                f.width,
                f.height
            )));
        };
        let p = f.pixel_center(c, r);
        Ok((p.x, p.y))
    }

    fn __repr__(&self) -> String {
        let f = self.map.grid.frame();
        format!(
            "Map({:?}, {} x {} px, {} m/px)",
            self.map.name, f.width, f.height, f.resolution
        )
    }
}

/// The recipe of a map file as the command line builds it: absolute paths, the file stem as
/// the name. Symbolic links are kept: a map YAML's image is looked up beside the path given.
fn recipe_of(path: &Path) -> MapRecipe {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    MapRecipe {
        path: Some(abs(path)),
        name: Some(
            path.file_stem()
                .map_or_else(|| "map".to_string(), |s| s.to_string_lossy().into_owned()),
        ),
        ..MapRecipe::default()
    }
}

/// [`recipe_of`] a path given by the user, refused when it is not valid UTF-8.
fn recipe_for(path: &Path) -> PyResult<MapRecipe> {
    utf8_path(path, "map")?;
    Ok(recipe_of(path))
}

/// Refuses a path that is not valid UTF-8 or holds a control character, as the command line
/// does ([`ccpp_io::names::path_text_problem`]): ccpp records paths as text (`run.json`, the
/// exports), and such a path used to load and run, then fail at `save` with a message naming
/// no file.
fn utf8_path(path: &Path, what: &str) -> PyResult<()> {
    ccpp_io::names::path_text_problem(path, what).map_or(Ok(()), |m| Err(msg(m)))
}

/// Loads a map: a ROS `map_server` YAML (with its PGM/PNG) or a bare image. An image whose
/// pixels alone would need more than `max_memory_mb` (default 4096) in a run is refused from
/// its header, before it is decoded.
/// A limit given here stays with the map: it is the default `max_memory_mb` of `run`,
/// `plan` and `Env` on it.
#[pyfunction]
#[pyo3(signature = (path, *, resolution=None, origin=None, occupied_thresh=None, free_thresh=None, inflate=None, georef=None, name=None, max_memory_mb=None))]
#[allow(clippy::too_many_arguments)] // keyword arguments of a Python function
fn load_map(
    py: Python<'_>,
    path: PathBuf,
    resolution: Option<Real>,
    origin: Option<Vec<Real>>,
    occupied_thresh: Option<Real>,
    free_thresh: Option<Real>,
    inflate: Option<Real>,
    georef: Option<PathBuf>,
    name: Option<String>,
    max_memory_mb: Option<&Bound<'_, PyAny>>,
) -> PyResult<Map> {
    let (resolution, origin, inflate) = (real(resolution), reals(origin), real(inflate));
    let (occupied_thresh, free_thresh) = (real(occupied_thresh), real(free_thresh));
    let mut recipe = recipe_for(&path)?;
    recipe.resolution = resolution;
    recipe.origin = match origin.as_deref() {
        None => None,
        Some([x, y]) => Some([*x, *y, 0.0]),
        Some([x, y, t]) => Some([*x, *y, *t]),
        Some(o) => {
            return Err(msg(format!(
                "origin expects (x, y) or (x, y, yaw), got {} values",
                o.len()
            )))
        }
    };
    recipe.occupied_thresh = occupied_thresh;
    recipe.free_thresh = free_thresh;
    recipe.inflate = inflate;
    if let Some(g) = &georef {
        utf8_path(g, "georef")?;
    }
    recipe.georef = georef.map(|g| std::path::absolute(&g).unwrap_or(g));
    if name.is_some() {
        recipe.name = name;
    }
    // As `Env` and `run` read it (a -1 or 2**64 was a bare `OverflowError` here).
    let given = max_memory_mb
        .filter(|v| !v.is_none())
        .map(|v| uint_arg("max_memory_mb", v, 1))
        .transpose()?;
    let limit = given.unwrap_or(ccpp_io::scenario::DEFAULT_MAX_MEMORY_MB);
    let map = py
        .detach(|| recipe.load_within(limit))
        .map_err(|e| err(&e))?;
    Ok(Map {
        map,
        max_memory_mb: given,
    })
}

// ---------------------------------------------------------------------------------------------
// Runs
// ---------------------------------------------------------------------------------------------

fn parse_kind(planner: &str) -> PyResult<PlannerKind> {
    planner.parse::<PlannerKind>().map_err(|e| err(&e))
}

fn not_applicable(opt: &str, kind: PlannerKind, applies_to: &str) -> PyErr {
    msg(format!(
        "{opt} does not apply to {kind} (it applies to {applies_to})"
    ))
}

/// The robot radius of `run`, `plan`, `Env` and `bench_run` when none (or `None`) is given, as
/// `ccpp run --radius`'s default.
const DEFAULT_RADIUS: f64 = 0.15;

/// Keyword options of `run` that are not planner options.
const RUN_KEYS: [&str; 13] = [
    "tool_radius",
    "start",
    "sensor_range",
    "max_memory_mb",
    "max_steps",
    "exec",
    "odometry_noise",
    "landmarks",
    "seed",
    "options",
    "name",
    "area",
    "keepout",
];

/// What a zone argument may be, for messages (serde's "data did not match any variant of
/// untagged enum `ZoneSpec`" says nothing to a user).
const ZONE_FORMS: &str =
    "a file name, [x0, y0, x1, y1], \"x0,y0,x1,y1\" or a list of polygons (each a list of [x, y] points)";

/// A work area: a file name, `[x0, y0, x1, y1]` or a list of polygons (`Scenario::area`).
fn parse_area(v: &Bound<'_, PyAny>) -> PyResult<ZoneSpec> {
    if let Some(r) = text_zone(v, "area") {
        return r;
    }
    serde_json::from_value(py_to_json(v)?)
        .map_err(|_| msg(format!("area must be {ZONE_FORMS}, got {}", repr(v))))
}

/// A zone given as text, read as the command line's `--area` / `--keepout` read it
/// ([`ZoneSpec`]'s `FromStr`): `"X0,Y0,X1,Y1"` is the rectangle (it was taken for a file name:
/// "No such file"), other text a file; `None` when `v` is not text.
fn text_zone(v: &Bound<'_, PyAny>, what: &str) -> Option<PyResult<ZoneSpec>> {
    let s: String = v.extract().ok()?;
    Some(
        s.parse::<ZoneSpec>()
            .map_err(|e| msg(format!("{what} {s:?}: {e}"))),
    )
}

/// Keep-out zones: one zone (as for an area) or a list of zones (`Scenario::keepout`).
fn parse_keepout(v: &Bound<'_, PyAny>) -> PyResult<Vec<ZoneSpec>> {
    if let Some(r) = text_zone(v, "keepout") {
        return r.map(|z| vec![z]);
    }
    // A list with a zone given as text ("x0,y0,x1,y1" rectangles and file names, as repeated
    // `--keepout` flags): each item as one zone (a list of text rectangles was read as file
    // names, and so was a text rectangle beside a list rectangle). No single zone is a list
    // holding text (a polygon's points are numbers).
    if !v.is_instance_of::<PyString>() {
        if let Ok(items) = v.extract::<Vec<Bound<'_, PyAny>>>() {
            if items.iter().any(PyAnyMethods::is_instance_of::<PyString>) {
                return items
                    .iter()
                    .map(|i| text_zone(i, "keepout").unwrap_or_else(|| parse_area(i)))
                    .collect();
            }
        }
    }
    let j = py_to_json(v)?;
    // An empty list is no keep-out (as leaving it out), not an empty polygon list.
    if j.as_array().is_some_and(Vec::is_empty) {
        return Ok(Vec::new());
    }
    match serde_json::from_value::<ZoneSpec>(j.clone()) {
        Ok(one) => Ok(vec![one]),
        Err(_) => serde_json::from_value(j).map_err(|_| {
            msg(format!(
                "keepout must be a zone ({ZONE_FORMS}) or a list of zones, got {}",
                repr(v)
            ))
        }),
    }
}

/// What a scenario is built for: a simulated run (`ccpp.run`) or a known-map plan
/// (`ccpp.plan`, as `ccpp plan`).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Purpose {
    Run,
    Plan,
}

/// A number argument that is not a `bool`. Python's `True` is an `int`, so pyo3 would take
/// `radius=True` as 1.0 m (or `max_steps=True` as 1); a bool where a length or a count belongs
/// is a mistake, not a value.
#[derive(Clone, Copy, Debug)]
struct NotBool<T>(T);

/// A real number argument ([`NotBool`]).
type Real = NotBool<f64>;

impl<'a, 'py, T> FromPyObject<'a, 'py> for NotBool<T>
where
    T: FromPyObject<'a, 'py, Error = PyErr>,
{
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if is_bool(&obj) {
            return Err(PyTypeError::new_err("must be a number, not bool"));
        }
        obj.extract().map(NotBool)
    }
}

/// Is `v` a truth value: Python's `bool` or numpy's (`np.True_` converts to 1.0 silently)?
fn is_bool(v: &Bound<'_, PyAny>) -> bool {
    if v.is_instance_of::<PyBool>() {
        return true;
    }
    // numpy's bool scalars and bool arrays (a 0-d `np.array(True)` converts to 1.0 too): their
    // dtype's kind is "b".
    v.getattr("dtype")
        .and_then(|d| d.getattr("kind"))
        .and_then(|k| k.extract::<String>())
        .is_ok_and(|k| k == "b")
}

/// The values of optional number arguments.
fn real(v: Option<Real>) -> Option<f64> {
    v.map(|r| r.0)
}

/// The values of a list of number arguments.
fn reals(v: Option<Vec<Real>>) -> Option<Vec<f64>> {
    v.map(|v| v.into_iter().map(|r| r.0).collect())
}

/// The `repr` of a Python value, for messages, on one line: a line break and the indent after
/// it become one space (numpy's repr of a 2-D array spans lines, which the one-line messages
/// showed as `\u{a}` escapes: hostile pass).
fn repr(v: &Bound<'_, PyAny>) -> String {
    let r = v.repr().map_or_else(|_| "?".to_string(), |r| r.to_string());
    if !r.contains(['\n', '\r']) {
        return r;
    }
    r.lines().map(str::trim).collect::<Vec<_>>().join(" ")
}

/// A keyword option that must be a number (its range is the scenario's to check).
fn float_arg(key: &str, v: &Bound<'_, PyAny>) -> PyResult<f64> {
    v.extract::<Real>()
        .map(|r| r.0)
        .map_err(|_| msg(format!("{key} must be a number, got {}", repr(v))))
}

/// A keyword option that must be a whole number, at least `lo` (named in the message of a
/// value that is no such number: `max_steps=-1` said "from 0", and 0 was then refused).
fn uint_arg(key: &str, v: &Bound<'_, PyAny>, lo: u64) -> PyResult<u64> {
    if is_bool(v) {
        return Err(msg(format!(
            "{key} must be a whole number, got {}",
            repr(v)
        )));
    }
    // Past u64 (`max_steps=2**70`) the value is not below 0: say what the range is (the
    // memory limit's is the scenario's, which refuses what lies beyond it).
    let hi = if key == "max_memory_mb" {
        ccpp_io::scenario::MAX_MEMORY_LIMIT_MB
    } else {
        u64::MAX
    };
    let range = || {
        msg(format!(
            "{key} must be a whole number from {lo} to {hi}, got {}",
            repr(v)
        ))
    };
    let n: u64 = v.extract().map_err(|_| range())?;
    // The memory limit's range is checked here too, by the scenario's own check: `0` or
    // `2**62` passed, and were refused only later, by the run (`bench_run` made them a row's
    // error, `sweep` every row's). The other keys' ranges are the scenario's, checked there.
    if key == "max_memory_mb" {
        ccpp_io::scenario::check_memory_limit(n).map_err(|e| err(&e))?;
    }
    Ok(n)
}

/// Whether two Python values set an option alike: equal, or text equal but for case (option
/// names such as `side` are read without regard to case: `"RIGHT"` beside `"right"` is one
/// value, as `--side RIGHT` beside `side: right` in `--config`).
fn same_value(a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<bool> {
    if let (Ok(x), Ok(y)) = (a.extract::<String>(), b.extract::<String>()) {
        return Ok(x.eq_ignore_ascii_case(&y));
    }
    a.eq(b)
}

/// [`same_value`] on JSON values.
fn same_json(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::String(x), Value::String(y)) => x.eq_ignore_ascii_case(y),
        // `1` and `1.0` are one value, as in Python.
        (Value::Number(x), Value::Number(y)) => x.as_f64() == y.as_f64(),
        _ => a == b,
    }
}

/// The nested section of a planner's options (`defaults`, the options at their defaults) that
/// alone holds the option `key`, when the planner itself has no option `key`: `ba_star` for
/// ba-star-extended's `smoothing`. The execution section is left out (`exec=` is a run
/// keyword).
fn nested_section<'a>(
    defaults: Option<&'a serde_json::Map<String, Value>>,
    key: &str,
) -> Option<&'a str> {
    let d = defaults?;
    if d.contains_key(key) {
        return None;
    }
    let mut holders = sections_holding(d, key);
    match (holders.next(), holders.next()) {
        (Some(sec), None) => Some(sec),
        _ => None,
    }
}

/// The nested sections of the planner options `d` (not `exec`) that hold an option `key`.
fn sections_holding<'a, 'k>(
    d: &'a serde_json::Map<String, Value>,
    key: &'k str,
) -> impl Iterator<Item = &'a str> + use<'a, 'k> {
    d.iter()
        .filter(move |(sec, v)| {
            *sec != "exec" && v.as_object().is_some_and(|o| o.contains_key(key))
        })
        .map(|(sec, _)| sec.as_str())
}

/// The planners (command-line names) that have an option `key`, as their own or in one of
/// their nested sections (ba-star-extended's `ba_star` and `extension`).
fn planners_with_option(key: &str) -> Vec<String> {
    PlannerKind::ALL
        .iter()
        .filter(|kind| {
            let cfg = serde_json::to_value(PlannerConfig::new(**kind)).ok();
            let opts = cfg.as_ref().and_then(|c| c.get("options")?.as_object());
            opts.is_some_and(|o| o.contains_key(key) || sections_holding(o, key).next().is_some())
        })
        .map(ToString::to_string)
        .collect()
}

/// `odometry_noise=`: a number (LIN) or a sequence of one to three numbers (LIN, ANG, DRIFT),
/// as `--odometry-noise LIN[,ANG[,DRIFT]]`.
fn noise_arg(v: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let bad = || {
        msg(format!(
            "odometry_noise expects a number or (lin, ang, drift) (one to three numbers), got {}",
            repr(v)
        ))
    };
    if v.is_instance_of::<PyString>() {
        return Err(bad());
    }
    let values: Vec<Real> = match v.extract::<Real>() {
        Ok(x) => vec![x],
        Err(_) => v.extract().map_err(|_| bad())?,
    };
    if is_bool(v) {
        return Err(bad());
    }
    Ok(values.into_iter().map(|r| r.0).collect())
}

/// `landmarks=`: a landmark file (CSV `id,x,y[,theta]` or a JSON array, as `--landmarks`) or
/// a list of `(id, x, y[, theta])`.
fn landmarks_arg(v: &Bound<'_, PyAny>) -> PyResult<Vec<ccpp_core::landmarks::Landmark>> {
    let list = if let Ok(path) = v.extract::<PathBuf>() {
        // (an empty file is refused by the loader, in the CLI's words)
        ccpp_io::landmarks::load_landmarks(&path)
            .map_err(|e| msg(format!("landmarks {}: {e}", path.display())))?
    } else {
        // A list goes through the file reader's own parsing (a JSON array), so both are
        // checked alike.
        if !v.is_instance_of::<PyList>() && !v.is_instance_of::<PyTuple>() {
            return Err(msg(format!(
                "landmarks expects a file name or a list of (id, x, y[, theta]), got {}",
                repr(v)
            )));
        }
        let text = py_to_json(v)?.to_string();
        ccpp_io::landmarks::parse_landmarks(&text).map_err(|e| msg(format!("landmarks: {e}")))?
    };
    if list.is_empty() {
        // Read and then nothing to correct with: the run would be the run without it.
        return Err(msg("landmarks: no landmark given"));
    }
    Ok(list)
}

/// A start pose `(x, y)` or `(x, y, theta)` (theta left out is 0), and whether theta was
/// given.
fn start_arg(v: &Bound<'_, PyAny>) -> PyResult<([f64; 3], bool)> {
    let p: Vec<Real> = v.extract().map_err(|_| {
        msg(format!(
            "start expects (x, y) or (x, y, theta), got {}",
            repr(v)
        ))
    })?;
    match p.as_slice() {
        [NotBool(x), NotBool(y)] => Ok(([*x, *y, 0.0], false)),
        [NotBool(x), NotBool(y), NotBool(t)] => Ok(([*x, *y, *t], true)),
        _ => Err(msg(format!(
            "start expects (x, y) or (x, y, theta), got {} values",
            p.len()
        ))),
    }
}

/// The text of an `exec=` keyword ("ideal" or "pid", checked by `exec_choice`).
fn exec_arg(v: &Bound<'_, PyAny>) -> PyResult<String> {
    v.extract().map_err(|_| {
        msg(format!(
            "exec must be \"ideal\" or \"pid\", got {} (the planner's own execution settings go in options={{\"exec\": ...}})",
            repr(v)
        ))
    })
}

/// Keywords of [`load_map`] that set the map (told apart from unknown run options).
const MAP_KEYS: [&str; 6] = [
    "resolution",
    "origin",
    "occupied_thresh",
    "free_thresh",
    "inflate",
    "georef",
];

/// Builds the scenario of `ccpp.run` / `ccpp.plan`: keyword options -> scenario fields
/// (validated later, once, by the scenario). The rules are the command line's:
/// * an option that does not apply to the planner (or to a plan) is refused, not ignored;
/// * a planner option given both as a keyword and inside `options=` must have one value (the
///   CLI's flag beside the same option in `--config`);
/// * `exec="pid"` keeps the planner's own PID settings; `exec="ideal"` beside PID settings
///   given for the planner is refused by the scenario (`--exec ideal` beside them in
///   `--config`).
fn scenario_from(
    map: &PreparedMap,
    planner: &str,
    radius: f64,
    options: Option<&Bound<'_, PyDict>>,
    purpose: Purpose,
) -> PyResult<Scenario> {
    let kind = parse_kind(planner)?;
    let mut s = Scenario::new(map.recipe.clone(), kind);
    s.robot = Robot::new(radius);
    // Planner options given as keywords, and the `options=` dict: kept apart to find clashes.
    let mut direct: Vec<(String, Bound<'_, PyAny>)> = Vec::new();
    let mut in_options: Option<Bound<'_, PyDict>> = None;
    let mut exec: Option<String> = None;
    let mut noise: Option<Vec<f64>> = None;
    let mut seed: Option<u64> = None;
    // A planner option given as `None`: its default, as if left out; the name is still
    // checked (a misspelt option is refused, `None` or not).
    let mut unset: Vec<String> = Vec::new();
    for (k, v) in options.into_iter().flat_map(PyDictMethods::iter) {
        let key: String = k.extract()?;
        if v.is_none() {
            // `None` means the default: left out, as a keyword not given.
            if !RUN_KEYS.contains(&key.as_str()) {
                unset.push(key);
            }
            continue;
        }
        match key.as_str() {
            "tool_radius" => {
                if purpose == Purpose::Plan && kind == PlannerKind::RectBoustrophedon {
                    // As `ccpp plan --tool-radius`: its lanes follow width_m and a plan has no
                    // coverage metrics, so the value would change nothing.
                    return Err(msg(format!(
                        "tool_radius does not apply to {kind} in plan (its lanes follow width_m)"
                    )));
                }
                s.robot.tool_radius = float_arg(&key, &v)?;
            }
            "start" => {
                let (p, heading_given) = start_arg(&v)?;
                if purpose == Purpose::Plan && heading_given {
                    // As `ccpp plan --start X,Y,THETA`: nothing a plan gives depends on it
                    // (0 included: it was taken, where any other theta was refused).
                    return Err(msg(
                        "start theta does not apply to plan (the path heads from the start to its first waypoint); give (x, y)",
                    ));
                }
                s.start = Some(p);
            }
            "sensor_range" => {
                if let Some(applies) = kind.sensor_range_refusal() {
                    return Err(not_applicable("sensor_range", kind, &applies));
                }
                s.sim.sensor_range = Some(float_arg(&key, &v)?);
            }
            "max_memory_mb" => s.max_memory_mb = uint_arg(&key, &v, 1)?,
            "max_steps" => {
                if purpose == Purpose::Plan {
                    // `ccpp plan` has no step cap to give: a cap cut the plan short, saying so
                    // only in `finished`.
                    return Err(msg(
                        "max_steps does not apply to plan (a plan runs the planner to its end); leave it out",
                    ));
                }
                s.sim.max_steps = uint_arg(&key, &v, 1)?;
            }
            "exec" => exec = Some(exec_arg(&v)?),
            "seed" => {
                // The seed of the odometry noise and random-bounce's own option `seed`: there,
                // a planner option like the others (so `seed=` and `options={"seed": ...}` must
                // agree). Where it seeds nothing, the execution refuses it (below).
                seed = Some(uint_arg(&key, &v, 0)?);
                if kind == PlannerKind::RandomBounce {
                    direct.push((key, v));
                }
            }
            "odometry_noise" => noise = Some(noise_arg(&v)?),
            "landmarks" => s.sim.landmarks.landmarks = landmarks_arg(&v)?,
            "options" => {
                let d = v
                    .cast::<PyDict>()
                    .map_err(|_| msg("options must be a dict of planner options"))?;
                in_options = Some(d.clone());
            }
            "name" => {
                s.map.name = Some(
                    v.extract()
                        .map_err(|_| msg(format!("name must be a string, got {}", repr(&v))))?,
                );
            }
            // Zones: a file name, [x0, y0, x1, y1] or a list of polygons (`Scenario::area`);
            // keepout: one zone or a list of zones (`Scenario::keepout`).
            // Zone files recorded absolute, as the command line and `Env` record them (a
            // relative `area.yaml` in run.json did not replay from another folder).
            "area" => s.area = Some(parse_area(&v)?.absolute()),
            "keepout" => {
                s.keepout = parse_keepout(&v)?
                    .into_iter()
                    .map(ZoneSpec::absolute)
                    .collect();
            }
            _ => direct.push((key, v)),
        }
    }
    // The robot first, as the command line does (same message).
    s.robot.validate().map_err(|e| err(&e))?;
    let mut planner_opts = serde_json::Map::new();
    if let Some(o) = &in_options {
        for (k, v) in o.iter() {
            let key = k.extract::<String>().map_err(|_| {
                msg(format!(
                    "options keys must be option names (strings), got {}",
                    repr(&k)
                ))
            })?;
            planner_opts.insert(key, py_to_json(&v)?);
        }
    }
    let defaults = serde_json::to_value(&s.planner).map_err(|e| err(&e))?;
    let defaults = defaults.get("options").and_then(Value::as_object);
    // The planner's own options first, then those of its nested sections: a nested keyword
    // beside its section given as a keyword (`ba_star={"smoothing": True}, smoothing=False`)
    // is checked against it whatever their order.
    let mut direct = direct;
    direct.sort_by_key(|(k, _)| nested_section(defaults, k).is_some());
    for (k, v) in &direct {
        // A keyword that is no option of the planner itself but of exactly one of its nested
        // sections (ba-star-extended's `ba_star`, `extension`) sets it there, as the command
        // line's `--smoothing` and `--tile-side` do for ba-star-extended.
        let section = nested_section(defaults, k);
        let given = match (&in_options, section) {
            (None, _) => None,
            (Some(o), None) => o.get_item(k)?,
            (Some(o), Some(sec)) => match o.get_item(sec)? {
                Some(d) => d.get_item(k).ok(),
                None => None,
            },
        };
        if let Some(w) = given {
            if !same_value(v, &w)? {
                let place =
                    section.map_or_else(|| format!("[{k:?}]"), |sec| format!("[{sec:?}][{k:?}]"));
                return Err(msg(format!(
                    "{k}={} and options{place}={} set the same option; remove one of them",
                    repr(v),
                    repr(&w)
                )));
            }
        }
        let value = py_to_json(v)?;
        match section {
            None => {
                planner_opts.insert(k.clone(), value);
            }
            Some(sec) => {
                let entry = planner_opts
                    .entry(sec.to_string())
                    .or_insert_with(|| Value::Object(serde_json::Map::new()));
                match entry {
                    Value::Object(o) => {
                        if let Some(w) = o.get(k.as_str()) {
                            // Set by the section's own keyword (`ba_star={...}`).
                            if !same_json(w, &value) {
                                return Err(msg(format!(
                                    "{k}={} and {sec}={{{k:?}: {w}}} set the same option; remove one of them",
                                    repr(v)
                                )));
                            }
                        }
                        o.insert(k.clone(), value);
                    }
                    other => {
                        return Err(msg(format!(
                            "options[{sec:?}] must be a dict of {sec} options, got {other}"
                        )))
                    }
                }
            }
        }
    }
    for k in &unset {
        let known =
            defaults.is_some_and(|o| o.contains_key(k)) || nested_section(defaults, k).is_some();
        if !known {
            return Err(msg(format!(
                "{k}=None: {k} is not an option of {kind} nor a run option ({})",
                RUN_KEYS.join(", ")
            )));
        }
    }
    // A map's own setting given to a run is no planner option: say where it goes (the message
    // named the planner's fields and the run options only: hostile pass).
    if let Some(k) = planner_opts
        .keys()
        .find(|k| MAP_KEYS.contains(&k.as_str()) && !defaults.is_some_and(|o| o.contains_key(*k)))
    {
        return Err(msg(format!(
            "{k} is a setting of the map, not of the run: load the map with ccpp.load_map(path, {k}=...) and pass that map"
        )));
    }
    // Another planner's option is said as the command line says it ("--side does not apply to
    // ba-star (it applies to bsa, bsa-extended)"); it was serde's "unknown field" with this
    // planner's fields (docs review).
    if let Some(k) = planner_opts
        .keys()
        .find(|k| !defaults.is_some_and(|o| o.contains_key(*k)))
    {
        let holders = planners_with_option(k);
        if !holders.is_empty() {
            return Err(not_applicable(k, kind, &holders.join(", ")));
        }
    }
    if !planner_opts.is_empty() {
        let mut cfg = serde_json::to_value(&s.planner).map_err(|e| err(&e))?;
        if let Some(Value::Object(o)) = cfg.get_mut("options") {
            o.extend(planner_opts);
        }
        let section = kind.info().section;
        s.planner = serde_json::from_value(cfg).map_err(|e| {
            msg(format!(
                "planner option {section}: {e} (or one of the run options {})",
                RUN_KEYS.join(", ")
            ))
        })?;
    }
    // After the planner's options: `pid` runs the planner's own PID settings (as `--exec pid`
    // beside `--config`); an execution that would drop them, and noise beside the planner's
    // own, are refused (the command line's rules, `ccpp_io::execution`).
    let pid = exec_choice(exec.as_deref(), &Names::KEYWORDS).map_err(msg)?;
    let preferred = s.planner.settings().preferred_execution();
    let section = kind.info().section;
    let exec_item = in_options
        .as_ref()
        .map(|d| d.get_item("exec"))
        .transpose()?
        .flatten()
        .filter(|v| !v.is_none());
    let gives_pid = exec_item.is_some() && matches!(preferred, Some(Execution::Pid(_)));
    let own_pid = matches!(preferred, Some(Execution::Pid(p)) if p != PidOptions::default());
    let gives_noise = exec_item
        .as_ref()
        .and_then(|e| e.get_item("pid").ok())
        .is_some_and(|p| p.get_item("noise").is_ok());
    let ask = ExecAsk {
        pid,
        noise,
        // random-bounce's seed, from `seed=` or its options, also seeds the noise (the two
        // are the same option; hostile pass).
        seed: seed.or(s.planner.seed()),
        noise_given_in: gives_noise
            .then(|| format!("options[\"exec\"], its {section}.exec.pid.noise")),
        pid_given_in: (gives_pid || own_pid)
            .then(|| format!("options[\"exec\"], its {section}.exec")),
    };
    s.sim.exec = execution(kind, preferred, &ask, &Names::KEYWORDS).map_err(msg)?;
    Ok(s)
}

/// A finished run: metrics, path, swept and accessible masks, events; `save` writes the files
/// of `ccpp run`.
#[pyclass(module = "ccpp", frozen)]
pub struct RunResult {
    scenario: Scenario,
    world: World,
    output: RunOutput,
    metrics: Metrics,
    /// The warnings `ccpp run` prints, found once on the run's thread.
    warnings: Vec<String>,
    /// The files the run read (`save` refuses a folder holding one).
    inputs: Vec<PathBuf>,
}

impl RunResult {
    /// The export files of the run (the command line's `render_export_files`).
    fn export_files(&self, formats: &[ExportFormat]) -> PyResult<Vec<(&'static str, Vec<u8>)>> {
        ccpp_render::run_files::render_export_files(
            &self.scenario,
            &self.output.trace,
            &self.metrics,
            formats,
            &zone_features(self.world.zones(), self.world.frame()),
        )
        .map_err(|e| err(&e))
    }
}

/// Export format names -> formats.
/// `export=` of `save`: one format name or a list of them (`export="csv"` raised "Can't
/// extract 'str' to 'Vec'").
enum Formats {
    /// One format.
    One(String),
    /// Several.
    Many(Vec<String>),
}

impl<'a, 'py> FromPyObject<'a, 'py> for Formats {
    type Error = PyErr;

    fn extract(ob: pyo3::Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Ok(s) = ob.extract::<String>() {
            return Ok(Formats::One(s));
        }
        let bad = || {
            PyTypeError::new_err(format!(
                "must be a format name or a list of them (csv, json, nav-path, geojson), got {}",
                repr(&ob)
            ))
        };
        if !ob.is_instance_of::<PyList>() && !ob.is_instance_of::<PyTuple>() {
            return Err(bad());
        }
        ob.extract::<Vec<String>>()
            .map(Formats::Many)
            .map_err(|_| bad())
    }
}

impl Formats {
    /// The names given.
    fn names(self) -> Vec<String> {
        match self {
            Formats::One(n) => vec![n],
            Formats::Many(v) => v,
        }
    }
}

fn parse_formats(names: &[String]) -> PyResult<Vec<ExportFormat>> {
    names
        .iter()
        .map(|n| n.parse::<ExportFormat>().map_err(|e| err(&e)))
        .collect()
}

fn check_tolerance(t: f64) -> PyResult<()> {
    if t.is_finite() && t >= 0.0 {
        Ok(())
    } else {
        Err(msg(format!(
            "tolerance_m must be a finite number >= 0, got {}",
            ccpp_core::display::Compact(t)
        )))
    }
}

/// A route's waypoints as an `(N, 3)` array, as the exports write them
/// ([`ccpp_io::export::tidy`]).
fn route_array<'py>(py: Python<'py>, route: &Route) -> Bound<'py, PyArray2<f64>> {
    let v: Vec<f64> = ccpp_io::export::tidy(route)
        .waypoints
        .iter()
        .flat_map(|p| [p.x, p.y, p.theta])
        .collect();
    let n = v.len() / 3;
    Array2::from_shape_vec((n, 3), v)
        .unwrap_or_else(|_| Array2::zeros((0, 3)))
        .into_pyarray(py)
}

/// The one rendered export file's text.
fn export_text(files: Vec<(&'static str, Vec<u8>)>) -> PyResult<String> {
    let (_, bytes) = files
        .into_iter()
        .next()
        .ok_or_else(|| msg("no export format given"))?;
    String::from_utf8(bytes).map_err(|e| err(&e))
}

/// Writes `files` as the whole content of `folder`, all or nothing, as `ccpp plan --out`
/// ([`ccpp_io::write::write_folder`]: an older set there is replaced whole, a folder holding
/// other files refused, and so is a folder holding one of the run's `inputs`).
fn write_files(
    folder: &Path,
    files: &[(&'static str, Vec<u8>)],
    inputs: &[PathBuf],
) -> PyResult<()> {
    ccpp_io::write::check_inputs_outside(folder, inputs).map_err(|e| err(&e))?;
    // (as `ccpp run --out`: a folder below one a bench or sweep is writing is refused)
    ccpp_io::write::check_not_in_busy_folder(folder).map_err(|e| err(&e))?;
    ccpp_io::write::check_not_bench_run(folder).map_err(|e| err(&e))?;
    ccpp_io::write::write_folder(folder, files).map_err(|e| err(&e))
}

/// A path planned on a known map by `ccpp.plan` (as `ccpp plan`): its waypoints and exports.
#[pyclass(module = "ccpp", frozen)]
pub struct PlanResult {
    planner: &'static str,
    map: String,
    robot: Robot,
    /// The rectangle a rect-boustrophedon route was planned for (the exports name it).
    footprint: Option<ccpp_io::export::Footprint>,
    route: Route,
    zones: Option<ZoneMasks>,
    /// The map's frame (for keep-out masks in the exports).
    frame: MapFrame,
    finished: bool,
    /// What `ccpp plan` warns of this plan (without `warning: `).
    warnings: Vec<String>,
    /// What `ccpp plan` notes of it (without `note: `): a start outside the area.
    notes: Vec<String>,
    /// The files the plan read (`save` refuses a folder holding one).
    inputs: Vec<PathBuf>,
}

impl PlanResult {
    fn files(&self, formats: &[ExportFormat]) -> PyResult<Vec<(&'static str, Vec<u8>)>> {
        let meta = ExportMeta {
            planner: self.planner,
            map: &self.map,
            robot: self.robot,
            footprint: self.footprint,
            tolerance_m: DEFAULT_TOLERANCE_M,
            metrics: None,
        };
        render_exports(
            &self.route,
            &meta,
            formats,
            &zone_features(self.zones.as_ref(), &self.frame),
        )
        .map_err(|e| err(&e))
    }
}

#[pymethods]
impl PlanResult {
    /// The waypoints, `float64` `(N, 3)`: x, y, theta at the ends of the straight segments.
    #[getter]
    fn waypoints<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        route_array(py, &self.route)
    }

    /// Path length, metres.
    #[getter]
    fn length_m(&self) -> f64 {
        ccpp_io::export::round_m(ccpp_io::export::tidy(&self.route).length_m())
    }

    /// Whether the planner finished (not cut by the step cap).
    #[getter]
    fn finished(&self) -> bool {
        self.finished
    }

    /// What `ccpp plan` warns of this plan (without `warning: `): a start whose free area
    /// reaches the map's border, zones that cut floor off from the start, a rect-boustrophedon
    /// lane rectangle that bounds the area, a path that does not move the robot, bcd lanes
    /// farther apart than the tool sweeps, transfers that could not keep bcd's `margin_px`.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// What `ccpp plan` notes of this plan (without `note: `): a start outside the area, and
    /// how far the path first drives to reach it. Empty otherwise.
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.notes.clone()
    }

    /// The path in export format `format` (`"csv"`, `"json"`, `"nav-path"`, `"geojson"`), as
    /// the text of the file `ccpp plan --export FORMAT` writes.
    fn export(&self, format: &str) -> PyResult<String> {
        export_text(self.files(&parse_formats(&[format.to_string()])?)?)
    }

    /// Writes the exports into `folder` (created if needed), as `ccpp plan --out folder`:
    /// `export` formats, default `["csv", "nav-path"]`; all or nothing, as `run`'s `save`.
    #[pyo3(signature = (folder, export=None))]
    fn save(&self, folder: PathBuf, export: Option<Formats>) -> PyResult<()> {
        utf8_path(&folder, "folder")?;
        let names = export.map_or_else(|| vec!["csv".into(), "nav-path".into()], Formats::names);
        if names.is_empty() {
            // A plan's folder holds its exports only: none would write an empty folder.
            return Err(msg(
                "export names no format: give at least one of csv, json, nav-path, geojson (or leave it out for csv and nav-path)",
            ));
        }
        write_files(&folder, &self.files(&parse_formats(&names)?)?, &self.inputs)
    }

    fn __repr__(&self) -> String {
        format!(
            "PlanResult({} on {}: {} waypoints, {:.2} m)",
            self.planner,
            self.map,
            self.route.waypoints.len(),
            self.route.length_m()
        )
    }
}

/// Plans a path with a known-map planner (`bcd`, the default, or `rect-boustrophedon`) on
/// `map` with robot radius `radius` (default 0.15 m), as
/// `ccpp plan`: the keyword options of `run` (zones included) that apply to a plan, no
/// simulation metrics. As `ccpp plan` refuses them, so does this: `exec` and the planner's own
/// execution settings (a plan executes the steps ideally), `sensor_range` (offline planners),
/// a start heading (`start=(x, y)` only), and `tool_radius` for `rect-boustrophedon` (its lanes
/// follow `width_m`), as is a `radius` not above the disk of its `length_m` x `width_m`
/// rectangle (the lanes keep clear of that disk; the radius is only a floor under it). The GIL is released while planning; Ctrl-C raises `KeyboardInterrupt`
/// at once.
#[pyfunction]
#[pyo3(signature = (map, planner=None, radius=None, **options))]
fn plan(
    py: Python<'_>,
    map: &Bound<'_, PyAny>,
    planner: Option<&str>,
    radius: Option<Real>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<PlanResult> {
    let radius = real(radius);
    let given = radius;
    let limit = memory_limit(map, memory_option(options)?);
    let mut prepared = as_map(py, map, limit)?;
    let (planner, radius) = (planner.unwrap_or("bcd"), radius.unwrap_or(DEFAULT_RADIUS));
    let mut scenario = scenario_from(&prepared, planner, radius, options, Purpose::Plan)?;
    scenario.max_memory_mb = limit;
    // Beside a rectangle a plan's radius is only a floor under its disk, as `ccpp plan` says.
    if let PlannerConfig::RectBoustrophedon(o) = &scenario.planner {
        if let Some(why) = ccpp_io::plan::radius_under_the_rectangle("radius", given, o) {
            return Err(msg(why));
        }
    }
    name_map(&mut prepared, &scenario);
    let (scenario, prepared) = (Arc::new(scenario), Arc::new(prepared));
    let (sc, pm) = (Arc::clone(&scenario), Arc::clone(&prepared));
    let p = interruptible(py, move |stop| {
        ccpp_io::plan::plan_route_until(&sc, &pm, DEFAULT_TOLERANCE_M, stop)
    })?
    .map_err(|e| err(&e))?;
    let scenario = Arc::unwrap_or_clone(scenario);
    Ok(PlanResult {
        planner: scenario.planner.name(),
        map: prepared.name.clone(),
        robot: scenario.robot,
        footprint: ccpp_io::export::Footprint::of(&scenario.planner, &scenario.robot),
        route: p.route,
        zones: p.world.zones().cloned(),
        frame: *p.world.frame(),
        finished: p.stop == StopReason::Done,
        notes: ccpp_io::warnings::approach_note(&p.world)
            .into_iter()
            .collect(),
        warnings: p.warnings,
        inputs: scenario.input_files(),
    })
}

#[pymethods]
impl RunResult {
    /// The metrics (the keys of `metrics.json`).
    #[getter]
    fn metrics(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        to_py(py, &self.metrics)
    }

    /// The executed poses, `float64` `(N, 3)`: x, y (metres), theta (radians); under PID
    /// execution the recorded ones (every control step but the inside of straight glides along
    /// the map's axes, which lie on the segments between them).
    #[getter]
    fn path<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let v: Vec<f64> = self
            .output
            .trace
            .poses()
            .flat_map(|p| [p.x, p.y, p.theta])
            .collect();
        let n = v.len() / 3;
        Array2::from_shape_vec((n, 3), v)
            .unwrap_or_else(|_| Array2::zeros((0, 3)))
            .into_pyarray(py)
    }

    /// Pixels the tool swept, `bool` `(height, width)` in image layout (row 0 = top).
    #[getter]
    fn swept<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<bool>> {
        let s = py.detach(|| metrics::swept_pixels(&self.world, &self.output.trace));
        mask(py, self.world.frame(), &s)
    }

    /// Pixels the tool can reach from the start, `bool` `(height, width)` in image layout.
    #[getter]
    fn accessible<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<bool>> {
        mask(py, self.world.frame(), self.world.accessible())
    }

    /// The trace's events, in order: dicts with the step counter `t`, the `event` kind and its
    /// fields (as in `trace.jsonl`, except that a `backtrack_list` event holds its whole list
    /// as `points`, where the file stores most as a `delta` against the list before).
    #[getter]
    fn events(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let ev: Vec<Record> = self
            .output
            .trace
            .records()
            .filter(|r| matches!(r, Record::Event { .. }))
            .collect();
        to_py(py, &ev)
    }

    /// Why the run ended: `"done"`, `"stalled"` (no progress for 1000 motions in a row) or
    /// `"max_steps"`.
    #[getter]
    fn stop(&self) -> &'static str {
        self.output.stop.as_str()
    }

    /// The warnings `ccpp run` prints for this run (without `warning: `): a start whose free
    /// area reaches the map's border (it may be outside the building), an early stop, PID
    /// motions cut at `max_steps_per_motion`, bumper contacts, keep-out entries or a true pose
    /// far off the plan under odometry noise (with or without landmarks: the estimate drifts
    /// between fixes), a run that never moved, a tool narrower than the map's pixels, tiles
    /// wider than the tool or stranded at the start (ba-star, bsa, bsa-bfs), a rectangle whose
    /// clearance disk reaches little of the floor (rect-boustrophedon), a random bounce boxed
    /// in, floor the run never came near (5 % or more of it farther than 1 m from anything
    /// swept). A run that ends `done` may still have some (`stop` is the planner's word).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// What `ccpp run` notes of this run (without `note: `): a start outside the area, and how
    /// far the robot first drives to reach it (that drive is part of `path` and of the
    /// metrics). Empty otherwise.
    #[getter]
    fn notes(&self) -> Vec<String> {
        ccpp_io::warnings::approach_note(&self.world)
            .into_iter()
            .collect()
    }

    /// The start pose used, `(x, y, theta)`: where the robot was placed, the first pose of
    /// `path` and the start of `run.json`. (With a start outside the area it was the point
    /// where the drive to the area ends, which neither `path` nor `run.json` holds.)
    #[getter]
    fn start(&self) -> (f64, f64, f64) {
        let s = self.world.initial_pose();
        (s.x, s.y, s.theta)
    }

    /// The scenario that ran, as the `run.json` text `save` writes (with the start used and the
    /// map's digest): `ccpp replay` and `Scenario::run` reproduce the run from it.
    #[getter]
    fn scenario_json(&self) -> PyResult<String> {
        ccpp_render::run_files::run_json(&self.scenario, &self.world).map_err(|e| err(&e))
    }

    /// Writes `run.json`, `path.csv`, `trace.jsonl`, `coverage.png` and `metrics.json` into
    /// `folder` (created if needed), exactly as `ccpp run --out folder`; `export` (one of, or
    /// a list of, `"csv"`, `"json"`, `"nav-path"`, `"geojson"`) adds the path exports, as
    /// `ccpp run --export FORMAT`. All or nothing, as the command line: the files of an older
    /// run or plan in `folder` are replaced whole, a folder holding other files is refused.
    /// Ctrl-C while the files are drawn raises `KeyboardInterrupt` once they are drawn (the
    /// picture of a long run takes seconds) and leaves `folder` as it was. Ctrl-C after that,
    /// while they are written, lets the write finish: `folder` then holds the new set whole,
    /// and Python raises `KeyboardInterrupt` as `save` returns.
    #[pyo3(signature = (folder, export=None))]
    fn save(&self, py: Python<'_>, folder: PathBuf, export: Option<Formats>) -> PyResult<()> {
        utf8_path(&folder, "folder")?;
        let formats = parse_formats(&export.map(Formats::names).unwrap_or_default())?;
        let extra = self.export_files(&formats)?;
        let mut files = py
            .detach(|| {
                ccpp_render::run_files::render_run_files(
                    &self.scenario,
                    &self.world,
                    &self.output.trace,
                    &self.metrics,
                    &self.warnings,
                )
            })
            .map_err(|e| err(&e))?;
        // A Ctrl-C while the files were drawn raises here, before the folder is touched: it
        // was raised after the write, with the folder already replaced.
        py.check_signals()?;
        files.extend(extra);
        py.detach(|| write_files(&folder, &files, &self.inputs))
    }

    /// The executed path's waypoints, `float64` `(N, 3)`: x, y, theta at the ends of its
    /// straight segments (poses merged within `tolerance_m`, default 0.001 m, as in
    /// `path.csv` and the exports; `None` is the default).
    #[pyo3(signature = (tolerance_m=None), text_signature = "($self, tolerance_m=0.001)")]
    fn waypoints<'py>(
        &self,
        py: Python<'py>,
        tolerance_m: Option<Real>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let tolerance_m = real(tolerance_m).unwrap_or(DEFAULT_TOLERANCE_M);
        check_tolerance(tolerance_m)?;
        Ok(route_array(
            py,
            &Route::from_trace(&self.output.trace, tolerance_m),
        ))
    }

    /// The path in export format `format` (`"csv"`, `"json"`, `"nav-path"`, `"geojson"`), as
    /// the text of the file `ccpp run --export FORMAT` writes.
    fn export(&self, format: &str) -> PyResult<String> {
        let f = parse_formats(&[format.to_string()])?;
        let files = self.export_files(&f)?;
        export_text(files)
    }

    fn __repr__(&self) -> String {
        format!(
            "RunResult({} on {}: effective coverage {:.4}, path {:.2} m)",
            self.metrics.planner,
            self.metrics.map,
            self.metrics.effective_coverage,
            self.metrics.path_length_m
        )
    }
}

/// Runs `planner` (default `"ba-star"`) on `map` with robot radius `radius` (default 0.15 m);
/// the other keyword options are scenario
/// fields (`tool_radius`, `start`, `sensor_range`, `exec`, `odometry_noise` (LIN or
/// `(LIN, ANG, DRIFT)`, as `--odometry-noise`), `landmarks` (a file or a list of
/// `(id, x, y[, theta])`, as `--landmarks`), `seed` (of random-bounce and of the noise),
/// `max_steps`, `max_memory_mb`, `name`, `area`, `keepout`) or the planner's own options
/// (`options={...}` or directly, e.g. `smoothing=False`). The command line's rules hold: an option that does
/// not apply to the planner is refused; a planner option given both directly and in
/// `options` must have one value; `exec="pid"` runs the planner's own PID settings
/// (`options={"exec": {"pid": {...}}}` of bsa-bfs, rect-boustrophedon) and `exec="ideal"`
/// beside such settings is refused. A keyword given as `None` is its default, as if left out
/// (a name that is no option is still refused). The GIL is released during the run, and
/// Ctrl-C raises `KeyboardInterrupt` at once (the run ends on its own thread, its result
/// dropped).
#[pyfunction]
#[pyo3(signature = (map, planner=None, radius=None, **options))]
fn run(
    py: Python<'_>,
    map: &Bound<'_, PyAny>,
    planner: Option<&str>,
    radius: Option<Real>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<RunResult> {
    let radius = real(radius);
    let limit = memory_limit(map, memory_option(options)?);
    let mut prepared = as_map(py, map, limit)?;
    let (planner, radius) = (
        planner.unwrap_or("ba-star"),
        radius.unwrap_or(DEFAULT_RADIUS),
    );
    let mut scenario = scenario_from(&prepared, planner, radius, options, Purpose::Run)?;
    scenario.max_memory_mb = limit;
    // The files the run reads (`save` refuses a folder holding one): the scenario's, and a
    // landmarks file, which the scenario holds as read.
    let mut inputs = scenario.input_files();
    let landmarks_file = landmarks_file(options);
    inputs.extend(landmarks_file.clone());
    name_map(&mut prepared, &scenario);
    let (scenario, prepared) = (Arc::new(scenario), Arc::new(prepared));
    let (sc, pm) = (Arc::clone(&scenario), Arc::clone(&prepared));
    let (run, warnings) = interruptible(py, move |stop| {
        sc.run_on_until(&pm, stop).map(|run| {
            // The warnings (the flood fill of the start's free area, rect-boustrophedon's
            // reach) here, once, and not on each `warnings` read: a read held the GIL for a
            // second on a 16-million-pixel map.
            let w = ccpp_io::warnings::warnings_with_start(
                None,
                &sc,
                &run.world,
                &run.output.trace,
                &run.metrics,
                &run.swept,
            );
            (run, w)
        })
    })?
    .map_err(|e| err(&e.naming_landmarks(landmarks_file.as_deref())))?;
    let scenario = Arc::unwrap_or_clone(scenario);
    Ok(RunResult {
        scenario,
        world: run.world,
        output: run.output,
        metrics: run.metrics,
        warnings,
        inputs,
    })
}

/// The landmarks file of `options` (`landmarks=` given as a file name), if any: the scenario
/// holds the landmarks as read, and `save` and error messages name their file.
fn landmarks_file(options: Option<&Bound<'_, PyDict>>) -> Option<PathBuf> {
    options
        .and_then(|o| o.get_item("landmarks").ok().flatten())
        .and_then(|v| v.extract::<PathBuf>().ok())
}

/// Gives the prepared map the scenario's map name (`name=`), which the metrics, the exports
/// and `run.json` all report.
fn name_map(map: &mut PreparedMap, scenario: &Scenario) {
    if let Some(n) = &scenario.map.name {
        map.name.clone_from(n);
    }
}

/// Interrupted runs still finishing on their threads ([`interruptible`]).
static ORPHANS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Runs `job` on a thread of its own while this one waits with the GIL released, looking
/// for signals every 50 ms: Ctrl-C (`KeyboardInterrupt`) ends the wait at once. A long run
/// used to hold the caller until it finished. On the interrupt the flag given to `job` is
/// set: a simulation stops within a few steps, bcd's planning at its next step and
/// rect-boustrophedon's within a lane point or a search ([`Scenario::run_on_until`]; its
/// planning on a large cluttered map ran on for minutes, and the next call waited); what
/// cannot be stopped (the online planners' building, which is quick) finishes on its thread
/// and its result is dropped (a script that ends on the
/// interrupt ends it with the process). A new job first waits
/// (interruptibly) until the interrupted ones have ended, so they never pile up: three
/// interrupted runs slowed the next one threefold and held 921 MB beside it, over the 800 MB
/// each was admitted under. An interrupted simulation used to run to its end too, so the next
/// run waited minutes for it.
fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    job: impl FnOnce(&AtomicBool) -> T + Send + 'static,
) -> PyResult<T> {
    use std::sync::atomic::{AtomicU8, Ordering};
    const RUNNING: u8 = 0;
    const FINISHED: u8 = 1;
    const ABANDONED: u8 = 2;
    let pause = std::time::Duration::from_millis(50);
    while ORPHANS.load(Ordering::SeqCst) > 0 {
        py.detach(|| std::thread::sleep(pause));
        py.check_signals()?;
    }
    let state = Arc::new(AtomicU8::new(RUNNING));
    let theirs = Arc::clone(&state);
    let stop = Arc::new(AtomicBool::new(false));
    let their_stop = Arc::clone(&stop);
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::Builder::new()
        .name("ccpp-run".into())
        // The stack of a main thread: planners recurse no deeper, but a spawned thread's
        // default is only 2 MiB.
        .stack_size(8 << 20)
        .spawn(move || {
            /// Marks the job finished when the thread ends, even by a panic (an orphan that
            /// was never counted down would hold every later run).
            struct Finish(Arc<AtomicU8>);
            impl Drop for Finish {
                fn drop(&mut self) {
                    if self.0.swap(FINISHED, Ordering::SeqCst) == ABANDONED {
                        ORPHANS.fetch_sub(1, Ordering::SeqCst);
                    }
                }
            }
            let finish = Finish(theirs);
            let out = job(&their_stop);
            if finish.0.load(Ordering::SeqCst) != ABANDONED {
                // The caller may leave meanwhile: the result is then dropped with the channel.
                tx.send(out).ok();
            }
            drop(finish);
        })
        .map_err(|e| msg(format!("cannot start a thread for the run: {e}")))?;
    let mut rx = rx;
    loop {
        // (the receiver moves into the GIL-free closure and back: it is `Send`, not `Sync`)
        let (got, back) = py.detach(move || {
            let got = rx.recv_timeout(pause);
            (got, rx)
        });
        rx = back;
        match got {
            Ok(v) => return Ok(v),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                if let Err(e) = py.check_signals() {
                    stop.store(true, Ordering::SeqCst);
                    // Counted before the job can see it abandoned (it then counts it down);
                    // a job that finished meanwhile is no orphan.
                    ORPHANS.fetch_add(1, Ordering::SeqCst);
                    if state
                        .compare_exchange(RUNNING, ABANDONED, Ordering::SeqCst, Ordering::SeqCst)
                        .is_err()
                    {
                        ORPHANS.fetch_sub(1, Ordering::SeqCst);
                    }
                    return Err(e);
                }
            }
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return Err(msg(
                    "the run stopped without a result (its thread panicked)",
                ))
            }
        }
    }
}

/// A `Map`, or a path loaded as one within the memory limit `max_memory_mb` (an image whose
/// pixels alone exceed it is refused from its header, before it is decoded).
fn as_map(py: Python<'_>, map: &Bound<'_, PyAny>, max_memory_mb: u64) -> PyResult<PreparedMap> {
    if let Ok(m) = map.cast::<Map>() {
        return Ok(m.get().map.clone());
    }
    let p: PathBuf = map.extract().map_err(|_| {
        msg("map must be a ccpp.Map (from ccpp.load_map) or the path of a map file")
    })?;
    let recipe = recipe_for(&p)?;
    py.detach(|| recipe.load_within(max_memory_mb))
        .map_err(|e| err(&e))
}

/// The memory limit of `run` and `plan` keyword options (`max_memory_mb`), read before the
/// map is loaded so that loading honours it too (it used to load within the default 4096 MB
/// whatever the user asked: a raised limit was refused as 4096 MB, and a lower one came too
/// late to keep a large image from being decoded); [`memory_limit`] gives the default.
fn memory_option(options: Option<&Bound<'_, PyDict>>) -> PyResult<Option<u64>> {
    let v = options
        .map(|o| o.get_item("max_memory_mb"))
        .transpose()?
        .flatten();
    match v {
        Some(v) if !v.is_none() => uint_arg("max_memory_mb", &v, 1).map(Some),
        _ => Ok(None),
    }
}

/// The memory limit of work on `map`: the one `given` to it, else the limit the `Map` was
/// loaded within when one was given (`load_map(..., max_memory_mb=)`: it was dropped after
/// the load, and a run on that map planned within the default 4096 MB), else
/// [`DEFAULT_MAX_MEMORY_MB`](ccpp_io::scenario::DEFAULT_MAX_MEMORY_MB).
fn memory_limit(map: &Bound<'_, PyAny>, given: Option<u64>) -> u64 {
    given
        .or_else(|| map.cast::<Map>().ok().and_then(|m| m.get().max_memory_mb))
        .unwrap_or(ccpp_io::scenario::DEFAULT_MAX_MEMORY_MB)
}

/// The map files that `items` (files and folders) stand for, as `ccpp bench --maps` takes them
/// ([`ccpp_io::names::expand_maps`]).
#[pyfunction]
fn expand_maps(items: Vec<PathBuf>) -> PyResult<Vec<PathBuf>> {
    ccpp_io::names::expand_maps(&items).map_err(|e| err(&e))
}

/// The maps a sweep runs and their names, as `ccpp bench` names them
/// ([`ccpp_io::names::name_maps`]): `(index in paths, name)` for every map kept (a file named
/// twice is run once), in order.
#[pyfunction]
fn name_maps(paths: Vec<PathBuf>) -> Vec<(usize, String)> {
    ccpp_io::names::name_maps_indexed(&paths)
}

/// What [`bench_run`] returns: the metrics (a dict) or the error message, and the warnings.
type BenchRow = (Option<Py<PyAny>>, Option<String>, Vec<String>);

/// One run of `ccpp bench` (default options, start and simulator settings): the metrics, or
/// the error message the bench's `results.csv` records, and the run's warnings (as
/// `ccpp run` prints them; none for a failed run). With `out`, the run's files are written
/// there. Arguments a run would refuse before it starts (an unknown planner, a bad robot or
/// memory limit) raise `CcppError`, as `run`'s do; what fails in the run is the row's error.
#[pyfunction]
#[pyo3(signature = (map_path, planner, radius=None, tool_radius=None, inflate=None, max_memory_mb=None, out=None, name=None))]
#[allow(clippy::too_many_arguments)] // keyword arguments of a Python function
fn bench_run(
    py: Python<'_>,
    map_path: PathBuf,
    planner: &str,
    radius: Option<Real>,
    tool_radius: Option<Real>,
    inflate: Option<Real>,
    max_memory_mb: Option<&Bound<'_, PyAny>>,
    out: Option<PathBuf>,
    name: Option<String>,
) -> PyResult<BenchRow> {
    let (radius, tool_radius, inflate) = (real(radius), real(tool_radius), real(inflate));
    // (as `run`'s: a value below 0 or past 64 bits raised a bare OverflowError)
    let max_memory_mb = max_memory_mb
        .filter(|v| !v.is_none())
        .map(|v| uint_arg("max_memory_mb", v, 1))
        .transpose()?;
    let kind = parse_kind(planner)?;
    let radius = radius.unwrap_or(DEFAULT_RADIUS);
    check_robot(NotBool(radius), tool_radius.map(NotBool))?;
    let robot = Robot {
        radius,
        tool_radius: tool_radius.unwrap_or(radius),
    };
    // A path that is not UTF-8 or holds a control character is the row's error, as any other
    // map that cannot be run.
    let bad_path = ccpp_io::names::path_text_problem(&map_path, "map");
    let outcome: Result<(Metrics, Vec<String>), String> = py.detach(|| {
        if let Some(m) = bad_path {
            return Err(m);
        }
        let mut recipe = recipe_of(&map_path);
        recipe.inflate = inflate;
        if name.is_some() {
            // The bench's distinct name of the map (two maps sharing a file stem).
            recipe.name.clone_from(&name);
        }
        let map = recipe
            .load_within(max_memory_mb.unwrap_or(ccpp_io::scenario::DEFAULT_MAX_MEMORY_MB))
            .map_err(|e| ccpp_io::message::one_line(&e))?;
        let scenario = Scenario::configure(map.recipe.clone(), PlannerConfig::new(kind))
            .robot(robot)
            .memory_limit(max_memory_mb)
            .build()
            .map_err(|e| ccpp_io::message::one_line(&e))?;
        let run = scenario
            .run_on(&map)
            .map_err(|e| ccpp_io::message::one_line(&e))?;
        let warnings = ccpp_io::warnings::run_warnings(
            &scenario,
            &run.world,
            &run.output.trace,
            &run.metrics,
            &run.swept,
        );
        if let Some(dir) = &out {
            ccpp_render::run_files::write_run_files(
                dir,
                &scenario,
                &run.world,
                &run.output.trace,
                &run.metrics,
                &warnings,
                &[],
            )
            .map_err(|e| ccpp_io::message::one_line(&e))?;
        }
        Ok((run.metrics, warnings))
    });
    Ok(match outcome {
        Ok((m, w)) => (Some(to_py(py, &m)?), None, w),
        Err(e) => (None, Some(e), Vec::new()),
    })
}

/// Checks a robot of radius `radius` and tool radius `tool_radius` (default the radius) as
/// runs do (`sweep` checks its radii before it starts any task).
#[pyfunction]
#[pyo3(signature = (radius, tool_radius=None))]
fn check_robot(radius: Real, tool_radius: Option<Real>) -> PyResult<()> {
    let (radius, tool_radius) = (radius.0, real(tool_radius));
    Robot {
        radius,
        tool_radius: tool_radius.unwrap_or(radius),
    }
    .validate()
    .map_err(|e| err(&e))
}

/// The planners: a list of dicts with `name`, `offline` (reads the whole map up front),
/// `description` and `options` (the defaults).
#[pyfunction]
fn planners(py: Python<'_>) -> PyResult<Py<PyAny>> {
    let mut v = Vec::new();
    for p in CATALOG {
        let cfg = serde_json::to_value(PlannerConfig::new(p.kind)).map_err(|e| err(&e))?;
        v.push(serde_json::json!({
            "name": p.name,
            "offline": p.offline,
            "description": p.description,
            "options": cfg.get("options").cloned().unwrap_or(Value::Null),
        }));
    }
    json_to_py(py, &Value::Array(v))
}

// ---------------------------------------------------------------------------------------------
// Step API
// ---------------------------------------------------------------------------------------------

/// What the simulator and the sweeper hold while an episode runs (they borrow the world).
struct Live<'w> {
    sim: Simulator<'w>,
    sweeper: Sweeper<'w>,
    known: KnownMap,
    /// Known map in image layout: 0 free, 1 occupied, 2 unknown.
    known_codes: Vec<u8>,
    /// Where the trace records not yet swept begin.
    records_seen: Cursor,
    /// Last swept position.
    last: Point,
    /// Swept accessible pixels.
    covered: usize,
    steps: u64,
    collisions: u32,
}

self_cell::self_cell!(
    struct Episode {
        owner: World,
        #[covariant]
        dependent: Live,
    }
);

/// A step-by-step coverage environment on a map: the simulator's physics (collision checks,
/// bumper, ideal or PID execution), its sensor (the pixels within `sensor_range`), and the
/// metrics' swept-area stamping, one action at a time.
#[pyclass(module = "ccpp")]
pub struct Env {
    map: PreparedMap,
    /// The validated scenario (robot, start, simulator settings, zones); its planner is unused.
    scenario: Scenario,
    /// The zones, loaded once.
    zones: Option<ZoneMasks>,
    robot: Robot,
    sim: SimConfig,
    max_steps: Option<u64>,
    /// What a run of the same robot on the map holds without its trace (the estimate the map
    /// was checked with), bytes: with the episode's trace, held against the memory limit.
    base_bytes: f64,
    episode: Option<Episode>,
    /// The episode terminated or was truncated: `step` refuses until `reset` (a robot that had
    /// hit a wall kept moving, and a truncated episode kept adding path).
    ended: bool,
    /// The last step truncated the episode at the memory limit (`info["memory_limit"]`).
    memory_cut: bool,
}

/// `(observation, reward, terminated, truncated, info)` of [`Env::step`].
type StepResult = (Py<PyDict>, f64, bool, bool, Py<PyDict>);

/// The square scan window's half side in pixels for a sensor of `range` metres on the map of
/// `frame`: no more than the map's diagonal, which from anywhere on the map reaches all of it
/// (a range capped at twice the diagonal made a window 16 times the area it can show: 537 MB
/// a scan on a 4096 px map).
fn window_half(range: f64, frame: &MapFrame) -> usize {
    let reach = range.min(frame.width_m().hypot(frame.height_m()));
    (reach / frame.resolution).ceil() as usize + 1
}

impl Env {
    fn episode(&self) -> PyResult<&Episode> {
        self.episode
            .as_ref()
            .ok_or_else(|| msg("the episode has not begun: call reset() first"))
    }

    fn observation(&self, py: Python<'_>) -> PyResult<Py<PyDict>> {
        let ep = self.episode()?;
        let world = ep.borrow_owner();
        let live = ep.borrow_dependent();
        let f = *world.frame();
        let d = PyDict::new(py);
        let p = live.sim.estimate();
        d.set_item("pose", vec![p.x, p.y, p.theta].into_pyarray(py))?;
        // Local scan: a square window of image pixels around the robot's pixel; pixels out
        // of sensor range (or outside the image) read unknown (2).
        let k = window_half(live.sim.sensor_range(), &f);
        let side = 2 * k + 1;
        let mut win = Array2::from_elem((side, side), Cell::Unknown as u8);
        let g = f.world_to_grid(live.sim.true_pose().position());
        let (c0, r0) = f.grid_to_pixel_signed(g);
        live.sim.scan().for_each(|col, row, cell| {
            let i = row as i64 - r0 + k as i64;
            let j = col as i64 - c0 + k as i64;
            if (0..side as i64).contains(&i) && (0..side as i64).contains(&j) {
                win[(i as usize, j as usize)] = cell as u8;
            }
        });
        d.set_item("scan", win.into_pyarray(py))?;
        let known = Array2::from_shape_vec((f.height, f.width), live.known_codes.clone())
            .unwrap_or_else(|_| Array2::zeros((f.height, f.width)));
        d.set_item("known", known.into_pyarray(py))?;
        Ok(d.unbind())
    }

    fn info(&self, py: Python<'_>, collision: bool) -> PyResult<Py<PyDict>> {
        let ep = self.episode()?;
        let world = ep.borrow_owner();
        let live = ep.borrow_dependent();
        let d = PyDict::new(py);
        let acc = world.accessible_count();
        d.set_item(
            "coverage",
            if acc == 0 {
                1.0
            } else {
                live.covered as f64 / acc as f64
            },
        )?;
        d.set_item("collision", collision)?;
        d.set_item("collisions", live.collisions)?;
        d.set_item("steps", live.steps)?;
        let t = live.sim.true_pose();
        d.set_item("true_pose", (t.x, t.y, t.theta))?;
        d.set_item("bumped", live.sim.bumped())?;
        d.set_item("memory_limit", self.memory_cut)?;
        Ok(d.unbind())
    }
}

/// Integrates the scan at the current pose into the known map.
fn integrate_scan(live: &mut Live<'_>, frame: &MapFrame) {
    let w = frame.width;
    let Live {
        sim,
        known,
        known_codes,
        ..
    } = live;
    known.integrate_with(&sim.scan(), |col, row, cell| {
        known_codes[row * w + col] = cell as u8;
    });
}

/// Sweeps the poses recorded since the last call; returns whether a collision was recorded.
fn sweep_new(live: &mut Live<'_>, world: &World) -> bool {
    let mut collided = false;
    let Live {
        sim,
        sweeper,
        records_seen,
        last,
        ..
    } = live;
    let trace = sim.trace();
    for r in trace.entries_from(*records_seen) {
        match r {
            Entry::Pose { pose, .. } => {
                let p = pose.position();
                if p != *last {
                    sweeper.add(*last, p);
                    *last = p;
                }
            }
            Entry::Event {
                event: Event::Collision { .. },
                ..
            } => collided = true,
            Entry::Event { .. } => {}
        }
    }
    *records_seen = trace.end();
    let mut s = sweeper.swept().clone();
    s.intersect_with(world.accessible());
    live.covered = s.count_ones(..);
    if collided {
        live.collisions += 1;
    }
    collided
}

fn parse_action(a: &Bound<'_, PyAny>) -> PyResult<Step> {
    let bad = || {
        msg(format!(
            "action must be (\"rotate\", angle), (\"translate\", distance) or (\"move_to\", x, y), got {}",
            a.repr().map_or_else(|_| "?".to_string(), |r| r.to_string())
        ))
    };
    let items: Vec<Bound<'_, PyAny>> = a
        .try_iter()
        .map_err(|_| bad())?
        .collect::<PyResult<_>>()
        .map_err(|_| bad())?;
    let Some(kind) = items.first().and_then(|k| k.extract::<String>().ok()) else {
        return Err(bad());
    };
    let num = |i: usize| -> PyResult<f64> {
        let item = items.get(i).ok_or_else(bad)?;
        if is_bool(item) {
            // A bool is an int to Python: `("translate", True)` drove 1 m.
            return Err(bad());
        }
        let v: f64 = item.extract().map_err(|_| bad())?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(msg(format!(
                "action {kind}: values must be finite, got {v}"
            )))
        }
    };
    match (kind.as_str(), items.len()) {
        ("rotate", 2) => {
            let a = num(1)?;
            // More than two turns is a typo or degrees, as for a start heading (the CLI
            // refuses those); `1e300` was taken.
            match ccpp_io::map::heading_problem(a) {
                Some(p) => Err(msg(format!("action rotate: {p}"))),
                None => Ok(Step::Rotate(a)),
            }
        }
        ("translate", 2) => Ok(Step::Translate(num(1)?)),
        ("move_to" | "move-to", 3) => Ok(Step::MoveTo(Point::new(num(1)?, num(2)?))),
        _ => Err(bad()),
    }
}

#[pymethods]
impl Env {
    /// A coverage environment on `map` (a `Map` or a map path) for a round robot of radius
    /// `radius` (tool radius `tool_radius`, default the same) with a sensor of range
    /// `sensor_range` metres (default 4 r). `exec` is `"ideal"` or `"pid"`; `start` a fixed
    /// start pose (default: the widest free spot, as in runs); `max_steps` truncates episodes.
    /// `area` and `keepout` are zones as in `run` (and `ccpp run --area/--keepout`): virtual
    /// walls the sensor shows (they do not stop the robot), keep-out entries and exits from
    /// the area counted as `keepout_violations` in `metrics()`, coverage
    /// measured on the allowed floor; a start outside the area drives there first.
    #[new]
    #[pyo3(signature = (map, *, radius=None, tool_radius=None, sensor_range=None, start=None, exec=None, max_steps=None, area=None, keepout=None, max_memory_mb=None))]
    #[allow(clippy::too_many_arguments)] // keyword arguments of a Python constructor
    fn new(
        py: Python<'_>,
        map: &Bound<'_, PyAny>,
        radius: Option<Real>,
        tool_radius: Option<Real>,
        sensor_range: Option<Real>,
        start: Option<&Bound<'_, PyAny>>,
        exec: Option<&Bound<'_, PyAny>>,
        max_steps: Option<&Bound<'_, PyAny>>,
        area: Option<&Bound<'_, PyAny>>,
        keepout: Option<&Bound<'_, PyAny>>,
        max_memory_mb: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let (radius, tool_radius, sensor_range) =
            (real(radius), real(tool_radius), real(sensor_range));
        let max_steps = max_steps
            .filter(|v| !v.is_none())
            .map(|v| uint_arg("max_steps", v, 1))
            .transpose()?;
        let given = max_memory_mb
            .filter(|v| !v.is_none())
            .map(|v| uint_arg("max_memory_mb", v, 1))
            .transpose()?;
        let limit = memory_limit(map, given);
        let map = as_map(py, map, limit)?;
        let radius = radius.unwrap_or(DEFAULT_RADIUS);
        // `start` and `exec` are read as `ccpp.run` reads them (a text start or a number for
        // `exec` was a bare TypeError here, a CcppError there).
        let exec = exec.filter(|v| !v.is_none()).map(exec_arg).transpose()?;
        let exec = match exec_choice(exec.as_deref(), &Names::KEYWORDS).map_err(msg)? {
            Some(true) => Execution::Pid(PidOptions::default()),
            Some(false) | None => Execution::Ideal,
        };
        let start = start
            .filter(|v| !v.is_none())
            .map(|v| start_arg(v).map(|(p, _)| p))
            .transpose()?;
        let area = area.map(parse_area).transpose()?;
        let keepout = keepout.map(parse_keepout).transpose()?.unwrap_or_default();
        // The scenario validates the robot, the sensor range, the execution, the episode cap
        // and the zones.
        let s = Scenario::configure(map.recipe.clone(), PlannerConfig::new(PlannerKind::BaStar))
            .robot(Robot {
                radius,
                tool_radius: tool_radius.unwrap_or(radius),
            })
            .start_pose(start)
            .sim(SimConfig {
                sensor_range,
                exec: Some(exec),
                // The episode cap, validated as a run's (the simulator steps one action at a
                // time here, so only `step` truncates on it).
                max_steps: max_steps.unwrap_or(SimConfig::default().max_steps),
                ..SimConfig::default()
            })
            .zones(area, keepout)
            .max_memory_mb(limit)
            .build()
            .map_err(|e| err(&e))?;
        // What a run of the same robot on the map would hold (the world, the sweep, the known
        // map), against the limit: an episode holds as much.
        let base_bytes = s.check_driven_map(&map).map_err(|e| err(&e))?.bytes;
        let zones = py.detach(|| s.zone_masks(&map)).map_err(|e| err(&e))?;
        // The zones and the start are checked now, not at the first reset.
        py.detach(|| s.world_with_zones(&map, zones.clone()))
            .map_err(|e| err(&e))?;
        Ok(Self {
            scenario: s.clone(),
            zones,
            map,
            robot: s.robot,
            sim: s.sim,
            max_steps,
            base_bytes,
            episode: None,
            ended: false,
            memory_cut: false,
        })
    }

    /// Starts an episode and returns `(observation, info)`. Without `seed` the robot starts
    /// at the configured start (or the widest free spot); with `seed` at a pose drawn from the
    /// free, reachable positions (deterministic for a seed; with zones, inside the area and
    /// outside the keep-outs). A seed is refused for an Env given `start=`: the drawn pose
    /// would replace the start in silence.
    #[pyo3(signature = (seed=None))]
    fn reset(
        &mut self,
        py: Python<'_>,
        seed: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<(Py<PyDict>, Py<PyDict>)> {
        // As `run`'s seed: a `CcppError` naming the range (a negative seed was an
        // `OverflowError`).
        let seed = seed
            .filter(|s| !s.is_none())
            .map(|s| uint_arg("seed", s, 0))
            .transpose()?;
        if let (Some(_), Some([x, y, theta])) = (seed, self.scenario.start) {
            return Err(msg(format!(
                "reset(seed=) draws a random start, and this Env was given start=({}, {}, {}): leave the seed out to start there, or leave start= out to draw starts",
                ccpp_core::display::Compact(x),
                ccpp_core::display::Compact(y),
                ccpp_core::display::Compact(theta)
            )));
        }
        let scenario = &self.scenario;
        let map = &self.map;
        let zones = &self.zones;
        let sim_cfg = self.sim.clone();
        // The GIL stays held (as in every method of an Env): calls from several threads then
        // take turns. Released here, a `step` from another thread met this call's borrow of
        // the Env and raised a bare `RuntimeError: Already borrowed`.
        let episode = (|| -> Result<Episode, ScenarioError> {
            let mut world = scenario.world_with_zones(map, zones.clone())?;
            if let Some(seed) = seed {
                let mut rng = SplitMix64::new(seed);
                let n = world.reachable().count_ones(..);
                let k = (rng.next_u64() % n.max(1) as u64) as usize;
                if let Some(i) = world.reachable().ones().nth(k) {
                    let f = *world.frame();
                    let (c, r) = f.col_row(i);
                    let p = f.pixel_center(c, r);
                    let theta = rng.range(-PI, PI);
                    let mut at = scenario.clone();
                    at.start = Some([p.x, p.y, theta]);
                    world = at.world_with_zones(map, zones.clone())?;
                }
            }
            Ok(Episode::new(world, |w| {
                let f = *w.frame();
                // Where the robot is placed (before an approach to the area).
                let start = w.initial_pose().position();
                let mut sweeper = Sweeper::new(w);
                sweeper.add(start, start);
                let mut live = Live {
                    sim: Simulator::new(w, &sim_cfg),
                    sweeper,
                    known: KnownMap::new(&f),
                    known_codes: vec![Cell::Unknown as u8; f.len()],
                    records_seen: Cursor::default(),
                    last: start,
                    covered: 0,
                    steps: 0,
                    collisions: 0,
                };
                integrate_scan(&mut live, &f);
                sweep_new(&mut live, w);
                live
            }))
        })()
        .map_err(|e| err(&e))?;
        self.episode = Some(episode);
        self.ended = false;
        self.memory_cut = false;
        Ok((self.observation(py)?, self.info(py, false)?))
    }

    /// Executes one action — `("rotate", angle_rad)`, `("translate", distance_m)` or
    /// `("move_to", x, y)` — and returns `(observation, reward, terminated, truncated, info)`:
    /// the reward is the accessible area the action newly swept, in m² (what the start pose
    /// sweeps is in `info["coverage"]` from `reset` on, so an episode's return is the final
    /// swept area less the start's); the episode terminates on a collision (the bumper) or
    /// when every accessible pixel is swept (one whose start already sweeps everything,
    /// `info["coverage"]` 1.0 at `reset`, ends at its first step with reward 0); it is truncated after
    /// `max_steps` actions, or when what the episode holds (its recorded path, with the map's
    /// share) passes `max_memory_mb` (`info["memory_limit"]` is then true). A step after the
    /// episode has ended is refused (call `reset`).
    fn step(&mut self, py: Python<'_>, action: &Bound<'_, PyAny>) -> PyResult<StepResult> {
        let step = parse_action(action)?;
        if self.ended {
            return Err(msg(
                "the episode has ended (terminated or truncated): call reset() before step()",
            ));
        }
        let ep = self
            .episode
            .as_mut()
            .ok_or_else(|| msg("the episode has not begun: call reset() first"))?;
        let (gain, collided, done, steps, trace_bytes) = ep.with_dependent_mut(|world, live| {
            let before = live.covered;
            live.sim.execute(step);
            live.steps += 1;
            let f = *world.frame();
            integrate_scan(live, &f);
            let collided = sweep_new(live, world);
            let done = live.covered >= world.accessible_count();
            (
                (live.covered - before) as f64 * f.resolution * f.resolution,
                collided,
                done,
                live.steps,
                live.sim.trace().heap_bytes(),
            )
        });
        // The episode's trace grows with every step (by about 1 kB a second of PID
        // execution): past the memory limit the episode is truncated, as a run is refused
        // (an Env left stepping grew without bound, 3.5 GB at `max_memory_mb=17`).
        self.memory_cut = self.base_bytes + trace_bytes as f64
            > self.scenario.max_memory_mb as f64 * 1024.0 * 1024.0;
        let truncated = self.memory_cut || self.max_steps.is_some_and(|m| steps >= m);
        self.ended = collided || done || truncated;
        Ok((
            self.observation(py)?,
            gain,
            collided || done,
            truncated,
            self.info(py, collided)?,
        ))
    }

    /// The map.
    #[getter]
    fn map(&self) -> Map {
        Map {
            map: self.map.clone(),
            max_memory_mb: Some(self.scenario.max_memory_mb),
        }
    }

    /// The sensor range in force, metres (a range beyond twice the map's diagonal runs as
    /// that: from anywhere the sensor sees the whole map).
    #[getter]
    fn sensor_range(&self) -> f64 {
        self.sim.sensor_range_on(&self.robot, self.map.grid.frame())
    }

    /// The robot radius, metres.
    #[getter]
    fn radius(&self) -> f64 {
        self.robot.radius
    }

    /// The tool radius, metres.
    #[getter]
    fn tool_radius(&self) -> f64 {
        self.robot.tool_radius
    }

    /// Side of the square `scan` window of observations, pixels.
    #[getter]
    fn scan_side(&self) -> usize {
        2 * window_half(self.sensor_range(), self.map.grid.frame()) + 1
    }

    /// Swept pixels of the episode so far, `bool` `(height, width)` in image layout.
    #[getter]
    fn swept<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<bool>>> {
        let ep = self.episode()?;
        Ok(mask(
            py,
            ep.borrow_owner().frame(),
            ep.borrow_dependent().sweeper.swept(),
        ))
    }

    /// Pixel centres the robot centre can reach from the episode's start (C-free, connected),
    /// `bool` `(height, width)` in image layout.
    #[getter]
    fn reachable<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<bool>>> {
        let ep = self.episode()?;
        let w = ep.borrow_owner();
        Ok(mask(py, w.frame(), w.reachable()))
    }

    /// Pixels the tool can reach from the episode's start, `bool` `(height, width)`.
    #[getter]
    fn accessible<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<bool>>> {
        let ep = self.episode()?;
        let w = ep.borrow_owner();
        Ok(mask(py, w.frame(), w.accessible()))
    }

    /// The metrics of the episode so far (as `ccpp run` computes them; planner `"env"`).
    fn metrics(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let ep = self.episode()?;
        let world = ep.borrow_owner();
        let sim = &ep.borrow_dependent().sim;
        let mut trace: Trace = sim.trace().clone();
        // The tracking error over every control step so far (a run's trace ends with it).
        if let Some(e) = sim.tracking() {
            trace.push_event(0, e);
        }
        let out = RunOutput {
            trace,
            // The episode so far: no early-stop reason in its metrics.
            stop: StopReason::Done,
            tile_side: None,
            planner: "env",
            wall_time_s: 0.0,
        };
        // With the GIL held, as in `reset`.
        let m = metrics::compute(world, &out, &self.map.name);
        to_py(py, &m)
    }
}

/// The lock a sweep holds on its output folder, the same as `ccpp bench`'s
/// ([`ccpp_io::lock`]): taken when made (an error naming the holder's process when another
/// bench or sweep holds it), released, and its file removed, by `release()` or when
/// collected.
#[pyclass(module = "ccpp")]
pub struct FolderLock {
    held: Option<ccpp_io::lock::FolderLock>,
}

#[pymethods]
impl FolderLock {
    /// Takes the lock of the existing folder `folder`.
    #[new]
    fn new(folder: std::path::PathBuf) -> PyResult<Self> {
        let held = ccpp_io::lock::FolderLock::take(&folder).map_err(|e| err(&e))?;
        Ok(Self { held: Some(held) })
    }

    /// Releases the lock and removes its file (again: nothing).
    fn release(&mut self) {
        self.held = None;
    }

    /// Whether the lock is still held.
    #[getter]
    fn held(&self) -> bool {
        self.held.is_some()
    }
}

/// The extension module.
#[pymodule]
fn _ccpp(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("CcppError", m.py().get_type::<CcppError>())?;
    m.add_class::<Map>()?;
    m.add_class::<RunResult>()?;
    m.add_class::<PlanResult>()?;
    m.add_function(wrap_pyfunction!(plan, m)?)?;
    m.add_class::<Env>()?;
    m.add_class::<FolderLock>()?;
    m.add("LOCK_FILE", ccpp_io::lock::LOCK_FILE)?;
    // (ccpp's stamp in every folder it writes: a sweep's folder holds it too)
    m.add("STAMP_FILE", ccpp_io::write::STAMP_FILE)?;
    m.add("STAMP_TEXT", ccpp_io::write::STAMP_TEXT)?;
    m.add("WARNINGS_SEPARATOR", ccpp_io::warnings::SEPARATOR)?;
    m.add_function(wrap_pyfunction!(load_map, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(bench_run, m)?)?;
    m.add_function(wrap_pyfunction!(name_maps, m)?)?;
    m.add_function(wrap_pyfunction!(expand_maps, m)?)?;
    m.add_function(wrap_pyfunction!(check_robot, m)?)?;
    m.add_function(wrap_pyfunction!(planners, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
