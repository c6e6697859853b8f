//! What `save` and `save_points` write beside the geometry into a glTF
//! file (`.glb`, or `.gltf` with its `.bin`): per-vertex colours
//! (`COLOR_0`) and named attributes (`_NAME`), from numpy arrays, checked
//! here so that a bad one is an `InputError` naming the argument, the
//! attribute and the row; and the same data back out of a file, as
//! numpy arrays (`Mesh.colors`, `Mesh.attributes`, `trilux.Points`).

use std::path::Path;

use glam::{Vec2, Vec3};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyMapping};
use trilux_io::mesh::gltf::{Attribute, AttributeValues, VertexData};

use crate::arrays;
use crate::error::Failure;

/// Whether `path` names a glTF file (`.glb` or `.gltf`, any case).
pub(crate) fn is_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"))
}

/// The colours and attributes given to a writer of `n` items (named
/// `(one, many)`: `("vertex", "vertices")`, `("point", "points")`), or
/// `None` when neither is. Only glTF keeps them: with another extension
/// they are an error.
pub(crate) fn vertex_data(
    path: &Path,
    colors: Option<&Bound<'_, PyAny>>,
    attributes: Option<&Bound<'_, PyAny>>,
    n: usize,
    items: (&str, &str),
) -> PyResult<Option<VertexData>> {
    let colors = colors.filter(|c| !c.is_none());
    let attributes = attributes.filter(|a| !a.is_none());
    if colors.is_none() && attributes.is_none() {
        return Ok(None);
    }
    if !is_gltf(path) {
        let what = if colors.is_some() {
            "colors"
        } else {
            "attributes"
        };
        return Err(Failure::input(format!(
            "{what}: only glTF files (.glb, .gltf) keep per-vertex colours and attributes, and {} \
             is not one",
            path.display()
        ))
        .into());
    }
    Ok(Some(VertexData {
        colors: colors.map(|c| colours(c, n, items)).transpose()?,
        attributes: attributes
            .map(|a| named(a, n, items))
            .transpose()?
            .unwrap_or_default(),
    }))
}

/// numpy's dtype kind letter and item size of `obj` as an array.
fn dtype(obj: &Bound<'_, PyAny>) -> PyResult<(String, usize, String)> {
    let np = obj.py().import("numpy")?;
    let dtype = np.call_method1("asarray", (obj,))?.getattr("dtype")?;
    Ok((
        dtype.getattr("kind")?.extract()?,
        dtype.getattr("itemsize")?.extract()?,
        dtype.str()?.to_string(),
    ))
}

/// numpy's shape of `obj` as an array.
fn shape(obj: &Bound<'_, PyAny>) -> PyResult<Vec<usize>> {
    let np = obj.py().import("numpy")?;
    np.call_method1("shape", (obj,))?.extract()
}

/// How far outside `[0, 1]` a float colour may be and still be taken,
/// clamped into `[0, 1]`: the rounding of colour arithmetic in float32
/// (a `MeshColors.lookup` interpolating texels of 1.0 gives 1.0000001).
/// trilux-io's glTF writer allows the same; beyond it a colour is an
/// `InputError`.
pub(crate) const COLOR_TOLERANCE: f64 = trilux_io::mesh::gltf::COLOR_SLACK;

/// `v` as Python prints a float (`1.0`, `nan`, `inf`, `-2e-05`, `1e+16`):
/// the shortest digits that read back as `v` (Rust's and Python's
/// `repr` agree on them), in exponent form below 1e-4 and from 1e16.
pub(crate) fn python_float(v: f64) -> String {
    if v.is_nan() {
        "nan".into()
    } else if v.is_infinite() {
        if v > 0.0 { "inf" } else { "-inf" }.into()
    } else if v != 0.0 && !(1e-4..1e16).contains(&v.abs()) {
        // Rust writes `2e-5`, Python `2e-05`: a sign and two digits at least.
        let text = format!("{v:e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        let (sign, digits) = match exponent.strip_prefix('-') {
            Some(d) => ('-', d),
            None => ('+', exponent),
        };
        format!("{mantissa}e{sign}{digits:0>2}")
    } else if v.fract() == 0.0 {
        format!("{v:.1}")
    } else {
        format!("{v}")
    }
}

/// A row of values as Python prints a list of floats: `[0.5, nan, 1.0]`.
pub(crate) fn row_text(values: &[f64]) -> String {
    let shown: Vec<String> = values.iter().map(|&v| python_float(v)).collect();
    format!("[{}]", shown.join(", "))
}

fn rows_text(shape: &[usize]) -> String {
    let parts: Vec<String> = shape.iter().map(usize::to_string).collect();
    match parts.len() {
        1 => format!("({},)", parts[0]),
        _ => format!("({})", parts.join(", ")),
    }
}

