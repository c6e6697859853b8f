//! The points one tile works on, sorted into a uniform grid (a cell list):
//! the tile's own candidates and the frozen points of the tiles done
//! before it. A disk query visits the cells its bounding box overlaps, one
//! contiguous run of points per row of cells, with 32-bit indices and
//! `f32` positions: no tree and no stored neighbour lists, so a tile's
//! memory is a few tens of bytes per point and its queries stay in cache.

/// The most cells of a tile's grid (1 MiB of offsets): a box that would
/// need more gets larger cells.
pub(crate) const MAX_CELLS: usize = 1 << 18;

/// A tile's points in cell order.
pub(crate) struct Local {
    /// Positions.
    pub(crate) xyz: Vec<[f32; 3]>,
    /// Packing radius of each point (`r_k`, from its density).
    pub(crate) r: Vec<f32>,
    /// The point's index in the candidate pool.
    pub(crate) global: Vec<u32>,
    /// Frozen points (kept by an earlier tile) weigh on the tile's
    /// candidates and count in its spacings but are never removed or moved.
    pub(crate) frozen: Vec<bool>,
    /// Ghosts: candidates of a neighbouring tile not done yet, eliminated
    /// with the tile's own (so its border sees a thinned neighbour, not an
    /// empty one) but not kept by it, and never moved.
    pub(crate) ghost: Vec<bool>,
    /// Ghosts beyond the reach of the tile's own disks: they thin the
    /// nearer ghosts but do not count in a tile's total.
    pub(crate) far: Vec<bool>,
    grid: Grid,
}

/// What a point is to the tile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    /// One of the tile's candidates.
    Own,
    /// Kept by an earlier tile.
    Frozen,
    /// A candidate of a later tile.
    Ghost,
    /// A candidate of a later tile, beyond the reach of the tile's own.
    FarGhost,
}

/// A uniform grid over a box: `start[c]..start[c + 1]` are the points of
/// cell `c` (x fastest).
struct Grid {
    lo: [f32; 3],
    inv_cell: f32,
    dims: [usize; 3],
    start: Vec<u32>,
}

impl Grid {
    #[inline]
    fn coord(&self, x: f32, axis: usize) -> usize {
        // `as` saturates: below the box gives 0, NaN gives 0.
        let c = ((x - self.lo[axis]) * self.inv_cell) as usize;
        c.min(self.dims[axis] - 1)
    }

    #[inline]
    fn cell(&self, p: &[f32; 3]) -> usize {
        let [x, y, z] = [
            self.coord(p[0], 0),
            self.coord(p[1], 1),
            self.coord(p[2], 2),
        ];
        (z * self.dims[1] + y) * self.dims[0] + x
    }
}

