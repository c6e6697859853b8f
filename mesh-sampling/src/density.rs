//! Sampling with a density: a texture by adaptive subdivision (Šik &
//! Křivánek 2013, Sec. 3.3–3.5), optionally exact, or per-face and
//! per-vertex weights.

use discrete_sampling::{DiscreteSampler, GuideTable};
use glam::{DVec2, Vec2};
use rand::Rng;
use rand::distr::Distribution;

use crate::layout::{Piece, PieceAlias};
use crate::parallel::{BLOCK, unit};
use crate::point::Frame;
use crate::subdivision::{self, MAX_LEVEL, Merge, SubTriangle, Values};
use crate::{DensityTexture, Error, Layout, MeshRef, SurfacePoint, SurfaceSampler};

/// Where the density comes from.
#[derive(Debug, Clone, Copy)]
pub enum Density<'a> {
    /// A texture looked up at the mesh's UVs.
    Texture(&'a DensityTexture),
    /// One weight per triangle, constant over it.
    PerFace(&'a [f32]),
    /// One weight per vertex, linear over each triangle.
    PerVertex(&'a [f32]),
}

/// Which density a texture sampler draws from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    /// The paper's `p′` (Eq. 2): the density sampled at each
    /// sub-triangle's barycenter, constant over the sub-triangle. Fastest;
    /// a sub-triangle straddling a texel edge gets one value.
    #[default]
    Approximate,
    /// The filtered texture exactly: `p′`'s subdivision as the proposal,
    /// weighted by a bound of the density on each sub-triangle (its exact
    /// maximum over the sub-triangle's UV bounding box), and a rejection
    /// step. [`DensitySampler::acceptance`] says how often it accepts.
    Exact,
}

/// How the subdivision depth of a triangle follows the texels it covers
/// (Šik & Křivánek 2013, Sec. 3.4: "each triangle is subdivided so that its
/// sub-triangles are smaller than a texel").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Depth {
    /// The level `L` with `4^L` nearest to the texel count `T` of the
    /// triangle (in log scale): sub-triangles of half a texel to two.
    Nearest,
    /// The paper's rule (the default): the smallest `L` with
    /// `T / 4^L ≤ 1`, so every sub-triangle covers at most one texel.
    /// Measured on the six data meshes with a noise and an HDR density
    /// (the `depth` example), it brings `p′` closer to the filtered
    /// density than [`Nearest`](Self::Nearest) in every case (total
    /// variation 1–7% lower) for 2–7% more pieces, since the edge rule
    /// already subdivides most triangles that far.
    #[default]
    AtMostOneTexel,
}

/// How finely a texture density is subdivided and merged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Approximate (the paper) or exact.
    pub mode: Mode,
    /// How a piece is drawn: the alias table with inlined records
    /// (default, one cache miss a draw) or the order-preserving inversion
    /// method.
    pub layout: Layout,
    /// The depth rule by texel count (both rules also subdivide until no
    /// sub-triangle edge spans more than two texels).
    pub depth: Depth,
    /// The most sub-triangles the subdivision may make before merging,
    /// `Σ 4^L` over the triangles whose texture footprint is not constant
    /// (a constant one is one piece). Computed before anything is built;
    /// when the depths ask for more, the deepest triangles are capped at
    /// a common level until the sum fits (coarser where it must: each
    /// capped sub-triangle takes the density at its barycenter, and the
    /// exact mode stays exact, with a lower acceptance). Default
    /// `1 << 22` (4,194,304: about 200 MB of tables), four sub-triangles
    /// per texel of a 1024² texture; the error
    /// [`Error::TooManyPieces`] only when even one piece per triangle
    /// exceeds it.
    pub max_pieces: usize,
    /// The deepest subdivision level, at most 13 (`4^13` sub-triangles for
    /// one triangle). Default 11: a triangle spanning a 2048² texture.
    pub max_level: u8,
    /// Levels beyond the one that makes sub-triangles about a texel (and
    /// their edges no longer than two). Each one divides the approximation error of
    /// [`Mode::Approximate`] (or the rejection rate of [`Mode::Exact`])
    /// roughly by two, and costs four times the memory.
    pub extra_levels: u8,
    /// Relative tolerance for merging siblings: 0 (default) merges only
    /// equal values, so `p′` is unchanged; `t > 0` merges when
    /// `max − min ≤ t · max`, trading accuracy (approximate mode: the mean
    /// replaces the four values) or acceptance (exact mode: the maximum)
    /// for memory.
    pub merge_tolerance: f32,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            mode: Mode::Approximate,
            layout: Layout::Alias,
            depth: Depth::AtMostOneTexel,
            max_pieces: DEFAULT_MAX_PIECES,
            max_level: 11,
            extra_levels: 0,
            merge_tolerance: 0.0,
        }
    }
}

