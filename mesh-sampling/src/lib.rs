//! Random points on triangle meshes: uniform over the area, or with a
//! density given by a texture, per-face or per-vertex weights; each point
//! with its pdf, for scattering, point clouds, hair roots and emissive
//! meshes in a path tracer (multiple importance sampling).
//!
//! - **Uniform** ([`UniformSampler`], the uniform-mesh-sampling article):
//!   triangle `i` with probability `A_i / ΣA` from the lookup-table CDF of
//!   Šik & Křivánek 2013 (Sec. 4, in `discrete-sampling`), then the
//!   square-root map `u = 1 − √ξ₁, v = ξ₂ √ξ₁` (Sec. 3.5); density `1 / A`.
//!   [`NaiveSampler`] (a triangle chosen uniformly) is the article's biased
//!   baseline, kept so that the tests show they can fail.
//!   [`MultiMeshSampler`] samples several meshes at once (the article's
//!   last section), [`MultiDensitySampler`] the same by density mass;
//!   `sample_stable` (here and on [`DensitySampler`]) is Blender's per-triangle mode.
//! - **Density textures** ([`DensitySampler`], Šik & Křivánek Sec.
//!   3.3–3.5): each triangle is subdivided 1-to-4 until its sub-triangles
//!   are about a texel, the bilinear density `f_i` is taken at
//!   each sub-triangle's barycenter, equal siblings are merged, and a
//!   sub-triangle is drawn with probability `P_i = f_i |D_i| / Σ f_j |D_j|`
//!   (Eq. 2: the approximation `p′` of Eq. 1's `p(x) = f(m(x)) / ∫ f dA`).
//!   [`Mode::Exact`] goes beyond the paper and samples Eq. 1 itself.
//!   [`RejectionSampler`] is the paper's Sec. 3.2 baseline.
//!   Pieces are drawn from an alias table whose 16-byte columns are the
//!   pieces' records, each with its alias's ([`Layout::Alias`], one
//!   column a draw) or, order-preserving,
//!   by the paper's lookup-table CDF ([`Layout::Inversion`]). A density
//!   constant over a triangle's UV footprint is one piece, found in O(1)
//!   from the texture's tables, so tiled UVs stay cheap, and
//!   [`Options::max_pieces`] bounds the subdivision before it is built.
//!   A mesh without texture coordinates gets spherical ones from
//!   [`spherical_uvs`] (vertices split along the seam).
//! - **Blue noise** ([`blue_noise`], feature `blue-noise`): Poisson-disk
//!   points that keep their distance, following any sampler's density, by
//!   weighted sample elimination (Yuksel 2015).
//! - **Scatter by rate** ([`Scatter`], [`scatter`]): `rate × density`
//!   points per unit area (Blender's and Houdini's "density"), a Poisson
//!   process of fixed candidates per face, each with its own threshold, so
//!   that an edit keeps the points of other faces bit for bit, a raised
//!   density only adds points, and [`Scatter::update_faces`] re-thins only
//!   the edited faces.
//! - **Hair** ([`grow_strands`], the paper's Sec. 6 application, Fig. 1a):
//!   a `k`-segment strand from every root along its shading normal, with
//!   per-root length, comb, curl, noise, clumping and widths from a
//!   closure; [`grow_strands_sampled`] grows the roots as a sampler draws
//!   them, the same strands without storing the roots.
//! - **Weights**: [`Density::PerFace`] and [`Density::PerVertex`] (linear
//!   over each triangle), both sampled exactly.
//! - **Light sampling** ([`Emitter`], the paper's Sec. 5.3 application:
//!   a luminaire that is a mesh with an HDR texture as its emission): RGB
//!   radiance from an [`EmissionTexture`] times a scale, or per face, one-
//!   or two-sided ([`Sides`]), sampled by area, by per-triangle power, or
//!   by emitted power inside triangles (the subdivision's `p′`, or exactly)
//!   behind one API ([`Strategy`]); each [`LightSample`] carries `Le` and
//!   its pdf, [`Emitter::toward`] and [`Emitter::pdf_solid_angle`] give
//!   the solid-angle pdf `p_A d² / |cos θ_l|` for multiple importance
//!   sampling, evaluated from `(face, barycentric)` at a BSDF-sampled hit,
//!   and [`Emitter::triangle_power`], [`Emitter::triangle_bounds`] and
//!   [`Emitter::sample_in_triangle`] serve a renderer's own light tree.
//!
//! Conventions: texture coordinates are glTF's (v = 0 at the first image
//! row, as `trilux-io`'s `TriMesh` holds them), [`Wrap`] has glTF's
//! sampler modes, seeds are `u64`, and sizes from arguments are checked
//! against stated budgets ([`MAX_POINTS`], [`Options::max_pieces`],
//! [`MAX_INTEGRATION_CELLS`], [`MIN_ACCEPTANCE`]) before any allocation,
//! so bad input is an [`Error`], never a panic or an abort.
//!
//! A point is a [`SurfacePoint`]: position, face, barycentrics, geometric
//! and shading normal, UV, and its density. Stored as (face, barycentrics),
//! it can be re-evaluated on a deformed mesh with [`SurfacePoint::on`].
//! Every sampler's batches ([`SurfaceSampler`]) run on all threads with
//! the `rayon` feature and depend only on the seed.
//!
//! # Example
//!
//! ```
//! use glam::{Vec2, Vec3};
//! use mesh_sampling::{
//!     Density, DensitySampler, DensityTexture, MeshRef, SurfaceSampler, UniformSampler,
//! };
//!
//! // A unit square with UVs, and a 2×2 density brightest in one texel.
//! let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
//! let uvs = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
//! let indices = [[0, 1, 2], [1, 3, 2]];
//! let mesh = MeshRef { uvs: Some(&uvs), ..MeshRef::new(&positions, &indices) };
//!
//! let uniform = UniformSampler::new(mesh)?;
//! assert!(uniform.sample_n(1, 1000).unwrap().iter().all(|p| (p.pdf - 1.0).abs() < 1e-6));
//!
//! let texture = DensityTexture::new(2, 2, vec![1.0, 1.0, 1.0, 9.0])?;
//! let sampler = DensitySampler::new(mesh, Density::Texture(&texture))?;
//! let points = sampler.sample_n(2, 10_000).unwrap(); // same on any number of threads
//! let p = points[0];
//! assert!((sampler.pdf(p.face as usize, p.barycentric) - p.pdf).abs() < 1e-6); // for MIS
//! # Ok::<(), mesh_sampling::Error>(())
//! ```

