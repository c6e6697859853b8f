//! The scene and the measurements of the `luminaire` example (Šik &
//! Křivánek 2013, Fig. 1b), shared with its test (`tests/all/luminaire.rs`
//! includes this file).
//!
//! A luminaire hangs above a Lambertian receiver, the plane `z = 0` with
//! normal `+z`, seen as an image of its irradiance over `[−2, 2] × [−1, 1]`
//! (pixel `(i, j)` covers `x ∈ −2 + 4 [i, i + 1) / W`, `y ∈ −1 + 2 [j, j + 1)
//! / H`). A pixel's value is the irradiance averaged over the pixel (a box
//! filter): each sample takes a uniform point in the pixel and one light
//! sample, and adds `Le · cos θ_r / pdf_ω` (next-event estimation, no
//! visibility: nothing stands between the light and the receiver but the
//! light itself, whose back does not emit).

#![allow(
    dead_code,
    reason = "the example and its test each use part of this module"
)]

use std::time::Instant;

use glam::{DVec2, DVec3, Vec2, Vec3};
use mesh_sampling::rand::{Rng, SeedableRng};
use mesh_sampling::rand_pcg::Pcg64Mcg;
use mesh_sampling::{
    Emission, EmissionTexture, Emitter, EmitterOptions, LightSample, MeshRef, Strategy, luminance,
};
use rayon::prelude::*;

/// The height of the rectangle luminaire's plane.
pub(crate) const HEIGHT: f64 = 1.0;
/// The rectangle luminaire: `x ∈ [−1, 1]`, `y ∈ [−0.5, 0.5]` at `z =
/// HEIGHT`, the aspect of an equirectangular image.
pub(crate) const RECT_X: [f64; 2] = [-1.0, 1.0];
/// See [`RECT_X`].
pub(crate) const RECT_Y: [f64; 2] = [-0.5, 0.5];
/// The receiver's extent in `x` and `y`.
pub(crate) const RECEIVER_X: [f64; 2] = [-2.0, 2.0];
/// See [`RECEIVER_X`].
pub(crate) const RECEIVER_Y: [f64; 2] = [-1.0, 1.0];
/// Light samples drawn together (one `sample_into` call).
const BLOCK: usize = 4096;

/// An emissive triangle mesh with UVs.
#[derive(Debug, Clone)]
pub(crate) struct Shape {
    /// `rectangle`, `bunny`, `blob`.
    pub(crate) name: String,
    pub(crate) positions: Vec<Vec3>,
    pub(crate) uvs: Vec<Vec2>,
    pub(crate) indices: Vec<[u32; 3]>,
    /// Whether the shape is the planar rectangle of [`rectangle`] (which
    /// has a quadrature and a closed form).
    pub(crate) planar: bool,
}

impl Shape {
    pub(crate) fn mesh(&self) -> MeshRef<'_> {
        MeshRef {
            uvs: Some(&self.uvs),
            ..MeshRef::new(&self.positions, &self.indices)
        }
    }

    pub(crate) fn triangles(&self) -> usize {
        self.indices.len()
    }

    /// The surface area, in `f64`.
    pub(crate) fn area(&self) -> f64 {
        let mesh = self.mesh();
        (0..self.indices.len()).map(|f| mesh.area(f)).sum()
    }
}