/// `colors`: `(n, 3)` or `(n, 4)`, floats in `[0, 1]` (linear RGB(A), as
/// glTF's `COLOR_0` is; within [`COLOR_TOLERANCE`] of it, clamped into
/// it) or `uint8` (8-bit sRGB colours, as trimesh's
/// `visual.vertex_colors`: RGB decoded to linear, alpha scaled).
fn colours(obj: &Bound<'_, PyAny>, n: usize, items: (&str, &str)) -> PyResult<Vec<[f32; 4]>> {
    let (kind, size, name) = dtype(obj)?;
    let eight_bit = kind == "u" && size == 1;
    if kind != "f" && !eight_bit {
        return Err(Failure::input(format!(
            "colors: expected floats in [0, 1] (linear) or uint8 (sRGB), got {name}"
        ))
        .into());
    }
    let s = shape(obj)?;
    let rows: Vec<[f64; 4]> = match s.as_slice() {
        [_, 3] => arrays::rows_f64::<3>(obj, "colors")?
            .into_iter()
            .map(|[r, g, b]| [r, g, b, if eight_bit { 255.0 } else { 1.0 }])
            .collect(),
        [_, 4] => arrays::rows_f64::<4>(obj, "colors")?,
        _ => {
            return Err(Failure::input(format!(
                "colors: expected an array of shape (n, 3) or (n, 4), got shape {}",
                rows_text(&s)
            ))
            .into());
        }
    };
    if rows.len() != n {
        return Err(Failure::input(format!(
            "colors: {} rows for {n} {} (one per {})",
            rows.len(),
            items.1,
            items.0
        ))
        .into());
    }
    rows.iter()
        .enumerate()
        .map(|(i, c)| {
            if eight_bit {
                let decode = |v: f64| trilux_io::image::srgb_to_linear((v / 255.0) as f32);
                return Ok([
                    decode(c[0]),
                    decode(c[1]),
                    decode(c[2]),
                    (c[3] / 255.0) as f32,
                ]);
            }
            let shown = || row_text(&c[..s[1]]);
            if c.iter().any(|v| !v.is_finite()) {
                return Err(
                    Failure::input(format!("colors: row {i} is not finite ({})", shown())).into(),
                );
            }
            let within = -COLOR_TOLERANCE..=1.0 + COLOR_TOLERANCE;
            if c.iter().any(|v| !within.contains(v)) {
                return Err(Failure::input(format!(
                    "colors: row {i} is {}, outside [0, 1] (linear colours; values within \
                     {COLOR_TOLERANCE:e} of it are clamped into it, others must be scaled or \
                     clipped)",
                    shown()
                ))
                .into());
            }
            Ok(c.map(|v| v.clamp(0.0, 1.0) as f32))
        })
        .collect()
}

/// `attributes`: a mapping of names to arrays of `n` rows, `(n,)` or
/// `(n, k)` with `k` from 1 to 4, any real dtype, finite, stored as
/// float32 (glTF attributes may not be 32-bit integers): floats are
/// rounded to float32, integers must be exact in it (every integer up
/// to 2^24 in magnitude is; [`inexact_integer`]). A name is written with
/// glTF's leading underscore and may be given with or without it
/// (`"PHI"` and `"_PHI"` are both `_PHI`).
fn named(obj: &Bound<'_, PyAny>, n: usize, items: (&str, &str)) -> PyResult<Vec<Attribute>> {
    let mapping = obj.cast::<PyMapping>().map_err(|_| {
        Failure::input("attributes: expected a dict of names to arrays, e.g. {\"PHI\": phi}")
    })?;
    let mut out: Vec<Attribute> = Vec::new();
    for item in mapping.items()?.iter() {
        let (key, values): (Bound<'_, PyAny>, Bound<'_, PyAny>) = item.extract()?;
        let given: String = key.extract().map_err(|_| {
            Failure::input(format!(
                "attributes: the key {} is not a str",
                key.repr().map(|r| r.to_string()).unwrap_or_default()
            ))
        })?;
        // As Python shows it: 'PHI'.
        let shown = key.repr()?.to_string();
        let name = given.strip_prefix('_').unwrap_or(&given).to_string();
        let ok = |c: char| c.is_ascii_alphanumeric() || c == '_';
        if name.is_empty() || !name.chars().all(ok) {
            return Err(Failure::input(format!(
                "attributes: the name {shown} may hold only ASCII letters, digits and '_' \
                 (glTF's _NAME attributes)"
            ))
            .into());
        }
        if out.iter().any(|a| a.name == name) {
            return Err(Failure::input(format!(
                "attributes: {shown} names the attribute _{name} a second time"
            ))
            .into());
        }
        let what = format!("attributes[{shown}]");
        let s = shape(&values)?;
        let array = values.clone();
        let to3 = |r: [f64; 3]| Vec3::new(r[0] as f32, r[1] as f32, r[2] as f32);
        let values = match s.as_slice() {
            [_] => AttributeValues::Scalar(
                arrays::values_f64(&values, &what)?
                    .into_iter()
                    .map(|v| v as f32)
                    .collect(),
            ),
            [_, 1] => AttributeValues::Scalar(
                arrays::rows_f64::<1>(&values, &what)?
                    .into_iter()
                    .map(|[v]| v as f32)
                    .collect(),
            ),
            [_, 2] => AttributeValues::Vec2(
                arrays::rows_f64::<2>(&values, &what)?
                    .into_iter()
                    .map(|[a, b]| Vec2::new(a as f32, b as f32))
                    .collect(),
            ),
            [_, 3] => AttributeValues::Vec3(
                arrays::rows_f64::<3>(&values, &what)?
                    .into_iter()
                    .map(to3)
                    .collect(),
            ),
            [_, 4] => AttributeValues::Vec4(
                arrays::rows_f64::<4>(&values, &what)?
                    .into_iter()
                    .map(|r| r.map(|v| v as f32))
                    .collect(),
            ),
            _ => {
                return Err(Failure::input(format!(
                    "{what}: expected an array of shape (n,) or (n, k) with k from 1 to 4, got \
                     shape {}",
                    rows_text(&s)
                ))
                .into());
            }
        };
        if values.len() != n {
            return Err(Failure::input(format!(
                "{what}: {} rows for {n} {} (one per {})",
                values.len(),
                items.1,
                items.0
            ))
            .into());
        }
        let k = values.components();
        if let Some((i, v)) = inexact_integer(&array)? {
            return Err(Failure::input(format!(
                "{what}: row {} holds the integer {v}, which float32 (the type of glTF \
                 attributes) cannot hold exactly (every integer up to 2**24 = 16777216 in \
                 magnitude is exact, larger ones only some); give the array as floats to accept \
                 the rounding",
                i / k
            ))
            .into());
        }
        if let Some(i) = values.flat().iter().position(|v| !v.is_finite()) {
            return Err(Failure::input(format!(
                "{what}: row {} is not finite (in float32, as glTF stores it)",
                i / k
            ))
            .into());
        }
        out.push(Attribute { name, values });
    }
    Ok(out)
}