impl Local {
    /// The tests' grid: `points` of radius `r` (pool indices their
    /// positions in the slice, those in `frozen` kept from earlier tiles)
    /// over the box `lo..hi`, cells of 0.5.
    #[cfg(test)]
    pub(crate) fn of_points(
        points: &[[f32; 3]],
        r: f32,
        frozen: &[usize],
        lo: [f32; 3],
        hi: [f32; 3],
    ) -> Self {
        let pts: Vec<_> = points
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                let kind = if frozen.contains(&i) {
                    Kind::Frozen
                } else {
                    Kind::Own
                };
                (p, r, i as u32, kind)
            })
            .collect();
        Self::new(&pts, lo, hi, 0.5)
    }

    /// Sorts `points` (position, radius, pool index, kind) into a grid of
    /// cubic cells of side `cell` over the box `lo..hi`; points outside the
    /// box go to its border cells (queries clamp the same way, so nothing
    /// is missed).
    /// Cells larger than `cell` are used when the box would need more than
    /// [`MAX_CELLS`] of them.
    pub(crate) fn new(
        points: &[([f32; 3], f32, u32, Kind)],
        lo: [f32; 3],
        hi: [f32; 3],
        cell: f32,
    ) -> Self {
        let extent = [0, 1, 2].map(|a| (hi[a] - lo[a]).max(0.0));
        let dims_of =
            |cell: f32| [0, 1, 2].map(|a| ((extent[a] / cell).ceil() as usize).clamp(1, MAX_CELLS));
        let mut cell = if cell > 0.0 { cell } else { 1.0 };
        while dims_of(cell).iter().product::<usize>() > MAX_CELLS {
            cell *= 1.25;
        }
        let dims = dims_of(cell);
        let mut grid = Grid {
            lo,
            inv_cell: 1.0 / cell,
            dims,
            start: vec![0; dims[0] * dims[1] * dims[2] + 1],
        };
        let cells: Vec<u32> = points.iter().map(|p| grid.cell(&p.0) as u32).collect();
        for &c in &cells {
            grid.start[c as usize + 1] += 1;
        }
        for c in 1..grid.start.len() {
            grid.start[c] += grid.start[c - 1];
        }
        let mut next = grid.start.clone();
        let mut order = vec![0u32; points.len()];
        for (i, &c) in cells.iter().enumerate() {
            order[next[c as usize] as usize] = i as u32;
            next[c as usize] += 1;
        }
        Self {
            xyz: order.iter().map(|&i| points[i as usize].0).collect(),
            r: order.iter().map(|&i| points[i as usize].1).collect(),
            global: order.iter().map(|&i| points[i as usize].2).collect(),
            frozen: order
                .iter()
                .map(|&i| points[i as usize].3 == Kind::Frozen)
                .collect(),
            ghost: order
                .iter()
                .map(|&i| matches!(points[i as usize].3, Kind::Ghost | Kind::FarGhost))
                .collect(),
            far: order
                .iter()
                .map(|&i| points[i as usize].3 == Kind::FarGhost)
                .collect(),
            grid,
        }
    }

    /// Whether point `j` is one of the tile's own candidates.
    #[inline]
    pub(crate) fn own(&self, j: usize) -> bool {
        !self.frozen[j] && !self.ghost[j]
    }

    /// The number of points.
    pub(crate) fn len(&self) -> usize {
        self.xyz.len()
    }

    /// Calls `f(j, d²)` for every point `j` closer than `reach` to `p`
    /// (including a point at `p` itself), in cell order.
    #[inline]
    pub(crate) fn within(&self, p: &[f32; 3], reach: f32, mut f: impl FnMut(usize, f32)) {
        let g = &self.grid;
        let r2 = reach * reach;
        let lo = [0, 1, 2].map(|a| g.coord(p[a] - reach, a));
        let hi = [0, 1, 2].map(|a| g.coord(p[a] + reach, a));
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                let row = (z * g.dims[1] + y) * g.dims[0];
                let (a, b) = (g.start[row + lo[0]], g.start[row + hi[0] + 1]);
                for j in a as usize..b as usize {
                    let q = &self.xyz[j];
                    let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
                    let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    if d2 < r2 {
                        f(j, d2);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_exactly_the_points_within_reach() {
        // A lattice of points, some outside the grid's box.
        let mut points = Vec::new();
        for i in 0..12 {
            for j in 0..12 {
                let p = [
                    i as f32 * 0.13 - 0.2,
                    j as f32 * 0.11 - 0.1,
                    (i * j % 5) as f32 * 0.05,
                ];
                let kind = [Kind::Own, Kind::Frozen, Kind::Ghost][i % 3];
                points.push((p, 0.1, points.len() as u32, kind));
            }
        }
        let local = Local::new(&points, [0.0; 3], [1.0, 1.0, 0.2], 0.07);
        assert_eq!(local.len(), points.len());
        for probe in [[0.5, 0.5, 0.1], [-0.3, 0.0, 0.0], [1.2, 1.1, 0.3]] {
            for reach in [0.05f32, 0.2, 0.6] {
                let mut got = Vec::new();
                local.within(&probe, reach, |j, _| got.push(local.global[j]));
                got.sort_unstable();
                let want: Vec<u32> = points
                    .iter()
                    .filter(|(q, ..)| {
                        let d: f32 = (0..3).map(|a| (q[a] - probe[a]).powi(2)).sum();
                        d < reach * reach
                    })
                    .map(|p| p.2)
                    .collect();
                assert_eq!(got, want, "{probe:?} {reach}");
            }
        }
        // The arrays stay aligned through the sort.
        for j in 0..local.len() {
            let p = &points[local.global[j] as usize];
            assert_eq!(local.xyz[j], p.0);
            assert_eq!(local.frozen[j], p.3 == Kind::Frozen);
            assert_eq!(local.ghost[j], p.3 == Kind::Ghost);
            assert_eq!(local.own(j), p.3 == Kind::Own);
        }
    }
}
