//! A density texture: one non-negative value per texel, filtered bilinearly
//! (or nearest), repeated, mirrored or clamped outside `[0, 1]²` (glTF's
//! sampler wrap modes).
//!
//! Besides point lookups it answers the two questions exact sampling needs:
//! the exact integral of the filtered density over a UV triangle, and its
//! exact maximum over a UV box. Both rely on the density being bilinear
//! (or constant) inside each cell between texel centres: a triangle is cut
//! into cell pieces, each integrated in closed form, and a box peaks on
//! the grid of its corners and the cell lines.

use glam::DVec2;

use crate::Error;

/// The most texel cells an exact integral visits: 2³⁰ (about a minute of
/// work). [`DensityTexture::integral`] returns NaN beyond it, and the
/// samplers that integrate exactly ([`Mode::Exact`](crate::Mode::Exact),
/// [`RejectionSampler`](crate::RejectionSampler)) refuse a mesh whose
/// footprints add up to more with [`Error::IntegrationTooLarge`].
pub const MAX_INTEGRATION_CELLS: u64 = 1 << 30;

/// What happens outside `[0, 1]²`, with glTF's sampler semantics (the
/// same enum, with the same meaning, as in `trilux-io` and `mesh-colors`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Wrap {
    /// The texture tiles the plane (tiled UV maps): texel `x` is texel
    /// `x mod W`.
    #[default]
    Repeat,
    /// The texture tiles the plane, every other copy mirrored: texel
    /// columns run `0 … W−1, W−1 … 0, 0 …`.
    MirroredRepeat,
    /// The edge texels extend outwards.
    ClampToEdge,
}

/// Rec. 709 luminance `0.2126 R + 0.7152 G + 0.0722 B` of linear RGB (the
/// same function, with the same name, in every trilux crate that needs
/// one).
#[inline]
pub fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// How the density between texel centres is reconstructed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Filter {
    /// Bilinear interpolation of the four nearest texel centres.
    #[default]
    Bilinear,
    /// The value of the texel the point lies in (piecewise constant).
    Nearest,
}

/// Which value of a multi-channel image becomes the density.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Channel {
    /// One channel, by index.
    Index(usize),
    /// Rec. 709 [`luminance`] of the first three channels (for HDR
    /// luminaires: sample by emitted power).
    Luminance,
}

/// A density texture. Texel `(x, y)` covers `u ∈ [x/W, (x+1)/W)`,
/// `v ∈ [y/H, (y+1)/H)`, and row 0 is the first row of the data: glTF's UV
/// convention (v grows downwards), the one `trilux-io`'s `TriMesh` uses,
/// so the rows of an image as stored (PNG, EXR, HDR) are used as they are.
///
/// Besides the texels it keeps a min/max pyramid (two thirds more memory),
/// so that the range of the density over any UV box is known in O(1):
/// the density sampler uses it to stop subdividing where the density is
/// constant, without visiting the texels there.
#[derive(Debug, Clone, PartialEq)]
pub struct DensityTexture {
    width: usize,
    height: usize,
    texels: Vec<f32>,
    wrap: Wrap,
    filter: Filter,
    max: f32,
    pyramid: Pyramid,
    changes: Changes,
}

impl DensityTexture {
    /// A texture of `width × height` values, row by row.
    ///
    /// # Errors
    /// [`Error::EmptyTexture`] for a size of 0,
    /// [`Error::TextureTooLarge`] when `width × height` overflows,
    /// [`Error::TextureSize`] when
    /// `texels` does not hold `width · height` values,
    /// [`Error::InvalidTexel`] naming the first negative, NaN or infinite
    /// value.
    pub fn new(width: usize, height: usize, texels: Vec<f32>) -> Result<Self, Error> {
        if width == 0 || height == 0 {
            return Err(Error::EmptyTexture { width, height });
        }
        let expected = width
            .checked_mul(height)
            .ok_or(Error::TextureTooLarge { width, height })?;
        if texels.len() != expected {
            return Err(Error::TextureSize {
                expected,
                len: texels.len(),
            });
        }
        if let Some(i) = texels.iter().position(|t| !(t.is_finite() && *t >= 0.0)) {
            return Err(Error::InvalidTexel {
                x: i % width,
                y: i / width,
                value: texels[i],
            });
        }
        let max = texels.iter().copied().fold(0.0f32, f32::max);
        let pyramid = Pyramid::new(width, height, &texels);
        let changes = Changes::new(width, height, &texels);
        Ok(Self {
            width,
            height,
            texels,
            wrap: Wrap::default(),
            filter: Filter::default(),
            max,
            pyramid,
            changes,
        })
    }

