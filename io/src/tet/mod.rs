//! Tetrahedral meshes: the plain data every tet reader returns, and the
//! boundary surface derived from the tetrahedra themselves.

use std::path::Path;

use glam::DVec3;

use crate::error::{Error, ErrorKind, Result};

pub mod gmsh;
mod gmsh_binary;
pub mod medit;
pub mod tetgen;
pub mod vtu;

/// A tetrahedral mesh as plain data.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TetMesh {
    /// Node positions (f64, as TetGen and Gmsh write them).
    pub positions: Vec<DVec3>,
    /// Four 0-based node indices per tetrahedron, as the file orders them.
    pub tets: Vec<[u32; 4]>,
    /// One region tag per tetrahedron (TetGen's region attribute, Gmsh's
    /// physical tag), or empty when the file has none.
    pub regions: Vec<i32>,
    /// The real-valued per-tetrahedron attributes a TetGen `.ele` file
    /// stores, one column per attribute: `attributes[k][t]` is attribute
    /// `k` of tetrahedron `t`. [`regions`](Self::regions) is the first
    /// column when all its values are integers (TetGen's region tags),
    /// and empty otherwise. Empty for the other formats.
    pub attributes: Vec<Vec<f64>>,
    /// What the reader skipped without refusing the file (elements other
    /// than tetrahedra, for instance), each naming the file, the element
    /// and what was skipped. Empty for a file read whole.
    pub warnings: Vec<crate::Warning>,
}

/// The faces of tetrahedron `(0, 1, 2, 3)` with outward normals (right-hand
/// rule) when it is positively oriented, `det[p1-p0, p2-p0, p3-p0] > 0`.
const OUTWARD_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// Reads a tetrahedral mesh, choosing the format by extension (see
/// [`TetMesh::read`]).
///
/// # Errors
/// [`Error`] naming the file, the line or byte, and what was wrong.
pub fn read(path: impl AsRef<Path>) -> Result<TetMesh> {
    TetMesh::read(path)
}

/// Writes a tetrahedral mesh, choosing the format by extension: `.node` or
/// `.ele` (TetGen, both files), `.mesh` (MEDIT), `.vtu` (VTK, ASCII, no
/// fields; [`vtu::write`] adds fields).
///
/// # Errors
/// [`crate::ErrorKind::UnknownExtension`] for other extensions; the
/// writer's errors.
pub fn write(path: impl AsRef<Path>, mesh: &TetMesh) -> Result<()> {
    let path = path.as_ref();
    match crate::error::extension(path).as_str() {
        "node" | "ele" => tetgen::write(path, mesh),
        "mesh" => medit::write(path, mesh),
        "vtu" => vtu::write(path, mesh, &[], &[], vtu::Encoding::Ascii),
        other => Err(Error::new(
            path,
            ErrorKind::UnknownExtension(other.to_string(), ".node, .ele, .mesh, .vtu"),
        )),
    }
}

