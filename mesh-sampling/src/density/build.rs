//! Building the pieces of a density: per-face depths and their cap, the
//! texture subdivision with early stops and merging, the exact integrals
//! (Šik & Křivánek 2013, Sec. 3.4).

use glam::{DVec2, Vec2};

use super::{Depth, Mode, Options};
use crate::layout::Piece;
use crate::subdivision::{self, MAX_LEVEL, Merge, SubTriangle, Values};
use crate::{DensityTexture, Error, MeshRef};

/// The mesh's UVs, checked finite on every referenced vertex.
pub(crate) fn texture_uvs<'a>(mesh: &MeshRef<'a>) -> Result<&'a [Vec2], Error> {
    let uvs = mesh.uvs.ok_or(Error::MissingUvs)?;
    for tri in mesh.indices {
        for &i in tri {
            if !uvs[i as usize].is_finite() {
                return Err(Error::NonFiniteUv { vertex: i as usize });
            }
        }
    }
    Ok(uvs)
}

#[inline]
pub(super) fn face_uvs(uvs: &[Vec2], tri: [u32; 3]) -> [DVec2; 3] {
    tri.map(|i| uvs[i as usize].as_dvec2())
}

/// The depth at which sub-triangles are about a texel (Šik & Křivánek
/// Sec. 3.4: the sub-triangle size matches the texture resolution; `4^L`
/// is the texels the triangle covers, rounded to the nearest power of 4,
/// so sub-triangles cover half a texel to two) and, so that a sliver (long,
/// with little area) is cut along its length too, no edge is longer than
/// two texels.
pub(super) fn face_level(texture: &DensityTexture, uv: [DVec2; 3], options: &Options) -> u8 {
    let scale = DVec2::new(texture.width() as f64, texture.height() as f64);
    let t = uv.map(|p| p * scale);
    let texels = 0.5 * (t[1] - t[0]).perp_dot(t[2] - t[0]).abs();
    let longest = (0..3)
        .map(|k| (t[(k + 1) % 3] - t[k]).length())
        .fold(0.0f64, f64::max);
    // 4^L ≈ texels (or ≥ texels) and 2^L ≥ longest / 2.
    let by_area = if texels > 1.0 {
        match options.depth {
            Depth::Nearest => (texels.log2() / 2.0).round(),
            Depth::AtMostOneTexel => (texels.log2() / 2.0).ceil(),
        }
    } else {
        0.0
    };
    let by_edge = if longest > 2.0 {
        (longest / 2.0).log2().ceil()
    } else {
        0.0
    };
    // NaN (an infinite footprint) and huge values end at MAX_LEVEL.
    let level = by_area.max(by_edge).min(f64::from(MAX_LEVEL)) as u8;
    (level.saturating_add(options.extra_levels)).min(options.max_level)
}

/// The density's value if it is constant over the UV triangle's bounding
/// box (O(1), whatever the footprint's size).
pub(super) fn uv_constant(texture: &DensityTexture, uv: [DVec2; 3]) -> Option<f32> {
    let (lo, hi) = (uv[0].min(uv[1]).min(uv[2]), uv[0].max(uv[1]).max(uv[2]));
    texture.constant_over_box(lo, hi)
}

/// Meshes with at least this many faces are processed on all threads.
pub(super) const PARALLEL_FACES: usize = 1 << 15;

/// Subdivisions with at least this many leaves are built on all threads.
pub(super) const PARALLEL_LEAVES: u128 = 1 << 16;

/// Faces per task of the parallel piece collection (fixed, so the split
/// never depends on the number of threads; the result never does).
const FACE_CHUNK: usize = 1 << 10;