    /// A texture from interleaved `channels`-channel pixels (such as
    /// `trilux-io`'s RGBA images), keeping one channel or the luminance.
    ///
    /// # Errors
    /// [`Error::InvalidChannel`] for a channel the pixels do not have
    /// (luminance needs three), and the errors of [`new`](Self::new).
    pub fn from_channels(
        width: usize,
        height: usize,
        data: &[f32],
        channels: usize,
        channel: Channel,
    ) -> Result<Self, Error> {
        let enough = match channel {
            Channel::Index(c) => c < channels,
            Channel::Luminance => channels >= 3,
        };
        if !enough {
            return Err(Error::InvalidChannel { channel, channels });
        }
        if !data.len().is_multiple_of(channels) {
            return Err(Error::TextureSize {
                expected: width.saturating_mul(height).saturating_mul(channels),
                len: data.len(),
            });
        }
        let texels = data
            .chunks_exact(channels)
            .map(|p| match channel {
                Channel::Index(c) => p[c],
                Channel::Luminance => luminance([p[0], p[1], p[2]]),
            })
            .collect();
        Self::new(width, height, texels)
    }

    /// The same texture with wrap mode `wrap`.
    #[must_use]
    pub fn with_wrap(mut self, wrap: Wrap) -> Self {
        self.wrap = wrap;
        self
    }

    /// The same texture with filter `filter`.
    #[must_use]
    pub fn with_filter(mut self, filter: Filter) -> Self {
        self.filter = filter;
        self
    }

    /// The same texture upside down (row 0 becomes the last row).
    #[must_use]
    pub fn flip_rows(mut self) -> Self {
        let w = self.width;
        let h = self.height;
        for y in 0..h / 2 {
            let (top, bottom) = self.texels.split_at_mut((h - 1 - y) * w);
            top[y * w..(y + 1) * w].swap_with_slice(&mut bottom[..w]);
        }
        self.pyramid = Pyramid::new(w, h, &self.texels);
        self.changes = Changes::new(w, h, &self.texels);
        self
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The wrap mode.
    pub fn wrap(&self) -> Wrap {
        self.wrap
    }

    /// The filter.
    pub fn filter(&self) -> Filter {
        self.filter
    }

    /// The largest texel: the supremum of the filtered density, the bound
    /// rejection sampling (Šik & Křivánek Sec. 3.2) uses.
    pub fn max(&self) -> f32 {
        self.max
    }

    /// The texels, row by row.
    pub fn texels(&self) -> &[f32] {
        &self.texels
    }

    /// Heap memory used (texels and the min/max pyramid), in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.texels.len() * size_of::<f32>()
            + self.pyramid.memory_bytes()
            + self.changes.memory_bytes()
    }

    /// The smallest and largest value the filtered density takes over the
    /// UV box `[lo, hi]`, or bounds of them (`min` may be lower, `max`
    /// higher, never the other way); exact, `(c, c)`, when the density is
    /// constant `c` over the box. O(1): a few table lookups per wrapped
    /// piece of the box, whatever its size.
    pub fn range_over_box(&self, lo: DVec2, hi: DVec2) -> (f32, f32) {
        let (xs, ys) = self.texel_spans(lo, hi);
        if let Some(c) = self.constant_over(&xs, &ys) {
            return (c, c);
        }
        let (mut min, mut max) = (f32::INFINITY, 0.0f32);
        for &x in xs.iter().flatten() {
            for &y in ys.iter().flatten() {
                let (a, b) = self.pyramid.range(&self.texels, self.width, x, y);
                min = min.min(a);
                max = max.max(b);
            }
        }
        (min.min(max), max)
    }

    /// The value of the density over the UV box `[lo, hi]` if it is
    /// constant there (all the texels it reads are equal), found in O(1).
    pub fn constant_over_box(&self, lo: DVec2, hi: DVec2) -> Option<f32> {
        let (xs, ys) = self.texel_spans(lo, hi);
        self.constant_over(&xs, &ys)
    }

    /// The texel columns and rows the density over a UV box reads: those
    /// of the cells it touches (and the next ones for bilinear filtering),
    /// as at most two ranges each after wrapping.
    #[expect(clippy::type_complexity, reason = "two small fixed arrays of ranges")]
    fn texel_spans(
        &self,
        lo: DVec2,
        hi: DVec2,
    ) -> ([Option<(usize, usize)>; 2], [Option<(usize, usize)>; 2]) {
        let (lo, hi) = (self.to_cells(lo), self.to_cells(hi));
        let reach = i64::from(self.filter == Filter::Bilinear);
        let span = |l: f64, h: f64, n: usize| {
            let (a, b) = (floor_i64(l), floor_i64(h).saturating_add(reach));
            self.wrap_span(a.min(b), a.max(b), n)
        };
        (span(lo.x, hi.x, self.width), span(lo.y, hi.y, self.height))
    }

    /// The common value of the texels in the spans, if they are all equal.
    fn constant_over(
        &self,
        xs: &[Option<(usize, usize)>; 2],
        ys: &[Option<(usize, usize)>; 2],
    ) -> Option<f32> {
        let mut value = None;
        for &x in xs.iter().flatten() {
            for &y in ys.iter().flatten() {
                if !self.changes.constant(x, y) {
                    return None;
                }
                let v = self.texels[y.0 * self.width + x.0];
                if value.is_some_and(|c| c != v) {
                    return None;
                }
                value = Some(v);
            }
        }
        value
    }

