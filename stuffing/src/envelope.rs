//! Fitting the stuffed boundary to the input ([`super::Options::envelope`]):
//! boundary vertices moved onto the parts of the input the lattice cut
//! across, each move kept only if the tetrahedra around the vertex keep
//! their dihedral angles.
//!
//! Stuffing puts its boundary vertices on the ½ level set already (cut
//! points on the input triangles, warped vertices on cut points), so what
//! lies far from the boundary is what the lattice's triangles span across:
//! tips (ears, fingers, a spout's end), sharp creases (fandisk) and thin
//! parts narrower than the spacing. So the fit works from the input's side,
//! as a one-sided Hausdorff pass (the way envelope meshers such as
//! fTetWild hold their envelope, here with the lattice's connectivity
//! fixed):
//!
//! 1. points to hold: the vertices of the input triangles that enclose
//!    volume (the winding number decides, as for the measurement), points
//!    every `h / 4` along its sharp edges (two faces meeting at an interior
//!    angle below [`SHARP_DEG`]), and points spread over its area;
//! 2. each point farther than the envelope from the boundary, farthest
//!    first, pulls the boundary vertex nearest to it onto itself (or a half
//!    or a quarter of the way), once per vertex; a few rounds, each against
//!    the boundary as the last one left it;
//! 3. where points stay far, boundary edges near them are split with the
//!    new vertex on them ([`crate::refine`], driven by the same distances
//!    both ways);
//! 4. the other boundary vertices are projected onto their nearest point of
//!    the input (the same partial steps), which brings back the ones a
//!    chord between two pulled vertices left off the surface.
//!
//! A move is kept when every tetrahedron around the vertex keeps its
//! orientation and its dihedral angles within [`MIN_DIHEDRAL_DEG`]–
//! [`MAX_DIHEDRAL_DEG`] (or, for one already outside that range, gets no
//! worse). Moves are made one after another in a fixed order, so the
//! result does not depend on the number of threads. What the fit cannot
//! reach — a part with no boundary vertex within a spacing, or whose
//! tetrahedra the angle check will not let bend or split towards it —
//! stays missing, and [`super::Report::distance`] says by how much.

use glam::DVec3;
use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::distance::{Surface, closest_point_on_triangle};
use crate::mesh::Assembled;
use crate::quality::{dihedral_angles, signed_volume};
use crate::refine;
use crate::winding::WindingNumber;

/// The smallest dihedral angle, degrees, a fitted tetrahedron may have.
pub(crate) const MIN_DIHEDRAL_DEG: f64 = 10.0;
/// The largest dihedral angle, degrees, a fitted tetrahedron may have.
pub(crate) const MAX_DIHEDRAL_DEG: f64 = 165.0;
/// Interior angle, degrees, between two input faces below which their
/// common edge is a crease the boundary should follow.
pub(crate) const SHARP_DEG: f64 = 140.0;
/// Most points put along the creases (about 24 MB), whatever their length.
const MAX_CREASE_POINTS: usize = 1 << 20;
/// Fractions of a move tried, in order.
pub(crate) const STEPS: [f64; 4] = [1.0, 0.5, 0.25, 0.125];
/// Rounds of pulling vertices towards far input points.
const ROUNDS: usize = 8;
/// Farthest a vertex is moved, in lattice spacings: beyond it the point
/// belongs to a part the lattice did not reach (or lies across a hole).
const REACH: f64 = 1.0;

/// What the fit did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Fitted {
    /// Boundary vertices moved.
    pub(crate) moved: usize,
    /// Edges split by the refinement (their new vertices count as moved).
    pub(crate) split_edges: usize,
    /// Sharp input edges found.
    pub(crate) sharp_edges: usize,
}

