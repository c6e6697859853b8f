//! The mesh colour structure (Sec. 3.1–3.2, Fig. 10): one sample array,
//! an index into it per vertex, edge and face, and the rule that keeps
//! edges between faces of different resolution continuous.

use glam::DVec3;

use crate::topology::{NO_FACE, Topology};
use crate::{Error, MAX_CHANNELS, MAX_LEVEL};

/// Samples on one edge of resolution `r` (Eq. 2): `r − 1`.
pub const fn samples_per_edge(r: u32) -> u32 {
    r.saturating_sub(1)
}

/// Samples inside one face of resolution `r` (Eq. 3): `(r − 1)(r − 2)/2`.
pub const fn samples_per_face(r: u32) -> u32 {
    if r < 2 { 0 } else { (r - 1) * (r - 2) / 2 }
}

/// The barycentric position of sample `C_ij` of a face of resolution `r`
/// (Eq. 4): `[i/r, j/r, 1 − (i + j)/r]`; weight `k` belongs to corner `k`.
pub fn sample_position(r: u32, i: u32, j: u32) -> [f64; 3] {
    let r = f64::from(r);
    let (i, j) = (f64::from(i), f64::from(j));
    [i / r, j / r, 1.0 - (i + j) / r]
}

/// The level `n` of a resolution `R = 2^n`, or the error naming the face.
pub fn level_of(face: usize, resolution: u32) -> Result<u8, Error> {
    if resolution == 0 || !resolution.is_power_of_two() || resolution > 1 << MAX_LEVEL {
        return Err(Error::BadResolution {
            face,
            resolution: u64::from(resolution),
        });
    }
    Ok(resolution.trailing_zeros() as u8)
}

/// Where one sample sits: a face that contains it and its barycentric
/// coordinates there (weight `k` for corner `k`). Isolated vertices have
/// `face == NO_FACE`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Site {
    /// A face the sample lies on.
    pub face: u32,
    /// Its barycentric coordinates in that face.
    pub barycentric: [f64; 3],
}

impl Site {
    /// The 3D position of the site on a mesh with these vertex positions.
    pub fn position(&self, topology: &Topology, positions: &[glam::Vec3]) -> Option<DVec3> {
        let face = topology.faces.get(self.face as usize)?;
        let mut p = DVec3::ZERO;
        for (b, &v) in self.barycentric.iter().zip(face) {
            p += *b * positions.get(v as usize)?.as_dvec3();
        }
        Some(p)
    }
}

/// Colour (any number of `f32` channels) on the vertices, edges and faces
/// of a triangle mesh, each face at its own resolution `R = 2^n`.
///
/// **Layout** (Fig. 10): one array of samples, vertex `v` at index `v`,
/// then each edge's `R_e − 1` samples in canonical order (from its smaller
/// vertex to its larger), then each face's `(R − 1)(R − 2)/2` samples, row
/// by row: `C_ij` for `i = 1..R−1`, `j = 1..R−1−i`.
///
/// **Continuity rule for mixed resolutions** (Sec. 3.2): an edge stores its
/// samples at the *lowest* resolution of its faces, `R_e = min(R_f)`. A face
/// of higher resolution reads the edge values it needs between two stored
/// samples by linear interpolation along the edge (the paper's "higher
/// resolution edge colors are linearly interpolated from the lower
/// resolution"), so both faces see one piecewise-linear function on the
/// edge. Any lookup whose point lies on an edge (a barycentric ≤ 0) is
/// evaluated from the edge's own samples and its canonical parameter
/// alone, so the linear, nearest and MIP filters return bit-identical
/// values from either face.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshColors {
    pub(crate) topology: Topology,
    pub(crate) channels: usize,
    pub(crate) face_level: Vec<u8>,
    pub(crate) edge_level: Vec<u8>,
    pub(crate) vertex_level: Vec<u8>,
    pub(crate) edge_offset: Vec<usize>,
    pub(crate) face_offset: Vec<usize>,
    pub(crate) samples: Vec<f32>,
}

