//! `trilux`: the adapters from trilux-io files to the algorithm crates,
//! and (with the default `cli` feature) the `trilux` command.
//!
//! The algorithm crates take plain data and read no files; `trilux-io`
//! reads and writes files and knows no algorithm. This library joins them
//! in one place, so neither grows the other's dependencies:
//!
//! | from | to | function |
//! |---|---|---|
//! | `TriMesh` | `mesh_sampling::MeshRef` (normals, UVs) | [`mesh_ref`] |
//! | `Image` | `mesh_sampling::DensityTexture` (a channel or luminance) | [`density_texture`] |
//! | `Image` | `mesh_sampling::EmissionTexture` (linear RGB radiance, for an `Emitter`) | [`emission_texture`] |
//! | `Image` | `mesh_colors::Texture` (linear RGB) | [`colors::texture`] |
//! | `TriMesh` (+ its materials' textures) | mesh colours, welded, seams averaged | [`to_mesh_colors`], [`ColorMesh`] |
//! | `mesh_colors::atlas::Atlas` | `TriMesh` + `Image` to write | [`atlas_mesh`] |
//! | sampled `SurfacePoint`s | a PLY point cloud | [`point_cloud`] |
//! | `TetMesh` | solver positions, boundary surface, dihedral range | [`tet`] |
//!
//! **UVs.** A `TriMesh`'s UVs are glTF's: `v = 0` is the first row of the
//! image, as stored in PNG/EXR/HDR. trilux-io's readers and writers convert
//! OBJ and PLY files (v up) to and from it; `DensityTexture`,
//! `EmissionTexture` and mesh-colors' `Texture` use the same convention, so
//! nothing here flips.
//!
//! Use it without the command-line dependencies (clap, indicatif, plotters)
//! as `trilux = { version = "0.1", default-features = false }`.
//!
//! # Example
//!
//! A textured mesh to mesh colours and back to an atlas, and a point cloud
//! with a density texture:
//!
//! ```
//! use mesh_sampling::{Channel, Density, DensitySampler, SurfaceSampler};
//!
//! let torus = trilux::shapes::torus(48, 24);
//! let checker = trilux::shapes::checkerboard(128, 128, 8);
//! let (surface, colors) = trilux::to_mesh_colors(&torus, Some(&checker), &Default::default())?;
//! let atlas = mesh_colors::atlas::bake(&colors, &Default::default())?;
//! let (baked, image) = trilux::atlas_mesh(&surface, &atlas, None);
//! assert_eq!(baked.indices.len(), torus.indices.len());
//!
//! let density = trilux::density_texture(&trilux::shapes::noise(64, 64, 1), Channel::Luminance)?;
//! let sampler = DensitySampler::new(trilux::mesh_ref(&torus), Density::Texture(&density))?;
//! let cloud = trilux::point_cloud(&torus, &sampler.sample_n(1, 10_000)?);
//! assert_eq!(cloud.positions.len(), 10_000);
//! # Ok::<(), trilux::Error>(())
//! ```

#![forbid(unsafe_code)]

pub mod colors;
mod density;
mod error;
pub mod hair;
pub mod mesh;
pub mod output;
#[cfg(feature = "paint")]
pub mod paint;
mod points;
pub mod preview;
pub mod shapes;
pub mod tet;
#[cfg(feature = "view")]
pub mod view;
#[cfg(feature = "web")]
pub mod web;

pub use colors::{
    ColorMesh, ConvertOptions, SurfaceTexture, atlas_mesh, attach_scalar_channels, to_mesh_colors,
};
pub use density::{density_texture, emission_texture, sampling_wrap};
pub use error::{Error, Result};
pub use mesh::mesh_ref;
pub use points::point_cloud;

pub use glam;
pub use mesh_colors;
pub use mesh_sampling;
pub use trilux_io;

// The README's file-to-result programs are compiled with the doctests, so
// that they keep working as the crates change.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