    /// The texel columns (or rows) `i0..=i1` as at most two ranges inside
    /// `0..n` whose union contains every texel they name after wrapping.
    fn wrap_span(&self, i0: i64, i1: i64, n: usize) -> [Option<(usize, usize)>; 2] {
        let last = n as i64 - 1;
        let all = [Some((0, n - 1)), None];
        match self.wrap {
            Wrap::ClampToEdge => {
                let (a, b) = (i0.clamp(0, last) as usize, i1.clamp(0, last) as usize);
                [Some((a, b)), None]
            }
            Wrap::Repeat => {
                if i1.saturating_sub(i0) >= last {
                    return all;
                }
                let (a, b) = (
                    i0.rem_euclid(n as i64) as usize,
                    i1.rem_euclid(n as i64) as usize,
                );
                if a <= b {
                    [Some((a, b)), None]
                } else {
                    [Some((a, n - 1)), Some((0, b))]
                }
            }
            Wrap::MirroredRepeat => {
                if i1.saturating_sub(i0) >= last {
                    return all;
                }
                // Shorter than a half-period: inside one half (rising
                // or falling) it maps to one contiguous range; across one
                // fold, to the range from the nearer end to the fold's
                // texel.
                let (a, b) = (self.wrap_index(i0, n), self.wrap_index(i1, n));
                let (h0, h1) = (i0.div_euclid(n as i64), i1.div_euclid(n as i64));
                if h0 == h1 {
                    [Some((a.min(b), a.max(b))), None]
                } else if h0.rem_euclid(2) == 0 {
                    [Some((a.min(b), n - 1)), None]
                } else {
                    [Some((0, a.max(b))), None]
                }
            }
        }
    }

    /// Column or row `i` wrapped, mirrored or clamped into `0..n`.
    #[inline]
    fn wrap_index(&self, i: i64, n: usize) -> usize {
        if (0..n as i64).contains(&i) {
            return i as usize; // the common case: no division
        }
        match self.wrap {
            Wrap::Repeat => i.rem_euclid(n as i64) as usize,
            Wrap::MirroredRepeat => {
                let m = i.rem_euclid(2 * n as i64) as usize;
                if m < n { m } else { 2 * n - 1 - m }
            }
            Wrap::ClampToEdge => i.clamp(0, n as i64 - 1) as usize,
        }
    }

    /// The texel at integer coordinates, wrapped or clamped.
    #[inline]
    fn texel(&self, x: i64, y: i64) -> f64 {
        let (x, y) = (
            self.wrap_index(x, self.width),
            self.wrap_index(y, self.height),
        );
        f64::from(self.texels[y * self.width + x])
    }

    /// Texel-space coordinates of `uv`: integers at the texel centres
    /// (bilinear) or at the texel corners (nearest), so the density is
    /// bilinear (or constant) on every unit cell.
    #[inline]
    fn to_cells(&self, uv: DVec2) -> DVec2 {
        let p = uv * DVec2::new(self.width as f64, self.height as f64);
        match self.filter {
            Filter::Bilinear => p - 0.5,
            Filter::Nearest => p,
        }
    }

    /// The density at a point in cell coordinates.
    #[inline]
    fn at_cell(&self, p: DVec2) -> f64 {
        // Saturating casts: a UV of 1e30 is a valid (if silly) tiled UV.
        self.in_cell((floor_i64(p.x), floor_i64(p.y)), p)
    }

    /// The filtered density at texture coordinate `uv`.
    #[inline]
    pub fn eval(&self, uv: DVec2) -> f64 {
        self.at_cell(self.to_cells(uv))
    }

    /// The texels (row-major indices) the filtered value at `uv` combines,
    /// with their weights: the four of the bilinear cell (weights summing
    /// to 1), or the nearest texel with weight 1 (and three of weight 0).
    /// [`eval`](Self::eval) is `Σ weight · texel`; a texture of other
    /// values on the same grid (an emitter's RGB) is filtered the same way.
    #[inline]
    pub(crate) fn taps(&self, uv: DVec2) -> [(usize, f64); 4] {
        let p = self.to_cells(uv);
        let cell = (floor_i64(p.x), floor_i64(p.y));
        let x0 = self.wrap_index(cell.0, self.width);
        let row0 = self.wrap_index(cell.1, self.height) * self.width;
        match self.filter {
            Filter::Nearest => [
                (row0 + x0, 1.0),
                (row0 + x0, 0.0),
                (row0 + x0, 0.0),
                (row0 + x0, 0.0),
            ],
            Filter::Bilinear => {
                let (fx, fy) = (
                    (p.x - cell.0 as f64).clamp(0.0, 1.0),
                    (p.y - cell.1 as f64).clamp(0.0, 1.0),
                );
                let x1 = self.wrap_index(cell.0.saturating_add(1), self.width);
                let row1 = self.wrap_index(cell.1.saturating_add(1), self.height) * self.width;
                [
                    (row0 + x0, (1.0 - fx) * (1.0 - fy)),
                    (row0 + x1, fx * (1.0 - fy)),
                    (row1 + x0, (1.0 - fx) * fy),
                    (row1 + x1, fx * fy),
                ]
            }
        }
    }

