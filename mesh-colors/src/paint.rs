//! 3D painting (Sec. 5.1): brush strokes on the samples themselves, with
//! no UV bookkeeping. A uniform grid over the samples' 3D positions finds
//! the samples near the brush, so a stroke costs the samples in the grid
//! cells it overlaps (a small multiple of the samples it touches when the
//! cell size is about the brush radius), not the size of the mesh.

use glam::Vec3;

use crate::parallel::map_ordered;
use crate::structure::MeshColors;
use crate::undo::Recorder;
use crate::{Error, MAX_CHANNELS};

/// How a brush combines its colour with a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blend {
    /// Replace the colour inside the radius (no falloff).
    Set,
    /// Move towards the brush colour by the falloff weight.
    Mix,
    /// Add the brush colour times the falloff weight (densities, masks).
    Add,
}

/// A brush dab: a sphere with a smooth falloff `w = strength · (1 −
/// (d/r)²)²`, which is 1 at the centre and reaches 0 with zero slope at
/// the rim, so strokes leave no visible edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Brush<'a> {
    /// The centre, in the mesh's space.
    pub center: Vec3,
    /// The radius; samples farther away are untouched.
    pub radius: f32,
    /// The colour, one value per channel.
    pub color: &'a [f32],
    /// Scales the falloff weight (1: full strength).
    pub strength: f32,
    /// How the colour is applied.
    pub blend: Blend,
}

impl Brush<'_> {
    /// The falloff weight at distance `d`.
    pub fn weight(&self, d: f32) -> f32 {
        let x = d / self.radius;
        if x > 1.0 {
            0.0
        } else {
            let s = 1.0 - x * x;
            self.strength * s * s
        }
    }
}

/// What a stroke did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Stroke {
    /// Samples within the radius (changed, unless the weight was zero).
    pub touched: usize,
    /// Samples whose distance was computed (the cost).
    pub examined: usize,
}

/// A spatial index of the sample positions of one [`MeshColors`] on one
/// set of vertex positions. Rebuild it after a topology edit, a resolution
/// change or a vertex move.
#[derive(Debug, Clone)]
pub struct Painter {
    positions: Vec<Vec3>,
    grid: Grid,
    channels: usize,
}

/// A spatial hash of sample positions: cells of side `cell`, hashed into
/// `2^k` buckets (about one per two samples), the samples of each bucket
/// listed in increasing order in one array (compressed rows). Building it
/// is two passes over the samples with no per-cell allocation, so a
/// resolution change that renumbers the samples can rebuild it cheaply.
#[derive(Debug, Clone)]
struct Grid {
    cell: f32,
    /// `start[b] .. start[b + 1]` are bucket `b`'s entries in `items`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Grid {
    fn new(positions: &[Vec3], cell: f32) -> Self {
        let buckets = (positions.len() / 2).max(1).next_power_of_two();
        // The hashing on all threads for a whole mesh; the counting sort
        // after it stays in order, so the buckets list samples in
        // increasing order at any thread count.
        let bucket: Vec<u32> = map_ordered(positions, positions.len(), |&p| {
            bucket_of(cell_of(p, cell), buckets)
        });
        let mut start = vec![0u32; buckets + 1];
        for &b in &bucket {
            start[b as usize + 1] += 1;
        }
        for b in 0..buckets {
            start[b + 1] += start[b];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; positions.len()];
        for (i, &b) in bucket.iter().enumerate() {
            items[fill[b as usize] as usize] = i as u32;
            fill[b as usize] += 1;
        }
        Self { cell, start, items }
    }

    fn buckets(&self) -> usize {
        self.start.len() - 1
    }

