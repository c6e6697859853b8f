//! From a UV-textured mesh to mesh colours.
//!
//! Each face's resolution comes from the texels its UV triangle covers: a
//! face of resolution `R` owns about `R²/2` samples (its share of the
//! shared vertices and edges plus its interior), so `R ≈ √(2 · A_texels ·
//! density)`, rounded to the nearest power of two in log scale and capped.
//! A sample budget (by default the texture's texel count) lowers the
//! density until the total fits, then raises the faces furthest below
//! their choice while the budget allows. Every sample takes the bilinearly
//! filtered texture at its UV; a vertex or edge sample that has several
//! UVs (it lies on a UV seam) takes the mean over its distinct UVs, which
//! removes the seam.

use glam::{Vec2, Vec3};

use crate::structure::{
    MeshColors, lattice_points, layout_sample_count, samples_per_edge, samples_per_face,
};
use crate::texture::Texture;
use crate::topology::Topology;
use crate::{Error, MAX_LEVEL};

/// How to choose resolutions when converting a texture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Samples per covered texel to aim for (1: the texture's density).
    pub density: f64,
    /// The highest face level (`R ≤ 2^max_level`).
    pub max_level: u8,
    /// At most this many samples; `None` means the texture's texel count.
    pub max_samples: Option<usize>,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            density: 1.0,
            max_level: 8,
            max_samples: None,
        }
    }
}

fn texel_area(uv: &[Vec2; 3], texture: &Texture) -> f64 {
    let (a, b, c) = (uv[0].as_dvec2(), uv[1].as_dvec2(), uv[2].as_dvec2());
    0.5 * (b - a).perp_dot(c - a).abs() * texture.width() as f64 * texture.height() as f64
}

/// The level for a face covering `area` texels at `density`.
fn level_for(area: f64, density: f64, max_level: u8) -> u8 {
    let r = (2.0 * area * density).sqrt();
    if r.is_nan() || r <= 1.0 {
        return 0;
    }
    (r.log2().round() as i64).clamp(0, i64::from(max_level)) as u8
}