impl TetMesh {
    /// Reads a tetrahedral mesh, choosing the format by extension: `.node`
    /// or `.ele` (TetGen; the other file is found beside it), `.msh` (Gmsh
    /// 2.2 ASCII or binary, or 4.1 ASCII) and `.mesh` (MEDIT).
    ///
    /// # Errors
    /// [`Error`] naming the file, the line or byte, and what was wrong.
    ///
    /// # Example
    /// ```
    /// use trilux_io::tet::TetMesh;
    /// let dir = std::env::temp_dir().join(format!("trilux-io-doc-tet-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir).unwrap();
    /// // One tetrahedron as a TetGen pair (1-based indices).
    /// std::fs::write(dir.join("one.node"), "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n").unwrap();
    /// std::fs::write(dir.join("one.ele"), "1 4 0\n1 1 2 3 4\n").unwrap();
    /// let mesh = TetMesh::read(dir.join("one.node"))?; // finds one.ele beside it
    /// assert_eq!(mesh.tets, vec![[0, 1, 2, 3]]);
    /// # std::fs::remove_dir_all(&dir).unwrap();
    /// # Ok::<(), trilux_io::Error>(())
    /// ```
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        match crate::error::extension(path).as_str() {
            "node" | "ele" => tetgen::read(path),
            "msh" => gmsh::read(path),
            "mesh" => medit::read(path),
            other => Err(Error::new(
                path,
                ErrorKind::UnknownExtension(other.to_string(), ".node, .ele, .msh, .mesh"),
            )),
        }
    }

    /// Six times the signed volume of tetrahedron `t`: positive when its
    /// nodes are ordered as TetGen and Gmsh order them. NaN when `t` or one
    /// of its nodes does not exist (the readers never return such a mesh).
    pub fn signed_volume6(&self, t: usize) -> f64 {
        let Some(tet) = self.tets.get(t) else {
            return f64::NAN;
        };
        let node = |i: u32| self.positions.get(i as usize).copied();
        match (node(tet[0]), node(tet[1]), node(tet[2]), node(tet[3])) {
            (Some(a), Some(b), Some(c), Some(d)) => (b - a).dot((c - a).cross(d - a)),
            _ => f64::NAN,
        }
    }

    /// The total volume of the tetrahedra.
    pub fn volume(&self) -> f64 {
        (0..self.tets.len())
            .map(|t| self.signed_volume6(t).abs())
            .sum::<f64>()
            / 6.0
    }

    /// The boundary surface: every triangle that belongs to exactly one
    /// tetrahedron, oriented with its normal pointing out of that
    /// tetrahedron (whatever the file's node order). Derived from the
    /// tetrahedra, never taken from a file's face list. Sorted, so the
    /// result does not depend on hashing.
    pub fn boundary(&self) -> Vec<[u32; 3]> {
        // Each face as (sorted nodes packed in a u128, oriented face).
        let mut faces: Vec<(u128, [u32; 3])> = Vec::with_capacity(4 * self.tets.len());
        for (t, tet) in self.tets.iter().enumerate() {
            let flip = self.signed_volume6(t) < 0.0;
            for local in OUTWARD_FACES {
                let mut face = local.map(|i| tet[i]);
                if flip {
                    face.swap(1, 2);
                }
                let mut key = face;
                key.sort_unstable();
                let packed =
                    (u128::from(key[0]) << 64) | (u128::from(key[1]) << 32) | u128::from(key[2]);
                faces.push((packed, face));
            }
        }
        faces.sort_unstable_by_key(|&(key, _)| key);
        let mut boundary = Vec::new();
        let mut i = 0;
        while i < faces.len() {
            let mut j = i + 1;
            while j < faces.len() && faces[j].0 == faces[i].0 {
                j += 1;
            }
            if j - i == 1 {
                boundary.push(faces[i].1);
            }
            i = j;
        }
        boundary
    }

    /// The nodes no tetrahedron uses, ascending. A solver on the mesh
    /// would give them an empty row (a zero diagonal); drop them with
    /// [`without_unused_nodes`](Self::without_unused_nodes) first.
    pub fn unused_nodes(&self) -> Vec<u32> {
        let mut used = vec![false; self.positions.len()];
        for &n in self.tets.iter().flatten() {
            if let Some(u) = used.get_mut(n as usize) {
                *u = true;
            }
        }
        (0..self.positions.len() as u32)
            .filter(|&n| !used[n as usize])
            .collect()
    }

    /// The mesh without the nodes no tetrahedron uses, and the map from
    /// each new node to its index in `self` (`map[new] = old`), to write
    /// per-node results back onto the original numbering. The tetrahedra,
    /// regions, attributes and warnings are kept, renumbered.
    pub fn without_unused_nodes(&self) -> (TetMesh, Vec<u32>) {
        let mut new_index = vec![u32::MAX; self.positions.len()];
        let mut map = Vec::with_capacity(self.positions.len());
        for &n in self.tets.iter().flatten() {
            if let Some(slot) = new_index.get_mut(n as usize)
                && *slot == u32::MAX
            {
                *slot = map.len() as u32;
                map.push(n);
            }
        }
        // Ascending old indices, so that the kept nodes keep their order.
        map.sort_unstable();
        for (new, &old) in map.iter().enumerate() {
            new_index[old as usize] = new as u32;
        }
        let mesh = TetMesh {
            positions: map
                .iter()
                .map(|&old| self.positions[old as usize])
                .collect(),
            tets: self
                .tets
                .iter()
                .map(|t| t.map(|n| new_index.get(n as usize).copied().unwrap_or(u32::MAX)))
                .collect(),
            regions: self.regions.clone(),
            attributes: self.attributes.clone(),
            warnings: self.warnings.clone(),
        };
        (mesh, map)
    }

    /// Tetrahedra that repeat an earlier one's nodes (in any order), as
    /// `(earlier, repeat)` pairs in file order.
    pub fn duplicate_tets(&self) -> Vec<(usize, usize)> {
        let mut keyed: Vec<([u32; 4], usize)> = self
            .tets
            .iter()
            .enumerate()
            .map(|(t, tet)| {
                let mut key = *tet;
                key.sort_unstable();
                (key, t)
            })
            .collect();
        keyed.sort_unstable();
        let mut pairs: Vec<(usize, usize)> = keyed
            .windows(2)
            .filter(|w| w[0].0 == w[1].0)
            .map(|w| (w[0].1, w[1].1))
            .collect();
        pairs.sort_unstable_by_key(|&(_, repeat)| repeat);
        pairs
    }

    /// Edges of the [`boundary`](Self::boundary) that belong to other
    /// than two boundary triangles (two tetrahedra touching along an edge
    /// only, or a surface that is not closed): sorted node pairs.
    pub fn non_manifold_boundary_edges(&self) -> Vec<[u32; 2]> {
        let mut edges: Vec<[u32; 2]> = self
            .boundary()
            .iter()
            .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
            .map(|mut e| {
                e.sort_unstable();
                e
            })
            .collect();
        edges.sort_unstable();
        let mut out = Vec::new();
        let mut i = 0;
        while i < edges.len() {
            let mut j = i + 1;
            while j < edges.len() && edges[j] == edges[i] {
                j += 1;
            }
            if j - i != 2 {
                out.push(edges[i]);
            }
            i = j;
        }
        out
    }

    /// Checks that every tetrahedron references existing nodes; the readers
    /// guarantee it, this is for meshes built by hand.
    pub(crate) fn check_indices(&self, path: &Path) -> Result<()> {
        let count = self.positions.len();
        for (index, tet) in self.tets.iter().enumerate() {
            if let Some(&node) = tet.iter().find(|&&n| n as usize >= count) {
                return Err(Error::new(
                    path,
                    ErrorKind::IndexOutOfRange {
                        element: "tetrahedron",
                        index,
                        node: i64::from(node),
                        count,
                    },
                ));
            }
        }
        Ok(())
    }
}