impl MeshColors {
    /// Mesh colours of `channels` channels, all zero, with face `f` at
    /// resolution `resolutions[f]` (a power of two up to `2^MAX_LEVEL`).
    ///
    /// # Errors
    /// [`Error::BadResolution`] naming the face, [`Error::ResolutionCount`],
    /// [`Error::BadChannels`].
    ///
    /// # Example
    /// ```
    /// use mesh_colors::{MeshColors, Topology};
    /// let topology = Topology::new(4, &[[0, 1, 2], [2, 1, 3]])?;
    /// // Face 0 at resolution 4, face 1 at 2, RGB.
    /// let colors = MeshColors::new(topology, &[4, 2], 3)?;
    /// assert_eq!(colors.face_resolution(0), Some(4));
    /// // 3 is not a power of two.
    /// let topology = Topology::new(4, &[[0, 1, 2], [2, 1, 3]])?;
    /// assert!(MeshColors::new(topology, &[3, 2], 3).is_err());
    /// # Ok::<(), mesh_colors::Error>(())
    /// ```
    pub fn new(topology: Topology, resolutions: &[u32], channels: usize) -> Result<Self, Error> {
        if resolutions.len() != topology.faces.len() {
            return Err(Error::ResolutionCount {
                got: resolutions.len(),
                faces: topology.faces.len(),
            });
        }
        let levels = resolutions
            .iter()
            .enumerate()
            .map(|(f, &r)| level_of(f, r))
            .collect::<Result<Vec<_>, _>>()?;
        Self::with_levels(topology, levels, channels)
    }

    /// As [`MeshColors::new`] with the same resolution on every face.
    ///
    /// # Errors
    /// As for [`MeshColors::new`].
    pub fn uniform(topology: Topology, resolution: u32, channels: usize) -> Result<Self, Error> {
        let r = vec![resolution; topology.faces.len()];
        Self::new(topology, &r, channels)
    }

    /// Builds the layout for per-face levels (already checked).
    pub(crate) fn with_levels(
        topology: Topology,
        levels: Vec<u8>,
        channels: usize,
    ) -> Result<Self, Error> {
        if channels == 0 || channels > MAX_CHANNELS {
            return Err(Error::BadChannels(channels));
        }
        if let Some(f) = levels.iter().position(|&n| n > MAX_LEVEL) {
            return Err(Error::BadResolution {
                face: f,
                resolution: 1u64 << levels[f].min(63),
            });
        }
        // The layout's size, checked against the budget before anything
        // sized by it (or by the vertex count) is allocated.
        let values = layout_sample_count(&topology, &levels).saturating_mul(channels as u64);
        if values > crate::MAX_SAMPLE_VALUES {
            return Err(Error::TooLarge {
                what: "the mesh colours",
                requested: values,
                budget: crate::MAX_SAMPLE_VALUES,
                unit: "f32 values",
            });
        }
        let (edge_level, vertex_level) = primitive_levels(&topology, &levels);
        let mut next = topology.vertex_count;
        let edge_offset = edge_level
            .iter()
            .map(|&n| {
                let at = next;
                next += samples_per_edge(1 << n) as usize;
                at
            })
            .collect();
        let face_offset = levels
            .iter()
            .map(|&n| {
                let at = next;
                next += samples_per_face(1 << n) as usize;
                at
            })
            .collect();
        Ok(Self {
            topology,
            channels,
            face_level: levels,
            edge_level,
            vertex_level,
            edge_offset,
            face_offset,
            samples: vec![0.0; next * channels],
        })
    }

    /// The connectivity.
    pub fn topology(&self) -> &Topology {
        &self.topology
    }

    /// Channels per sample.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The number of faces.
    pub fn face_count(&self) -> usize {
        self.face_level.len()
    }

    /// The number of samples (colours), `samples().len() / channels()`.
    pub fn sample_count(&self) -> usize {
        self.samples.len() / self.channels
    }