    /// The exact integral of the filtered density over the UV triangle
    /// `uv`, in UV area (the unit square has area 1).
    ///
    /// Constant footprints cost O(1); others one clipping step per texel
    /// cell of the triangle's bounding box ([`cells_to_integrate`](Self::cells_to_integrate)),
    /// and beyond [`MAX_INTEGRATION_CELLS`] the answer is NaN (not computed).
    pub fn integral(&self, uv: [DVec2; 3]) -> f64 {
        let (lo, hi) = (uv[0].min(uv[1]).min(uv[2]), uv[0].max(uv[1]).max(uv[2]));
        if let Some(c) = self.constant_over_box(lo, hi) {
            // Constant over the footprint (say a tiled constant region):
            // the value times the UV area, without visiting its cells.
            return f64::from(c) * 0.5 * (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]).abs();
        }
        let cells = self.cells_to_integrate(uv);
        if cells.is_nan() || cells > MAX_INTEGRATION_CELLS as f64 {
            return f64::NAN;
        }
        let scale = 1.0 / (self.width as f64 * self.height as f64);
        let tri = uv.map(|p| self.to_cells(p));
        let mut sum = 0.0;
        self.for_each_cell_piece(tri, |piece, cell| {
            sum += integrate_piece(piece, |p| self.in_cell(cell, p));
        });
        sum * scale
    }

    /// The texel cells [`integral`](Self::integral) visits for the UV
    /// triangle `uv`: 0 if the density is constant over its bounding box,
    /// else the cells of that box (NaN or infinite for non-finite UVs).
    pub fn cells_to_integrate(&self, uv: [DVec2; 3]) -> f64 {
        let (lo, hi) = (uv[0].min(uv[1]).min(uv[2]), uv[0].max(uv[1]).max(uv[2]));
        if self.constant_over_box(lo, hi).is_some() {
            return 0.0;
        }
        let (a, b) = (self.to_cells(lo).floor(), self.to_cells(hi).ceil());
        ((b.x - a.x).max(1.0)) * ((b.y - a.y).max(1.0))
    }

    /// The maximum of the filtered density over the UV box `[lo, hi]`,
    /// rounded up by a relative 1e-6 so that it bounds every value
    /// [`eval`](Self::eval) returns inside, rounding included. Exact: a
    /// bilinear function is linear along each axis, so on a box inside
    /// one cell it peaks at a corner, and the box's maximum is at a point
    /// of the grid its corners and the cell lines crossing it make.
    ///
    /// A box over more than 64 cells takes the pyramid's bound instead
    /// (at least the true maximum, at most the largest texel it reads),
    /// so that the cost stays O(1) for footprints that tile the texture.
    pub fn max_over_box(&self, lo: DVec2, hi: DVec2) -> f64 {
        let cells = (self.to_cells(hi) - self.to_cells(lo)).abs() + 1.0;
        if cells.x * cells.y > 64.0 {
            return f64::from(self.range_over_box(lo, hi).1) * (1.0 + 1e-6);
        }
        let (lo, hi) = (self.to_cells(lo), self.to_cells(hi));
        let mut max = 0.0f64;
        match self.filter {
            Filter::Nearest => {
                // Cells [k, k + 1) the box reaches into (its upper edge
                // only touches the cell it ends on).
                let last = |l: f64, h: f64| {
                    let c = h.ceil() as i64 - 1;
                    c.max(l.floor() as i64)
                };
                for y in lo.y.floor() as i64..=last(lo.y, hi.y) {
                    for x in lo.x.floor() as i64..=last(lo.x, hi.x) {
                        max = max.max(self.texel(x, y));
                    }
                }
            }
            Filter::Bilinear => {
                let stops = |l: f64, h: f64| {
                    std::iter::once(l)
                        .chain((l.floor() as i64 + 1..=h.ceil() as i64 - 1).map(|k| k as f64))
                        .chain(std::iter::once(h))
                };
                for y in stops(lo.y, hi.y) {
                    for x in stops(lo.x, hi.x) {
                        max = max.max(self.at_cell(DVec2::new(x, y)));
                    }
                }
            }
        }
        max * (1.0 + 1e-6)
    }

    /// The density at `p` evaluated with the texels of cell `cell`, so
    /// points on the cell's border use the cell's own formula.
    #[inline]
    fn in_cell(&self, cell: (i64, i64), p: DVec2) -> f64 {
        match self.filter {
            Filter::Nearest => self.texel(cell.0, cell.1),
            Filter::Bilinear => {
                // In [0, 1] inside the cell; clamped for coordinates so
                // far out (beyond 2⁶³) that the cell index saturated.
                let (fx, fy) = (
                    (p.x - cell.0 as f64).clamp(0.0, 1.0),
                    (p.y - cell.1 as f64).clamp(0.0, 1.0),
                );
                let x0 = self.wrap_index(cell.0, self.width);
                let x1 = self.wrap_index(cell.0.saturating_add(1), self.width);
                let row0 = self.wrap_index(cell.1, self.height) * self.width;
                let row1 = self.wrap_index(cell.1.saturating_add(1), self.height) * self.width;
                let t = |i: usize| f64::from(self.texels[i]);
                let top = lerp(t(row0 + x0), t(row0 + x1), fx);
                let bottom = lerp(t(row1 + x0), t(row1 + x1), fx);
                lerp(top, bottom, fy)
            }
        }
    }

    /// Calls `f(piece, cell)` for the intersection of triangle `tri` (in
    /// cell coordinates) with every unit cell it overlaps. With clamping,
    /// the cells beyond the texture's edge have the edge's values, which
    /// the cell formula reproduces.
    fn for_each_cell_piece(&self, tri: [DVec2; 3], mut f: impl FnMut(&[DVec2], (i64, i64))) {
        let lo = tri[0].min(tri[1]).min(tri[2]);
        let hi = tri[0].max(tri[1]).max(tri[2]);
        let (x0, x1) = (lo.x.floor() as i64, hi.x.ceil() as i64);
        let (y0, y1) = (lo.y.floor() as i64, hi.y.ceil() as i64);
        let tri = Polygon::from(tri);
        for y in y0..y1.max(y0 + 1) {
            let row = tri.clip(1, y as f64, y as f64 + 1.0);
            if row.len < 3 {
                continue;
            }
            let points = row.points();
            let rlo = points.iter().fold(f64::INFINITY, |m, p| m.min(p.x));
            let rhi = points.iter().fold(f64::NEG_INFINITY, |m, p| m.max(p.x));
            let (cx0, cx1) = ((rlo.floor() as i64).max(x0), (rhi.ceil() as i64).min(x1));
            for x in cx0..cx1.max(cx0 + 1) {
                let piece = row.clip(0, x as f64, x as f64 + 1.0);
                if piece.len >= 3 {
                    f(piece.points(), (x, y));
                }
            }
        }
    }
}

