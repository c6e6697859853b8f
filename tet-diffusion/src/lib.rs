//! TransCut on tetrahedral meshes (Li et al.), and isosurface stuffing.
//!
//! (Crate documentation is written by the crate's owner.)

pub mod stuffing;
