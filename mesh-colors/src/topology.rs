//! Vertices, edges and faces of a triangle mesh: the primitives mesh
//! colours are attached to (Sec. 3.1, Fig. 10).

use std::collections::HashMap;

use crate::Error;

/// No face on this side of an edge (a boundary edge).
pub const NO_FACE: u32 = u32::MAX;

/// The connectivity of a triangle mesh, with edges numbered and given a
/// canonical direction (from the smaller vertex index to the larger), so
/// that two faces that run along an edge in opposite directions read the
/// same edge samples in the same order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Topology {
    pub(crate) vertex_count: usize,
    pub(crate) faces: Vec<[u32; 3]>,
    /// Per face, the edge of local edge `k` (from corner `k` to `k + 1`).
    pub(crate) face_edges: Vec<[u32; 3]>,
    /// Per edge, its vertices `[start, end]` with `start < end`.
    pub(crate) edges: Vec<[u32; 2]>,
    /// Per edge, its one or two faces ([`NO_FACE`] for a missing side).
    pub(crate) edge_faces: Vec<[u32; 2]>,
}

impl Topology {
    /// Builds the edges of `faces` over `vertex_count` vertices.
    ///
    /// # Errors
    /// [`Error::MissingVertex`], [`Error::DegenerateFace`] (a repeated
    /// vertex), [`Error::NonManifoldEdge`] (an edge with three or more faces:
    /// mesh colours give an edge one sample row seen from both sides, which
    /// has no meaning for a fan of faces, so such meshes are rejected rather
    /// than coloured inconsistently).
    ///
    /// # Example
    /// ```
    /// use mesh_colors::Topology;
    /// // Two triangles sharing the edge (1, 2): five edges, one shared.
    /// let t = Topology::new(4, &[[0, 1, 2], [2, 1, 3]])?;
    /// assert_eq!(t.edges().len(), 5);
    /// // A vertex index beyond the count is an error naming the face.
    /// assert!(Topology::new(3, &[[0, 1, 3]]).is_err());
    /// # Ok::<(), mesh_colors::Error>(())
    /// ```
    pub fn new(vertex_count: usize, faces: &[[u32; 3]]) -> Result<Self, Error> {
        let mut lookup: HashMap<(u32, u32), u32> = HashMap::with_capacity(faces.len() * 3 / 2);
        let mut edges = Vec::with_capacity(faces.len() * 3 / 2);
        let mut edge_faces: Vec<[u32; 2]> = Vec::with_capacity(faces.len() * 3 / 2);
        let mut face_edges = Vec::with_capacity(faces.len());
        for (f, face) in faces.iter().enumerate() {
            for &v in face {
                if v as usize >= vertex_count {
                    return Err(Error::MissingVertex {
                        face: f,
                        vertex: v,
                        count: vertex_count,
                    });
                }
            }
            for k in 0..3 {
                if face[k] == face[(k + 1) % 3] {
                    return Err(Error::DegenerateFace {
                        face: f,
                        vertex: face[k],
                    });
                }
            }
            let mut fe = [0u32; 3];
            for (k, slot) in fe.iter_mut().enumerate() {
                let (a, b) = (face[k], face[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                let e = *lookup.entry(key).or_insert_with(|| {
                    edges.push([key.0, key.1]);
                    edge_faces.push([NO_FACE, NO_FACE]);
                    (edges.len() - 1) as u32
                });
                let sides = &mut edge_faces[e as usize];
                if sides[0] == NO_FACE {
                    sides[0] = f as u32;
                } else if sides[1] == NO_FACE {
                    sides[1] = f as u32;
                } else {
                    return Err(Error::NonManifoldEdge {
                        a: key.0,
                        b: key.1,
                        faces: [sides[0] as usize, sides[1] as usize, f],
                    });
                }
                *slot = e;
            }
            face_edges.push(fe);
        }
        Ok(Self {
            vertex_count,
            faces: faces.to_vec(),
            face_edges,
            edges,
            edge_faces,
        })
    }

    /// The number of vertices (including any not used by a face).
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// The faces, as given.
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// The edges, each `[start, end]` in canonical direction (`start < end`).
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// The edge of each face's local edge `k` (corner `k` to corner `k + 1`).
    pub fn face_edges(&self) -> &[[u32; 3]] {
        &self.face_edges
    }

    /// The one or two faces of each edge ([`NO_FACE`] on a boundary).
    pub fn edge_faces(&self) -> &[[u32; 2]] {
        &self.edge_faces
    }

    /// The fingerprint of this connectivity (see [`Fingerprint`]).
    pub fn fingerprint(&self) -> Fingerprint {
        Fingerprint::of(self.vertex_count, &self.faces)
    }

    /// The edge between two vertices, if there is one. Linear in the face
    /// count (no vertex-to-edge index is kept): for occasional queries.
    pub fn edge_between(&self, a: u32, b: u32) -> Option<u32> {
        let (lo, hi) = (a.min(b), a.max(b));
        self.faces.iter().zip(&self.face_edges).find_map(|(f, fe)| {
            (0..3).find_map(|k| {
                let (x, y) = (f[k], f[(k + 1) % 3]);
                (x.min(y) == lo && x.max(y) == hi).then_some(fe[k])
            })
        })
    }
}

/// Identifies the mesh that mesh colours belong to: vertex and face counts
/// and a 64-bit hash of the faces' vertex indices, in order. Positions are
/// not part of it, so a deformed or animated mesh keeps its colours; any
/// change of connectivity (a re-export that reorders or welds vertices)
/// changes it. `.meshcolors` files store it, and
/// [`file::load_for`](crate::file::load_for) refuses colours made for
/// another mesh.
///
/// The hash is FNV-1a over the 32-bit vertex indices of the faces, each
/// index one step (`h ← (h ⊕ v) · 0x100000001b3` from
/// `0xcbf29ce484222325`), then a final avalanche (`h ⊕= h >> 33`,
/// `h ·= 0xff51afd7ed558ccd`, `h ⊕= h >> 33`): stable across versions and
/// platforms, since it is stored in files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Fingerprint {
    /// Number of vertices.
    pub vertices: u64,
    /// Number of faces.
    pub faces: u64,
    /// Hash of the faces' vertex indices.
    pub topology_hash: u64,
}

impl Fingerprint {
    /// The fingerprint of a mesh with `vertex_count` vertices and these
    /// faces (the welded faces that mesh colours are built on).
    pub fn of(vertex_count: usize, faces: &[[u32; 3]]) -> Self {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for &v in faces.iter().flatten() {
            h = (h ^ u64::from(v)).wrapping_mul(0x0000_0100_0000_01b3);
        }
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        Self {
            vertices: vertex_count as u64,
            faces: faces.len() as u64,
            topology_hash: h,
        }
    }
}

impl std::fmt::Display for Fingerprint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} vertices and {} faces (topology hash {:016x})",
            self.vertices, self.faces, self.topology_hash
        )
    }
}

/// Welds vertices that share a position exactly, returning the welded
/// positions, the faces over them, and for each input vertex its welded
/// index. Mesh loaders split a vertex wherever its UV or normal changes (a
/// seam); mesh colours need the connectivity of the surface itself.
pub fn weld(
    positions: &[glam::Vec3],
    faces: &[[u32; 3]],
) -> (Vec<glam::Vec3>, Vec<[u32; 3]>, Vec<u32>) {
    let mut map: HashMap<[u32; 3], u32> = HashMap::with_capacity(positions.len());
    let mut welded = Vec::new();
    let remap: Vec<u32> = positions
        .iter()
        .map(|p| {
            // +0.0 and -0.0 are one position.
            let key = (*p + glam::Vec3::ZERO).to_array().map(f32::to_bits);
            *map.entry(key).or_insert_with(|| {
                welded.push(*p);
                (welded.len() - 1) as u32
            })
        })
        .collect();
    let faces = faces
        .iter()
        .map(|f| f.map(|v| remap.get(v as usize).copied().unwrap_or(v)))
        .collect();
    (welded, faces, remap)
}
