//! The crate's one error type.

/// What is wrong with a mesh, a material, a light, an edit or a solve.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The mesh has no tetrahedra (or no vertices).
    #[error("the mesh is empty: it has {vertices} vertices and {tets} tetrahedra")]
    EmptyMesh {
        /// Vertices given.
        vertices: usize,
        /// Tetrahedra given.
        tets: usize,
    },
    /// More vertices or tetrahedra than 32-bit indices address.
    #[error("the mesh has {count} {what}, more than 32-bit indices allow")]
    TooLarge {
        /// "vertices" or "tetrahedra".
        what: &'static str,
        /// How many were given.
        count: usize,
    },
    /// A tetrahedron refers to a vertex that does not exist.
    #[error("tetrahedron {tet} refers to vertex {index}, but the mesh has {vertices} vertices")]
    IndexOutOfRange {
        /// The tetrahedron.
        tet: usize,
        /// The bad index.
        index: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// A tetrahedron names the same vertex twice.
    #[error("tetrahedron {tet} repeats vertex {index}")]
    RepeatedVertex {
        /// The tetrahedron.
        tet: usize,
        /// The repeated index.
        index: u32,
    },
    /// A vertex that no tetrahedron uses: its row of the diffusion system
    /// would be empty (a zero diagonal). Drop such vertices first
    /// (`trilux_io::tet::TetMesh::without_unused_nodes` keeps the map back
    /// to the file's numbering).
    #[error(
        "vertex {vertex} is used by no tetrahedron ({count} such vertices); drop unused vertices \
         before solving"
    )]
    UnusedVertex {
        /// The first unused vertex.
        vertex: usize,
        /// How many vertices are unused.
        count: usize,
    },
    /// A position is NaN or infinite.
    #[error("vertex {vertex} has a non-finite position {position:?}")]
    NonFinitePosition {
        /// The vertex.
        vertex: usize,
        /// Its coordinates.
        position: [f64; 3],
    },
    /// A tetrahedron has (numerically) zero volume.
    #[error(
        "tetrahedron {tet} (vertices {vertices:?}) has zero volume ({volume:e}): its vertices are coplanar"
    )]
    DegenerateTet {
        /// The tetrahedron.
        tet: usize,
        /// Its vertex indices.
        vertices: [u32; 4],
        /// Its signed volume.
        volume: f64,
    },
    /// A face is shared by more than two tetrahedra: not a manifold mesh.
    #[error(
        "the face {face:?} is shared by more than two tetrahedra (tetrahedron {tet} is the third)"
    )]
    NonManifoldFace {
        /// The face's sorted vertex indices.
        face: [u32; 3],
        /// The third tetrahedron found on it.
        tet: usize,
    },
    /// An argument is NaN, infinite or outside its range.
    #[error("{what} is {value}: {need}")]
    BadArgument {
        /// Which argument (for example `sigma_s_prime[1] of tetrahedron 12`).
        what: String,
        /// Its value.
        value: f64,
        /// What it must be.
        need: &'static str,
    },
    /// A per-tet or per-vertex array has the wrong length.
    #[error("{what} has {found} entries, expected {expected}")]
    LengthMismatch {
        /// Which array.
        what: &'static str,
        /// Entries needed.
        expected: usize,
        /// Entries given.
        found: usize,
    },
    /// An unknown preset name.
    #[error(
        "no measured material is called {0:?}; the names are those of Jensen et al. 2001 (apple, chicken1, chicken2, cream, ketchup, marble, potato, skimmilk, skin1, skin2, spectralon, wholemilk)"
    )]
    UnknownMaterial(String),
    /// A cut would remove every tetrahedron.
    #[error("the cut removes all {tets} tetrahedra: nothing would be left")]
    CutRemovesEverything {
        /// Tetrahedra before the cut.
        tets: usize,
    },
    /// An exact cut (or a fracture) would make a tet below the angle bound
    /// ([`created_angle_bound`](crate::created_angle_bound)) and no snap of a vertex avoids it.
    #[error(
        "the exact cut would split input tet {tet} into a tet with a {angle:.3}° dihedral angle, below the bound {bound:.3}° there, and no vertex of it can snap onto the cut; cut a little elsewhere or use the relaxation cut"
    )]
    CutAngleBound {
        /// The input tet (index in the mesh before the cut).
        tet: usize,
        /// The smallest dihedral angle of its pieces, degrees.
        angle: f64,
        /// Its bound, degrees.
        bound: f64,
    },
    /// A fracture plane leaves one side empty.
    #[error("the fracture plane leaves {side} side empty: all tetrahedra lie on one side")]
    EmptyPiece {
        /// "the positive" or "the negative".
        side: &'static str,
    },
    /// Two pieces given to `recombine` did not come from one fracture.
    #[error("these pieces were not split from one object by one fracture")]
    NotMatchingPieces,
    /// The solver stopped before reaching the tolerance.
    #[error(
        "the {channel} channel did not converge to the tolerance {tolerance:e}: it {stop} after {iterations} iteration{} at relative residual {residual:.3e}",
        if *iterations == 1 { "" } else { "s" }
    )]
    NotConverged {
        /// "red", "green" or "blue".
        channel: &'static str,
        /// The true relative residual `‖b − M φ‖ / ‖b‖` of the returned φ.
        residual: f64,
        /// Iterations done.
        iterations: usize,
        /// Why it stopped.
        stop: multires::Stop,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// An error of the linear solver (the source says which).
    #[error("the linear solver failed")]
    Solver(#[from] multires::Error),
    /// The environment map's distribution could not be built (the source,
    /// `discrete-sampling`'s error, says why).
    #[error("the environment map cannot be sampled")]
    Environment(#[from] discrete_sampling::Error),
}

/// Checks that `value` is finite.
pub(crate) fn finite(what: impl FnOnce() -> String, value: f64) -> Result<f64, Error> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::BadArgument {
            what: what(),
            value,
            need: "it must be finite",
        })
    }
}

/// Checks that every coordinate of `v` is finite.
pub(crate) fn finite_vec(what: &str, v: glam::DVec3) -> Result<glam::DVec3, Error> {
    for (k, c) in v.to_array().into_iter().enumerate() {
        finite(|| format!("{what}[{k}]"), c)?;
    }
    Ok(v)
}
