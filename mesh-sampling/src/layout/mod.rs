//! How the density sampler stores its pieces for drawing: an alias table
//! whose 16-byte columns are the piece records themselves, or the
//! inversion method's CDF with a lookup table (order-preserving).

mod column;

use rand::Rng;

use crate::subdivision::SubTriangle;
#[cfg(test)]
pub(crate) use column::FORCE_LINKED;
pub(crate) use column::Format;
pub use column::MAX_VALUE_SHIFT;
use column::{Column, low_mask};

/// How a [`DensitySampler`](crate::DensitySampler) draws a piece (a
/// sub-triangle of a face, or a component of a per-vertex density).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// Walker's alias method (built by Vose's algorithm) over 16-byte
    /// columns, bit-packed with widths fitted to the mesh. Column `k`
    /// holds piece `k`'s record (face, sub-triangle code, value), its
    /// threshold, and its alias's record, so that a draw reads one
    /// column; the batch path loads the columns of a block of draws
    /// first, then the faces, so that the misses of a block overlap. The
    /// fastest; a variate's neighbours do not map to neighbouring points.
    ///
    /// To make room for two records, a column stores the values with the
    /// mantissa bits their range leaves: all 23 on most meshes, never
    /// fewer than `23 −` [`MAX_VALUE_SHIFT`], a relative change of at most
    /// `2⁻¹³` (rounded to nearest; bounds upward). The values are rounded
    /// before the masses are computed, so the table draws exactly the
    /// density it reports ([`DensitySampler::value_tolerance`](crate::DensitySampler::value_tolerance)
    /// gives the change). When the face count and the deepest level leave
    /// too few bits for that, column `k` holds the index of its alias
    /// instead, whose column a draw taking the alias side reads too (the
    /// values then exact); when they leave fewer than
    /// [`MIN_THRESHOLD_BITS`] bits for the threshold even so, the sampler
    /// uses [`Inversion`](Self::Inversion) instead
    /// ([`DensitySampler::layout`](crate::DensitySampler::layout) says
    /// which).
    #[default]
    Alias,
    /// The inversion method: the CDF of the pieces in face order, searched
    /// with a lookup table (Šik & Křivánek 2013, Sec. 4) or by bisection,
    /// then the piece's record. Monotone in the variate (stratified or
    /// low-discrepancy variates stay stratified over the surface), but a
    /// draw walks table → CDF → record: two or three cache misses once the
    /// pieces outgrow the cache. The values are exact.
    Inversion,
}

/// The fewest bits an alias column keeps for its threshold: a column's
/// split between its two sides is rounded to `2⁻²⁴` of the column, a
/// relative change of a piece's probability below `2⁻²⁴ / (n pᵢ)`, far
/// under what the `f32` values of the pieces resolve.
pub const MIN_THRESHOLD_BITS: u32 = 24;

/// One entry of the discrete distribution: a sub-triangle (or linear
/// component) of a face, with its density value (exact mode: its bound).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Piece {
    pub(crate) face: u32,
    pub(crate) part: SubTriangle,
    pub(crate) value: f32,
}

impl Piece {
    /// A placeholder (face 0, the root, value 0).
    pub(crate) const EMPTY: Self = Self {
        face: 0,
        part: SubTriangle::ROOT,
        value: 0.0,
    };
}

/// The alias table over pieces, its columns holding the records: column
/// `k` holds piece `k` (in the order given, face order for the sampler),
/// and with the [`Inline`](column::Inline) format its alias's record too.
#[derive(Debug, Clone)]
pub(crate) struct PieceAlias {
    columns: Vec<Column>,
    format: Format,
}

impl PieceAlias {
    /// The table drawing `pieces[i]` with probability `masses[i] / Σ`, in
    /// `format` ([`Format::fit`] to these pieces, their values rounded by
    /// [`Format::round_values`]). Entries of zero (or non-finite) mass
    /// keep their column, with a threshold of 0: never drawn. `None` when
    /// no mass is positive and finite.
    pub(crate) fn new(pieces: &[Piece], masses: &[f64], format: Format) -> Option<Self> {
        let (alias, threshold) = vose(masses, format.threshold_bits())?;
        let columns = (0..pieces.len())
            .map(|k| {
                let a = alias[k] as usize;
                match format {
                    Format::Inline(f) => f.pack(pieces[k], pieces[a], threshold[k]),
                    Format::Linked(f) => f.pack(pieces[k], a, threshold[k]),
                }
            })
            .collect();
        Some(Self { columns, format })
    }

