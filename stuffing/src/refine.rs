//! Refinement driven by the measured distance (part of
//! [`super::Options::envelope`]): where an input point still lies farther
//! than the envelope from the boundary after the fit has moved every vertex
//! it could, the edge of its nearest boundary triangle nearest to it is
//! split and the new vertex put on the point (or part of the way); where
//! the midpoint of a boundary edge lies farther than the envelope from the
//! input (a chord across a thin part or a concavity; not over a hole, see
//! [`crate::distance`]), that edge is split towards the input. Where the
//! angle check refuses both, the longest edge of the tetrahedron under the
//! boundary triangle is bisected (Rivara's longest-edge bisection) so that
//! the next round finds smaller tetrahedra. So thin parts and tips get
//! smaller tetrahedra than the lattice's where, and only where, the
//! measured distance asks for them.
//!
//! Why edge bisection and not a finer lattice there: the remaining far
//! points lie within a spacing of a boundary vertex that the angle check
//! will not let move (the diagnosis of issue #48 on the data meshes: parts
//! 0.2–2 spacings thick, the nearest boundary vertex 0.4–0.8 spacings
//! away). Splitting an edge splits every tetrahedron around it in two, so
//! the mesh stays conforming with no transition stencils; each new
//! tetrahedron is checked before the split is made, so the bound the fit
//! holds (10°–165°, [`super::envelope::MIN_DIHEDRAL_DEG`]) holds for every
//! tetrahedron made here. A lattice refined only near some of the surface
//! would need stencils for cut transition tetrahedra, whose angles are not
//! bounded by Labelle & Shewchuk's analysis.
//!
//! Splits happen one after another in a fixed order (farthest point first,
//! ties by index), so the result does not depend on the number of threads.
//! The tetrahedra may grow to a stated budget (three times the stuffed
//! count by default, the cost bound); what the budget or the
//! angle check leaves far stays far, and the measured distance says so.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::distance::{Surface, closest_point_on_triangle, on_hole_cap};
use crate::envelope::{STEPS, keeps_angles};
use crate::mesh::Assembled;
use crate::winding::WindingNumber;

/// Rounds of splitting: each halves the edges near the points it serves,
/// so a point can be served by edges down to `2^-ROUNDS` of the lattice's.
pub(crate) const ROUNDS: usize = 8;

/// What the refinement did.
#[derive(Debug, Default)]
pub(crate) struct Refined {
    /// Edges split.
    pub(crate) splits: usize,
    /// New vertices put all the way onto an input point.
    pub(crate) on_input: Vec<u32>,
}

/// Splits boundary edges near the `targets` (input points) farther than
/// `eps` from the boundary of `(positions, tets, boundary)`, until none is
/// or no split keeps the angles, within `ROUNDS` rounds and at most
/// `max_tets` tetrahedra. `input` is the input where it encloses volume.
pub(crate) fn refine(
    wn: &WindingNumber,
    input: &Surface<'_>,
    mesh: &mut Assembled,
    targets: &[DVec3],
    eps: f64,
    max_tets: usize,
) -> Refined {
    let mut mesh = Dynamic::new(&mut mesh.positions, &mut mesh.tets, &mut mesh.boundary);
    let mut refined = Refined::default();
    let mut candidates: Vec<u32> = (0..targets.len() as u32).collect();
    // Boundary vertices whose edges to look at: all at first, then those
    // of far edges and of changed triangles (elsewhere nothing moved).
    let mut watched = vec![true; mesh.positions.len()];
    let mut known = HashMap::new();
    for _ in 0..ROUNDS {
        let mut jobs = far_input(&mesh, targets, &candidates, eps);
        let far_edges = far_boundary(wn, input, &mesh, eps, &watched, &mut known);
        watched = vec![false; mesh.positions.len()];
        for job in &far_edges {
            if let Some((a, b)) = job.edge {
                watched[a as usize] = true;
                watched[b as usize] = true;
            }
        }
        jobs.extend(far_edges);
        jobs.sort_unstable_by(|a, b| b.d2.total_cmp(&a.d2).then(a.order.cmp(&b.order)));
        let mut busy = vec![false; mesh.positions.len()];
        let mut again = Vec::new();
        let mut splits = 0;
        for job in jobs {
            if mesh.tets.len() >= max_tets {
                break;
            }
            let corners = mesh.boundary[job.triangle as usize];
            // A triangle changed this round: look again next round.
            if corners.iter().any(|&v| busy[v as usize]) {
                again.extend(job.input_point);
                continue;
            }
            let edges = match job.edge {
                Some(e) => vec![e],
                None => mesh.edges_by_gap(corners, job.target),
            };
            let split = mesh
                .split_towards(&edges, job.target, input, eps)
                .or_else(|| mesh.bisect_under(corners, input, eps));
            let Some((m, changed)) = split else {
                continue; // no split near it keeps the angles: given up
            };
            splits += 1;
            again.extend(job.input_point);
            busy.resize(mesh.positions.len(), false);
            watched.resize(mesh.positions.len(), false);
            for v in changed {
                busy[v as usize] = true;
                watched[v as usize] = true;
            }
            if mesh.positions[m as usize] == job.target {
                refined.on_input.push(m);
            }
        }
        refined.splits += splits;
        if splits == 0 {
            break;
        }
        again.sort_unstable();
        again.dedup();
        candidates = again;
    }
    refined
}

