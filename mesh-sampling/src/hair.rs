//! Hair strands grown from roots on a surface: the application of Šik &
//! Křivánek 2013 (Sec. 6, Fig. 1a: 6 million hairs whose roots follow a
//! density texture).
//!
//! The geometry is documented on [`grow_strands`].

use glam::{Vec2, Vec3};
use rand::Rng;
use rand_pcg::Pcg64Mcg;

use crate::parallel::{CHUNK, check_points, chunk_rng, unit};
use crate::{Error, SurfacePoint, SurfaceSampler};

/// The most segments a strand may have (4,096): far beyond what a renderer
/// needs, and a bound that catches a count given by mistake before the
/// budget of [`MAX_POINTS`](crate::MAX_POINTS) is even computed.
pub const MAX_SEGMENTS: u32 = 4096;

/// What shapes one strand; see [`grow_strands`] for the geometry.
/// Lengths are in the mesh's unit, angles in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrandParams {
    /// Length of the strand's axis (`>= 0`; 0 gives a strand collapsed on its root).
    pub length: f32,
    /// World direction the strand is combed toward (only its component in
    /// the tangent plane counts; zero for none).
    pub comb: Vec3,
    /// Angle between the axis and the normal, in `[0, π]` (0: along the normal).
    pub comb_angle: f32,
    /// Radius of the curl helix at the tip (`>= 0`).
    pub curl_radius: f32,
    /// Turns of the curl helix over the whole strand (finite, any sign).
    pub curl_turns: f32,
    /// Amplitude of the random offset of each point at the tip (`>= 0`).
    pub noise: f32,
    /// Fraction of the way the tip moves toward its clump centre's tip, in `[0, 1]`.
    pub clump: f32,
    /// Width at the root (`>= 0`).
    pub width: f32,
    /// Width at the tip (`>= 0`).
    pub tip_width: f32,
}

impl StrandParams {
    /// A straight strand of `length` along the normal, 1 % of its length
    /// wide at the root and 0 at the tip.
    pub fn straight(length: f32) -> Self {
        Self {
            length,
            comb: Vec3::ZERO,
            comb_angle: 0.0,
            curl_radius: 0.0,
            curl_turns: 0.0,
            noise: 0.0,
            clump: 0.0,
            width: 0.01 * length,
            tip_width: 0.0,
        }
    }

    /// `Err` naming the first parameter out of range.
    fn check(&self, root: usize) -> Result<(), Error> {
        let bad = |parameter: &'static str, value: f32, expected: &'static str| {
            Err(Error::InvalidStrandParameter {
                root,
                parameter,
                value,
                expected,
            })
        };
        let non_negative = "finite and >= 0";
        if !(self.length.is_finite() && self.length >= 0.0) {
            return bad("length", self.length, non_negative);
        }
        if !self.comb.is_finite() {
            let value = [self.comb.x, self.comb.y, self.comb.z]
                .into_iter()
                .find(|v| !v.is_finite())
                .unwrap_or(f32::NAN);
            return bad("comb", value, "a finite direction");
        }
        if !(0.0..=std::f32::consts::PI).contains(&self.comb_angle) {
            return bad("comb_angle", self.comb_angle, "in [0, π] radians");
        }
        if !(self.curl_radius.is_finite() && self.curl_radius >= 0.0) {
            return bad("curl_radius", self.curl_radius, non_negative);
        }
        if !self.curl_turns.is_finite() {
            return bad("curl_turns", self.curl_turns, "finite");
        }
        if !(self.noise.is_finite() && self.noise >= 0.0) {
            return bad("noise", self.noise, non_negative);
        }
        if !(0.0..=1.0).contains(&self.clump) {
            return bad("clump", self.clump, "in [0, 1]");
        }
        if !(self.width.is_finite() && self.width >= 0.0) {
            return bad("width", self.width, non_negative);
        }
        if !(self.tip_width.is_finite() && self.tip_width >= 0.0) {
            return bad("tip_width", self.tip_width, non_negative);
        }
        Ok(())
    }
}

/// Options shared by all strands of one call to [`grow_strands`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HairOptions {
    /// Segments per strand `k` (`1..=`[`MAX_SEGMENTS`]); each strand has `k + 1` points.
    pub segments: u32,
    /// Seed of the curl phases, the noise and the choice of clump centres.
    pub seed: u64,
    /// Clump centres to draw among the roots (0: no clumping). Duplicate
    /// draws are merged, so there may be slightly fewer.
    pub clumps: usize,
    /// Store per-point widths in [`Strands::widths`].
    pub widths: bool,
}

impl Default for HairOptions {
    /// 8 segments (Šik & Křivánek's Fig. 1a), seed 0, no clumps, no widths.
    fn default() -> Self {
        Self {
            segments: 8,
            seed: 0,
            clumps: 0,
            widths: false,
        }
    }
}