// Denied, not forbidden: `prefetch` holds the one `unsafe` block, with its
// own `expect` (DESIGN.md: a measured speed-up).
#![deny(unsafe_code)]

// The foreign crates this API speaks, so that callers use the same
// versions: glam for positions, rand for `Rng` and `Distribution`,
// discrete-sampling for the 1D samplers `DensitySampler` can take, and
// rand_pcg, the generator the batches use, for seeding your own.
pub use discrete_sampling;
pub use glam;
pub use rand;
pub use rand_pcg;

mod batch;
#[cfg(feature = "blue-noise")]
mod blue_noise;
mod density;
mod emitter;
mod error;
mod hair;
mod layout;
mod mesh;
mod multi;
mod naive;
mod parallel;
mod point;
mod prefetch;
mod projection;
mod rejection;
mod scatter;
mod subdivision;
mod texture;
mod uniform;

pub use batch::SurfaceSampler;
#[cfg(feature = "blue-noise")]
pub use blue_noise::{
    BlueNoiseOptions, BlueNoiseTarget, Packing, SurfaceArea, blue_noise, max_poisson_radius,
    nearest_neighbour_distances, relative_radius, relative_radius_with_density,
};
pub use density::{
    DEFAULT_MAX_PIECES, Density, DensitySampler, Depth, MIN_ACCEPTANCE, Mode, Options,
};
pub use emitter::{
    DEFAULT_DEFENSIVE_FRACTION, Emission, EmissionTexture, Emitter, EmitterOptions, LightSample,
    Sides, Strategy, Toward, TriangleBounds,
};
pub use error::Error;
pub use hair::{
    HairOptions, MAX_SEGMENTS, Root, StrandParams, Strands, grow_strands, grow_strands_sampled,
    grow_strands_with,
};
pub use layout::{Layout, MAX_VALUE_SHIFT, MIN_THRESHOLD_BITS};
pub use mesh::MeshRef;
pub use multi::{MeshPoint, MultiDensitySampler, MultiMeshSampler};
pub use naive::NaiveSampler;
pub use parallel::MAX_POINTS;
pub use point::{SurfacePoint, uniform_barycentric};
pub use projection::spherical_uvs;
pub use rejection::RejectionSampler;
pub use scatter::{Scatter, ScatterDensity, ScatterOptions, ScatterUpdate, scatter};
pub use texture::{Channel, DensityTexture, Filter, MAX_INTEGRATION_CELLS, Wrap, luminance};
pub use uniform::{GROUP, UniformSampler};

/// The README's examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
