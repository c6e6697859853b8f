//! Sub-triangles of a regular 1-to-4 subdivision, named by one `u32`, and
//! the per-triangle build with merging (Šik & Křivánek 2013, Sec. 3.4 and
//! Fig. 4).
//!
//! At level `L` a triangle is cut into `4^L` sub-triangles on a grid of
//! step `h = 2^-L` in its barycentric coordinates `(u, v)` (the weights of
//! its second and third corner). The grid has "up" triangles with corners
//! `h·(i, j), h·(i+1, j), h·(i, j+1)` and "down" triangles with corners
//! `h·(i+1, j+1), h·(i, j+1), h·(i+1, j)`. A code holds the level, the
//! orientation and `(i, j)`, so its corners come out in O(1), with no
//! per-level table. The grid is hierarchical: the four children of up
//! `(I, J)` are up `(2I, 2J)`, `(2I+1, 2J)`, `(2I, 2J+1)` and down
//! `(2I, 2J)`; those of down `(I, J)` are down `(2I+1, 2J+1)`,
//! `(2I, 2J+1)`, `(2I+1, 2J)` and up `(2I+1, 2J+1)`.

/// The deepest level a code can name: `(i, j)` take 13 bits each.
pub(crate) const MAX_LEVEL: u8 = 13;

const BITS: u32 = 13;
const MASK: u32 = (1 << BITS) - 1;
const DOWN: u32 = 1 << 26;
const LEVEL_SHIFT: u32 = 27;
/// Marks the per-vertex component of a linear density (low bits: corner).
const VERTEX: u32 = 1 << 31;

/// One sub-triangle of a mesh triangle, or one corner component of a
/// linear per-vertex density.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct SubTriangle(u32);

impl SubTriangle {
    /// The whole triangle.
    pub(crate) const ROOT: Self = Self(0);

    pub(crate) fn new(level: u8, i: u32, j: u32, down: bool) -> Self {
        debug_assert!(level <= MAX_LEVEL && i <= MASK && j <= MASK);
        Self((u32::from(level) << LEVEL_SHIFT) | (u32::from(down) * DOWN) | (i << BITS) | j)
    }

    /// The component "density proportional to the barycentric weight of
    /// `corner`" of a linear density.
    pub(crate) fn vertex(corner: usize) -> Self {
        Self(VERTEX | corner as u32)
    }

    /// The corner, for a vertex component.
    pub(crate) fn corner(self) -> Option<usize> {
        (self.0 & VERTEX != 0).then_some((self.0 & 3) as usize)
    }

    pub(crate) fn level(self) -> u8 {
        ((self.0 >> LEVEL_SHIFT) & 0xf) as u8
    }

    fn i(self) -> u32 {
        (self.0 >> BITS) & MASK
    }

    fn j(self) -> u32 {
        self.0 & MASK
    }

    fn down(self) -> bool {
        self.0 & DOWN != 0
    }

    /// The grid position and orientation `(i, j, down)`.
    pub(crate) fn grid(self) -> (u32, u32, bool) {
        (self.i(), self.j(), self.down())
    }

    /// The fraction of the parent triangle's area: `4^-level`.
    pub(crate) fn area_fraction(self) -> f64 {
        0.25f64.powi(i32::from(self.level()))
    }

    /// The four children, in the order the build visits them.
    pub(crate) fn children(self) -> [Self; 4] {
        let (l, i, j) = (self.level() + 1, 2 * self.i(), 2 * self.j());
        if self.down() {
            [
                Self::new(l, i + 1, j + 1, true),
                Self::new(l, i, j + 1, true),
                Self::new(l, i + 1, j, true),
                Self::new(l, i + 1, j + 1, false),
            ]
        } else {
            [
                Self::new(l, i, j, false),
                Self::new(l, i + 1, j, false),
                Self::new(l, i, j + 1, false),
                Self::new(l, i, j, true),
            ]
        }
    }

    /// Parent barycentrics `(u, v)` of the point with local coordinates
    /// `(a, b)` (`a, b ≥ 0`, `a + b ≤ 1`) along this sub-triangle's two
    /// legs.
    #[inline]
    pub(crate) fn to_parent(self, a: f64, b: f64) -> (f64, f64) {
        // h = 2^-level from its exponent bits (no division), and the
        // orientation as arithmetic (no branch: it is a coin flip the
        // predictor cannot learn on a random draw).
        let h = f64::from_bits((1023 - u64::from(self.level())) << 52);
        let (i, j) = (f64::from(self.i()), f64::from(self.j()));
        let d = f64::from((self.0 >> 26) & 1);
        let s = 1.0 - 2.0 * d;
        (h * (i + d + s * a), h * (j + d + s * b))
    }

    /// The barycenter, as parent `(u, v)`.
    pub(crate) fn barycenter(self) -> (f64, f64) {
        self.to_parent(1.0 / 3.0, 1.0 / 3.0)
    }