/// The pieces `fill(f, out)` appends for every face `f`, in face order,
/// and where each face's pieces start (`faces + 1` entries). On all
/// threads when `parallel` (and the `rayon` feature), in chunks of
/// [`FACE_CHUNK`] faces, each appending to its own list.
pub(super) fn collect_pieces(
    parallel: bool,
    faces: usize,
    fill: impl Fn(usize, &mut Vec<(SubTriangle, f32)>) + Sync + Send,
) -> (Vec<Piece>, Vec<u32>) {
    let chunk = |c: usize| {
        let mut out = Vec::new();
        let mut starts = Vec::new();
        for f in c * FACE_CHUNK..((c + 1) * FACE_CHUNK).min(faces) {
            starts.push(out.len());
            fill(f, &mut out);
        }
        (out, starts)
    };
    let chunks = map_faces(parallel, faces.div_ceil(FACE_CHUNK), chunk);
    let total = chunks.iter().map(|c| c.0.len()).sum();
    let mut pieces = Vec::with_capacity(total);
    let mut face_start = Vec::with_capacity(faces + 1);
    for (c, (parts, starts)) in chunks.into_iter().enumerate() {
        let base = pieces.len();
        face_start.extend(starts.iter().map(|&s| (base + s) as u32));
        let first = c * FACE_CHUNK;
        let ends = starts
            .iter()
            .skip(1)
            .copied()
            .chain(std::iter::once(parts.len()));
        for (k, (&start, end)) in starts.iter().zip(ends).enumerate() {
            let face = (first + k) as u32;
            pieces.extend(parts[start..end].iter().map(|&(part, value)| Piece {
                face,
                part,
                value,
            }));
        }
    }
    face_start.push(pieces.len() as u32);
    (pieces, face_start)
}

/// The levels to build: each face's wanted level, capped at the deepest
/// common level `C` for which `Σ 4^min(L, C)` over the faces that are not
/// constant (plus one per constant face) stays within `budget`; and that
/// sum.
pub(super) fn capped_levels(
    wanted: &[(u8, Option<f32>)],
    budget: usize,
) -> Result<(Vec<u8>, u128), Error> {
    let count = |cap: u8| -> u128 {
        wanted
            .iter()
            .map(|&(l, constant)| match constant {
                Some(_) => 1,
                None => 1u128 << (2 * l.min(cap)),
            })
            .sum()
    };
    let deepest = wanted.iter().map(|w| w.0).max().unwrap_or(0);
    let cap = (0..=deepest)
        .rev()
        .find(|&c| count(c) <= budget as u128)
        .ok_or(Error::TooManyPieces {
            needed: count(0),
            budget,
        })?;
    Ok((
        wanted.iter().map(|&(l, _)| l.min(cap)).collect(),
        count(cap),
    ))
}