/// Moves boundary vertices of the tetrahedral mesh `(positions, tets)`
/// with boundary `boundary` towards the input `wn` was built on, until
/// the input's sampled points lie within `eps` of the boundary or no move
/// is left that keeps the angles; `h` is the lattice spacing, `bounding`
/// the input triangles that enclose volume
/// ([`crate::distance::bounding_triangles`]).
pub(crate) fn fit(
    wn: &WindingNumber,
    bounding: &[bool],
    mesh: &mut Assembled,
    h: f64,
    eps: f64,
    max_tets: usize,
) -> Fitted {
    let input_positions = wn.positions();
    let kept: Vec<[u32; 3]> = wn
        .triangles()
        .iter()
        .zip(bounding)
        .filter_map(|(t, &b)| b.then_some(*t))
        .collect();
    if kept.is_empty() || mesh.boundary.is_empty() {
        return Fitted::default();
    }
    let sharp = sharp_edges(input_positions, &kept);
    // The winding number's tree is the same tree when every triangle
    // encloses volume (the usual case).
    let own_bvh;
    let input_bvh = if kept.len() == wn.triangles().len() {
        wn.bvh()
    } else {
        own_bvh = Bvh::build(input_positions, &kept);
        &own_bvh
    };
    let input = Surface {
        positions: input_positions,
        triangles: &kept,
        bvh: input_bvh,
    };
    let targets = points_to_hold(&input, &sharp, h, mesh.boundary.len());
    let (mut moved, mut touched) = pull_rounds(&input, mesh, &targets, h, eps);
    // What the moves could not reach: split edges near it (`refine`).
    let refined = refine::refine(wn, &input, mesh, &targets, eps, max_tets);
    moved.resize(mesh.positions.len(), false);
    touched.resize(mesh.positions.len(), false);
    for &v in &refined.on_input {
        moved[v as usize] = true;
    }
    let mut mover = Mover::new(&mesh.tets, &mesh.boundary, &input, eps, moved, touched);
    mover.project(&mut mesh.positions, &mesh.boundary, h);
    let touched = mover.touched.iter().filter(|&&m| m).count();
    Fitted {
        moved: touched + refined.splits,
        split_edges: refined.splits,
        sharp_edges: sharp.len(),
    }
}

/// Step 2: rounds of pulls on the stuffed mesh; the vertices pulled all
/// the way and those moved at all.
fn pull_rounds(
    input: &Surface<'_>,
    mesh: &mut Assembled,
    targets: &[DVec3],
    h: f64,
    eps: f64,
) -> (Vec<bool>, Vec<bool>) {
    let n = mesh.positions.len();
    let (moved, touched) = (vec![false; n], vec![false; n]);
    let mut mover = Mover::new(&mesh.tets, &mesh.boundary, input, eps, moved, touched);
    // Later rounds look again only at the points that were far and still
    // had a vertex to move: a pull uncovers at most half the distance it
    // closes (or `eps`), see `Mover::pull`.
    let mut far: Vec<u32> = (0..targets.len() as u32).collect();
    for _ in 0..ROUNDS {
        let moved;
        (far, moved) = mover.pull(&mut mesh.positions, &mesh.boundary, targets, &far, h, eps);
        if moved == 0 {
            break;
        }
    }
    (mover.moved, mover.touched)
}

/// Edges shared by exactly two of `triangles` whose faces meet at an
/// interior angle below [`SHARP_DEG`], as vertex pairs.
pub(crate) fn sharp_edges(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut edges: Vec<([u32; 2], u32)> = triangles
        .iter()
        .enumerate()
        .flat_map(|(t, tri)| {
            (0..3).map(move |k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                ([a.min(b), a.max(b)], t as u32)
            })
        })
        .collect();
    edges.par_sort_unstable();
    let normal = |t: u32| {
        let [a, b, c] = triangles[t as usize].map(|v| positions[v as usize]);
        (b - a).cross(c - a).normalize_or_zero()
    };
    // Interior angle θ between the faces: their normals are π − θ apart.
    let cos_limit = (std::f64::consts::PI - SHARP_DEG.to_radians()).cos();
    let mut out = Vec::new();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == edges[i].0 {
            j += 1;
        }
        if j - i == 2 {
            let (n0, n1) = (normal(edges[i].1), normal(edges[i + 1].1));
            if n0 != DVec3::ZERO && n1 != DVec3::ZERO && n0.dot(n1) < cos_limit {
                out.push(edges[i].0);
            }
        }
        i = j;
    }
    out
}

