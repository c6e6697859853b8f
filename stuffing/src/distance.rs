//! How far the stuffed boundary lies from the input surface: the
//! symmetric Hausdorff distance and the mean distance, sampled on both
//! surfaces, as meshing papers and tools (Metro, fTetWild's envelope)
//! report it.
//!
//! Only the part of the input that encloses volume is held to the
//! boundary: a triangle whose two sides have the same inside/outside
//! status by the winding number (an open sheet, a fin, a doubled wall)
//! bounds nothing, so the stuffing leaves it out and
//! [`SurfaceDistance::left_out_triangles`] counts it instead. The other
//! direction measures the boundary against every input triangle, except
//! where the boundary caps a hole of the input: there the ½ level set runs
//! through space the input does not reach, and its distance is the hole's
//! size, not an error of the mesh. A boundary point counts as on a cap when
//! it lies farther than [`CAP_MIN_DISTANCE`] of the diagonal from the input
//! and the winding number there is between ¼ and ¾ ([`on_hole_cap`]): along
//! the input the winding number jumps by 1 across its triangles, so a
//! boundary point off them (a chord across a concavity or a thin part)
//! sees nearly 0 or 1, whereas over a hole no triangle separates the
//! sides and it stays near ½. Cap points are reported apart
//! ([`SurfaceDistance::hole_caps`], [`SurfaceDistance::hole_caps_to_input`]),
//! not hidden.
//!
//! Sampling is deterministic: point `i` of `n` falls in the triangle where
//! the area's cumulative sum passes `(i + ½) / n` (stratified by area) at
//! the barycentrics of the `i`-th point of the R₂ sequence (Roberts 2018),
//! so the same surfaces give the same figures on any number of threads.
//! The vertices are added when there are no more of them than samples, so
//! tips and corners, where the largest distances hide, are measured.

use glam::DVec3;
use rayon::prelude::*;

use crate::bvh::{Aabb, Bvh};
use crate::winding::{WindingNumber, solid_angle};

/// Distances between the stuffed boundary and the input surface, in the
/// surface's length unit, sampled on both surfaces (deterministically:
/// stratified by area, plus the vertices when there are no more of them
/// than samples), the input only where it encloses volume.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceDistance {
    /// The symmetric Hausdorff distance: the larger of
    /// [`input_to_tets`](Self::input_to_tets) and
    /// [`tets_to_input`](Self::tets_to_input).
    pub hausdorff: f64,
    /// The largest distance from a sampled point of the input (where it
    /// encloses volume) to the boundary: the parts of the input the
    /// tetrahedra miss, such as thin parts.
    pub input_to_tets: f64,
    /// The largest distance from a sampled point of the boundary to the
    /// input, over the points not on hole caps (see the module docs).
    pub tets_to_input: f64,
    /// The share of the boundary's sampled points, 0 to 1, that lie on caps
    /// over holes of the input (farther than [`CAP_MIN_DISTANCE`] of the
    /// diagonal from it, winding number between ¼ and ¾): left out of
    /// `tets_to_input` and of the mean. 0 on a closed input.
    pub hole_caps: f64,
    /// The largest distance from a cap point to the input (0 without caps):
    /// about the size of the largest hole.
    pub hole_caps_to_input: f64,
    /// The mean over both directions' samples (cap points left out) of the
    /// distance to the other surface.
    pub mean: f64,
    /// The length of the diagonal of the input's bounding box (of the
    /// vertices triangles use), the scale the figures are usually quoted
    /// against.
    pub diagonal: f64,
    /// Points measured on the input (samples plus vertices).
    pub input_samples: usize,
    /// Points measured on the boundary (samples plus vertices).
    pub boundary_samples: usize,
    /// Input triangles of positive area that enclose no volume (the
    /// winding number is on the same side of ½ in front and behind): left
    /// out of the tetrahedra and of `input_to_tets`.
    pub left_out_triangles: usize,
    /// Their share of the input's area, 0 to 1.
    pub left_out_area: f64,
}

impl SurfaceDistance {
    /// [`hausdorff`](Self::hausdorff) as a fraction of the
    /// [`diagonal`](Self::diagonal) (0 for a degenerate diagonal).
    pub fn hausdorff_fraction(&self) -> f64 {
        fraction(self.hausdorff, self.diagonal)
    }

    /// [`mean`](Self::mean) as a fraction of the [`diagonal`](Self::diagonal).
    pub fn mean_fraction(&self) -> f64 {
        fraction(self.mean, self.diagonal)
    }
}

fn fraction(x: f64, diagonal: f64) -> f64 {
    if diagonal > 0.0 { x / diagonal } else { 0.0 }
}

