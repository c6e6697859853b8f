//! Blue-noise (Poisson-disk) points on a mesh, following a density:
//! weighted sample elimination (Yuksel 2015, "Sample Elimination for
//! Generating Poisson Disk Sample Sets") applied to candidates drawn by any
//! of this crate's samplers.
//!
//! 1. Draw `M = candidate_factor · N` candidates from the sampler (5 N by
//!    default, as in the paper's experiments).
//! 2. Give candidate `k` the disk radius `r_k = √(1 / (2√3 N p_k))`, where
//!    `p_k` is the candidate's density w.r.t. area: for the uniform sampler
//!    `p = 1/A` and this is the paper's `r_max = √(A / (2√3 N))` (Eq. 4,
//!    the radius of `N` hexagonally packed disks); with a density, the
//!    local spacing scales as `1/√p`, so local counts follow the density
//!    while the spacing stays blue.
//! 3. Weight each candidate by its crowded neighbours,
//!    `w_ik = (1 − d̂_ik / 2r_k)^α` with `α = 8` and the weight limiting of
//!    Sec. 4.1 (`d̂ = max(d, 2 r_min)`, `r_min = r β (1 − (N/M)^γ)`,
//!    `β = 0.65`, `γ = 1.5`), using Euclidean 3D distance, and remove the
//!    heaviest candidate (an indexed max-heap) until `N` are left.
//! 4. With [`Packing::Dense`], move the worst-spaced survivors into the
//!    largest holes of the candidate pool (farthest-point relocation, a
//!    greedy form of Schlömer, Heck & Deussen 2011's farthest-point
//!    optimisation on the candidates), which raises the relative radius ρ
//!    from about 0.69 to 0.75 and more.
//! 5. Optionally order the output progressively (Sec. 5): the survivors are
//!    eliminated again to `N/2`, `N/4`, …, and each prefix of length
//!    `N/2^j` is itself a blue-noise set.
//!
//! **Scale.** The candidates are held as position and density only (16
//! bytes; the kept ones are drawn again from the sampler's chunked streams
//! at the end), and steps 3–4 run tile by tile over a uniform grid with the
//! weights listed for one tile at a time: the domain is cut into cubic
//! tiles of about 96 mean radii, done in eight phases of independent tiles
//! (in parallel), each seeing the points kept by the tiles done before it
//! as fixed neighbours and the candidates of those after it as "ghosts"
//! thinned with its own; each tile stops near its share of `N`, and the
//! few surplus points of the run are removed closest pair first. ρ is
//! that of one global queue or a little higher (0.693–0.697 for elimination
//! and 0.765–0.770 for the dense packing on the bunny at 10⁵–10⁶), and the
//! peak memory about 165 bytes per output point for elimination and 400
//! for the dense packing at 10⁶ (the output's 72 included).
//!
//! The output depends only on the sampler, the target and the seed: the
//! candidates come from [`SurfaceSampler::sample_n`]'s streams, the tiles
//! and their phases from the candidates alone, and every queue breaks
//! ties by a fixed order; never on the number of threads.

mod elimination;
mod grid;
mod heap;
mod relocation;
mod spacing;
mod tiles;
mod trim;

pub use spacing::{
    max_poisson_radius, nearest_neighbour_distances, relative_radius, relative_radius_with_density,
};

use crate::parallel::{CHUNK, chunk_rng, for_each_chunk_via};
use crate::{DensitySampler, Error, SurfacePoint, SurfaceSampler, UniformSampler};
use discrete_sampling::DiscreteSampler;
use elimination::Weights;
use tiles::Stage;

/// How many points to keep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BlueNoiseTarget {
    /// Exactly this many points.
    Count(usize),
    /// The points of a hexagonal packing of disks of this radius over the
    /// surface (Blender's `distance_min` is twice this): the count is
    /// `N = A / (2√3 r²)` for surface area `A`, in the mesh's length unit.
    /// With a density, `r` is the radius where the density equals its mean
    /// over the surface.
    Radius(f64),
}