/// The default of [`Options::max_pieces`].
pub const DEFAULT_MAX_PIECES: usize = 1 << 22;

/// The structure a piece is drawn from.
#[derive(Debug, Clone)]
enum Table<S> {
    Alias(PieceAlias),
    Inversion(S),
}

/// Draws points on a mesh with probability density proportional to a
/// texture, per-face or per-vertex weights.
///
/// A texture density is resampled on an adaptive subdivision of each
/// triangle (Šik & Křivánek 2013): the depth makes sub-triangles about a
/// texel and their edges no longer than two texels (so slivers are
/// subdivided along their length too), the density is looked up at each
/// sub-triangle's
/// barycenter, and four siblings of equal value merge into their parent.
/// A sub-triangle costs its triangle, a 32-bit code of its level and
/// position (Fig. 4, decoded in O(1)) and its value, plus its share of the
/// table it is drawn from ([`Layout`]): by default an alias table whose
/// columns hold the records themselves (one cache miss per draw). With
/// [`Layout::Inversion`], `S` is the 1D sampler over the CDF that picks a
/// sub-triangle: the guide table by default,
/// [`CdfBisection`](discrete_sampling::CdfBisection) for the paper's
/// "without table" variant.
///
/// Per-face weights are sampled exactly (triangle by weight × area, then
/// uniformly in it), and so are per-vertex weights: a linear density is a
/// mixture of three components, each "proportional to one barycentric
/// weight", drawn in closed form.
///
/// # Example
/// ```
/// use glam::{Vec2, Vec3};
/// use mesh_sampling::{Density, DensitySampler, DensityTexture, MeshRef, SurfaceSampler};
///
/// let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
/// let uvs = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
/// let indices = [[0, 1, 2], [1, 3, 2]];
/// let mesh = MeshRef { uvs: Some(&uvs), ..MeshRef::new(&positions, &indices) };
/// // Left half black, right half white.
/// let texture = DensityTexture::new(2, 1, vec![0.0, 1.0])?
///     .with_filter(mesh_sampling::Filter::Nearest);
/// let sampler = DensitySampler::new(mesh, Density::Texture(&texture))?;
/// for p in sampler.sample_n(1, 1000).unwrap() {
///     assert!(p.position.x >= 0.5);
///     assert!((p.pdf - 2.0).abs() < 1e-4); // density 1 over half the area
/// }
/// # Ok::<(), mesh_sampling::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct DensitySampler<'a, S = GuideTable> {
    mesh: MeshRef<'a>,
    density: Density<'a>,
    mode: Mode,
    pieces: Vec<Piece>,
    table: Table<S>,
    /// Pieces of face `f`: `face_start[f]..face_start[f + 1]`.
    face_start: Vec<u32>,
    /// Subdivision depth of each face (texture densities).
    face_level: Vec<u8>,
    /// Per face, its corner, edges and normal: one memory access.
    frames: Vec<Frame>,
    /// `1 / ∫ density dA` of the density sampled.
    norm: f64,
    /// Expected fraction of proposals accepted (1 without rejection).
    acceptance: f64,
}

impl<'a> DensitySampler<'a, GuideTable> {
    /// A sampler with default [`Options`] and the guide table.
    ///
    /// # Errors
    /// As for [`with_options`](Self::with_options).
    pub fn new(mesh: MeshRef<'a>, density: Density<'a>) -> Result<Self, Error> {
        Self::with_options(mesh, density, &Options::default())
    }