/// Where a strand is attached: enough for a renderer to re-attach it to a
/// deformed mesh ([`SurfacePoint::on`]) or look up a texture.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Root {
    /// The triangle the root lies on.
    pub face: u32,
    /// Its barycentric coordinates in that triangle.
    pub barycentric: [f32; 3],
    /// The unit normal the strand was grown along (the shading normal, or
    /// the geometric one when the mesh has none).
    pub normal: Vec3,
    /// The texture coordinate, when the mesh has UVs.
    pub uv: Option<Vec2>,
}

/// Strands as one flat polyline buffer: strand `s` is
/// `points[s (k + 1) .. (s + 1) (k + 1)]`, root first, with
/// `k = segments`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Strands {
    /// Segments per strand `k`.
    pub segments: u32,
    /// All strands' points, `k + 1` per strand.
    pub points: Vec<Vec3>,
    /// Per-point widths (same length as `points`), when asked for.
    pub widths: Option<Vec<f32>>,
    /// Per-strand roots, in the order of the roots given.
    pub roots: Vec<Root>,
}

impl Strands {
    /// Points per strand, `segments + 1`.
    pub fn points_per_strand(&self) -> usize {
        self.segments as usize + 1
    }

    /// The number of strands.
    pub fn len(&self) -> usize {
        self.roots.len()
    }

    /// Whether there are no strands.
    pub fn is_empty(&self) -> bool {
        self.roots.is_empty()
    }

    /// The points of strand `s`, root first (`None` past the last strand).
    pub fn strand(&self, s: usize) -> Option<&[Vec3]> {
        let k = self.points_per_strand();
        self.points.get(s.checked_mul(k)?..(s + 1).checked_mul(k)?)
    }
}

/// Grows one strand per root: `k + 1` points each, shaped by
/// `params(root)` (a constant: `|_| StrandParams::straight(0.1)`; or read
/// from a texture or mesh-colour channel at the root's UV or face).
///
///
/// A strand is a polyline of `k` segments (`k + 1` points, the root first)
/// grown from a [`SurfacePoint`] along its shading normal (the geometric
/// normal when the mesh has none). Per root, [`StrandParams`] give:
///
/// - **length** `L` of the strand's axis, in the mesh's unit;
/// - **comb**: the axis `d = cos θ n + sin θ t` is the normal `n` tilted by
///   `comb_angle` θ towards `t`, the world direction `comb` projected onto
///   the tangent plane (no tilt where that projection vanishes);
/// - **curl**: a helix around the axis of radius `curl_radius · s` and
///   `curl_turns` turns over the strand, where `s = i / k` is the point's
///   parameter, so the curl grows from nothing at the root (which stays on
///   the surface); its phase is random per root;
/// - **noise**: each point moved by a random vector of `[-1, 1]³ · noise · s`;
/// - **clump**: strand points pulled toward the same point (same `i`) of
///   their clump centre's strand by the fraction `clump · s`, so the tip
///   moves `clump` of the way and the root stays;
/// - **width** at the root, tapering linearly to `tip_width` (only stored
///   when [`HairOptions::widths`] is set).
///
/// Point `i` of a strand before clumping is
/// `root + L s d + curl_radius s (cos φᵢ u + sin φᵢ v) + noise s ηᵢ` with
/// `φᵢ = φ₀ + 2π curl_turns s` and `(u, v)` an orthonormal pair
/// perpendicular to `d`. Without curl and noise it is exactly the straight
/// segment of length `L` along `d`.
///
/// **Clumps.** Up to [`HairOptions::clumps`] roots, drawn from the seed, are
/// clump centres; every strand is pulled toward the strand of the centre
/// nearest to its root (Euclidean, found in a uniform grid). A centre's
/// own strand does not move.
///
/// **Determinism.** Random phases and noise come from per-chunk streams
/// seeded by `(seed, chunk of 16,384 roots)`, and the clump centres from
/// the seed alone: the same roots, parameters and seed give the same
/// strands on any number of threads.
///
/// # Errors
/// - [`Error::InvalidOption`] if `options.segments` is 0 or above [`MAX_SEGMENTS`];
/// - [`Error::TooManyPoints`] if the strands would have more than
///   [`MAX_POINTS`](crate::MAX_POINTS) points (checked before allocating);
/// - [`Error::InvalidRoot`] for a root with a non-finite position or no
///   usable normal;
/// - [`Error::InvalidStrandParameter`] naming the root and parameter that is
///   NaN or out of range (the lowest such root, whatever the thread count).
pub fn grow_strands(
    roots: &[SurfacePoint],
    options: &HairOptions,
    params: impl Fn(&SurfacePoint) -> StrandParams + Sync,
) -> Result<Strands, Error> {
    grow_strands_with(roots, options, |_, root| params(root))
}