#[inline]
fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

/// `⌊x⌋` as an integer, saturating (NaN gives 0): far-out UVs are valid.
#[inline]
fn floor_i64(x: f64) -> i64 {
    x.floor() as i64
}

/// Minima and maxima of blocks of texels, level by level: level `k ≥ 1`
/// holds, for each block of `2^k × 2^k` texels, their smallest and largest
/// value (level 0 is the texels themselves, not stored again). A box of at
/// most `2^k` texels each way touches at most 2×2 entries of level `k`, so
/// its range costs four lookups.
#[derive(Debug, Clone, PartialEq)]
struct Pyramid {
    /// Levels 1, 2, …: (width, (min, max) per entry).
    levels: Vec<(usize, Vec<(f32, f32)>)>,
}

impl Pyramid {
    fn new(width: usize, height: usize, texels: &[f32]) -> Self {
        let mut levels: Vec<(usize, Vec<(f32, f32)>)> = Vec::new();
        let (mut w, mut h) = (width, height);
        while w > 1 || h > 1 {
            let (nw, nh) = (w.div_ceil(2), h.div_ceil(2));
            let mut next = vec![(f32::INFINITY, 0.0f32); nw * nh];
            let prev = levels.last();
            for y in 0..h {
                for x in 0..w {
                    let (a, b) = match prev {
                        Some((pw, p)) => p[y * pw + x],
                        None => (texels[y * w + x], texels[y * w + x]),
                    };
                    let slot = &mut next[(y / 2) * nw + x / 2];
                    slot.0 = slot.0.min(a);
                    slot.1 = slot.1.max(b);
                }
            }
            levels.push((nw, next));
            (w, h) = (nw, nh);
        }
        Self { levels }
    }

    fn memory_bytes(&self) -> usize {
        self.levels
            .iter()
            .map(|l| l.1.len() * size_of::<(f32, f32)>())
            .sum()
    }

    /// (min, max) bounds over texels `x0..=x1` × `y0..=y1` (all inside the
    /// texture of `width` columns whose texels are `texels`).
    fn range(
        &self,
        texels: &[f32],
        width: usize,
        (x0, x1): (usize, usize),
        (y0, y1): (usize, usize),
    ) -> (f32, f32) {
        let extent = (x1 - x0).max(y1 - y0) + 1;
        // The level whose blocks are at least `extent` wide.
        let k = (extent.next_power_of_two().trailing_zeros() as usize).min(self.levels.len());
        let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
        for y in (y0 >> k)..=(y1 >> k) {
            for x in (x0 >> k)..=(x1 >> k) {
                let (a, b) = match k {
                    0 => (texels[y * width + x], texels[y * width + x]),
                    _ => {
                        let (w, level) = &self.levels[k - 1];
                        level[y * w + x]
                    }
                };
                lo = lo.min(a);
                hi = hi.max(b);
            }
        }
        (lo, hi)
    }
}

