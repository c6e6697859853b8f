//! A bounding volume hierarchy over triangles: the tree the fast winding
//! number walks (Barill et al. 2018) and the segment queries that
//! place cut points on lattice edges.
//!
//! Built top-down by median split of the triangle centroids along the
//! longest axis of their bounds; the split uses `select_nth_unstable_by`,
//! which is deterministic, so the same input always gives the same tree.

use glam::DVec3;

/// Triangles per leaf: small enough that the exact sum at a leaf is cheap,
/// large enough that the tree stays shallow.
pub(crate) const LEAF_SIZE: usize = 8;

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Aabb {
    pub(crate) min: DVec3,
    pub(crate) max: DVec3,
}

impl Aabb {
    pub(crate) const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    pub(crate) fn grow(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// Whether the segment `a + t (b - a)`, `t` in `[0, 1]`, meets the box
    /// (slab test; a zero direction component is handled by the infinities).
    pub(crate) fn hits_segment(&self, a: DVec3, inv_d: DVec3) -> bool {
        let t0 = (self.min - a) * inv_d;
        let t1 = (self.max - a) * inv_d;
        let lo = t0.min(t1);
        let hi = t0.max(t1);
        let enter = lo.x.max(lo.y).max(lo.z).max(0.0);
        let exit = hi.x.min(hi.y).min(hi.z).min(1.0);
        // NaN (0 * inf) is unordered, which keeps the box: conservative.
        enter.partial_cmp(&exit) != Some(std::cmp::Ordering::Greater)
    }
}

/// One node: an inner node has two children, a leaf a range of
/// [`Bvh::order`].
#[derive(Debug, Clone)]
pub(crate) struct Node {
    pub(crate) bounds: Aabb,
    /// Leaf: the first index into [`Bvh::order`]. Inner: unused.
    pub(crate) start: u32,
    /// Leaf: number of triangles (> 0). Inner: 0.
    pub(crate) count: u32,
    /// Inner node: indices of the two children.
    pub(crate) children: [u32; 2],
}

impl Node {
    pub(crate) fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// The tree. Node 0 is the root.
#[derive(Debug, Clone)]
pub(crate) struct Bvh {
    pub(crate) nodes: Vec<Node>,
    /// Triangle indices, grouped so that every node owns a contiguous range.
    pub(crate) order: Vec<u32>,
}

impl Bvh {
    /// Builds the tree over `triangles` (indices into `positions`, already
    /// validated). `triangles` must not be empty.
    pub(crate) fn build(positions: &[DVec3], triangles: &[[u32; 3]]) -> Bvh {
        let centroids: Vec<DVec3> = triangles
            .iter()
            .map(|t| {
                (positions[t[0] as usize] + positions[t[1] as usize] + positions[t[2] as usize])
                    / 3.0
            })
            .collect();
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF_SIZE + 1);
        nodes.push(Node {
            bounds: Aabb::EMPTY,
            start: 0,
            count: 0,
            children: [0, 0],
        });
        // Explicit stack of (node, start, end) so deep trees cannot overflow
        // the thread's stack.
        let mut stack = vec![(0usize, 0usize, order.len())];
        while let Some((node, start, end)) = stack.pop() {
            let mut bounds = Aabb::EMPTY;
            let mut cbounds = Aabb::EMPTY;
            for &t in &order[start..end] {
                for &v in &triangles[t as usize] {
                    bounds.grow(positions[v as usize]);
                }
                cbounds.grow(centroids[t as usize]);
            }
            nodes[node].bounds = bounds;
            if end - start <= LEAF_SIZE {
                nodes[node].start = start as u32;
                nodes[node].count = (end - start) as u32;
                continue;
            }
            let ext = cbounds.max - cbounds.min;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let mid = start + (end - start) / 2;
            order[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
                let ca = centroids[a as usize][axis];
                let cb = centroids[b as usize][axis];
                ca.total_cmp(&cb).then(a.cmp(&b))
            });
            let left = nodes.len();
            for _ in 0..2 {
                nodes.push(Node {
                    bounds: Aabb::EMPTY,
                    start: 0,
                    count: 0,
                    children: [0, 0],
                });
            }
            nodes[node].children = [left as u32, left as u32 + 1];
            stack.push((left + 1, mid, end));
            stack.push((left, start, mid));
        }
        Bvh { nodes, order }
    }