    /// Face `f`'s resolution `R`. The per-primitive accessors below return
    /// `None` for an index out of range.
    pub fn face_resolution(&self, f: usize) -> Option<u32> {
        self.face_level.get(f).map(|&n| 1 << n)
    }

    /// Face `f`'s level `n` (`R = 2^n`).
    pub fn face_level(&self, f: usize) -> Option<u8> {
        self.face_level.get(f).copied()
    }

    /// Edge `e`'s resolution: the lowest of its faces (the continuity rule).
    pub fn edge_resolution(&self, e: usize) -> Option<u32> {
        self.edge_level.get(e).map(|&n| 1 << n)
    }

    /// All samples, `channels()` values each, in the layout described on
    /// [`MeshColors`].
    pub fn samples(&self) -> &[f32] {
        &self.samples
    }

    /// Heap bytes of these colours: the samples (`4 · channels` bytes
    /// each) and the per-primitive levels and indices, not counting the
    /// [`Topology`] (which the mesh has anyway).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.samples.capacity() * std::mem::size_of::<f32>()
            + (self.face_level.capacity()
                + self.edge_level.capacity()
                + self.vertex_level.capacity())
            + (self.edge_offset.capacity() + self.face_offset.capacity())
                * std::mem::size_of::<usize>()
    }

    /// Gives back the spare capacity a resolution change left (the sample
    /// array grows as samples are inserted), so that
    /// [`memory_bytes`](Self::memory_bytes) is what the colours need. One
    /// copy of the samples at most.
    pub fn shrink_to_fit(&mut self) {
        self.samples.shrink_to_fit();
        self.edge_offset.shrink_to_fit();
        self.face_offset.shrink_to_fit();
    }

    /// All samples, mutable.
    pub fn samples_mut(&mut self) -> &mut [f32] {
        &mut self.samples
    }

    /// The index of vertex `v`'s sample (Fig. 10: the vertex index).
    pub fn vertex_index(&self, v: usize) -> Option<usize> {
        (v < self.topology.vertex_count).then_some(v)
    }

    /// The index of edge `e`'s first sample; the `R_e − 1` samples follow
    /// in canonical order.
    pub fn edge_index(&self, e: usize) -> Option<usize> {
        self.edge_offset.get(e).copied()
    }

    /// The index of face `f`'s first interior sample; the rest follow.
    pub fn face_index(&self, f: usize) -> Option<usize> {
        self.face_offset.get(f).copied()
    }

    /// Face `f`'s level, for indices the crate knows are in range.
    #[inline]
    pub(crate) fn level_at(&self, f: usize) -> u8 {
        self.face_level[f]
    }

    /// Sample `i`'s values, for indices the crate knows are in range.
    #[inline]
    pub(crate) fn sample_at_mut(&mut self, i: usize) -> &mut [f32] {
        &mut self.samples[i * self.channels..(i + 1) * self.channels]
    }

    /// Sample `i`'s values, `None` if `i >= sample_count()`.
    pub fn sample(&self, i: usize) -> Option<&[f32]> {
        let c = self.channels;
        self.samples
            .get(i.checked_mul(c)?..i.checked_add(1)?.checked_mul(c)?)
    }

    /// Sample `i`'s values, mutable; `None` if `i >= sample_count()`.
    pub fn sample_mut(&mut self, i: usize) -> Option<&mut [f32]> {
        let c = self.channels;
        self.samples
            .get_mut(i.checked_mul(c)?..i.checked_add(1)?.checked_mul(c)?)
    }

    /// The sample index of lattice point `a = (a0, a1, a2)` (Eq. 4 with
    /// `i = a0`, `j = a1`, `a0 + a1 + a2 = R`) of face `f` at its own
    /// resolution, when a stored sample sits there; `None` for a point on
    /// an edge of lower resolution that falls between two stored samples.
    pub fn lattice_index(&self, f: usize, a: [u32; 3]) -> Option<usize> {
        let n = *self.face_level.get(f)?;
        let r = 1u32 << n;
        if u64::from(a[0]) + u64::from(a[1]) + u64::from(a[2]) != u64::from(r) {
            return None;
        }
        let face = self.topology.faces[f];
        for k in 0..3 {
            if a[k] == r {
                return Some(face[k] as usize);
            }
        }
        for m in 0..3 {
            if a[m] == 0 {
                let k = (m + 1) % 3;
                let e = self.topology.face_edges[f][k] as usize;
                let p = edge_param(face, k, a, r);
                let d = n - self.edge_level[e];
                if p & ((1 << d) - 1) != 0 {
                    return None;
                }
                return Some(self.edge_offset[e] + (p >> d) as usize - 1);
            }
        }
        Some(self.face_offset[f] + interior_index(r, a[0], a[1]))
    }

    /// One site per sample: a face containing it and its barycentrics.
    pub fn sites(&self) -> Vec<Site> {
        let mut sites = vec![
            Site {
                face: NO_FACE,
                barycentric: [0.0; 3]
            };
            self.sample_count()
        ];
        for f in 0..self.face_count() {
            let r = 1u32 << self.level_at(f);
            for a in lattice_points(r) {
                if let Some(i) = self.lattice_index(f, a)
                    && sites[i].face == NO_FACE
                {
                    sites[i] = Site {
                        face: f as u32,
                        barycentric: sample_position(r, a[0], a[1]),
                    };
                }
            }
        }
        sites
    }

    /// The sites of edge `e`'s samples, as [`MeshColors::sites`] gives
    /// them (on the edge's first face, in face order): `f(sample, site)`.
    pub(crate) fn edge_sites(&self, e: usize, mut f: impl FnMut(usize, Site)) {
        let t = &self.topology;
        let Some(g) = t.edge_faces[e]
            .iter()
            .copied()
            .filter(|&g| g != NO_FACE)
            .min()
        else {
            return;
        };
        let g = g as usize;
        let Some(k) = (0..3).find(|&k| t.face_edges[g][k] as usize == e) else {
            return;
        };
        // Every face of an edge is at least as fine as the edge, so its
        // lattice reaches each of the edge's samples.
        let r = 1u32 << self.face_level[g];
        for s in 1..r {
            let mut a = [0u32; 3];
            a[k] = r - s;
            a[(k + 1) % 3] = s;
            if let Some(i) = self.lattice_index(g, a)
                && i >= self.topology.vertex_count
            {
                let barycentric = sample_position(r, a[0], a[1]);
                f(
                    i,
                    Site {
                        face: g as u32,
                        barycentric,
                    },
                );
            }
        }
    }

    /// The sites of face `f`'s interior samples (on `f`): `out(sample,
    /// site)`.
    pub(crate) fn face_sites(&self, f: usize, mut out: impl FnMut(usize, Site)) {
        let r = 1u32 << self.face_level[f];
        for i in 1..r {
            for j in 1..r - i {
                out(
                    self.face_offset[f] + interior_index(r, i, j),
                    Site {
                        face: f as u32,
                        barycentric: sample_position(r, i, j),
                    },
                );
            }
        }
    }

    /// Sets every sample from a function of its 3D position, `f(p, out)`
    /// writing `channels()` values.
    ///
    /// # Errors
    /// [`Error::ChannelMismatch`] if `positions` has fewer entries than the
    /// topology's vertices.
    pub fn fill(
        &mut self,
        positions: &[glam::Vec3],
        mut f: impl FnMut(DVec3, &mut [f32]),
    ) -> Result<(), Error> {
        if positions.len() < self.topology.vertex_count {
            return Err(Error::ChannelMismatch {
                what: "positions",
                expected: self.topology.vertex_count,
                got: positions.len(),
            });
        }
        let sites = self.sites();
        let c = self.channels;
        for (i, site) in sites.iter().enumerate() {
            let p = site
                .position(&self.topology, positions)
                .unwrap_or_else(|| positions[i].as_dvec3());
            f(p, &mut self.samples[i * c..(i + 1) * c]);
        }
        Ok(())
    }
}

