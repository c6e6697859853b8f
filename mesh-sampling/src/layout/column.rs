//! The bit formats of an alias column: which fields its 16 bytes hold and
//! how wide each is, fitted to the mesh and its pieces.
//!
//! Two formats exist. [`Inline`] holds both sides of the column (the
//! piece's record and its alias's record) and the threshold, so that a
//! draw reads one column; to make room it stores each value with the
//! mantissa bits the table's range of values leaves (rounded before the
//! masses are computed, so the table samples exactly the values it
//! reports). [`Linked`] holds the piece's record with its `f32` value, the
//! threshold and the index of the alias's column, which a draw taking the
//! alias side reads too: the fallback when the faces and the depth leave
//! too few bits for two records.

use super::{MIN_THRESHOLD_BITS, Piece};
use crate::subdivision::SubTriangle;

/// A packed column. Sixteen bytes, 16-byte aligned, so a column never
/// straddles two cache lines.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Column(pub(super) u128);

/// The most low mantissa bits an alias column holding both of its sides
/// may drop from a piece's value ([`Layout::Alias`](crate::Layout::Alias)):
/// 11, so a normal `f32` value keeps 12 of its 23 and moves by at most a
/// relative `2⁻¹³` (rounded to nearest; upward for exact mode's bounds).
/// Where the values' range needs more, a column holds its alias's index
/// instead, and the values are exact.
pub const MAX_VALUE_SHIFT: u32 = 11;

/// Bits needed for the values `0..n` (0 for `n ≤ 1`).
fn bits_for(n: usize) -> u32 {
    usize::BITS - n.saturating_sub(1).leading_zeros()
}

/// The `width` low bits set (`width ≤ 64`).
#[inline]
pub(super) fn low_mask(width: u32) -> u64 {
    u64::MAX.checked_shr(64 - width).unwrap_or(0)
}

/// The `width` bits of `c` from bit `shift` (`width ≤ 64`).
#[inline]
fn field(c: Column, shift: u32, width: u32) -> u64 {
    (c.0 >> shift) as u64 & low_mask(width)
}

/// The threshold width left by `used` bits of fields: at most 64 (a `u64`
/// of the variate), `None` below [`MIN_THRESHOLD_BITS`].
fn threshold_bits(used: u32) -> Option<u32> {
    let threshold = 128u32.checked_sub(used)?.min(64);
    (threshold >= MIN_THRESHOLD_BITS).then_some(threshold)
}

/// The sub-triangle code: `1` followed by the level's `2·level` bits of
/// position (so its highest set bit gives the level), `2·deepest + 1` bits
/// in all; or, for a per-vertex density's components, the corner (2 bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct PartCode {
    deepest: u32,
    vertex: bool,
}

impl PartCode {
    /// The code for `pieces`: `None` when sub-triangles and vertex
    /// components are mixed (no density makes both).
    fn fit(pieces: &[Piece]) -> Option<Self> {
        let corners = pieces.iter().filter(|p| p.part.corner().is_some()).count();
        if corners != 0 && corners != pieces.len() {
            return None;
        }
        let deepest = pieces.iter().map(|p| p.part.level()).max().unwrap_or(0);
        Some(Self {
            deepest: u32::from(deepest),
            vertex: corners != 0,
        })
    }

    fn width(self) -> u32 {
        if self.vertex { 2 } else { 2 * self.deepest + 1 }
    }

    /// The up and down triangles of a level-`l` grid (`n = 2^l` a side)
    /// fill an `n × n` square: up `(i, j)` (`i + j < n`) stays, down
    /// `(i, j)` (`i + j ≤ n − 2`) goes to `(n−1−i, n−1−j)`, the cells with
    /// `i + j ≥ n`.
    fn pack(self, part: SubTriangle) -> u64 {
        if let Some(corner) = part.corner() {
            return corner as u64;
        }
        let l = u32::from(part.level());
        let n = 1u32 << l;
        let (i, j, down) = part.grid();
        let (x, y) = if down { (n - 1 - i, n - 1 - j) } else { (i, j) };
        1u64 << (2 * l) | u64::from(x) << l | u64::from(y)
    }

