//! Curves (hair strands, fur, grass blades) as polylines, and the files
//! artists import them from: USD text ([`usda`]: `BasisCurves` and the
//! roots as `Points`, which Blender and Houdini import), Cem Yuksel's
//! `.hair` ([`hair`], read by research renderers), and glTF lines plus
//! root points ([`write_gltf`]: one `LINES` primitive, since a
//! `LINE_STRIP` primitive per strand would be millions of primitives).
//! [`write()`] picks the format by extension.
//!
//! Alembic is not written: there is no usable Rust writer.

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::error::{Error, ErrorKind, Result};

pub mod hair;
pub mod usda;

/// Curves as plain data: curve `c` is the run of `counts[c]` consecutive
/// points of [`points`](Self::points), root first; per-curve root data
/// (where each curve is attached to a surface) is optional.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Curves {
    /// All curves' points, in the file's unit.
    pub points: Vec<Vec3>,
    /// Points per curve (each at least 2); they sum to `points.len()`.
    pub counts: Vec<u32>,
    /// Per-point widths (diameters, USD's convention), when known.
    pub widths: Option<Vec<f32>>,
    /// Per-curve triangle the root lies on.
    pub faces: Option<Vec<u32>>,
    /// Per-curve barycentric coordinates of the root in its triangle.
    pub barycentrics: Option<Vec<[f32; 3]>>,
    /// Per-curve unit surface normal at the root.
    pub normals: Option<Vec<Vec3>>,
    /// Per-curve texture coordinate of the root (glTF's v-down convention,
    /// as [`TriMesh::uvs`](crate::mesh::TriMesh::uvs); USD's v-up `st` is
    /// `1 - v`).
    pub uvs: Option<Vec<Vec2>>,
}

impl Curves {
    /// `counts.len()` curves of `points_per_curve` points each.
    pub fn uniform(points: Vec<Vec3>, points_per_curve: u32) -> Self {
        let n = if points_per_curve == 0 {
            0
        } else {
            points.len() / points_per_curve as usize
        };
        Curves {
            points,
            counts: vec![points_per_curve; n],
            ..Curves::default()
        }
    }

    /// The index of each curve's first point (its root).
    pub fn offsets(&self) -> Vec<usize> {
        let mut at = 0usize;
        self.counts
            .iter()
            .map(|&c| {
                let first = at;
                at += c as usize;
                first
            })
            .collect()
    }

    /// `Err` naming what is inconsistent: counts below 2 or not summing to
    /// the points, per-point or per-curve arrays of the wrong length,
    /// non-finite values, negative widths.
    pub fn check(&self, path: &Path) -> Result<()> {
        let invalid = |what: String| Err(Error::new(path, ErrorKind::InvalidInput(what)));
        if let Some(c) = self.counts.iter().position(|&c| c < 2) {
            return invalid(format!(
                "curve {c} has {} point(s); a curve needs at least 2",
                self.counts[c]
            ));
        }
        let total: u64 = self.counts.iter().map(|&c| u64::from(c)).sum();
        if total != self.points.len() as u64 {
            return invalid(format!(
                "the curves' counts sum to {total} points, and there are {}",
                self.points.len()
            ));
        }
        if let Some(i) = self.points.iter().position(|p| !p.is_finite()) {
            return invalid(format!("point {i} is not finite"));
        }
        if let Some(widths) = &self.widths {
            if widths.len() != self.points.len() {
                return invalid(format!(
                    "{} widths for {} points",
                    widths.len(),
                    self.points.len()
                ));
            }
            if let Some(i) = widths.iter().position(|w| !(w.is_finite() && *w >= 0.0)) {
                return invalid(format!(
                    "the width of point {i} is {}: widths must be finite and >= 0",
                    widths[i]
                ));
            }
        }
        let n = self.counts.len();
        let lengths = [
            ("root faces", self.faces.as_ref().map(Vec::len)),
            (
                "root barycentrics",
                self.barycentrics.as_ref().map(Vec::len),
            ),
            ("root normals", self.normals.as_ref().map(Vec::len)),
            ("root UVs", self.uvs.as_ref().map(Vec::len)),
        ];
        for (what, len) in lengths {
            if let Some(len) = len.filter(|&l| l != n) {
                return invalid(format!("{len} {what} for {n} curves"));
            }
        }
        let finite = [
            (
                "barycentrics",
                self.barycentrics
                    .as_ref()
                    .and_then(|b| b.iter().position(|b| !b.iter().all(|v| v.is_finite()))),
            ),
            (
                "normal",
                self.normals
                    .as_ref()
                    .and_then(|v| v.iter().position(|v| !v.is_finite())),
            ),
            (
                "UV",
                self.uvs
                    .as_ref()
                    .and_then(|v| v.iter().position(|v| !v.is_finite())),
            ),
        ];
        for (what, bad) in finite {
            if let Some(c) = bad {
                return invalid(format!("the root {what} of curve {c} is not finite"));
            }
        }
        Ok(())
    }
}

/// Writes `curves` in the format of `path`'s extension: `.usda`
/// ([`usda::write`] with [`usda::Stage::default`]), `.hair`
/// ([`hair::write`]), `.glb` or `.gltf` ([`write_gltf`]).
///
/// # Errors
/// An unknown extension, inconsistent curves ([`Curves::check`]), what
/// the format cannot hold, or an I/O error; each names the file.
pub fn write(path: impl AsRef<Path>, curves: &Curves) -> Result<()> {
    let path = path.as_ref();
    match crate::error::extension(path).as_str() {
        // `.usd` may be text or binary USD; readers take either.
        "usda" | "usd" => usda::write(path, curves, &usda::Stage::default()),
        "hair" => hair::write(path, curves),
        "glb" | "gltf" => write_gltf(path, curves),
        other => Err(Error::new(
            path,
            ErrorKind::UnknownExtension(other.to_string(), ".usda, .usd, .hair, .glb, .gltf"),
        )),
    }
}

/// Writes `curves` as glTF (`.glb`, or `.gltf` + `.bin`): one `LINES`
/// primitive whose index pairs join consecutive points of each curve
/// (glTF has no multi-strip primitive, and one `LINE_STRIP` per curve
/// would be a primitive per hair), with per-point widths as `_WIDTH`; and
/// the roots as a `POINTS` primitive with `NORMAL`, `TEXCOORD_0`, the
/// face as `_FACE` and the barycentrics as `_BARYCENTRIC`, when the
/// curves have them.
///
/// # Errors
/// As [`Curves::check`], a root face of 2^24 or more (glTF's `f32`
/// attribute), or an I/O error.
pub fn write_gltf(path: impl AsRef<Path>, curves: &Curves) -> Result<()> {
    let path = path.as_ref();
    curves.check(path)?;
    crate::mesh::gltf::write_curves(path, curves)
}
