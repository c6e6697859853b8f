//! Which faces read which samples: a stroke changes samples, a scatter
//! keeps its points per face, and this index joins the two.

use mesh_colors::MeshColors;

/// For every sample, the faces whose colours it enters (a vertex sample
/// reaches the faces around the vertex, an edge sample the one or two
/// faces beside the edge, an interior sample its face), in compressed
/// rows. Rebuilt when the face resolutions change (the sample numbering
/// is new then).
#[derive(Debug, Clone, Default)]
pub(crate) struct SampleFaces {
    /// `starts[i]..starts[i + 1]` indexes `faces` for sample `i`.
    starts: Vec<u32>,
    faces: Vec<u32>,
}

impl SampleFaces {
    /// The index of `colors`.
    pub(crate) fn new(colors: &MeshColors) -> Self {
        let n = colors.sample_count();
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        let topology = colors.topology();
        for (f, (corners, edges)) in topology
            .faces()
            .iter()
            .zip(topology.face_edges())
            .enumerate()
        {
            let f = f as u32;
            for &v in corners {
                pairs.extend(colors.vertex_index(v as usize).map(|i| (i as u32, f)));
            }
            for &e in edges {
                let (Some(first), Some(r)) = (
                    colors.edge_index(e as usize),
                    colors.edge_resolution(e as usize),
                ) else {
                    continue;
                };
                pairs.extend((first..first + r as usize - 1).map(|i| (i as u32, f)));
            }
            if let (Some(first), Some(r)) = (
                colors.face_index(f as usize),
                colors.face_resolution(f as usize),
            ) {
                let interior = (r as usize).saturating_sub(1) * (r as usize).saturating_sub(2) / 2;
                pairs.extend((first..first + interior).map(|i| (i as u32, f)));
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut starts = vec![0u32; n + 1];
        for &(i, _) in &pairs {
            starts[i as usize + 1] += 1;
        }
        for i in 0..n {
            starts[i + 1] += starts[i];
        }
        Self {
            starts,
            faces: pairs.into_iter().map(|(_, f)| f).collect(),
        }
    }

    /// The faces `samples` reach, sorted, each once (indices beyond the
    /// index are skipped).
    pub(crate) fn faces_of(&self, samples: &[u32]) -> Vec<u32> {
        let mut faces: Vec<u32> = samples
            .iter()
            .filter(|&&i| (i as usize) + 1 < self.starts.len())
            .flat_map(|&i| {
                let (a, b) = (self.starts[i as usize], self.starts[i as usize + 1]);
                self.faces[a as usize..b as usize].iter().copied()
            })
            .collect();
        faces.sort_unstable();
        faces.dedup();
        faces
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mesh_colors::Topology;

    /// Two triangles sharing the edge 1–2, at resolution 4.
    fn pair() -> MeshColors {
        let t = Topology::new(4, &[[0, 1, 2], [2, 1, 3]]).unwrap();
        MeshColors::uniform(t, 4, 1).unwrap()
    }

    #[test]
    fn samples_reach_the_faces_that_read_them() {
        let c = pair();
        let index = SampleFaces::new(&c);
        // Vertex 0 is on face 0 only, vertex 1 on both, vertex 3 on face 1.
        assert_eq!(index.faces_of(&[0]), vec![0]);
        assert_eq!(index.faces_of(&[1]), vec![0, 1]);
        assert_eq!(index.faces_of(&[3]), vec![1]);
        // The shared edge's samples reach both faces; face 1's interior
        // only face 1.
        let shared = c.topology().edge_between(1, 2).unwrap() as usize;
        let first = c.edge_index(shared).unwrap() as u32;
        assert_eq!(index.faces_of(&[first, first + 1]), vec![0, 1]);
        let inner = c.face_index(1).unwrap() as u32;
        assert_eq!(index.faces_of(&[inner]), vec![1]);
        assert!(index.faces_of(&[c.sample_count() as u32]).is_empty());
    }

    /// Every face's linear lookups read only samples that reach it: a
    /// sample changed alone changes exactly the faces the index names.
    #[test]
    fn a_changed_sample_changes_only_the_faces_it_reaches() {
        let base = pair();
        let index = SampleFaces::new(&base);
        let probes = [
            [0.2f32, 0.3, 0.5],
            [0.6, 0.2, 0.2],
            [0.0, 0.5, 0.5],
            [1.0, 0.0, 0.0],
        ];
        let values = |c: &MeshColors, f: usize| -> Vec<f32> {
            probes
                .iter()
                .map(|b| {
                    let mut out = [0.0];
                    c.linear(f, *b, &mut out).unwrap();
                    out[0]
                })
                .collect()
        };
        for i in 0..base.sample_count() {
            let mut c = base.clone();
            c.sample_mut(i).unwrap()[0] = 1.0;
            let reached = index.faces_of(&[i as u32]);
            for f in 0..2u32 {
                if !reached.contains(&f) {
                    assert_eq!(
                        values(&c, f as usize),
                        values(&base, f as usize),
                        "sample {i}"
                    );
                }
            }
            assert!(!reached.is_empty(), "sample {i} reaches no face");
        }
    }
}