/// A triangle surface with the tree its nearest-point queries walk.
pub(crate) struct Surface<'a> {
    pub(crate) positions: &'a [DVec3],
    pub(crate) triangles: &'a [[u32; 3]],
    pub(crate) bvh: &'a Bvh,
}

impl Surface<'_> {
    fn corners(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|v| self.positions[v as usize])
    }

    /// The distance from `q` to the nearest point of the surface.
    fn distance(&self, q: DVec3) -> f64 {
        self.nearest(q).1.sqrt()
    }

    /// The nearest point of the surface to `q`, its squared distance and
    /// its triangle (`q`, infinity and `u32::MAX` for a surface without
    /// triangles).
    pub(crate) fn nearest(&self, q: DVec3) -> (DVec3, f64, u32) {
        let mut best = f64::INFINITY;
        let mut point = q;
        let mut triangle = u32::MAX;
        // Depth-first, nearer child first; the tree's depth is below 40.
        let mut stack = [(0u32, 0.0f64); 64];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let (n, d2) = stack[len];
            if d2 >= best {
                continue;
            }
            let node = &self.bvh.nodes[n as usize];
            if node.is_leaf() {
                let s = node.start as usize;
                for &t in &self.bvh.order[s..s + node.count as usize] {
                    let [a, b, c] = self.corners(t as usize);
                    let p = closest_point_on_triangle(q, a, b, c);
                    let d2 = p.distance_squared(q);
                    if d2 < best {
                        best = d2;
                        point = p;
                        triangle = t;
                    }
                }
                continue;
            }
            let [l, r] = node.children;
            let dl = box_distance2(&self.bvh.nodes[l as usize].bounds, q);
            let dr = box_distance2(&self.bvh.nodes[r as usize].bounds, q);
            let (near, far) = if dl <= dr {
                ((l, dl), (r, dr))
            } else {
                ((r, dr), (l, dl))
            };
            stack[len] = far;
            stack[len + 1] = near;
            len += 2;
        }
        (point, best, triangle)
    }

    /// Whether some triangle has a point within `r` of `q`: the same answer
    /// as `nearest(q).1.sqrt() <= r` (the smallest square root is the
    /// square root of the smallest square), found without looking past
    /// `r`, and done at the first triangle that is near enough.
    pub(crate) fn within(&self, q: DVec3, r: f64) -> bool {
        // Boxes farther than this cannot hold such a triangle; the margin
        // keeps a rounding of the box distance from pruning one that does.
        let reach2 = r * r * (1.0 + 1e-9) + f64::MIN_POSITIVE;
        let mut stack = [0u32; 64];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let node = &self.bvh.nodes[stack[len] as usize];
            if box_distance2(&node.bounds, q) > reach2 {
                continue;
            }
            if node.is_leaf() {
                let s = node.start as usize;
                for &t in &self.bvh.order[s..s + node.count as usize] {
                    let [a, b, c] = self.corners(t as usize);
                    if closest_point_on_triangle(q, a, b, c)
                        .distance_squared(q)
                        .sqrt()
                        <= r
                    {
                        return true;
                    }
                }
                continue;
            }
            // The nearer child on top, as `nearest` visits them.
            let [l, rr] = node.children;
            let dl = box_distance2(&self.bvh.nodes[l as usize].bounds, q);
            let dr = box_distance2(&self.bvh.nodes[rr as usize].bounds, q);
            let (near, far) = if dl <= dr { (l, rr) } else { (rr, l) };
            stack[len] = far;
            stack[len + 1] = near;
            len += 2;
        }
        false
    }

    /// `n` points spread over the triangles `chosen` by area (see the
    /// module docs), plus the vertices those triangles use when there are
    /// at most `n` of them.
    pub(crate) fn sample(&self, chosen: &[u32], n: usize) -> Vec<DVec3> {
        let mut cumulative = Vec::with_capacity(chosen.len());
        let mut total = 0.0;
        for &t in chosen {
            total += area(self.corners(t as usize));
            cumulative.push(total);
        }
        let mut points = Vec::new();
        if total > 0.0 {
            points.extend((0..n).map(|i| {
                let target = (i as f64 + 0.5) / n as f64 * total;
                let k = cumulative
                    .partition_point(|&c| c <= target)
                    .min(chosen.len() - 1);
                let [a, b, c] = self.corners(chosen[k] as usize);
                let (u, v) = r2(i);
                // Uniform on the triangle (Turk 1990's square-root map).
                let s = u.sqrt();
                a * (1.0 - s) + b * (s * (1.0 - v)) + c * (s * v)
            }));
        }
        let mut used: Vec<u32> = chosen
            .iter()
            .flat_map(|&t| self.triangles[t as usize])
            .collect();
        used.sort_unstable();
        used.dedup();
        if used.len() <= n {
            points.extend(used.iter().map(|&v| self.positions[v as usize]));
        }
        points
    }
}

