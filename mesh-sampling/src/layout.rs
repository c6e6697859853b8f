//! How the density sampler stores its pieces for drawing: an alias table
//! whose 16-byte columns are the piece records themselves, or the
//! inversion method's CDF with a lookup table (order-preserving).

use rand::Rng;

use crate::subdivision::SubTriangle;

/// How a [`DensitySampler`](crate::DensitySampler) draws a piece (a
/// sub-triangle of a face, or a component of a per-vertex density).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// Walker's alias method (built by Vose's algorithm) over 16-byte
    /// columns: column `k` is piece `k`'s record (face, sub-triangle code,
    /// value), its threshold and the index of its alias, bit-packed with
    /// widths fitted to the mesh. A draw reads one column, plus the alias's
    /// column when the alias side is taken; the batch path loads the
    /// columns of a block of draws first, then the aliases' columns, then
    /// the faces, so that the misses of a block overlap. The fastest; a
    /// variate's neighbours do not map to neighbouring points. When a
    /// mesh's face count, deepest level and piece count leave fewer than
    /// [`MIN_THRESHOLD_BITS`] bits for the threshold, the sampler uses
    /// [`Inversion`](Self::Inversion) instead
    /// ([`DensitySampler::layout`](crate::DensitySampler::layout) says
    /// which).
    #[default]
    Alias,
    /// The inversion method: the CDF of the pieces in face order, searched
    /// with a lookup table (Šik & Křivánek 2013, Sec. 4) or by bisection,
    /// then the piece's record. Monotone in the variate (stratified or
    /// low-discrepancy variates stay stratified over the surface), but a
    /// draw walks table → CDF → record: two or three cache misses once the
    /// pieces outgrow the cache.
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

/// Bit widths of a packed column, from the least significant bit: the
/// value (32, an `f32`), the compact sub-triangle code (`part`), the face
/// (`face`), the alias's column (`alias`), and the threshold in the top
/// `threshold` bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Format {
    /// Bits of `i` and of `j` in the compact code (the deepest level).
    level_bits: u32,
    face: u32,
    alias: u32,
    threshold: u32,
}

/// Bits of the compact code besides `i` and `j`: level (4) and down (1).
const PART_FIXED: u32 = 5;
/// The level field marking a per-vertex component (levels are ≤ 13).
const VERTEX_LEVEL: u32 = 15;

/// Bits needed for the values `0..n` (0 for `n ≤ 1`).
fn bits_for(n: usize) -> u32 {
    usize::BITS - n.saturating_sub(1).leading_zeros()
}

impl Format {
    /// The widths for `pieces` pieces over `faces` faces, the deepest at
    /// level `deepest`, or `None` when fewer
    /// than [`MIN_THRESHOLD_BITS`] would be left for the threshold.
    fn fit(deepest: u8, faces: usize, pieces: usize) -> Option<Self> {
        // A vertex component keeps its corner (0..3) in `j`: two bits.
        let level_bits = u32::from(deepest).max(2);
        let (face, alias) = (bits_for(faces), bits_for(pieces));
        let used = 32 + PART_FIXED + 2 * level_bits + face + alias;
        let threshold = 128u32.checked_sub(used)?.min(64);
        (threshold >= MIN_THRESHOLD_BITS).then_some(Self {
            level_bits,
            face,
            alias,
            threshold,
        })
    }

    fn part_bits(self) -> u32 {
        PART_FIXED + 2 * self.level_bits
    }

    /// The compact code of a sub-triangle (or vertex component).
    fn pack_part(self, part: SubTriangle) -> u128 {
        let l = self.level_bits;
        let (level, down, i, j) = match part.corner() {
            Some(c) => (VERTEX_LEVEL, 0, 0, c as u32),
            None => {
                let (i, j, down) = part.grid();
                (u32::from(part.level()), u32::from(down), i, j)
            }
        };
        u128::from((((level << 1 | down) << l | i) << l) | j)
    }

    fn unpack_part(self, code: u32) -> SubTriangle {
        let l = self.level_bits;
        let mask = (1u32 << l) - 1;
        let (j, i) = (code & mask, (code >> l) & mask);
        let down = (code >> (2 * l)) & 1 != 0;
        let level = code >> (2 * l + 1);
        if level == VERTEX_LEVEL {
            SubTriangle::vertex(j as usize)
        } else {
            SubTriangle::new(level as u8, i, j, down)
        }
    }

    fn pack(self, piece: Piece, alias: usize, threshold: u64) -> Column {
        let p = self.part_bits();
        let bits = u128::from(piece.value.to_bits())
            | self.pack_part(piece.part) << 32
            | u128::from(piece.face) << (32 + p)
            | (alias as u128) << (32 + p + self.face)
            | u128::from(threshold) << (128 - self.threshold);
        Column(bits)
    }

    /// The piece a column holds (its own side).
    #[inline]
    fn own(self, c: Column) -> Piece {
        let p = self.part_bits();
        let field = |shift: u32, width: u32| ((c.0 >> shift) as u64 & low_mask(width)) as u32;
        Piece {
            value: f32::from_bits(c.0 as u32),
            part: self.unpack_part(field(32, p)),
            face: field(32 + p, self.face),
        }
    }