/// The input's points the boundary should come near (see the module
/// docs): vertices, points along sharp edges every `h / 4` (at most
/// [`MAX_CREASE_POINTS`] of them), and
/// `4 × boundary triangles` points spread by area (at most 2^18).
fn points_to_hold(
    surface: &Surface<'_>,
    sharp: &[[u32; 2]],
    h: f64,
    boundary_triangles: usize,
) -> Vec<DVec3> {
    let (positions, kept) = (surface.positions, surface.triangles);
    let mut used: Vec<u32> = kept.iter().flatten().copied().collect();
    used.par_sort_unstable();
    used.dedup();
    let mut points: Vec<DVec3> = used.iter().map(|&v| positions[v as usize]).collect();
    // Every h/4, or farther apart when the creases are so long that this
    // would be more than MAX_CREASE_POINTS.
    let length: f64 = sharp
        .iter()
        .map(|&[a, b]| positions[a as usize].distance(positions[b as usize]))
        .sum();
    let step = (0.25 * h).max(length / MAX_CREASE_POINTS as f64);
    for &[a, b] in sharp {
        let (pa, pb) = (positions[a as usize], positions[b as usize]);
        let steps = (pa.distance(pb) / step)
            .ceil()
            .min(MAX_CREASE_POINTS as f64) as usize;
        points.extend((1..steps).map(|k| pa.lerp(pb, k as f64 / steps as f64)));
    }
    let all: Vec<u32> = (0..kept.len() as u32).collect();
    let n = (4 * boundary_triangles).min(1 << 18);
    // `sample` adds the vertices again when there are few; they are
    // already in.
    points.extend(surface.sample(&all, n).into_iter().take(n));
    points
}

/// The elements (tetrahedra or triangles) around each vertex, as
/// compressed rows.
struct Incidence {
    start: Vec<u32>,
    elements: Vec<u32>,
}

impl Incidence {
    fn new<const N: usize>(vertices: usize, elements: &[[u32; N]]) -> Incidence {
        let mut start = vec![0u32; vertices + 1];
        for e in elements {
            for &v in e {
                start[v as usize + 1] += 1;
            }
        }
        for k in 0..vertices {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut list = vec![0u32; start[vertices] as usize];
        for (i, e) in elements.iter().enumerate() {
            for &v in e {
                list[fill[v as usize] as usize] = i as u32;
                fill[v as usize] += 1;
            }
        }
        Incidence {
            start,
            elements: list,
        }
    }

    fn of(&self, v: u32) -> &[u32] {
        &self.elements[self.start[v as usize] as usize..self.start[v as usize + 1] as usize]
    }
}

/// Moves vertices under the angle check.
struct Mover<'a> {
    tets: &'a [[u32; 4]],
    /// The tetrahedra around each vertex.
    incident: Incidence,
    boundary: &'a [[u32; 3]],
    /// The boundary triangles around each vertex.
    faces: Incidence,
    /// The input where it encloses volume.
    input: &'a Surface<'a>,
    /// The envelope, in the input's unit.
    eps: f64,
    /// Vertices pulled all the way onto an input point: not moved again.
    moved: Vec<bool>,
    /// Vertices moved at all.
    touched: Vec<bool>,
    /// The boundary triangles' distances from the input, kept between
    /// moves: a vertex's ring is measured again and again as points try
    /// it, while only moves change it.
    centroid_off: CentroidDistances,
}

impl<'a> Mover<'a> {
    /// A mover over the tetrahedra `tets` with boundary `boundary`, whose
    /// vertices are flagged in `moved` and `touched` (one flag each).
    fn new(
        tets: &'a [[u32; 4]],
        boundary: &'a [[u32; 3]],
        input: &'a Surface<'a>,
        eps: f64,
        moved: Vec<bool>,
        touched: Vec<bool>,
    ) -> Self {
        let vertices = moved.len();
        Mover {
            tets,
            incident: Incidence::new(vertices, tets),
            boundary,
            faces: Incidence::new(vertices, boundary),
            input,
            eps,
            moved,
            touched,
            centroid_off: CentroidDistances(vec![f64::NAN; boundary.len()]),
        }
    }