/// A split to try: towards `target`, for a point `sqrt(d2)` from the
/// other surface, near boundary triangle `triangle` (an edge of it, or
/// the given `edge`).
struct Job {
    d2: f64,
    /// Input points first, then boundary points, each by index: the ties'
    /// order.
    order: (u8, u32),
    triangle: u32,
    edge: Option<(u32, u32)>,
    target: DVec3,
    /// The index of the input point this serves, if one.
    input_point: Option<u32>,
}

/// Input points (of `candidates`) farther than `eps` from the boundary:
/// split the edge of their nearest boundary triangle nearest to them.
fn far_input(mesh: &Dynamic<'_>, targets: &[DVec3], candidates: &[u32], eps: f64) -> Vec<Job> {
    let bvh = Bvh::build(mesh.positions, mesh.boundary);
    let surface = Surface {
        positions: mesh.positions,
        triangles: mesh.boundary,
        bvh: &bvh,
    };
    candidates
        .par_iter()
        .filter_map(|&i| {
            let target = targets[i as usize];
            // Most points are near: a bounded query says so for less.
            if surface.within(target, eps) {
                return None;
            }
            let (_, d2, triangle) = surface.nearest(target);
            (d2 > eps * eps && triangle != u32::MAX).then_some(Job {
                d2,
                order: (0, i),
                triangle,
                edge: None,
                target,
                input_point: Some(i),
            })
        })
        .collect()
}

/// Boundary points farther than `eps` from the input, tried at the
/// midpoint of every boundary edge (where a chord between two vertices on
/// the input is farthest from it), but not on hole caps
/// ([`on_hole_cap`]): split that edge towards the input point nearest its
/// midpoint. Only edges with a `watched` end are looked at. `known` keeps
/// each edge's answer (the squared distance and the input point, for a
/// far one): splits add vertices but move none, so an edge's answer never
/// changes, while its ends stay watched round after round.
fn far_boundary(
    wn: &WindingNumber,
    input: &Surface<'_>,
    mesh: &Dynamic<'_>,
    eps: f64,
    watched: &[bool],
    known: &mut HashMap<(u32, u32), Option<(f64, DVec3)>>,
) -> Vec<Job> {
    let edges: Vec<(u32, u32, u32)> = mesh
        .boundary
        .iter()
        .enumerate()
        .flat_map(|(f, t)| {
            (0..3).filter_map(move |k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                // Each edge once (from the triangle that has it as a→b
                // with a < b; a closed boundary has both directions).
                (a < b && (watched[a as usize] || watched[b as usize])).then_some((a, b, f as u32))
            })
        })
        .collect();
    let new: Vec<(u32, u32)> = edges
        .iter()
        .filter(|&&(a, b, _)| !known.contains_key(&(a, b)))
        .map(|&(a, b, _)| (a, b))
        .collect();
    let answers: Vec<Option<(f64, DVec3)>> = new
        .par_iter()
        .map(|&(a, b)| {
            let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            let mid = 0.5 * (pa + pb);
            let (target, d2, _) = input.nearest(mid);
            // Far, within an edge's length of the input (not across a
            // gap), and not where the input is missing.
            (d2 > eps * eps && d2 <= pa.distance_squared(pb) && !on_hole_cap(wn, mid))
                .then_some((d2, target))
        })
        .collect();
    known.extend(new.into_iter().zip(answers));
    edges
        .iter()
        .enumerate()
        .filter_map(|(k, &(a, b, f))| {
            let (d2, target) = known[&(a, b)]?;
            Some(Job {
                d2,
                order: (1, k as u32),
                triangle: f,
                edge: Some((a, b)),
                target,
                input_point: None,
            })
        })
        .collect()
}