    /// The three corners, as parent `(u, v)`.
    pub(crate) fn corners(self) -> [(f64, f64); 3] {
        [
            self.to_parent(0.0, 0.0),
            self.to_parent(1.0, 0.0),
            self.to_parent(0.0, 1.0),
        ]
    }

    /// The level-`level` sub-triangle containing parent barycentrics
    /// `(u, v)` (clamped onto the triangle).
    pub(crate) fn locate(level: u8, u: f64, v: f64) -> Self {
        let n = 1u32 << level;
        let (x, y) = (u.max(0.0) * f64::from(n), v.max(0.0) * f64::from(n));
        let i = (x.floor() as u32).min(n - 1);
        let j = (y.floor() as u32).min(n - 1 - i);
        let down = x - f64::from(i) + (y - f64::from(j)) > 1.0 && i + j + 1 < n;
        Self::new(level, i, j, down)
    }

    /// The position of this sub-triangle in depth-first order among the
    /// level-`depth` sub-triangles (`depth ≥ level`), left-aligned: a
    /// node's key is that of its first level-`depth` descendant. Keys
    /// increase in the order [`build`] emits sub-triangles.
    pub(crate) fn key(self, depth: u8) -> u64 {
        let (mut i, mut j, mut down) = (self.i(), self.j(), self.down());
        let mut key = 0u64;
        for k in 0..self.level() {
            let (oi, oj) = (i & 1, j & 1);
            let digit = if down {
                if oi == 0 && oj == 0 {
                    down = false;
                    3
                } else {
                    (1 - oi) + 2 * (1 - oj)
                }
            } else if oi == 1 && oj == 1 {
                down = true;
                3
            } else {
                oi + 2 * oj
            };
            key |= u64::from(digit) << (2 * k);
            i >>= 1;
            j >>= 1;
        }
        key << (2 * (depth - self.level()))
    }
}

/// How the value of merged siblings is formed.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Merge {
    /// Their mean (keeps the mass: the approximate density).
    Mean,
    /// Their maximum (keeps an upper bound: the exact mode's proposal).
    Max,
}

/// What the build evaluates: the value of a leaf, and, for a node above
/// the leaves, its value if the density is constant over all of it (then
/// its subtree would merge into it anyway, and is not visited).
pub(crate) struct Values<V, C> {
    /// The value of a leaf.
    pub(crate) leaf: V,
    /// `Some(value)` when the node is known to be constant.
    pub(crate) constant: C,
}

/// Subdivides one triangle to `depth`, evaluates the leaves, and merges
/// four siblings into their parent when their values are equal, or within
/// `tolerance` relative to the largest, recursively. A node found constant
/// by `values.constant` is emitted whole, which gives the same result
/// without visiting its leaves. Appends the surviving sub-triangles with
/// their values to `out` in depth-first order; zero values are kept (the
/// caller drops them after merging, so zeros still merge).
pub(crate) fn build<V, C>(
    depth: u8,
    tolerance: f32,
    merge: Merge,
    values: &Values<V, C>,
    out: &mut Vec<(SubTriangle, f32)>,
) where
    V: Fn(SubTriangle) -> f32,
    C: Fn(SubTriangle) -> Option<f32>,
{
    visit(SubTriangle::ROOT, depth, tolerance, merge, values, out);
}