    /// One round of step 2: every point of `targets` (those indexed by
    /// `candidates`) farther than `eps` from the boundary, farthest first,
    /// pulls the nearest corner of its nearest boundary triangle that is
    /// free. Returns the indices of the points to look at next round and
    /// the number of vertices moved.
    fn pull(
        &mut self,
        positions: &mut [DVec3],
        boundary: &[[u32; 3]],
        targets: &[DVec3],
        candidates: &[u32],
        h: f64,
        eps: f64,
    ) -> (Vec<u32>, usize) {
        let bvh = Bvh::build(positions, boundary);
        let surface = Surface {
            positions,
            triangles: boundary,
            bvh: &bvh,
        };
        let mut far: Vec<(f64, [u32; 3], usize)> = candidates
            .par_iter()
            .filter_map(|&i| {
                let i = i as usize;
                let s = targets[i];
                // Most points are near: a bounded query says so for less.
                if surface.within(s, eps) {
                    return None;
                }
                let (_, d2, t) = surface.nearest(s);
                if d2 <= eps * eps || t == u32::MAX {
                    return None;
                }
                // The corners of the nearest triangle, nearest first.
                let mut corners = boundary[t as usize];
                corners.sort_by(|&a, &b| {
                    positions[a as usize]
                        .distance_squared(s)
                        .total_cmp(&positions[b as usize].distance_squared(s))
                        .then(a.cmp(&b))
                });
                Some((d2, corners, i))
            })
            .collect();
        far.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.2.cmp(&b.2)));
        let mut count = 0;
        // Vertices moved this round, against the boundary as it was.
        let mut busy = vec![false; positions.len()];
        // Points to look at again: those that moved a vertex, or found
        // their corners busy. A point none of whose corners could move
        // (angles, reach) is given up.
        let mut again = Vec::new();
        for (d2, corners, i) in far {
            // The nearest corner that is free and can move, if any.
            let mut waiting = false;
            for v in corners {
                if self.moved[v as usize] || positions[v as usize].distance(targets[i]) > REACH * h
                {
                    continue;
                }
                if busy[v as usize] {
                    waiting = true;
                    continue;
                }
                // The pull must not uncover more of the input around the
                // vertex's old place than it covers at the point.
                let exposure = eps.max(0.5 * d2.sqrt());
                if let Some(step) = self.try_move(positions, v, targets[i], exposure) {
                    self.touched[v as usize] = true;
                    busy[v as usize] = true;
                    // A vertex that got all the way is done; one that got
                    // part of the way may go on next round.
                    self.moved[v as usize] = step == 1.0;
                    count += 1;
                    waiting = true;
                    break;
                }
            }
            if waiting {
                again.push(i as u32);
            }
        }
        again.sort_unstable();
        (again, count)
    }

    /// Step 3: boundary vertices not pulled onto their nearest input point.
    fn project(&mut self, positions: &mut [DVec3], boundary: &[[u32; 3]], h: f64) {
        let mut vertices: Vec<u32> = boundary.iter().flatten().copied().collect();
        vertices.sort_unstable();
        vertices.dedup();
        vertices.retain(|&v| !self.moved[v as usize]);
        // Each vertex's nearest input point, all found at once: a move
        // changes only the moved vertex's position, so where each one
        // stands when its turn comes is where it stands now.
        let nearest: Vec<(DVec3, f64)> = vertices
            .par_iter()
            .map(|&v| {
                let (q, d2, _) = self.input.nearest(positions[v as usize]);
                (q, d2)
            })
            .collect();
        for (v, (q, d2)) in vertices.into_iter().zip(nearest) {
            // Already on the surface (cut points are), or too far to be
            // this part of it (across a hole).
            if d2 <= (1e-9 * h).powi(2) || d2 > (0.5 * REACH * h).powi(2) {
                continue;
            }
            if self.try_move(positions, v, q, f64::INFINITY).is_some() {
                self.touched[v as usize] = true;
            }
        }
    }

    /// Moves `v` to `target`, or the largest of [`STEPS`] of the way there
    /// that keeps the angle check, leaves `v`'s old place within
    /// `exposure` of its new boundary triangles, and keeps those triangles
    /// as near the input as they were (or within the envelope); the step
    /// taken, if any.
    fn try_move(
        &mut self,
        positions: &mut [DVec3],
        v: u32,
        target: DVec3,
        exposure: f64,
    ) -> Option<f64> {
        let from = positions[v as usize];
        let around = self.incident.of(v);
        // Computed when a step first gets this far (it costs queries).
        let mut off_before = None;
        'steps: for s in STEPS {
            let to = from.lerp(target, s);
            for &t in around {
                let ids = self.tets[t as usize];
                let before = ids.map(|u| positions[u as usize]);
                let after = ids.map(|u| if u == v { to } else { positions[u as usize] });
                if !keeps_angles(before, after) {
                    continue 'steps;
                }
            }
            if exposure.is_finite() {
                let uncovered = self
                    .faces
                    .of(v)
                    .iter()
                    .map(|&f| {
                        let [a, b, c] = self.boundary[f as usize]
                            .map(|u| if u == v { to } else { positions[u as usize] });
                        closest_point_on_triangle(from, a, b, c).distance(from)
                    })
                    .fold(f64::INFINITY, f64::min);
                if uncovered > exposure {
                    continue 'steps;
                }
            }
            let before = match off_before {
                Some(d) => d,
                None => *off_before.insert(self.centroid_off.ring(
                    &self.faces,
                    self.boundary,
                    self.input,
                    positions,
                    v,
                )),
            };
            if !self.ring_within(positions, v, to, before.max(self.eps)) {
                continue;
            }
            positions[v as usize] = to;
            self.centroid_off.forget(&self.faces, v);
            return Some(s);
        }
        None
    }
}