/// The `i`-th point of the R₂ sequence in the unit square (Roberts 2018:
/// additive recurrence on the inverse powers of the plastic number).
fn r2(i: usize) -> (f64, f64) {
    const G: f64 = 1.324_717_957_244_746;
    let x = 0.5 + i as f64 / G;
    let y = 0.5 + i as f64 / (G * G);
    (x.fract(), y.fract())
}

fn area([a, b, c]: [DVec3; 3]) -> f64 {
    0.5 * (b - a).cross(c - a).length()
}

/// Squared distance from `q` to the box (0 inside).
fn box_distance2(b: &Aabb, q: DVec3) -> f64 {
    let d = (b.min - q).max(q - b.max).max(DVec3::ZERO);
    d.length_squared()
}

/// The point of the triangle `abc` nearest to `q`, by the Voronoi regions
/// of its vertices, edges and face (Ericson, Real-Time Collision Detection,
/// Sec. 5.1.5). Degenerate triangles fall into an edge or vertex region.
pub(crate) fn closest_point_on_triangle(q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = q - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = q - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = q - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom.is_nan() || denom <= 0.0 {
        // Collinear corners that no region above took: the nearest of
        // the three edges' points.
        return [
            closest_on_segment(q, a, b),
            closest_on_segment(q, b, c),
            closest_on_segment(q, c, a),
        ]
        .into_iter()
        .min_by(|x, y| x.distance_squared(q).total_cmp(&y.distance_squared(q)))
        .unwrap_or(a);
    }
    a + ab * (vb / denom) + ac * (vc / denom)
}

fn closest_on_segment(q: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let d = b - a;
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return a;
    }
    a + d * ((q - a).dot(d) / len2).clamp(0.0, 1.0)
}

/// Whether a triangle bounds the region `w > ½`: the winding number just
/// in front of it and just behind are on different sides of ½. Across the
/// triangle the winding number jumps by exactly 1 (its own solid angle
/// goes from −2π in front to 2π behind), so with `w₀`, the other
/// triangles' winding number at its centroid, the two sides are `w₀ ∓ ½`
/// and the test is `0 < w₀ ≤ 1`: one evaluation. (The triangle's own
/// term at its centroid is ±2π by the sign of a rounded zero; it is taken
/// out exactly as the sum computed it: a point on the triangle is never in
/// a far-field cluster of it.) The test's margin, ½ on a closed surface,
/// allows the coarsest series (β = 1), which keeps the exact near field,
/// the costly part of a query on the surface, small.
pub(crate) fn encloses_volume(wn: &WindingNumber, [a, b, c]: [DVec3; 3]) -> bool {
    let doubled_area = (b - a).cross(c - a).length();
    // Zero, or NaN from overflow: no sides to tell apart.
    if !(doubled_area.is_finite() && doubled_area > 0.0) {
        return false;
    }
    let q = (a + b + c) / 3.0;
    let own = solid_angle(a - q, b - q, c - q) / (4.0 * std::f64::consts::PI);
    let w = wn.fast_with(q, 1.0) - own;
    w > 0.0 && w <= 1.0
}

/// Whether a point of the ½ level set (a stuffed boundary) lies on a cap
/// over a hole of the input rather than along the input: there the winding
/// number is near ½ (between ¼ and ¾, [`CAP_WINDING`]) because no input
/// triangle separates inside from outside, whereas along the input it
/// jumps by 1 across the triangles and a boundary point a discretization
/// step off them sees nearly 0 or 1.
pub(crate) fn on_hole_cap(wn: &WindingNumber, q: DVec3) -> bool {
    let w = wn.fast(q);
    (CAP_WINDING.0..CAP_WINDING.1).contains(&w)
}

/// The winding numbers, exclusive, between which a boundary point farther
/// than [`CAP_MIN_DISTANCE`] from the input counts as capping a hole of
/// it (see [`SurfaceDistance::hole_caps`]).
pub const CAP_WINDING: (f64, f64) = (0.25, 0.75);

/// Samples per parallel chunk: fixed, so the sum's order (and the mean's
/// last bits) does not depend on the number of threads.
const CHUNK: usize = 4096;