    #[inline]
    fn alias(self, c: Column) -> usize {
        let shift = 32 + self.part_bits() + self.face;
        ((c.0 >> shift) as u64 & low_mask(self.alias)) as usize
    }

    #[inline]
    fn threshold(self, c: Column) -> u64 {
        (c.0 >> (128 - self.threshold)) as u64
    }

    /// The column the fraction `frac` (the low half of `bits · n`) picks
    /// in column `k`: `k` itself below the threshold, its alias above.
    #[inline]
    fn side(self, k: usize, c: Column, frac: u64) -> usize {
        if frac >> (64 - self.threshold) >= self.threshold(c) {
            self.alias(c)
        } else {
            k
        }
    }
}

/// The `width` low bits set (`width ≤ 64`).
#[inline]
fn low_mask(width: u32) -> u64 {
    u64::MAX.checked_shr(64 - width).unwrap_or(0)
}

/// A packed column (see [`Format`]). Sixteen bytes, 16-byte aligned, so a
/// column never straddles two cache lines.
#[derive(Debug, Clone, Copy, Default)]
struct Column(u128);

/// The alias table over pieces, its columns holding the records: column
/// `k` is piece `k` (in the order given, face order for the sampler).
#[derive(Debug, Clone)]
pub(crate) struct PieceAlias {
    columns: Vec<Column>,
    format: Format,
}

