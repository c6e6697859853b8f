//! A uniform grid hashed into buckets: what finds the samples ([`crate::Painter`])
//! or the faces ([`crate::session`]) near a brush. Cells of side `cell`
//! are hashed into `2^k` buckets, each bucket's items listed in increasing
//! order in one array (compressed rows), so building it is two passes with
//! no per-cell allocation.

use glam::Vec3;

use crate::parallel::map_ordered;

/// Items spanning more cells than this are kept apart and visited by
/// every query (a face as large as the mesh would otherwise fill
/// thousands of cells).
const MAX_CELLS_PER_ITEM: u64 = 64;

#[derive(Debug, Clone)]
pub(crate) struct Grid {
    cell: f32,
    /// `start[b] .. start[b + 1]` are bucket `b`'s entries in `items`.
    start: Vec<u32>,
    items: Vec<u32>,
    /// Items over more than [`MAX_CELLS_PER_ITEM`] cells.
    large: Vec<u32>,
}

impl Grid {
    /// Item `i` at point `points[i]` (finite), in cells of `cell`.
    pub(crate) fn of_points(points: &[Vec3], cell: f32) -> Self {
        let buckets = (points.len() / 2).max(1).next_power_of_two();
        // The hashing on all threads for a whole mesh; the counting sort
        // after it stays in order, so the buckets list items in
        // increasing order at any thread count.
        let bucket: Vec<u32> = map_ordered(points, points.len(), |&p| {
            bucket_of(cell_of(p, cell), buckets)
        });
        let (start, items) = counting_sort(buckets, bucket.iter().copied().zip(0..));
        Self {
            cell,
            start,
            items,
            large: Vec::new(),
        }
    }

    /// Item `i` over the box `boxes[i]` (finite corners, `lo ≤ hi`): listed
    /// in the bucket of every cell the box overlaps.
    pub(crate) fn of_boxes(boxes: &[(Vec3, Vec3)], cell: f32) -> Self {
        let buckets = boxes.len().max(1).next_power_of_two();
        let mut large = Vec::new();
        let mut entries = Vec::with_capacity(boxes.len() * 2);
        for (i, &(lo, hi)) in (0u32..).zip(boxes) {
            let (lo, hi) = (cell_of(lo, cell), cell_of(hi, cell));
            if cells_between(lo, hi) > MAX_CELLS_PER_ITEM {
                large.push(i);
                continue;
            }
            let mut seen = [u32::MAX; MAX_CELLS_PER_ITEM as usize];
            let mut n = 0;
            for_each_cell(lo, hi, |c| {
                let b = bucket_of(c, buckets);
                // Cells of one box that share a bucket list it once.
                if !seen[..n].contains(&b) {
                    seen[n] = b;
                    n += 1;
                    entries.push((b, i));
                }
            });
        }
        let (start, items) = counting_sort(buckets, entries.into_iter());
        Self {
            cell,
            start,
            items,
            large,
        }
    }

    /// Calls `f` with each list of items that may lie within `radius` of
    /// `center`. An item can come in more than one list when it spans
    /// cells (boxes).
    pub(crate) fn for_each_list_near(&self, center: Vec3, radius: f32, mut f: impl FnMut(&[u32])) {
        let lo = cell_of(center - Vec3::splat(radius), self.cell);
        let hi = cell_of(center + Vec3::splat(radius), self.cell);
        f(&self.large);
        let buckets = self.start.len() - 1;
        if cells_between(lo, hi) > buckets as u64 {
            // A brush larger than the grid: every item.
            f(&self.items);
            return;
        }
        // Each bucket once: cells that share a bucket would otherwise
        // report its items twice.
        let mut list = Vec::new();
        for_each_cell(lo, hi, |c| list.push(bucket_of(c, buckets)));
        list.sort_unstable();
        list.dedup();
        for b in list {
            let b = b as usize;
            f(&self.items[self.start[b] as usize..self.start[b + 1] as usize]);
        }
    }
}

/// `(bucket, item)` pairs into compressed rows, items in the order given.
fn counting_sort(
    buckets: usize,
    entries: impl Iterator<Item = (u32, u32)> + Clone,
) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; buckets + 1];
    for (b, _) in entries.clone() {
        start[b as usize + 1] += 1;
    }
    for b in 0..buckets {
        start[b + 1] += start[b];
    }
    let mut fill = start.clone();
    let mut items = vec![0u32; start[buckets] as usize];
    for (b, i) in entries {
        items[fill[b as usize] as usize] = i;
        fill[b as usize] += 1;
    }
    (start, items)
}

/// How many cells the box of cells `lo..=hi` holds (saturating).
fn cells_between(lo: [i32; 3], hi: [i32; 3]) -> u64 {
    (0..3).fold(1u64, |s, k| {
        s.saturating_mul((i64::from(hi[k]) - i64::from(lo[k]) + 1).max(0) as u64)
    })
}

fn for_each_cell(lo: [i32; 3], hi: [i32; 3], mut f: impl FnMut([i32; 3])) {
    for x in lo[0]..=hi[0] {
        for y in lo[1]..=hi[1] {
            for z in lo[2]..=hi[2] {
                f([x, y, z]);
            }
        }
    }
}

/// The bucket of grid cell `c` among `buckets` (a power of two).
#[inline]
fn bucket_of(c: [i32; 3], buckets: usize) -> u32 {
    let h = (c[0] as u32).wrapping_mul(73_856_093)
        ^ (c[1] as u32).wrapping_mul(19_349_663)
        ^ (c[2] as u32).wrapping_mul(83_492_791);
    // Mix the high bits down: the primes leave the low bits weak.
    let h = h ^ (h >> 15);
    h.wrapping_mul(0x2c1b_3c6d) & (buckets as u32 - 1)
}

fn cell_of(p: Vec3, cell: f32) -> [i32; 3] {
    (p / cell).to_array().map(floor_clamped)
}

/// `x.floor().clamp(-1e9, 1e9) as i32` without a call to `floorf`
/// (x86-64's baseline has no rounding instruction; the grid hashes every
/// sample of a mesh): ±10⁹ are integers in `f32`, so clamping first gives
/// the same, and within them the truncation is exact and one below it
/// when it rounded a negative number up. NaN gives 0, as the cast of a
/// NaN floor does.
#[inline]
fn floor_clamped(x: f32) -> i32 {
    let x = x.clamp(-1e9, 1e9);
    let t = x as i32;
    if (t as f32) > x { t - 1 } else { t }
}

#[cfg(test)]
mod tests {
    use super::floor_clamped;

    #[test]
    fn the_fast_floor_is_the_floor_it_replaces() {
        let reference = |x: f32| x.floor().clamp(-1e9, 1e9) as i32;
        let mut xs = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            -1.5,
            2.999_999_8,
            -2.999_999_8,
            8_388_607.5,
            -8_388_607.5,
            16_777_217.0,
            -16_777_217.0,
            1e9,
            -1e9,
            1.000_000_1e9,
            -1.000_000_1e9,
            3e38,
            -3e38,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        // Every 2^-20th of the range of bit patterns, and their neighbours.
        for k in 0..(1u32 << 12) {
            let bits = k << 20;
            for b in [bits, bits.wrapping_add(1), bits.wrapping_sub(1)] {
                xs.push(f32::from_bits(b));
            }
        }
        for x in xs {
            assert_eq!(floor_clamped(x), reference(x), "{x:e}");
        }
    }
}