/// Edge levels (minimum of the faces: the continuity rule) and vertex
/// levels (maximum of the faces: the finest MIP level a vertex needs).
pub(crate) fn primitive_levels(topology: &Topology, levels: &[u8]) -> (Vec<u8>, Vec<u8>) {
    let edge_level = edge_levels(topology, levels).collect();
    let mut vertex_level = vec![0u8; topology.vertex_count];
    for (face, &n) in topology.faces.iter().zip(levels) {
        for &v in face {
            vertex_level[v as usize] = vertex_level[v as usize].max(n);
        }
    }
    (edge_level, vertex_level)
}

/// Each edge's level: the lowest of its faces' (Sec. 3.2).
fn edge_levels<'a>(topology: &'a Topology, levels: &'a [u8]) -> impl Iterator<Item = u8> + 'a {
    topology.edge_faces.iter().map(move |fs| {
        fs.iter()
            .filter(|&&f| f != NO_FACE)
            .map(|&f| levels[f as usize])
            .min()
            .unwrap_or(0)
    })
}

/// Total samples (Eq. 1–3 summed) for these face levels on this topology,
/// without allocating anything: the budget check, the conversion's budget
/// and the file reader's size check all need it.
pub(crate) fn layout_sample_count(topology: &Topology, levels: &[u8]) -> u64 {
    // Saturating: a vertex count near usize::MAX must come out as "too
    // large", not overflow.
    (topology.vertex_count as u64)
        .saturating_add(
            edge_levels(topology, levels)
                .map(|n| u64::from(samples_per_edge(1 << n)))
                .sum::<u64>(),
        )
        .saturating_add(
            levels
                .iter()
                .map(|&n| u64::from(samples_per_face(1 << n)))
                .sum::<u64>(),
        )
}

