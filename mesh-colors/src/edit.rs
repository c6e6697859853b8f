//! Editing coloured meshes without resampling (Sec. 3.3): exact 1-to-4
//! subdivision, deleting and adding faces, and changing one face's
//! resolution. Vertex moves need nothing: samples live on primitives, not
//! at positions.
//!
//! Edits build a new sample array and copy every sample they keep (the
//! indices of Fig. 10 change, the values do not): the cost is a copy of
//! the array, and only the primitives an edit touches get new values.

use std::collections::HashMap;

use glam::Vec3;

use crate::Error;
use crate::filter::{FINEST, Store, edge_point, eval, lattice};
use crate::structure::{MeshColors, lattice_points, level_of, sample_position};
use crate::topology::Topology;

/// Corners of the four children of a face, as lattice points of the
/// parent at resolution 2: `v0, v1, v2` at `2·e_k`, midpoints between.
const CHILD_CORNERS: [[[u32; 3]; 3]; 4] = [
    [[2, 0, 0], [1, 1, 0], [1, 0, 1]],
    [[1, 1, 0], [0, 2, 0], [0, 1, 1]],
    [[1, 0, 1], [0, 1, 1], [0, 0, 2]],
    [[0, 1, 1], [1, 0, 1], [1, 1, 0]],
];

/// The result of [`MeshColors::subdivide`].
#[derive(Debug, Clone, PartialEq)]
pub struct Subdivided {
    /// The colours on the subdivided mesh: each face of resolution `R` is
    /// four faces of `R/2`, every sample at the same place with the same
    /// value.
    pub colors: MeshColors,
    /// The new faces: face `f`'s children are `4f .. 4f + 4` (corner,
    /// corner, corner, centre; see [`child_of`]).
    pub faces: Vec<[u32; 3]>,
    /// New vertex `V + e` is the midpoint of old edge `e`, these vertices.
    pub midpoints: Vec<[u32; 2]>,
}

impl Subdivided {
    /// Vertex positions of the subdivided mesh: the old ones, then edge
    /// midpoints (a caller applying a smoothing scheme moves them after;
    /// the colours do not depend on positions).
    ///
    /// # Errors
    /// [`Error::ChannelMismatch`] if `old` has fewer positions than the
    /// mesh had vertices.
    pub fn positions(&self, old: &[Vec3]) -> Result<Vec<Vec3>, Error> {
        let need = self.colors.topology.vertex_count - self.midpoints.len();
        if old.len() < need {
            return Err(Error::ChannelMismatch {
                what: "vertex positions",
                expected: need,
                got: old.len(),
            });
        }
        let mut p = old[..need].to_vec();
        p.extend(
            self.midpoints
                .iter()
                .map(|&[a, b]| 0.5 * (old[a as usize] + old[b as usize])),
        );
        Ok(p)
    }
}

/// Which child of a subdivided face holds the point with parent
/// barycentrics `b`, and its barycentrics there (Fig. 5: the texture
/// coordinates that keep lookups where they were).
pub fn child_of(b: [f32; 3]) -> (usize, [f32; 3]) {
    if b[0] >= 0.5 {
        let (c1, c2) = (2.0 * b[1], 2.0 * b[2]);
        (0, [1.0 - c1 - c2, c1, c2])
    } else if b[1] >= 0.5 {
        let (c0, c2) = (2.0 * b[0], 2.0 * b[2]);
        (1, [c0, 1.0 - c0 - c2, c2])
    } else if b[2] >= 0.5 {
        let (c0, c1) = (2.0 * b[0], 2.0 * b[1]);
        (2, [c0, c1, 1.0 - c0 - c1])
    } else {
        (3, [1.0 - 2.0 * b[0], 1.0 - 2.0 * b[1], 1.0 - 2.0 * b[2]])
    }
}