/// Face levels from the texel footprint of each face's UVs, within the
/// sample budget.
///
/// # Errors
/// [`Error::ChannelMismatch`] (one UV triple per face),
/// [`Error::NonFinite`] for a NaN or infinite UV.
pub fn choose_levels(
    topology: &Topology,
    corner_uvs: &[[Vec2; 3]],
    texture: &Texture,
    options: &Options,
) -> Result<Vec<u8>, Error> {
    if corner_uvs.len() != topology.faces().len() {
        return Err(Error::ChannelMismatch {
            what: "corner UVs (one triple per face)",
            expected: topology.faces().len(),
            got: corner_uvs.len(),
        });
    }
    if let Some(i) = corner_uvs.iter().flatten().position(|uv| !uv.is_finite()) {
        return Err(Error::NonFinite {
            what: "uv",
            index: i,
        });
    }
    let max_level = options.max_level.min(MAX_LEVEL);
    let areas: Vec<f64> = corner_uvs
        .iter()
        .map(|uv| texel_area(uv, texture))
        .collect();
    let levels_at =
        |d: f64| -> Vec<u8> { areas.iter().map(|&a| level_for(a, d, max_level)).collect() };
    let budget = options
        .max_samples
        .unwrap_or(texture.width() * texture.height()) as u64;
    let mut levels = levels_at(options.density);
    if layout_sample_count(topology, &levels) > budget {
        // The count only grows with the density: bisect it.
        let (mut lo, mut hi) = (0.0, options.density);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if layout_sample_count(topology, &levels_at(mid)) > budget {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        levels = levels_at(lo);
        top_up(
            topology,
            &mut levels,
            &levels_at(options.density),
            &areas,
            budget,
        );
    }
    Ok(levels)
}

/// Spends what the bisection left of the budget: raises faces one level at
/// a time, those furthest below their unconstrained level first, while the
/// total stays within `budget` (the count changes only at the face and its
/// three edges, so each step is O(1)).
fn top_up(topology: &Topology, levels: &mut [u8], target: &[u8], areas: &[f64], budget: u64) {
    let mut total = layout_sample_count(topology, levels);
    let edge_count = |n: u8| u64::from(samples_per_edge(1 << n));
    for _ in 0..=MAX_LEVEL {
        let mut order: Vec<usize> = (0..levels.len())
            .filter(|&f| levels[f] < target[f])
            .collect();
        // Largest texel area per current sample first.
        order.sort_by(|&a, &b| {
            let d = |f: usize| areas[f] / f64::from(1u32 << (2 * levels[f]));
            d(b).total_cmp(&d(a))
        });
        let mut changed = false;
        for f in order {
            let (old, new) = (levels[f], levels[f] + 1);
            let mut grow =
                u64::from(samples_per_face(1 << new)) - u64::from(samples_per_face(1 << old));
            for &e in &topology.face_edges[f] {
                let other = topology.edge_faces[e as usize]
                    .iter()
                    .filter(|&&g| g != crate::NO_FACE && g as usize != f)
                    .map(|&g| levels[g as usize])
                    .min()
                    .unwrap_or(u8::MAX);
                grow += edge_count(new.min(other)) - edge_count(old.min(other));
            }
            if total + grow <= budget {
                levels[f] = new;
                total += grow;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
}

/// Converts a UV-textured mesh to mesh colours with as many channels as the
/// texture. `corner_uvs[f][k]` is the UV of corner `k` of face `f`, in the
/// [`Texture`] convention (`v = 0` is row 0).
///
/// # Errors
/// As for [`choose_levels`].
pub fn from_texture(
    topology: Topology,
    corner_uvs: &[[Vec2; 3]],
    texture: &Texture,
    options: &Options,
) -> Result<MeshColors, Error> {
    let levels = choose_levels(&topology, corner_uvs, texture, options)?;
    let mut mc = MeshColors::with_levels(topology, levels, texture.channels())?;
    fill(&mut mc, corner_uvs, texture)?;
    Ok(mc)
}

/// Fills existing mesh colours from a texture (resolutions unchanged):
/// each sample is the bilinear texture value at its UV, averaged over its
/// distinct UVs on seams.
///
/// # Errors
/// [`Error::ChannelMismatch`] for a texture with other channels or UVs
/// not one triple per face; [`Error::NonFinite`].
pub fn fill(mc: &mut MeshColors, corner_uvs: &[[Vec2; 3]], texture: &Texture) -> Result<(), Error> {
    if texture.channels() != mc.channels() {
        return Err(Error::ChannelMismatch {
            what: "texture channels",
            expected: mc.channels(),
            got: texture.channels(),
        });
    }
    if corner_uvs.len() != mc.face_count() {
        return Err(Error::ChannelMismatch {
            what: "corner UVs (one triple per face)",
            expected: mc.face_count(),
            got: corner_uvs.len(),
        });
    }
    if let Some(i) = corner_uvs.iter().flatten().position(|uv| !uv.is_finite()) {
        return Err(Error::NonFinite {
            what: "uv",
            index: i,
        });
    }
    // Every (sample, UV) pair; a sample on a seam has several UVs.
    let mut entries: Vec<(usize, [u32; 2])> =
        Vec::with_capacity(mc.sample_count() + mc.sample_count() / 2);
    for (f, uv) in corner_uvs.iter().enumerate() {
        let r = 1u32 << mc.level_at(f);
        let rf = f64::from(r);
        for a in lattice_points(r) {
            if let Some(i) = mc.lattice_index(f, a) {
                let p = (0..3).fold(glam::DVec2::ZERO, |s, k| {
                    s + f64::from(a[k]) / rf * uv[k].as_dvec2()
                });
                entries.push((i, [(p.x as f32).to_bits(), (p.y as f32).to_bits()]));
            }
        }
    }
    entries.sort_unstable();
    entries.dedup();
    let values = lookups(&entries, texture);
    average(mc, entries.iter().map(|e| e.0), &values);
    Ok(())
}

/// Sets every sample to the mean of its values: `samples` gives, in
/// ascending order, the sample of each value (`channels` numbers each in
/// `values`); a sample seen several times (on a seam) takes their mean,
/// summed in order in `f64`.
fn average(mc: &mut MeshColors, samples: impl Iterator<Item = usize>, values: &[f32]) {
    let c = mc.channels();
    let samples: Vec<usize> = samples.collect();
    let mut sum = vec![0.0f64; c];
    let mut start = 0;
    while start < samples.len() {
        let i = samples[start];
        let mut end = start;
        sum.fill(0.0);
        while end < samples.len() && samples[end] == i {
            for (s, &x) in sum.iter_mut().zip(&values[end * c..(end + 1) * c]) {
                *s += f64::from(x);
            }
            end += 1;
        }
        let n = (end - start) as f64;
        for (o, s) in mc.sample_at_mut(i).iter_mut().zip(&sum) {
            *o = (s / n) as f32;
        }
        start = end;
    }
}

/// What colours one face in [`from_textures`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Source {
    /// Texture `i` of the list, read bilinearly at the face's UVs.
    Texture(usize),
    /// One linear RGB colour (a material without a texture).
    Flat([f32; 3]),
}

/// Converts a mesh whose faces read different RGB textures (one per
/// material), or flat colours, to 3-channel mesh colours.
/// `sources[f]` says what colours face `f`, `corner_uvs[f]` its UVs (unused
/// for a flat face).
///
/// Each face's resolution comes from its footprint in its own texture's
/// texels ([`choose_levels`] on UVs scaled by `√(width · height)` of that
/// texture; flat faces get the coarsest level), within
/// `options.max_samples`, by default the texel count of all the textures.
/// Every sample is the bilinear value of its face's texture at its UV (or
/// the face's flat colour), averaged over its distinct (texture, UV) pairs,
/// so that a sample on a seam between materials takes both.
///
/// # Errors
/// [`Error::ChannelMismatch`] for a texture that is not RGB or a count of
/// sources or UVs other than one per face, [`Error::MissingTexture`],
/// and those of [`choose_levels`].
pub fn from_textures(
    topology: Topology,
    corner_uvs: &[[Vec2; 3]],
    textures: &[Texture],
    sources: &[Source],
    options: &Options,
) -> Result<MeshColors, Error> {
    check_sources(topology.faces().len(), textures, sources)?;
    // Each face's footprint in its own texture's texels: scale its UVs so
    // that a 1×1 reference texture sees the same texel area.
    let scale: Vec<f32> = textures
        .iter()
        .map(|t| ((t.width() * t.height()) as f32).sqrt())
        .collect();
    let scaled: Vec<[Vec2; 3]> = corner_uvs
        .iter()
        .zip(sources)
        .map(|(uv, s)| match s {
            Source::Texture(t) => uv.map(|p| p * scale[*t]),
            Source::Flat(_) => [Vec2::ZERO; 3],
        })
        .collect();
    let reference = Texture::new(1, 1, 1, vec![0.0])?;
    let budget = options
        .max_samples
        .unwrap_or_else(|| textures.iter().map(|t| t.width() * t.height()).sum());
    let levels = choose_levels(
        &topology,
        &scaled,
        &reference,
        &Options {
            max_samples: Some(budget),
            ..*options
        },
    )?;
    let resolutions: Vec<u32> = levels.iter().map(|&n| 1u32 << n).collect();
    let mut colors = MeshColors::new(topology, &resolutions, 3)?;
    fill_sources(&mut colors, corner_uvs, textures, sources);
    Ok(colors)
}

/// One source per face, naming RGB textures of the list.
fn check_sources(faces: usize, textures: &[Texture], sources: &[Source]) -> Result<(), Error> {
    if sources.len() != faces {
        return Err(Error::ChannelMismatch {
            what: "face sources (one per face)",
            expected: faces,
            got: sources.len(),
        });
    }
    if let Some(t) = textures.iter().find(|t| t.channels() != 3) {
        return Err(Error::ChannelMismatch {
            what: "texture channels (RGB)",
            expected: 3,
            got: t.channels(),
        });
    }
    for (face, s) in sources.iter().enumerate() {
        if let Source::Texture(texture) = *s
            && texture >= textures.len()
        {
            return Err(Error::MissingTexture {
                face,
                texture,
                count: textures.len(),
            });
        }
    }
    Ok(())
}

/// [`from_textures`]'s fill: every sample the bilinear value of its face's
/// texture at its UV (or the face's flat colour), averaged over its
/// distinct (texture, UV) pairs. The sources are checked.
fn fill_sources(
    colors: &mut MeshColors,
    corner_uvs: &[[Vec2; 3]],
    textures: &[Texture],
    sources: &[Source],
) {
    const FLAT: u32 = u32::MAX;
    // (sample, texture or FLAT, u bits, v bits; for FLAT: the face).
    let mut entries: Vec<(usize, u32, u32, u32)> =
        Vec::with_capacity(colors.sample_count() * 3 / 2);
    for (f, uv) in corner_uvs.iter().enumerate() {
        let Some(r) = colors.face_resolution(f) else {
            continue;
        };
        let rf = f64::from(r);
        for a in lattice_points(r) {
            let Some(i) = colors.lattice_index(f, a) else {
                continue;
            };
            match sources[f] {
                Source::Texture(t) => {
                    let p = (0..3).fold(glam::DVec2::ZERO, |s, k| {
                        s + f64::from(a[k]) / rf * uv[k].as_dvec2()
                    });
                    entries.push((i, t as u32, (p.x as f32).to_bits(), (p.y as f32).to_bits()));
                }
                Source::Flat(_) => entries.push((i, FLAT, f as u32, 0)),
            }
        }
    }
    // Equal entries are identical, so the unstable sort is deterministic.
    #[cfg(feature = "rayon")]
    rayon::slice::ParallelSliceMut::par_sort_unstable(entries.as_mut_slice());
    #[cfg(not(feature = "rayon"))]
    entries.sort_unstable();
    entries.dedup_by(|a, b| {
        // Flat entries of one sample from several faces of one colour
        // count once, like equal UVs.
        a.0 == b.0
            && a.1 == b.1
            && (a.1 == FLAT && sources[a.2 as usize] == sources[b.2 as usize]
                || a.2 == b.2 && a.3 == b.3)
    });
    let value = |&(_, t, u, v): &(usize, u32, u32, u32)| -> [f32; 3] {
        if t == FLAT {
            match sources[u as usize] {
                Source::Flat(c) => c,
                Source::Texture(_) => [0.0; 3],
            }
        } else {
            let mut out = [0.0f32; 3];
            textures[t as usize].bilinear([f32::from_bits(u), f32::from_bits(v)], &mut out);
            out
        }
    };
    #[cfg(feature = "rayon")]
    let values: Vec<[f32; 3]> = {
        use rayon::prelude::*;
        entries.par_iter().map(value).collect()
    };
    #[cfg(not(feature = "rayon"))]
    let values: Vec<[f32; 3]> = entries.iter().map(value).collect();
    average(colors, entries.iter().map(|e| e.0), values.as_flattened());
}

/// A mesh welded for mesh colours by [`weld_manifold`].
#[derive(Debug, Clone, PartialEq)]
pub struct Welded {
    /// The positions, welded and used ones only, in order of first use.
    pub positions: Vec<Vec3>,
    /// Face `f` of the input over them.
    pub faces: Vec<[u32; 3]>,
    /// How many faces keep vertices of their own.
    pub detached: usize,
}

/// Welds a triangle soup for mesh colours: readers split a vertex
/// wherever its UV or normal changes (a seam), while mesh colours live on
/// the connectivity of the surface itself. Vertices with equal positions
/// are welded ([`weld`](crate::weld)) and unused ones dropped; a face that
/// would repeat a vertex after welding, or be the third on an edge (which
/// mesh colours cannot colour consistently), keeps vertices of its own
/// (counted in [`Welded::detached`]), so the result always makes a
/// [`Topology`]. Deterministic: mesh colours made for a mesh fit the same
/// mesh read again.
///
/// # Errors
/// [`Error::MissingVertex`] for a face naming a vertex beyond `positions`.
///
/// # Example
/// ```
/// use mesh_colors::{Topology, convert::weld_manifold, glam::Vec3};
/// // Two triangles sharing an edge, its vertices split (a UV seam), and a
/// // flat one.
/// let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::X, Vec3::Y, Vec3::ONE];
/// let w = weld_manifold(&p, &[[0, 1, 2], [3, 5, 4], [0, 0, 1]])?;
/// assert_eq!((w.positions.len(), w.detached), (7, 1));
/// assert_eq!(Topology::new(w.positions.len(), &w.faces)?.faces().len(), 3);
/// # Ok::<(), mesh_colors::Error>(())
/// ```
pub fn weld_manifold(positions: &[Vec3], faces: &[[u32; 3]]) -> Result<Welded, Error> {
    use std::collections::HashMap;
    let count = positions.len();
    for (face, tri) in faces.iter().enumerate() {
        if let Some(&vertex) = tri.iter().find(|&&v| v as usize >= count) {
            return Err(Error::MissingVertex {
                face,
                vertex,
                count,
            });
        }
    }
    let (welded, faces, _) = crate::weld(positions, faces);
    let mut compact = vec![u32::MAX; welded.len()];
    let mut positions = Vec::new();
    let mut edges: HashMap<(u32, u32), u8> = HashMap::with_capacity(faces.len() * 3 / 2);
    let mut detached = 0;
    let mut out = Vec::with_capacity(faces.len());
    for face in &faces {
        let degenerate = face[0] == face[1] || face[1] == face[2] || face[2] == face[0];
        let full = |edges: &HashMap<(u32, u32), u8>| {
            (0..3).any(|k| {
                let (a, b) = (
                    compact[face[k] as usize],
                    compact[face[(k + 1) % 3] as usize],
                );
                a != u32::MAX
                    && b != u32::MAX
                    && edges.get(&(a.min(b), a.max(b))).is_some_and(|&c| c >= 2)
            })
        };
        if degenerate || full(&edges) {
            // Vertices of its own: a small island, coloured alone.
            let base = positions.len() as u32;
            positions.extend(face.map(|v| welded[v as usize]));
            out.push([base, base + 1, base + 2]);
            detached += 1;
            continue;
        }
        let tri = face.map(|v| {
            let slot = &mut compact[v as usize];
            if *slot == u32::MAX {
                *slot = positions.len() as u32;
                positions.push(welded[v as usize]);
            }
            *slot
        });
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
        out.push(tri);
    }
    Ok(Welded {
        positions,
        faces: out,
        detached,
    })
}

/// The bilinear texture value at each entry's UV (on all threads with the
/// `rayon` feature; each value depends only on its UV).
fn lookups(entries: &[(usize, [u32; 2])], texture: &Texture) -> Vec<f32> {
    let c = texture.channels();
    let mut values = vec![0.0f32; entries.len() * c];
    let one = |(e, out): (&(usize, [u32; 2]), &mut [f32])| {
        texture.bilinear([f32::from_bits(e.1[0]), f32::from_bits(e.1[1])], out);
    };
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        entries
            .par_iter()
            .zip(values.par_chunks_mut(c))
            .for_each(one);
    }
    #[cfg(not(feature = "rayon"))]
    entries.iter().zip(values.chunks_mut(c)).for_each(one);
    values
}

/// Peak signal-to-noise ratio, in dB, of mesh colours (linear filter)
/// against the bilinearly filtered texture at the given surface points
/// `(face, barycentrics)`, for values in `[0, peak]`. Infinite when equal.
pub fn psnr(
    mc: &MeshColors,
    corner_uvs: &[[Vec2; 3]],
    texture: &Texture,
    points: &[(u32, [f32; 3])],
    peak: f64,
) -> Result<f64, Error> {
    let c = mc.channels();
    let (mut got, mut want) = (vec![0.0f32; c], vec![0.0f32; c]);
    let mut sse = 0.0f64;
    for &(f, b) in points {
        mc.linear(f as usize, b, &mut got)?;
        let uv = corner_uvs.get(f as usize).ok_or(Error::MissingFace {
            face: f as usize,
            count: corner_uvs.len(),
        })?;
        let p = b[0] * uv[0] + b[1] * uv[1] + b[2] * uv[2];
        texture.bilinear([p.x, p.y], &mut want);
        for (g, w) in got.iter().zip(&want) {
            sse += f64::from(g - w).powi(2);
        }
    }
    let mse = sse / (points.len() * c).max(1) as f64;
    Ok(10.0 * (peak * peak / mse).log10())
}