/// Sub-triangles of face `f` with their values (approximate mode: the
/// density at the barycenter; exact: a bound of the density over the
/// sub-triangle), merged, zeros dropped.
pub(super) fn texture_pieces(
    mesh: &MeshRef<'_>,
    uvs: &[Vec2],
    texture: &DensityTexture,
    level: u8,
    options: &Options,
    f: usize,
    out: &mut Vec<(SubTriangle, f32)>,
) {
    if mesh.area(f) <= 0.0 {
        return;
    }
    let start = out.len();
    let [a, b, c] = face_uvs(uvs, mesh.indices[f]);
    let at = |(u, v): (f64, f64)| a + (b - a) * u + (c - a) * v;
    // A node whose UV box is constant is one piece (its subtree would
    // merge into it): found from the texture's tables in O(1). With a
    // tolerance, so is a node whose box the min/max pyramid bounds within
    // it (`max − min ≤ t · max`): its value is the density at its
    // barycenter (approximate mode, the paper's `p′` at that level) or
    // the pyramid's maximum (exact mode, still a bound).
    let tolerance = options.merge_tolerance;
    let near_constant = |s: SubTriangle| -> Option<(f32, f32)> {
        let [p, q, r] = s.corners().map(at);
        let (lo, hi) = (p.min(q).min(r), p.max(q).max(r));
        if tolerance == 0.0 {
            return texture.constant_over_box(lo, hi).map(|c| (c, c));
        }
        let (min, max) = texture.range_over_box(lo, hi);
        (max - min <= tolerance * max).then_some((min, max))
    };
    match options.mode {
        Mode::Approximate => {
            let values = Values {
                leaf: |s: SubTriangle| texture.eval(at(s.barycenter())) as f32,
                constant: |s: SubTriangle| {
                    let (min, max) = near_constant(s)?;
                    Some(if min == max {
                        min
                    } else {
                        texture.eval(at(s.barycenter())) as f32
                    })
                },
            };
            subdivision::build(level, tolerance, Merge::Mean, &values, out);
        }
        Mode::Exact => {
            // The maximum over the sub-triangle's UV bounding box, rounded
            // up to f32 so that it stays a bound.
            let values = Values {
                leaf: |s: SubTriangle| {
                    let [p, q, r] = s.corners().map(at);
                    round_up(texture.max_over_box(p.min(q).min(r), p.max(q).max(r)))
                },
                constant: |s: SubTriangle| near_constant(s).map(|(_, max)| max),
            };
            subdivision::build(level, tolerance, Merge::Max, &values, out);
        }
    }
    // Zeros merged with their siblings first; now they go.
    let mut kept = start;
    for k in start..out.len() {
        if out[k].1 > 0.0 {
            out[kept] = out[k];
            kept += 1;
        }
    }
    out.truncate(kept);
}

/// The smallest `f32` not below `x`, at most `f32::MAX` (a bound of a
/// density whose texels are at most that).
fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x {
        y.next_up().min(f32::MAX)
    } else {
        y.min(f32::MAX)
    }
}

/// `Ok` if integrating `texture` exactly over the mesh stays within
/// [`MAX_INTEGRATION_CELLS`](crate::MAX_INTEGRATION_CELLS) (checked in
/// O(1) per face, before integrating).
pub(crate) fn check_integration(
    mesh: &MeshRef<'_>,
    uvs: &[Vec2],
    texture: &DensityTexture,
) -> Result<(), Error> {
    let faces = mesh.indices.len();
    let cells: f64 = map_faces(faces >= PARALLEL_FACES, faces, |f| {
        texture.cells_to_integrate(face_uvs(uvs, mesh.indices[f]))
    })
    .iter()
    .sum();
    let budget = crate::MAX_INTEGRATION_CELLS;
    if cells <= budget as f64 {
        Ok(())
    } else {
        Err(Error::IntegrationTooLarge { cells, budget })
    }
}

/// The exact integral of the filtered texture over face `f` in 3D area:
/// the UV integral times the face's area scale (affine map). A face whose
/// UV triangle is degenerate takes its area times the density at its UV
/// centroid.
pub(crate) fn exact_mass(
    mesh: &MeshRef<'_>,
    uvs: &[Vec2],
    texture: &DensityTexture,
    f: usize,
) -> f64 {
    let area = mesh.area(f);
    if area <= 0.0 {
        return 0.0;
    }
    let uv = face_uvs(uvs, mesh.indices[f]);
    let uv_area = 0.5 * (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]).abs();
    if uv_area > 0.0 {
        texture.integral(uv) * area / uv_area
    } else {
        area * texture.eval((uv[0] + uv[1] + uv[2]) / 3.0)
    }
}

/// `f(0..n)` collected in order, in parallel when `parallel` and the
/// `rayon` feature is on (the result is the same either way).
pub(crate) fn map_faces<T: Send>(
    parallel: bool,
    n: usize,
    f: impl Fn(usize) -> T + Sync + Send,
) -> Vec<T> {
    #[cfg(feature = "rayon")]
    if parallel {
        use rayon::prelude::*;
        return (0..n).into_par_iter().map(f).collect();
    }
    #[cfg(not(feature = "rayon"))]
    let _ = parallel;
    (0..n).map(f).collect()
}