impl Mover<'_> {
    /// Whether every boundary triangle around `v`, with `v` at `at`, has
    /// its centroid within `limit` of the input: the same answer as
    /// [`CentroidDistances::ring`] `<= limit`, with bounded queries that stop at
    /// the first triangle near enough (the fit's most frequent query). A
    /// triangle whose kept distance plus the way its centroid moves is
    /// within `limit` (with a margin far above rounding) needs no query:
    /// the distance to a surface changes by at most the way moved.
    fn ring_within(&self, positions: &[DVec3], v: u32, at: DVec3, limit: f64) -> bool {
        let shift = positions[v as usize].distance(at) / 3.0;
        self.faces.of(v).iter().all(|&f| {
            if self.centroid_off.surely_within(f, shift, limit) {
                return true;
            }
            let corners =
                self.boundary[f as usize].map(|u| if u == v { at } else { positions[u as usize] });
            let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
            self.input.within(centroid, limit)
        })
    }
}

/// Relative margin below a limit within which [`CentroidDistances::surely_within`]
/// still asks the query rather than trusting its bound: far above the
/// rounding of the bound (about 1e-15), so its answers are the query's.
const SHIFT_MARGIN: f64 = 1e-9;

/// Per boundary triangle, the squared distance of its centroid from the
/// input, once asked for (NaN before, and again once a corner moves).
struct CentroidDistances(Vec<f64>);

impl CentroidDistances {
    /// How far the boundary triangles around `v` lie from the input: the
    /// largest distance of their centroids.
    fn ring(
        &mut self,
        faces: &Incidence,
        boundary: &[[u32; 3]],
        input: &Surface<'_>,
        positions: &[DVec3],
        v: u32,
    ) -> f64 {
        let mut off: f64 = 0.0;
        for &f in faces.of(v) {
            let known = &mut self.0[f as usize];
            if known.is_nan() {
                let corners = boundary[f as usize].map(|u| positions[u as usize]);
                let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
                *known = input.nearest(centroid).1;
            }
            off = off.max(*known);
        }
        off.sqrt()
    }

    /// Whether triangle `f`'s centroid, moved by `shift`, is surely
    /// within `limit` of the input by its kept distance alone (false when
    /// none is kept, or when only a query can tell).
    fn surely_within(&self, f: u32, shift: f64, limit: f64) -> bool {
        self.0[f as usize].sqrt() + shift <= limit * (1.0 - SHIFT_MARGIN)
    }