/// The boundary distance a point must exceed before it can count as on a
/// hole cap, as a fraction of the diagonal (the default envelope,
/// 2·10⁻³): nearer points are along the input for every purpose here, and
/// the winding number is evaluated only for the farther ones.
pub const CAP_MIN_DISTANCE: f64 = 2e-3;

/// How [`one_way`] tells cap points apart.
struct Caps<'a> {
    wn: &'a WindingNumber,
    /// [`CAP_MIN_DISTANCE`] in the input's unit.
    min_distance: f64,
}

/// Points left out as on hole caps: how many and their largest distance.
#[derive(Default, Clone, Copy)]
struct CapPoints {
    count: usize,
    max: f64,
}

/// The largest and the summed distance from `points` to `surface`, over
/// the points not on hole caps when `caps` is given, and those cap points.
fn one_way(
    points: &[DVec3],
    surface: &Surface<'_>,
    caps: Option<&Caps<'_>>,
) -> (f64, f64, CapPoints) {
    let partial: Vec<(f64, f64, CapPoints)> = points
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut cap = CapPoints::default();
            let (max, sum) = chunk.iter().fold((0.0f64, 0.0f64), |(max, sum), &p| {
                let d = surface.distance(p);
                if caps.is_some_and(|c| d > c.min_distance && on_hole_cap(c.wn, p)) {
                    cap.count += 1;
                    cap.max = cap.max.max(d);
                    return (max, sum);
                }
                (max.max(d), sum + d)
            });
            (max, sum, cap)
        })
        .collect();
    partial.iter().fold(
        (0.0, 0.0, CapPoints::default()),
        |(max, sum, cap), &(m, s, c)| {
            let cap = CapPoints {
                count: cap.count + c.count,
                max: cap.max.max(c.max),
            };
            (max.max(m), sum + s, cap)
        },
    )
}

/// Per triangle of the input `wn` was built on, whether it encloses volume
/// ([`encloses_volume`]): one winding number each, computed once and shared
/// by the envelope fit and the measurement.
pub(crate) fn bounding_triangles(wn: &WindingNumber) -> Vec<bool> {
    let p = wn.positions();
    wn.triangles()
        .par_iter()
        .map(|t| encloses_volume(wn, t.map(|v| p[v as usize])))
        .collect()
}

