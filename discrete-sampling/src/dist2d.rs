//! Piecewise-constant 2D distributions over `[0, 1)²`: a marginal over rows
//! and a conditional per row (pbrt's `PiecewiseConstant2D`), each a 1D
//! sampler, by default a [`GuideTable`] as in the paper's Fig. 8.

use std::f64::consts::PI;

use rand::distr::Distribution;

use crate::uniform::{ONE_MINUS_EPSILON, bits_to_unit, fill_batch_pairs, unit_f64};
use crate::weights::checked_total;
use crate::{DiscreteSampler, Error, GuideTable, InvertibleSampler};

/// A point drawn from a [`Distribution2D`]. `Default` (the origin, cell
/// `[0, 0]`, density 0) is for allocating buffers for
/// [`sample_into`](Distribution2D::sample_into).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Sample2D {
    /// `[x, y]` in `[0, 1)²`: `x` runs along a row (columns), `y` down the
    /// rows, as in an image.
    pub point: [f64; 2],
    /// The cell, `[column, row]`.
    pub cell: [usize; 2],
    /// Density of `point` with respect to area in `[0, 1)²`.
    pub pdf: f64,
}

/// A piecewise-constant density over `[0, 1)²` given by a `width × height`
/// grid of non-negative weights (an image, row-major, row 0 first).
///
/// Sampling draws a row from the marginal with `u[1]` and a column from that
/// row's conditional with `u[0]`, then places the point inside the cell with
/// the remapped remainders, so one pair of variates makes one point and
/// stratified pairs stay stratified (with an invertible `S`).
///
/// `S` is the 1D sampler of the marginal and of every row: [`GuideTable`]
/// by default; [`CdfBisection`](crate::CdfBisection) gives the classic
/// method without the table (the paper's Fig. 8 compares the two).
///
/// # Example
/// ```
/// use discrete_sampling::Distribution2D;
/// // A 4×2 image whose right half is three times as bright.
/// let image = [1.0f32, 1.0, 3.0, 3.0, 1.0, 1.0, 3.0, 3.0];
/// let d = Distribution2D::new(&image, 4, 2)?;
/// let s = d.sample_u([0.9, 0.2]);
/// assert_eq!(s.cell, [3, 0]);
/// assert!((s.pdf - 1.5).abs() < 1e-12); // 3 / mean(2)
/// assert_eq!(d.pdf(s.point), s.pdf);
/// # Ok::<(), discrete_sampling::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution2D<S = GuideTable> {
    width: usize,
    height: usize,
    /// `1 / width`, `1 / height`: points are placed by multiplication.
    inv_size: [f64; 2],
    marginal: S,
    rows: Vec<S>,
}

impl Distribution2D<GuideTable> {
    /// Builds the distribution of a `width × height` grid with guide tables.
    ///
    /// # Errors
    /// [`Error::DimensionMismatch`] when `weights.len() != width · height`,
    /// and the weight errors of [`Error`] with `index = row · width + column`.
    pub fn new<W: Copy + Into<f64>>(
        weights: &[W],
        width: usize,
        height: usize,
    ) -> Result<Self, Error> {
        Self::with_sampler(weights, width, height)
    }

    /// Builds the distribution of an equirectangular (latitude–longitude)
    /// environment map: each row is weighted by `sin θ` of its centre, where
    /// row 0 is the top (`θ = 0`), so that [`pdf_solid_angle`] is
    /// proportional to the map's value. Without this weighting the poles,
    /// which the map stretches over whole rows, are drawn far too often.
    ///
    /// # Errors
    /// As for [`new`](Self::new).
    pub fn from_equirect<W: Copy + Into<f64>>(
        luminance: &[W],
        width: usize,
        height: usize,
    ) -> Result<Self, Error> {
        Self::from_equirect_with_sampler(luminance, width, height)
    }
}

impl<S: DiscreteSampler> Distribution2D<S> {
    /// Builds the distribution with rows and marginal of sampler type `S`.
    ///
    /// # Errors
    /// As for [`Distribution2D::new`].
    pub fn with_sampler<W: Copy + Into<f64>>(
        weights: &[W],
        width: usize,
        height: usize,
    ) -> Result<Self, Error> {
        Self::build(weights, width, height, |_| 1.0)
    }

