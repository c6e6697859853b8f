//! TransCut (Li et al., *TransCut: Interactive Rendering of Translucent
//! Cutouts*) on tetrahedral meshes: the diffusion equation of subsurface
//! scattering solved per vertex with a matrix built from closed-form
//! cotangent weights, fast enough to re-solve after every cut, brush
//! stroke or fracture.
//!
//! (Crate documentation is completed below.)

pub mod assembly;
pub mod cut;
mod error;
pub mod fem;
mod fracture;
pub mod fresnel;
pub mod light;
pub mod material;
pub mod mesh;
mod object;
pub mod paint;
pub mod stuffing;

pub use cut::{Cut, CutReport};
pub use error::Error;
pub use fem::{Integration, P1Matrices};
pub use light::{Environment, Light};
pub use material::{MEASURED, Medium, Noise, ResolutionWarning};
pub use mesh::{Quality, TetMesh};
pub use object::{Method, Object, SolveReport, SolverSettings};
pub use paint::{PaintReport, Stroke};

pub use glam;
pub use multires;
pub use sprs;