    /// `v` moved: its triangles' distances are no longer known.
    fn forget(&mut self, faces: &Incidence, v: u32) {
        for &f in faces.of(v) {
            self.0[f as usize] = f64::NAN;
        }
    }
}

/// Whether a positively oriented tetrahedron moved from `before` to
/// `after` stays positive with its angles within the fit's range, or no
/// worse than before where it already was outside it.
pub(crate) fn keeps_angles(before: [DVec3; 4], after: [DVec3; 4]) -> bool {
    if signed_volume(after) <= 0.0 {
        return false;
    }
    // Most moves keep every angle well inside the range: their cosines say
    // so without an arc cosine. Near a bound the exact test decides.
    if surely_within(after) {
        return true;
    }
    keeps_angles_exactly(before, after)
}

/// How far inside the bounds a dihedral angle's cosine must be for
/// [`surely_within`] to decide: far above the rounding of either way of
/// computing it (about 1e-15), so its answer is the exact test's.
const COSINE_MARGIN: f64 = 1e-9;

/// Whether every dihedral angle of the positively oriented tetrahedron
/// `p` is surely within [`MIN_DIHEDRAL_DEG`]–[`MAX_DIHEDRAL_DEG`]: at edge
/// `(i, j)`, the interior angle's cosine is minus the dot product of the
/// outward unit normals of the two faces through it (the faces opposite
/// the other two vertices). False when unsure (near a bound, or NaN).
fn surely_within(p: [DVec3; 4]) -> bool {
    let lo = MIN_DIHEDRAL_DEG.to_radians().cos() - COSINE_MARGIN;
    let hi = MAX_DIHEDRAL_DEG.to_radians().cos() + COSINE_MARGIN;
    // The outward normal of the face opposite vertex k.
    let normal = |k: usize| {
        let [a, b, c] = [(k + 1) % 4, (k + 2) % 4, (k + 3) % 4].map(|v| p[v]);
        let n = (b - a).cross(c - a).normalize();
        if n.dot(p[k] - a) > 0.0 { -n } else { n }
    };
    let n = [normal(0), normal(1), normal(2), normal(3)];
    (0..4).all(|k| {
        (k + 1..4).all(|l| {
            let cos = -n[k].dot(n[l]);
            cos <= lo && cos >= hi
        })
    })
}