/// [`grow_strands`] with `params(index, root)`: for parameters held in
/// per-root arrays (a length per root from a painted channel, a file or
/// Python), indexed like `roots`.
///
/// # Errors
/// As for [`grow_strands`].
pub fn grow_strands_with(
    roots: &[SurfacePoint],
    options: &HairOptions,
    params: impl Fn(usize, &SurfacePoint) -> StrandParams + Sync,
) -> Result<Strands, Error> {
    grow(roots.len(), &Given(roots), options, params)
}

/// Hair from `n` roots drawn from `sampler` with `seed`: the strands of
/// [`grow_strands_with`] on `sampler.sample_n(seed, n)`, bit for bit, but
/// each chunk of roots is drawn and grown at once instead of all roots
/// being stored first (56 bytes a root less to write and read back: the
/// Fig. 1a pipeline of the `hair` example).
///
/// # Errors
/// As for [`grow_strands`].
pub fn grow_strands_sampled<S: SurfaceSampler>(
    sampler: &S,
    seed: u64,
    n: usize,
    options: &HairOptions,
    params: impl Fn(usize, &SurfacePoint) -> StrandParams + Sync,
) -> Result<Strands, Error> {
    grow(n, &Sampled { sampler, seed }, options, params)
}

/// Where a chunk's roots come from.
trait RootSource: Sync {
    /// `f` of the roots of chunk `c` (`len` of them).
    fn with_chunk<R>(&self, c: usize, len: usize, f: impl FnOnce(&[SurfacePoint]) -> R) -> R;
}

/// Roots given by the caller.
struct Given<'a>(&'a [SurfacePoint]);

impl RootSource for Given<'_> {
    fn with_chunk<R>(&self, c: usize, len: usize, f: impl FnOnce(&[SurfacePoint]) -> R) -> R {
        f(&self.0[c * CHUNK..c * CHUNK + len])
    }
}

/// Roots drawn chunk by chunk as [`SurfaceSampler::sample_n`] draws them
/// (chunk `c` from `chunk_rng(seed, c)`, the same [`CHUNK`]).
struct Sampled<'a, S> {
    sampler: &'a S,
    seed: u64,
}

impl<S: SurfaceSampler> RootSource for Sampled<'_, S> {
    fn with_chunk<R>(&self, c: usize, len: usize, f: impl FnOnce(&[SurfacePoint]) -> R) -> R {
        let mut roots = vec![SurfacePoint::default(); len];
        self.sampler
            .sample_into(&mut chunk_rng(self.seed, c), &mut roots);
        f(&roots)
    }
}

/// The strands of `n` roots from `source`.
fn grow(
    n: usize,
    source: &impl RootSource,
    options: &HairOptions,
    params: impl Fn(usize, &SurfacePoint) -> StrandParams + Sync,
) -> Result<Strands, Error> {
    let k = options.segments;
    if k == 0 || k > MAX_SEGMENTS {
        return Err(Error::InvalidOption(format!(
            "hair segments = {k}: a strand needs 1 to {MAX_SEGMENTS} segments"
        )));
    }
    let per = k as usize + 1;
    check_points(n as f64 * per as f64)?;
    let mut points = filled(n * per, Vec3::ZERO);
    let mut widths = options.widths.then(|| vec![0.0f32; n * per]);
    let mut out_roots = filled(n, Root::default());
    let mut clump = vec![0.0f32; if options.clumps > 0 { n } else { 0 }];

    let grow_one_chunk = |c: usize, chunk: ChunkOut<'_>| -> Result<(), Error> {
        let len = chunk.roots.len();
        source.with_chunk(c, len, |roots| {
            grow_chunk(c, roots, chunk, options, &params)
        })
    };
    let results = for_each_root_chunk(
        per,
        &mut points,
        widths.as_deref_mut(),
        &mut out_roots,
        &mut clump,
        grow_one_chunk,
    );
    if let Some(error) = results.into_iter().find_map(Result::err) {
        return Err(error);
    }
    if options.clumps > 0 && n > 0 {
        apply_clumps(options, per, &clump, &mut points);
    }
    Ok(Strands {
        segments: k,
        points,
        widths,
        roots: out_roots,
    })
}