    /// Parameters `t` in `(0, 1)` where the segment `a -> b` crosses a
    /// triangle, with the crossing's direction (+1 when the segment goes
    /// against the triangle's normal, i.e. enters through a front face),
    /// sorted by `t`.
    pub(crate) fn segment_hits(
        &self,
        positions: &[DVec3],
        triangles: &[[u32; 3]],
        a: DVec3,
        b: DVec3,
        out: &mut Vec<(f64, i8)>,
    ) {
        out.clear();
        let d = b - a;
        let inv_d = DVec3::ONE / d;
        let mut stack = vec![0u32];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if !node.bounds.hits_segment(a, inv_d) {
                continue;
            }
            if node.is_leaf() {
                let s = node.start as usize;
                for &t in &self.order[s..s + node.count as usize] {
                    let tri = triangles[t as usize];
                    if let Some(hit) = segment_triangle(
                        a,
                        d,
                        positions[tri[0] as usize],
                        positions[tri[1] as usize],
                        positions[tri[2] as usize],
                    ) {
                        out.push(hit);
                    }
                }
            } else {
                stack.extend_from_slice(&node.children);
            }
        }
        out.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    }
}

/// Möller–Trumbore intersection of the segment `a + t d`, `t` in `(0, 1)`,
/// with a triangle; returns `t` and +1 when `d` points against the
/// triangle's (counter-clockwise) normal.
fn segment_triangle(a: DVec3, d: DVec3, p0: DVec3, p1: DVec3, p2: DVec3) -> Option<(f64, i8)> {
    let e1 = p1 - p0;
    let e2 = p2 - p0;
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let tv = a - p0;
    let u = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = tv.cross(e1);
    let v = d.dot(qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(qv) * inv;
    if t <= 0.0 || t >= 1.0 {
        return None;
    }
    // det = e1 . (d x e2) = d . (e2 x e1) = -d . n: positive when d opposes n.
    Some((t, if det > 0.0 { 1 } else { -1 }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_triangle_is_in_exactly_one_leaf_and_inside_its_bounds() {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..100u32 {
            let x = f64::from(i).sin() * 10.0;
            let y = f64::from(i).cos() * 3.0;
            let base = positions.len() as u32;
            positions.push(DVec3::new(x, y, 0.0));
            positions.push(DVec3::new(x + 1.0, y, 0.5));
            positions.push(DVec3::new(x, y + 1.0, f64::from(i) * 0.1));
            triangles.push([base, base + 1, base + 2]);
        }
        let bvh = Bvh::build(&positions, &triangles);
        let mut seen = vec![0u32; triangles.len()];
        for node in &bvh.nodes {
            if node.is_leaf() {
                let s = node.start as usize;
                for &t in &bvh.order[s..s + node.count as usize] {
                    seen[t as usize] += 1;
                    for &v in &triangles[t as usize] {
                        let p = positions[v as usize];
                        assert!(p.cmpge(node.bounds.min).all() && p.cmple(node.bounds.max).all());
                    }
                }
            }
        }
        assert!(seen.iter().all(|&c| c == 1));
    }

    #[test]
    fn segment_crossing_a_triangle_reports_its_parameter_and_side() {
        let positions = vec![
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(2.0, -1.0, 0.0),
            DVec3::new(-1.0, 2.0, 0.0),
        ];
        let triangles = vec![[0, 1, 2]];
        let bvh = Bvh::build(&positions, &triangles);
        let mut hits = Vec::new();
        bvh.segment_hits(
            &positions,
            &triangles,
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(0.0, 0.0, -3.0),
            &mut hits,
        );
        assert_eq!(hits.len(), 1);
        assert!((hits[0].0 - 0.25).abs() < 1e-12);
        // Normal is +z, the segment goes down: it enters through the front.
        assert_eq!(hits[0].1, 1);
    }
}
