//! The tetrahedral mesh: validation, one-ring neighbourhoods, face
//! adjacency, the boundary surface with outward normals and per-vertex
//! boundary areas `S_i` (TransCut Sec. 3.2), and a quality report.

use glam::DVec3;
use rayon::prelude::*;

use crate::Error;
use crate::geometry::{EDGES, OUTWARD_FACES, dihedral_angles, volume6};

/// "No neighbour" in [`TetMesh::tet_neighbors`].
pub const NONE: u32 = u32::MAX;

/// Compressed rows: `items[offsets[i]..offsets[i + 1]]` belong to `i`.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub(crate) struct Csr {
    pub(crate) offsets: Vec<usize>,
    pub(crate) items: Vec<u32>,
}

impl Csr {
    #[inline]
    pub(crate) fn row(&self, i: usize) -> &[u32] {
        &self.items[self.offsets[i]..self.offsets[i + 1]]
    }
}

/// A validated tetrahedral mesh with its neighbourhoods and boundary.
///
/// Positions are in any length unit (the physics says how many
/// millimetres one unit is, see [`crate::Object`]). Every tetrahedron is
/// stored positively oriented: `det[p1 − p0, p2 − p0, p3 − p0] > 0`.
#[derive(Debug, Clone)]
pub struct TetMesh {
    positions: Vec<DVec3>,
    tets: Vec<[u32; 4]>,
    original: Vec<u32>,
    reoriented: usize,
    vertex_tets: Csr,
    neighbors: Csr,
    /// Parallel to `vertex_tets.items`: for vertex `i` and its tet `t`,
    /// entry `b` is the position of column `tets[t][b]` within row `i` of
    /// the matrix (CSR, columns = the vertex and its one-ring, ascending),
    /// the diagonal where `tets[t][b] == i`. Fixed per mesh: every assembly, paint and
    /// rebuild reuses it instead of searching the rows.
    slots: Vec<[u32; 4]>,
    tet_neighbors: Vec<[u32; 4]>,
    boundary: Vec<[u32; 3]>,
    boundary_vertices: Vec<u32>,
    boundary_index: Vec<u32>,
    vertex_area: Vec<f64>,
    vertex_normal: Vec<DVec3>,
}

impl TetMesh {
    /// Bytes of the arrays this mesh holds (positions, tets, adjacency,
    /// boundary), to budget copies of it.
    pub fn memory_bytes(&self) -> usize {
        let csr = |c: &Csr| c.offsets.len() * 8 + c.items.len() * 4;
        self.positions.len() * 24
            + self.tets.len() * (16 + 4 + 16 + 16)
            + csr(&self.vertex_tets)
            + csr(&self.neighbors)
            + self.boundary.len() * 12
            + self.boundary_vertices.len() * 4
            + self.boundary_index.len() * 4
            + self.vertex_area.len() * 8
            + self.vertex_normal.len() * 24
    }

    /// Builds and validates a mesh from positions and four vertex indices
    /// per tetrahedron (0-based): exactly the fields of a TetGen, Gmsh or
    /// MEDIT file as `trilux_io::tet::TetMesh` reads them.
    ///
    /// Negatively oriented tetrahedra are re-oriented (two indices
    /// swapped) and counted ([`reoriented`](Self::reoriented)).
    ///
    /// # Errors
    /// [`Error::EmptyMesh`], [`Error::TooLarge`],
    /// [`Error::NonFinitePosition`], [`Error::IndexOutOfRange`],
    /// [`Error::RepeatedVertex`], [`Error::UnusedVertex`] (a vertex no
    /// tetrahedron uses), [`Error::DegenerateTet`] (zero volume
    /// relative to the tet's size, naming the tet),
    /// [`Error::NonManifoldFace`].
    ///
    /// # Example
    /// ```
    /// use tet_diffusion::{glam::DVec3, TetMesh};
    /// let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    /// let mesh = TetMesh::new(&p, &[[0, 2, 1, 3]])?; // inverted: re-oriented
    /// assert_eq!((mesh.reoriented(), mesh.boundary().len()), (1, 4));
    /// # Ok::<(), tet_diffusion::Error>(())
    /// ```
    pub fn new(positions: &[DVec3], tets: &[[u32; 4]]) -> Result<Self, Error> {
        let original = (0..tets.len() as u32).collect();
        let mesh = Self::with_original(positions.to_vec(), tets.to_vec(), original)?;
        // A vertex without tetrahedra has an empty row in every system
        // built on the mesh: named here, not a zero diagonal in a solver.
        // (The indices are valid now.)
        if let Some(vertex) = mesh
            .vertex_tets
            .offsets
            .windows(2)
            .position(|w| w[0] == w[1])
        {
            let count = mesh
                .vertex_tets
                .offsets
                .windows(2)
                .filter(|w| w[0] == w[1])
                .count();
            return Err(Error::UnusedVertex { vertex, count });
        }
        Ok(mesh)
    }