    /// A sampler with the guide table and `options`.
    ///
    /// # Errors
    /// As for [`with_table`](Self::with_table).
    pub fn with_options(
        mesh: MeshRef<'a>,
        density: Density<'a>,
        options: &Options,
    ) -> Result<Self, Error> {
        Self::with_table(mesh, density, options)
    }
}

impl<'a, S: DiscreteSampler + Sync> DensitySampler<'a, S> {
    /// Validates the mesh and the density, subdivides (in parallel with
    /// the `rayon` feature; the result does not depend on the thread
    /// count) and builds the table `options.layout` names; with
    /// [`Layout::Inversion`] it is of type `S`:
    /// `DensitySampler::<CdfBisection>::with_table(…)` is the paper's
    /// variant without the lookup table (`S` is not used by the alias
    /// layout).
    ///
    /// # Errors
    /// The mesh's errors ([`MeshRef::validate`]); [`Error::MissingUvs`] or
    /// [`Error::NonFiniteUv`] for a texture density;
    /// [`Error::WeightLength`], [`Error::InvalidWeight`] for weights;
    /// [`Error::InvalidOption`]; [`Error::TooManyPieces`] when one piece
    /// per triangle already exceeds [`Options::max_pieces`];
    /// [`Error::IntegrationTooLarge`] in exact mode for UVs that tile a
    /// varying texture too many times to integrate it exactly, and
    /// [`Error::AcceptanceTooLow`] below [`MIN_ACCEPTANCE`];
    /// [`Error::ZeroDensity`] when the density is zero on every triangle
    /// of non-zero area.
    pub fn with_table(
        mesh: MeshRef<'a>,
        density: Density<'a>,
        options: &Options,
    ) -> Result<Self, Error> {
        mesh.validate()?;
        if options.max_level > MAX_LEVEL {
            return Err(Error::InvalidOption(format!(
                "max_level {} exceeds {MAX_LEVEL}",
                options.max_level
            )));
        }
        if !(options.merge_tolerance >= 0.0 && options.merge_tolerance <= 1.0) {
            return Err(Error::InvalidOption(format!(
                "merge_tolerance {} is not in [0, 1]",
                options.merge_tolerance
            )));
        }
        let faces = mesh.indices.len();
        // Threads pay off for large meshes or deep subdivisions; below
        // that, waking them costs more than the work (a constant density
        // builds as fast as the uniform sampler's table).
        let many = faces >= PARALLEL_FACES;
        let (pieces, face_start, face_level, exact_mass) = match density {
            Density::Texture(texture) => {
                let uvs = texture_uvs(&mesh)?;
                // Per face: its level, and its value if the density is
                // constant over its footprint (then it is one piece).
                let wanted: Vec<(u8, Option<f32>)> = map_faces(many, faces, |f| {
                    let uv = face_uvs(uvs, mesh.indices[f]);
                    (face_level(texture, uv, options), uv_constant(texture, uv))
                });
                let (levels, leaves) = capped_levels(&wanted, options.max_pieces)?;
                let heavy = many || leaves >= PARALLEL_LEAVES;
                let (pieces, starts) = collect_pieces(heavy, faces, |f, out| match wanted[f].1 {
                    Some(c) if c > 0.0 && mesh.area(f) > 0.0 => out.push((SubTriangle::ROOT, c)),
                    Some(_) => {}
                    None => texture_pieces(&mesh, uvs, texture, levels[f], options, f, out),
                });
                if options.mode == Mode::Exact {
                    check_integration(&mesh, uvs, texture)?;
                }
                let exact = (options.mode == Mode::Exact).then(|| {
                    map_faces(heavy, faces, |f| exact_mass(&mesh, uvs, texture, f))
                        .iter()
                        .sum()
                });
                (pieces, starts, levels, exact)
            }
            Density::PerFace(w) => {
                check_weights("face", w, faces)?;
                let (pieces, starts) = collect_pieces(many, faces, |f, out| {
                    if w[f] > 0.0 && mesh.area(f) > 0.0 {
                        out.push((SubTriangle::ROOT, w[f]));
                    }
                });
                (pieces, starts, vec![0; faces], None)
            }
            Density::PerVertex(w) => {
                check_weights("vertex", w, mesh.positions.len())?;
                let (pieces, starts) = collect_pieces(many, faces, |f, out| {
                    if mesh.area(f) > 0.0 {
                        let tri = mesh.indices[f];
                        for c in (0..3).filter(|&c| w[tri[c] as usize] > 0.0) {
                            out.push((SubTriangle::vertex(c), w[tri[c] as usize]));
                        }
                    }
                });
                (pieces, starts, vec![0; faces], None)
            }
        };
        if pieces.len() > u32::MAX as usize {
            return Err(Error::TooLarge(pieces.len()));
        }
        let areas: Vec<f64> = map_faces(many, faces, |f| mesh.area(f));
        let masses: Vec<f64> = pieces
            .iter()
            .map(|p| f64::from(p.value) * areas[p.face as usize] * piece_fraction(p.part))
            .collect();
        let proposal_mass: f64 = masses.iter().sum();
        let zero = Error::ZeroDensity { triangles: faces };
        let table = match options.layout {
            Layout::Alias => Table::Alias(PieceAlias::new(&pieces, &masses).ok_or(zero)?),
            Layout::Inversion => Table::Inversion(S::from_weights(&masses).map_err(|_| zero)?),
        };
        drop(masses);
        let mass = exact_mass.unwrap_or(proposal_mass);
        if mass.is_nan() || mass <= 0.0 {
            return Err(Error::ZeroDensity { triangles: faces });
        }
        check_acceptance((mass / proposal_mass).min(1.0))?;
        Ok(Self {
            mesh,
            density,
            mode: if exact_mass.is_some() {
                Mode::Exact
            } else {
                Mode::Approximate
            },
            pieces,
            table,
            face_start,
            face_level,
            frames: Frame::all(&mesh),
            norm: 1.0 / mass,
            acceptance: (mass / proposal_mass).min(1.0),
        })
    }