/// The rectangle luminaire in `2 · cols · rows` triangles, facing down
/// (corners counter-clockwise seen from below), UV `[0, 1]²` over it
/// (`u` along `x`, `v = 0` at `y = −0.5`: image row 0).
pub(crate) fn rectangle(cols: usize, rows: usize) -> Shape {
    let (mut positions, mut uvs, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for y in 0..=rows {
        for x in 0..=cols {
            let (s, t) = (x as f64 / cols as f64, y as f64 / rows as f64);
            positions.push(Vec3::new(
                (RECT_X[0] + s * (RECT_X[1] - RECT_X[0])) as f32,
                (RECT_Y[0] + t * (RECT_Y[1] - RECT_Y[0])) as f32,
                HEIGHT as f32,
            ));
            uvs.push(Vec2::new(s as f32, t as f32));
        }
    }
    let at = |x: usize, y: usize| (y * (cols + 1) + x) as u32;
    for y in 0..rows {
        for x in 0..cols {
            indices.push([at(x, y), at(x, y + 1), at(x + 1, y)]);
            indices.push([at(x + 1, y), at(x, y + 1), at(x + 1, y + 1)]);
        }
    }
    Shape {
        name: "rectangle".into(),
        positions,
        uvs,
        indices,
        planar: true,
    }
}

/// The rectangle in `triangles` triangles: square cells, twice as many
/// columns as rows, so `triangles = 4 · rows²` (256: 16 × 8 cells; 1,024:
/// 32 × 16; 4,096; 16,384: 128 × 64).
pub(crate) fn rectangle_with(triangles: usize) -> Result<Shape, String> {
    let rows = ((triangles / 4) as f64).sqrt().round() as usize;
    if rows == 0 || 4 * rows * rows != triangles {
        return Err(format!(
            "--triangles {triangles}: the rectangle has 4·k² triangles (256, 1024, 4096, 16384, …)"
        ));
    }
    Ok(rectangle(2 * rows, rows))
}

/// A y-up mesh (an OBJ's convention) turned into a luminaire with
/// overlapping UVs: rotated to z-up, scaled to 1.2 units across in `x`,
/// centred over the receiver with its lowest point at `z = 0.5`, and given
/// UVs by a planar projection along `z` over its bounding box (`u` from
/// `x`, `v` from `y`): the projection folds at the silhouette, so the top
/// and the bottom of the mesh share their UVs (as do the ears and the back
/// of a bunny). Triangles are reoriented so that the mesh's signed volume
/// is positive (normals outward: the outside emits); returns whether they
/// were.
pub(crate) fn folded(name: &str, positions: &[Vec3], indices: &[[u32; 3]]) -> (Shape, bool) {
    let turned: Vec<DVec3> = positions
        .iter()
        .map(|p| DVec3::new(f64::from(p.x), -f64::from(p.z), f64::from(p.y)))
        .collect();
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for t in indices {
        for &i in t {
            lo = lo.min(turned[i as usize]);
            hi = hi.max(turned[i as usize]);
        }
    }
    let scale = 1.2 / (hi.x - lo.x);
    let centre = DVec3::new(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), lo.z);
    let placed: Vec<DVec3> = turned
        .iter()
        .map(|p| (*p - centre) * scale + DVec3::new(0.0, 0.0, 0.5))
        .collect();
    let (lo, hi) = ((lo - centre) * scale, (hi - centre) * scale);
    let uvs = placed
        .iter()
        .map(|p| {
            Vec2::new(
                ((p.x - lo.x) / (hi.x - lo.x)) as f32,
                ((p.y - lo.y) / (hi.y - lo.y)) as f32,
            )
        })
        .collect();
    let volume: f64 = indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| placed[i as usize]);
            a.dot(b.cross(c))
        })
        .sum();
    let flip = volume < 0.0;
    let indices = indices
        .iter()
        .map(|&[a, b, c]| if flip { [a, c, b] } else { [a, b, c] })
        .collect();
    (
        Shape {
            name: name.into(),
            positions: placed.iter().map(|p| p.as_vec3()).collect(),
            uvs,
            indices,
            planar: false,
        },
        flip,
    )
}

/// A generated stand-in for the bunny (y-up, outward): a sphere of
/// `rings × 2·rings` quads squashed and dented so that its planar
/// projection folds like a bunny's.
pub(crate) fn blob(rings: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let segments = 2 * rings;
    let mut positions = Vec::new();
    for r in 0..=rings {
        let theta = std::f64::consts::PI * r as f64 / rings as f64;
        for s in 0..segments {
            let phi = 2.0 * std::f64::consts::PI * s as f64 / segments as f64;
            let radius = 1.0 + 0.25 * (3.0 * phi).cos() * theta.sin();
            positions.push(Vec3::new(
                (radius * theta.sin() * phi.cos()) as f32,
                (0.7 * theta.cos()) as f32,
                (radius * theta.sin() * phi.sin()) as f32,
            ));
        }
    }
    let at = |r: usize, s: usize| (r * segments + s % segments) as u32;
    let mut indices = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            // Seen from outside, counter-clockwise.
            if r > 0 {
                indices.push([at(r, s), at(r, s + 1), at(r + 1, s)]);
            }
            if r + 1 < rings {
                indices.push([at(r, s + 1), at(r + 1, s + 1), at(r + 1, s)]);
            }
        }
    }
    (positions, indices)
}

/// The receiver's image: `width × height` pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Receiver {
    pub(crate) width: usize,
    pub(crate) height: usize,
}

impl Receiver {
    pub(crate) fn pixels(&self) -> usize {
        self.width * self.height
    }

