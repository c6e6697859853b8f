//! USD text (`.usda`): the curves as a `BasisCurves` prim of `type =
//! "linear"` (`curveVertexCounts`, `points`, per-point `widths`) and
//! their roots as a `Points` prim (`points`, `normals`, `widths`, `ids`),
//! under one `Xform` that is the stage's default prim; the stage states
//! `metersPerUnit` and `upAxis`. Blender (`wm.usd_import`) and Houdini
//! import both. Root data goes on the curves as `uniform` primvars:
//! `primvars:st` (texture coordinate, USD's v up: `1 - v` of
//! [`Curves::uvs`]), `primvars:surface_face` (`int`),
//! `primvars:surface_barycentric` (`float3`) and
//! `primvars:surface_normal` (`normal3f`).
//!
//! A small writer of the text format (the `openusd` crate needs a newer
//! Rust than this workspace's): values are written in Rust's shortest
//! round-trip form, so `f32` values read back bit-identical.

use std::fmt::Display;
use std::io::{BufWriter, Write};
use std::path::Path;

use super::Curves;
use crate::error::{Error, Result};

/// The stage metadata of a written file.
#[derive(Debug, Clone, PartialEq)]
pub struct Stage {
    /// Metres per unit of the coordinates (1: metres; 0.01: centimetres).
    pub meters_per_unit: f64,
    /// The up axis: `"Y"` (glTF, OBJ and Blender's USD export) or `"Z"`.
    pub up_axis: UpAxis,
    /// The default prim's name (a USD identifier).
    pub name: String,
    /// Whether to write the roots as a `Points` prim.
    pub roots: bool,
}

/// USD's `upAxis`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UpAxis {
    /// `"Y"`.
    #[default]
    Y,
    /// `"Z"`.
    Z,
}

impl Default for Stage {
    /// Metres, Y up, prim `hair`, with the roots.
    fn default() -> Self {
        Stage {
            meters_per_unit: 1.0,
            up_axis: UpAxis::Y,
            name: "hair".into(),
            roots: true,
        }
    }
}

/// Writes `curves` as a `.usda` file (streamed: no copy of the text in memory).
///
/// # Errors
/// As [`Curves::check`]; a `meters_per_unit` that is not finite and
/// positive or a name that is not a USD identifier; an I/O error.
pub fn write(path: impl AsRef<Path>, curves: &Curves, stage: &Stage) -> Result<()> {
    let path = path.as_ref();
    curves.check(path)?;
    let invalid = |what: String| Error::new(path, crate::ErrorKind::InvalidInput(what));
    if !(stage.meters_per_unit.is_finite() && stage.meters_per_unit > 0.0) {
        return Err(invalid(format!(
            "metersPerUnit {} must be finite and > 0",
            stage.meters_per_unit
        )));
    }
    let identifier = |s: &str| {
        s.chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
    };
    if !identifier(&stage.name) {
        return Err(invalid(format!(
            "prim name {:?} is not a USD identifier (a letter or '_', then letters, digits, '_')",
            stage.name
        )));
    }
    if let Some(c) = curves
        .faces
        .as_ref()
        .and_then(|f| f.iter().position(|&f| i32::try_from(f).is_err()))
    {
        return Err(invalid(format!(
            "curve {c}'s root face does not fit USD's int (below 2^31)"
        )));
    }
    let file = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
    let mut out = BufWriter::with_capacity(1 << 20, file);
    text(&mut out, curves, stage)
        .and_then(|()| out.flush())
        .map_err(|e| Error::io(path, e))
}