    #[inline]
    fn unpack(self, code: u64) -> SubTriangle {
        if self.vertex {
            return SubTriangle::vertex((code & 3) as usize);
        }
        let l = (63 - (code | 1).leading_zeros()) / 2;
        let mask = (1u32 << l) - 1;
        let (x, y) = ((code >> l) as u32 & mask, code as u32 & mask);
        // Without a branch: the orientation of a drawn piece is a coin
        // flip no predictor learns. `n − 1 − x` is `x ^ (n − 1)`.
        let down = x + y > mask;
        let flip = mask * u32::from(down);
        SubTriangle::new(l as u8, x ^ flip, y ^ flip, down)
    }
}

/// A value kept as `bits` bits: `(value.to_bits() >> shift) − base`. The
/// values are positive and finite, rounded to a multiple of `2^shift` in
/// their bit pattern (their mantissa's low `shift` bits cleared): to
/// nearest, or upward when they are bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct ValueCode {
    bits: u32,
    shift: u32,
    base: u32,
    upward: bool,
}

/// The bit pattern of `f32::INFINITY`: finite positive values are below.
const INFINITY_BITS: u32 = 0x7f80_0000;

impl ValueCode {
    /// The fewest dropped bits for which the rounded values of `pieces`
    /// span at most `2^available` codes, up to [`MAX_VALUE_SHIFT`]; `None`
    /// when a value is zero, negative or not finite, or the range needs
    /// more.
    fn fit(pieces: &[Piece], available: u32, upward: bool) -> Option<Self> {
        let valid = |b: u32| b != 0 && b < INFINITY_BITS;
        let (mut lo, mut hi) = (u32::MAX, 0u32);
        for p in pieces {
            let b = p.value.to_bits();
            if !valid(b) {
                return None;
            }
            (lo, hi) = (lo.min(b), hi.max(b));
        }
        (0..=MAX_VALUE_SHIFT).find_map(|shift| {
            let code = Self {
                bits: 0,
                shift,
                base: 0,
                upward,
            };
            let (lo, hi) = (code.round_bits(lo)?, code.round_bits(hi)?);
            let bits = bits_for(((hi >> shift) - (lo >> shift)) as usize + 1);
            (bits <= available).then_some(Self {
                bits,
                base: lo >> shift,
                ..code
            })
        })
    }

    /// `b` rounded to a multiple of `2^shift`, or `None` when that is zero
    /// or not finite.
    fn round_bits(self, b: u32) -> Option<u32> {
        let unit = 1u32 << self.shift;
        let bias = if self.upward { unit - 1 } else { unit / 2 };
        let r = b.checked_add(bias)? & !(unit - 1);
        (r != 0 && r < INFINITY_BITS).then_some(r)
    }

    /// `v` as this code stores it (a value `fit` saw).
    pub(super) fn round(self, v: f32) -> f32 {
        self.round_bits(v.to_bits()).map_or(v, f32::from_bits)
    }

    fn pack(self, v: f32) -> u64 {
        u64::from((v.to_bits() >> self.shift).wrapping_sub(self.base))
    }

    #[inline]
    fn unpack(self, code: u64) -> f32 {
        f32::from_bits(((code as u32).wrapping_add(self.base)) << self.shift)
    }
}

/// Both sides of a column inline, from the least significant bit: the
/// piece's record (value, part, face), the alias's record, and the
/// threshold in the top `threshold` bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Inline {
    part: PartCode,
    face: u32,
    pub(super) value: ValueCode,
    pub(super) threshold: u32,
}

impl Inline {
    fn fit(part: PartCode, face: u32, pieces: &[Piece], upward: bool) -> Option<Self> {
        let fixed = part.width() + face;
        let available = (128 - MIN_THRESHOLD_BITS).checked_sub(2 * fixed)? / 2;
        let value = ValueCode::fit(pieces, available.min(31), upward)?;
        let threshold = threshold_bits(2 * (fixed + value.bits))?;
        Some(Self {
            part,
            face,
            value,
            threshold,
        })
    }

    fn record_bits(self) -> u32 {
        self.value.bits + self.part.width() + self.face
    }

    fn pack_record(self, p: Piece) -> u128 {
        let v = self.value.bits;
        u128::from(self.value.pack(p.value))
            | u128::from(self.part.pack(p.part)) << v
            | u128::from(p.face) << (v + self.part.width())
    }