    /// The point at fraction `(fx, fy)` of pixel `(i, j)`.
    pub(crate) fn point(&self, i: usize, j: usize, fx: f64, fy: f64) -> DVec3 {
        DVec3::new(
            RECEIVER_X[0] + (RECEIVER_X[1] - RECEIVER_X[0]) * (i as f64 + fx) / self.width as f64,
            RECEIVER_Y[0] + (RECEIVER_Y[1] - RECEIVER_Y[0]) * (j as f64 + fy) / self.height as f64,
            0.0,
        )
    }
}

/// An irradiance image: per pixel the mean RGB irradiance, its
/// luminance, and the variance of that luminance mean (from the samples;
/// 0 with one sample per pixel).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Irradiance {
    pub(crate) rgb: Vec<[f64; 3]>,
    pub(crate) y: Vec<f64>,
    pub(crate) y_var: Vec<f64>,
}

/// A uniform `f64` in `[0, 1)` from 53 random bits.
#[inline]
pub(crate) fn unit(bits: u64) -> f64 {
    (bits >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The random stream of image row `row` (a SplitMix64 step of `(seed,
/// row)` as the seed), so that images do not depend on the thread count.
fn row_rng(seed: u64, row: usize) -> Pcg64Mcg {
    let mut z = seed.wrapping_add((row as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    Pcg64Mcg::seed_from_u64(z ^ (z >> 31))
}

fn luma(rgb: [f64; 3]) -> f64 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// One image row's sums per pixel: RGB, luminance, luminance squared.
type RowSums = (Vec<[f64; 3]>, Vec<f64>, Vec<f64>);

/// The irradiance image by next-event estimation with `spp` light samples
/// per pixel, rows in parallel on the current rayon pool; a function of
/// `(emitter, receiver, spp, seed)` alone.
pub(crate) fn render(
    emitter: &Emitter<'_>,
    receiver: &Receiver,
    spp: usize,
    seed: u64,
) -> Irradiance {
    let w = receiver.width;
    let rows: Vec<RowSums> = (0..receiver.height)
        .into_par_iter()
        .map(|j| {
            let mut rng = row_rng(seed, j);
            let mut rgb = vec![[0.0; 3]; w];
            let mut y = vec![0.0; w];
            let mut y2 = vec![0.0; w];
            let mut lights = vec![LightSample::default(); BLOCK.min(w * spp)];
            let total = w * spp;
            let mut n = 0;
            while n < total {
                let block = &mut lights[..BLOCK.min(total - n)];
                emitter.sample_into(&mut rng, block);
                for (k, s) in block.iter().enumerate() {
                    let i = (n + k) / spp;
                    let (fx, fy) = (unit(rng.next_u64()), unit(rng.next_u64()));
                    let x = receiver.point(i, j, fx, fy).as_vec3();
                    let t = emitter.toward(s, x);
                    if t.pdf_solid_angle > 0.0 {
                        let g = f64::from(t.direction.z.max(0.0)) / f64::from(t.pdf_solid_angle);
                        let c = t.radiance.map(|l| f64::from(l) * g);
                        for (a, b) in rgb[i].iter_mut().zip(c) {
                            *a += b;
                        }
                        let l = luma(c);
                        y[i] += l;
                        y2[i] += l * l;
                    }
                }
                n += block.len();
            }
            (rgb, y, y2)
        })
        .collect();
    let n = spp as f64;
    let mut out = Irradiance {
        rgb: Vec::with_capacity(receiver.pixels()),
        y: Vec::with_capacity(receiver.pixels()),
        y_var: Vec::with_capacity(receiver.pixels()),
    };
    for (rgb, y, y2) in rows {
        out.rgb.extend(rgb.iter().map(|c| c.map(|v| v / n)));
        for (s, s2) in y.iter().zip(&y2) {
            let mean = s / n;
            out.y.push(mean);
            out.y_var.push(if spp > 1 {
                ((s2 / n - mean * mean) * n / (n - 1.0)).max(0.0) / n
            } else {
                0.0
            });
        }
    }
    out
}

/// How far an estimate is from a reference (luminance of the irradiance).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Errors {
    /// Root mean square error over the pixels.
    pub(crate) rmse: f64,
    /// Relative MSE: the mean over pixels of `(x − r)² / r²`.
    pub(crate) rel_mse: f64,
    /// The mean over pixels of `(x − r) / r`: the relative bias of the
    /// image, 0 for an unbiased estimate up to noise.
    pub(crate) bias: f64,
    /// The standard error of `bias`: the spread of `(x − r) / r` over
    /// the pixels divided by `√pixels` (pixels are independent).
    pub(crate) bias_se: f64,
}

impl Errors {
    /// `bias / bias_se`: an unbiased estimate is within ±4 but for one
    /// time in about 16,000 (or when its error has a heavy tail, as the
    /// area strategy's with a sun: then the spread is unreliable).
    pub(crate) fn z(&self) -> f64 {
        if self.bias_se > 0.0 {
            self.bias / self.bias_se
        } else if self.bias == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    }
}

/// The errors of `estimate` against `reference` (luminances, every
/// reference pixel positive).
pub(crate) fn compare(estimate: &[f64], reference: &[f64]) -> Errors {
    let n = reference.len() as f64;
    let (mut se, mut rel, mut sum) = (0.0, 0.0, 0.0);
    let d: Vec<f64> = estimate
        .iter()
        .zip(reference)
        .map(|(x, r)| {
            se += (x - r) * (x - r);
            let q = (x - r) / r;
            rel += q * q;
            sum += q;
            q
        })
        .collect();
    let bias = sum / n;
    let spread = d.iter().map(|q| (q - bias) * (q - bias)).sum::<f64>() / (n - 1.0).max(1.0);
    Errors {
        rmse: (se / n).sqrt(),
        rel_mse: rel / n,
        bias,
        bias_se: (spread / n).sqrt(),
    }
}

/// The reference: two renders of `strategy` at `spp` with different
/// seeds, and their mean.
#[derive(Debug, Clone)]
pub(crate) struct Reference {
    /// The mean of the two renders.
    pub(crate) image: Irradiance,
    /// The relative MSE between the two renders (`≈ 2 v / spp` for a
    /// per-sample relative variance `v`): the reference's own relative
    /// MSE is a quarter of it.
    pub(crate) agreement: f64,
    /// The same predicted from the renders' per-pixel variances.
    pub(crate) predicted_agreement: f64,
    /// Wall seconds for both renders.
    pub(crate) seconds: f64,
}

/// Two renders with seeds `seed` and `seed + 1` at `spp`, compared and
/// averaged.
///
/// # Errors
/// When a pixel of either render is not positive (a relative error there
/// has no meaning): the pixel is named.
pub(crate) fn make_reference(
    emitter: &Emitter<'_>,
    receiver: &Receiver,
    spp: usize,
    seed: u64,
) -> Result<Reference, String> {
    let start = Instant::now();
    let a = render(emitter, receiver, spp, seed);
    let b = render(emitter, receiver, spp, seed.wrapping_add(1));
    let seconds = start.elapsed().as_secs_f64();
    for (k, (x, y)) in a.y.iter().zip(&b.y).enumerate() {
        if !(*x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite()) {
            return Err(format!(
                "reference pixel ({}, {}) is {x} and {y}: the receiver must see the light everywhere",
                k % receiver.width,
                k / receiver.width
            ));
        }
    }
    let image = Irradiance {
        rgb: a
            .rgb
            .iter()
            .zip(&b.rgb)
            .map(|(p, q)| [0, 1, 2].map(|c| 0.5 * (p[c] + q[c])))
            .collect(),
        y: a.y.iter().zip(&b.y).map(|(p, q)| 0.5 * (p + q)).collect(),
        y_var: a
            .y_var
            .iter()
            .zip(&b.y_var)
            .map(|(p, q)| 0.25 * (p + q))
            .collect(),
    };
    let n = receiver.pixels() as f64;
    let predicted_agreement = a
        .y_var
        .iter()
        .zip(&b.y_var)
        .zip(&image.y)
        .map(|((p, q), r)| (p + q) / (r * r))
        .sum::<f64>()
        / n;
    Ok(Reference {
        agreement: compare(&a.y, &b.y).rel_mse,
        predicted_agreement,
        image,
        seconds,
    })
}

/// Gauss–Legendre nodes of two points on `[0, 1]` (weights ½ each).
const GAUSS2: [f64; 2] = [0.211_324_865_405_187_1, 0.788_675_134_594_812_9];

/// The irradiance luminance of the [`rectangle`] carrying `texture` (scale
/// 1), averaged over each pixel of `pixels`, by quadrature: 2 × 2 Gauss
/// points in the pixel, and over the rectangle the midpoint rule on each
/// quarter texel (exact for the bilinear texture on each quarter, which
/// lies within one bilinear patch; only the smooth geometric factor is
/// approximated).
pub(crate) fn rectangle_quadrature(
    texture: &EmissionTexture,
    receiver: &Receiver,
    pixels: &[(usize, usize)],
) -> Vec<f64> {
    let (kw, kh) = (2 * texture.width(), 2 * texture.height());
    let (sx, sy) = (RECT_X[1] - RECT_X[0], RECT_Y[1] - RECT_Y[0]);
    let da = sx * sy / (kw * kh) as f64;
    // (x, y, Y(Le)) at the centre of every quarter texel.
    let cells: Vec<[f64; 3]> = (0..kh)
        .flat_map(|b| (0..kw).map(move |a| (a, b)))
        .map(|(a, b)| {
            let uv = DVec2::new((a as f64 + 0.5) / kw as f64, (b as f64 + 0.5) / kh as f64);
            [
                RECT_X[0] + sx * uv.x,
                RECT_Y[0] + sy * uv.y,
                luma(texture.eval(uv)),
            ]
        })
        .collect();
    let h2 = HEIGHT * HEIGHT;
    pixels
        .par_iter()
        .map(|&(i, j)| {
            let mut e = 0.0;
            for fy in GAUSS2 {
                for fx in GAUSS2 {
                    let p = receiver.point(i, j, fx, fy);
                    // Le cos θ_r cos θ_l / d² with cos θ_r = cos θ_l = h / d.
                    let sum: f64 = cells
                        .iter()
                        .map(|c| {
                            let d2 = (c[0] - p.x).powi(2) + (c[1] - p.y).powi(2) + h2;
                            c[2] / (d2 * d2)
                        })
                        .sum();
                    e += 0.25 * sum * h2 * da;
                }
            }
            e
        })
        .collect()
}

/// Irradiance at `x` (normal `+z`) from the whole [`rectangle`] with
/// constant radiance `radiance`: Lambert's formula `E = L/2 · |Σ βᵢ
/// n·(uᵢ × uᵢ₊₁)/|uᵢ × uᵢ₊₁||` over its edges, averaged over each pixel
/// by 2 × 2 Gauss points.
pub(crate) fn rectangle_constant(radiance: f64, receiver: &Receiver) -> Vec<f64> {
    let corners = [
        DVec3::new(RECT_X[0], RECT_Y[0], HEIGHT),
        DVec3::new(RECT_X[1], RECT_Y[0], HEIGHT),
        DVec3::new(RECT_X[1], RECT_Y[1], HEIGHT),
        DVec3::new(RECT_X[0], RECT_Y[1], HEIGHT),
    ];
    let lambert = |x: DVec3| {
        let u = corners.map(|c| (c - x).normalize());
        let mut sum = 0.0;
        for k in 0..4 {
            let (a, b) = (u[k], u[(k + 1) % 4]);
            sum += a.dot(b).clamp(-1.0, 1.0).acos() * a.cross(b).normalize().z;
        }
        radiance * 0.5 * sum.abs()
    };
    (0..receiver.pixels())
        .map(|k| {
            let (i, j) = (k % receiver.width, k / receiver.width);
            let mut e = 0.0;
            for fy in GAUSS2 {
                for fx in GAUSS2 {
                    e += 0.25 * lambert(receiver.point(i, j, fx, fy));
                }
            }
            e
        })
        .collect()
}

/// The radiance (grey) of a constant emitter on `shape` with the power of
/// `emitter`: `∫ Y(Le) dA / A`.
pub(crate) fn constant_radiance(emitter: &Emitter<'_>, shape: &Shape) -> f64 {
    emitter.power() / std::f64::consts::PI / shape.area()
}

/// The name of the constant floor's rows (beside the four strategies' names).
pub(crate) const FLOOR: &str = "constant-floor";

/// A measured row.
#[derive(Debug, Clone)]
pub(crate) struct Row {
    pub(crate) scene: String,
    pub(crate) texture: String,
    pub(crate) triangles: usize,
    pub(crate) strategy: String,
    /// `equal-spp` or `equal-time`.
    pub(crate) budget: &'static str,
    pub(crate) spp: usize,
    /// The render's wall seconds (median of the repeats), sampling and
    /// estimation only: the emitter is built before.
    pub(crate) seconds: f64,
    /// Seconds to build the emitter.
    pub(crate) build_seconds: f64,
    pub(crate) errors: Errors,
    /// The strategy's per-sample relative variance `v` (the mean over
    /// pixels of a sample's variance over the reference squared), from a
    /// render at [`Config::variance_spp`]: the expected relative MSE at
    /// `n` spp is `v / n`. One image's relative MSE at low spp is a poor
    /// estimate of that expectation when the estimator has a heavy tail
    /// (by area, the sun is hit about 10 times in 524,288 samples).
    pub(crate) rel_var: f64,
}

impl Row {
    /// The expected relative MSE at this row's spp: `rel_var / spp`.
    pub(crate) fn expected(&self) -> f64 {
        self.rel_var / self.spp as f64
    }
}

/// What [`measure`] does.
#[derive(Debug, Clone)]
pub(crate) struct Config {
    pub(crate) receiver: Receiver,
    /// Samples per pixel of the equal-spp rows.
    pub(crate) spps: Vec<usize>,
    /// Samples per pixel of each of the two reference renders.
    pub(crate) reference_spp: usize,
    /// Samples per pixel of the render that measures each strategy's
    /// per-sample variance ([`Row::rel_var`]).
    pub(crate) variance_spp: usize,
    pub(crate) seed: u64,
    /// Timed repeats of each row (the median is kept).
    pub(crate) repeats: usize,
    /// Equal-time rows: the budget is `texture`'s time at the largest spp.
    pub(crate) equal_time: bool,
    /// Threads of the pool the rows are rendered on (references and
    /// quadrature use the caller's pool).
    pub(crate) threads: usize,
}

/// A luminaire measured: its references and rows, and the images of each
/// strategy at `picture_spp`.
#[derive(Debug, Clone)]
pub(crate) struct Measured {
    pub(crate) reference: Reference,
    /// The constant floor's reference (closed form for the rectangle).
    pub(crate) floor_reference: Vec<f64>,
    /// The rectangle only: quadrature pixels, the quadrature and the
    /// largest `|reference − quadrature| / SE` and relative difference.
    pub(crate) quadrature: Option<QuadratureCheck>,
    pub(crate) rows: Vec<Row>,
    /// (strategy, image) at the picture spp.
    pub(crate) pictures: Vec<(String, Irradiance)>,
}

/// The reference against the quadrature on a lattice of pixels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct QuadratureCheck {
    pub(crate) pixels: usize,
    /// The largest `|r − q| / q`.
    pub(crate) max_relative: f64,
    /// The largest `|r − q| / SE(r)`.
    pub(crate) max_z: f64,
    /// The root mean square of `(r − q) / SE(r)`: about 1 when they agree.
    pub(crate) rms_z: f64,
}

/// An emitter of `shape` with `emission` and `strategy` (`constant-floor`:
/// per-face radiance `floor` everywhere, by area), with its build time.
fn build<'a>(
    shape: &'a Shape,
    emission: Emission<'a>,
    strategy: &str,
) -> Result<(Emitter<'a>, f64), String> {
    let start = Instant::now();
    let strategy = if strategy == FLOOR {
        Strategy::Area
    } else {
        Strategy::from_name(strategy).ok_or(format!("no strategy {strategy}"))?
    };
    let options = EmitterOptions {
        strategy,
        ..Default::default()
    };
    let e = Emitter::new(shape.mesh(), emission, &options)
        .map_err(|e| format!("{} emitter ({}): {e}", shape.name, strategy.name()))?;
    Ok((e, start.elapsed().as_secs_f64()))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Renders `repeats` times (the same image each time), returning the
/// image and the median seconds.
fn timed(
    pool: &rayon::ThreadPool,
    emitter: &Emitter<'_>,
    config: &Config,
    spp: usize,
) -> (Irradiance, f64) {
    let run = || {
        let start = Instant::now();
        let image = pool.install(|| render(emitter, &config.receiver, spp, config.seed));
        (image, start.elapsed().as_secs_f64())
    };
    let (image, first) = run();
    let mut times = vec![first];
    for _ in 1..config.repeats {
        times.push(run().1);
    }
    (image, median(times))
}

/// Every strategy on `shape` with `texture`: the reference (texture-exact,
/// two seeds), the quadrature check (rectangle), the constant floor's
/// reference, and the rows at each spp and at equal time. `shared` is a
/// reference (and its quadrature check) made before for the same
/// irradiance, used instead of a new one.
///
/// # Errors
/// An emitter that cannot be built, a reference pixel that is not
/// positive, a thread pool that cannot be made.
pub(crate) fn measure(
    shape: &Shape,
    texture: &EmissionTexture,
    texture_name: &str,
    config: &Config,
    picture_spp: usize,
    shared: Option<(&Reference, Option<QuadratureCheck>)>,
) -> Result<Measured, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(config.threads)
        .build()
        .map_err(|e| format!("thread pool: {e}"))?;
    let emission = Emission::Texture {
        texture,
        scale: 1.0,
    };
    let receiver = &config.receiver;
    let (exact, _) = build(shape, emission, "texture-exact")?;
    if let Some((reference, quadrature)) = shared {
        return measure_rows(
            shape,
            emission,
            texture_name,
            config,
            picture_spp,
            &pool,
            constant_radiance(&exact, shape),
            reference.clone(),
            quadrature,
        );
    }
    let reference = make_reference(&exact, receiver, config.reference_spp, config.seed ^ 0xA5A5)?;
    let quadrature = shape.planar.then(|| {
        let lattice: Vec<(usize, usize)> = (0..4)
            .flat_map(|b| (0..8).map(move |a| (a, b)))
            .map(|(a, b)| {
                (
                    (receiver.width * (2 * a + 1) / 16).min(receiver.width - 1),
                    (receiver.height * (2 * b + 1) / 8).min(receiver.height - 1),
                )
            })
            .collect();
        let q = rectangle_quadrature(texture, receiver, &lattice);
        let (mut max_relative, mut max_z, mut z2) = (0.0f64, 0.0f64, 0.0);
        for (&(i, j), q) in lattice.iter().zip(&q) {
            let k = j * receiver.width + i;
            let r = reference.image.y[k];
            let z = (r - q) / reference.image.y_var[k].sqrt();
            max_relative = max_relative.max(((r - q) / q).abs());
            max_z = max_z.max(z.abs());
            z2 += z * z;
        }
        QuadratureCheck {
            pixels: lattice.len(),
            max_relative,
            max_z,
            rms_z: (z2 / lattice.len() as f64).sqrt(),
        }
    });
    let floor_radiance = constant_radiance(&exact, shape);
    drop(exact);
    measure_rows(
        shape,
        emission,
        texture_name,
        config,
        picture_spp,
        &pool,
        floor_radiance,
        reference,
        quadrature,
    )
}

/// [`measure`] with the reference made: the floor's reference and the rows.
#[expect(
    clippy::too_many_arguments,
    reason = "one private step of measure, called twice"
)]
fn measure_rows(
    shape: &Shape,
    emission: Emission<'_>,
    texture_name: &str,
    config: &Config,
    picture_spp: usize,
    pool: &rayon::ThreadPool,
    floor_radiance: f64,
    reference: Reference,
    quadrature: Option<QuadratureCheck>,
) -> Result<Measured, String> {
    let receiver = &config.receiver;
    let floor_rgb = vec![[floor_radiance as f32; 3]; shape.triangles()];
    let floor_emission = Emission::PerFace(&floor_rgb);
    let floor_reference = if shape.planar {
        rectangle_constant(f64::from(floor_radiance as f32), receiver)
    } else {
        let (e, _) = build(shape, floor_emission, FLOOR)?;
        make_reference(&e, receiver, config.reference_spp, config.seed ^ 0x5A5A)?
            .image
            .y
    };

    let mut rows = Vec::new();
    let mut pictures = Vec::new();
    // Per strategy, seconds per spp at the largest spp (for equal time).
    let mut per_spp = Vec::new();
    let strategies = Strategy::ALL
        .iter()
        .map(|s| s.name())
        .chain([FLOOR])
        .collect::<Vec<_>>();
    let largest = config.spps.iter().copied().max().unwrap_or(1);
    for &name in &strategies {
        let (emitter, build_seconds) = if name == FLOOR {
            build(shape, floor_emission, name)?
        } else {
            build(shape, emission, name)?
        };
        let target = if name == FLOOR {
            &floor_reference
        } else {
            &reference.image.y
        };
        let rel_var = {
            let n = config.variance_spp as f64;
            let img = pool.install(|| {
                render(
                    &emitter,
                    receiver,
                    config.variance_spp,
                    config.seed ^ 0x7777,
                )
            });
            img.y_var
                .iter()
                .zip(target)
                .map(|(v, r)| v * n / (r * r))
                .sum::<f64>()
                / target.len() as f64
        };
        let row = |budget, spp, seconds, image: &Irradiance| Row {
            scene: shape.name.clone(),
            texture: texture_name.into(),
            triangles: shape.triangles(),
            strategy: name.into(),
            budget,
            spp,
            seconds,
            build_seconds,
            errors: compare(&image.y, target),
            rel_var,
        };
        for &spp in &config.spps {
            let (image, seconds) = timed(pool, &emitter, config, spp);
            rows.push(row("equal-spp", spp, seconds, &image));
            if spp == largest {
                per_spp.push((name, seconds / spp as f64, rel_var));
            }
            if spp == picture_spp {
                pictures.push((name.to_string(), image));
            }
        }
    }
    if config.equal_time {
        let budget = per_spp
            .iter()
            .find(|(n, _, _)| *n == "texture")
            .map(|(_, s, _)| s * largest as f64)
            .unwrap_or(0.0);
        for &(name, seconds_per_spp, rel_var) in &per_spp {
            if name == FLOOR {
                continue;
            }
            let spp = ((budget / seconds_per_spp).round() as usize).clamp(1, 1 << 16);
            let (emitter, build_seconds) = build(shape, emission, name)?;
            let (image, seconds) = timed(pool, &emitter, config, spp);
            rows.push(Row {
                scene: shape.name.clone(),
                texture: texture_name.into(),
                triangles: shape.triangles(),
                strategy: name.into(),
                budget: "equal-time",
                spp,
                seconds,
                build_seconds,
                errors: compare(&image.y, &reference.image.y),
                rel_var,
            });
        }
    }
    Ok(Measured {
        reference,
        floor_reference,
        quadrature,
        rows,
        pictures,
    })
}

