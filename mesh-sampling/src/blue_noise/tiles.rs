//! Elimination (and relocation) streamed through spatial tiles, so that a
//! run holds its candidates compactly (16 bytes each) and only one tile's
//! working set per thread at a time.
//!
//! The candidates' bounding box is cut into tiles of side about
//! [`TILE_RADII`] mean packing radii (and at least four times the largest
//! disk's reach), done in eight phases by the parities of their grid
//! coordinates. Two tiles of a phase are at least one tile apart, farther
//! than anything reaches, so a phase's tiles are independent and run in
//! parallel. A tile eliminates its own candidates together with
//!
//! - the points kept by the neighbouring tiles of earlier phases within
//!   reach of its box (frozen: they weigh on its candidates as in one
//!   global queue but are not removed), and
//! - the candidates of neighbouring tiles of later phases within twice the
//!   reach (ghosts: eliminated with its own, so its border sees a thinned
//!   neighbour rather than an empty one, which left crowded borders and ρ
//!   0.31 without them; the ghosts beyond the reach only thin the nearer
//!   ones and are not counted),
//!
//! and stops when its own and near ghosts are down to its share of `N`
//! (its candidates times `N / M`) plus the ghosts' share, plus
//! [`OVERSHOOT`]: its own count floats with the weights as in one queue.
//! Forcing every tile to its exact share cost ρ 0.63 on the bunny (small
//! pieces of surface in a tile's corner must take a count their space
//! cannot hold). [`trim`] then removes the run's surplus, closest first.
//! The result depends on the candidates, `N` and the options only, never
//! on the number of threads.

use super::elimination::{Stop, Weights, eliminate};
use super::grid::{Kind, Local};
use super::relocation::relocate;
use super::trim::trim;

/// Tile side in mean packing radii (at least twice the largest radius).
/// Measured on the data meshes at N = 10⁵–10⁶: 32 to 64 give the same ρ
/// and time within a few per cent.
const TILE_RADII: f32 = 96.0;

/// How far above its share a tile keeps points (0.5%): with the ghosts'
/// weights a tile's own count comes out within a fraction of a per cent of
/// its share either way, and [`trim`] removes the surplus of the whole
/// run, closest pairs first.
const OVERSHOOT: f64 = 0.005;

/// Packing radii from densities: `r = √(1 / (2√3 N p))`, with densities
/// below 1/64 of the mean treated as 1/64 of it (so a candidate in a
/// nearly empty region does not reach across the mesh; its spacing stops
/// growing at 8× the mean's).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Radii {
    scale: f64,
    floor: f64,
    mean: f64,
}

impl Radii {
    /// The radii for `n` points from candidates with densities `pdf`.
    pub(crate) fn new(pdf: impl Iterator<Item = f32>, n: usize) -> Self {
        let (sum, count) = pdf
            .map(f64::from)
            .filter(|p| p.is_finite() && *p > 0.0)
            .fold((0.0, 0usize), |(s, c), p| (s + p, c + 1));
        // The mean of p over candidates drawn from p is ∫p² dA, at least
        // the area mean 1/A; the floor is relative to it.
        let mean = if count > 0 { sum / count as f64 } else { 1.0 };
        Self {
            scale: 1.0 / (2.0 * 3f64.sqrt() * n as f64),
            floor: mean / 64.0,
            mean,
        }
    }

    /// The radius of a candidate with density `p` (invalid densities
    /// count as the floor).
    #[inline]
    pub(crate) fn of(&self, p: f32) -> f32 {
        let p = f64::from(p);
        let p = if p.is_finite() && p > self.floor {
            p
        } else {
            self.floor
        };
        (self.scale / p).sqrt() as f32
    }

    /// The radius at the mean density.
    fn typical(&self) -> f32 {
        (self.scale / self.mean).sqrt() as f32
    }
}

/// How the candidates fall into tiles.
struct Tiling {
    lo: [f32; 3],
    /// Tile sides: the box's extent over the tile count, per axis (between
    /// half and all of the side asked for, so no thin slivers at the end).
    side: [f32; 3],
    dims: [usize; 3],
    /// The candidates, tile after tile (ascending within a tile).
    order: Vec<u32>,
    /// `order[start[t]..start[t + 1]]` are tile `t`'s candidates.
    start: Vec<u32>,
}