/// The first value of an integer array (numpy kind `i` or `u`) that
/// float32 does not hold exactly, with its index in the flattened array;
/// `None` for an array of another kind or one whose every value is exact.
fn inexact_integer(obj: &Bound<'_, PyAny>) -> PyResult<Option<(usize, i128)>> {
    let (kind, _, _) = dtype(obj)?;
    let exact = |v: i128| (v as f32) as i128 == v;
    let np = obj.py().import("numpy")?;
    let flat = |dtype: &str| -> PyResult<Bound<'_, PyAny>> {
        np.call_method1("ascontiguousarray", (obj, dtype))?
            .call_method0("ravel")
    };
    Ok(match kind.as_str() {
        "u" => {
            let a = flat("uint64")?;
            let a = a.cast::<PyArray1<u64>>()?.readonly();
            a.as_slice()?
                .iter()
                .map(|&v| i128::from(v))
                .enumerate()
                .find(|&(_, v)| !exact(v))
        }
        "i" => {
            let a = flat("int64")?;
            let a = a.cast::<PyArray1<i64>>()?.readonly();
            a.as_slice()?
                .iter()
                .map(|&v| i128::from(v))
                .enumerate()
                .find(|&(_, v)| !exact(v))
        }
        _ => None,
    })
}

/// Colours as stored (linear RGBA in `[0, 1]`) as numpy float32:
/// `(n, 3)` when every alpha is 1 (the glTF writer then writes `VEC3`),
/// else `(n, 4)`.
pub(crate) fn colours_out<'py>(
    py: Python<'py>,
    colors: &[[f32; 4]],
) -> PyResult<Bound<'py, PyAny>> {
    if colors.iter().all(|c| c[3] == 1.0) {
        let data = colors.iter().flat_map(|c| [c[0], c[1], c[2]]).collect();
        crate::arrays::matrix(py, data, 3)
    } else {
        let data = colors.iter().flatten().copied().collect();
        crate::arrays::matrix(py, data, 4)
    }
}

/// Attributes as a dict of names (without glTF's underscore) to float32
/// arrays: `(n,)` for a `SCALAR`, `(n, k)` for a `VECk`, in the file's
/// order.
pub(crate) fn attributes_out<'py>(
    py: Python<'py>,
    attributes: &[Attribute],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for a in attributes {
        let k = a.values.components();
        let flat = a.values.flat();
        let array = if k == 1 {
            crate::arrays::vector(py, flat)
        } else {
            crate::arrays::matrix(py, flat, k)?
        };
        d.set_item(&a.name, array)?;
    }
    Ok(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values in messages read as Python prints them.
    #[test]
    fn floats_are_shown_as_python_prints_them() {
        let cases = [
            (1.0, "1.0"),
            (-0.0, "-0.0"),
            (0.5, "0.5"),
            (1.0000001192092896, "1.0000001192092896"),
            (1.00002, "1.00002"),
            (-2e-5, "-2e-05"),
            (1.5e-7, "1.5e-07"),
            (1e-4, "0.0001"),
            (1e16, "1e+16"),
            (1.25e300, "1.25e+300"),
            (123456.0, "123456.0"),
            (f64::NAN, "nan"),
            (f64::NEG_INFINITY, "-inf"),
        ];
        for (v, text) in cases {
            assert_eq!(python_float(v), text, "{v}");
        }
        assert_eq!(row_text(&[0.5, f64::NAN, 0.5]), "[0.5, nan, 0.5]");
    }
}