/// The canonical position (in steps of `1/r` from the edge's smaller
/// vertex) of lattice point `a` on local edge `k` of a face.
#[inline]
pub(crate) fn edge_param(face: [u32; 3], k: usize, a: [u32; 3], r: u32) -> u32 {
    let t = a[(k + 1) % 3];
    if face[k] < face[(k + 1) % 3] {
        t
    } else {
        r - t
    }
}

/// Row-major index of interior sample `C_ij` (`i, j ≥ 1`, `i + j ≤ r − 1`).
#[inline]
pub(crate) fn interior_index(r: u32, i: u32, j: u32) -> usize {
    let (r, i, j) = (r as usize, i as usize, j as usize);
    (i - 1) * (r - 1) - (i - 1) * i / 2 + (j - 1)
}

/// Every lattice point `(i, j, r − i − j)` of a face of resolution `r`.
pub fn lattice_points(r: u32) -> impl Iterator<Item = [u32; 3]> {
    (0..=r).flat_map(move |i| (0..=r - i).map(move |j| [i, j, r - i - j]))
}

/// Moves the segments `(old offset, new offset, length, keep)` (in values
/// of `c` floats, in layout order: both offsets increase and the new
/// segments do not overlap) of `buf` in place to a layout of `total`
/// values; segments not kept are left for the caller to write. Segments
/// moving towards the front go first, front to back, then those moving
/// towards the back, back to front: neither overwrites a segment still to
/// be moved. Only a grown tail is newly allocated.
pub(crate) fn move_segments<T: Copy + Default>(
    buf: &mut Vec<T>,
    c: usize,
    segments: &[(usize, usize, usize, bool)],
    total: usize,
) {
    if buf.len() < total * c {
        buf.resize(total * c, T::default());
    }
    for &(from, to, len, keep) in segments {
        if keep && to < from {
            buf.copy_within(from * c..(from + len) * c, to * c);
        }
    }
    for &(from, to, len, keep) in segments.iter().rev() {
        if keep && to > from {
            buf.copy_within(from * c..(from + len) * c, to * c);
        }
    }
    buf.truncate(total * c);
}