/// The volume enclosed by a closed, outward-oriented triangle surface
/// (divergence theorem); used to check boundary orientation. NaN when a
/// triangle references a missing position.
pub fn enclosed_volume(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let p = |i: u32| positions.get(i as usize).copied();
            match (p(t[0]), p(t[1]), p(t[2])) {
                (Some(a), Some(b), Some(c)) => a.dot(b.cross(c)),
                _ => f64::NAN,
            }
        })
        .sum::<f64>()
        / 6.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_tet() -> TetMesh {
        TetMesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            tets: vec![[0, 1, 2, 3]],
            regions: Vec::new(),
            attributes: Vec::new(),
            warnings: Vec::new(),
        }
    }

    #[test]
    fn boundary_of_one_tet_is_outward() {
        let mesh = unit_tet();
        assert!(mesh.signed_volume6(0) > 0.0);
        let b = mesh.boundary();
        assert_eq!(b.len(), 4);
        assert!((enclosed_volume(&mesh.positions, &b) - 1.0 / 6.0).abs() < 1e-15);
        // An inverted tet still gets an outward boundary.
        let mut inverted = mesh.clone();
        inverted.tets[0].swap(2, 3);
        assert!(inverted.signed_volume6(0) < 0.0);
        let b = inverted.boundary();
        assert!((enclosed_volume(&inverted.positions, &b) - 1.0 / 6.0).abs() < 1e-15);
    }

    /// A node no tetrahedron uses is found, dropped with a map back, and
    /// the volume and boundary are unchanged; a repeated tetrahedron and
    /// two tetrahedra sharing only an edge are named.
    #[test]
    fn unused_nodes_duplicates_and_non_manifold_edges() {
        let mut mesh = unit_tet();
        mesh.positions.insert(1, DVec3::splat(9.0));
        mesh.tets = vec![[0, 2, 3, 4]];
        assert_eq!(mesh.unused_nodes(), vec![1]);
        let (compact, map) = mesh.without_unused_nodes();
        assert_eq!(map, vec![0, 2, 3, 4]);
        assert_eq!(compact.tets, vec![[0, 1, 2, 3]]);
        assert!(compact.unused_nodes().is_empty());
        assert!((compact.volume() - mesh.volume()).abs() < 1e-15);
        for (new, &old) in map.iter().enumerate() {
            assert_eq!(compact.positions[new], mesh.positions[old as usize]);
        }
        assert!(mesh.duplicate_tets().is_empty());
        assert!(mesh.non_manifold_boundary_edges().is_empty());
        mesh.tets.push([4, 3, 2, 0]);
        assert_eq!(mesh.duplicate_tets(), vec![(0, 1)]);
        // Two tetrahedra sharing only the edge (0, 1).
        let bowtie = TetMesh {
            positions: vec![
                DVec3::ZERO,
                DVec3::Z,
                DVec3::X,
                DVec3::Y,
                -DVec3::X,
                -DVec3::Y,
            ],
            tets: vec![[0, 2, 3, 1], [0, 4, 5, 1]],
            ..TetMesh::default()
        };
        assert_eq!(bowtie.non_manifold_boundary_edges(), vec![[0, 1]]);
    }

    #[test]
    fn shared_faces_are_interior() {
        // Two tets sharing face (1, 2, 3).
        let mut mesh = unit_tet();
        mesh.positions.push(DVec3::ONE);
        mesh.tets.push([4, 1, 3, 2]);
        assert!(mesh.signed_volume6(1) > 0.0);
        let b = mesh.boundary();
        assert_eq!(b.len(), 6);
        assert!((enclosed_volume(&mesh.positions, &b) - mesh.volume()).abs() < 1e-15);
    }
}
