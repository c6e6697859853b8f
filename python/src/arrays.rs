//! numpy in and out: any array-like of a real dtype, any strides, into
//! the plain Rust data the crates take; owned Rust vectors back out as
//! numpy arrays without a copy.

use numpy::ndarray::{Array1, Array2, Array3, ArrayViewD};
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods};
use pyo3::prelude::*;

use crate::error::Failure;

/// `obj` as a numpy array of `dtype` ("float64", "float32", "int64"),
/// after checking that its own dtype is one of `kinds` (numpy's kind
/// letters: `f` float, `i` signed, `u` unsigned, `b` bool). A float array
/// given as indices is refused rather than truncated.
fn as_array<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
    kinds: &str,
    dtype: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let np = obj.py().import("numpy")?;
    let arr = np.call_method1("asarray", (obj,))?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    if !kinds.contains(kind.as_str()) {
        let name = dtype_text(&arr.getattr("dtype")?)?;
        let wanted = if kinds.contains('f') {
            "a real (float or integer) dtype"
        } else {
            "an integer dtype"
        };
        return Err(Failure::input(format!("{what}: expected {wanted}, got {name}")).into());
    }
    np.call_method1("asarray", (arr, dtype))
}

/// A dtype as numpy prints it (`float64`, `<U168`, `object`), with what
/// its kind is where the code alone does not say (numpy's `dtype.name`
/// would say `str672`, the bits of a 168-character string).
fn dtype_text(dtype: &Bound<'_, PyAny>) -> PyResult<String> {
    let text = dtype.str()?.to_string();
    let kind: String = dtype.getattr("kind")?.extract()?;
    let what = match kind.as_str() {
        "U" | "S" => " (strings)",
        "O" => " (Python objects)",
        "c" => " (complex numbers)",
        "M" | "m" => " (dates or times)",
        "V" => " (structured records)",
        _ => "",
    };
    Ok(format!("{text}{what}"))
}

fn shape_text(shape: &[usize]) -> String {
    let parts: Vec<String> = shape.iter().map(usize::to_string).collect();
    if parts.len() == 1 {
        format!("({},)", parts[0])
    } else {
        format!("({})", parts.join(", "))
    }
}

/// Checks that `view` has `ndim` axes and, for each `Some(k)` of `cols`,
/// that the axis has length `k`.
fn check_shape<T>(
    view: &ArrayViewD<'_, T>,
    what: &str,
    expected: &str,
    cols: &[Option<usize>],
) -> PyResult<()> {
    let shape = view.shape();
    let ok = shape.len() == cols.len()
        && shape
            .iter()
            .zip(cols)
            .all(|(&s, c)| c.is_none_or(|c| c == s));
    if ok {
        Ok(())
    } else {
        Err(Failure::input(format!(
            "{what}: expected an array of shape {expected}, got shape {}",
            shape_text(shape)
        ))
        .into())
    }
}

/// An `(n, K)` array of reals as `n` rows of `f64`.
pub(crate) fn rows_f64<const K: usize>(
    obj: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<Vec<[f64; K]>> {
    let arr = as_array(obj, what, "fiub", "float64")?;
    let arr = arr.cast::<PyArrayDyn<f64>>()?.readonly();
    let view = arr.as_array();
    check_shape(&view, what, &format!("(n, {K})"), &[None, Some(K)])?;
    Ok(view
        .rows()
        .into_iter()
        .map(|r| std::array::from_fn(|k| r[k]))
        .collect())
}

/// A 1-D array of reals as `f64` (a scalar counts as one value).
pub(crate) fn values_f64(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    let arr = as_array(obj, what, "fiub", "float64")?;
    let arr = arr.cast::<PyArrayDyn<f64>>()?.readonly();
    let view = arr.as_array();
    if view.ndim() == 0 {
        return Ok(view.iter().copied().collect());
    }
    check_shape(&view, what, "(n,)", &[None])?;
    Ok(view.iter().copied().collect())
}

/// A 1-D array of integers as `i64`.
pub(crate) fn values_i64(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<i64>> {
    let arr = as_array(obj, what, "iub", "int64")?;
    let arr = arr.cast::<PyArrayDyn<i64>>()?.readonly();
    let view = arr.as_array();
    if view.ndim() == 0 {
        return Ok(view.iter().copied().collect());
    }
    check_shape(&view, what, "(n,)", &[None])?;
    Ok(view.iter().copied().collect())
}

/// An `(m, K)` array of integer indices into `count` items, as `u32`
/// rows; a negative index or one `>= count` is an error naming the row.
pub(crate) fn index_rows<const K: usize>(
    obj: &Bound<'_, PyAny>,
    what: &str,
    count: usize,
    (item, items): (&str, &str),
) -> PyResult<Vec<[u32; K]>> {
    let arr = as_array(obj, what, "iu", "int64")?;
    let arr = arr.cast::<PyArrayDyn<i64>>()?.readonly();
    let view = arr.as_array();
    check_shape(&view, what, &format!("(m, {K})"), &[None, Some(K)])?;
    let mut out = Vec::with_capacity(view.shape()[0]);
    for (row, r) in view.rows().into_iter().enumerate() {
        let mut tri = [0u32; K];
        for (k, slot) in tri.iter_mut().enumerate() {
            let v = r[k];
            if v < 0 || v as u64 >= count as u64 {
                return Err(Failure::input(format!(
                    "{what}: row {row} references {item} {v}, but there are only {count} {items}"
                ))
                .into());
            }
            *slot = v as u32;
        }
        out.push(tri);
    }
    Ok(out)
}

/// A PIL image whose array is not colour values — a palette image's
/// indices (mode `P`, `PA`; trimesh keeps palette PNGs so), or CMYK,
/// YCbCr, LAB, HSV channels — converted to RGB (RGBA with transparency)
/// first, as PIL shows it; anything else is returned as it is.
fn pil_as_colours<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    // Not a PIL image, or one that cannot be touched (trimesh's placeholder
    // without Pillow): numpy's conversion below reports it.
    let Some(mode) = obj
        .getattr("mode")
        .ok()
        .and_then(|m| m.extract::<String>().ok())
    else {
        return Ok(obj.clone());
    };
    let transparent = || -> bool {
        obj.getattr("info")
            .and_then(|info| info.contains("transparency"))
            .unwrap_or(false)
    };
    let target = match mode.as_str() {
        "PA" => "RGBA",
        "P" if transparent() => "RGBA",
        "P" | "CMYK" | "YCbCr" | "LAB" | "HSV" => "RGB",
        _ => return Ok(obj.clone()),
    };
    obj.call_method1("convert", (target,))
}

/// An image as a numpy array: `(H, W)` or `(H, W, C)` with `C` in 1..=4,
/// any real dtype; integers are scaled to `[0, 1]` by their type's maximum
/// (`uint8` by 255, `uint16` by 65535). Returns width, height, channels
/// and the values row-major, row 0 first, and whether they were integers.
pub(crate) struct ImageArray {
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) channels: usize,
    pub(crate) values: Vec<f32>,
    pub(crate) integer: bool,
}