    pub(super) fn pack(self, own: Piece, alias: Piece, threshold: u64) -> Column {
        Column(
            self.pack_record(own)
                | self.pack_record(alias) << self.record_bits()
                | u128::from(threshold) << (128 - self.threshold),
        )
    }

    /// The record of side 0 (the piece) or 1 (its alias).
    #[inline]
    pub(super) fn record(self, c: Column, side: u32) -> Piece {
        let r = self.record_bits();
        self.unpack_record((c.0 >> (side * r)) as u64 & low_mask(r))
    }

    /// A record's fields from its `record_bits` (at most 52) bits.
    #[inline]
    fn unpack_record(self, bits: u64) -> Piece {
        let (v, p) = (self.value.bits, self.part.width());
        Piece {
            value: self.value.unpack(bits & low_mask(v)),
            part: self.part.unpack((bits >> v) & low_mask(p)),
            face: ((bits >> (v + p)) & low_mask(self.face)) as u32,
        }
    }

    #[inline]
    pub(super) fn threshold(self, c: Column) -> u64 {
        (c.0 >> (128 - self.threshold)) as u64
    }

    /// The record the fraction `frac` (the low half of `bits · n`) picks:
    /// the piece's below the threshold, the alias's above.
    #[inline]
    pub(super) fn pick(self, c: Column, frac: u64) -> Piece {
        let above = frac >> (64 - self.threshold) >= self.threshold(c);
        // Both records by the table's fixed shifts, then a select by mask:
        // a shift by a per-draw amount, or a branch, would be a coin flip
        // the predictor cannot learn.
        let r = self.record_bits();
        let own = c.0 as u64 & low_mask(r);
        let alias = (c.0 >> r) as u64 & low_mask(r);
        let take = 0u64.wrapping_sub(u64::from(above));
        self.unpack_record(own ^ ((own ^ alias) & take))
    }
}

/// One record and a link, from the least significant bit: the value (32,
/// an `f32`), the part, the face, the alias's column, and the threshold in
/// the top `threshold` bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Linked {
    part: PartCode,
    face: u32,
    alias: u32,
    pub(super) threshold: u32,
}

impl Linked {
    fn fit(part: PartCode, face: u32, pieces: usize) -> Option<Self> {
        let alias = bits_for(pieces);
        let threshold = threshold_bits(32 + part.width() + face + alias)?;
        Some(Self {
            part,
            face,
            alias,
            threshold,
        })
    }

    pub(super) fn pack(self, piece: Piece, alias: usize, threshold: u64) -> Column {
        let p = self.part.width();
        Column(
            u128::from(piece.value.to_bits())
                | u128::from(self.part.pack(piece.part)) << 32
                | u128::from(piece.face) << (32 + p)
                | (alias as u128) << (32 + p + self.face)
                | u128::from(threshold) << (128 - self.threshold),
        )
    }

    /// The piece a column holds (its own side).
    #[inline]
    pub(super) fn own(self, c: Column) -> Piece {
        let p = self.part.width();
        Piece {
            value: f32::from_bits(c.0 as u32),
            part: self.part.unpack(field(c, 32, p)),
            face: field(c, 32 + p, self.face) as u32,
        }
    }

    #[inline]
    pub(super) fn alias(self, c: Column) -> usize {
        field(c, 32 + self.part.width() + self.face, self.alias) as usize
    }

    #[inline]
    pub(super) fn threshold(self, c: Column) -> u64 {
        (c.0 >> (128 - self.threshold)) as u64
    }

    /// The column whose record the fraction `frac` picks in column `k`:
    /// `k` itself below the threshold, its alias above.
    #[inline]
    pub(super) fn side(self, k: usize, c: Column, frac: u64) -> usize {
        if frac >> (64 - self.threshold) >= self.threshold(c) {
            self.alias(c)
        } else {
            k
        }
    }
}

/// The layout of a table's columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Format {
    /// Both sides' records in the column: one read a draw.
    Inline(Inline),
    /// The piece's record and its alias's index: two reads when the alias
    /// side is taken.
    Linked(Linked),
}