    pub(crate) fn memory_bytes(&self) -> usize {
        self.columns.len() * size_of::<Column>()
    }

    /// Number of pieces (columns).
    pub(crate) fn len(&self) -> usize {
        self.columns.len()
    }

    /// See [`Format::value_tolerance`].
    pub(crate) fn value_tolerance(&self) -> f64 {
        self.format.value_tolerance()
    }

    /// Whether a column holds its alias's record (a draw reads one
    /// column) rather than its index (two when the alias side is taken).
    pub(crate) fn inline(&self) -> bool {
        matches!(self.format, Format::Inline(_))
    }

    /// Piece `k` (its column's own record).
    #[inline]
    pub(crate) fn get(&self, k: usize) -> Piece {
        match self.format {
            Format::Inline(f) => f.record(self.columns[k], 0),
            Format::Linked(f) => f.own(self.columns[k]),
        }
    }

    /// The piece for one `u64` of random bits: the column from the high
    /// part of `bits · n`, the side from the low part.
    #[inline]
    pub(crate) fn piece(&self, bits: u64) -> Piece {
        let (k, frac) = self.split(bits);
        self.pick(k, frac)
    }

    /// The piece a draw takes in column `k` for the fraction `frac`.
    #[inline]
    pub(crate) fn pick(&self, k: usize, frac: u64) -> Piece {
        match self.format {
            Format::Inline(f) => f.pick(self.columns[k], frac),
            Format::Linked(f) => self.get(f.side(k, self.columns[k], frac)),
        }
    }

    /// The column and the side fraction for one `u64` of random bits (the
    /// high and low parts of `bits · n`), as [`piece`](Self::piece) splits
    /// them.
    #[inline]
    pub(crate) fn split(&self, bits: u64) -> (usize, u64) {
        let x = u128::from(bits) * self.columns.len() as u128;
        ((x >> 64) as usize, x as u64)
    }

    /// In a linked table, the column whose own record a draw takes in
    /// column `k` for the fraction `frac`: `k` or its alias (reads column
    /// `k`). In an inline table, `k`: the record is in column `k`, on the
    /// side [`pick`](Self::pick) reads.
    #[inline]
    pub(crate) fn side(&self, k: usize, frac: u64) -> usize {
        match self.format {
            Format::Inline(_) => k,
            Format::Linked(f) => f.side(k, self.columns[k], frac),
        }
    }

    /// Asks for column `k`'s cache line ahead of its use (a hint: no read).
    #[inline(always)]
    pub(crate) fn prefetch(&self, k: usize) {
        crate::prefetch::prefetch(&self.columns, k);
    }

    /// Fills `out` with pieces, one `u64` of `rng` each, in blocks whose
    /// memory accesses are issued a stage at a time so that the misses of
    /// a block overlap: the columns from the random numbers; the columns'
    /// loads alone, a loop of independent loads; then the records (in a
    /// linked table: the sides, a loop without loads, and the picked
    /// columns' loads alone, a miss only for draws that take the alias
    /// side).
    #[inline]
    pub(crate) fn fill<R: Rng + ?Sized>(&self, rng: &mut R, out: &mut [Piece]) {
        const B: usize = crate::parallel::BLOCK;
        let (mut index, mut frac) = ([0usize; B], [0u64; B]);
        let mut loaded = [Column::default(); B];
        for block in out.chunks_mut(B) {
            let len = block.len();
            for (i, f) in index[..len].iter_mut().zip(&mut frac[..len]) {
                (*i, *f) = self.split(rng.next_u64());
            }
            for (c, &i) in loaded[..len].iter_mut().zip(&index[..len]) {
                *c = self.columns[i];
            }
            match self.format {
                Format::Inline(f) => {
                    for ((slot, &c), &x) in block.iter_mut().zip(&loaded).zip(&frac) {
                        *slot = f.pick(c, x);
                    }
                }
                Format::Linked(f) => {
                    // The sides first, in a loop without loads, so that the
                    // loads of the next loop are issued back to back (a
                    // loop mixing the two keeps few of them in flight).
                    for k in 0..len {
                        index[k] = f.side(index[k], loaded[k], frac[k]);
                    }
                    for (c, &i) in loaded[..len].iter_mut().zip(&index[..len]) {
                        *c = self.columns[i];
                    }
                    for (slot, &c) in block.iter_mut().zip(&loaded[..len]) {
                        *slot = f.own(c);
                    }
                }
            }
        }
    }
}