impl PieceAlias {
    /// The table drawing `pieces[i]` with probability `masses[i] / Σ`.
    /// Entries of zero (or non-finite) mass keep their column, with a
    /// threshold of 0: never drawn. `None` when no mass is positive and
    /// finite, or when the columns cannot be packed (see [`Layout::Alias`]).
    pub(crate) fn new(pieces: &[Piece], masses: &[f64], faces: usize) -> Option<Self> {
        let deepest = pieces
            .iter()
            .filter(|p| p.part.corner().is_none())
            .map(|p| p.part.level())
            .max()
            .unwrap_or(0);
        let format = Format::fit(deepest, faces, pieces.len())?;
        let usable = |m: f64| m > 0.0 && m.is_finite();
        let n = pieces.len();
        let total: f64 = masses.iter().copied().filter(|&m| usable(m)).sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        // Vose: scaled probabilities n·p_i; a column is filled from a
        // small entry topped up by a large one.
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
            threshold[s] = to_threshold(scaled[s], format.threshold);
            alias[s] = l as u32;
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l as u32);
            }
        }
        // What is left is 1 up to rounding: full columns (alias = own),
        // except that an entry of zero mass must never be drawn, whatever
        // the rounding did: it goes wholly to the heaviest entry.
        let heaviest = (0..n).max_by(|&a, &b| scaled[a].total_cmp(&scaled[b]))?;
        for &s in &small {
            if !usable(masses[s as usize]) {
                threshold[s as usize] = 0;
                alias[s as usize] = heaviest as u32;
            }
        }
        let full = low_mask(format.threshold);
        let columns = (0..n)
            .map(|k| format.pack(pieces[k], alias[k] as usize, threshold[k].min(full)))
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

    /// Piece `k` (its column's own record).
    #[inline]
    pub(crate) fn get(&self, k: usize) -> Piece {
        self.format.own(self.columns[k])
    }

    /// The piece for one `u64` of random bits: the column from the high
    /// part of `bits · n`, the side from the low part.
    #[inline]
    pub(crate) fn piece(&self, bits: u64) -> Piece {
        let x = u128::from(bits) * self.columns.len() as u128;
        let k = (x >> 64) as usize;
        let picked = self.format.side(k, self.columns[k], x as u64);
        self.get(picked)
    }

    /// The column and the side fraction for one `u64` of random bits (the
    /// high and low parts of `bits · n`), as [`piece`](Self::piece) splits
    /// them.
    #[inline]
    pub(crate) fn split(&self, bits: u64) -> (usize, u64) {
        let x = u128::from(bits) * self.columns.len() as u128;
        ((x >> 64) as usize, x as u64)
    }

    /// The column a draw takes in column `k` for the fraction `frac`: `k`
    /// or its alias (reads column `k`).
    #[inline]
    pub(crate) fn side(&self, k: usize, frac: u64) -> usize {
        self.format.side(k, self.columns[k], frac)
    }

    /// Asks for column `k`'s cache line ahead of its use (a hint: no read).
    #[inline(always)]
    pub(crate) fn prefetch(&self, k: usize) {
        crate::prefetch::prefetch(&self.columns, k);
    }

    /// Fills `out` with pieces, one `u64` of `rng` each, in blocks whose
    /// memory accesses are issued a stage at a time so that the misses of
    /// a block overlap: the columns from the random numbers; the columns'
    /// loads alone, a loop of independent loads; the sides, a loop without
    /// loads; the picked columns' loads alone (a miss only for draws that
    /// take the alias side); then the records, read from lines now cached.
    #[inline]
    pub(crate) fn fill<R: Rng + ?Sized>(&self, rng: &mut R, out: &mut [Piece]) {
        const B: usize = crate::parallel::BLOCK;
        let n = self.columns.len() as u128;
        let format = self.format;
        let (mut index, mut frac) = ([0usize; B], [0u64; B]);
        let mut loaded = [Column::default(); B];
        for block in out.chunks_mut(B) {
            let len = block.len();
            for (i, f) in index[..len].iter_mut().zip(&mut frac[..len]) {
                let x = u128::from(rng.next_u64()) * n;
                (*i, *f) = ((x >> 64) as usize, x as u64);
            }
            for (c, &i) in loaded[..len].iter_mut().zip(&index[..len]) {
                *c = self.columns[i];
            }
            // The sides first, in a loop without loads, so that the loads
            // of the next loop are issued back to back (a loop mixing the
            // two keeps few of them in flight).
            for k in 0..len {
                index[k] = format.side(index[k], loaded[k], frac[k]);
            }
            for (c, &i) in loaded[..len].iter_mut().zip(&index[..len]) {
                *c = self.columns[i];
            }
            for (slot, &c) in block.iter_mut().zip(&loaded[..len]) {
                *slot = format.own(c);
            }
        }
    }
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

    /// The probability of each piece, read off the columns exactly.
    fn realised(table: &PieceAlias, n: usize) -> Vec<f64> {
        let mut p = vec![0.0; n];
        let width = 1.0 / table.columns.len() as f64;
        let f = table.format;
        let scale = 2f64.powi(f.threshold as i32);
        for (k, &c) in table.columns.iter().enumerate() {
            let below = f.threshold(c) as f64 / scale;
            p[table.get(k).face as usize] += width * below;
            p[table.get(f.alias(c)).face as usize] += width * (1.0 - below);
        }
        p
    }

    #[test]
    fn columns_realise_the_masses_and_skip_zeros() {
        let masses = [3.0, 0.0, 1.0, 6.0, 1e-300, 0.5, 0.0, f64::INFINITY];
        let pieces: Vec<Piece> = (0..masses.len() as u32).map(piece).collect();
        let table = PieceAlias::new(&pieces, &masses, masses.len()).unwrap();
        let total: f64 = masses.iter().filter(|m| m.is_finite()).sum();
        let p = realised(&table, masses.len());
        for (k, (&m, &q)) in masses.iter().zip(&p).enumerate() {
            let want = if m.is_finite() { m / total } else { 0.0 };
            // Thresholds keep `format.threshold` bits of a column.
            assert!((q - want).abs() < 1e-7, "piece {k}: {q} for {want}");
        }
        assert_eq!(p[1], 0.0);
        assert_eq!(p[6], 0.0);
        assert_eq!(p[7], 0.0);
        // Sampling by bits: the extreme variates stay in range.
        for bits in [0, 1, u64::MAX / 2, u64::MAX - 1, u64::MAX] {
            let f = table.piece(bits).face;
            assert!(masses[f as usize] > 0.0 && masses[f as usize].is_finite());
        }
        assert!(PieceAlias::new(&pieces[..2], &[0.0, f64::NAN], 2).is_none());
    }

    #[test]
    fn a_column_is_sixteen_bytes_and_round_trips_its_record() {
        assert_eq!(size_of::<Column>(), 16);
        assert_eq!(align_of::<Column>(), 16);
        // Every level, both orientations, corner codes, and the largest
        // face and value a format of these widths holds.
        let mut pieces = Vec::new();
        for level in 0..=11u8 {
            let top = (1u32 << level) - 1;
            pieces.push(Piece {
                face: 70_000,
                part: SubTriangle::new(level, top, 0, false),
                value: f32::MAX,
            });
            pieces.push(Piece {
                face: 3,
                part: SubTriangle::new(level, 0, top.saturating_sub(1), level > 0),
                value: 1e-30,
            });
        }
        let masses = vec![1.0; pieces.len()];
        let table = PieceAlias::new(&pieces, &masses, 70_001).unwrap();
        assert!(table.format.threshold >= MIN_THRESHOLD_BITS);
        for (k, p) in pieces.iter().enumerate() {
            assert_eq!(table.get(k), *p, "piece {k}");
        }
        let corners: Vec<Piece> = (0..3)
            .map(|c| Piece {
                face: 9,
                part: SubTriangle::vertex(c),
                value: 0.5,
            })
            .collect();
        let table = PieceAlias::new(&corners, &[1.0; 3], 10).unwrap();
        for (k, p) in corners.iter().enumerate() {
            assert_eq!(table.get(k), *p);
        }
    }

    #[test]
    fn a_format_without_room_for_the_threshold_is_refused() {
        // 2³² faces, level 13 and 2²⁰ pieces leave 128 − 32 − 31 − 32 − 20
        // bits for the threshold; 2²⁰ faces leave 25.
        assert!(Format::fit(13, 1 << 32, 1 << 20).is_none());
        assert_eq!(
            Format::fit(13, 1 << 20, 1 << 20).map(|f| f.threshold),
            Some(25)
        );
    }
}
