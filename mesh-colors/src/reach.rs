//! Which samples a brush dab reaches, found through the faces: a grid
//! over the faces' bounding boxes finds the faces near the dab, and their
//! vertices', edges' and own samples are measured where they lie.
//!
//! The faces and the vertex positions never change while a mesh is
//! painted, so neither does this index: a resolution change (the detail
//! brush) renumbers the samples but leaves it as it is. An index of the
//! samples themselves ([`crate::Painter`]) would be rebuilt, and the
//! samples' positions moved, on every such change.

use glam::Vec3;

use crate::grid::Grid;
use crate::structure::{MeshColors, Site};
use crate::topology::NO_FACE;

/// A sample within a dab's radius.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Hit {
    /// The sample's index in the colours.
    pub(crate) sample: usize,
    /// Its distance from the dab's centre.
    pub(crate) distance: f32,
    /// Its position.
    pub(crate) position: Vec3,
    /// Where it lies ([`MeshColors::sites`]'s site, or one on another face
    /// for a vertex: the same point). A vertex on no face has none.
    pub(crate) site: Site,
}

/// The faces of a mesh (and the vertices on none) in a grid.
#[derive(Debug, Clone)]
pub(crate) struct Reach {
    grid: Grid,
    /// Per face, then per loose vertex: its bounding box, grown by
    /// `slack`.
    boxes: Vec<(Vec3, Vec3)>,
    /// The vertices on no face (they have samples, at their positions).
    loose: Vec<u32>,
}

impl Reach {
    /// The index of the faces `faces` (vertex ids into `vertices`, all
    /// finite and in range) in cells of `cell`.
    pub(crate) fn new(faces: &[[u32; 3]], vertices: &[Vec3], cell: f32) -> Self {
        // A sample's position is rounded from its exact point, which may
        // lie a rounding error outside its face's box in f32: the boxes
        // grow by far more than that.
        let scale = vertices
            .iter()
            .fold(0.0f32, |m, p| m.max(p.abs().max_element()));
        let slack = 1e-5 * (scale + cell);
        let mut on_face = vec![false; vertices.len()];
        let mut boxes: Vec<(Vec3, Vec3)> = faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|v| {
                    on_face[v as usize] = true;
                    vertices[v as usize]
                });
                (
                    a.min(b).min(c) - Vec3::splat(slack),
                    a.max(b).max(c) + Vec3::splat(slack),
                )
            })
            .collect();
        let loose: Vec<u32> = (0u32..)
            .zip(&on_face)
            .filter(|&(_, &on)| !on)
            .map(|(v, _)| v)
            .collect();
        boxes.extend(
            loose
                .iter()
                .map(|&v| (vertices[v as usize], vertices[v as usize])),
        );
        Self {
            grid: Grid::of_boxes(&boxes, cell),
            boxes,
            loose,
        }
    }

    /// Every sample of `colors` (on these faces, at `vertices`) within
    /// `radius` of `center`, sorted by sample, each once, into `hits`
    /// (cleared first). Positions are those [`crate::Painter`] indexes:
    /// each site's point in `f64`, rounded.
    pub(crate) fn within(
        &self,
        colors: &MeshColors,
        vertices: &[Vec3],
        center: Vec3,
        radius: f32,
        hits: &mut Vec<Hit>,
    ) {
        hits.clear();
        let faces = colors.topology().faces();
        let mut near: Vec<u32> = Vec::new();
        self.grid
            .for_each_list_near(center, radius, |list| near.extend_from_slice(list));
        near.sort_unstable();
        near.dedup();
        near.retain(|&i| box_distance(center, self.boxes[i as usize]) <= radius);
        let split = near.partition_point(|&i| (i as usize) < faces.len());
        let (near_faces, near_loose) = near.split_at(split);

        let mut measure = |sample: usize, site: Site| {
            let position = site.position(colors.topology(), vertices).map_or_else(
                || vertices.get(sample).copied().unwrap_or_default(),
                |p| p.as_vec3(),
            );
            let distance = position.distance(center);
            if distance <= radius {
                hits.push(Hit {
                    sample,
                    distance,
                    position,
                    site,
                });
            }
        };
        // The corners: vertex v is sample v, at corner k of any face of it.
        let mut corners: Vec<(u32, u32, usize)> = near_faces
            .iter()
            .flat_map(|&f| (0..3).map(move |k| (faces[f as usize][k], f, k)))
            .collect();
        corners.sort_unstable();
        corners.dedup_by_key(|c| c.0);
        for (v, f, k) in corners {
            let mut barycentric = [0.0; 3];
            barycentric[k] = 1.0;
            measure(
                v as usize,
                Site {
                    face: f,
                    barycentric,
                },
            );
        }
        for &i in near_loose {
            let v = self.loose[i as usize - faces.len()];
            let site = Site {
                face: NO_FACE,
                barycentric: [0.0; 3],
            };
            measure(v as usize, site);
        }
        let mut edges: Vec<u32> = near_faces
            .iter()
            .flat_map(|&f| colors.topology().face_edges()[f as usize])
            .collect();
        edges.sort_unstable();
        edges.dedup();
        for e in edges {
            colors.edge_sites(e as usize, &mut measure);
        }
        for &f in near_faces {
            colors.face_sites(f as usize, &mut measure);
        }
        hits.sort_unstable_by_key(|h| h.sample);
    }
}

/// The distance from `p` to the box `(lo, hi)` (0 inside).
fn box_distance(p: Vec3, (lo, hi): (Vec3, Vec3)) -> f32 {
    (lo - p).max(p - hi).max(Vec3::ZERO).length()
}