impl Tiling {
    /// Tiles of side at most `side` and at least `side / 2` (or the whole
    /// extent, when it is shorter).
    fn new(pts: &[[f32; 4]], side: f32) -> Self {
        let (lo, hi) = bounds(pts);
        let extent = [0, 1, 2].map(|a| (hi[a] - lo[a]).max(0.0));
        // At most one tile per 8 candidates (plus a few): a long, thin or
        // sparse box gets larger tiles rather than an empty array.
        let most = (pts.len() / 8).max(64);
        let dims_of =
            |side: f32| [0, 1, 2].map(|a| ((extent[a] / side).ceil() as usize).clamp(1, most));
        let mut side = if side > 0.0 && side.is_finite() {
            side
        } else {
            1.0
        };
        while dims_of(side).iter().product::<usize>() > most {
            side *= 1.25;
        }
        let dims = dims_of(side);
        let mut tiling = Self {
            lo,
            // 0 for a flat axis: one layer of tiles, as thin as the points.
            side: [0, 1, 2].map(|a| extent[a] / dims[a] as f32),
            dims,
            order: Vec::new(),
            start: vec![0; dims[0] * dims[1] * dims[2] + 1],
        };
        for p in pts {
            let t = tiling.tile_of(p);
            tiling.start[t + 1] += 1;
        }
        for t in 1..tiling.start.len() {
            tiling.start[t] += tiling.start[t - 1];
        }
        let mut next = tiling.start.clone();
        let mut order = vec![0u32; pts.len()];
        for (i, p) in pts.iter().enumerate() {
            let t = tiling.tile_of(p);
            order[next[t] as usize] = i as u32;
            next[t] += 1;
        }
        tiling.order = order;
        tiling
    }

    #[inline]
    fn coords(&self, p: &[f32; 4]) -> [usize; 3] {
        // A flat axis divides 0 by 0: NaN, which `as` turns into 0.
        [0, 1, 2].map(|a| (((p[a] - self.lo[a]) / self.side[a]) as usize).min(self.dims[a] - 1))
    }

    #[inline]
    fn tile_of(&self, p: &[f32; 4]) -> usize {
        let [x, y, z] = self.coords(p);
        (z * self.dims[1] + y) * self.dims[0] + x
    }

    fn candidates(&self, t: usize) -> &[u32] {
        &self.order[self.start[t] as usize..self.start[t + 1] as usize]
    }

    fn phase(&self, t: usize) -> usize {
        let x = t % self.dims[0];
        let y = t / self.dims[0] % self.dims[1];
        let z = t / (self.dims[0] * self.dims[1]);
        (x & 1) | (y & 1) << 1 | (z & 1) << 2
    }
}

/// The bounding box of the candidates' positions.
fn bounds(pts: &[[f32; 4]]) -> ([f32; 3], [f32; 3]) {
    let fold = |(lo, hi): ([f32; 3], [f32; 3]), p: &[f32; 4]| {
        (
            [0, 1, 2].map(|a| lo[a].min(p[a])),
            [0, 1, 2].map(|a| hi[a].max(p[a])),
        )
    };
    let empty = ([f32::MAX; 3], [f32::MIN; 3]);
    let (lo, hi) = pts.iter().fold(empty, fold);
    if pts.is_empty() {
        ([0.0; 3], [0.0; 3])
    } else {
        (lo, hi)
    }
}

/// Each tile's share of `n` for candidate counts `counts` (summing to
/// `m`): `count · n / m` rounded down, plus one for the largest remainders
/// (ties to the lower tile) until the shares sum to `n`.
fn shares(counts: &[usize], n: usize, m: usize) -> Vec<usize> {
    let (n128, m128) = (n as u128, m.max(1) as u128);
    let mut share: Vec<usize> = counts
        .iter()
        .map(|&c| (c as u128 * n128 / m128) as usize)
        .collect();
    let mut left = n - share.iter().sum::<usize>();
    let mut by_remainder: Vec<(u128, usize)> = counts
        .iter()
        .enumerate()
        .map(|(t, &c)| (c as u128 * n128 % m128, t))
        .collect();
    by_remainder.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    for &(_, t) in &by_remainder {
        if left == 0 {
            break;
        }
        if share[t] < counts[t] {
            share[t] += 1;
            left -= 1;
        }
    }
    share
}

/// What a stage does with each tile.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stage {
    pub(crate) weights: Weights,
    /// Relocate after eliminating ([`Packing::Dense`](super::Packing::Dense)).
    pub(crate) relocate: bool,
}