    /// The mesh sampled.
    pub fn mesh(&self) -> &MeshRef<'a> {
        &self.mesh
    }

    /// The mode actually used: [`Mode::Exact`] only for a texture density
    /// built with it (per-face and per-vertex densities are always exact).
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Number of sub-triangles (or linear components) in the table.
    pub fn pieces(&self) -> usize {
        self.pieces.len()
    }

    /// The subdivision depth of triangle `face` (0 for weights).
    pub fn level(&self, face: usize) -> u8 {
        self.face_level.get(face).copied().unwrap_or(0)
    }

    /// The integral of the sampled density's unnormalised form over the
    /// mesh: `Σ f_i |D_i|` (Eq. 2's denominator) in approximate mode, the
    /// exact integral of the filtered texture in exact mode.
    pub fn total_mass(&self) -> f64 {
        1.0 / self.norm
    }

    /// The expected fraction of proposals accepted: 1 in approximate mode
    /// and for weights, `∫ f / Σ bound_i |D_i|` in exact mode.
    pub fn acceptance(&self) -> f64 {
        self.acceptance
    }

    /// The layout pieces are drawn from.
    pub fn layout(&self) -> Layout {
        match self.table {
            Table::Alias(_) => Layout::Alias,
            Table::Inversion(_) => Layout::Inversion,
        }
    }

    /// Heap memory of the sampler (pieces, table, face index and frames), not
    /// counting the mesh and texture it borrows.
    pub fn memory_bytes(&self) -> usize {
        let table = match &self.table {
            Table::Alias(a) => a.memory_bytes(),
            Table::Inversion(t) => t.memory_bytes(),
        };
        self.pieces.len() * size_of::<Piece>()
            + table
            + self.face_start.len() * size_of::<u32>()
            + self.face_level.len()
            + self.frames.len() * size_of::<Frame>()
    }

    /// The density (w.r.t. area, normalised over the mesh) this sampler
    /// draws from, at barycentrics `barycentric` of triangle `face`: what a
    /// path tracer needs for multiple importance sampling when a ray hits
    /// the mesh. 0 for a triangle that does not exist, a zero-area
    /// triangle, or barycentrics that are NaN or infinite.
    pub fn pdf(&self, face: usize, barycentric: [f32; 3]) -> f32 {
        let Some(range) = self.face_range(face) else {
            return 0.0;
        };
        if !barycentric.iter().all(|b| b.is_finite()) {
            return 0.0;
        }
        let [b0, b1, b2] = barycentric.map(f64::from);
        let value = match self.density {
            Density::PerFace(w) => {
                if range.is_empty() {
                    0.0
                } else {
                    f64::from(w[face])
                }
            }
            Density::PerVertex(w) => {
                if range.is_empty() {
                    return 0.0;
                }
                let t = self.mesh.indices[face].map(|i| f64::from(w[i as usize]));
                t[0] * b0 + t[1] * b1 + t[2] * b2
            }
            Density::Texture(texture) => match self.mode {
                Mode::Exact if range.is_empty() => 0.0,
                Mode::Exact => texture.eval(self.uv_at(face, b1, b2)),
                Mode::Approximate => self.approximate_value(range, face, b1, b2),
            },
        };
        (value * self.norm) as f32
    }

    fn face_range(&self, face: usize) -> Option<std::ops::Range<usize>> {
        let start = *self.face_start.get(face)? as usize;
        let end = *self.face_start.get(face + 1)? as usize;
        Some(start..end)
    }

    /// `p′` before normalisation at `(u, v)` of `face`: the value of the
    /// stored sub-triangle containing it, found by bisection on the
    /// depth-first keys of the face's sub-triangles.
    fn approximate_value(&self, range: std::ops::Range<usize>, face: usize, u: f64, v: f64) -> f64 {
        let depth = self.face_level[face];
        let key = SubTriangle::locate(depth, u, v).key(depth);
        let pieces = &self.pieces[range];
        let k = pieces.partition_point(|p| p.part.key(depth) <= key);
        let Some(p) = k.checked_sub(1).map(|k| pieces[k]) else {
            return 0.0;
        };
        let span = 1u64 << (2 * (depth - p.part.level()));
        if key < p.part.key(depth) + span {
            f64::from(p.value)
        } else {
            0.0
        }
    }

    /// The texture coordinate at `(u, v)` of `face`.
    #[inline]
    fn uv_at(&self, face: usize, u: f64, v: f64) -> DVec2 {
        let uvs = self.mesh.uvs.unwrap_or_default();
        let [a, b, c] = face_uvs(uvs, self.mesh.indices[face]);
        a + (b - a) * u + (c - a) * v
    }

    /// Where piece `k` puts the point for variates `xi1`, `xi2`: parent
    /// barycentrics.
    #[inline]
    fn place(&self, piece: Piece, xi1: f64, xi2: f64) -> [f32; 3] {
        match piece.part.corner() {
            Some(corner) => linear_corner_barycentric(corner, xi1, xi2),
            None => {
                // The square-root map (Sec. 3.5) in the sub-triangle's own
                // legs, kept in f64 up to the parent's barycentrics.
                let s = xi1.sqrt();
                let a = xi2 * s;
                let (u, v) = piece.part.to_parent(a, s - a);
                [(1.0 - u - v).max(0.0) as f32, u as f32, v as f32]
            }
        }
    }

    /// The point at `bary` of the piece's face, with its density (which
    /// for the approximate mode and per-face weights is the piece's value,
    /// and for per-vertex weights is interpolated).
    #[inline]
    fn point(&self, piece: Piece, bary: [f32; 3], value: f64) -> SurfacePoint {
        let face = piece.face;
        let frame = &self.frames[face as usize];
        SurfacePoint::in_frame(&self.mesh, frame, face, bary, (value * self.norm) as f32)
    }

    /// The unnormalised density of a non-rejected point.
    #[inline]
    fn value(&self, piece: Piece, bary: [f32; 3]) -> f64 {
        match self.density {
            Density::PerVertex(w) => {
                let t = self.mesh.indices[piece.face as usize].map(|i| w[i as usize]);
                f64::from(t[0] * bary[0] + t[1] * bary[1] + t[2] * bary[2])
            }
            _ => f64::from(piece.value),
        }
    }

    /// One piece drawn from the table (one `u64` of `rng`).
    #[inline]
    fn piece<R: Rng + ?Sized>(&self, rng: &mut R) -> Piece {
        match &self.table {
            Table::Alias(alias) => alias.piece(rng.next_u64()),
            Table::Inversion(table) => self.pieces[table.sample_rng(rng)],
        }
    }

    /// Fills `out` with pieces (one `u64` of `rng` each): the variates
    /// first, then the searches, then the records, each in a pass of its
    /// own so that the loads of independent draws overlap.
    #[inline]
    fn pieces_into<R: Rng + ?Sized>(&self, rng: &mut R, out: &mut [Piece]) {
        match &self.table {
            Table::Alias(alias) => alias.fill(rng, out),
            Table::Inversion(table) => {
                let mut picks = [0usize; BLOCK];
                for block in out.chunks_mut(BLOCK) {
                    let picks = &mut picks[..block.len()];
                    table.sample_into(rng, picks);
                    for (piece, &k) in block.iter_mut().zip(picks.iter()) {
                        *piece = self.pieces[k];
                    }
                }
            }
        }
    }

    fn exact_texture(&self) -> Option<&DensityTexture> {
        match (self.density, self.mode) {
            (Density::Texture(t), Mode::Exact) => Some(t),
            _ => None,
        }
    }
}

