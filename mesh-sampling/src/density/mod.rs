//! Sampling with a density: a texture by adaptive subdivision (Šik &
//! Křivánek 2013, Sec. 3.3–3.5), optionally exact, or per-face and
//! per-vertex weights.

mod build;
mod options;
mod stable;
mod weights;

use discrete_sampling::{DiscreteSampler, GuideTable};
use glam::DVec2;
use rand::Rng;
use rand::distr::Distribution;

use crate::layout::{Format, Piece, PieceAlias};
use crate::parallel::{BLOCK, unit};
use crate::point::Frame;
use crate::prefetch::prefetch;
use crate::subdivision::{MAX_LEVEL, SubTriangle};
use crate::{DensityTexture, Error, Layout, MeshRef, SurfacePoint, SurfaceSampler};

use build::{
    PARALLEL_FACES, PARALLEL_LEAVES, capped_levels, collect_pieces, face_level, face_uvs,
    texture_pieces, uv_constant,
};
pub(crate) use build::{check_integration, exact_mass, map_faces, texture_uvs};
pub use options::{DEFAULT_MAX_PIECES, Density, Depth, Mode, Options};
use weights::{check_weights, linear_corner_barycentric, piece_fraction};

/// The structure a piece is drawn from, which also holds the pieces in
/// face order (the alias table's columns are the records).
#[derive(Debug, Clone)]
enum Table<S> {
    Alias(PieceAlias),
    Inversion { sampler: S, pieces: Vec<Piece> },
}

impl<S> Table<S> {
    fn len(&self) -> usize {
        match self {
            Self::Alias(a) => a.len(),
            Self::Inversion { pieces, .. } => pieces.len(),
        }
    }

    /// Piece `k` in face order.
    #[inline]
    fn get(&self, k: usize) -> Piece {
        match self {
            Self::Alias(a) => a.get(k),
            Self::Inversion { pieces, .. } => pieces[k],
        }
    }
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
/// A sub-triangle costs its triangle, a code of its level and position
/// (Fig. 4, decoded in O(1)) and its value, plus its share of the table it
/// is drawn from ([`Layout`]): by default an alias table whose 16-byte
/// columns are the records themselves, a column holding both of its
/// sides (one column read per draw). With
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
    /// Whether each point's density is the one [`DensitySampler::pdf`]
    /// gives at its stored barycentrics (see `settle_pdfs`).
    settle: bool,
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
        let (mut pieces, face_start, face_level, exact_mass) = match density {
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
        // The alias layout's columns when they can be packed (see
        // `Layout::Alias`), otherwise the inversion method. The columns
        // may store the values with fewer bits: rounded first, so that
        // the masses are those of the values drawn and reported.
        let format = match options.layout {
            Layout::Alias => Format::fit(&pieces, faces, exact_mass.is_some()),
            Layout::Inversion => None,
        };
        if let Some(format) = format {
            format.round_values(&mut pieces);
        }
        let areas: Vec<f64> = map_faces(many, faces, |f| mesh.area(f));
        let masses: Vec<f64> = pieces
            .iter()
            .map(|p| f64::from(p.value) * areas[p.face as usize] * piece_fraction(p.part))
            .collect();
        let proposal_mass: f64 = masses.iter().sum();
        let zero = Error::ZeroDensity { triangles: faces };
        let table = match format.and_then(|f| PieceAlias::new(&pieces, &masses, f)) {
            Some(alias) => Table::Alias(alias),
            None => Table::Inversion {
                sampler: S::from_weights(&masses).map_err(|_| zero)?,
                pieces,
            },
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
            table,
            face_start,
            face_level,
            frames: Frame::all(&mesh),
            norm: 1.0 / mass,
            acceptance: (mass / proposal_mass).min(1.0),
            settle: false,
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
        self.table.len()
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
            Table::Inversion { .. } => Layout::Inversion,
        }
    }

    /// The largest relative change the table made to a piece's value to
    /// store it: 0 when the values are exact (the inversion layout, and
    /// the alias layout where the values' range fits its columns), at most
    /// `2⁻¹³` (see [`Layout::Alias`]). The density drawn and reported
    /// (`p′`, or exact mode's bounds) is the one with the changed values.
    pub fn value_tolerance(&self) -> f64 {
        match &self.table {
            Table::Alias(alias) => alias.value_tolerance(),
            Table::Inversion { .. } => 0.0,
        }
    }