    /// [`new`](Self::new) with each tet's id in the mesh it was cut from.
    pub(crate) fn with_original(
        positions: Vec<DVec3>,
        mut tets: Vec<[u32; 4]>,
        original: Vec<u32>,
    ) -> Result<Self, Error> {
        if positions.is_empty() || tets.is_empty() {
            return Err(Error::EmptyMesh {
                vertices: positions.len(),
                tets: tets.len(),
            });
        }
        if positions.len() >= NONE as usize {
            return Err(Error::TooLarge {
                what: "vertices",
                count: positions.len(),
            });
        }
        if tets.len() >= NONE as usize {
            return Err(Error::TooLarge {
                what: "tetrahedra",
                count: tets.len(),
            });
        }
        if let Some(v) = positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::NonFinitePosition {
                vertex: v,
                position: positions[v].to_array(),
            });
        }
        let n = positions.len();
        // Validate and orient in parallel; the first bad tet (lowest index)
        // is reported, whatever the number of threads.
        let results: Vec<Result<bool, Error>> = tets
            .par_iter_mut()
            .enumerate()
            .map(|(t, tet)| orient(t, tet, &positions))
            .collect();
        let mut reoriented = 0;
        for r in results {
            if r? {
                reoriented += 1;
            }
        }
        debug_assert!(tets.iter().flatten().all(|&v| (v as usize) < n));
        let vertex_tets = vertex_tets(n, &tets);
        let (neighbors, slots) = neighbors(&vertex_tets, &tets);
        let (tet_neighbors, boundary) = faces(&tets)?;
        let mut mesh = Self {
            positions,
            tets,
            original,
            reoriented,
            vertex_tets,
            neighbors,
            slots,
            tet_neighbors,
            boundary,
            boundary_vertices: Vec::new(),
            boundary_index: Vec::new(),
            vertex_area: Vec::new(),
            vertex_normal: Vec::new(),
        };
        mesh.boundary_attributes();
        Ok(mesh)
    }

    /// The sub-mesh of the tets `keep` (ascending), with vertex `v` of
    /// this mesh renumbered `new_index[v]` and `old_of_new` its inverse.
    /// What a cut leaves: the tets are already validated and oriented and
    /// their face adjacency is known, so only what the removal changes is
    /// recomputed (no re-validation, no sort of the faces). Equal to
    /// building the sub-mesh from scratch with [`with_original`](Self::with_original).
    pub(crate) fn subset(
        &self,
        keep: &[usize],
        new_index: &[u32],
        old_of_new: &[usize],
    ) -> Result<Self, Error> {
        let positions: Vec<DVec3> = old_of_new.par_iter().map(|&v| self.positions[v]).collect();
        let tets: Vec<[u32; 4]> = keep
            .par_iter()
            .map(|&t| self.tets[t].map(|v| new_index[v as usize]))
            .collect();
        let original: Vec<u32> = keep.par_iter().map(|&t| self.original[t]).collect();
        let mut new_tet = vec![NONE; self.tets.len()];
        for (k, &t) in keep.iter().enumerate() {
            new_tet[t] = k as u32;
        }
        let tet_neighbors: Vec<[u32; 4]> = keep
            .par_iter()
            .map(|&t| {
                self.tet_neighbors[t].map(|o| if o == NONE { NONE } else { new_tet[o as usize] })
            })
            .collect();
        Ok(Self::with_adjacency(
            positions,
            tets,
            original,
            tet_neighbors,
        ))
    }

    /// A mesh made mostly of this one's tets: what an exact cut or a
    /// fracture leaves. `tets` are positively oriented; `tets[k]` with
    /// `from[k] = t` (not [`NONE`]) is this mesh's tet `t` with vertex `v`
    /// renumbered `new_index[v]`, so its face adjacency to another such tet
    /// is kept; only the faces of the new tets and of the kept tets next to
    /// a tet not kept whole are matched (no re-validation, no sort of all
    /// the faces). Equal to building it with
    /// [`with_original`](Self::with_original).
    ///
    /// # Errors
    /// [`Error::EmptyMesh`], [`Error::TooLarge`],
    /// [`Error::NonManifoldFace`].
    pub(crate) fn derived(
        &self,
        positions: Vec<DVec3>,
        tets: Vec<[u32; 4]>,
        original: Vec<u32>,
        from: &[u32],
        new_index: &[u32],
    ) -> Result<Self, Error> {
        if positions.is_empty() || tets.is_empty() {
            return Err(Error::EmptyMesh {
                vertices: positions.len(),
                tets: tets.len(),
            });
        }
        if positions.len() >= NONE as usize || tets.len() >= NONE as usize {
            return Err(Error::TooLarge {
                what: "vertices or tetrahedra",
                count: positions.len().max(tets.len()),
            });
        }
        // A kept tet is one of ours only if it is ours renumbered.
        let from: Vec<u32> = from
            .par_iter()
            .zip(&tets)
            .map(|(&t, tet)| {
                let ours =
                    t != NONE && self.tets[t as usize].map(|v| new_index[v as usize]) == *tet;
                if ours { t } else { NONE }
            })
            .collect();
        let mut kept = vec![NONE; self.tets.len()];
        for (k, &t) in from.iter().enumerate() {
            if t != NONE {
                kept[t as usize] = k as u32;
            }
        }
        // Adjacency: kept where both sides are kept whole; the other faces
        // (`PENDING`) are matched below.
        const PENDING: u32 = NONE - 1;
        let mut tet_neighbors: Vec<[u32; 4]> = from
            .par_iter()
            .map(|&t| {
                if t == NONE {
                    return [PENDING; 4];
                }
                self.tet_neighbors[t as usize].map(|o| {
                    if o == NONE {
                        NONE
                    } else if kept[o as usize] != NONE {
                        kept[o as usize]
                    } else {
                        PENDING
                    }
                })
            })
            .collect();
        let mut keys: Vec<([u32; 3], u32)> = tet_neighbors
            .par_iter()
            .enumerate()
            .flat_map_iter(|(t, adjacent)| {
                let tet = tets[t];
                (0..4).filter(|&k| adjacent[k] == PENDING).map(move |k| {
                    let mut f = OUTWARD_FACES[k].map(|l| tet[l]);
                    f.sort_unstable();
                    (f, (t * 4 + k) as u32)
                })
            })
            .collect();
        keys.par_sort_unstable();
        let mut i = 0;
        while i < keys.len() {
            let mut j = i + 1;
            while j < keys.len() && keys[j].0 == keys[i].0 {
                j += 1;
            }
            let at = |key: u32| ((key / 4) as usize, (key % 4) as usize);
            match j - i {
                1 => {
                    let (t, k) = at(keys[i].1);
                    tet_neighbors[t][k] = NONE;
                }
                2 => {
                    let ((a, ka), (b, kb)) = (at(keys[i].1), at(keys[i + 1].1));
                    tet_neighbors[a][ka] = b as u32;
                    tet_neighbors[b][kb] = a as u32;
                }
                _ => {
                    return Err(Error::NonManifoldFace {
                        face: keys[i].0,
                        tet: (keys[i + 2].1 / 4) as usize,
                    });
                }
            }
            i = j;
        }
        Ok(Self::with_adjacency(
            positions,
            tets,
            original,
            tet_neighbors,
        ))
    }

    /// The mesh of validated, positively oriented `tets` whose face
    /// adjacency is known: the boundary, one-rings and boundary areas.
    fn with_adjacency(
        positions: Vec<DVec3>,
        tets: Vec<[u32; 4]>,
        original: Vec<u32>,
        tet_neighbors: Vec<[u32; 4]>,
    ) -> Self {
        // Ordered by (tet, local face), as `faces` orders them.
        let mut boundary = Vec::new();
        for (t, adjacent) in tet_neighbors.iter().enumerate() {
            for (k, &o) in adjacent.iter().enumerate() {
                if o == NONE {
                    boundary.push(OUTWARD_FACES[k].map(|l| tets[t][l]));
                }
            }
        }
        let n = positions.len();
        let vertex_tets = vertex_tets(n, &tets);
        let (neighbors, slots) = neighbors(&vertex_tets, &tets);
        let mut mesh = Self {
            positions,
            tets,
            original,
            reoriented: 0,
            vertex_tets,
            neighbors,
            slots,
            tet_neighbors,
            boundary,
            boundary_vertices: Vec::new(),
            boundary_index: Vec::new(),
            vertex_area: Vec::new(),
            vertex_normal: Vec::new(),
        };
        mesh.boundary_attributes();
        mesh
    }

    /// Boundary vertex list, per-vertex areas `S_i` and area-weighted
    /// normals.
    fn boundary_attributes(&mut self) {
        let n = self.positions.len();
        let mut area = vec![0.0; n];
        let mut normal = vec![DVec3::ZERO; n];
        for f in &self.boundary {
            let [a, b, c] = f.map(|v| self.positions[v as usize]);
            let cross = (b - a).cross(c - a);
            for &v in f {
                area[v as usize] += 0.5 * cross.length();
                normal[v as usize] += cross;
            }
        }
        let mut boundary_index = vec![NONE; n];
        let mut boundary_vertices = Vec::new();
        for v in 0..n {
            if area[v] > 0.0 {
                boundary_index[v] = boundary_vertices.len() as u32;
                boundary_vertices.push(v as u32);
            }
        }
        self.vertex_area = area;
        self.vertex_normal = normal.into_iter().map(DVec3::normalize_or_zero).collect();
        self.boundary_vertices = boundary_vertices;
        self.boundary_index = boundary_index;
    }

    /// Moves the vertices without changing the topology (the caller keeps
    /// every tet positively oriented), and updates the boundary areas and
    /// normals.
    pub(crate) fn move_vertices(&mut self, positions: Vec<DVec3>) {
        debug_assert_eq!(positions.len(), self.positions.len());
        self.positions = positions;
        self.boundary_attributes();
    }

    /// Vertex positions, in mesh units.
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// Tetrahedra, positively oriented.
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// Each tetrahedron's id in the mesh this one was cut or split from
    /// (its own index for a mesh made by [`new`](Self::new)).
    pub fn original_ids(&self) -> &[u32] {
        &self.original
    }

    /// How many tetrahedra were negatively oriented and re-oriented.
    pub fn reoriented(&self) -> usize {
        self.reoriented
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// The one-ring of vertex `v`: the vertices sharing an edge with it,
    /// ascending.
    pub fn one_ring(&self, v: usize) -> &[u32] {
        self.neighbors.row(v)
    }

    /// The tetrahedra containing vertex `v`, ascending.
    pub fn vertex_tets(&self, v: usize) -> &[u32] {
        self.vertex_tets.row(v)
    }

    /// The positions within row `v` of the matrix of the corners of `v`'s
    /// tets (see the field `slots`), in the order of
    /// [`vertex_tets`](Self::vertex_tets).
    pub(crate) fn vertex_slots(&self, v: usize) -> &[[u32; 4]] {
        &self.slots[self.vertex_tets.offsets[v]..self.vertex_tets.offsets[v + 1]]
    }

    /// Start of row `v` in the matrix's value array: the entries before
    /// it are the one-rings of the vertices before it plus their
    /// diagonals.
    pub(crate) fn row_start(&self, v: usize) -> usize {
        self.neighbors.offsets[v] + v
    }

    /// Number of edges.
    pub fn edge_count(&self) -> usize {
        self.neighbors.items.len() / 2
    }

    /// The edges `(i, j)` with `i < j`, in ascending order.
    pub fn edges(&self) -> impl Iterator<Item = [u32; 2]> + '_ {
        (0..self.vertex_count()).flat_map(move |i| {
            self.one_ring(i)
                .iter()
                .filter(move |&&j| j as usize > i)
                .map(move |&j| [i as u32, j])
        })
    }

    /// Face adjacency: entry `k` of tet `t` is the tetrahedron across the
    /// face opposite local vertex `k`, or [`NONE`] on the boundary.
    pub fn tet_neighbors(&self) -> &[[u32; 4]] {
        &self.tet_neighbors
    }

    /// The boundary triangles, oriented with outward normals (right-hand
    /// rule), ordered by (tetrahedron, local face).
    pub fn boundary(&self) -> &[[u32; 3]] {
        &self.boundary
    }

    /// The vertices on the boundary, ascending.
    pub fn boundary_vertices(&self) -> &[u32] {
        &self.boundary_vertices
    }

    /// Position of vertex `v` in [`boundary_vertices`](Self::boundary_vertices),
    /// or `None` for an interior vertex.
    pub fn boundary_index(&self, v: usize) -> Option<usize> {
        match self.boundary_index.get(v) {
            Some(&i) if i != NONE => Some(i as usize),
            _ => None,
        }
    }

    /// `S_i`: the summed area of the boundary triangles sharing each vertex
    /// (0 inside), in mesh units². The vertex's share is `S_i / 3`.
    pub fn vertex_areas(&self) -> &[f64] {
        &self.vertex_area
    }

    /// Area-weighted outward unit normals of the boundary vertices (zero
    /// inside).
    pub fn vertex_normals(&self) -> &[DVec3] {
        &self.vertex_normal
    }

    /// The corners of tet `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [DVec3; 4] {
        self.tets[t].map(|v| self.positions[v as usize])
    }

    /// Volume of tet `t`.
    pub fn tet_volume(&self, t: usize) -> f64 {
        volume6(&self.corners(t)) / 6.0
    }

    /// Total volume.
    pub fn volume(&self) -> f64 {
        (0..self.tets.len())
            .into_par_iter()
            .with_min_len(4096)
            .map(|t| self.tet_volume(t))
            .sum()
    }

    /// Centre (mean of the corners) of tet `t`.
    pub fn tet_center(&self, t: usize) -> DVec3 {
        let c = self.corners(t);
        (c[0] + c[1] + c[2] + c[3]) * 0.25
    }

    /// The six dihedral angles (radians) of tet `t`, at its local edges
    /// (0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3).
    pub fn dihedral_angles(&self, t: usize) -> [f64; 6] {
        dihedral_angles(&self.corners(t))
    }

    /// Mean edge length (mesh units).
    pub fn mean_edge_length(&self) -> f64 {
        let mut total = 0.0;
        for e in self.edges() {
            total += self.positions[e[0] as usize].distance(self.positions[e[1] as usize]);
        }
        total / self.edge_count().max(1) as f64
    }
}