/// A tetrahedral mesh with its boundary and the elements around each
/// vertex, open to edge splits.
struct Dynamic<'a> {
    positions: &'a mut Vec<DVec3>,
    tets: &'a mut Vec<[u32; 4]>,
    boundary: &'a mut Vec<[u32; 3]>,
    tets_of: Vec<Vec<u32>>,
    faces_of: Vec<Vec<u32>>,
}

impl<'a> Dynamic<'a> {
    fn new(
        positions: &'a mut Vec<DVec3>,
        tets: &'a mut Vec<[u32; 4]>,
        boundary: &'a mut Vec<[u32; 3]>,
    ) -> Dynamic<'a> {
        let mut tets_of = vec![Vec::new(); positions.len()];
        for (t, tet) in tets.iter().enumerate() {
            for &v in tet {
                tets_of[v as usize].push(t as u32);
            }
        }
        let mut faces_of = vec![Vec::new(); positions.len()];
        for (f, face) in boundary.iter().enumerate() {
            for &v in face {
                faces_of[v as usize].push(f as u32);
            }
        }
        Dynamic {
            positions,
            tets,
            boundary,
            tets_of,
            faces_of,
        }
    }

    /// The edges of the boundary triangle `corners`, nearest to `s` first.
    fn edges_by_gap(&self, corners: [u32; 3], s: DVec3) -> Vec<(u32, u32)> {
        let mut edges = [0, 1, 2].map(|k| (corners[k], corners[(k + 1) % 3]));
        let gap = |(a, b): (u32, u32)| {
            let (pa, pb) = (self.positions[a as usize], self.positions[b as usize]);
            closest_point_on_triangle(s, pa, pb, pb).distance_squared(s)
        };
        edges.sort_by(|&x, &y| gap(x).total_cmp(&gap(y)).then(x.cmp(&y)));
        edges.to_vec()
    }

    /// Splits the first of `edges` that can be split, its new vertex
    /// moved from the edge's midpoint to `s`, or the largest of
    /// [`STEPS`] of the way that keeps every new tetrahedron within the
    /// fit's angle range (or no worse than the one it was cut from) and
    /// the new boundary triangles as near the input as the old ones (or
    /// within `eps`). Returns the new vertex and the vertices whose
    /// boundary triangles changed.
    fn split_towards(
        &mut self,
        edges: &[(u32, u32)],
        s: DVec3,
        input: &Surface<'_>,
        eps: f64,
    ) -> Option<(u32, Vec<u32>)> {
        for &(a, b) in edges {
            if let Some(p) = self.feasible(a, b, s, input, eps, false) {
                return Some(self.split(a, b, p));
            }
        }
        None
    }

    /// Makes room where no boundary vertex can move far enough: splits the
    /// longest edge of the tetrahedron under the boundary triangle
    /// `corners` at its midpoint (a boundary edge's new vertex goes onto
    /// the input point nearest to it, or part of the way), so that the next
    /// round finds smaller tetrahedra there (Rivara's longest-edge
    /// bisection, each split kept only under the same angle check).
    fn bisect_under(
        &mut self,
        corners: [u32; 3],
        input: &Surface<'_>,
        eps: f64,
    ) -> Option<(u32, Vec<u32>)> {
        let &t = self.tets_of[corners[0] as usize]
            .iter()
            .find(|&&t| corners.iter().all(|c| self.tets[t as usize].contains(c)))?;
        let tet = self.tets[t as usize];
        let length2 = |(a, b): (u32, u32)| {
            self.positions[a as usize].distance_squared(self.positions[b as usize])
        };
        let (a, b) = crate::quality::EDGES
            .iter()
            .map(|&(i, j)| (tet[i].min(tet[j]), tet[i].max(tet[j])))
            .max_by(|&x, &y| length2(x).total_cmp(&length2(y)).then(y.cmp(&x)))?;
        let mid = 0.5 * (self.positions[a as usize] + self.positions[b as usize]);
        let on_boundary = !Self::around(&self.faces_of, self.boundary, a, b).is_empty();
        let target = if on_boundary {
            input.nearest(mid).0
        } else {
            mid
        };
        let p = self.feasible(a, b, target, input, eps, true)?;
        Some(self.split(a, b, p))
    }

    /// The tetrahedra (or boundary triangles) around the edge `ab`.
    fn around<const N: usize>(of: &[Vec<u32>], elements: &[[u32; N]], a: u32, b: u32) -> Vec<u32> {
        of[a as usize]
            .iter()
            .copied()
            .filter(|&e| elements[e as usize].contains(&b))
            .collect()
    }

    /// Where the vertex splitting `ab` can go on the way to `s` (see
    /// [`Dynamic::split_towards`]), if anywhere; an inner edge only if
    /// `inner` (then `s` is its midpoint).
    fn feasible(
        &self,
        a: u32,
        b: u32,
        s: DVec3,
        input: &Surface<'_>,
        eps: f64,
        inner: bool,
    ) -> Option<DVec3> {
        let tets = Self::around(&self.tets_of, self.tets, a, b);
        let faces = Self::around(&self.faces_of, self.boundary, a, b);
        if faces.is_empty() && !inner {
            return None; // an inner edge: its split would not reach the boundary
        }
        let mid = 0.5 * (self.positions[a as usize] + self.positions[b as usize]);
        let at = |ids: &[u32], v: u32, p: DVec3| -> Vec<DVec3> {
            ids.iter()
                .map(|&u| {
                    if u == v {
                        p
                    } else {
                        self.positions[u as usize]
                    }
                })
                .collect()
        };
        let centroid = |corners: Vec<DVec3>| corners.iter().sum::<DVec3>() / 3.0;
        // The old triangles' distance, with the new vertex at the midpoint:
        // found only when a step's new triangles are not all within `eps`
        // (the limit is at least that).
        let mut before = None;
        'steps: for step in STEPS {
            let p = mid.lerp(s, step);
            for &t in &tets {
                let ids = self.tets[t as usize];
                let parent = ids.map(|u| self.positions[u as usize]);
                for x in [a, b] {
                    let child = ids.map(|u| {
                        if u == x {
                            p
                        } else {
                            self.positions[u as usize]
                        }
                    });
                    if !keeps_angles(parent, child) {
                        continue 'steps;
                    }
                }
            }
            let halves: Vec<DVec3> = faces
                .iter()
                .flat_map(|&f| [a, b].map(|x| centroid(at(&self.boundary[f as usize], x, p))))
                .collect();
            if halves.iter().all(|&c| input.within(c, eps)) {
                return Some(p);
            }
            let limit = before
                .get_or_insert_with(|| {
                    faces
                        .iter()
                        .flat_map(|&f| {
                            [b, a].map(|x| {
                                let c = centroid(at(&self.boundary[f as usize], x, mid));
                                input.nearest(c).1.sqrt()
                            })
                        })
                        .fold(0.0f64, f64::max)
                })
                .max(eps);
            if halves.iter().all(|&c| input.within(c, limit)) {
                return Some(p);
            }
        }
        None
    }

    /// Splits edge `ab` with a new vertex at `p`: each tetrahedron and
    /// boundary triangle around it becomes two, the one keeping `a` in its
    /// place and the one keeping `b` appended (orientation kept: the new
    /// vertex takes the place of a corner). Returns the new vertex and the
    /// corners of the boundary triangles that changed.
    fn split(&mut self, a: u32, b: u32, p: DVec3) -> (u32, Vec<u32>) {
        let m = self.positions.len() as u32;
        self.positions.push(p);
        self.tets_of.push(Vec::new());
        self.faces_of.push(Vec::new());
        for t in Self::around(&self.tets_of, self.tets, a, b) {
            let old = self.tets[t as usize];
            let new = self.tets.len() as u32;
            self.tets[t as usize] = old.map(|u| if u == b { m } else { u });
            self.tets.push(old.map(|u| if u == a { m } else { u }));
            relink(&mut self.tets_of, &old, a, b, m, t, new);
        }
        let mut changed = vec![m];
        for f in Self::around(&self.faces_of, self.boundary, a, b) {
            let old = self.boundary[f as usize];
            let new = self.boundary.len() as u32;
            self.boundary[f as usize] = old.map(|u| if u == b { m } else { u });
            self.boundary.push(old.map(|u| if u == a { m } else { u }));
            relink(&mut self.faces_of, &old, a, b, m, f, new);
            changed.extend(old);
        }
        changed.sort_unstable();
        changed.dedup();
        (m, changed)
    }
}