/// How tightly [`blue_noise`] packs its points.
///
/// ρ is the relative radius of Lagae & Dutré 2008 ([`relative_radius`]:
/// half the smallest distance between two points over the radius of a
/// hexagonal packing of as many disks; 1 for the hexagonal lattice, about
/// 0.01 for independent points), measured on the data meshes at
/// N = 10⁵ with Euclidean 3D distances. MeshLab's and point-cloud-utils'
/// Poisson-disk sampling (Corsini et al. 2012) reach 0.75–0.77.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Packing {
    /// Weighted sample elimination alone (Yuksel 2015): ρ ≈ 0.69 with the
    /// paper's 5 candidates per point. Keeps the paper's progressive order
    /// and is the fastest.
    #[default]
    Elimination,
    /// Elimination followed by farthest-point relocation (a greedy form of
    /// Schlömer, Heck & Deussen 2011, "Farthest-Point Optimized Point Sets
    /// with Maximized Minimum Distance", restricted to the candidates): the
    /// point with the smallest spacing moves to the unused candidate
    /// farthest from every kept point while that raises the smallest
    /// spacing. ρ ≈ 0.76 on the data meshes (uniform and with a density)
    /// with [`BlueNoiseOptions::dense`]'s 14 candidates per point (0.755
    /// with 12, 0.765 with 15), about 6× the time of elimination at 5.
    /// Every output point is still one of the sampler's candidates; with
    /// `progressive`, the dense set is ordered by eliminating it to `N/2`,
    /// `N/4`, … (the prefixes have elimination's spacing, the whole set the
    /// dense one).
    Dense,
}

/// Parameters of [`blue_noise`]; the defaults are Yuksel 2015's
/// ([`Packing::Elimination`]); [`BlueNoiseOptions::dense`] gives the
/// denser packing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlueNoiseOptions {
    /// Candidates drawn per output point (≥ 1; the paper uses 5, the dense
    /// packing 14): more candidates give a denser packing, at a cost
    /// roughly proportional to their square.
    pub candidate_factor: f64,
    /// Elimination alone, or followed by farthest-point relocation.
    pub packing: Packing,
    /// Order the output so that every prefix of length `N / 2^j` is
    /// itself well spread (Sec. 5). Costs about twice the time.
    pub progressive: bool,
    /// The weight function's exponent α (8).
    pub alpha: f64,
    /// Weight limiting β (0.65); 0 turns limiting off.
    pub beta: f64,
    /// Weight limiting γ (1.5).
    pub gamma: f64,
    /// The most memory a run may take (the candidates, one tile's working
    /// set per thread and the output), checked against an estimate before
    /// anything is allocated (2 GiB by default: about 10⁷ output points at
    /// the default factor, 5·10⁶ with the dense packing).
    pub max_memory_bytes: usize,
}

impl Default for BlueNoiseOptions {
    fn default() -> Self {
        Self {
            candidate_factor: 5.0,
            packing: Packing::Elimination,
            progressive: false,
            alpha: 8.0,
            beta: 0.65,
            gamma: 1.5,
            max_memory_bytes: 2 << 30,
        }
    }
}

impl BlueNoiseOptions {
    /// Candidates per point of [`BlueNoiseOptions::dense`].
    pub const DENSE_CANDIDATE_FACTOR: f64 = 14.0;

    /// The dense packing ([`Packing::Dense`]) with
    /// [`DENSE_CANDIDATE_FACTOR`](Self::DENSE_CANDIDATE_FACTOR) candidates
    /// per point, the other options at their defaults.
    pub fn dense() -> Self {
        Self {
            candidate_factor: Self::DENSE_CANDIDATE_FACTOR,
            packing: Packing::Dense,
            ..Self::default()
        }
    }
}

/// A sampler whose surface area is known: the area turns a radius into a
/// point count and gives the uniform spacing.
pub trait SurfaceArea {
    /// The total area of the sampled surface, in the mesh's unit squared.
    fn surface_area(&self) -> f64;
}

impl SurfaceArea for UniformSampler<'_> {
    fn surface_area(&self) -> f64 {
        self.total_area()
    }
}

impl<S: DiscreteSampler + Sync> SurfaceArea for DensitySampler<'_, S> {
    fn surface_area(&self) -> f64 {
        let mesh = self.mesh();
        (0..mesh.indices.len()).map(|f| mesh.area(f)).sum()
    }
}

/// Estimated bytes of a run for `n` points from `m` candidates: the
/// candidate pool (position and density, 16 bytes) and its tile order (4),
/// the output and the kept indices, the progressive stages' pools, and one
/// tile's working set per thread.
fn estimated_bytes(n: f64, m: f64, options: &BlueNoiseOptions) -> f64 {
    let pool = m * (16.0 + 4.0);
    let output = n * (size_of::<SurfacePoint>() + 4 + 4) as f64;
    let progressive = if options.progressive { n * 24.0 } else { 0.0 };
    pool + output + progressive + (threads() * TILE_WORKING_BYTES) as f64
}

/// A bound of one tile's working set: its points (position, radius,
/// index, flag, key and queue entry, about 48 bytes) and its grid.
const TILE_WORKING_BYTES: usize = 4 << 20;