/// Checks one tet and orients it positively; `Ok(true)` if it was flipped.
fn orient(t: usize, tet: &mut [u32; 4], positions: &[DVec3]) -> Result<bool, Error> {
    let n = positions.len();
    for &v in tet.iter() {
        if v as usize >= n {
            return Err(Error::IndexOutOfRange {
                tet: t,
                index: v,
                vertices: n,
            });
        }
    }
    for a in 0..4 {
        for b in a + 1..4 {
            if tet[a] == tet[b] {
                return Err(Error::RepeatedVertex {
                    tet: t,
                    index: tet[a],
                });
            }
        }
    }
    let p = tet.map(|v| positions[v as usize]);
    let det = volume6(&p);
    // Zero volume relative to the tet's size: a flat tet has cot weights
    // of ±∞.
    let longest = EDGES
        .iter()
        .map(|&[a, b]| p[a].distance_squared(p[b]))
        .fold(0.0, f64::max)
        .sqrt();
    if det.is_nan() || det.abs() <= 1e-12 * longest.powi(3) {
        return Err(Error::DegenerateTet {
            tet: t,
            vertices: *tet,
            volume: det / 6.0,
        });
    }
    if det < 0.0 {
        tet.swap(0, 1);
        return Ok(true);
    }
    Ok(false)
}