impl<S: DiscreteSampler + Sync> DensitySampler<'_, S> {
    /// Blender's per-triangle mode with a density: each triangle draws its
    /// own number of points, `points_per_unit_mass` times its mass
    /// `∫ p dA` rounded down or up at random, and their positions, all
    /// from a random stream seeded by `(seed, triangle index)`, so editing
    /// part of a mesh (or of its weights) leaves the points of the other
    /// triangles unchanged. In exact mode the triangle's proposals are
    /// counted that way and thinned by the rejection step, which keeps the
    /// expected count `points_per_unit_mass · ∫ p dA` exactly. Points come
    /// in triangle order, the same on any number of threads; their
    /// density field is the sampler's `pdf` times `points_per_unit_mass ·
    /// total_mass()`.
    ///
    /// # Errors
    /// [`Error::InvalidDensity`] for a negative, NaN or infinite rate;
    /// [`Error::TooManyPoints`] when the count could exceed
    /// [`MAX_POINTS`](crate::MAX_POINTS) (the rate times the proposal mass,
    /// plus one per triangle), checked before allocating.
    pub fn sample_stable(
        &self,
        seed: u64,
        points_per_unit_mass: f64,
    ) -> Result<Vec<SurfacePoint>, Error> {
        if !(points_per_unit_mass >= 0.0 && points_per_unit_mass.is_finite()) {
            return Err(Error::InvalidDensity(points_per_unit_mass));
        }
        let faces = self.mesh.indices.len() as f64;
        let proposal_mass = self.total_mass() / self.acceptance;
        crate::parallel::check_points(points_per_unit_mass * proposal_mass + faces)?;
        let texture = self.exact_texture();
        let triangle = |face: usize| -> Vec<SurfacePoint> {
            let Some(range) = self.face_range(face) else {
                return Vec::new();
            };
            let area = self.mesh.area(face);
            // The face's proposal masses, accumulated for the choice.
            let mut cumulative = Vec::with_capacity(range.len());
            let mut sum = 0.0;
            for p in &self.pieces[range.clone()] {
                sum += f64::from(p.value) * area * piece_fraction(p.part);
                cumulative.push(sum);
            }
            if sum.is_nan() || sum <= 0.0 {
                return Vec::new();
            }
            let mut rng = crate::parallel::chunk_rng(seed, face);
            let expected = points_per_unit_mass * sum;
            let whole = expected.floor();
            let extra = unit(rng.next_u64()) < expected - whole;
            let count = whole as usize + usize::from(extra);
            let mut points = Vec::with_capacity(count);
            for _ in 0..count {
                let target = unit(rng.next_u64()) * sum;
                let k = cumulative
                    .partition_point(|&c| c <= target)
                    .min(cumulative.len() - 1);
                let piece = self.pieces[range.start + k];
                let xi1 = unit(rng.next_u64());
                let bary = self.place(piece, xi1, unit(rng.next_u64()));
                match texture {
                    None => points.push(self.point(piece, bary, self.value(piece, bary))),
                    Some(texture) => {
                        let [_, u, v] = bary.map(f64::from);
                        let f = texture.eval(self.uv_at(face, u, v));
                        if unit(rng.next_u64()) * f64::from(piece.value) < f {
                            points.push(self.point(piece, bary, f));
                        }
                    }
                }
            }
            points
        };
        Ok(crate::parallel::per_face(self.mesh.indices.len(), triangle))
    }
}