/// Summed-area tables of where neighbouring texels differ, horizontally
/// and vertically: a block of texels is constant exactly when neither
/// counts a change inside it (four lookups each, whatever the block's
/// size). Counts are `u32` with wrapping arithmetic, exact while the
/// texture has fewer than 2³² texels.
#[derive(Debug, Clone, PartialEq)]
struct Changes {
    /// `(width + 1) × (height + 1)` pairs: changes between `(x, y)` and
    /// `(x + 1, y)` summed over `x' < x, y' < y`, and the same for
    /// `(x, y)` and `(x, y + 1)` (side by side: one cache line per corner).
    sums: Vec<[u32; 2]>,
    width: usize,
}

impl Changes {
    fn new(width: usize, height: usize, texels: &[f32]) -> Self {
        let stride = width + 1;
        let mut sums = vec![[0u32; 2]; stride * (height + 1)];
        for y in 0..height {
            let (mut row_a, mut row_d) = (0u32, 0u32);
            for x in 0..width {
                let t = texels[y * width + x];
                row_a =
                    row_a.wrapping_add(u32::from(x + 1 < width && texels[y * width + x + 1] != t));
                row_d = row_d.wrapping_add(u32::from(
                    y + 1 < height && texels[(y + 1) * width + x] != t,
                ));
                let at = (y + 1) * stride + x + 1;
                let above = sums[at - stride];
                sums[at] = [above[0].wrapping_add(row_a), above[1].wrapping_add(row_d)];
            }
        }
        Self { sums, width }
    }

    fn memory_bytes(&self) -> usize {
        self.sums.len() * size_of::<[u32; 2]>()
    }

    /// The sum of table `k` over texels `x0..x1` × `y0..y1` (exclusive ends).
    fn sum(&self, k: usize, (x0, x1): (usize, usize), (y0, y1): (usize, usize)) -> u32 {
        let s = self.width + 1;
        let t = &self.sums;
        t[y1 * s + x1][k]
            .wrapping_sub(t[y0 * s + x1][k])
            .wrapping_sub(t[y1 * s + x0][k])
            .wrapping_add(t[y0 * s + x0][k])
    }

    /// Whether texels `x0..=x1` × `y0..=y1` are all equal.
    fn constant(&self, (x0, x1): (usize, usize), (y0, y1): (usize, usize)) -> bool {
        // Horizontal pairs starting at x0..x1 − 1 and vertical pairs
        // starting at y0..y1 − 1: those inside the block.
        self.sum(0, (x0, x1), (y0, y1 + 1)) == 0 && self.sum(1, (x0, x1 + 1), (y0, y1)) == 0
    }
}

/// A convex polygon of at most 8 corners on the stack: a triangle clipped
/// by four axis-aligned half-planes has at most 7.
#[derive(Clone, Copy)]
struct Polygon {
    corners: [DVec2; 8],
    len: usize,
}

impl From<[DVec2; 3]> for Polygon {
    fn from(t: [DVec2; 3]) -> Self {
        let mut corners = [DVec2::ZERO; 8];
        corners[..3].copy_from_slice(&t);
        Self { corners, len: 3 }
    }
}

impl Polygon {
    fn points(&self) -> &[DVec2] {
        &self.corners[..self.len]
    }

    /// The part in the slab `lo ≤ p[axis] ≤ hi`.
    fn clip(&self, axis: usize, lo: f64, hi: f64) -> Self {
        self.clip_half(|p| p[axis] - lo).clip_half(|p| hi - p[axis])
    }

    /// Sutherland–Hodgman against the half-plane `side(p) ≥ 0`.
    fn clip_half(&self, side: impl Fn(DVec2) -> f64) -> Self {
        let mut out = Self {
            corners: [DVec2::ZERO; 8],
            len: 0,
        };
        let mut push = |p: DVec2| {
            if out.len < out.corners.len() {
                out.corners[out.len] = p;
                out.len += 1;
            }
        };
        let points = self.points();
        for k in 0..points.len() {
            let (a, b) = (points[k], points[(k + 1) % points.len()]);
            let (sa, sb) = (side(a), side(b));
            if sa >= 0.0 {
                push(a);
            }
            if (sa >= 0.0) != (sb >= 0.0) {
                push(a + (b - a) * (sa / (sa - sb)));
            }
        }
        out
    }
}