/// Measures the boundary `(positions, boundary)` against the input
/// surface `wn` was built on, with `samples` points on each surface (plus
/// their vertices when there are no more of them); `bounding` is
/// [`bounding_triangles`] of `wn`.
pub(crate) fn measure(
    wn: &WindingNumber,
    bounding: &[bool],
    positions: &[DVec3],
    boundary: &[[u32; 3]],
    samples: usize,
) -> SurfaceDistance {
    let input = Surface {
        positions: wn.positions(),
        triangles: wn.triangles(),
        bvh: wn.bvh(),
    };
    let output_bvh = Bvh::build(positions, boundary);
    let output = Surface {
        positions,
        triangles: boundary,
        bvh: &output_bvh,
    };
    let all_area: Vec<f64> = (0..input.triangles.len())
        .into_par_iter()
        .map(|t| area(input.corners(t)))
        .collect();
    let kept: Vec<u32> = (0..input.triangles.len() as u32)
        .filter(|&t| bounding[t as usize])
        .collect();
    let total_area: f64 = all_area.iter().sum();
    let (mut left_out, mut left_out_area) = (0, 0.0);
    for (t, &a) in all_area.iter().enumerate() {
        if !bounding[t] && a > 0.0 {
            left_out += 1;
            left_out_area += a;
        }
    }
    let on_input = input.sample(&kept, samples);
    let all: Vec<u32> = (0..output.triangles.len() as u32).collect();
    let on_boundary = output.sample(&all, samples);
    let mut bounds = Aabb::EMPTY;
    for t in input.triangles {
        for &v in t {
            bounds.grow(input.positions[v as usize]);
        }
    }
    let diagonal = (bounds.max - bounds.min).length();
    let (input_to_tets, sum_in, _) = one_way(&on_input, &output, None);
    let caps = Caps {
        wn,
        min_distance: CAP_MIN_DISTANCE * diagonal,
    };
    let (tets_to_input, sum_out, cap) = one_way(&on_boundary, &input, Some(&caps));
    let count = on_input.len() + on_boundary.len() - cap.count;
    SurfaceDistance {
        hausdorff: input_to_tets.max(tets_to_input),
        input_to_tets,
        tets_to_input,
        mean: if count > 0 {
            (sum_in + sum_out) / count as f64
        } else {
            0.0
        },
        hole_caps: fraction(cap.count as f64, on_boundary.len() as f64),
        hole_caps_to_input: cap.max,
        diagonal,
        input_samples: on_input.len(),
        boundary_samples: on_boundary.len(),
        left_out_triangles: left_out,
        left_out_area: fraction(left_out_area, total_area),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nearest point by brute force over a fine grid of barycentrics.
    fn brute(q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
        let n = 400;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let p = a + (b - a) * u + (c - a) * v;
                best = best.min(p.distance(q));
            }
        }
        best
    }

    #[test]
    fn the_nearest_point_of_a_triangle_matches_a_brute_force_search() {
        let (a, b, c) = (
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.2, 0.1),
            DVec3::new(0.3, 1.5, -0.2),
        );
        for k in 0..200 {
            let (x, y) = r2(k);
            let q = DVec3::new(4.0 * x - 1.0, 3.0 * y - 1.0, (k as f64 * 0.37).sin());
            let exact = closest_point_on_triangle(q, a, b, c).distance(q);
            // The grid's spacing bounds how far above the truth it can be.
            assert!(exact <= brute(q, a, b, c) + 1e-12, "{q}");
            assert!(brute(q, a, b, c) - exact < 0.01, "{q}");
        }
    }

    #[test]
    fn a_bounded_query_answers_as_the_nearest_point_does() {
        let (p, t) = crate::tests::sphere(16, 1.0, DVec3::ZERO);
        let bvh = Bvh::build(&p, &t);
        let s = Surface {
            positions: &p,
            triangles: &t,
            bvh: &bvh,
        };
        let mut near = 0;
        for k in 0..2000 {
            let (x, y) = r2(k);
            let q = DVec3::new(3.0 * x - 1.5, 3.0 * y - 1.5, (k as f64 * 0.37).sin() * 1.5);
            let d = s.nearest(q).1.sqrt();
            // Radii around the distance itself, where rounding decides.
            for r in [
                0.5 * d,
                d * (1.0 - 1e-15),
                d,
                d * (1.0 + 1e-15),
                2.0 * d + 1e-3,
            ] {
                assert_eq!(s.within(q, r), d <= r, "{q} at {r} (distance {d})");
            }
            near += usize::from(s.within(q, 0.1));
        }
        // Both answers occur.
        assert!(near > 50 && near < 1950, "{near}");
    }

    #[test]
    fn a_wrong_region_test_is_caught_by_the_same_check() {
        // The face projection for every point (no edge or vertex regions)
        // lands outside the triangle: the brute force rejects it.
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let q = DVec3::new(2.0, 2.0, 1.0);
        let wrong = DVec3::new(q.x, q.y, 0.0).distance(q);
        assert!(wrong + 1e-12 < brute(q, a, b, c));
        assert!(closest_point_on_triangle(q, a, b, c).distance(q) <= brute(q, a, b, c) + 1e-12);
    }

    #[test]
    fn every_triangle_of_a_closed_sphere_encloses_volume_and_no_triangle_of_a_sheet() {
        let (p, t) = crate::tests::sphere(24, 1.0, DVec3::ZERO);
        let sheet = [
            DVec3::new(3.0, 0.0, 0.0),
            DVec3::new(3.0, 1.0, 0.0),
            DVec3::new(3.0, 0.0, 1.0),
        ];
        let mut positions = p.clone();
        positions.extend(sheet);
        let n = p.len() as u32;
        let mut triangles = t.clone();
        triangles.push([n, n + 1, n + 2]);
        let wn = WindingNumber::new(&positions, &triangles, 2.0).unwrap();
        let corners = |f: &[u32; 3]| f.map(|v| positions[v as usize]);
        let kept = triangles
            .iter()
            .filter(|f| encloses_volume(&wn, corners(f)))
            .count();
        assert_eq!(kept, t.len());
        // The wrong twin: the sum at the centroid with the triangle's own
        // term left in, whose sign is a rounded zero's.
        let naive = |[a, b, c]: [DVec3; 3]| {
            let w = wn.fast_with((a + b + c) / 3.0, 1.0);
            w > 0.0 && w <= 1.0
        };
        let wrong = t.iter().filter(|f| naive(corners(f))).count();
        assert!(wrong < t.len(), "{wrong} of {}", t.len());
    }

    #[test]
    fn degenerate_triangles_give_the_nearest_point_of_their_segment() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        let q = DVec3::new(1.5, 1.0, 0.0);
        assert!((closest_point_on_triangle(q, a, b, c).distance(q) - 1.0).abs() < 1e-12);
        let p = DVec3::splat(3.0);
        assert_eq!(closest_point_on_triangle(DVec3::ZERO, p, p, p), p);
    }
}