    /// [`from_equirect`](Distribution2D::from_equirect) with sampler type `S`.
    ///
    /// # Errors
    /// As for [`Distribution2D::new`].
    pub fn from_equirect_with_sampler<W: Copy + Into<f64>>(
        luminance: &[W],
        width: usize,
        height: usize,
    ) -> Result<Self, Error> {
        Self::build(luminance, width, height, |row| {
            (PI * (row as f64 + 0.5) / height as f64).sin()
        })
    }

    fn build<W: Copy + Into<f64>>(
        weights: &[W],
        width: usize,
        height: usize,
        row_scale: impl Fn(usize) -> f64,
    ) -> Result<Self, Error> {
        let expected = width.checked_mul(height);
        if expected != Some(weights.len()) || width == 0 || height == 0 {
            return Err(Error::DimensionMismatch {
                width,
                height,
                expected: expected.unwrap_or(usize::MAX),
                len: weights.len(),
            });
        }
        // Validate everything first, so the error names the flat index.
        checked_total(weights)?;
        let mut row_mass = Vec::with_capacity(height);
        let mut rows = Vec::with_capacity(height);
        for (r, row) in weights.chunks_exact(width).enumerate() {
            let sum: f64 = row.iter().map(|&w| w.into()).sum();
            let mass = sum * row_scale(r);
            row_mass.push(mass);
            // A row of zero mass is never drawn; any valid sampler will do.
            rows.push(if mass > 0.0 {
                S::from_weights(row)?
            } else {
                S::from_weights(&[1.0f64])?
            });
        }
        let marginal = S::from_weights(&row_mass)?;
        Ok(Self {
            width,
            height,
            inv_size: [1.0 / width as f64, 1.0 / height as f64],
            marginal,
            rows,
        })
    }

    /// Columns of the grid.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Rows of the grid.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The marginal distribution over rows.
    pub fn marginal(&self) -> &S {
        &self.marginal
    }

    /// The conditional distribution of the columns of `row`, `None` when
    /// `row >= height()`.
    pub fn row(&self, row: usize) -> Option<&S> {
        self.rows.get(row)
    }

    /// Probability of drawing the cell `[column, row]`.
    pub fn cell_probability(&self, cell: [usize; 2]) -> f64 {
        let [column, row] = cell;
        match self.rows.get(row) {
            Some(r) if column < self.width => self.marginal.pdf(row) * r.pdf(column),
            _ => 0.0,
        }
    }

    /// Density (w.r.t. area in `[0, 1)²`) at `point`; 0 outside the square
    /// and for NaN coordinates.
    pub fn pdf(&self, point: [f64; 2]) -> f64 {
        match self.cell_at(point) {
            Some(cell) => self.cell_probability(cell) * self.area(),
            None => 0.0,
        }
    }

    /// The cell `[column, row]` that contains `point`, or `None` outside
    /// `[0, 1)²` (and for NaN). The one rule shared by [`pdf`](Self::pdf),
    /// [`invert`](Distribution2D::invert) and the placement of sampled
    /// points, so a sampled point is always found in the cell it was drawn
    /// from.
    pub fn cell_at(&self, point: [f64; 2]) -> Option<[usize; 2]> {
        let [x, y] = point;
        if !((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y)) {
            return None;
        }
        Some([cell_of(x, self.width), cell_of(y, self.height)])
    }

    /// Draws a point for the variates `u = [u0, u1]` in `[0, 1)²` (clamped
    /// otherwise, NaN counts as 0, as for the 1D samplers): `u1` picks the
    /// row, `u0` the column. The point always lies inside its cell, also
    /// for a variate just below 1, where `(row + v) / height` would round up
    /// onto the next cell's edge.
    #[inline]
    pub fn sample_u(&self, u: [f64; 2]) -> Sample2D {
        let (row, v) = self.marginal.sample_remapped(u[1]);
        let conditional = &self.rows[row];
        let (column, w) = conditional.sample_remapped(u[0]);
        let [inv_w, inv_h] = self.inv_size;
        Sample2D {
            point: [
                place(column, w, self.width, inv_w),
                place(row, v, self.height, inv_h),
            ],
            cell: [column, row],
            pdf: self.marginal.pdf(row) * conditional.pdf(column) * self.area(),
        }
    }

