//! Fast, exact sampling of 1D and 2D discrete distributions.
//!
//! Renderers choose lights, environment-map texels and mesh triangles by
//! their weights millions of times per second. This crate gives the usual
//! methods one interface and makes the fastest one the default:
//!
//! | type | method | sample cost | keeps the order of `u` |
//! |---|---|---|---|
//! | [`CdfBisection`] | binary search in the CDF (pbrt, rand's `WeightedIndex`) | `log₂ n` loads | yes |
//! | [`GuideTable`] | lookup table over the CDF's codomain (Šik & Křivánek 2013, Sec. 4) | 1–2 loads | yes |
//! | [`AliasTable`] | Walker's alias method, Vose's build | 1 load | no |
//! | [`Distribution2D`] | marginal over rows + conditional per row, for images and lat-long maps | two 1D samples | yes (with an invertible 1D sampler) |
//!
//! # The paper
//!
//! M. Šik and J. Křivánek, *Fast Random Sampling of Triangular Meshes*,
//! Pacific Graphics 2013, Section 4. The CDF `F_i = Σ_{j≤i} P_j` is searched
//! for `argmin_i {F_i > ξ}`; a table over `[0, 1]` stores for each cell `C_k`
//! the index `C_k^begin = argmin_i {F_i ≥ C_k^min}`, and since
//! `C_k^end = C_{k+1}^begin` one index per cell suffices (Fig. 5). The search
//! then bisects only inside `[C_k^begin, C_k^end]`. The paper measured the
//! best table at about four cells per CDF entry (Fig. 7), which is
//! [`DEFAULT_RATIO`], and a 2–14× speed-up over bisection; Fig. 8 applies it
//! to environment maps in 1D and 2D ([`Distribution2D`]).
//!
//! # Guarantees
//!
//! - CDFs are accumulated and stored in `f64`. In `f32` a dim entry added to
//!   a large running sum is rounded away: most entries of a heavy-tailed
//!   distribution with 10⁶ entries become unreachable.
//! - An entry of weight zero is never returned, for any `u`.
//! - [`GuideTable`] returns exactly the index [`CdfBisection`] returns, for
//!   every `u`: it is the same inversion, only faster.
//! - Every sampler answers [`pdf`](DiscreteSampler::pdf), the probability it
//!   realises, for multiple importance sampling.
//! - Sampling from `u` also returns the remapped remainder of `u`
//!   ([`DiscreteSampler::sample_remapped`]), and the CDF samplers can
//!   [`invert`](InvertibleSampler::invert) an index back to its `u`.
//! - Bad weights are an [`Error`] naming the first offending index, never a
//!   panic.
//! - A fixed seed gives the same samples on every platform and `rand`
//!   version: one `u64` makes one variate, by a conversion defined here.
//! - Variates outside `[0, 1)` are clamped and NaN counts as 0, in every
//!   sampler; a 2D point always lies inside the cell it was drawn from.
//! - Weights are normalised by division, so subnormal weights keep their
//!   ratios.
//!
//! # Environment maps
//!
//! [`Distribution2D::from_equirect`] builds the distribution of a
//! latitude–longitude map; [`Distribution2D::sample_direction`] draws a
//! direction with its density per steradian, and
//! [`Distribution2D::pdf_direction`] gives that density for any direction
//! (multiple importance sampling). [`equirect_direction`] and
//! [`equirect_point`] convert between map points and directions.
//!
//! # Example
//!
//! ```
//! use discrete_sampling::{DiscreteSampler, GuideTable, InvertibleSampler};
//! use rand::distr::Distribution;
//! use rand::SeedableRng;
//!
//! // Light powers: the third light is off and is never chosen.
//! let lights = GuideTable::new(&[5.0, 1.0, 0.0, 2.0])?;
//! let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(42);
//!
//! let i = lights.sample(&mut rng); // rand's Distribution trait
//! assert_ne!(i, 2);
//! let pmf = lights.pdf(i); // for multiple importance sampling
//! assert!(pmf > 0.0);
//!
//! // Your own variate (stratified, QMC), and the remainder to reuse.
//! let (j, u_rest) = lights.sample_remapped(0.7);
//! assert_eq!(j, 1);
//! assert!((0.0..1.0).contains(&u_rest));
//! assert_eq!(lights.invert(1), Some(0.625)); // start of entry 1's interval
//!
//! // A batch.
//! let mut batch = vec![0usize; 1024];
//! lights.sample_into(&mut rng, &mut batch);
//! assert!(batch.iter().all(|&k| k != 2));
//! # Ok::<(), discrete_sampling::Error>(())
//! ```
//!
//! # Features
//!
//! - `rayon`: fill the lookup table of very large distributions (≥ 2²⁰
//!   cells) on several threads. The result is identical to the serial build.

#![forbid(unsafe_code)]

mod alias;
mod bisection;
mod cdf;
mod dist2d;
mod error;
mod guide_table;
mod luminance;
mod sampler;
mod uniform;
mod weights;

pub use alias::AliasTable;
pub use bisection::CdfBisection;
pub use dist2d::{
    DirectionSample, Distribution2D, Sample2D, equirect_direction, equirect_point, pdf_solid_angle,
};
pub use error::Error;
pub use guide_table::{DEFAULT_RATIO, GuideTable, MAX_CELLS, MAX_RATIO};
pub use luminance::luminance;
/// The `rand` this crate's API speaks (its `Rng` and `Distribution` traits),
/// re-exported so that callers use the same version.
pub use rand;
pub use sampler::{DiscreteSampler, InvertibleSampler};

/// The README's examples, compiled as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