/// Vertex → tetrahedra, ascending, by counting.
fn vertex_tets(n: usize, tets: &[[u32; 4]]) -> Csr {
    let mut offsets = vec![0usize; n + 1];
    for tet in tets {
        for &v in tet {
            offsets[v as usize + 1] += 1;
        }
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut items = vec![0u32; offsets[n]];
    for (t, tet) in tets.iter().enumerate() {
        for &v in tet {
            items[fill[v as usize]] = t as u32;
            fill[v as usize] += 1;
        }
    }
    Csr { offsets, items }
}

/// The one-rings, ascending, and the row positions of each vertex's tet
/// corners (`TetMesh::slots`), built per block of vertices in parallel:
/// each vertex's neighbours are gathered from its tets, deduplicated with
/// a per-thread stamp array (no sort of the ~90 repeats) and sorted; a
/// second per-thread array then gives each neighbour's position in the row
/// without a search.
fn neighbors(vertex_tets: &Csr, tets: &[[u32; 4]]) -> (Csr, Vec<[u32; 4]>) {
    const BLOCK: usize = 1024;
    let n = vertex_tets.offsets.len() - 1;
    type Block = (Vec<u32>, Vec<usize>, Vec<[u32; 4]>);
    let blocks: Vec<Block> = (0..n.div_ceil(BLOCK))
        .into_par_iter()
        // Few inits: each allocates two arrays of n entries.
        .with_min_len(8)
        .map_init(
            || (vec![u32::MAX; n], vec![0u32; n]),
            |(stamp, position), b| {
                let (lo, hi) = (b * BLOCK, ((b + 1) * BLOCK).min(n));
                let mut items = Vec::new();
                let mut lens = Vec::with_capacity(hi - lo);
                let mut slots =
                    Vec::with_capacity(vertex_tets.offsets[hi] - vertex_tets.offsets[lo]);
                for i in lo..hi {
                    let start = items.len();
                    for &t in vertex_tets.row(i) {
                        for v in tets[t as usize] {
                            if v as usize != i && stamp[v as usize] != i as u32 {
                                stamp[v as usize] = i as u32;
                                items.push(v);
                            }
                        }
                    }
                    let ring = &mut items[start..];
                    ring.sort_unstable();
                    // Row i holds the ring with i inserted in order.
                    let split = ring.partition_point(|&j| (j as usize) < i);
                    for (k, &j) in ring.iter().enumerate() {
                        position[j as usize] = (k + usize::from(k >= split)) as u32;
                    }
                    position[i] = split as u32;
                    for &t in vertex_tets.row(i) {
                        slots.push(tets[t as usize].map(|v| position[v as usize]));
                    }
                    lens.push(ring.len());
                }
                (items, lens, slots)
            },
        )
        .collect();
    let mut offsets = Vec::with_capacity(n + 1);
    offsets.push(0);
    let mut items = Vec::with_capacity(blocks.iter().map(|b| b.0.len()).sum());
    let mut slots = Vec::with_capacity(vertex_tets.items.len());
    for (block, lens, block_slots) in blocks {
        for len in lens {
            offsets.push(offsets[offsets.len() - 1] + len);
        }
        items.extend_from_slice(&block);
        slots.extend_from_slice(&block_slots);
    }
    (Csr { offsets, items }, slots)
}

/// Face adjacency per tet and the outward boundary triangles.
type Faces = (Vec<[u32; 4]>, Vec<[u32; 3]>);

/// A face's sorted vertex triple and its `4 t + k` (tet `t`, face `k`)
/// packed into one integer, triple first: sorting the integers sorts the
/// faces by triple, and compares two words instead of four fields.
fn face_key(triple: [u32; 3], face: u32) -> u128 {
    (u128::from(triple[0]) << 96)
        | (u128::from(triple[1]) << 64)
        | (u128::from(triple[2]) << 32)
        | u128::from(face)
}

/// Face adjacency and the outward boundary triangles, by sorting the
/// faces' sorted vertex triples.
fn faces(tets: &[[u32; 4]]) -> Result<Faces, Error> {
    let mut keys: Vec<u128> = tets
        .par_iter()
        .enumerate()
        .flat_map_iter(|(t, tet)| {
            (0..4).map(move |k| {
                let mut s = OUTWARD_FACES[k].map(|l| tet[l]);
                s.sort_unstable();
                face_key(s, (t * 4 + k) as u32)
            })
        })
        .collect();
    keys.par_sort_unstable();
    let triple = |key: u128| key >> 32;
    let face = |key: u128| key as u32;
    let mut adjacency = vec![[NONE; 4]; tets.len()];
    let mut boundary = Vec::new();
    let mut i = 0;
    while i < keys.len() {
        let mut j = i + 1;
        while j < keys.len() && triple(keys[j]) == triple(keys[i]) {
            j += 1;
        }
        match j - i {
            1 => boundary.push(face(keys[i])),
            2 => {
                let (a, b) = (face(keys[i]), face(keys[i + 1]));
                adjacency[(a / 4) as usize][(a % 4) as usize] = b / 4;
                adjacency[(b / 4) as usize][(b % 4) as usize] = a / 4;
            }
            _ => {
                let t = triple(keys[i]);
                return Err(Error::NonManifoldFace {
                    face: [(t >> 64) as u32, (t >> 32) as u32, t as u32],
                    tet: (face(keys[i + 2]) / 4) as usize,
                });
            }
        }
        i = j;
    }
    boundary.sort_unstable();
    Ok((
        adjacency,
        boundary
            .into_iter()
            .map(|f| {
                let (t, k) = ((f / 4) as usize, (f % 4) as usize);
                OUTWARD_FACES[k].map(|l| tets[t][l])
            })
            .collect(),
    ))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The Kuhn lattice of `[0, size]³` the unit tests share.
    pub(crate) fn cube(n: usize, size: f64) -> (Vec<DVec3>, Vec<[u32; 4]>) {
        crate::kuhn_lattice(n, DVec3::ZERO, DVec3::splat(size))
    }

    #[test]
    fn a_face_of_three_tets_is_named() {
        // Three tets on the triangle (0, 1, 2), apexes above and below.
        let p = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::new(0.2, 0.2, 1.0),
            DVec3::new(0.2, 0.2, -1.0),
            DVec3::new(0.3, 0.3, 2.0),
        ];
        let tets = [[0, 1, 2, 3], [0, 1, 2, 4], [0, 1, 2, 5]];
        match TetMesh::new(&p, &tets) {
            Err(Error::NonManifoldFace { face, tet }) => {
                assert_eq!(face, [0, 1, 2]);
                assert!(tet < 3);
            }
            other => panic!("{other:?}"),
        }
        // Two of them are a mesh: one shared face, six on the boundary.
        let two = TetMesh::new(&p[..5], &tets[..2]).unwrap();
        assert_eq!(two.boundary.len(), 6);
        assert_eq!(
            two.tet_neighbors
                .iter()
                .flatten()
                .filter(|&&t| t != NONE)
                .count(),
            2
        );
    }

    #[test]
    fn subset_equals_a_mesh_built_from_scratch() {
        let (p, t) = cube(4, 1.0);
        let mesh = TetMesh::new(&p, &t).unwrap();
        // Keep the tets with their centre below a slanted plane.
        let keep: Vec<usize> = (0..mesh.tets().len())
            .filter(|&k| {
                let c = mesh.tet_center(k);
                c.x + 0.7 * c.y + 0.3 * c.z < 0.9
            })
            .collect();
        let mut new_index = vec![NONE; p.len()];
        for &k in &keep {
            for &v in &mesh.tets()[k] {
                new_index[v as usize] = 0;
            }
        }
        let mut old_of_new = Vec::new();
        for (v, slot) in new_index.iter_mut().enumerate() {
            if *slot == 0 {
                *slot = old_of_new.len() as u32;
                old_of_new.push(v);
            }
        }
        assert!(old_of_new.len() < p.len() && keep.len() < t.len());
        let sub = mesh.subset(&keep, &new_index, &old_of_new).unwrap();
        let scratch = TetMesh::with_original(
            old_of_new.iter().map(|&v| p[v]).collect(),
            keep.iter()
                .map(|&k| mesh.tets()[k].map(|v| new_index[v as usize]))
                .collect(),
            keep.iter().map(|&k| k as u32).collect(),
        )
        .unwrap();
        assert_eq!(sub.positions(), scratch.positions());
        assert_eq!(sub.tets(), scratch.tets());
        assert_eq!(sub.original_ids(), scratch.original_ids());
        assert_eq!(scratch.reoriented(), 0);
        assert_eq!(sub.vertex_tets, scratch.vertex_tets);
        assert_eq!(sub.neighbors, scratch.neighbors);
        assert_eq!(sub.slots, scratch.slots);
        assert_eq!(sub.tet_neighbors(), scratch.tet_neighbors());
        assert_eq!(sub.boundary(), scratch.boundary());
        assert_eq!(sub.boundary_vertices(), scratch.boundary_vertices());
        assert_eq!(sub.vertex_areas(), scratch.vertex_areas());
        assert_eq!(sub.vertex_normals(), scratch.vertex_normals());
    }

    #[test]
    fn slots_point_at_the_columns() {
        let (p, t) = cube(3, 1.0);
        let mesh = TetMesh::new(&p, &t).unwrap();
        for i in 0..mesh.vertex_count() {
            let ring = mesh.one_ring(i);
            let split = ring.partition_point(|&j| (j as usize) < i);
            let mut cols: Vec<u32> = ring.to_vec();
            cols.insert(split, i as u32);
            for (&k, slots) in mesh.vertex_tets(i).iter().zip(mesh.vertex_slots(i)) {
                for (b, &s) in slots.iter().enumerate() {
                    assert_eq!(cols[s as usize], mesh.tets()[k as usize][b]);
                }
            }
        }
    }

    #[test]
    fn cube_topology() {
        let (p, t) = cube(3, 1.0);
        let mesh = TetMesh::new(&p, &t).unwrap();
        // Half of Kuhn's tets are negatively oriented as listed.
        assert_eq!(mesh.reoriented(), 27 * 3);
        assert_eq!(mesh.boundary().len(), 6 * 9 * 2);
        assert!((mesh.volume() - 1.0).abs() < 1e-12);
        let area: f64 = mesh.vertex_areas().iter().sum::<f64>() / 3.0;
        assert!((area - 6.0).abs() < 1e-12);
        // Outward normals: the boundary encloses the volume positively.
        let enclosed: f64 = mesh
            .boundary()
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|v| p[v as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        assert!((enclosed - 1.0).abs() < 1e-12);
        // Interior vertex (1,1,1) of a 3-lattice: 14 neighbours in Kuhn's split.
        assert_eq!(mesh.one_ring(21).len(), 14);
        assert!(mesh.boundary_index(21).is_none());
        // Euler: V − E + F − T = 1 for a ball.
        let faces = (4 * t.len() + mesh.boundary().len()) / 2;
        assert_eq!(
            p.len() as i64 - mesh.edge_count() as i64 + faces as i64 - t.len() as i64,
            1
        );
        // Every interior face has a neighbour back.
        for (a, nb) in mesh.tet_neighbors().iter().enumerate() {
            for &b in nb {
                if b != NONE {
                    assert!(mesh.tet_neighbors()[b as usize].contains(&(a as u32)));
                }
            }
        }
        let q = mesh.quality();
        assert!((q.min_dihedral - 45.0).abs() < 1e-9 && (q.max_dihedral - 90.0).abs() < 1e-9);
        assert_eq!(q.poor_tets, 0);
    }

    #[test]
    fn bad_meshes_are_errors_naming_the_element() {
        let p = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(1.0, 1.0, 0.0),
        ];
        assert!(matches!(
            TetMesh::new(&p, &[[0, 1, 2, 3], [0, 1, 2, 9]]),
            Err(Error::IndexOutOfRange {
                tet: 1,
                index: 9,
                ..
            })
        ));
        assert!(matches!(
            TetMesh::new(&p, &[[0, 1, 2, 4]]),
            Err(Error::DegenerateTet { tet: 0, .. })
        ));
        assert!(matches!(
            TetMesh::new(&p, &[[0, 1, 1, 3]]),
            Err(Error::RepeatedVertex { tet: 0, index: 1 })
        ));
        // Vertex 4 is in no tetrahedron: named, never a zero diagonal in
        // a solver later.
        let e = TetMesh::new(&p, &[[0, 1, 2, 3]]).unwrap_err();
        assert_eq!(
            e,
            Error::UnusedVertex {
                vertex: 4,
                count: 1
            }
        );
        assert!(e.to_string().contains("vertex 4 is used by no tetrahedron"));
        let mut q = p;
        q[2].y = f64::NAN;
        assert!(matches!(
            TetMesh::new(&q, &[[0, 1, 2, 3]]),
            Err(Error::NonFinitePosition { vertex: 2, .. })
        ));
        assert!(matches!(
            TetMesh::new(&p, &[]),
            Err(Error::EmptyMesh { .. })
        ));
        let e = TetMesh::new(&p, &[[0, 1, 2, 4]]).unwrap_err().to_string();
        assert!(e.contains("tetrahedron 0"), "{e}");
    }
}