/// Grows chunk `c`'s strands from its `roots` into its share of the outputs.
fn grow_chunk(
    c: usize,
    roots: &[SurfacePoint],
    mut chunk: ChunkOut<'_>,
    options: &HairOptions,
    params: &(impl Fn(usize, &SurfacePoint) -> StrandParams + Sync),
) -> Result<(), Error> {
    let k = options.segments;
    let per = k as usize + 1;
    let mut rng = chunk_rng(options.seed, c);
    let first = c * CHUNK;
    for (j, (root, out_root)) in roots.iter().zip(chunk.roots.iter_mut()).enumerate() {
        let index = first + j;
        let p = params(index, root);
        p.check(index)?;
        let normal = root_normal(root, index)?;
        *out_root = Root {
            face: root.face,
            barycentric: root.barycentric,
            normal,
            uv: root.uv,
        };
        let line = &mut chunk.points[j * per..(j + 1) * per];
        grow_one(root.position, normal, &p, &mut rng, line);
        if let Some(w) = chunk.widths.as_deref_mut() {
            let w = &mut w[j * per..(j + 1) * per];
            for (i, slot) in w.iter_mut().enumerate() {
                let s = i as f32 / k as f32;
                *slot = p.width + (p.tip_width - p.width) * s;
            }
        }
        if let Some(slot) = chunk.clump.get_mut(j) {
            *slot = p.clump;
        }
    }
    Ok(())
}

/// `n` copies of `value`, written on all threads: `vec![value; n]` fills
/// (and faults in) hundreds of megabytes on one thread, which for the
/// strands of millions of roots took as long as growing them.
fn filled<T: Copy + Send + Sync>(n: usize, value: T) -> Vec<T> {
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        (0..n)
            .into_par_iter()
            .with_min_len(CHUNK)
            .map(|_| value)
            .collect()
    }
    #[cfg(not(feature = "rayon"))]
    {
        vec![value; n]
    }
}

/// The unit direction a root's strand starts from.
fn root_normal(root: &SurfacePoint, index: usize) -> Result<Vec3, Error> {
    if !root.position.is_finite() {
        return Err(Error::InvalidRoot {
            root: index,
            reason: "its position is not finite",
        });
    }
    let shading = root
        .shading_normal
        .map_or(Vec3::ZERO, Vec3::normalize_or_zero);
    let normal = if shading == Vec3::ZERO {
        root.normal.normalize_or_zero()
    } else {
        shading
    };
    if normal == Vec3::ZERO {
        return Err(Error::InvalidRoot {
            root: index,
            reason: "it has no normal (zero or non-finite)",
        });
    }
    Ok(normal)
}

/// Writes one strand's `k + 1` points into `line`.
fn grow_one(origin: Vec3, normal: Vec3, p: &StrandParams, rng: &mut Pcg64Mcg, line: &mut [Vec3]) {
    let tangent = (p.comb - p.comb.dot(normal) * normal).normalize_or_zero();
    let (sin, cos) = p.comb_angle.sin_cos();
    let axis = if tangent == Vec3::ZERO {
        normal
    } else {
        cos * normal + sin * tangent
    };
    let k = (line.len() - 1) as f32;
    // One draw per root for the phase whether or not it curls, so that a
    // parameter change on one root does not shift the others' streams.
    let phase = unit(rng.next_u64()) as f32 * std::f32::consts::TAU;
    if p.curl_radius == 0.0 && p.noise == 0.0 {
        let step = axis * (p.length / k);
        for (i, slot) in line.iter_mut().enumerate() {
            *slot = origin + step * i as f32;
        }
        return;
    }
    let (u, v) = axis.any_orthonormal_pair();
    // The helix angle advances by a fixed rotation per point.
    let (step_sin, step_cos) = (std::f32::consts::TAU * p.curl_turns / k).sin_cos();
    let (mut s_phi, mut c_phi) = phase.sin_cos();
    for (i, slot) in line.iter_mut().enumerate() {
        let s = i as f32 / k;
        let mut at = origin + axis * (p.length * s) + (u * c_phi + v * s_phi) * (p.curl_radius * s);
        if p.noise > 0.0 {
            // Three 21-bit variates from one draw: ample for an offset.
            let bits = rng.next_u64();
            let jitter =
                |k: u32| ((bits >> (21 * k)) & 0x1F_FFFF) as f32 * (2.0 / 2_097_152.0) - 1.0;
            at += Vec3::new(jitter(0), jitter(1), jitter(2)) * (p.noise * s);
        }
        *slot = at;
        (c_phi, s_phi) = (
            c_phi * step_cos - s_phi * step_sin,
            s_phi * step_cos + c_phi * step_sin,
        );
    }
}

/// One chunk's share of the outputs.
struct ChunkOut<'a> {
    points: &'a mut [Vec3],
    widths: Option<&'a mut [f32]>,
    roots: &'a mut [Root],
    clump: &'a mut [f32],
}