fn threads() -> usize {
    #[cfg(feature = "rayon")]
    return rayon::current_num_threads();
    #[cfg(not(feature = "rayon"))]
    1
}

/// `n` points (or as many as [`BlueNoiseTarget::Radius`] implies) spread
/// as blue noise over the surface, following the density of `sampler`.
/// Each [`SurfacePoint`] keeps the fields its candidate had, including
/// `pdf`, the density of the candidate distribution.
///
/// # Example
/// ```
/// use glam::Vec3;
/// use mesh_sampling::{
///     BlueNoiseOptions, BlueNoiseTarget, MeshRef, UniformSampler, blue_noise, relative_radius,
/// };
///
/// let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
/// let indices = [[0, 1, 2], [1, 3, 2]];
/// let sampler = UniformSampler::new(MeshRef::new(&positions, &indices))?;
/// let opts = BlueNoiseOptions::default();
/// let points = blue_noise(&sampler, BlueNoiseTarget::Count(1000), 7, &opts)?;
/// assert_eq!(points.len(), 1000);
/// let xyz: Vec<Vec3> = points.iter().map(|p| p.position).collect();
/// assert!(relative_radius(&xyz, 1.0) > 0.5); // random points: about 0.01
/// # Ok::<(), mesh_sampling::Error>(())
/// ```
///
/// # Errors
/// [`Error::InvalidOption`] for a count of 0, a radius that is not finite
/// and positive, a count or candidate count above `u32::MAX - 1`, options
/// out of range (`candidate_factor < 1`, `alpha ≤ 0`, `beta` outside
/// `[0, 1)`, `gamma ≤ 0`, any NaN), or a run that would need more than
/// `max_memory_bytes`.
///
/// # Memory and time
/// The candidates are held as position and density (16 bytes each, plus 4
/// for their tile order), not as [`SurfacePoint`]s: the kept ones are drawn
/// again from the sampler's chunked streams at the end. Elimination runs
/// tile by tile over a uniform grid (see the module docs), so the peak is
/// about `20 M + 80 N` bytes plus a few MB per thread: about 180 bytes per
/// output point at the default 5 candidates, 370 for the dense packing's
/// 14. Time is `O(M)` for a density that varies slowly: one grid query
/// per candidate to sum the weights and one per removal to lower them.
pub fn blue_noise<S: SurfaceSampler + SurfaceArea>(
    sampler: &S,
    target: BlueNoiseTarget,
    seed: u64,
    options: &BlueNoiseOptions,
) -> Result<Vec<SurfacePoint>, Error> {
    check_options(options)?;
    let area = sampler.surface_area();
    let n = target_count(target, area)?;
    let m_f = (n as f64 * options.candidate_factor).ceil();
    let bytes = estimated_bytes(n as f64, m_f, options);
    if m_f >= f64::from(u32::MAX) || bytes > options.max_memory_bytes as f64 {
        return Err(Error::InvalidOption(format!(
            "blue noise: {n} points from {m_f:.0} candidates need about {:.1} MB, more than \
             the memory budget of {:.1} MB (BlueNoiseOptions::max_memory_bytes) or the \
             {} candidates a run can index; ask for fewer points or fewer candidates per point",
            bytes / 1e6,
            options.max_memory_bytes as f64 / 1e6,
            u32::MAX - 1,
        )));
    }
    let m = m_f as usize;
    let mut pool = vec![[0.0f32; 4]; m];
    for_each_chunk_via(
        seed,
        &mut pool,
        |rng, chunk| sampler.sample_into(rng, chunk),
        |p: &SurfacePoint| [p.position.x, p.position.y, p.position.z, p.pdf],
    );
    let order = select(&pool, n, options);
    drop(pool);
    Ok(redraw(sampler, seed, m, order))
}