/// Walker's alias method by Vose's algorithm over `masses`: each entry's
/// alias and its threshold in `bits` bits. Entries of zero (or
/// non-finite) mass get a threshold of 0 (never drawn); `None` when no
/// mass is positive and finite.
fn vose(masses: &[f64], bits: u32) -> Option<(Vec<u32>, Vec<u64>)> {
    let usable = |m: f64| m > 0.0 && m.is_finite();
    let n = masses.len();
    let total: f64 = masses.iter().copied().filter(|&m| usable(m)).sum();
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    // Scaled probabilities n·p_i; a column is filled from a small entry
    // topped up by a large one.
    let mut scaled: Vec<f64> = masses
        .iter()
        .map(|&m| if usable(m) { m / total * n as f64 } else { 0.0 })
        .collect();
    let mut alias: Vec<u32> = (0..n as u32).collect();
    let mut threshold = vec![u64::MAX; n];
    let (mut small, mut large): (Vec<u32>, Vec<u32>) =
        (0..n as u32).partition(|&k| scaled[k as usize] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        let (s, l) = (s as usize, l as usize);
        threshold[s] = to_threshold(scaled[s], bits);
        alias[s] = l as u32;
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l as u32);
        }
    }
    // What is left is 1 up to rounding: full columns (alias = own),
    // except that an entry of zero mass must never be drawn, whatever the
    // rounding did: it goes wholly to the heaviest entry.
    let heaviest = (0..n).max_by(|&a, &b| scaled[a].total_cmp(&scaled[b]))?;
    for &s in &small {
        if !usable(masses[s as usize]) {
            threshold[s as usize] = 0;
            alias[s as usize] = heaviest as u32;
        }
    }
    let full = low_mask(bits);
    threshold.iter_mut().for_each(|t| *t = (*t).min(full));
    Some((alias, threshold))
}