/// Runs `grow(chunk index, outputs)` over chunks of [`CHUNK`] roots, on all
/// threads with `rayon`; the results in chunk order.
fn for_each_root_chunk(
    per: usize,
    points: &mut [Vec3],
    widths: Option<&mut [f32]>,
    roots: &mut [Root],
    clump: &mut [f32],
    grow: impl Fn(usize, ChunkOut<'_>) -> Result<(), Error> + Sync,
) -> Vec<Result<(), Error>> {
    let mut chunks: Vec<ChunkOut<'_>> = Vec::with_capacity(roots.len().div_ceil(CHUNK));
    let mut widths = widths.map(|w| w.chunks_mut(CHUNK * per));
    let mut clumps = clump.chunks_mut(CHUNK);
    for (r, p) in roots.chunks_mut(CHUNK).zip(points.chunks_mut(CHUNK * per)) {
        chunks.push(ChunkOut {
            points: p,
            widths: widths.as_mut().and_then(Iterator::next),
            roots: r,
            clump: clumps.next().unwrap_or_default(),
        });
    }
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        chunks
            .into_par_iter()
            .enumerate()
            .map(|(c, chunk)| grow(c, chunk))
            .collect()
    }
    #[cfg(not(feature = "rayon"))]
    {
        chunks
            .into_iter()
            .enumerate()
            .map(|(c, chunk)| grow(c, chunk))
            .collect()
    }
}

/// The clump centres: up to `options.clumps` root indices drawn from the
/// seed (sorted, duplicates merged).
fn clump_centres(n: usize, options: &HairOptions) -> Vec<usize> {
    // A stream apart from the chunks' (their chunk indices are small).
    let mut rng = chunk_rng(options.seed, usize::MAX);
    let mut centres: Vec<usize> = (0..options.clumps.min(n))
        .map(|_| ((unit(rng.next_u64()) * n as f64) as usize).min(n - 1))
        .collect();
    centres.sort_unstable();
    centres.dedup();
    centres
}

/// Pulls every strand toward its nearest clump centre's strand (second
/// pass: the centres' strands are copied first, so the result does not
/// depend on the order strands are visited in).
fn apply_clumps(options: &HairOptions, per: usize, clump: &[f32], points: &mut [Vec3]) {
    // A strand's first point is its root, exactly, and never moves.
    let centres = clump_centres(points.len() / per, options);
    let sites: Vec<Vec3> = centres.iter().map(|&c| points[c * per]).collect();
    let grid = Grid::new(&sites);
    let centre_lines: Vec<Vec3> = centres
        .iter()
        .flat_map(|&c| points[c * per..(c + 1) * per].iter().copied())
        .collect();
    let k = (per - 1) as f32;
    let pull = |(s, line): (usize, &mut [Vec3])| {
        let amount = clump[s];
        if amount == 0.0 {
            return;
        }
        let nearest = grid.nearest(&sites, line[0]);
        let centre = &centre_lines[nearest * per..(nearest + 1) * per];
        for (i, (at, c)) in line.iter_mut().zip(centre).enumerate() {
            *at += (*c - *at) * (amount * i as f32 / k);
        }
    };
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        points
            .par_chunks_mut(per)
            .enumerate()
            .with_min_len(1024)
            .for_each(pull);
    }
    #[cfg(not(feature = "rayon"))]
    points.chunks_mut(per).enumerate().for_each(pull);
}

/// A uniform grid over the clump centres for nearest-centre queries: cells
/// about as wide as the centres' spacing on a surface, searched ring by
/// ring until no closer centre can remain.
struct Grid {
    min: Vec3,
    cell: f32,
    dims: [usize; 3],
    /// Site indices grouped by cell; cell `c` holds `order[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    order: Vec<u32>,
}

/// The most cells a clump grid allocates.
const MAX_GRID_CELLS: f64 = (1 << 22) as f64;

impl Grid {
    fn new(sites: &[Vec3]) -> Self {
        let (min, max) = sites
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let e = (max - min).max(Vec3::splat(1e-12));
        // Sites on a surface: spread over about the box's face areas.
        let area =
            2.0 * (e.x as f64 * e.y as f64 + e.y as f64 * e.z as f64 + e.z as f64 * e.x as f64);
        // Half the spacing: fewer sites per cell visited (measured: the clump
        // pass about 1.3× faster than at the spacing itself).
        let mut cell = 0.5 * (area / sites.len() as f64).sqrt().max(1e-12);
        let cells = |cell: f64| {
            [e.x, e.y, e.z].map(|x| ((x as f64 / cell).floor() as usize).saturating_add(1))
        };
        while cells(cell).iter().map(|&d| d as f64).product::<f64>() > MAX_GRID_CELLS {
            cell *= 2.0;
        }
        let dims = cells(cell);
        let mut grid = Self {
            min,
            cell: cell as f32,
            dims,
            start: vec![0; dims[0] * dims[1] * dims[2] + 1],
            order: vec![0; sites.len()],
        };
        for &p in sites {
            let c = grid.index(grid.cell_of(p));
            grid.start[c + 1] += 1;
        }
        for c in 1..grid.start.len() {
            grid.start[c] += grid.start[c - 1];
        }
        let mut fill = grid.start.clone();
        for (s, &p) in sites.iter().enumerate() {
            let c = grid.index(grid.cell_of(p));
            grid.order[fill[c] as usize] = s as u32;
            fill[c] += 1;
        }
        grid
    }

