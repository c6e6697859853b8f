//! How the density sampler stores its pieces for drawing: an alias table
//! with the piece records inside its columns (one cache miss per draw), or
//! the inversion method's CDF with a lookup table (order-preserving).

use rand::Rng;

use crate::subdivision::SubTriangle;

/// How a [`DensitySampler`](crate::DensitySampler) draws a piece (a
/// sub-triangle of a face, or a component of a per-vertex density).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// Walker's alias method (built by Vose's algorithm) whose columns
    /// hold the records of the two pieces they can return: 32 bytes per
    /// piece, and a draw reads one column, so it costs one cache miss
    /// however many pieces there are. The fastest; a variate's neighbours
    /// do not map to neighbouring points.
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

/// One entry of the discrete distribution: a sub-triangle (or linear
/// component) of a face, with its density value (exact mode: its bound).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Piece {
    pub(crate) face: u32,
    pub(crate) part: SubTriangle,
    pub(crate) value: f32,
}

/// A column: below `threshold · 2⁻⁶⁴` of its width it returns `own`,
/// above it `alias`. 32 bytes, so a column never straddles two cache
/// lines once the vector is 32-byte aligned (it is 8-byte aligned, so at
/// worst one column in two lines' worth touches both: still one miss in
/// the common case).
#[derive(Debug, Clone, Copy, Default)]
struct Column {
    threshold: u64,
    own: Piece,
    alias: Piece,
}

/// The alias table over pieces with the records inlined.
#[derive(Debug, Clone, Default)]
pub(crate) struct PieceAlias {
    columns: Vec<Column>,
}

impl PieceAlias {
    /// The table drawing `pieces[i]` with probability `masses[i] / Σ`.
    /// Entries of zero mass are left out (never drawn). `None` when no
    /// mass is positive and finite.
    pub(crate) fn new(pieces: &[Piece], masses: &[f64]) -> Option<Self> {
        let kept: Vec<usize> = (0..pieces.len())
            .filter(|&i| masses[i] > 0.0 && masses[i].is_finite())
            .collect();
        let n = kept.len();
        let total: f64 = kept.iter().map(|&i| masses[i]).sum();
        if n == 0 || !(total > 0.0 && total.is_finite()) {
            return None;
        }
        // Vose: scaled probabilities n·p_i, columns filled from a small
        // entry topped up by a large one.
        let mut scaled: Vec<f64> = kept.iter().map(|&i| masses[i] / total * n as f64).collect();
        let mut columns: Vec<Column> = kept
            .iter()
            .map(|&i| Column {
                threshold: u64::MAX,
                own: pieces[i],
                alias: pieces[i],
            })
            .collect();
        let (mut small, mut large): (Vec<u32>, Vec<u32>) =
            (0..n as u32).partition(|&k| scaled[k as usize] < 1.0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            let (s, l) = (s as usize, l as usize);
            columns[s].threshold = to_threshold(scaled[s]);
            columns[s].alias = columns[l].own;
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l as u32);
            }
        }
        // What is left is 1 up to rounding: full columns (threshold MAX,
        // alias = own).
        Some(Self { columns })
    }

    pub(crate) fn memory_bytes(&self) -> usize {
        self.columns.len() * size_of::<Column>()
    }

    /// The piece for one `u64` of random bits: the column from the high
    /// part of `bits · n`, the side from the low part.
    #[inline]
    pub(crate) fn piece(&self, bits: u64) -> Piece {
        let x = u128::from(bits) * self.columns.len() as u128;
        let column = &self.columns[(x >> 64) as usize];
        column.side(x as u64 >= column.threshold)
    }

    /// Fills `out` with pieces, one `u64` of `rng` each. Three passes per
    /// block: the columns and positions from the random numbers; then the
    /// columns' thresholds alone, a loop of independent loads with nothing
    /// between them, so that as many cache misses as the core allows are
    /// in flight at once (and the lines are in L1 afterwards); then the
    /// choice of side, reading the records from lines now cached.
    #[inline]
    pub(crate) fn fill<R: Rng + ?Sized>(&self, rng: &mut R, out: &mut [Piece]) {
        const B: usize = crate::parallel::BLOCK;
        let n = self.columns.len() as u128;
        let (mut index, mut frac, mut threshold) = ([0usize; B], [0u64; B], [0u64; B]);
        for block in out.chunks_mut(B) {
            let len = block.len();
            for (i, f) in index[..len].iter_mut().zip(&mut frac[..len]) {
                let x = u128::from(rng.next_u64()) * n;
                (*i, *f) = ((x >> 64) as usize, x as u64);
            }
            for (t, &i) in threshold[..len].iter_mut().zip(&index[..len]) {
                *t = self.columns[i].threshold;
            }
            for (k, slot) in block.iter_mut().enumerate() {
                let c = &self.columns[index[k]];
                *slot = c.side(frac[k] >= threshold[k]);
            }
        }
    }
}

impl Column {
    /// `own` below the threshold, `alias` above, without a branch: which
    /// side is a coin flip the predictor cannot learn.
    #[inline]
    fn side(&self, alias: bool) -> Piece {
        let mask = 0u32.wrapping_sub(u32::from(alias));
        let pick = |own: u32, alias: u32| own ^ ((own ^ alias) & mask);
        let (own, alias) = (self.own, self.alias);
        Piece {
            face: pick(own.face, alias.face),
            part: SubTriangle::from_bits(pick(own.part.bits(), alias.part.bits())),
            value: f32::from_bits(pick(own.value.to_bits(), alias.value.to_bits())),
        }
    }
}

/// `p · 2⁶⁴` for `p ∈ [0, 1)`, saturating at 1.
fn to_threshold(p: f64) -> u64 {
    // 2⁶⁴ as f64 is exact; the cast saturates for p ≥ 1.
    (p.max(0.0) * 18_446_744_073_709_551_616.0) as u64
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
        for c in &table.columns {
            let below = c.threshold as f64 / 18_446_744_073_709_551_616.0;
            p[c.own.face as usize] += width * below;
            p[c.alias.face as usize] += width * (1.0 - below);
        }
        p
    }

    #[test]
    fn columns_realise_the_masses_and_skip_zeros() {
        let masses = [3.0, 0.0, 1.0, 6.0, 1e-300, 0.5, 0.0];
        let pieces: Vec<Piece> = (0..masses.len() as u32).map(piece).collect();
        let table = PieceAlias::new(&pieces, &masses).unwrap();
        let total: f64 = masses.iter().sum();
        let p = realised(&table, masses.len());
        for (k, (&m, &q)) in masses.iter().zip(&p).enumerate() {
            assert!(
                (q - m / total).abs() < 1e-12,
                "piece {k}: {q} for {}",
                m / total
            );
        }
        assert_eq!(p[1], 0.0);
        assert_eq!(p[6], 0.0);
        // Sampling by bits: the extreme variates stay in range.
        for bits in [0, 1, u64::MAX / 2, u64::MAX - 1, u64::MAX] {
            let f = table.piece(bits).face;
            assert!(masses[f as usize] > 0.0);
        }
        assert!(PieceAlias::new(&pieces[..2], &[0.0, f64::NAN]).is_none());
    }
}