fn visit<V, C>(
    node: SubTriangle,
    depth: u8,
    tolerance: f32,
    merge: Merge,
    values: &Values<V, C>,
    out: &mut Vec<(SubTriangle, f32)>,
) where
    V: Fn(SubTriangle) -> f32,
    C: Fn(SubTriangle) -> Option<f32>,
{
    if node.level() == depth {
        out.push((node, (values.leaf)(node)));
        return;
    }
    // Worth asking only above subtrees of 16 leaves or more (and at the
    // root, where a constant face ends in one lookup).
    if (node.level() == 0 || depth - node.level() >= 2)
        && let Some(c) = (values.constant)(node)
    {
        out.push((node, c));
        return;
    }
    let start = out.len();
    for child in node.children() {
        visit(child, depth, tolerance, merge, values, out);
    }
    // Four leaves, all direct children, means no child was split.
    if out.len() != start + 4 {
        return;
    }
    let values = [0, 1, 2, 3].map(|k| out[start + k].1);
    let lo = values.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = values.iter().copied().fold(0.0f32, f32::max);
    if hi == lo || hi - lo <= tolerance * hi {
        let merged = match merge {
            Merge::Mean => (values.iter().map(|&v| f64::from(v)).sum::<f64>() * 0.25) as f32,
            Merge::Max => hi,
        };
        out.truncate(start);
        out.push((node, merged));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every leaf of a level, each exactly once, in key order.
    fn leaves(node: SubTriangle, depth: u8, out: &mut Vec<SubTriangle>) {
        if node.level() == depth {
            out.push(node);
        } else {
            for c in node.children() {
                leaves(c, depth, out);
            }
        }
    }

    #[test]
    fn children_tile_their_parent_and_keys_follow_the_visit_order() {
        for depth in 0..6u8 {
            let mut all = Vec::new();
            leaves(SubTriangle::ROOT, depth, &mut all);
            assert_eq!(all.len(), 1 << (2 * depth));
            let keys: Vec<u64> = all.iter().map(|s| s.key(depth)).collect();
            assert!(keys.windows(2).all(|w| w[0] < w[1]), "depth {depth}");
            assert_eq!(keys, (0..all.len() as u64).collect::<Vec<_>>());
            // Each leaf's barycenter lies in it, and locate finds it.
            for s in &all {
                let (u, v) = s.barycenter();
                assert_eq!(SubTriangle::locate(depth, u, v), *s);
            }
        }
    }

    #[test]
    fn a_child_lies_inside_its_parent() {
        let mut all = Vec::new();
        leaves(SubTriangle::ROOT, 3, &mut all);
        for s in all {
            for c in s.children() {
                for (u, v) in c.corners() {
                    // (u, v) is a convex combination of the parent corners.
                    let [p0, p1, p2] = s.corners();
                    let det = (p1.0 - p0.0) * (p2.1 - p0.1) - (p2.0 - p0.0) * (p1.1 - p0.1);
                    let a = ((u - p0.0) * (p2.1 - p0.1) - (p2.0 - p0.0) * (v - p0.1)) / det;
                    let b = ((p1.0 - p0.0) * (v - p0.1) - (u - p0.0) * (p1.1 - p0.1)) / det;
                    assert!(a >= -1e-12 && b >= -1e-12 && a + b <= 1.0 + 1e-12);
                }
                assert_eq!(
                    c.key(4) >> 2,
                    s.key(4) >> 2,
                    "a child extends its parent's key"
                );
            }
        }
    }

    fn leaves_only(
        leaf: impl Fn(SubTriangle) -> f32,
    ) -> Values<impl Fn(SubTriangle) -> f32, impl Fn(SubTriangle) -> Option<f32>> {
        Values {
            leaf,
            constant: |_| None,
        }
    }

    #[test]
    fn a_constant_node_is_emitted_whole_as_merging_would() {
        // Constant on the first level-1 child, varying elsewhere.
        let first = SubTriangle::ROOT.children()[0];
        let inside = |s: SubTriangle| {
            let (u, v) = s.barycenter();
            SubTriangle::locate(1, u, v) == first
        };
        let leaf = |s: SubTriangle| {
            if inside(s) {
                7.0
            } else {
                (s.key(4) % 5) as f32
            }
        };
        let mut full = Vec::new();
        build(4, 0.0, Merge::Mean, &leaves_only(leaf), &mut full);
        let asked = std::cell::Cell::new(0);
        let inside_leaves = std::cell::Cell::new(0);
        let values = Values {
            leaf: |s: SubTriangle| {
                inside_leaves.set(inside_leaves.get() + usize::from(inside(s)));
                leaf(s)
            },
            constant: |s: SubTriangle| {
                asked.set(asked.get() + 1);
                (s == first).then_some(7.0)
            },
        };
        let mut fast = Vec::new();
        build(4, 0.0, Merge::Mean, &values, &mut fast);
        assert_eq!(fast, full);
        assert_eq!(inside_leaves.get(), 0, "the constant child was subdivided");
        // The root, its four children, and the level-2 nodes of the three
        // varying ones (level 3 nodes have only 4 leaves: not asked).
        assert_eq!(asked.get(), 1 + 4 + 12);
    }

    #[test]
    fn equal_siblings_merge_recursively_and_unequal_ones_do_not() {
        let mut out = Vec::new();
        build(4, 0.0, Merge::Mean, &leaves_only(|_| 2.0), &mut out);
        assert_eq!(out, vec![(SubTriangle::ROOT, 2.0)]);
        // A value that depends on the first level-1 child only.
        out.clear();
        let first = SubTriangle::ROOT.children()[0];
        let value = |s: SubTriangle| {
            let (u, v) = s.barycenter();
            if SubTriangle::locate(1, u, v) == first {
                if s.key(3).is_multiple_of(2) { 1.0 } else { 3.0 }
            } else {
                5.0
            }
        };
        build(3, 0.0, Merge::Mean, &leaves_only(value), &mut out);
        // 16 leaves in the first child, three merged level-1 siblings.
        assert_eq!(out.len(), 16 + 3);
        assert!(out.windows(2).all(|w| w[0].0.key(3) < w[1].0.key(3)));
        out.clear();
        // 0.7 merges 1 with 3 (into 2), then 2 with 5: the mean keeps the
        // mass, the maximum keeps the bound.
        build(3, 0.7, Merge::Mean, &leaves_only(value), &mut out);
        assert_eq!(out, vec![(SubTriangle::ROOT, 4.25)]);
        out.clear();
        build(3, 0.7, Merge::Max, &leaves_only(value), &mut out);
        assert_eq!(out, vec![(SubTriangle::ROOT, 5.0)]);
        out.clear();
        build(3, 0.5, Merge::Mean, &leaves_only(value), &mut out);
        assert_eq!(out.len(), 16 + 3, "0.5 merges nothing");
    }
}