pub(crate) fn image_array(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<ImageArray> {
    let np = obj.py().import("numpy")?;
    let obj = pil_as_colours(obj)?;
    let arr = np.call_method1("asarray", (&obj,))?;
    let dtype = arr.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    let scale = match kind.as_str() {
        "f" => 1.0,
        "u" | "i" => {
            let info = np.call_method1("iinfo", (&dtype,))?;
            let max: f64 = info.getattr("max")?.extract()?;
            1.0 / max
        }
        "b" => 1.0,
        _ => {
            let name = dtype_text(&dtype)?;
            return Err(
                Failure::input(format!("{what}: expected a real dtype, got {name}")).into(),
            );
        }
    };
    let arr = np.call_method1("asarray", (arr, "float64"))?;
    let arr = arr.cast::<PyArrayDyn<f64>>()?.readonly();
    let view = arr.as_array();
    let shape = view.shape().to_vec();
    let (height, width, channels) = match shape.as_slice() {
        [h, w] => (*h, *w, 1),
        [h, w, c] if (1..=4).contains(c) => (*h, *w, *c),
        _ => {
            return Err(Failure::input(format!(
                "{what}: expected an image of shape (H, W) or (H, W, C) with C in 1..4, got shape {}",
                shape_text(&shape)
            ))
            .into());
        }
    };
    if width == 0 || height == 0 {
        return Err(Failure::input(format!(
            "{what}: the image is {width}×{height}: it has no pixels"
        ))
        .into());
    }
    Ok(ImageArray {
        width,
        height,
        channels,
        values: view.iter().map(|&x| (x * scale) as f32).collect(),
        integer: kind != "f",
    })
}

/// `n × K` values as an `(n, K)` array.
pub(crate) fn matrix<'py, T: numpy::Element>(
    py: Python<'py>,
    data: Vec<T>,
    cols: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let rows = data.len().checked_div(cols).unwrap_or(0);
    let a = Array2::from_shape_vec((rows, cols), data)
        .map_err(|e| Failure::input(format!("internal shape error: {e}")))?;
    Ok(a.into_pyarray(py).into_any())
}

/// Unit vectors (normals) as an `(n, 3)` float64 array.
pub(crate) fn vectors<'py>(py: Python<'py>, v: &[glam::Vec3]) -> PyResult<Bound<'py, PyAny>> {
    let data = v.iter().flat_map(|v| v.as_dvec3().to_array()).collect();
    matrix(py, data, 3)
}

/// Texture coordinates in trilux's convention (v down) as the `(n, 2)`
/// float64 array Python gets, OpenGL's convention (`v = 0` at the image's
/// bottom row, as trimesh's `visual.uv`).
pub(crate) fn uvs<'py>(py: Python<'py>, uv: &[glam::Vec2]) -> PyResult<Bound<'py, PyAny>> {
    let data = uv
        .iter()
        .flat_map(|t| [f64::from(t.x), 1.0 - f64::from(t.y)])
        .collect();
    matrix(py, data, 2)
}