/// `p · 2^bits` for `p ∈ [0, 1)`, saturating at `2^bits − 1`.
fn to_threshold(p: f64, bits: u32) -> u64 {
    // 2^bits as f64 is exact; the cast saturates for p ≥ 1.
    ((p.max(0.0) * 2f64.powi(bits as i32)) as u64).min(low_mask(bits))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn piece(k: u32) -> Piece {
        Piece {
            face: k,
            part: SubTriangle::ROOT,
            value: 1.0,
        }
    }

    /// The table in the format `fit` picks, or forced to be linked.
    fn build(pieces: &[Piece], masses: &[f64], faces: usize, linked: bool) -> Option<PieceAlias> {
        FORCE_LINKED.with(|f| f.set(linked));
        let format = Format::fit(pieces, faces, false);
        FORCE_LINKED.with(|f| f.set(false));
        let format = format?;
        assert_eq!(matches!(format, Format::Linked(_)), linked);
        PieceAlias::new(pieces, masses, format)
    }

    /// Column `k`'s two sides and the fraction of it below the threshold.
    fn sides(table: &PieceAlias, k: usize) -> (Piece, Piece, f64) {
        let c = table.columns[k];
        let scale = 2f64.powi(table.format.threshold_bits() as i32);
        match table.format {
            Format::Inline(f) => (
                f.record(c, 0),
                f.record(c, 1),
                f.threshold(c) as f64 / scale,
            ),
            Format::Linked(f) => (
                f.own(c),
                table.get(f.alias(c)),
                f.threshold(c) as f64 / scale,
            ),
        }
    }

    /// The probability of each piece, read off the columns exactly.
    fn realised(table: &PieceAlias, n: usize) -> Vec<f64> {
        let mut p = vec![0.0; n];
        let width = 1.0 / table.columns.len() as f64;
        for k in 0..table.len() {
            let (own, alias, below) = sides(table, k);
            p[own.face as usize] += width * below;
            p[alias.face as usize] += width * (1.0 - below);
        }
        p
    }

    #[test]
    fn columns_realise_the_masses_and_skip_zeros() {
        let masses = [3.0, 0.0, 1.0, 6.0, 1e-300, 0.5, 0.0, f64::INFINITY];
        let pieces: Vec<Piece> = (0..masses.len() as u32).map(piece).collect();
        for linked in [false, true] {
            let table = build(&pieces, &masses, masses.len(), linked).unwrap();
            assert_eq!(table.inline(), !linked);
            let total: f64 = masses.iter().filter(|m| m.is_finite()).sum();
            let p = realised(&table, masses.len());
            for (k, (&m, &q)) in masses.iter().zip(&p).enumerate() {
                let want = if m.is_finite() { m / total } else { 0.0 };
                // Thresholds keep at least 24 bits of a column.
                assert!((q - want).abs() < 1e-7, "piece {k}: {q} for {want}");
            }
            assert_eq!(p[1], 0.0);
            assert_eq!(p[6], 0.0);
            assert_eq!(p[7], 0.0);
            // Sampling by bits: the extreme variates stay in range, and
            // `piece` is `pick` after `split`, on the side `side` names.
            for bits in [0, 1, u64::MAX / 2, u64::MAX - 1, u64::MAX] {
                let f = table.piece(bits).face;
                assert!(masses[f as usize] > 0.0 && masses[f as usize].is_finite());
                let (k, frac) = table.split(bits);
                if linked {
                    assert_eq!(table.get(table.side(k, frac)), table.piece(bits));
                }
            }
            assert!(build(&pieces[..2], &[0.0, f64::NAN], 2, linked).is_none());
        }
    }

    #[test]
    fn a_column_is_sixteen_bytes_and_round_trips_its_records() {
        assert_eq!(size_of::<Column>(), 16);
        assert_eq!(align_of::<Column>(), 16);
        // Every level, both orientations, and the largest face a format
        // of these widths holds; values over thirty binades.
        let mut pieces = Vec::new();
        for level in 0..=8u8 {
            let top = (1u32 << level) - 1;
            pieces.push(Piece {
                face: 70_000,
                part: SubTriangle::new(level, top, 0, false),
                value: 3e4,
            });
            pieces.push(Piece {
                face: 3,
                part: SubTriangle::new(level, 0, top.saturating_sub(1), level > 0),
                value: 2e-5,
            });
        }
        let masses: Vec<f64> = (1..=pieces.len()).map(|k| k as f64).collect();
        for linked in [false, true] {
            let mut pieces = pieces.clone();
            FORCE_LINKED.with(|f| f.set(linked));
            let format = Format::fit(&pieces, 70_001, false).unwrap();
            FORCE_LINKED.with(|f| f.set(false));
            format.round_values(&mut pieces);
            assert_eq!(format.value_tolerance() == 0.0, linked);
            let table = PieceAlias::new(&pieces, &masses, format).unwrap();
            for (k, p) in pieces.iter().enumerate() {
                assert_eq!(table.get(k), *p, "piece {k}");
                // The alias side holds a piece of the table, whole.
                assert!(pieces.contains(&sides(&table, k).1));
            }
        }
        let corners: Vec<Piece> = (0..3)
            .map(|c| Piece {
                face: 9,
                part: SubTriangle::vertex(c),
                value: 0.5,
            })
            .collect();
        for linked in [false, true] {
            let table = build(&corners, &[1.0; 3], 10, linked).unwrap();
            for (k, p) in corners.iter().enumerate() {
                assert_eq!(table.get(k), *p);
            }
        }
    }

    #[test]
    fn the_block_fill_draws_what_one_at_a_time_draws() {
        use rand::SeedableRng;
        let masses: Vec<f64> = (0..300).map(|k| ((k * 37) % 11) as f64).collect();
        let pieces: Vec<Piece> = (0..300).map(piece).collect();
        for linked in [false, true] {
            let table = build(&pieces, &masses, 300, linked).unwrap();
            let mut a = rand_pcg::Pcg64Mcg::seed_from_u64(5);
            let mut b = a.clone();
            let mut filled = vec![Piece::EMPTY; 200];
            table.fill(&mut a, &mut filled);
            let one: Vec<Piece> = (0..200).map(|_| table.piece(b.next_u64())).collect();
            assert_eq!(filled, one);
        }
    }
}
