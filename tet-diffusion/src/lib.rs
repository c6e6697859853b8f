//! TransCut (Li, Sun, Ren, Lin, Tong, Guo & Zhou, *TransCut: Interactive
//! Rendering of Translucent Cutouts*) on tetrahedral meshes: the diffusion
//! equation of subsurface scattering, solved per vertex with a matrix built
//! from closed-form cotangent weights, fast enough to re-solve after every
//! cut, brush stroke or fracture.
//!
//! A tet mesh and materials go in, radiance on the surface comes out:
//!
//! - [`TetMesh`]: plain arrays (`&[DVec3]`, `&[[u32; 4]]`, exactly the
//!   fields of a TetGen/Gmsh/MEDIT file) validated — inverted tets
//!   re-oriented and counted, degenerate ones an error naming the tet —
//!   with one-rings, face adjacency, the outward boundary, per-vertex
//!   boundary areas `S_i` and a [`Quality`] report.
//! - [`Medium`]: `μa` and `σs′` per RGB channel in mm⁻¹, the 12
//!   [`MEASURED`] materials of Jensen et al. 2001, a procedural [`Noise`]
//!   between two media; `κ = 1/(3(μa + σs′))`.
//! - [`Object`]: the mesh in any length unit (`length_unit_mm`), its media,
//!   relative index `η`, lights, and the three RGB systems `M φ = b` of
//!   Sec. 3.2 — `w_ij` of Eq. 10, the diagonal of Eq. 13 with the boundary
//!   term `2 S_i / 3A`, `A = (1 + F_dr)/(1 − F_dr)` ([`fresnel`]), `b` of
//!   Eq. 12 — sharing one sparsity pattern, assembled in parallel with
//!   results independent of the number of threads. [`Object::solve`] uses
//!   `multires`: by default ([`Method::Auto`]) the three channels as one
//!   block of Jacobi-PCG, switching to V-cycle-PCG when its estimate of
//!   the system says the hierarchy pays ([`SolveReport::choice`] says what
//!   ran and why); V-cycle-PCG, the paper's cascade and Jacobi-PCG can be
//!   forced. Warm-started from the last `φ`;
//!   [`Object::radiance`] is Eq. 3 divided by `η²`, the radiance in air
//!   (Eq. 3 as printed, the radiance just inside, is
//!   [`Object::radiance_inside`]).
//! - [`Light`]: directional, point and importance-sampled environment
//!   maps, with shadow rays against the boundary cached per vertex; `q` of
//!   Eq. 2 with the Fresnel transmittance on entry.
//! - Edits (Sec. 5): [`Object::cut`] by a plane or a swept stroke with
//!   the paper's relaxation, [`Object::paint`] re-assembling only the rows
//!   it touches, [`Object::fracture`] and [`Object::recombine`].
//! - [`P1Matrices`]: the P1 finite-element reference of Arbree et al., assembled
//!   independently in closed form and by quadrature, with the exact
//!   relation `M = 4 (K + lumped mass + lumped boundary mass / 2A)`.
//!
//! Tetrahedra from a surface come from the `tet-stuffing` crate (isosurface
//! stuffing, once this crate's `stuffing` module), whose plain-array output
//! [`TetMesh::new`] takes as is.
//!
//! Positions are glam `DVec3` in the mesh's unit; materials are per mm, so
//! a mesh in metres needs `length_unit_mm = 1000` (a marble bunny must look
//! like marble, not like milk). Irradiance is per mm².
//!
//! # Example
//! ```
//! use tet_diffusion::{glam::DVec3, Light, Medium, Object, Stroke, TetMesh};
//! // A 10 mm cube of six tets (any TetGen/Gmsh mesh works the same way).
//! let p: Vec<DVec3> = (0..8)
//!     .map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64) * 10.0)
//!     .collect();
//! let tets = [[0, 1, 3, 7], [0, 3, 2, 7], [0, 2, 6, 7], [0, 6, 4, 7], [0, 4, 5, 7], [0, 5, 1, 7]];
//! let mesh = TetMesh::new(&p, &tets)?;
//! let mut cube = Object::homogeneous(mesh, 1.0, Medium::measured("skin1")?, 1.3)?;
//! cube.add_light(Light::Directional { to_light: DVec3::Z, irradiance: [1.0; 3] })?;
//! cube.solve()?;
//! let radiance = cube.radiance(None); // RGB per boundary vertex (Eq. 3 / η²)
//! assert_eq!(radiance.len(), cube.mesh().boundary_vertices().len());
//! // Paint ketchup into one corner: only the touched rows are re-assembled.
//! let ketchup = Medium::measured("ketchup")?;
//! cube.paint(&Stroke { points: vec![DVec3::splat(9.0)], radius: 3.0, medium: ketchup, strength: 1.0 })?;
//! cube.solve()?; // warm-started from the last φ
//! # Ok::<(), tet_diffusion::Error>(())
//! ```

// Every public item is reachable by one path: the types and functions
// from the root, the Fresnel terms from `fresnel`. The modules below the
// root are private; `geometry` (per-tet) is a leaf under `mesh`,
// `assembly` and `quality`.
mod assembly;
mod cut;
mod error;
mod fem;
mod fracture;
pub mod fresnel;
mod geometry;
mod lattice;
mod light;
mod medium;
mod mesh;
mod object;
mod paint;
mod quality;
mod session;

pub use cut::{
    ANGLE_BOUND_DEGREES, ANGLE_BOUND_FRACTION, Cut, CutMethod, CutReport, CutTimes,
    created_angle_bound,
};
pub use error::Error;
pub use fem::{Integration, P1Matrices};
pub use lattice::{kuhn_ball, kuhn_lattice};
pub use light::{Environment, Light};
pub use medium::{MEASURED, Medium, Noise, ResolutionWarning};
pub use mesh::{NONE, TetMesh};
pub use object::{
    AUTO_PROBE, AutoCosts, Budget, Choice, Method, Object, Prediction, REFRESH_DRIFT, SolveReport,
    Solver, SolverSettings,
};
pub use paint::{PaintReport, Stroke};
pub use quality::{POOR_DIHEDRAL_DEGREES, Quality};
pub use session::{Applied, Edit, Log, Logged, Session, SessionOptions, UndoMemory};

pub use glam;
pub use multires;
pub use sprs;

/// The README's example, compiled as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctest;