    fn cell_of(&self, p: Vec3) -> [usize; 3] {
        let rel = (p - self.min) / self.cell;
        [rel.x, rel.y, rel.z]
            .map(|x| x.max(0.0) as usize)
            .zip_with(self.dims, |x, d| x.min(d - 1))
    }

    fn index(&self, [x, y, z]: [usize; 3]) -> usize {
        (z * self.dims[1] + y) * self.dims[0] + x
    }

    /// The index of the site nearest to `p` (the lowest index on ties).
    fn nearest(&self, sites: &[Vec3], p: Vec3) -> usize {
        let c = self.cell_of(p);
        let mut best = (f32::INFINITY, usize::MAX);
        let max_ring = self.dims.into_iter().max().unwrap_or(1);
        for ring in 0..=max_ring {
            let lo = c.map(|x| x.saturating_sub(ring));
            let hi = c.zip_with(self.dims, |x, d| (x + ring).min(d - 1));
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        let on_ring = [x, y, z]
                            .zip_with(c, |a, b| a.abs_diff(b))
                            .into_iter()
                            .max()
                            == Some(ring);
                        if !on_ring {
                            continue;
                        }
                        let cell = self.index([x, y, z]);
                        for &s in
                            &self.order[self.start[cell] as usize..self.start[cell + 1] as usize]
                        {
                            let d = sites[s as usize].distance_squared(p);
                            if (d, s as usize) < best {
                                best = (d, s as usize);
                            }
                        }
                    }
                }
            }
            // Sites outside the cube of rings 0..=ring lie beyond its
            // faces: at least the distance from `p` to the nearest face.
            let reach = (0..3)
                .map(|a| {
                    let lo = self.min[a] + (c[a] as f32 - ring as f32) * self.cell;
                    let hi = self.min[a] + (c[a] + ring + 1) as f32 * self.cell;
                    (p[a] - lo).min(hi - p[a])
                })
                .fold(f32::INFINITY, f32::min)
                .max(ring as f32 * self.cell);
            if best.1 != usize::MAX && best.0 <= reach * reach {
                break;
            }
        }
        best.1
    }
}

/// `[T; 3]::zip` with a function (stable `array::zip` is not there yet).
trait ZipWith<T> {
    fn zip_with<U, V>(self, other: [U; 3], f: impl Fn(T, U) -> V) -> [V; 3];
}