/// Three `u64` of the random stream per point (one for the piece, two for
/// the point in it); four per proposal in exact mode.
impl<S: DiscreteSampler + Sync> SurfaceSampler for DensitySampler<'_, S> {
    /// Computed in blocks, like
    /// [`UniformSampler`](crate::UniformSampler)'s: the block's pieces by
    /// the table's batch search, then their records, then the points; in
    /// exact mode, blocks of proposals of which the accepted are kept.
    fn sample_into<R: Rng + ?Sized>(&self, rng: &mut R, out: &mut [SurfacePoint]) {
        let mut pieces = [Piece::default(); BLOCK];
        if let Some(texture) = self.exact_texture() {
            // Proposals in blocks, the accepted ones kept in order.
            let mut filled = 0;
            while filled < out.len() {
                self.pieces_into(rng, &mut pieces);
                for &piece in &pieces {
                    let xi1 = unit(rng.next_u64());
                    let bary = self.place(piece, xi1, unit(rng.next_u64()));
                    let [_, u, v] = bary.map(f64::from);
                    let f = texture.eval(self.uv_at(piece.face as usize, u, v));
                    if unit(rng.next_u64()) * f64::from(piece.value) < f && filled < out.len() {
                        out[filled] = self.point(piece, bary, f);
                        filled += 1;
                    }
                }
            }
            return;
        }
        for block in out.chunks_mut(BLOCK) {
            let n = block.len();
            self.pieces_into(rng, &mut pieces[..n]);
            for (slot, &piece) in block.iter_mut().zip(&pieces) {
                let xi1 = unit(rng.next_u64());
                let bary = self.place(piece, xi1, unit(rng.next_u64()));
                *slot = self.point(piece, bary, self.value(piece, bary));
            }
        }
    }
}