/// Light samples per second on one thread (`sample_into` in blocks of
/// [`BLOCK`], the radiance included), for about `seconds`.
pub(crate) fn light_rate(emitter: &Emitter<'_>, seconds: f64, seed: u64) -> f64 {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut block = vec![LightSample::default(); BLOCK];
    let mut sink = 0.0f32;
    let start = Instant::now();
    let mut n = 0usize;
    while n == 0 || start.elapsed().as_secs_f64() < seconds {
        emitter.sample_into(&mut rng, &mut block);
        sink += block
            .iter()
            .map(|s| s.point.pdf + s.radiance[1])
            .sum::<f32>();
        n += block.len();
    }
    let rate = n as f64 / start.elapsed().as_secs_f64();
    std::hint::black_box(sink);
    rate
}

/// The ratio of `a`'s light-sample rate to `b`'s on one thread: the median
/// of `pairs` back-to-back pairs of runs (alternating which goes first),
/// so that a neighbour's load falls on both sides of each pair; and the
/// median rates.
pub(crate) fn paired_rate(
    a: &Emitter<'_>,
    b: &Emitter<'_>,
    pairs: usize,
    seconds: f64,
) -> (f64, f64, f64) {
    let (mut ratios, mut ra, mut rb) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..pairs.max(1) {
        let (x, y) = if k % 2 == 0 {
            let x = light_rate(a, seconds, k as u64);
            (x, light_rate(b, seconds, k as u64))
        } else {
            let y = light_rate(b, seconds, k as u64);
            (light_rate(a, seconds, k as u64), y)
        };
        ratios.push(x / y);
        ra.push(x);
        rb.push(y);
    }
    (median(ratios), median(ra), median(rb))
}

