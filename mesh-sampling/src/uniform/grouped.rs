//! Area-uniform batches in face order: the same independent points as
//! [`UniformSampler::sample_n`] (as a set), drawn group by group of
//! consecutive faces, so that each group's table and triangles stay in
//! the cache instead of one random read per point. For callers that need
//! no random order (hair roots, scatter, point clouds): Šik & Křivánek's
//! Fig. 1a application and Blender's Distribute Points on Faces, which
//! also walks the faces in order.
//!
//! How: the faces are split into groups of [`GROUP`] consecutive faces;
//! the `n` points are shared among the groups by a multinomial draw on
//! the groups' areas (conditional binomials, group after group); each
//! group then draws its points from its own alias table of its faces'
//! areas and its own random stream. A point lands on face `i` with
//! probability `A_i / A`, independently of the others, as the uniform
//! sampler's do; only their order differs (grouped by face ranges).

use discrete_sampling::{AliasTable, DiscreteSampler};
use rand::Rng;
use rand::distr::Distribution;
use rand_distr::Binomial;

use super::UniformSampler;
use crate::parallel::{check_points, chunk_rng, unit};
use crate::point::uniform_barycentric;
use crate::{Error, SurfacePoint};

/// Consecutive faces in one group: their alias table (16 bytes a face)
/// and frames (64) stay in a core's L2 cache.
pub const GROUP: usize = 4096;

/// The stream the group counts are drawn from (the groups' own streams
/// are numbered by group).
const COUNTS_STREAM: usize = usize::MAX;

impl UniformSampler<'_> {
    /// `n` independent points uniform by area, like
    /// [`sample_n`](crate::SurfaceSampler::sample_n), but grouped in face
    /// order ([`GROUP`] consecutive faces at a time; random order inside
    /// a group): faster on large meshes because each group's tables stay
    /// in the cache. The same on any number of threads.
    ///
    /// # Errors
    /// [`Error::TooManyPoints`] above [`MAX_POINTS`](crate::MAX_POINTS).
    pub fn sample_n_grouped(&self, seed: u64, n: usize) -> Result<Vec<SurfacePoint>, Error> {
        self.grouped(seed, n, SurfacePoint::default(), |s, face, bary| {
            s.point(face, bary)
        })
    }

    /// The positions of [`sample_n_grouped`](Self::sample_n_grouped)'s
    /// points, computed without the rest of each point.
    ///
    /// # Errors
    /// As [`sample_n_grouped`](Self::sample_n_grouped).
    pub fn sample_positions_grouped(&self, seed: u64, n: usize) -> Result<Vec<[f32; 3]>, Error> {
        self.grouped(seed, n, [0.0; 3], |s, face, [_, w1, w2]| {
            s.frames[face as usize].at(w1, w2).to_array()
        })
    }

    /// `n` values `make(self, face, barycentrics)`, grouped as the module
    /// documentation says.
    fn grouped<T: Clone + Send>(
        &self,
        seed: u64,
        n: usize,
        zero: T,
        make: impl Fn(&Self, u32, [f32; 3]) -> T + Sync,
    ) -> Result<Vec<T>, Error> {
        check_points(n as f64)?;
        let faces = self.mesh.indices.len();
        let groups = faces.div_ceil(GROUP);
        let masses: Vec<f64> = (0..groups)
            .map(|g| {
                (g * GROUP..faces.min((g + 1) * GROUP))
                    .map(|f| self.triangles.pdf(f))
                    .sum()
            })
            .collect();
        let counts = multinomial(&masses, n, &mut chunk_rng(seed, COUNTS_STREAM));
        let mut out = vec![zero; n];
        let mut slices = Vec::with_capacity(groups);
        let mut rest = out.as_mut_slice();
        for &c in &counts {
            let (group, tail) = rest.split_at_mut(c);
            slices.push(group);
            rest = tail;
        }
        let fill = |g: usize, slice: &mut [T]| {
            if slice.is_empty() {
                return;
            }
            let first = g * GROUP;
            let weights: Vec<f64> = (first..faces.min(first + GROUP))
                .map(|f| self.triangles.pdf(f))
                .collect();
            // A group that drew points has area (its mass was positive).
            let Ok(table) = AliasTable::new(&weights) else {
                return;
            };
            let mut rng = chunk_rng(seed, g);
            for slot in slice {
                let face = (first + table.sample_rng(&mut rng)) as u32;
                let bary = uniform_barycentric(unit(rng.next_u64()), unit(rng.next_u64()));
                *slot = make(self, face, bary);
            }
        };
        #[cfg(feature = "rayon")]
        {
            use rayon::prelude::*;
            slices
                .into_par_iter()
                .enumerate()
                .for_each(|(g, s)| fill(g, s));
        }
        #[cfg(not(feature = "rayon"))]
        for (g, s) in slices.into_iter().enumerate() {
            fill(g, s);
        }
        Ok(out)
    }
}