/// The whole text.
fn text(out: &mut impl Write, curves: &Curves, stage: &Stage) -> std::io::Result<()> {
    let up = match stage.up_axis {
        UpAxis::Y => "Y",
        UpAxis::Z => "Z",
    };
    writeln!(out, "#usda 1.0")?;
    writeln!(out, "(")?;
    writeln!(out, "    defaultPrim = \"{}\"", stage.name)?;
    writeln!(
        out,
        "    doc = \"written by trilux-io {}\"",
        env!("CARGO_PKG_VERSION")
    )?;
    writeln!(out, "    metersPerUnit = {}", stage.meters_per_unit)?;
    writeln!(out, "    upAxis = \"{up}\"")?;
    writeln!(out, ")")?;
    writeln!(out)?;
    writeln!(out, "def Xform \"{}\"", stage.name)?;
    writeln!(out, "{{")?;
    writeln!(out, "    def BasisCurves \"strands\"")?;
    writeln!(out, "    {{")?;
    writeln!(out, "        uniform token type = \"linear\"")?;
    array(
        out,
        None,
        "int[] curveVertexCounts",
        &curves.counts,
        |o, c| write!(o, "{c}"),
    )?;
    array(out, None, "point3f[] points", &curves.points, |o, p| {
        tuple(o, &p.to_array())
    })?;
    if let Some(widths) = &curves.widths {
        array(out, Some("vertex"), "float[] widths", widths, |o, w| {
            write!(o, "{w}")
        })?;
    }
    if let Some(uvs) = &curves.uvs {
        array(
            out,
            Some("uniform"),
            "texCoord2f[] primvars:st",
            uvs,
            |o, t| tuple(o, &[t.x, 1.0 - t.y]),
        )?;
    }
    if let Some(faces) = &curves.faces {
        array(
            out,
            Some("uniform"),
            "int[] primvars:surface_face",
            faces,
            |o, f| write!(o, "{f}"),
        )?;
    }
    if let Some(b) = &curves.barycentrics {
        array(
            out,
            Some("uniform"),
            "float3[] primvars:surface_barycentric",
            b,
            |o, b| tuple(o, b),
        )?;
    }
    if let Some(n) = &curves.normals {
        array(
            out,
            Some("uniform"),
            "normal3f[] primvars:surface_normal",
            n,
            |o, n| tuple(o, &n.to_array()),
        )?;
    }
    writeln!(out, "    }}")?;
    if stage.roots {
        roots(out, curves)?;
    }
    writeln!(out, "}}")
}

/// The roots as a `Points` prim: each curve's first point, its normal,
/// its width and its index as the id.
fn roots(out: &mut impl Write, curves: &Curves) -> std::io::Result<()> {
    let first = curves.offsets();
    writeln!(out)?;
    writeln!(out, "    def Points \"roots\"")?;
    writeln!(out, "    {{")?;
    array(out, None, "point3f[] points", &first, |o, &i| {
        tuple(o, &curves.points[i].to_array())
    })?;
    if let Some(n) = &curves.normals {
        array(out, Some("vertex"), "normal3f[] normals", n, |o, n| {
            tuple(o, &n.to_array())
        })?;
    }
    if let Some(widths) = &curves.widths {
        array(out, Some("vertex"), "float[] widths", &first, |o, &i| {
            write!(o, "{}", widths[i])
        })?;
    }
    let ids: Vec<usize> = (0..first.len()).collect();
    array(out, None, "int64[] ids", &ids, |o, i| write!(o, "{i}"))?;
    writeln!(out, "    }}")
}

/// `        TYPE NAME = [a, b, …]`, with its `interpolation` metadata when given.
fn array<T>(
    out: &mut impl Write,
    interpolation: Option<&str>,
    declaration: &str,
    values: &[T],
    mut item: impl FnMut(&mut dyn Write, &T) -> std::io::Result<()>,
) -> std::io::Result<()> {
    write!(out, "        {declaration} = [")?;
    for (i, v) in values.iter().enumerate() {
        if i > 0 {
            out.write_all(b", ")?;
        }
        item(out, v)?;
    }
    match interpolation {
        Some(kind) => writeln!(
            out,
            "] (\n            interpolation = \"{kind}\"\n        )"
        ),
        None => writeln!(out, "]"),
    }
}

/// `(a, b, c)`.
fn tuple<T: Display>(out: &mut dyn Write, values: &[T]) -> std::io::Result<()> {
    out.write_all(b"(")?;
    for (i, v) in values.iter().enumerate() {
        if i > 0 {
            out.write_all(b", ")?;
        }
        write!(out, "{v}")?;
    }
    out.write_all(b")")
}