#[cfg(test)]
thread_local! {
    /// Tests set this to build [`Linked`] tables where [`Inline`] fits.
    pub(crate) static FORCE_LINKED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

impl Format {
    /// The format for `pieces` over `faces` faces: [`Inline`] when two
    /// records fit with at most [`MAX_VALUE_SHIFT`] bits dropped from the
    /// values, else [`Linked`], else `None` (fewer than
    /// [`MIN_THRESHOLD_BITS`] left for the threshold, or vertex components
    /// mixed with sub-triangles). `bounds`: the values are upper bounds
    /// (exact mode), so they round upward.
    pub(crate) fn fit(pieces: &[Piece], faces: usize, bounds: bool) -> Option<Self> {
        let part = PartCode::fit(pieces)?;
        let face = bits_for(faces);
        #[cfg(test)]
        if FORCE_LINKED.with(|f| f.get()) {
            return Linked::fit(part, face, pieces.len()).map(Self::Linked);
        }
        Inline::fit(part, face, pieces, bounds)
            .map(Self::Inline)
            .or_else(|| Linked::fit(part, face, pieces.len()).map(Self::Linked))
    }

    /// Rounds the pieces' values to what the columns store (a no-op for
    /// [`Linked`], which stores them exactly): call before computing the
    /// masses, so that the table draws the values it reports.
    pub(crate) fn round_values(self, pieces: &mut [Piece]) {
        if let Self::Inline(f) = self {
            for p in pieces {
                p.value = f.value.round(p.value);
            }
        }
    }

    /// Bits of the threshold.
    pub(super) fn threshold_bits(self) -> u32 {
        match self {
            Self::Inline(f) => f.threshold,
            Self::Linked(f) => f.threshold,
        }
    }

    /// The largest relative change [`round_values`](Self::round_values)
    /// makes to a normal `f32` value: `2^(shift − 24)` to nearest,
    /// `2^(shift − 23)` upward, 0 when no bit is dropped.
    pub(crate) fn value_tolerance(self) -> f64 {
        match self {
            Self::Inline(f) if f.value.shift > 0 => {
                let half = if f.value.upward { 0 } else { 1 };
                2f64.powi(f.value.shift as i32 - 23 - half)
            }
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn piece(face: u32, part: SubTriangle, value: f32) -> Piece {
        Piece { face, part, value }
    }

    #[test]
    fn the_part_code_names_every_sub_triangle_of_every_level_once() {
        for deepest in 0..=6u8 {
            let code = PartCode {
                deepest: u32::from(deepest),
                vertex: false,
            };
            let mut seen = std::collections::HashSet::new();
            for level in 0..=deepest {
                let n = 1u32 << level;
                for i in 0..n {
                    for j in 0..n - i {
                        for down in [false, true] {
                            if down && i + j + 1 >= n {
                                continue;
                            }
                            let s = SubTriangle::new(level, i, j, down);
                            let c = code.pack(s);
                            assert!(c < 1 << code.width(), "{s:?}: {c} too wide");
                            assert_eq!(code.unpack(c), s);
                            assert!(seen.insert(c), "{s:?}: code {c} twice");
                        }
                    }
                }
            }
            // 4^l sub-triangles at each level, no more.
            let all: usize = (0..=deepest).map(|l| 1usize << (2 * l)).sum();
            assert_eq!(seen.len(), all);
        }
        let deep = PartCode {
            deepest: 13,
            vertex: false,
        };
        let top = (1u32 << 13) - 1;
        for s in [
            SubTriangle::new(13, top, 0, false),
            SubTriangle::new(13, 0, top - 1, true),
        ] {
            assert_eq!(deep.unpack(deep.pack(s)), s);
        }
        let vertex = PartCode::fit(&[piece(0, SubTriangle::vertex(2), 1.0)]).unwrap();
        assert_eq!(
            vertex.unpack(vertex.pack(SubTriangle::vertex(2))),
            SubTriangle::vertex(2)
        );
        // Mixed corners and sub-triangles have no code.
        let mixed = [
            piece(0, SubTriangle::vertex(1), 1.0),
            piece(0, SubTriangle::ROOT, 1.0),
        ];
        assert!(PartCode::fit(&mixed).is_none());
    }

    #[test]
    fn values_keep_every_bit_the_range_allows_and_round_within_the_tolerance() {
        let values: Vec<Piece> = [0.3f32, 0.9, 1.0 / 7.0, 2.5e-3, 0.75]
            .iter()
            .map(|&v| piece(0, SubTriangle::ROOT, v))
            .collect();
        // Room enough: no bit dropped, the values exact.
        let wide = ValueCode::fit(&values, 31, false).unwrap();
        assert_eq!(wide.shift, 0);
        for p in &values {
            assert_eq!(wide.unpack(wide.pack(p.value)), p.value);
        }
        // Little room: bits dropped, each value within 2^(shift − 24).
        for upward in [false, true] {
            let narrow = ValueCode::fit(&values, 20, upward).unwrap();
            assert!(narrow.shift > 0 && narrow.bits <= 20);
            for p in &values {
                let r = narrow.round(p.value);
                assert_eq!(narrow.unpack(narrow.pack(r)), r, "{} round trip", p.value);
                let rel = (f64::from(r) - f64::from(p.value)) / f64::from(p.value);
                let half = if upward { 0 } else { 1 };
                assert!(rel.abs() <= 2f64.powi(narrow.shift as i32 - 23 - half));
                if upward {
                    assert!(r >= p.value, "a bound rounds up");
                }
            }
        }
        // Equal values need no bits at all.
        let same = vec![piece(0, SubTriangle::ROOT, 0.5); 3];
        let code = ValueCode::fit(&same, 0, false).unwrap();
        assert_eq!((code.bits, code.shift), (0, 0));
        assert_eq!(code.unpack(0), 0.5);
        // A range wider than MAX_VALUE_SHIFT allows, a zero, a NaN: none.
        let huge = [
            piece(0, SubTriangle::ROOT, 1e-30),
            piece(0, SubTriangle::ROOT, 1e30),
        ];
        assert!(ValueCode::fit(&huge, 12, false).is_none());
        for bad in [0.0, f32::NAN, f32::INFINITY, -1.0] {
            assert!(ValueCode::fit(&[piece(0, SubTriangle::ROOT, bad)], 31, false).is_none());
        }
    }

    #[test]
    fn both_formats_round_trip_their_records_and_fall_back_in_order() {
        let mut pieces = Vec::new();
        for level in 0..=8u8 {
            let top = (1u32 << level) - 1;
            pieces.push(piece(70_000, SubTriangle::new(level, top, 0, false), 3.5));
            let down = SubTriangle::new(level, 0, top.saturating_sub(1), level > 0);
            pieces.push(piece(3, down, 1e-3));
        }
        let Some(Format::Inline(f)) = Format::fit(&pieces, 70_001, false) else {
            panic!("two records of 17 + 17 bits and a value fit");
        };
        for (a, b) in pieces.iter().zip(pieces.iter().rev()) {
            let (a, b) = (
                piece(a.face, a.part, f.value.round(a.value)),
                piece(b.face, b.part, f.value.round(b.value)),
            );
            let c = f.pack(a, b, 12345);
            assert_eq!(
                (f.record(c, 0), f.record(c, 1), f.threshold(c)),
                (a, b, 12345)
            );
        }
        let linked = Linked::fit(PartCode::fit(&pieces).unwrap(), 17, pieces.len()).unwrap();
        for p in &pieces {
            let c = linked.pack(*p, 7, 99);
            assert_eq!(
                (linked.own(c), linked.alias(c), linked.threshold(c)),
                (*p, 7, 99)
            );
        }
        // 2³⁰ faces at level 13 leave no room for two records: linked.
        let deep = vec![piece(0, SubTriangle::new(13, 0, 0, false), 1.0)];
        assert!(matches!(
            Format::fit(&deep, 1 << 30, false),
            Some(Format::Linked(_))
        ));
        // 2³² faces at level 13 and 2²⁰ pieces leave 128 − 32 − 27 − 32 −
        // 20 bits for the threshold: too few, no format.
        let part = PartCode::fit(&deep).unwrap();
        assert!(Linked::fit(part, 32, 1 << 20).is_none());
        assert_eq!(
            Linked::fit(part, 20, 1 << 20).map(|f| f.threshold),
            Some(29)
        );
    }
}