/// A multinomial draw of `n` items over cells of `masses` (summing to 1
/// up to rounding): cell `k` takes a binomial share of what the cells
/// before it left, with the probability of its mass among the rest; the
/// last cell with mass takes the remainder.
fn multinomial<R: Rng + ?Sized>(masses: &[f64], n: usize, rng: &mut R) -> Vec<usize> {
    let mut counts = vec![0; masses.len()];
    let last = masses.iter().rposition(|&m| m > 0.0);
    let mut left = n as u64;
    let mut rest: f64 = masses.iter().sum();
    for (k, &m) in masses.iter().enumerate() {
        if left == 0 || m <= 0.0 {
            continue;
        }
        let take = if Some(k) == last || rest <= m {
            left
        } else {
            let p = (m / rest).clamp(0.0, 1.0);
            Binomial::new(left, p).map_or(0, |b| b.sample(rng))
        };
        counts[k] = take as usize;
        left -= take;
        rest -= m;
    }
    counts
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::{MeshRef, SurfaceSampler};

    /// A strip of `n` triangles whose areas grow with their index (1 to
    /// `n`, times a wobble), crossing several groups.
    fn strip(n: usize) -> (Vec<Vec3>, Vec<[u32; 3]>, Vec<f64>) {
        let mut positions = Vec::new();
        let mut indices = Vec::new();
        let mut areas = Vec::new();
        for i in 0..n {
            let h = (1 + i % 97) as f32 * (1.0 + 0.5 * ((i * 7919) % 13) as f32 / 13.0);
            let x = 2.0 * i as f32;
            let b = positions.len() as u32;
            positions.extend([
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x + 1.0, 0.0, 0.0),
                Vec3::new(x, h, 0.0),
            ]);
            indices.push([b, b + 1, b + 2]);
            areas.push(0.5 * f64::from(h));
        }
        (positions, indices, areas)
    }

    /// Pearson's statistic of per-face counts against `n A_i / A`, as a
    /// z-score of its chi-square distribution.
    fn chi_square_z(faces: impl Iterator<Item = u32>, areas: &[f64], n: usize) -> f64 {
        let mut counts = vec![0.0f64; areas.len()];
        for f in faces {
            counts[f as usize] += 1.0;
        }
        let total: f64 = areas.iter().sum();
        let x2: f64 = counts
            .iter()
            .zip(areas)
            .map(|(c, a)| {
                let e = n as f64 * a / total;
                (c - e) * (c - e) / e
            })
            .sum();
        let dof = (areas.len() - 1) as f64;
        (x2 - dof) / (2.0 * dof).sqrt()
    }

    #[test]
    fn grouped_points_are_uniform_by_area_and_a_wrong_twin_is_not() {
        let (positions, indices, areas) = strip(3 * GROUP + 1000);
        let mesh = MeshRef::new(&positions, &indices);
        let sampler = UniformSampler::new(mesh).unwrap();
        let n = 2_000_000;
        let points = sampler.sample_n_grouped(11, n).unwrap();
        assert_eq!(points.len(), n);
        let z = chi_square_z(points.iter().map(|p| p.face), &areas, n);
        assert!(z.abs() < 5.0, "chi-square z = {z}");
        // The wrong twin: faces equally likely inside each group (area
        // ignored within a group) — the same test rejects it.
        let mut rng = chunk_rng(11, 0);
        let faces = indices.len();
        let wrong = points.iter().map(|p| {
            let g = p.face as usize / GROUP;
            let len = faces.min((g + 1) * GROUP) - g * GROUP;
            (g * GROUP + (rng.next_u64() % len as u64) as usize) as u32
        });
        let z = chi_square_z(wrong, &areas, n);
        assert!(z > 50.0, "the wrong twin passed: z = {z}");
    }

    /// The article's bias test: the mean of the points is the
    /// area-weighted centroid within 1.96 standard errors per axis (a
    /// fixed seed), and the points lie in their triangles.
    #[test]
    fn the_mean_is_the_area_weighted_centroid() {
        let (positions, indices, areas) = strip(GROUP + 500);
        let mesh = MeshRef::new(&positions, &indices);
        let sampler = UniformSampler::new(mesh).unwrap();
        let n = 400_000;
        let points = sampler.sample_n_grouped(5, n).unwrap();
        let total: f64 = areas.iter().sum();
        let centroid: [f64; 2] = [0, 1].map(|k| {
            indices
                .iter()
                .zip(&areas)
                .map(|(t, a)| {
                    a * t
                        .iter()
                        .map(|&v| f64::from(positions[v as usize][k]))
                        .sum::<f64>()
                        / 3.0
                })
                .sum::<f64>()
                / total
        });
        for (k, centroid) in centroid.into_iter().enumerate() {
            let xs: Vec<f64> = points.iter().map(|p| f64::from(p.position[k])).collect();
            let mean = xs.iter().sum::<f64>() / n as f64;
            let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
            let se = (var / n as f64).sqrt();
            assert!(
                (mean - centroid).abs() < 1.96 * se,
                "axis {k}: {mean} vs {centroid}"
            );
        }
    }

    #[test]
    fn positions_match_points_and_threads_do_not_matter() {
        let (positions, indices, _) = strip(GROUP + 17);
        let mesh = MeshRef::new(&positions, &indices);
        let sampler = UniformSampler::new(mesh).unwrap();
        let points = sampler.sample_n_grouped(3, 50_000).unwrap();
        let only = sampler.sample_positions_grouped(3, 50_000).unwrap();
        assert!(
            points
                .iter()
                .zip(&only)
                .all(|(p, q)| p.position.to_array() == *q)
        );
        #[cfg(feature = "rayon")]
        {
            let one = rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .unwrap();
            let serial = one.install(|| sampler.sample_positions_grouped(3, 50_000).unwrap());
            assert_eq!(serial, only);
        }
        // Grouped in face order: the groups' points follow each other.
        let groups: Vec<u32> = points.iter().map(|p| p.face / GROUP as u32).collect();
        assert!(groups.windows(2).all(|w| w[0] <= w[1]));
        assert!(sampler.sample_n_grouped(3, usize::MAX).is_err());
        assert!(sampler.sample_n_grouped(3, 0).unwrap().is_empty());
        // The same sampler's independent points: another order, same law.
        assert_eq!(sampler.sample_n(3, 10).unwrap().len(), 10);
    }

    #[test]
    fn the_multinomial_shares_every_point() {
        let mut rng = chunk_rng(1, 2);
        let masses = [0.25, 0.0, 0.5, 0.25, 0.0];
        for n in [0, 1, 7, 1000, 123_457] {
            let c = multinomial(&masses, n, &mut rng);
            assert_eq!(c.iter().sum::<usize>(), n);
            assert_eq!((c[1], c[4]), (0, 0), "no points where there is no mass");
        }
    }
}