/// Generated textures for runs without data (and the test): `sun`, a sky
/// gradient with a 2 × 2-texel sun carrying about a third of the power, and
/// `soft`, a smooth overcast gradient; `width × width/2` texels.
pub(crate) fn generated_textures(width: usize) -> Vec<(String, EmissionTexture)> {
    let height = width / 2;
    let sky = |x: usize, y: usize| {
        let (s, t) = (
            (x as f64 + 0.5) / width as f64,
            (y as f64 + 0.5) / height as f64,
        );
        let g = 0.3 + 0.7 * (1.0 - t) + 0.2 * (6.0 * s).sin();
        [0.8 * g, 0.9 * g, 1.1 * g].map(|c| c as f32)
    };
    let sun_at = (width * 6 / 10, height * 3 / 10);
    let sun_texels = (width * height) as f32 / 6.0;
    let sun: Vec<[f32; 3]> = (0..width * height)
        .map(|k| {
            let (x, y) = (k % width, k / width);
            if (x == sun_at.0 || x == sun_at.0 + 1) && (y == sun_at.1 || y == sun_at.1 + 1) {
                [sun_texels, 0.95 * sun_texels, 0.8 * sun_texels]
            } else {
                sky(x, y)
            }
        })
        .collect();
    let soft: Vec<[f32; 3]> = (0..width * height)
        .map(|k| sky(k % width, k / width))
        .collect();
    let make = |rgb| {
        EmissionTexture::new(width, height, rgb)
            .unwrap_or_else(|e| unreachable!("generated texture: {e}"))
            .with_wrap(mesh_sampling::Wrap::ClampToEdge)
    };
    vec![("sun".into(), make(sun)), ("soft".into(), make(soft))]
}

/// The texture's largest texel luminance over its mean.
pub(crate) fn peak_over_mean(texture: &EmissionTexture) -> f64 {
    let y: Vec<f64> = texture
        .texels()
        .iter()
        .map(|&c| f64::from(luminance(c)))
        .collect();
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    y.iter().copied().fold(0.0, f64::max) / mean
}