impl<S: DiscreteSampler + Sync> Distribution<SurfacePoint> for DensitySampler<'_, S> {
    fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> SurfacePoint {
        loop {
            let piece = self.piece(rng);
            let xi1 = unit(rng.next_u64());
            let bary = self.place(piece, xi1, unit(rng.next_u64()));
            let Some(texture) = self.exact_texture() else {
                return self.point(piece, bary, self.value(piece, bary));
            };
            let [_, u, v] = bary.map(f64::from);
            let f = texture.eval(self.uv_at(piece.face as usize, u, v));
            // Accept with probability f / bound (bound ≥ f).
            if unit(rng.next_u64()) * f64::from(piece.value) < f {
                return self.point(piece, bary, f);
            }
        }
    }
}

/// Barycentrics with density proportional to the weight of `corner`: that
/// weight is Beta(2, 2) (the uniform marginal `2(1 − b)` times `b`), drawn
/// by inverting its CDF `3b² − 2b³` in closed form; the other two split
/// the rest uniformly.
fn linear_corner_barycentric(corner: usize, xi1: f64, xi2: f64) -> [f32; 3] {
    // 4y³ − 3y = 1 − 2ξ for y = b − 1/2 is cos 3θ = 1 − 2ξ with y = cos θ;
    // the root in [−1/2, 1/2] has 3θ in [π, 2π].
    let theta = (2.0 * std::f64::consts::PI - (1.0 - 2.0 * xi1).clamp(-1.0, 1.0).acos()) / 3.0;
    let b = (0.5 + theta.cos()).clamp(0.0, 1.0);
    let other = xi2 * (1.0 - b);
    let mut bary = [0.0f32; 3];
    bary[corner] = b as f32;
    bary[(corner + 1) % 3] = other as f32;
    bary[(corner + 2) % 3] = (1.0 - b - other).max(0.0) as f32;
    bary
}

