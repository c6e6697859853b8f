//! What `save` and `save_points` write beside the geometry into a glTF
//! file (`.glb`, or `.gltf` with its `.bin`): per-vertex colours
//! (`COLOR_0`) and named attributes (`_NAME`), from numpy arrays, checked
//! here so that a bad one is an `InputError` naming the argument, the
//! attribute and the row.

use std::path::Path;

use glam::{Vec2, Vec3};
use pyo3::prelude::*;
use pyo3::types::PyMapping;
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

/// `v` as Python prints a float (`1.0`, `nan`, `inf`).
fn python_float(v: f64) -> String {
    if v.is_nan() {
        "nan".into()
    } else if v.is_infinite() {
        if v > 0.0 { "inf" } else { "-inf" }.into()
    } else if v.fract() == 0.0 && v.abs() < 1e16 {
        format!("{v:.1}")
    } else {
        format!("{v}")
    }
}

fn rows_text(shape: &[usize]) -> String {
    let parts: Vec<String> = shape.iter().map(usize::to_string).collect();
    match parts.len() {
        1 => format!("({},)", parts[0]),
        _ => format!("({})", parts.join(", ")),
    }
}

/// `colors`: `(n, 3)` or `(n, 4)`, floats in `[0, 1]` (linear RGB(A), as
/// glTF's `COLOR_0` is) or `uint8` (8-bit sRGB colours, as trimesh's
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
            if c.iter().any(|v| !(0.0..=1.0).contains(v)) {
                let shown: Vec<String> = c[..s[1]].iter().map(|&v| python_float(v)).collect();
                return Err(Failure::input(format!(
                    "colors: row {i} is [{}], outside [0, 1] (linear colours; scale or clip them)",
                    shown.join(", ")
                ))
                .into());
            }
            Ok(c.map(|v| v as f32))
        })
        .collect()
}

/// `attributes`: a mapping of names to arrays of `n` rows, `(n,)` or
/// `(n, k)` with `k` from 1 to 4, any real dtype, finite. A name is
/// written with glTF's leading underscore and may be given with or
/// without it (`"PHI"` and `"_PHI"` are both `_PHI`).
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