/// The candidates `order` (indices into the `m` of [`SurfaceSampler::sample_n`]
/// for `seed`), in that order, drawn again chunk by chunk from the same
/// streams: the same points, bit for bit, without holding all `m`.
fn redraw<S: SurfaceSampler>(
    sampler: &S,
    seed: u64,
    m: usize,
    order: Vec<u32>,
) -> Vec<SurfacePoint> {
    let n = order.len();
    // Ascending indices and, unless they already are, where each goes.
    let ascending = order.windows(2).all(|w| w[0] < w[1]);
    let (sorted, mut goes_to) = if ascending {
        (order, Vec::new())
    } else {
        let mut by_index: Vec<(u32, u32)> = order
            .iter()
            .enumerate()
            .map(|(at, &i)| (i, at as u32))
            .collect();
        drop(order);
        by_index.sort_unstable();
        by_index.into_iter().unzip()
    };
    let mut out = vec![SurfacePoint::default(); n];
    // One slice of the output per chunk of candidates.
    let mut jobs = Vec::new();
    let mut rest = out.as_mut_slice();
    let mut at = 0;
    while at < n {
        let chunk = sorted[at] as usize / CHUNK;
        let end = at + sorted[at..].partition_point(|&i| (i as usize) / CHUNK == chunk);
        let (here, tail) = rest.split_at_mut(end - at);
        jobs.push((chunk, &sorted[at..end], here));
        rest = tail;
        at = end;
    }
    let run = |buf: &mut Vec<SurfacePoint>,
               (chunk, picks, slots): (usize, &[u32], &mut [SurfacePoint])| {
        buf.resize(CHUNK.min(m - chunk * CHUNK), SurfacePoint::default());
        sampler.sample_into(&mut chunk_rng(seed, chunk), buf);
        for (slot, &i) in slots.iter_mut().zip(picks) {
            *slot = buf[i as usize - chunk * CHUNK];
        }
    };
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        jobs.into_par_iter().for_each_init(Vec::new, run);
    }
    #[cfg(not(feature = "rayon"))]
    {
        let mut buf = Vec::new();
        jobs.into_iter().for_each(|job| run(&mut buf, job));
    }
    // Into output order, in place: the point in slot k belongs in slot
    // goes_to[k].
    for k in 0..goes_to.len() {
        while goes_to[k] as usize != k {
            let t = goes_to[k] as usize;
            out.swap(k, t);
            goes_to.swap(k, t);
        }
    }
    out
}

fn check_options(o: &BlueNoiseOptions) -> Result<(), Error> {
    let bad = |what: &str, v: f64| {
        Err(Error::InvalidOption(format!(
            "blue noise: BlueNoiseOptions::{what} = {v} is out of range"
        )))
    };
    if !(o.candidate_factor >= 1.0 && o.candidate_factor.is_finite()) {
        return bad("candidate_factor (must be >= 1)", o.candidate_factor);
    }
    if !(o.alpha > 0.0 && o.alpha.is_finite()) {
        return bad("alpha (must be > 0)", o.alpha);
    }
    if !(0.0..1.0).contains(&o.beta) {
        return bad("beta (must be in [0, 1))", o.beta);
    }
    if !(o.gamma > 0.0 && o.gamma.is_finite()) {
        return bad("gamma (must be > 0)", o.gamma);
    }
    Ok(())
}

fn target_count(target: BlueNoiseTarget, area: f64) -> Result<usize, Error> {
    let n = match target {
        BlueNoiseTarget::Count(n) => n as f64,
        BlueNoiseTarget::Radius(r) => {
            if !(r > 0.0 && r.is_finite()) {
                return Err(Error::InvalidOption(format!(
                    "blue noise: the radius must be finite and > 0, got {r}"
                )));
            }
            (area / (2.0 * 3f64.sqrt() * r * r)).round().max(1.0)
        }
    };
    if n < 1.0 {
        return Err(Error::InvalidOption(
            "blue noise: asked for 0 points".to_string(),
        ));
    }
    if n >= f64::from(u32::MAX) {
        return Err(Error::InvalidOption(format!(
            "blue noise: {n:.0} points is more than a run can index ({})",
            u32::MAX - 1
        )));
    }
    Ok(n as usize)
}

/// The weights of an elimination from `m` candidates to `n`.
fn weights(n: usize, m: usize, options: &BlueNoiseOptions) -> Weights {
    let ratio = n as f64 / m.max(1) as f64;
    Weights {
        alpha: options.alpha,
        min_ratio: options.beta * (1.0 - ratio.powf(options.gamma)),
    }
}