/// The share of its face's area (times the weight's normalisation) a
/// piece covers: `4^-level` for sub-triangles, 1/3 for a linear component
/// (∫ b_c dA = A / 3).
fn piece_fraction(part: SubTriangle) -> f64 {
    if part.corner().is_some() {
        1.0 / 3.0
    } else {
        part.area_fraction()
    }
}

fn check_weights(what: &'static str, w: &[f32], expected: usize) -> Result<(), Error> {
    if w.len() != expected {
        return Err(Error::WeightLength {
            what,
            len: w.len(),
            expected,
        });
    }
    if let Some(index) = w.iter().position(|x| !(x.is_finite() && *x >= 0.0)) {
        return Err(Error::InvalidWeight {
            what,
            index,
            value: w[index],
        });
    }
    Ok(())
}

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
fn face_uvs(uvs: &[Vec2], tri: [u32; 3]) -> [DVec2; 3] {
    tri.map(|i| uvs[i as usize].as_dvec2())
}

/// The depth at which sub-triangles are about a texel (Šik & Křivánek
/// Sec. 3.4: the sub-triangle size matches the texture resolution; `4^L`
/// is the texels the triangle covers, rounded to the nearest power of 4,
/// so sub-triangles cover half a texel to two) and, so that a sliver (long,
/// with little area) is cut along its length too, no edge is longer than
/// two texels.
fn face_level(texture: &DensityTexture, uv: [DVec2; 3], options: &Options) -> u8 {
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
fn uv_constant(texture: &DensityTexture, uv: [DVec2; 3]) -> Option<f32> {
    let (lo, hi) = (uv[0].min(uv[1]).min(uv[2]), uv[0].max(uv[1]).max(uv[2]));
    texture.constant_over_box(lo, hi)
}

/// Meshes with at least this many faces are processed on all threads.
const PARALLEL_FACES: usize = 1 << 15;

/// Subdivisions with at least this many leaves are built on all threads.
const PARALLEL_LEAVES: u128 = 1 << 16;

/// Faces per task of the parallel piece collection (fixed, so the split
/// never depends on the number of threads; the result never does).
const FACE_CHUNK: usize = 1 << 10;

/// The pieces `fill(f, out)` appends for every face `f`, in face order,
/// and where each face's pieces start (`faces + 1` entries). On all
/// threads when `parallel` (and the `rayon` feature), in chunks of
/// [`FACE_CHUNK`] faces, each appending to its own list.
fn collect_pieces(
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
fn capped_levels(wanted: &[(u8, Option<f32>)], budget: usize) -> Result<(Vec<u8>, u128), Error> {
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
fn texture_pieces(
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
    // merge into it): found from the texture's tables in O(1).
    let constant = |s: SubTriangle| uv_constant(texture, s.corners().map(at));
    match options.mode {
        Mode::Approximate => {
            let values = Values {
                leaf: |s: SubTriangle| texture.eval(at(s.barycenter())) as f32,
                constant,
            };
            let tolerance = options.merge_tolerance;
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
                constant,
            };
            let tolerance = options.merge_tolerance;
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

/// The lowest expected acceptance a rejection step may have: 10⁻⁹ (a
/// billion proposals a point, about a minute of work), so that no draw
/// runs unbounded.
pub const MIN_ACCEPTANCE: f64 = 1e-9;

/// `Ok` if a rejection step accepts at least [`MIN_ACCEPTANCE`].
pub(crate) fn check_acceptance(acceptance: f64) -> Result<(), Error> {
    if acceptance >= MIN_ACCEPTANCE {
        Ok(())
    } else {
        Err(Error::AcceptanceTooLow {
            acceptance,
            minimum: MIN_ACCEPTANCE,
        })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_corner_component_has_beta22_weight() {
        // The CDF of the corner weight is 3b² − 2b³: invert and check.
        for k in 0..=100 {
            let xi = k as f64 / 100.0;
            let b = f64::from(linear_corner_barycentric(1, xi, 0.3)[1]);
            let cdf = 3.0 * b * b - 2.0 * b * b * b;
            assert!((cdf - xi).abs() < 1e-5, "{xi} -> {b} -> {cdf}");
        }
    }
}
