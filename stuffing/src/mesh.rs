//! Turning stencil output into a tetrahedral mesh: compact vertex
//! numbering (no unused vertex), positive orientation, and the boundary
//! surface.

use glam::DVec3;
use rayon::prelude::*;

use super::quality::signed_volume;
use super::stencils::Point;

/// Vertices, positively oriented tetrahedra and outward boundary triangles.
pub(crate) struct Assembled {
    pub(crate) positions: Vec<DVec3>,
    pub(crate) tets: Vec<[u32; 4]>,
    pub(crate) boundary: Vec<[u32; 3]>,
}

/// Renumbers the points the tetrahedra use (in increasing id order, so the
/// numbering is deterministic), orients every tetrahedron positively and
/// extracts the faces that belong to one tetrahedron only.
pub(crate) fn assemble(cells: Vec<[Point; 4]>) -> Assembled {
    let mut used: Vec<(u32, DVec3)> = cells
        .iter()
        .flat_map(|t| t.iter().map(|p| (p.id, p.pos)))
        .collect();
    used.par_sort_unstable_by_key(|p| p.0);
    used.dedup_by_key(|p| p.0);
    let positions: Vec<DVec3> = used.iter().map(|p| p.1).collect();
    let index = |id: u32| -> u32 {
        // Every id of a cell is in `used` by construction.
        used.binary_search_by_key(&id, |p| p.0).unwrap_or(0) as u32
    };
    let tets: Vec<[u32; 4]> = cells
        .par_iter()
        .map(|t| {
            let mut v = t.map(|p| index(p.id));
            if signed_volume(t.map(|p| p.pos)) < 0.0 {
                v.swap(1, 2);
            }
            v
        })
        .collect();
    let boundary = boundary_faces(&tets);
    Assembled {
        positions,
        tets,
        boundary,
    }
}

/// The faces of positively oriented tetrahedra that no other tetrahedron
/// shares, oriented with outward normals (counter-clockwise seen from
/// outside).
pub(crate) fn boundary_faces(tets: &[[u32; 4]]) -> Vec<[u32; 3]> {
    // Face opposite vertex k of a positive tetrahedron, outward.
    const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
    let mut faces: Vec<([u32; 3], [u32; 3])> = tets
        .par_iter()
        .flat_map_iter(|t| {
            FACES.iter().map(move |f| {
                let oriented = [t[f[0]], t[f[1]], t[f[2]]];
                let mut key = oriented;
                key.sort_unstable();
                (key, oriented)
            })
        })
        .collect();
    faces.par_sort_unstable();
    let mut out = Vec::new();
    let mut i = 0;
    while i < faces.len() {
        let mut j = i + 1;
        while j < faces.len() && faces[j].0 == faces[i].0 {
            j += 1;
        }
        if j - i == 1 {
            out.push(faces[i].1);
        }
        i = j;
    }
    out
}