impl MeshColors {
    /// 1-to-4 subdivision of every face, carrying the colours over exactly
    /// (Sec. 3.3): a face of resolution `R` becomes four of `R/2`, edge
    /// samples split between the halves of their edge, the middle edge
    /// sample becomes the new vertex's colour. Nothing is interpolated.
    ///
    /// # Errors
    /// [`Error::CannotSubdivide`] naming a face of resolution 1 (its four
    /// children would need samples it does not have).
    pub fn subdivide(&self) -> Result<Subdivided, Error> {
        if let Some(f) = self.face_level.iter().position(|&n| n == 0) {
            return Err(Error::CannotSubdivide { face: f });
        }
        let t = &self.topology;
        let v0 = t.vertex_count as u32;
        let mut faces = Vec::with_capacity(4 * t.faces.len());
        let mut levels = Vec::with_capacity(4 * t.faces.len());
        for (f, face) in t.faces.iter().enumerate() {
            let m = t.face_edges[f].map(|e| v0 + e);
            let [a, b, c] = *face;
            faces.extend([
                [a, m[0], m[2]],
                [m[0], b, m[1]],
                [m[2], m[1], c],
                [m[1], m[2], m[0]],
            ]);
            levels.extend([self.face_level[f] - 1; 4]);
        }
        let topology = Topology::new(t.vertex_count + t.edges.len(), &faces)?;
        let mut colors = MeshColors::with_levels(topology, levels, self.channels)?;
        let c = self.channels;
        let mut value = vec![0.0f32; c];
        for f in 0..t.faces.len() {
            let lf = self.face_level[f];
            for (child, corners) in CHILD_CORNERS.iter().enumerate() {
                let g = 4 * f + child;
                for a in lattice_points(1 << (lf - 1)) {
                    let Some(i) = colors.lattice_index(g, a) else {
                        continue;
                    };
                    let parent =
                        [0, 1, 2].map(|m| (0..3).map(|k| a[k] * corners[k][m]).sum::<u32>());
                    value.fill(0.0);
                    lattice(self, f, FINEST, lf, parent, 1.0, false, &mut value);
                    colors.sample_at_mut(i).copy_from_slice(&value);
                }
            }
        }
        Ok(Subdivided {
            colors,
            faces,
            midpoints: t.edges.clone(),
        })
    }

    /// The same colours without the faces `remove` (their interior samples
    /// go; vertices stay; an edge left with one face keeps its samples,
    /// refined by interpolation if that face is finer, which leaves its
    /// colours unchanged).
    ///
    /// # Errors
    /// [`Error::MissingFace`].
    pub fn delete_faces(&self, remove: &[usize]) -> Result<MeshColors, Error> {
        let n = self.face_count();
        let mut gone = vec![false; n];
        for &f in remove {
            if f >= n {
                return Err(Error::MissingFace { face: f, count: n });
            }
            gone[f] = true;
        }
        let keep: Vec<usize> = (0..n).filter(|&f| !gone[f]).collect();
        let faces: Vec<[u32; 3]> = keep.iter().map(|&f| self.topology.faces[f]).collect();
        let levels = keep.iter().map(|&f| self.face_level[f]).collect();
        let origin: Vec<Option<usize>> = keep.iter().map(|&f| Some(f)).collect();
        let topology = Topology::new(self.topology.vertex_count, &faces)?;
        self.rebuild(topology, levels, &origin)
    }

    /// The same colours with `faces` added at `resolutions`, over
    /// `vertex_count` vertices (at least the current count; new vertices
    /// start at zero). The new faces' edge and interior samples start as
    /// the linear interpolation of their vertex colours; existing samples
    /// are kept (an existing edge that a coarser new face now shares is
    /// sub-sampled to its resolution, the continuity rule).
    ///
    /// # Errors
    /// As for [`Topology::new`] and [`MeshColors::new`].
    pub fn add_faces(
        &self,
        faces: &[[u32; 3]],
        resolutions: &[u32],
        vertex_count: usize,
    ) -> Result<MeshColors, Error> {
        if resolutions.len() != faces.len() {
            return Err(Error::ResolutionCount {
                got: resolutions.len(),
                faces: faces.len(),
            });
        }
        let n = self.face_count();
        let mut all = self.topology.faces.clone();
        all.extend_from_slice(faces);
        let mut levels = self.face_level.clone();
        for (k, &r) in resolutions.iter().enumerate() {
            levels.push(level_of(n + k, r)?);
        }
        let origin: Vec<Option<usize>> = (0..all.len()).map(|f| (f < n).then_some(f)).collect();
        let topology = Topology::new(vertex_count.max(self.topology.vertex_count), &all)?;
        self.rebuild(topology, levels, &origin)
    }

