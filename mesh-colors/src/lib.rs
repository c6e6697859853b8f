//! Mesh colours: colour — or any attribute with any number of `f32`
//! channels (AO, a sampling density, material parameters) — stored on the
//! vertices, edges and faces of a triangle mesh, each face at its own
//! resolution, with no UV map and so no seams.
//!
//! Implements Yuksel, Keyser & House 2010, *Mesh Colors* (ACM TOG 29(2)):
//!
//! - **Structure** ([`MeshColors`], Sec. 3.1, Fig. 10): face resolution
//!   `R = 2^n`; one sample per vertex (Eq. 1), `R − 1` per edge (Eq. 2),
//!   `(R − 1)(R − 2)/2` per face (Eq. 3), at barycentrics `[i/R, j/R,
//!   1 − (i+j)/R]` (Eq. 4), all in one array with an index per primitive.
//!   Edges have a canonical direction from the [`Topology`].
//! - **Mixed resolutions** (Sec. 3.2): an edge stores samples at the lowest
//!   resolution of its faces and finer faces interpolate it, so every
//!   filter gives bit-identical values on an edge from both faces.
//! - **Filtering** (Sec. 4): nearest and linear (Fig. 7), per-primitive
//!   MIP-maps ([`MipMap`]: Eq. 5 for faces, the six-neighbour rule for
//!   edges, Eq. 6 for vertices), trilinear from a footprint, anisotropic
//!   from screen-space derivatives of the barycentrics (Sec. 4.3); batch
//!   lookups ([`MeshColors::linear_into`], [`MipMap::trilinear_into`]) on
//!   all threads with the `rayon` feature.
//! - **Editing** (Sec. 3.3, [`edit`]): exact 1-to-4 subdivision, adding
//!   and deleting faces, changing one face's resolution.
//! - **Painting** ([`Painter`], Sec. 5.1): brush strokes whose cost is the
//!   samples they touch, undone and redone from the deltas of the samples
//!   a stroke touched ([`undo`]); many faces' resolutions changed in place
//!   ([`MeshColors::set_face_resolutions`]).
//! - **Real-time rendering** ([`gpu`], Sec. 5.3): every sample and MIP
//!   level packed in 2D textures with a per-face table, the formulas a
//!   fragment shader implements, and a CPU reference that reads the
//!   packed layout.
//! - **UV textures** ([`convert`], [`atlas`]): from a textured mesh (seams
//!   averaged away) and back to an atlas with per-corner UVs.
//! - **Files** ([`mod@file`]): the versioned little-endian `.meshcolors` format.
//!
//! # Example
//!
//! ```
//! use mesh_colors::{MeshColors, Topology};
//!
//! // Two triangles sharing the edge (1, 2), at resolutions 4 and 2.
//! let topology = Topology::new(4, &[[0, 1, 2], [2, 1, 3]])?;
//! let mut colors = MeshColors::new(topology, &[4, 2], 3)?;
//! // 4 vertex + 3·1 (edges of face 1 and the shared edge, R_e = 2)
//! // + 2·3 (the other edges of face 0) + 3 (inside face 0) samples:
//! assert_eq!(colors.sample_count(), 4 + 3 + 6 + 3);
//! colors.sample_mut(1).unwrap().copy_from_slice(&[1.0, 0.5, 0.0]); // vertex 1
//!
//! let mut rgb = [0.0; 3];
//! colors.linear(0, [0.2, 0.5, 0.3], &mut rgb)?;
//! // The shared edge looks the same from both faces, exactly:
//! let (mut a, mut b) = ([0.0; 3], [0.0; 3]);
//! colors.linear(0, [0.0, 0.3, 0.7], &mut a)?; // face 0: corners 1, 2
//! colors.linear(1, [0.7, 0.3, 0.0], &mut b)?; // face 1: corners 2, 1
//! assert_eq!(a, b);
//! let mip = colors.mip_map();
//! mip.trilinear(0, [0.2, 0.5, 0.3], 0.3, &mut rgb)?; // about level 1.7
//! # Ok::<(), mesh_colors::Error>(())
//! ```

#![forbid(unsafe_code)]

pub mod atlas;
mod batch;
pub mod convert;
pub mod edit;
mod error;
pub mod file;
mod filter;
pub mod gpu;
mod grid;
mod luminance;
mod mip;
mod paint;
mod parallel;
mod reach;
pub mod session;
mod structure;
#[cfg(test)]
mod test_mesh;
mod texture;
mod topology;
pub mod undo;

pub use error::{Error, IoError};
pub use luminance::luminance;
pub use mip::{FINEST_LEVEL, MAX_PROBES, MipMap};
pub use paint::{Blend, Brush, Painter, Stroke};
pub use structure::{
    MeshColors, Site, lattice_points, level_of, sample_position, samples_per_edge, samples_per_face,
};
pub use texture::{Texture, Wrap};
pub use topology::{Fingerprint, NO_FACE, Topology, weld};

/// The `glam` whose vector types this crate's API speaks, re-exported so
/// that callers use the same version.
pub use glam;

/// The largest level `n`: face resolutions go up to `2^MAX_LEVEL` (a face
/// at the cap holds about half a million samples).
pub const MAX_LEVEL: u8 = 10;

/// The most channels a sample may have.
pub const MAX_CHANNELS: usize = 64;

/// The budget of `f32` values one [`MeshColors`] (samples × channels) may
/// allocate: 2³⁰, 4 GiB. Layouts above it (a large mesh at a high
/// resolution) are an [`Error::TooLarge`] that names the count, checked
/// before allocating.
pub const MAX_SAMPLE_VALUES: u64 = 1 << 30;