/// Element `old` (index `kept`, now with `m` for `b`) was split into it and
/// `new` (with `m` for `a`): `b` loses `kept` and gains `new`, `m` gains
/// both, the other corners gain `new`.
fn relink(of: &mut [Vec<u32>], old: &[u32], a: u32, b: u32, m: u32, kept: u32, new: u32) {
    let list = &mut of[b as usize];
    if let Some(k) = list.iter().position(|&e| e == kept) {
        list[k] = new;
    }
    of[m as usize].extend([kept, new]);
    for &u in old {
        if u != a && u != b {
            of[u as usize].push(new);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tests::sphere;
    use crate::winding::DEFAULT_BETA;

    #[test]
    fn an_edges_kept_answer_is_the_one_found_afresh_after_splits() {
        let (p, t) = sphere(16, 1.0, DVec3::ZERO);
        let m = crate::tetrahedralize(&p, &t, &crate::Options::new(0.25)).unwrap();
        let (mut positions, mut tets, mut boundary) = (m.positions, m.tets, m.boundary);
        let wn = WindingNumber::new(&p, &t, DEFAULT_BETA).unwrap();
        let bvh = Bvh::build(&p, &t);
        let input = Surface {
            positions: &p,
            triangles: &t,
            bvh: &bvh,
        };
        let mut mesh = Dynamic::new(&mut positions, &mut tets, &mut boundary);
        // Chords of a unit sphere at this spacing sag by about 0.01.
        let eps = 1e-3;
        let mut known = HashMap::new();
        let all = vec![true; mesh.positions.len()];
        let first = far_boundary(&wn, &input, &mesh, eps, &all, &mut known);
        assert!(first.len() > 50, "{} far edges", first.len());
        let old = mesh.positions.clone();
        for job in first.iter().step_by(3) {
            let (a, b) = job.edge.unwrap();
            mesh.split(a, b, job.target);
        }
        // The cache's premise: splits add vertices and move none.
        assert_eq!(mesh.positions[..old.len()], old[..]);
        let all = vec![true; mesh.positions.len()];
        let answers = |jobs: Vec<Job>| -> Vec<_> {
            jobs.into_iter()
                .map(|j| (j.d2, j.order, j.triangle, j.edge, j.target))
                .collect()
        };
        let kept = answers(far_boundary(&wn, &input, &mesh, eps, &all, &mut known));
        let fresh = answers(far_boundary(
            &wn,
            &input,
            &mesh,
            eps,
            &all,
            &mut HashMap::new(),
        ));
        assert_eq!(kept, fresh);
        // The new edges were asked about too, and some are far.
        assert!(kept.iter().any(|j| j.3.unwrap().1 as usize >= old.len()));
    }
}