impl<T: Copy> ZipWith<T> for [T; 3] {
    fn zip_with<U, V>(self, other: [U; 3], f: impl Fn(T, U) -> V) -> [V; 3] {
        let [a, b, c] = self;
        let [x, y, z] = other;
        [f(a, x), f(b, y), f(c, z)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{MeshRef, SurfaceSampler, UniformSampler};

    /// A 1×1 square in the xy plane, normal +z, with UVs.
    fn square() -> (Vec<Vec3>, Vec<[u32; 3]>, Vec<Vec2>) {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        let uvs = vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
        (positions, vec![[0, 1, 2], [1, 3, 2]], uvs)
    }

    fn roots(n: usize, seed: u64) -> Vec<SurfacePoint> {
        let (p, i, uv) = square();
        let mesh = MeshRef {
            uvs: Some(&uv),
            ..MeshRef::new(&p, &i)
        };
        UniformSampler::new(mesh)
            .unwrap()
            .sample_n(seed, n)
            .unwrap()
    }

    fn options(segments: u32) -> HairOptions {
        HairOptions {
            segments,
            ..HairOptions::default()
        }
    }

    #[test]
    fn straight_strands_run_along_the_normal_with_their_exact_length() {
        let roots = roots(1000, 1);
        let strands = grow_strands(&roots, &options(5), |r| {
            StrandParams::straight(0.5 + r.position.x)
        })
        .unwrap();
        assert_eq!(strands.len(), 1000);
        assert_eq!(strands.points.len(), 6000);
        let mut total = 0.0f64;
        for (s, root) in roots.iter().enumerate() {
            let line = strands.strand(s).unwrap();
            assert_eq!(line[0], root.position);
            let want = 0.5 + root.position.x;
            for (i, p) in line.iter().enumerate() {
                let expect = root.position + Vec3::Z * (want * i as f32 / 5.0);
                assert!(
                    p.distance(expect) < 1e-6,
                    "strand {s} point {i}: {p} vs {expect}"
                );
            }
            let length: f32 = line.windows(2).map(|w| w[0].distance(w[1])).sum();
            assert!((length - want).abs() < 1e-5);
            total += length as f64;
            let r = strands.roots[s];
            assert_eq!(
                (r.face, r.barycentric, r.uv),
                (root.face, root.barycentric, root.uv)
            );
            assert_eq!(r.normal, Vec3::Z);
        }
        let expected: f64 = roots.iter().map(|r| 0.5 + r.position.x as f64).sum();
        assert!((total - expected).abs() < 1e-3 * expected);
        assert_eq!(strands.strand(1000), None);
    }

    #[test]
    fn comb_tilts_the_axis_by_its_angle_toward_the_comb_in_the_tangent_plane() {
        let roots = roots(200, 2);
        for angle in [0.3f32, 1.0, std::f32::consts::FRAC_PI_2] {
            let strands = grow_strands(&roots, &options(4), |_| StrandParams {
                // The z component is off the tangent plane and must not count.
                comb: Vec3::new(3.0, 0.0, 7.0),
                comb_angle: angle,
                ..StrandParams::straight(2.0)
            })
            .unwrap();
            for s in 0..roots.len() {
                let line = strands.strand(s).unwrap();
                let axis = line[4] - line[0];
                assert!((axis.length() - 2.0).abs() < 1e-5);
                let want = Vec3::new(angle.sin(), 0.0, angle.cos()) * 2.0;
                assert!(
                    axis.distance(want) < 1e-5,
                    "angle {angle}: {axis} vs {want}"
                );
            }
        }
    }

    #[test]
    fn curl_keeps_its_radius_about_the_axis_and_starts_at_the_root() {
        let roots = roots(100, 3);
        let strands = grow_strands(&roots, &options(16), |_| StrandParams {
            curl_radius: 0.25,
            curl_turns: 3.0,
            ..StrandParams::straight(1.0)
        })
        .unwrap();
        for (s, root) in roots.iter().enumerate() {
            let line = strands.strand(s).unwrap();
            assert_eq!(line[0], root.position);
            for (i, p) in line.iter().enumerate() {
                let t = i as f32 / 16.0;
                let rel = *p - root.position;
                assert!((rel.z - t).abs() < 1e-5, "height along the axis");
                assert!((rel.truncate().length() - 0.25 * t).abs() < 1e-5, "radius");
            }
        }
    }

    #[test]
    fn strands_are_the_same_on_any_number_of_threads() {
        let roots = roots(3 * CHUNK + 17, 4);
        let grow = || {
            grow_strands(
                &roots,
                &HairOptions {
                    segments: 6,
                    seed: 9,
                    clumps: 50,
                    widths: true,
                },
                |r| StrandParams {
                    curl_radius: 0.05,
                    curl_turns: 1.5,
                    noise: 0.02,
                    clump: r.position.y,
                    ..StrandParams::straight(0.3)
                },
            )
            .unwrap()
        };
        let pool = |n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap()
        };
        let one = pool(1).install(grow);
        let four = pool(4).install(grow);
        assert_eq!(one, four);
        assert_eq!(one.widths.as_ref().map(Vec::len), Some(one.points.len()));
    }

    #[test]
    fn strands_grown_while_sampling_equal_those_of_the_stored_roots() {
        let (p, i, uv) = square();
        let mesh = MeshRef {
            uvs: Some(&uv),
            ..MeshRef::new(&p, &i)
        };
        let sampler = UniformSampler::new(mesh).unwrap();
        let n = 2 * CHUNK + 99;
        let options = HairOptions {
            segments: 5,
            seed: 3,
            clumps: 25,
            widths: true,
        };
        let params = |i: usize, r: &SurfacePoint| StrandParams {
            curl_radius: 0.01,
            curl_turns: 2.0,
            noise: 0.003,
            clump: r.position.x,
            ..StrandParams::straight(0.1 + (i % 7) as f32 * 0.01)
        };
        let stored =
            grow_strands_with(&sampler.sample_n(11, n).unwrap(), &options, params).unwrap();
        let streamed = grow_strands_sampled(&sampler, 11, n, &options, params).unwrap();
        assert_eq!(stored, streamed);
        let other_seed = grow_strands_sampled(&sampler, 12, n, &options, params).unwrap();
        assert_ne!(stored.points, other_seed.points);
    }

    #[test]
    fn clumping_moves_each_tip_its_fraction_of_the_way_to_the_nearest_centre() {
        let roots = roots(5000, 5);
        let opts = HairOptions {
            clumps: 40,
            ..options(8)
        };
        let loose = grow_strands(&roots, &opts, |_| StrandParams::straight(1.0)).unwrap();
        let clumped = grow_strands(&roots, &opts, |_| StrandParams {
            clump: 0.75,
            ..StrandParams::straight(1.0)
        })
        .unwrap();
        let centres = clump_centres(roots.len(), &opts);
        assert!(centres.len() > 30 && centres.len() <= 40);
        let (mut before, mut after) = (0.0f64, 0.0f64);
        for (s, root) in roots.iter().enumerate() {
            // The nearest centre by brute force, not by the grid.
            let c = *centres
                .iter()
                .min_by(|&&a, &&b| {
                    let da = roots[a].position.distance_squared(root.position);
                    let db = roots[b].position.distance_squared(root.position);
                    da.total_cmp(&db).then(a.cmp(&b))
                })
                .unwrap();
            let centre_tip = loose.strand(c).unwrap()[8];
            let (tip0, tip1) = (loose.strand(s).unwrap()[8], clumped.strand(s).unwrap()[8]);
            let want = tip0 + (centre_tip - tip0) * 0.75;
            assert!(tip1.distance(want) < 1e-5, "strand {s}: {tip1} vs {want}");
            assert_eq!(clumped.strand(s).unwrap()[0], root.position, "roots stay");
            before += tip0.distance(centre_tip) as f64;
            after += tip1.distance(centre_tip) as f64;
        }
        assert!((after - 0.25 * before).abs() < 1e-3 * before);
    }

    #[test]
    fn the_grid_finds_the_brute_force_nearest_site() {
        let mut rng = chunk_rng(7, 0);
        let mut point = || {
            Vec3::new(
                unit(rng.next_u64()) as f32,
                unit(rng.next_u64()) as f32 * 0.1,
                unit(rng.next_u64()) as f32 * 3.0,
            )
        };
        let sites: Vec<Vec3> = (0..300).map(|_| point()).collect();
        let grid = Grid::new(&sites);
        for _ in 0..2000 {
            let q = point() * 1.5 - Vec3::splat(0.2);
            let brute = (0..sites.len())
                .min_by(|&a, &b| {
                    sites[a]
                        .distance_squared(q)
                        .total_cmp(&sites[b].distance_squared(q))
                })
                .unwrap();
            assert_eq!(
                sites[grid.nearest(&sites, q)].distance_squared(q),
                sites[brute].distance_squared(q)
            );
        }
    }

    #[test]
    fn bad_parameters_are_errors_naming_root_and_parameter() {
        let roots = roots(2 * CHUNK + 5, 6);
        let bad_root = CHUNK + 3;
        for (parameter, set) in [
            (
                "length",
                (|p: &mut StrandParams| p.length = f32::NAN) as fn(&mut StrandParams),
            ),
            ("length", |p| p.length = -1.0),
            ("comb_angle", |p| p.comb_angle = 4.0),
            ("curl_radius", |p| p.curl_radius = f32::INFINITY),
            ("clump", |p| p.clump = 1.5),
            ("width", |p| p.width = -0.1),
        ] {
            let err = grow_strands(&roots, &options(3), |r| {
                let mut p = StrandParams::straight(1.0);
                // Two bad roots: the lower one is reported.
                if r == &roots[bad_root] || r == &roots[2 * CHUNK + 1] {
                    set(&mut p);
                }
                p
            })
            .unwrap_err();
            assert!(
                matches!(err, Error::InvalidStrandParameter { root, parameter: got, .. } if root == bad_root && got == parameter),
                "{err}"
            );
            assert!(err.to_string().contains(parameter));
        }
        for segments in [0, MAX_SEGMENTS + 1] {
            let err = grow_strands(&roots, &options(segments), |_| StrandParams::straight(1.0))
                .unwrap_err();
            assert!(err.to_string().contains("segments"), "{err}");
        }
        let mut nan = roots[..3].to_vec();
        nan[1].position.x = f32::NAN;
        let err = grow_strands(&nan, &options(3), |_| StrandParams::straight(1.0)).unwrap_err();
        assert_eq!(
            err,
            Error::InvalidRoot {
                root: 1,
                reason: "its position is not finite"
            }
        );
    }

    #[test]
    fn the_point_budget_is_checked_before_allocating() {
        let roots = roots(40_000, 7);
        let err = grow_strands(&roots, &options(MAX_SEGMENTS), |_| {
            StrandParams::straight(1.0)
        })
        .unwrap_err();
        assert!(matches!(err, Error::TooManyPoints { .. }), "{err}");
    }
}