    /// The same colours with face `face` at resolution `resolution`: only
    /// that face is resampled (by linear filtering of its old samples), and
    /// those of its edges whose resolution (the lowest of their faces)
    /// changes, which keeps them continuous. Every other sample is kept.
    ///
    /// # Errors
    /// [`Error::MissingFace`], [`Error::BadResolution`].
    pub fn set_face_resolution(&self, face: usize, resolution: u32) -> Result<MeshColors, Error> {
        if face >= self.face_count() {
            return Err(Error::MissingFace {
                face,
                count: self.face_count(),
            });
        }
        let mut levels = self.face_level.clone();
        levels[face] = level_of(face, resolution)?;
        let origin: Vec<Option<usize>> = (0..self.face_count()).map(Some).collect();
        self.rebuild(self.topology.clone(), levels, &origin)
    }

    /// New colours on `topology` at `levels`, new face `g` coming from old
    /// face `origin[g]` (or new). Vertices keep their index.
    fn rebuild(
        &self,
        topology: Topology,
        levels: Vec<u8>,
        origin: &[Option<usize>],
    ) -> Result<MeshColors, Error> {
        let mut out = MeshColors::with_levels(topology, levels, self.channels)?;
        let c = self.channels;
        let shared = self.topology.vertex_count.min(out.topology.vertex_count);
        out.samples[..shared * c].copy_from_slice(&self.samples[..shared * c]);
        let old_edges: HashMap<[u32; 2], usize> = self
            .topology
            .edges
            .iter()
            .enumerate()
            .map(|(e, &k)| (k, e))
            .collect();
        let mut value = vec![0.0f32; c];
        for e in 0..out.topology.edges.len() {
            let key = out.topology.edges[e];
            let le = out.edge_level[e];
            let first = out.edge_offset[e];
            match old_edges.get(&key) {
                Some(&old) if self.edge_level[old] == le => {
                    let len = ((1usize << le) - 1) * c;
                    let from = self.edge_offset[old] * c;
                    out.samples[first * c..first * c + len]
                        .copy_from_slice(&self.samples[from..from + len]);
                }
                Some(&old) => {
                    // Evaluate the old edge's function at the new positions:
                    // copies when coarser, interpolation when finer.
                    let lp = le.max(self.edge_level[old]);
                    for s in 1..1u32 << le {
                        value.fill(0.0);
                        edge_point(
                            self,
                            old,
                            FINEST,
                            lp,
                            s << (lp - le),
                            1.0,
                            false,
                            &mut value,
                        );
                        out.sample_at_mut(first + s as usize - 1)
                            .copy_from_slice(&value);
                    }
                }
                None => {
                    let r = 1u32 << le;
                    for s in 1..r {
                        let t = s as f32 / r as f32;
                        for (ch, v) in value.iter_mut().enumerate() {
                            let (a, b) = (
                                out.samples[key[0] as usize * c + ch],
                                out.samples[key[1] as usize * c + ch],
                            );
                            *v = (1.0 - t) * a + t * b;
                        }
                        out.sample_at_mut(first + s as usize - 1)
                            .copy_from_slice(&value);
                    }
                }
            }
        }
        for g in 0..out.face_level.len() {
            let r = 1u32 << out.face_level[g];
            let first = out.face_offset[g];
            let count = crate::samples_per_face(r) as usize;
            match origin.get(g).copied().flatten() {
                Some(f) if self.face_level[f] == out.face_level[g] => {
                    let from = self.face_offset[f] * c;
                    out.samples[first * c..(first + count) * c]
                        .copy_from_slice(&self.samples[from..from + count * c]);
                }
                Some(f) => {
                    for i in 1..r {
                        for j in 1..r - i {
                            let b = sample_position(r, i, j).map(|x| x as f32);
                            eval(self, f, b, FINEST, false, &mut value);
                            let at = first + crate::structure::interior_index(r, i, j);
                            out.sample_at_mut(at).copy_from_slice(&value);
                        }
                    }
                }
                None => {
                    let face = out.topology.faces[g];
                    for i in 1..r {
                        for j in 1..r - i {
                            let b = sample_position(r, i, j);
                            for (ch, v) in value.iter_mut().enumerate() {
                                *v = (0..3)
                                    .map(|k| {
                                        b[k] * f64::from(out.vertex_at(face[k] as usize, 0)[ch])
                                    })
                                    .sum::<f64>() as f32;
                            }
                            let at = first + crate::structure::interior_index(r, i, j);
                            out.sample_at_mut(at).copy_from_slice(&value);
                        }
                    }
                }
            }
        }
        Ok(out)
    }
}