    /// Fills `out` with independent samples, two `u64` of `rng` each: the
    /// same samples as calling `sample` in a loop, faster because the
    /// variates are generated ahead and the samples' memory accesses
    /// overlap.
    pub fn sample_into<R: rand::Rng + ?Sized>(&self, rng: &mut R, out: &mut [Sample2D]) {
        fill_batch_pairs(rng, out, |b0, b1| {
            self.sample_u([bits_to_unit(b0), bits_to_unit(b1)])
        });
    }

    /// `width · height`, the density of a cell of probability 1.
    fn area(&self) -> f64 {
        self.width as f64 * self.height as f64
    }
}

impl<S: InvertibleSampler> Distribution2D<S> {
    /// The variates that [`sample_u`](Self::sample_u) maps to `point`, or
    /// `None` where the density is zero (and outside `[0, 1)²`, NaN
    /// included). `sample_u(invert(p)?)` lands in the cell of `p`, at `p` up
    /// to rounding.
    pub fn invert(&self, point: [f64; 2]) -> Option<[f64; 2]> {
        let [column, row] = self.cell_at(point)?;
        let ys = point[1] * self.height as f64 - row as f64;
        let xs = point[0] * self.width as f64 - column as f64;
        let u1 = invert_within(&self.marginal, row, ys)?;
        let u0 = invert_within(&self.rows[row], column, xs)?;
        Some([u0, u1])
    }
}

/// The variate that draws `index` from `sampler` with remainder about
/// `fraction`: the start of the entry's interval plus `fraction` of its
/// width, stepped back below the interval's end if rounding carried it
/// there (it would draw the next entry).
fn invert_within<S: InvertibleSampler>(sampler: &S, index: usize, fraction: f64) -> Option<f64> {
    let start = sampler.invert(index)?;
    let fraction = fraction.clamp(0.0, ONE_MINUS_EPSILON);
    let mut u = (start + fraction * sampler.pdf(index)).min(ONE_MINUS_EPSILON);
    // A few ulps at most; bounded so a sampler that disagrees with its own
    // `invert` cannot make this loop long.
    for _ in 0..64 {
        if u <= start || sampler.sample_u(u) == index {
            return Some(u);
        }
        u = u.next_down();
    }
    Some(start)
}

/// The cell among `n` equal cells of `[0, 1)` that contains `x`.
#[inline]
fn cell_of(x: f64, n: usize) -> usize {
    ((x * n as f64) as usize).min(n - 1)
}

/// The point of `[0, 1)` at `fraction` of cell `index` of `n` (`inv_n` =
/// `1 / n`), kept inside that cell as [`cell_of`] sees it: rounding of
/// `(index + fraction) / n` may reach the next cell's lower edge (or, by an
/// ulp, stay below this cell's), so the point is stepped by ulps until it
/// is inside. At most a few steps, and only for fractions next to 0 or 1.
#[inline]
fn place(index: usize, fraction: f64, n: usize, inv_n: f64) -> f64 {
    let i = index as f64;
    let p = ((i + fraction) * inv_n).min(ONE_MINUS_EPSILON);
    // The test `cell_of(p, n) == index` without its float-to-integer
    // conversion (measured: that conversion and its branch made 2D
    // sampling 1.4× slower): `⌊p · n⌋ = index` exactly when
    // `index ≤ p · n < index + 1`, both sides exact floats.
    let t = p * n as f64;
    if t >= i && t < i + 1.0 {
        return p;
    }
    step_into(p, index, n)
}

/// [`place`]'s slow path: ulp steps until `p` is in cell `index`.
#[cold]
fn step_into(mut p: f64, index: usize, n: usize) -> f64 {
    while p > 0.0 && cell_of(p, n) > index {
        p = p.next_down();
    }
    while cell_of(p, n) < index {
        p = p.next_up();
    }
    p
}

impl<S: DiscreteSampler> Distribution<Sample2D> for Distribution2D<S> {
    fn sample<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> Sample2D {
        let u0 = unit_f64(rng);
        let u1 = unit_f64(rng);
        self.sample_u([u0, u1])
    }
}