    /// Heap memory of the table the pieces are drawn from (with the
    /// alias layout: the pieces themselves, 16 bytes each; with the
    /// inversion layout: the pieces' 12-byte records and the sampler over
    /// their CDF).
    pub fn table_bytes(&self) -> usize {
        match &self.table {
            Table::Alias(a) => a.memory_bytes(),
            Table::Inversion { sampler, pieces } => {
                sampler.memory_bytes() + pieces.len() * size_of::<Piece>()
            }
        }
    }

    /// Heap memory of the sampler (table, face index and frames), not
    /// counting the mesh and texture it borrows.
    pub fn memory_bytes(&self) -> usize {
        self.table_bytes()
            + self.face_start.len() * size_of::<u32>()
            + self.face_level.len()
            + self.frames.len() * size_of::<Frame>()
    }

    /// The density (w.r.t. area, normalised over the mesh) this sampler
    /// draws from, at barycentrics `barycentric` of triangle `face`: what a
    /// path tracer needs for multiple importance sampling when a ray hits
    /// the mesh. 0 for a triangle that does not exist, a zero-area
    /// triangle, or barycentrics that are NaN or infinite (or all zero).
    /// Barycentrics outside the triangle (a negative weight, or a sum
    /// away from 1) are first moved onto it: negative weights to 0, then
    /// all divided by their sum; a ray's hit, inside up to rounding, is
    /// taken as it is.
    pub fn pdf(&self, face: usize, barycentric: [f32; 3]) -> f32 {
        let Some(range) = self.face_range(face) else {
            return 0.0;
        };
        let Some([b0, b1, b2]) = onto_triangle(barycentric) else {
            return 0.0;
        };
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

    /// The table indices of face `face`'s pieces (`None` for no such face).
    pub(crate) fn face_range(&self, face: usize) -> Option<std::ops::Range<usize>> {
        let start = *self.face_start.get(face)? as usize;
        let end = *self.face_start.get(face + 1)? as usize;
        Some(start..end)
    }

    /// Piece `k` of the table, in face order.
    #[inline]
    pub(crate) fn piece_at(&self, k: usize) -> Piece {
        self.table.get(k)
    }

    /// The unnormalised mass piece `piece` is drawn with: its value (the
    /// density, or in exact mode its bound) times its area.
    pub(crate) fn piece_mass(&self, piece: Piece) -> f64 {
        f64::from(piece.value) * self.mesh.area(piece.face as usize) * piece_fraction(piece.part)
    }

    /// `p′` before normalisation at `(u, v)` of `face`: the value of the
    /// stored sub-triangle containing it, found by bisection on the
    /// depth-first keys of the face's sub-triangles.
    fn approximate_value(&self, range: std::ops::Range<usize>, face: usize, u: f64, v: f64) -> f64 {
        let depth = self.face_level[face];
        let key = SubTriangle::locate(depth, u, v).key(depth);
        // Bisection for the last piece whose key is at most `key`.
        let (mut lo, mut hi) = (range.start, range.end);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if self.table.get(mid).part.key(depth) <= key {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        if lo == range.start {
            return 0.0;
        }
        let p = self.table.get(lo - 1);
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
    pub(crate) fn place(&self, piece: Piece, xi1: f64, xi2: f64) -> [f32; 3] {
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
        let value = if self.settle {
            self.settled(piece, bary, value)
        } else {
            value
        };
        let frame = &self.frames[face as usize];
        SurfacePoint::in_frame(&self.mesh, frame, face, bary, (value * self.norm) as f32)
    }

    /// From now on, every point carries the density
    /// [`pdf`](Self::pdf) gives at its stored barycentrics, bit for bit
    /// (what multiple importance sampling wants of a light's samples). In
    /// approximate mode a point drawn in one sub-triangle can, rounded to
    /// `f32` barycentrics, lie in its neighbour (about one point in 10⁵);
    /// it then takes the neighbour's value. The check costs one
    /// `SubTriangle::locate` per point, no memory access, and a search of
    /// the face's pieces only for those rare points.
    pub(crate) fn settle_pdfs(&mut self) {
        self.settle = true;
    }

    /// The value [`pdf`](Self::pdf) takes at `bary` of the piece's face,
    /// for a point drawn in `piece` with value `value`.
    #[inline]
    fn settled(&self, piece: Piece, bary: [f32; 3], value: f64) -> f64 {
        if self.mode != Mode::Approximate
            || !matches!(self.density, Density::Texture(_))
            || piece.part.corner().is_some()
        {
            return value;
        }
        let face = piece.face as usize;
        let Some([_, u, v]) = onto_triangle(bary) else {
            return value;
        };
        let depth = self.face_level[face];
        let key = SubTriangle::locate(depth, u, v).key(depth);
        let start = piece.part.key(depth);
        let span = 1u64 << (2 * (depth - piece.part.level()));
        if (start..start + span).contains(&key) {
            return value;
        }
        match self.face_range(face) {
            Some(range) => self.approximate_value(range, face, u, v),
            None => value,
        }
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
            Table::Inversion { sampler, pieces } => pieces[sampler.sample_rng(rng)],
        }
    }

    /// Fills `out` with pieces (one `u64` of `rng` each): the variates
    /// first, then the searches, then the records, each in a pass of its
    /// own so that the loads of independent draws overlap.
    #[inline]
    fn pieces_into<R: Rng + ?Sized>(&self, rng: &mut R, out: &mut [Piece]) {
        match &self.table {
            Table::Alias(alias) => alias.fill(rng, out),
            Table::Inversion { sampler, pieces } => {
                let mut picks = [0usize; BLOCK];
                for block in out.chunks_mut(BLOCK) {
                    let picks = &mut picks[..block.len()];
                    sampler.sample_into(rng, picks);
                    for (piece, &k) in block.iter_mut().zip(picks.iter()) {
                        *piece = pieces[k];
                    }
                }
            }
        }
    }

    /// Loads what the points of `pieces` will read of their faces: the
    /// frames (one cache line each, with the texture coordinates), and for
    /// shading normals the corner indices, then the corners' normals, each
    /// a pass of independent loads, so that a block's cache misses overlap
    /// instead of coming one point at a time (the point computations
    /// between them are too long for the core to look ahead past). The
    /// values are kept (and passed to `black_box`) only so that the loads
    /// are not optimised away; the points read the lines again from L1.
    #[inline]
    fn touch_faces(&self, pieces: &[Piece]) {
        let mut seen = [0u32; BLOCK];
        for (s, p) in seen.iter_mut().zip(pieces) {
            *s = self.frames[p.face as usize].touch();
        }
        if let Some(normals) = self.mesh.normals {
            let mut corners = [[0u32; 3]; BLOCK];
            for (c, p) in corners.iter_mut().zip(pieces) {
                *c = self.mesh.indices[p.face as usize];
            }
            for (s, c) in seen.iter_mut().zip(&corners[..pieces.len()]) {
                *s ^= c
                    .map(|i| normals[i as usize].x.to_bits())
                    .iter()
                    .fold(0, |a, b| a ^ b);
            }
        }
        std::hint::black_box(&seen);
    }

    /// The batch path of the alias layout (not in exact mode): a software
    /// pipeline over blocks of [`BLOCK`] draws, [`DEPTH`] blocks in
    /// flight. Each turn draws a new block's random numbers and prefetches
    /// its columns, picks the records of the block before it from its
    /// columns (arrived meanwhile) and prefetches their frames, and
    /// computes the points of the oldest block: every miss of a draw is
    /// asked for a turn before its use, and overlaps a block's
    /// computation. In a linked table (columns holding their alias's
    /// index) the second stage picks the sides and prefetches the picked
    /// columns, and a third reads their records. The random numbers are
    /// drawn in the order of the blockwise loop (a block's `u64` for the
    /// pieces, then its two per point), so the points are the same bit
    /// for bit.
    fn sample_alias<R: Rng + ?Sized>(
        &self,
        alias: &PieceAlias,
        rng: &mut R,
        out: &mut [SurfacePoint],
    ) {
        let blocks = out.len().div_ceil(BLOCK);
        let mut ring = [Stage::EMPTY; DEPTH];
        let needs_indices =
            self.mesh.normals.is_some() || matches!(self.density, Density::PerVertex(_));
        let inline = alias.inline();
        for t in 0..blocks + DEPTH - 1 {
            if t < blocks {
                let s = &mut ring[t % DEPTH];
                s.len = (out.len() - t * BLOCK).min(BLOCK);
                for (c, f) in s.column[..s.len].iter_mut().zip(&mut s.frac[..s.len]) {
                    (*c, *f) = alias.split(rng.next_u64());
                }
                for xi in &mut s.xi[..s.len] {
                    *xi = [rng.next_u64(), rng.next_u64()];
                }
                for &c in &s.column[..s.len] {
                    alias.prefetch(c);
                }
            }
            // An inline table has the records a turn early: the alias's
            // column is not read.
            let records = |s: &mut Stage| {
                for p in &s.piece[..s.len] {
                    prefetch(&self.frames, p.face as usize);
                    if needs_indices {
                        prefetch(self.mesh.indices, p.face as usize);
                    }
                }
            };
            if let Some(b) = t.checked_sub(1).filter(|&b| b < blocks) {
                let s = &mut ring[b % DEPTH];
                if inline {
                    for ((p, &c), &f) in s.piece.iter_mut().zip(&s.column[..s.len]).zip(&s.frac) {
                        *p = alias.pick(c, f);
                    }
                    records(s);
                } else {
                    for (c, &f) in s.column[..s.len].iter_mut().zip(&s.frac[..s.len]) {
                        *c = alias.side(*c, f);
                    }
                    for &c in &s.column[..s.len] {
                        alias.prefetch(c);
                    }
                }
            }
            if let Some(b) = t.checked_sub(2).filter(|&b| b < blocks && !inline) {
                let s = &mut ring[b % DEPTH];
                for (p, &c) in s.piece[..s.len].iter_mut().zip(&s.column[..s.len]) {
                    *p = alias.get(c);
                }
                records(s);
            }
            if let Some(b) = t.checked_sub(DEPTH - 1).filter(|&b| b < blocks) {
                let s = &ring[b % DEPTH];
                if let Some(normals) = self.mesh.normals {
                    for p in &s.piece[..s.len] {
                        for i in self.mesh.indices[p.face as usize] {
                            prefetch(normals, i as usize);
                        }
                    }
                }
                let block = &mut out[b * BLOCK..][..s.len];
                for ((slot, &piece), &[x1, x2]) in block.iter_mut().zip(&s.piece).zip(&s.xi) {
                    let bary = self.place(piece, unit(x1), unit(x2));
                    *slot = self.point(piece, bary, self.value(piece, bary));
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

/// Blocks in flight in [`DensitySampler::sample_alias`]'s pipeline: one
/// drawing its columns, one picking its records (linked tables: its
/// sides), one waiting (linked: reading its records), one computing its
/// points.
const DEPTH: usize = 4;

/// One block of [`DensitySampler::sample_alias`]'s pipeline.
#[derive(Clone, Copy)]
struct Stage {
    len: usize,
    /// The drawn columns, then the picked ones.
    column: [usize; BLOCK],
    frac: [u64; BLOCK],
    /// The two `u64` of each point in its piece.
    xi: [[u64; 2]; BLOCK],
    piece: [Piece; BLOCK],
}

impl Stage {
    const EMPTY: Self = Self {
        len: 0,
        column: [0; BLOCK],
        frac: [0; BLOCK],
        xi: [[0; 2]; BLOCK],
        piece: [Piece::EMPTY; BLOCK],
    };
}

/// Three `u64` of the random stream per point (one for the piece, two for
/// the point in it); four per proposal in exact mode.
impl<S: DiscreteSampler + Sync> SurfaceSampler for DensitySampler<'_, S> {
    /// Computed in blocks, like
    /// [`UniformSampler`](crate::UniformSampler)'s: the block's pieces by
    /// the table's batch search (with the alias layout: the columns, and
    /// in a linked table the aliases' columns), then their faces'
    /// records, then the points;
    /// in exact mode, blocks of proposals of which the accepted are kept.
    fn sample_into<R: Rng + ?Sized>(&self, rng: &mut R, out: &mut [SurfacePoint]) {
        let mut pieces = [Piece::default(); BLOCK];
        if let Some(texture) = self.exact_texture() {
            // Proposals in blocks, the accepted ones kept in order.
            let mut filled = 0;
            while filled < out.len() {
                self.pieces_into(rng, &mut pieces);
                self.touch_faces(&pieces);
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
        if let Table::Alias(alias) = &self.table {
            return self.sample_alias(alias, rng, out);
        }
        for block in out.chunks_mut(BLOCK) {
            let n = block.len();
            self.pieces_into(rng, &mut pieces[..n]);
            self.touch_faces(&pieces[..n]);
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

/// `b` in `f64`, unchanged when it is a point of the triangle up to
/// rounding (weights ≥ 0 summing to 1 within `10⁻⁶`), else with negative
/// weights set to 0 and divided by the sum; `None` for weights that are
/// not finite or sum to 0.
fn onto_triangle(b: [f32; 3]) -> Option<[f64; 3]> {
    if !b.iter().all(|x| x.is_finite()) {
        return None;
    }
    let b = b.map(f64::from);
    let sum: f64 = b.iter().sum();
    if b.iter().all(|&x| x >= 0.0) && (sum - 1.0).abs() <= 1e-6 {
        return Some(b);
    }
    let b = b.map(|x| x.max(0.0));
    let sum: f64 = b.iter().sum();
    (sum > 0.0).then(|| b.map(|x| x / sum))
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

#[cfg(test)]
mod tests {
    use glam::Vec2;
    use rand::SeedableRng;

    use super::*;

    /// The alias pipeline gives the plain blockwise loop's points (a
    /// block's pieces, then its points' variates, block after block), for
    /// a texture with and without shading normals and for per-vertex
    /// weights (which read the corner indices), with the columns inline
    /// and linked.
    #[test]
    fn the_alias_pipeline_draws_the_blockwise_loops_points() {
        let n = 12u32;
        let (positions, normals, indices) = crate::mesh::test_grid(n);
        let uvs: Vec<Vec2> = positions.iter().map(|p| p.truncate() / n as f32).collect();
        let texels: Vec<f32> = (0..64 * 64).map(|k| ((k * 37) % 11) as f32).collect();
        let texture = DensityTexture::new(64, 64, texels).unwrap();
        let weights: Vec<f32> = (0..n * n).map(|k| (k % 4) as f32).collect();
        let plain = MeshRef {
            uvs: Some(&uvs),
            ..MeshRef::new(&positions, &indices)
        };
        let shaded = MeshRef {
            normals: Some(&normals),
            ..plain
        };
        let cases = [
            (plain, Density::Texture(&texture)),
            (shaded, Density::Texture(&texture)),
            (shaded, Density::PerVertex(&weights)),
        ];
        for ((mesh, density), linked) in cases.into_iter().flat_map(|c| [(c, false), (c, true)]) {
            crate::layout::FORCE_LINKED.with(|f| f.set(linked));
            let sampler = DensitySampler::new(mesh, density);
            crate::layout::FORCE_LINKED.with(|f| f.set(false));
            let sampler = sampler.unwrap();
            let Table::Alias(alias) = &sampler.table else {
                panic!("the default layout is the alias table")
            };
            assert_eq!(alias.inline(), !linked);
            assert!(sampler.pieces() > 4 * BLOCK, "{} pieces", sampler.pieces());
            // Whole blocks, a partial last block, fewer than the pipeline
            // holds, and fewer than one block.
            for count in [7 * BLOCK, 9 * BLOCK + 17, 3 * BLOCK + 5, BLOCK - 1, 1, 0] {
                let mut got = vec![SurfacePoint::default(); count];
                sampler.sample_into(&mut rand_pcg::Pcg64Mcg::seed_from_u64(5), &mut got);
                let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(5);
                let mut want = Vec::new();
                for start in (0..count).step_by(BLOCK) {
                    let len = (count - start).min(BLOCK);
                    let pieces: Vec<Piece> =
                        (0..len).map(|_| alias.piece(rng.next_u64())).collect();
                    for piece in pieces {
                        let xi1 = unit(rng.next_u64());
                        let bary = sampler.place(piece, xi1, unit(rng.next_u64()));
                        want.push(sampler.point(piece, bary, sampler.value(piece, bary)));
                    }
                }
                assert_eq!(got, want, "{count} points");
            }
        }
    }
}