/// ∫ f over a convex polygon where `f` is at most quadratic: a fan of
/// triangles, each by the edge-midpoint rule (exact for degree 2).
fn integrate_piece(piece: &[DVec2], f: impl Fn(DVec2) -> f64) -> f64 {
    let o = piece[0];
    let mut sum = 0.0;
    for k in 1..piece.len() - 1 {
        let (a, b) = (piece[k], piece[k + 1]);
        let area = 0.5 * (a - o).perp_dot(b - o).abs();
        let mid = f((o + a) * 0.5) + f((a + b) * 0.5) + f((b + o) * 0.5);
        sum += area * mid / 3.0;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(w: usize, h: usize) -> DensityTexture {
        let texels = (0..w * h)
            .map(|i| ((i * 2_654_435_761) % 1000) as f32 / 100.0)
            .collect();
        DensityTexture::new(w, h, texels).unwrap()
    }

    /// Midpoint-rule integral on a fine grid of the triangle (reference).
    fn brute_integral(t: &DensityTexture, uv: [DVec2; 3], n: usize) -> f64 {
        let mut sum = 0.0;
        let e1 = uv[1] - uv[0];
        let e2 = uv[2] - uv[0];
        let area = 0.5 * e1.perp_dot(e2).abs();
        let mut count = 0usize;
        for i in 0..n {
            for j in 0..n - i {
                // Up triangles' centroids of a regular n-subdivision, and
                // the down ones'.
                for (a, b) in [(i as f64 + 1.0 / 3.0, j as f64 + 1.0 / 3.0)]
                    .into_iter()
                    .chain((i + j + 1 < n).then(|| (i as f64 + 2.0 / 3.0, j as f64 + 2.0 / 3.0)))
                {
                    sum += t.eval(uv[0] + e1 * (a / n as f64) + e2 * (b / n as f64));
                    count += 1;
                }
            }
        }
        sum / count as f64 * area
    }

    #[test]
    fn integral_matches_a_fine_quadrature() {
        let tri = [
            DVec2::new(-0.13, 0.2),
            DVec2::new(1.4, 0.05),
            DVec2::new(0.3, 1.21),
        ];
        for wrap in [Wrap::Repeat, Wrap::MirroredRepeat, Wrap::ClampToEdge] {
            for filter in [Filter::Bilinear, Filter::Nearest] {
                let t = noise(7, 5).with_wrap(wrap).with_filter(filter);
                let exact = t.integral(tri);
                let brute = brute_integral(&t, tri, 1500);
                let tol = if filter == Filter::Nearest {
                    2e-3
                } else {
                    1e-5
                };
                assert!(
                    (exact - brute).abs() <= tol * brute,
                    "{wrap:?} {filter:?}: {exact} vs {brute}"
                );
            }
        }
    }

    #[test]
    fn integral_of_a_constant_is_the_area() {
        let t = DensityTexture::new(3, 2, vec![2.0; 6]).unwrap();
        let tri = [DVec2::ZERO, DVec2::new(3.0, 0.0), DVec2::new(0.0, 5.0)];
        assert!((t.integral(tri) - 15.0).abs() < 1e-9);
    }

    #[test]
    fn max_over_box_bounds_every_point_and_is_attained() {
        for filter in [Filter::Bilinear, Filter::Nearest] {
            let t = noise(6, 6).with_filter(filter);
            let (lo, hi) = (DVec2::new(0.11, 0.3), DVec2::new(0.52, 0.71));
            let bound = t.max_over_box(lo, hi);
            let mut seen = 0.0f64;
            let n = 400;
            for i in 0..=n {
                for j in 0..=n {
                    let p = lo + (hi - lo) * DVec2::new(i as f64, j as f64) / n as f64;
                    seen = seen.max(t.eval(p));
                }
            }
            assert!(seen <= bound, "{filter:?}: {seen} > {bound}");
            assert!(
                seen >= bound * 0.99,
                "{filter:?}: bound {bound} is loose: max {seen}"
            );
        }
        // A box on texel edges does not reach the next texel (nearest).
        let t = DensityTexture::new(2, 1, vec![1.0, 5.0])
            .unwrap()
            .with_filter(Filter::Nearest);
        assert!(t.max_over_box(DVec2::ZERO, DVec2::new(0.5, 1.0)) < 1.01);
    }

    #[test]
    fn bilinear_reproduces_texels_at_centres_and_wraps() {
        let t = noise(4, 3);
        for y in 0..3 {
            for x in 0..4 {
                let uv = DVec2::new((x as f64 + 0.5) / 4.0, (y as f64 + 0.5) / 3.0);
                let v = f64::from(t.texels()[y * 4 + x]);
                assert!((t.eval(uv) - v).abs() < 1e-6);
                assert!((t.eval(uv + DVec2::new(2.0, -3.0)) - v).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn mirrored_repeat_reflects_every_other_tile() {
        for filter in [Filter::Bilinear, Filter::Nearest] {
            let t = noise(5, 3)
                .with_wrap(Wrap::MirroredRepeat)
                .with_filter(filter);
            for k in 0..200 {
                let uv = DVec2::new(k as f64 * 0.0123 % 1.0, (k as f64 * 0.0371) % 1.0);
                let v = t.eval(uv);
                // u ↦ 2 − u and v ↦ −v are mirrors; +2 is a whole period.
                assert!((t.eval(DVec2::new(2.0 - uv.x, uv.y)) - v).abs() < 1e-9);
                assert!((t.eval(DVec2::new(uv.x, -uv.y)) - v).abs() < 1e-9);
                assert!((t.eval(uv + DVec2::new(2.0, -4.0)) - v).abs() < 1e-9);
            }
        }
        // Texel columns 0 1 2 | 2 1 0 | 0 1 2 (nearest).
        let t = DensityTexture::new(3, 1, vec![1.0, 2.0, 3.0])
            .unwrap()
            .with_wrap(Wrap::MirroredRepeat)
            .with_filter(Filter::Nearest);
        let row: Vec<f64> = (-3..6)
            .map(|x| t.eval(DVec2::new((x as f64 + 0.5) / 3.0, 0.5)))
            .collect();
        assert_eq!(row, [3.0, 2.0, 1.0, 1.0, 2.0, 3.0, 3.0, 2.0, 1.0]);
    }

    /// The pyramid's range contains every value the density takes over
    /// the box, for every wrap mode and filter, and is exact on constant
    /// regions.
    #[test]
    fn range_over_box_bounds_dense_probes() {
        let mut rng_state = 12345u64;
        let mut next = || {
            rng_state = rng_state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (rng_state >> 11) as f64 / (1u64 << 53) as f64
        };
        for wrap in [Wrap::Repeat, Wrap::MirroredRepeat, Wrap::ClampToEdge] {
            for filter in [Filter::Bilinear, Filter::Nearest] {
                let t = noise(13, 7).with_wrap(wrap).with_filter(filter);
                for _ in 0..300 {
                    let lo = DVec2::new(next() * 6.0 - 3.0, next() * 6.0 - 3.0);
                    let size = DVec2::new(next(), next()) * if next() < 0.5 { 0.3 } else { 2.0 };
                    let hi = lo + size;
                    let (min, max) = t.range_over_box(lo, hi);
                    for i in 0..=40 {
                        for j in 0..=40 {
                            let p = lo + size * DVec2::new(i as f64, j as f64) / 40.0;
                            let v = t.eval(p) as f32;
                            assert!(
                                v >= min - 1e-5 && v <= max + 1e-5,
                                "{wrap:?} {filter:?} [{lo}, {hi}]: {v} outside [{min}, {max}]"
                            );
                        }
                    }
                }
            }
        }
        // A constant region is found constant.
        let mut texels = vec![0.0f32; 64 * 64];
        for (i, t) in texels.iter_mut().enumerate() {
            if i % 64 >= 32 {
                *t = (i % 7) as f32;
            } else {
                *t = 2.0;
            }
        }
        let t = DensityTexture::new(64, 64, texels).unwrap();
        let (lo, hi) = (DVec2::new(0.05, 0.1), DVec2::new(0.4, 0.9));
        assert_eq!(t.range_over_box(lo, hi), (2.0, 2.0));
        assert_eq!(t.constant_over_box(lo, hi), Some(2.0));
        // Repeat: the box wraps from the right half into the left one.
        assert_eq!(
            t.constant_over_box(DVec2::new(0.9, 0.1), DVec2::new(1.2, 0.3)),
            None
        );
        assert_eq!(
            t.constant_over_box(DVec2::new(1.05, 0.1), DVec2::new(1.4, 0.3)),
            Some(2.0)
        );
        for clamp in [Wrap::ClampToEdge, Wrap::MirroredRepeat] {
            let c = t.clone().with_wrap(clamp);
            assert_eq!(
                c.constant_over_box(DVec2::new(-0.3, 0.1), DVec2::new(0.2, 0.3)),
                Some(2.0)
            );
        }
        assert_eq!(
            t.range_over_box(lo, DVec2::new(0.6, 0.9)),
            (0.0, 6.0),
            "crosses into the varying half"
        );
    }

    #[test]
    fn luminance_is_rec709() {
        assert!((luminance([1.0, 0.0, 0.0]) - 0.2126).abs() < 1e-6);
        assert!((luminance([0.0, 1.0, 0.0]) - 0.7152).abs() < 1e-6);
        assert!((luminance([0.0, 0.0, 1.0]) - 0.0722).abs() < 1e-6);
        // 0.5·0.2126 + 0.25·0.7152 + 2·0.0722 = 0.1063 + 0.1788 + 0.1444.
        assert!((luminance([0.5, 0.25, 2.0]) - 0.4295).abs() < 1e-6);
    }

    #[test]
    fn channels_and_luminance() {
        let rgba = [1.0, 2.0, 3.0, 4.0, 0.0, 1.0, 0.0, 1.0];
        let g = DensityTexture::from_channels(2, 1, &rgba, 4, Channel::Index(1)).unwrap();
        assert_eq!(g.texels(), &[2.0, 1.0]);
        let y = DensityTexture::from_channels(2, 1, &rgba, 4, Channel::Luminance).unwrap();
        assert!((y.texels()[1] - 0.7152).abs() < 1e-6);
        assert_eq!(
            DensityTexture::from_channels(2, 1, &rgba, 4, Channel::Index(4)),
            Err(Error::InvalidChannel {
                channel: Channel::Index(4),
                channels: 4
            })
        );
        assert!(matches!(
            DensityTexture::from_channels(2, 1, &rgba[..7], 4, Channel::Luminance),
            Err(Error::TextureSize { .. })
        ));
    }

    #[test]
    fn flip_rows_reverses_rows() {
        let t = DensityTexture::new(2, 3, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
        assert_eq!(t.flip_rows().texels(), &[5.0, 6.0, 3.0, 4.0, 1.0, 2.0]);
    }
}