/// The direction of a point of an equirectangular map: `θ = π y` from the
/// `+Z` pole (row 0 is the top), `φ = 2π x` from `+X` towards `+Y`; returns
/// the unit vector `[sin θ cos φ, sin θ sin φ, cos θ]`. Convert to your
/// renderer's axes. [`equirect_point`] is its inverse.
pub fn equirect_direction(point: [f64; 2]) -> [f64; 3] {
    let theta = PI * point[1];
    let phi = 2.0 * PI * point[0];
    let (sin_t, cos_t) = theta.sin_cos();
    let (sin_p, cos_p) = phi.sin_cos();
    [sin_t * cos_p, sin_t * sin_p, cos_t]
}

/// The point of an equirectangular map in `[0, 1)²` that looks in
/// `direction` (any length): the inverse of [`equirect_direction`], with
/// `x = φ / 2π`, `φ = atan2(y, x)` in `[0, 2π)`, and `y = θ / π`,
/// `θ = atan2(√(x² + y²), z)`. `None` for a zero, infinite or NaN direction. At the
/// poles, where every `φ` looks the same way, `x` is 0.
pub fn equirect_point(direction: [f64; 3]) -> Option<[f64; 2]> {
    if !direction.iter().all(|c| c.is_finite()) {
        return None;
    }
    // Scaled by the largest component first, so that the length of a
    // huge (or subnormal) direction neither overflows nor underflows.
    let big = direction.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    if big == 0.0 {
        return None;
    }
    let [dx, dy, dz] = direction.map(|c| c / big);
    // atan2 rather than acos(z / len): acos loses half the digits next to
    // the poles, where z is close to ±1.
    let theta = (dx * dx + dy * dy).sqrt().atan2(dz);
    let mut phi = dy.atan2(dx);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    // φ just below 2π and θ = π round to 1, which is outside the map.
    Some([
        (phi / (2.0 * PI)).min(ONE_MINUS_EPSILON),
        (theta / PI).min(ONE_MINUS_EPSILON),
    ])
}

/// Converts a density over `[0, 1)²` of an equirectangular map to a density
/// over solid angle: `p(ω) = p(x, y) / (2π² sin θ)`, the Jacobian of
/// `dω = 2π² sin θ dx dy`. Returns 0 at the poles, where the map is
/// singular.
pub fn pdf_solid_angle(pdf_area: f64, point: [f64; 2]) -> f64 {
    let sin_t = (PI * point[1]).sin();
    if sin_t > 0.0 {
        pdf_area / (2.0 * PI * PI * sin_t)
    } else {
        0.0
    }
}

/// A direction drawn from an environment map by
/// [`Distribution2D::sample_direction`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DirectionSample {
    /// Unit vector, in the axes of [`equirect_direction`].
    pub direction: [f64; 3],
    /// Density with respect to solid angle (per steradian).
    pub pdf: f64,
    /// The point of the map, as [`Distribution2D::sample_u`] returns it.
    pub point: [f64; 2],
}

/// Environment maps: a `Distribution2D` read as an equirectangular map
/// (best built by [`Distribution2D::from_equirect`], whose rows are
/// weighted by `sin θ`, so that the density over directions follows the
/// map's values), in the axes of [`equirect_direction`].
impl<S: DiscreteSampler> Distribution2D<S> {
    /// Draws a direction for the variates `u` and its density with respect
    /// to solid angle, for a path tracer's light sampling.
    pub fn sample_direction(&self, u: [f64; 2]) -> DirectionSample {
        let s = self.sample_u(u);
        DirectionSample {
            direction: equirect_direction(s.point),
            pdf: pdf_solid_angle(s.pdf, s.point),
            point: s.point,
        }
    }

    /// The density with respect to solid angle with which
    /// [`sample_direction`](Self::sample_direction) draws `direction` (any
    /// length): what multiple importance sampling needs for a direction
    /// found by BSDF sampling. 0 for a zero or NaN direction and at the
    /// poles. Integrates to 1 over the sphere.
    pub fn pdf_direction(&self, direction: [f64; 3]) -> f64 {
        match equirect_point(direction) {
            Some(point) => pdf_solid_angle(self.pdf(point), point),
            None => 0.0,
        }
    }
}