/// [`keeps_angles`] by the angles themselves (for a tetrahedron with
/// positive volume).
fn keeps_angles_exactly(before: [DVec3; 4], after: [DVec3; 4]) -> bool {
    // None for a degenerate tetrahedron (NaN angles).
    let range = |p: [DVec3; 4]| {
        let a = dihedral_angles(p).map(f64::to_degrees);
        if a.iter().any(|d| d.is_nan()) {
            return None;
        }
        Some(a.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &d| {
            (lo.min(d), hi.max(d))
        }))
    };
    let Some((lo, hi)) = range(after) else {
        return false;
    };
    if lo >= MIN_DIHEDRAL_DEG && hi <= MAX_DIHEDRAL_DEG {
        return true;
    }
    let (lo0, hi0) = range(before).unwrap_or((0.0, 180.0));
    lo >= MIN_DIHEDRAL_DEG.min(lo0) && hi <= MAX_DIHEDRAL_DEG.max(hi0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tests::{cuboid, sphere};

    /// A regular tetrahedron, positively oriented.
    const REGULAR: [DVec3; 4] = [
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(-1.0, -1.0, 1.0),
    ];

    #[test]
    fn the_cosine_shortcut_agrees_with_the_angles_themselves() {
        let mut rng = test_support::SplitMix64(17);
        let regular = REGULAR;
        assert!(signed_volume(regular) > 0.0);
        let (mut sure, mut kept, mut near) = (0, 0, 0);
        for k in 0..200_000 {
            // Perturbations from slight to wild, so that many angles land
            // near 10° and 165°.
            let scale = [0.05, 0.8, 2.0, 4.0][k % 4];
            let p = regular
                .map(|q| q + scale * DVec3::new(rng.f64() - 0.5, rng.f64() - 0.5, rng.f64() - 0.5));
            if signed_volume(p) <= 0.0 {
                continue;
            }
            // From the regular tetrahedron (within the range), so the
            // exact test keeps exactly the moves within the range.
            let exact = keeps_angles_exactly(regular, p);
            if surely_within(p) {
                assert!(exact, "{p:?}: the shortcut keeps what the angles refuse");
                sure += 1;
            }
            let a = dihedral_angles(p).map(f64::to_degrees);
            kept += usize::from(
                a.iter()
                    .all(|&d| (MIN_DIHEDRAL_DEG..=MAX_DIHEDRAL_DEG).contains(&d)),
            );
            near += usize::from(a.iter().any(|&d| {
                (d - MIN_DIHEDRAL_DEG).abs() < 0.5 || (d - MAX_DIHEDRAL_DEG).abs() < 0.5
            }));
        }
        // It decides nearly every tetrahedron within the range, and the
        // test reached the bounds often.
        assert!(kept > 50_000 && sure * 100 >= kept * 99, "{sure} of {kept}");
        assert!(near > 1000, "{near} near a bound");
    }

    #[test]
    fn kept_ring_distances_are_those_measured_afresh_after_moves() {
        let (p, t) = sphere(16, 1.0, DVec3::ZERO);
        let mut m = crate::tetrahedralize(&p, &t, &crate::Options::new(0.25)).unwrap();
        let bvh = Bvh::build(&p, &t);
        let input = Surface {
            positions: &p,
            triangles: &t,
            bvh: &bvh,
        };
        let n = m.positions.len();
        let mut mover = Mover::new(
            &m.tets,
            &m.boundary,
            &input,
            1e-3,
            vec![false; n],
            vec![false; n],
        );
        let fresh = |mover: &Mover<'_>, positions: &[DVec3], v: u32| {
            let mut blank = CentroidDistances(vec![f64::NAN; m.boundary.len()]);
            blank.ring(&mover.faces, mover.boundary, mover.input, positions, v)
        };
        let mut on_boundary: Vec<u32> = m.boundary.iter().flatten().copied().collect();
        on_boundary.sort_unstable();
        on_boundary.dedup();
        let mut rng = test_support::SplitMix64(5);
        let mut moves = 0;
        for k in 0..400 {
            let v = on_boundary[k * 7919 % on_boundary.len()];
            let to = m.positions[v as usize]
                + 0.08 * DVec3::new(rng.f64() - 0.5, rng.f64() - 0.5, rng.f64() - 0.5);
            moves += usize::from(
                mover
                    .try_move(&mut m.positions, v, to, f64::INFINITY)
                    .is_some(),
            );
            // The ring of a neighbour (sharing a triangle with v) and v's own.
            let f = mover.faces.of(v)[k % mover.faces.of(v).len()];
            for u in m.boundary[f as usize] {
                let kept = mover.centroid_off.ring(
                    &mover.faces,
                    mover.boundary,
                    mover.input,
                    &m.positions,
                    u,
                );
                assert_eq!(
                    kept,
                    fresh(&mover, &m.positions, u),
                    "vertex {u} after move {k}"
                );
            }
        }
        assert!(moves > 100, "{moves} moves");
        // The ring check with its bound answers as the queries do, at the
        // new ring's own distances and just below them.
        let by_query = |positions: &[DVec3], v: u32, at: DVec3| {
            mover
                .faces
                .of(v)
                .iter()
                .map(|&f| {
                    let c = m.boundary[f as usize]
                        .map(|u| if u == v { at } else { positions[u as usize] });
                    input.nearest((c[0] + c[1] + c[2]) / 3.0).1.sqrt()
                })
                .fold(0.0f64, f64::max)
        };
        let mut bound_decided = 0;
        for k in 0..2000 {
            let v = on_boundary[k * 104_729 % on_boundary.len()];
            let from = m.positions[v as usize];
            let at = from + 0.05 * DVec3::new(rng.f64() - 0.5, rng.f64() - 0.5, rng.f64() - 0.5);
            mover
                .centroid_off
                .ring(&mover.faces, mover.boundary, mover.input, &m.positions, v);
            let worst = by_query(&m.positions, v, at);
            for limit in [worst, worst * (1.0 - 1e-6), worst * 1.5 + 0.01] {
                let expected = by_query(&m.positions, v, at) <= limit;
                assert_eq!(
                    mover.ring_within(&m.positions, v, at, limit),
                    expected,
                    "{v} {limit}"
                );
                let shift = from.distance(at) / 3.0;
                bound_decided += usize::from(
                    mover
                        .faces
                        .of(v)
                        .iter()
                        .any(|&f| mover.centroid_off.surely_within(f, shift, limit)),
                );
            }
        }
        assert!(
            bound_decided > 1000,
            "the bound decided {bound_decided} times"
        );
        // A move the cache is not told of leaves it stale: the comparison
        // above would see it.
        let v = on_boundary[0];
        let before =
            mover
                .centroid_off
                .ring(&mover.faces, mover.boundary, mover.input, &m.positions, v);
        m.positions[v as usize] *= 1.1;
        let stale =
            mover
                .centroid_off
                .ring(&mover.faces, mover.boundary, mover.input, &m.positions, v);
        assert_eq!(stale, before);
        assert_ne!(stale, fresh(&mover, &m.positions, v));
    }

    #[test]
    fn a_box_has_its_twelve_edges_sharp_and_its_face_diagonals_not() {
        let (p, t) = cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 0.5));
        let sharp = sharp_edges(&p, &t);
        assert_eq!(sharp.len(), 12);
        for [a, b] in sharp {
            // A box edge changes exactly one coordinate.
            let d = p[a as usize] - p[b as usize];
            let changed = d.to_array().iter().filter(|c| c.abs() > 0.0).count();
            assert_eq!(changed, 1, "{a}-{b}");
        }
        let (p, t) = sphere(24, 1.0, DVec3::ZERO);
        assert!(sharp_edges(&p, &t).is_empty());
    }

    #[test]
    fn a_move_that_flattens_or_inverts_a_tetrahedron_is_refused() {
        let regular = REGULAR;
        assert!(signed_volume(regular) > 0.0);
        let moved = |to: DVec3| {
            let mut p = regular;
            p[0] = to;
            p
        };
        // A small move keeps the angles.
        assert!(keeps_angles(regular, moved(DVec3::new(1.1, 0.9, 1.0))));
        // Onto the opposite face's plane: flat; through it: inverted.
        let centroid = (regular[1] + regular[2] + regular[3]) / 3.0;
        assert!(!keeps_angles(regular, moved(centroid)));
        assert!(!keeps_angles(regular, moved(centroid * 2.0)));
        // Close to the plane: positive, but angles below 10°.
        assert!(!keeps_angles(
            regular,
            moved(centroid + 0.02 * (regular[0] - centroid))
        ));
    }

    #[test]
    fn the_fit_pulls_a_box_corner_onto_the_input() {
        // A box whose corners fall between lattice points: the plain
        // stuffing cuts them off; the fit puts boundary vertices on them.
        let (p, t) = cuboid(DVec3::splat(0.03), DVec3::new(1.07, 0.96, 0.52));
        let mut options = crate::Options::new(0.1);
        let plain = crate::tetrahedralize(&p, &t, &options).unwrap();
        options.envelope = Some(1e-3);
        let fitted = crate::tetrahedralize(&p, &t, &options).unwrap();
        let corner_gap = |m: &crate::TetMesh| {
            p.iter()
                .map(|c| {
                    m.positions
                        .iter()
                        .map(|q| q.distance(*c))
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max)
        };
        let (before, after) = (corner_gap(&plain), corner_gap(&fitted));
        assert!(before > 0.01, "{before}");
        assert!(after < 1e-9, "{after}");
        assert_eq!(fitted.report.sharp_edges, 12);
        assert!(fitted.report.min_dihedral_deg >= MIN_DIHEDRAL_DEG);
    }
}