/// The indices of the `n` candidates kept (of `pool`, `[x, y, z, pdf]`
/// each), in output order.
fn select(pool: &[[f32; 4]], n: usize, options: &BlueNoiseOptions) -> Vec<u32> {
    let first = Stage {
        weights: weights(n, pool.len(), options),
        relocate: options.packing == Packing::Dense,
    };
    let mut kept = tiles::select(pool, n, first);
    if !options.progressive {
        return kept;
    }
    // Progressive order: eliminate the survivors again to half, and so on;
    // each stage's removed points follow its survivors in the output, so
    // every prefix N/2^j is a stage's survivor set.
    let mut tails: Vec<Vec<u32>> = Vec::new();
    while kept.len() > 1 {
        let sub: Vec<[f32; 4]> = kept.iter().map(|&i| pool[i as usize]).collect();
        let half = kept.len() / 2;
        let stage = Stage {
            weights: weights(half, sub.len(), options),
            relocate: false,
        };
        let survivors = tiles::select(&sub, half, stage);
        let mut is_kept = vec![false; sub.len()];
        for &j in &survivors {
            is_kept[j as usize] = true;
        }
        tails.push(
            (0..sub.len())
                .filter(|&j| !is_kept[j])
                .map(|j| kept[j])
                .collect(),
        );
        kept = survivors.iter().map(|&j| kept[j as usize]).collect();
    }
    tails.reverse();
    kept.into_iter()
        .chain(tails.into_iter().flatten())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Density, DensityTexture, Filter, MeshRef};
    use glam::{Vec2, Vec3};

    /// The density-following check of the integration tests, applied to a
    /// deliberately wrong elimination that gives every candidate the
    /// uniform radius (every density replaced by the mean): it thins the
    /// dense regions hardest and flattens the density, and the same χ²
    /// rejects it (the right one passes here too). The same for the dense
    /// packing. In one tile: tiles' shares alone follow the density at the
    /// tiles' scale, which would hide a wrong radius on this
    /// checkerboard.
    #[test]
    fn one_radius_for_all_fails_the_density_test() {
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        let uvs = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
        let indices = [[0, 1, 2], [1, 3, 2]];
        let mesh = MeshRef {
            uvs: Some(&uvs),
            ..MeshRef::new(&positions, &indices)
        };
        let texture = DensityTexture::new(2, 2, vec![1.0, 4.0, 4.0, 1.0])
            .unwrap()
            .with_filter(Filter::Nearest);
        let sampler = DensitySampler::new(mesh, Density::Texture(&texture)).unwrap();
        let n = 4000;
        for options in [BlueNoiseOptions::default(), BlueNoiseOptions::dense()] {
            let m = (options.candidate_factor * n as f64) as usize;
            let candidates = sampler.sample_n(3, m).unwrap();
            let pool: Vec<[f32; 4]> = candidates
                .iter()
                .map(|p| [p.position.x, p.position.y, p.position.z, p.pdf])
                .collect();
            let flat: Vec<[f32; 4]> = pool.iter().map(|p| [p[0], p[1], p[2], 1.0]).collect();
            // χ² with 3 degrees of freedom: 16.27 is the 0.1% critical value.
            let stage = Stage {
                weights: weights(n, m, &options),
                relocate: options.packing == Packing::Dense,
            };
            let one_tile = |pool: &[[f32; 4]]| tiles::select_in_tiles(pool, n, stage, f32::MAX);
            let right = chi_square_of(&candidates, &one_tile(&pool), n);
            let wrong = chi_square_of(&candidates, &one_tile(&flat), n);
            let packing = options.packing;
            assert!(right < 16.27, "{packing:?} right: χ² = {right}");
            assert!(wrong > 16.27 * 10.0, "{packing:?} wrong: χ² = {wrong}");
        }
    }

    /// χ² of the quadrant counts of `kept` against the checkerboard's
    /// masses 0.1, 0.4, 0.4, 0.1.
    fn chi_square_of(candidates: &[SurfacePoint], kept: &[u32], n: usize) -> f64 {
        let mut counts = [0.0f64; 4];
        for &k in kept {
            let uv = candidates[k as usize].uv.unwrap();
            counts[usize::from(uv.x >= 0.5) + 2 * usize::from(uv.y >= 0.5)] += 1.0;
        }
        let expected = [0.1, 0.4, 0.4, 0.1].map(|p| p * n as f64);
        (0..4)
            .map(|q| (counts[q] - expected[q]).powi(2) / expected[q])
            .sum::<f64>()
    }

    /// The kept points drawn again are the candidates of `sample_n`, bit
    /// for bit, in the order asked for.
    #[test]
    fn redrawn_points_are_the_candidates() {
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let indices = [[0, 1, 2]];
        let sampler = UniformSampler::new(MeshRef::new(&positions, &indices)).unwrap();
        let m = 3 * CHUNK + 17;
        let all = sampler.sample_n(5, m).unwrap();
        let order = vec![m as u32 - 1, 0, 7, CHUNK as u32, 2 * CHUNK as u32 + 3, 1];
        let got = redraw(&sampler, 5, m, order.clone());
        let want: Vec<SurfacePoint> = order.iter().map(|&i| all[i as usize]).collect();
        assert_eq!(got, want);
        let ascending = vec![0, 1, 7, CHUNK as u32 + 1, m as u32 - 1];
        let got = redraw(&sampler, 5, m, ascending.clone());
        let want: Vec<SurfacePoint> = ascending.iter().map(|&i| all[i as usize]).collect();
        assert_eq!(got, want);
    }
}