    fn bucket(&self, b: usize) -> &[u32] {
        &self.items[self.start[b] as usize..self.start[b + 1] as usize]
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

impl Painter {
    /// Indexes the samples of `colors` on a mesh with vertex `positions`,
    /// in grid cells of size `cell` (about the usual brush radius).
    ///
    /// # Errors
    /// [`Error::ChannelMismatch`] if `positions` is shorter than the vertex
    /// count, [`Error::NonFinite`] for a non-finite position or cell size.
    pub fn new(colors: &MeshColors, positions: &[Vec3], cell: f32) -> Result<Self, Error> {
        Self::with_sites(colors, positions, &colors.sites(), cell)
    }

    /// [`Painter::new`] with the colours' [`MeshColors::sites`] already
    /// computed (the paint session needs them for its normals too).
    pub(crate) fn with_sites(
        colors: &MeshColors,
        positions: &[Vec3],
        sites: &[crate::structure::Site],
        cell: f32,
    ) -> Result<Self, Error> {
        let t = colors.topology();
        if positions.len() < t.vertex_count() {
            return Err(Error::ChannelMismatch {
                what: "vertex positions",
                expected: t.vertex_count(),
                got: positions.len(),
            });
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::NonFinite {
                what: "position",
                index: i,
            });
        }
        if !(cell.is_finite() && cell > 0.0) {
            return Err(Error::NonFinite {
                what: "cell size",
                index: 0,
            });
        }
        let sample_positions: Vec<Vec3> = sites
            .iter()
            .enumerate()
            .map(|(i, s)| {
                s.position(t, positions)
                    .map_or_else(|| positions[i], |p| p.as_vec3())
            })
            .collect();
        Ok(Self::from_positions(
            sample_positions,
            cell,
            colors.channels(),
        ))
    }

    /// The index of samples at `positions` (finite), in cells of `cell`.
    pub(crate) fn from_positions(positions: Vec<Vec3>, cell: f32, channels: usize) -> Self {
        Self {
            grid: Grid::new(&positions, cell),
            positions,
            channels,
        }
    }

    /// Gives the sample positions back (to move them to a new numbering
    /// and index them again with [`Painter::from_positions`]).
    pub(crate) fn into_positions(self) -> Vec<Vec3> {
        self.positions
    }

    /// The grid's cell size.
    pub(crate) fn cell(&self) -> f32 {
        self.grid.cell
    }

    /// The 3D position of every sample.
    pub fn sample_positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Calls `f(sample, distance)` for every sample within `radius` of
    /// `center`; returns how many were examined.
    pub fn for_each_within(
        &self,
        center: Vec3,
        radius: f32,
        mut f: impl FnMut(usize, f32),
    ) -> usize {
        let grid = &self.grid;
        let lo = cell_of(center - Vec3::splat(radius), grid.cell);
        let hi = cell_of(center + Vec3::splat(radius), grid.cell);
        let span = (0..3).fold(1u64, |s, k| {
            s.saturating_mul((i64::from(hi[k]) - i64::from(lo[k]) + 1) as u64)
        });
        let mut examined = 0;
        let mut visit = |list: &[u32]| {
            for &i in list {
                examined += 1;
                let d = self.positions[i as usize].distance(center);
                if d <= radius {
                    f(i as usize, d);
                }
            }
        };
        if span > grid.buckets() as u64 {
            // A brush larger than the grid: every sample.
            visit(&grid.items);
        } else {
            // Each bucket once: cells that share a bucket would otherwise
            // report its samples twice.
            let mut buckets = Vec::with_capacity(span as usize);
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        buckets.push(bucket_of([x, y, z], grid.buckets()));
                    }
                }
            }
            buckets.sort_unstable();
            buckets.dedup();
            for b in buckets {
                visit(grid.bucket(b as usize));
            }
        }
        examined
    }

    /// Applies one brush dab to `colors` (the ones this painter indexed).
    ///
    /// # Errors
    /// [`Error::ChannelMismatch`] if the brush colour or `colors` do not
    /// match this painter; [`Error::NonFinite`] for a bad radius.
    pub fn paint(&self, colors: &mut MeshColors, brush: &Brush<'_>) -> Result<Stroke, Error> {
        self.dab(colors, brush, None)
    }

    /// As [`Painter::paint`], recording into `recorder` the old value of
    /// every sample the dab changes (once per stroke: a sample already
    /// recorded by an earlier dab keeps its first value), for undo
    /// (Sec. 5.1; see [`crate::undo`]).
    ///
    /// # Errors
    /// As for [`Painter::paint`], and [`Error::StaleUndo`] if `recorder`
    /// was made for other colours; nothing changes then.
    pub fn paint_recorded(
        &self,
        colors: &mut MeshColors,
        brush: &Brush<'_>,
        recorder: &mut Recorder,
    ) -> Result<Stroke, Error> {
        recorder.fits(colors)?;
        self.dab(colors, brush, Some(recorder))
    }

    fn dab(
        &self,
        colors: &mut MeshColors,
        brush: &Brush<'_>,
        mut recorder: Option<&mut Recorder>,
    ) -> Result<Stroke, Error> {
        if brush.color.len() != self.channels || colors.channels() != self.channels {
            return Err(Error::ChannelMismatch {
                what: "brush colour",
                expected: self.channels,
                got: brush.color.len(),
            });
        }
        if colors.sample_count() != self.positions.len() {
            return Err(Error::ChannelMismatch {
                what: "samples indexed by this painter",
                expected: self.positions.len(),
                got: colors.sample_count(),
            });
        }
        if !(brush.radius.is_finite() && brush.radius > 0.0 && brush.center.is_finite()) {
            return Err(Error::NonFinite {
                what: "brush",
                index: 0,
            });
        }
        let mut touched = 0;
        let examined = self.for_each_within(brush.center, brush.radius, |i, d| {
            touched += 1;
            let w = brush.weight(d);
            let s = colors.sample_at_mut(i);
            let mut new = [0.0f32; MAX_CHANNELS];
            let new = &mut new[..s.len()];
            for ((n, &x), &c) in new.iter_mut().zip(s.iter()).zip(brush.color) {
                *n = match brush.blend {
                    Blend::Set => c,
                    Blend::Mix => x + w * (c - x),
                    Blend::Add => x + w * c,
                };
            }
            // Only samples whose bits change are recorded (the rim of a
            // dab, weight 0, changes nothing).
            if let Some(r) = recorder.as_deref_mut()
                && new
                    .iter()
                    .zip(s.iter())
                    .any(|(a, b)| a.to_bits() != b.to_bits())
            {
                r.note(i, s);
            }
            s.copy_from_slice(new);
        });
        Ok(Stroke { touched, examined })
    }
}

fn cell_of(p: Vec3, cell: f32) -> [i32; 3] {
    (p / cell).to_array().map(floor_clamped)
}

/// `x.floor().clamp(-1e9, 1e9) as i32` without a call to `floorf`
/// (x86-64's baseline has no rounding instruction; the grid hashes every
/// sample after a resolution change): ±10⁹ are integers in `f32`, so
/// clamping first gives the same, and within them the truncation is exact
/// and one below it when it rounded a negative number up. NaN gives 0, as
/// the cast of a NaN floor does.
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