/// The indices (ascending) of the `n` candidates kept of `pts`
/// (`[x, y, z, pdf]` each), by elimination tile by tile.
pub(crate) fn select(pts: &[[f32; 4]], n: usize, stage: Stage) -> Vec<u32> {
    select_in_tiles(pts, n, stage, TILE_RADII)
}

/// [`select`] with tiles of `tile_radii` mean radii (or twice the halo).
pub(crate) fn select_in_tiles(
    pts: &[[f32; 4]],
    n: usize,
    stage: Stage,
    tile_radii: f32,
) -> Vec<u32> {
    let m = pts.len();
    if n >= m {
        return (0..m as u32).collect();
    }
    let radii = Radii::new(pts.iter().map(|p| p[3]), n);
    let r_hi = pts.iter().map(|p| radii.of(p[3])).fold(0.0f32, f32::max);
    let typical = radii.typical();
    let halo = 2.0 * r_hi;
    // Sides of at least twice the ghosts' reach (tiles may come out at
    // half the side asked for): a phase's tiles never reach each other.
    let tiling = Tiling::new(pts, (tile_radii * typical).max(4.0 * halo * 1.001));
    let plan = Plan::new(&tiling, n, m);
    let env = Env {
        pts,
        tiling: &tiling,
        plan: &plan,
        radii,
        halo,
        cell: 2.0 * typical,
        stage,
        ghost_ratio: n as f64 / m as f64,
    };
    if let Some(kept) = run_phases(&env, n, false) {
        let xyz: Vec<[f32; 3]> = kept
            .iter()
            .map(|&i| {
                let p = &pts[i as usize];
                [p[0], p[1], p[2]]
            })
            .collect();
        let r: Vec<f32> = kept.iter().map(|&i| radii.of(pts[i as usize][3])).collect();
        return trim(&xyz, &r, n)
            .into_iter()
            .map(|j| kept[j as usize])
            .collect();
    }
    // The last phase could not make up the count (it lacked candidates):
    // every tile keeps exactly its share instead.
    run_phases(&env, n, true).unwrap_or_default()
}

/// The occupied tiles, their shares and the phase order.
struct Plan {
    /// Occupied tiles, by ordinal.
    occupied: Vec<usize>,
    /// Tile → ordinal (`u32::MAX` when empty).
    ordinal: Vec<u32>,
    /// Each occupied tile's share of the target.
    share: Vec<usize>,
    /// The last phase that has tiles: its tiles have no later neighbour.
    last: usize,
}

impl Plan {
    fn new(tiling: &Tiling, n: usize, m: usize) -> Self {
        let tiles = tiling.start.len() - 1;
        let occupied: Vec<usize> = (0..tiles)
            .filter(|&t| !tiling.candidates(t).is_empty())
            .collect();
        let counts: Vec<usize> = occupied
            .iter()
            .map(|&t| tiling.candidates(t).len())
            .collect();
        let mut ordinal = vec![u32::MAX; tiles];
        for (o, &t) in occupied.iter().enumerate() {
            ordinal[t] = o as u32;
        }
        let last = occupied.iter().map(|&t| tiling.phase(t)).max().unwrap_or(0);
        Self {
            share: shares(&counts, n, m),
            occupied,
            ordinal,
            last,
        }
    }
}

/// What every tile of a run reads.
struct Env<'a> {
    pts: &'a [[f32; 4]],
    tiling: &'a Tiling,
    plan: &'a Plan,
    radii: Radii,
    halo: f32,
    cell: f32,
    stage: Stage,
    ghost_ratio: f64,
}

/// The eight phases. Unless `exact`, every tile stops at a total count
/// of its own and near ghosts (its own count floats, as in one queue) a
/// little above its share; `None` if the run falls short of `n` (then
/// [`select_in_tiles`] runs again with `exact`, where every tile keeps
/// exactly its share).
fn run_phases(env: &Env, n: usize, exact: bool) -> Option<Vec<u32>> {
    let plan = env.plan;
    let mut kept: Vec<Vec<u32>> = vec![Vec::new(); plan.occupied.len()];
    for phase in 0..=plan.last {
        let todo: Vec<usize> = (0..plan.occupied.len())
            .filter(|&o| env.tiling.phase(plan.occupied[o]) == phase)
            .collect();
        let target = |o: usize| {
            if exact {
                Target::Own(plan.share[o])
            } else {
                Target::Share((plan.share[o] as f64 * (1.0 + OVERSHOOT)).ceil() as usize)
            }
        };
        let kept_so_far = &kept;
        let run = |&o: &usize| tile(env, o, phase, kept_so_far, target(o));
        #[cfg(feature = "rayon")]
        let done: Vec<Vec<u32>> = {
            use rayon::prelude::*;
            todo.par_iter().map(run).collect()
        };
        #[cfg(not(feature = "rayon"))]
        let done: Vec<Vec<u32>> = todo.iter().map(run).collect();
        for (o, k) in todo.into_iter().zip(done) {
            kept[o] = k;
        }
    }
    let mut all: Vec<u32> = kept.into_iter().flatten().collect();
    if all.len() < n || (exact && all.len() != n) {
        return None;
    }
    all.sort_unstable();
    Some(all)
}