/// Positions stored relative to `origin` (`f32`, as trilux-io's meshes
/// hold them) as an `(n, 3)` float64 array in the file's coordinates:
/// `origin` added back in `f64`.
pub(crate) fn absolute_positions<'py>(
    py: Python<'py>,
    origin: glam::DVec3,
    positions: &[glam::Vec3],
) -> PyResult<Bound<'py, PyAny>> {
    let data = positions
        .iter()
        .flat_map(|p| (origin + p.as_dvec3()).to_array())
        .collect();
    matrix(py, data, 3)
}

/// Index rows (triangles, tetrahedra) as an `(m, K)` int64 array, the
/// dtype trimesh and numpy indexing use.
pub(crate) fn index_matrix<'py, const K: usize>(
    py: Python<'py>,
    rows: &[[u32; K]],
) -> PyResult<Bound<'py, PyAny>> {
    let data = rows.iter().flatten().map(|&v| i64::from(v)).collect();
    matrix(py, data, K)
}

/// An integer argument as the caller gave it. Extraction never fails, so
/// that the function, which knows the argument's name, says what was
/// wrong: PyO3's own message (`'float' object cannot be interpreted as an
/// integer`) names no argument. A Python `int` or anything with
/// `__index__` (numpy's integers) is an integer; `bool` is not, though
/// Python makes it an `int` subclass (`count=True` is a slip, not 1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Int {
    /// The value.
    Value(i128),
    /// An integer beyond `i128`, as Python prints it.
    Huge(String),
    /// Not an integer: the type's name.
    Wrong(String),
}

impl<'a, 'py> FromPyObject<'a, 'py> for Int {
    type Error = PyErr;

    fn extract(obj: pyo3::Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if obj.is_instance_of::<pyo3::types::PyBool>() {
            return Ok(Self::Wrong("bool".into()));
        }
        match obj.extract::<i128>() {
            Ok(v) => Ok(Self::Value(v)),
            Err(e) if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(obj.py()) => {
                Ok(Self::Huge(obj.str()?.to_string()))
            }
            Err(_) => Ok(Self::Wrong(obj.get_type().name()?.to_string())),
        }
    }
}

impl Int {
    /// The value, or a `TypeError` naming the argument `what` and the type
    /// given (`count must be an int, got float`); beyond `i128`, a
    /// `trilux.InputError` with `range`, the values `what` takes.
    pub(crate) fn value(&self, what: &str, range: &str) -> PyResult<i128> {
        match self {
            Self::Value(v) => Ok(*v),
            Self::Huge(text) => {
                Err(Failure::input(format!("{what}: {text} is not in {range}")).into())
            }
            Self::Wrong(ty) => Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "{what} must be an int, got {ty}"
            ))),
        }
    }

    /// The value as a `T` (an unsigned or small integer type), else an
    /// error naming `what`, the value and `range` (as Python writes
    /// ranges, e.g. `0..2**32`).
    pub(crate) fn to<T: TryFrom<i128>>(&self, what: &str, range: &str) -> PyResult<T> {
        let v = self.value(what, range)?;
        T::try_from(v).map_err(|_| Failure::input(format!("{what}: {v} is not in {range}")).into())
    }
}

/// A `seed` argument as the `u64` the samplers seed their generators
/// with: 0 when not given (or `None`), an error naming it when it is not
/// an integer or outside `0..2**64`.
pub(crate) fn seed(seed: Option<&Int>) -> PyResult<u64> {
    match seed {
        None => Ok(0),
        Some(s) => s.to("seed", "0..2**64"),
    }
}

/// A count argument named `what` as a `usize`: a `TypeError` naming it
/// when it is not an integer, a `trilux.InputError` when negative (or
/// beyond the address space).
pub(crate) fn count(count: &Int, what: &str) -> PyResult<usize> {
    let n = match count {
        Int::Huge(text) => {
            return Err(Failure::input(format!("{what}: {text} is too large a count")).into());
        }
        _ => count.value(what, "0 or more")?,
    };
    usize::try_from(n).map_err(|_| {
        let why = if n < 0 {
            "is not a count (0 or more)"
        } else {
            "is too large a count"
        };
        Failure::input(format!("{what}: {n} {why}")).into()
    })
}

/// A vector as a 1-D array.
pub(crate) fn vector<'py, T: numpy::Element>(py: Python<'py>, data: Vec<T>) -> Bound<'py, PyAny> {
    Array1::from_vec(data).into_pyarray(py).into_any()
}

/// `h × w × c` values as an `(h, w, c)` array.
pub(crate) fn image<'py, T: numpy::Element>(
    py: Python<'py>,
    data: Vec<T>,
    h: usize,
    w: usize,
    c: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let a = Array3::from_shape_vec((h, w, c), data)
        .map_err(|e| Failure::input(format!("internal shape error: {e}")))?;
    Ok(a.into_pyarray(py).into_any())
}

/// Whether `obj` is a `str` or an `os.PathLike` (a file to read).
pub(crate) fn is_path(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    if obj.is_instance_of::<pyo3::types::PyString>() {
        return Ok(true);
    }
    let os = obj.py().import("os")?;
    obj.is_instance(&os.getattr("PathLike")?)
}
