//! Random points on triangle meshes.
//!
//! This first part implements **area-uniform sampling** as in the
//! uniform-mesh-sampling article: a triangle drawn with probability
//! `A_i / ΣA` (from the lookup-table CDF of Šik & Křivánek 2013, Sec. 4, in
//! `discrete-sampling`), then a uniform point in it by the square-root map
//! `u = 1 − √ξ₁, v = ξ₂ √ξ₁` (Šik & Křivánek, Sec. 3.5). The density is
//! `1 / A` everywhere. The article's naive sampler (a triangle chosen
//! uniformly) is here too, documented as biased, so the tests can show
//! that they reject it. [`MultiMeshSampler`] samples several meshes at once
//! (the article's last section): a CDF over the meshes' areas above one
//! sampler per mesh, so editing one mesh rebuilds only its table. Density-texture sampling by adaptive subdivision
//! (Šik & Křivánek Sec. 3.3–3.5) is the next part (issue 4).
//!
//! A sample is a [`SurfacePoint`]: position, face, barycentrics, geometric
//! and shading normal, UV, and its density. Stored as (face, barycentrics),
//! it can be re-evaluated on a deformed mesh with [`SurfacePoint::on`].
//!
//! # Example
//!
//! ```
//! use glam::Vec3;
//! use mesh_sampling::{MeshRef, UniformSampler};
//! use rand::distr::Distribution;
//! use rand::SeedableRng;
//!
//! let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
//! let indices = [[0, 1, 2]];
//! let sampler = UniformSampler::new(MeshRef::new(&positions, &indices))?;
//! let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
//! let p = sampler.sample(&mut rng);
//! assert_eq!(p.face, 0);
//! assert!((p.pdf - 2.0).abs() < 1e-6); // area 1/2
//! # Ok::<(), mesh_sampling::Error>(())
//! ```

#![forbid(unsafe_code)]

mod batch;
mod density;
mod error;
mod mesh;
mod multi;
mod naive;
mod parallel;
mod point;
mod projection;
mod rejection;
mod subdivision;
mod texture;
mod uniform;

pub use batch::SurfaceSampler;
pub use density::{Density, DensitySampler, Mode, Options};
pub use error::Error;
pub use mesh::MeshRef;
pub use multi::{MeshPoint, MultiMeshSampler};
pub use naive::NaiveSampler;
pub use point::{SurfacePoint, uniform_barycentric};
pub use projection::spherical_uvs;
pub use rejection::RejectionSampler;
pub use texture::{Channel, DensityTexture, Filter, Wrap};
pub use uniform::UniformSampler;