/// A tile's target.
#[derive(Debug, Clone, Copy)]
enum Target {
    /// About its share: stop when its candidates and ghosts together are
    /// down to the share plus the ghosts' expected survivors.
    Share(usize),
    /// Exactly this many of its own.
    Own(usize),
}

/// The up to 26 tiles around tile `t`.
fn neighbour_tiles(tiling: &Tiling, t: usize) -> impl Iterator<Item = usize> + '_ {
    let d = tiling.dims;
    let c = [t % d[0], t / d[0] % d[1], t / (d[0] * d[1])];
    (0..27).filter_map(move |k| {
        let off = [k % 3, k / 3 % 3, k / 9];
        if off == [1, 1, 1] {
            return None;
        }
        let mut u = [0usize; 3];
        for a in 0..3 {
            u[a] = (c[a] + off[a]).checked_sub(1).filter(|&v| v < d[a])?;
        }
        Some((u[2] * d[1] + u[1]) * d[0] + u[0])
    })
}

/// One tile (ordinal `o`, of phase `phase`): its candidates, the points
/// kept by earlier neighbours within `halo` of its box (frozen) and the
/// candidates of later neighbours within twice that (ghosts: those farther
/// than `halo` only thin the nearer ones, so that the ghosts the tile's
/// own see are not the unthinned edge of a cut-off region), eliminated to
/// `target` (and relocated for the dense packing). Returns the kept
/// candidates' indices, ascending.
fn tile(env: &Env, o: usize, phase: usize, kept: &[Vec<u32>], target: Target) -> Vec<u32> {
    let (tiling, plan, pts) = (env.tiling, env.plan, env.pts);
    let t = plan.occupied[o];
    let own = tiling.candidates(t);
    if matches!(target, Target::Own(k) if k >= own.len()) {
        return own.to_vec();
    }
    let d = tiling.dims;
    let c = [t % d[0], t / d[0] % d[1], t / (d[0] * d[1])];
    let box_at = |pad: f32| {
        (
            [0, 1, 2].map(|a| tiling.lo[a] + c[a] as f32 * tiling.side[a] - pad),
            [0, 1, 2].map(|a| tiling.lo[a] + (c[a] + 1) as f32 * tiling.side[a] + pad),
        )
    };
    let (lo, hi) = box_at(env.halo);
    let (glo, ghi) = box_at(2.0 * env.halo);
    let point = |i: u32, kind: Kind| {
        let p = &pts[i as usize];
        ([p[0], p[1], p[2]], p[3], i, kind)
    };
    let inside = |(lo, hi): ([f32; 3], [f32; 3])| {
        move |&(p, ..): &([f32; 3], f32, u32, Kind)| (0..3).all(|a| p[a] >= lo[a] && p[a] <= hi[a])
    };
    let neighbours = neighbour_tiles(tiling, t);
    let mut points: Vec<_> = own.iter().map(|&i| point(i, Kind::Own)).collect();
    for u in neighbours {
        let Some(k) = kept.get(plan.ordinal[u] as usize) else {
            continue;
        };
        if tiling.phase(u) < phase {
            points.extend(
                k.iter()
                    .map(|&i| point(i, Kind::Frozen))
                    .filter(inside((lo, hi))),
            );
        } else {
            let near = inside((lo, hi));
            let ghosts = tiling.candidates(u).iter().map(|&i| {
                let p = point(i, Kind::Ghost);
                if near(&p) {
                    p
                } else {
                    point(i, Kind::FarGhost)
                }
            });
            points.extend(ghosts.filter(inside((glo, ghi))));
        }
    }
    for p in &mut points {
        p.1 = env.radii.of(p.1);
    }
    // Near ghosts: those the tile's own disks reach.
    let ghosts = points.iter().filter(|p| p.3 == Kind::Ghost).count();
    let local = Local::new(&points, glo, ghi, env.cell);
    drop(points);
    let stop = match target {
        Target::Own(k) => Stop::Own(k),
        Target::Share(k) => Stop::Total(k + (ghosts as f64 * env.ghost_ratio).round() as usize),
    };
    let mut kept = eliminate(&local, stop, env.stage.weights);
    if env.stage.relocate {
        kept = relocate(&local, kept);
    }
    let mut out: Vec<u32> = (0..local.len())
        .filter(|&j| kept[j] && local.own(j))
        .map(|j| local.global[j])
        .collect();
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ρ of elimination from 5 N uniform candidates on the unit square,
    /// with tiles of `tile_radii` mean radii.
    fn rho_in_tiles(tile_radii: f32) -> f64 {
        use rand::{RngExt, SeedableRng};
        let n = 6000;
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let pts: Vec<[f32; 4]> = (0..5 * n)
            .map(|_| [rng.random::<f32>(), rng.random::<f32>(), 0.0, 1.0])
            .collect();
        let stage = Stage {
            weights: Weights {
                alpha: 8.0,
                min_ratio: 0.65 * (1.0 - 0.2f64.powf(1.5)),
            },
            relocate: false,
        };
        let kept = select_in_tiles(&pts, n, stage, tile_radii);
        assert_eq!(kept.len(), n);
        let xyz: Vec<glam::Vec3> = kept
            .iter()
            .map(|&i| glam::Vec3::new(pts[i as usize][0], pts[i as usize][1], 0.0))
            .collect();
        super::super::relative_radius(&xyz, 1.0)
    }

    #[test]
    fn tiles_keep_the_spacing_of_one_queue() {
        // Sixteen tiles. Without the ghosts (a tile's border facing a later
        // tile seen as empty) the first tiles crowded their borders and
        // the later ones had to squeeze their share next to them: ρ 0.31
        // here; with them, 0.687 against one queue's 0.696.
        let one_queue = rho_in_tiles(1e9);
        let tiled = rho_in_tiles(64.0);
        assert!(one_queue > 0.68, "{one_queue}");
        assert!(
            tiled > one_queue - 0.01,
            "tiled {tiled}, one queue {one_queue}"
        );
    }

    #[test]
    fn shares_sum_to_the_target_and_follow_the_counts() {
        let s = shares(&[10, 20, 30, 1], 20, 61);
        assert_eq!(s.iter().sum::<usize>(), 20);
        assert_eq!(s, vec![3, 7, 10, 0]);
        assert_eq!(shares(&[5, 5], 10, 10), vec![5, 5]);
        assert_eq!(shares(&[3, 3, 3], 1, 9), vec![1, 0, 0]);
    }

    #[test]
    fn phases_separate_neighbours() {
        let pts: Vec<[f32; 4]> = (0..4096)
            .map(|i| [(i % 16) as f32, (i / 16 % 16) as f32, (i / 256) as f32, 1.0])
            .collect();
        let tiling = Tiling::new(&pts, 4.0);
        assert_eq!(tiling.dims, [4, 4, 4]);
        for t in 0..64 {
            assert_eq!(tiling.candidates(t).len(), 64);
            let around: Vec<usize> = neighbour_tiles(&tiling, t).collect();
            assert!(around.iter().all(|&u| tiling.phase(u) != tiling.phase(t)));
            let corner = [0, 3, 12, 15, 48, 51, 60, 63].contains(&t);
            if corner {
                assert_eq!(around.len(), 7);
            }
        }
        assert_eq!(neighbour_tiles(&tiling, 21).count(), 26);
    }

    #[test]
    fn radii_follow_the_inverse_square_root_of_the_density() {
        let radii = Radii::new([1.0f32, 4.0, 1e-9, f32::NAN].into_iter(), 10);
        assert!((radii.of(1.0) / radii.of(4.0) - 2.0).abs() < 1e-6);
        // Nearly empty regions and invalid densities are capped at 1/64 of
        // the mean density: spacing at most 8× the mean's.
        assert!(radii.of(1e-9).is_finite() && radii.of(1e-9) == radii.of(f32::NAN));
        assert!((radii.of(1e-9) / radii.typical() - 8.0).abs() < 1e-5);
    }
}
