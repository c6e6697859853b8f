//! An independent check of the diffusion model's brightness: a small Monte
//! Carlo volumetric path tracer (light tracing) for a homogeneous sphere
//! with a smooth refractive boundary, against `Object::radiance` on the
//! TetGen sphere of the data folder.
//!
//! ```sh
//! TRILUX_DATA=../shared/data cargo run --release -p tet-diffusion --example pathtrace -- [--photons N] [--material NAME]
//! ```
//!
//! The scene of the issue's bar: a sphere of radius 10 mm (`sphere_200k`,
//! 1 unit = 10 mm), η = 1.3, one directional light of irradiance
//! 1 W/mm² from +y, seen from +z. Compared is the radiant intensity
//! toward the viewer from the lit hemisphere (`y > 0`),
//! `I = ∫_{y>0} L(x, ω) (n·ω)⁺ dA`, averaged over the directions `ω`
//! within 15° of +z (the path tracer bins escaping photons in that cone),
//! in W/sr per channel: the sum of an orthographic picture's pixels.
//!
//! The path tracer: photons enter through the disc the light sees, are
//! refracted with Fresnel's transmittance (the specular reflection is left
//! out, as the diffusion picture leaves it out), take exponential steps of
//! `1/(μa + σs′)` with isotropic scattering (the similarity relation, as
//! the diffusion model uses σs′), are weighted by the albedo at each
//! scattering and leave, or are reflected, at the boundary by Fresnel.
//! Independent of the crate except for reading `Medium::measured`.

use rayon::prelude::*;
use tet_diffusion::glam::DVec3;
use tet_diffusion::{Light, Medium, Object, TetMesh};

const RADIUS: f64 = 10.0;
const ETA: f64 = 1.3;
const CONE_DEGREES: f64 = 15.0;

use test_support::SplitMix64 as Random;

/// Unpolarised Fresnel reflectance between indices `n1` (incident side)
/// and `n2`, incident cosine `ci`; 1 under total internal reflection.
/// Returns (reflectance, transmitted cosine).
fn fresnel(ci: f64, n1: f64, n2: f64) -> (f64, f64) {
    let r = n1 / n2;
    let st2 = r * r * (1.0 - ci * ci);
    if st2 >= 1.0 {
        return (1.0, 0.0);
    }
    let ct = (1.0 - st2).sqrt();
    let rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    let rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    (0.5 * (rs * rs + rp * rp), ct)
}

/// The distance from `p` (inside) along unit `d` to the sphere.
fn exit_distance(p: DVec3, d: DVec3) -> f64 {
    let b = p.dot(d);
    let c = p.length_squared() - RADIUS * RADIUS;
    -b + (b * b - c).max(0.0).sqrt()
}

fn isotropic(rng: &mut Random) -> DVec3 {
    let z = 2.0 * rng.f64() - 1.0;
    let phi = 2.0 * std::f64::consts::PI * rng.f64();
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// One photon's weight escaping from the lit hemisphere into the cone
/// around +z (0 if it does not).
fn photon(rng: &mut Random, sigma_s: f64, mu_a: f64) -> f64 {
    let sigma_t = sigma_s + mu_a;
    let albedo = sigma_s / sigma_t;
    let cone = CONE_DEGREES.to_radians().cos();
    // Enter through the disc the light (from +y) sees.
    let (r, a) = (
        RADIUS * rng.f64().sqrt(),
        2.0 * std::f64::consts::PI * rng.f64(),
    );
    let (x, z) = (r * a.cos(), r * a.sin());
    let mut p = DVec3::new(x, (RADIUS * RADIUS - r * r).max(0.0).sqrt(), z);
    let n = p / RADIUS;
    let d_in = DVec3::NEG_Y;
    let ci = -d_in.dot(n);
    let (reflect, ct) = fresnel(ci, 1.0, ETA);
    if rng.f64() < reflect {
        return 0.0; // specular reflection: not subsurface light
    }
    let k = 1.0 / ETA;
    let mut d = (d_in * k + n * (k * ci - ct)).normalize();
    let mut w = 1.0;
    for _ in 0..1_000_000 {
        let step = -(1.0 - rng.f64()).ln() / sigma_t;
        let to_wall = exit_distance(p, d);
        if step < to_wall {
            p += d * step;
            w *= albedo;
            if w < 1e-3 {
                // Russian roulette keeps the estimate unbiased.
                if rng.f64() < 0.5 {
                    return 0.0;
                }
                w *= 2.0;
            }
            d = isotropic(rng);
            continue;
        }
        p += d * to_wall;
        p = p.normalize() * RADIUS;
        let n = p / RADIUS;
        let ci = d.dot(n);
        let (reflect, ct) = fresnel(ci, ETA, 1.0);
        if rng.f64() < reflect {
            d = (d - n * (2.0 * ci)).normalize();
            continue;
        }
        let out = (d * ETA + n * (ct - ETA * ci)).normalize();
        return if p.y > 0.0 && out.z >= cone { w } else { 0.0 };
    }
    0.0
}

/// The path tracer's intensity (W/sr) for one channel.
fn traced(photons: usize, sigma_s: f64, mu_a: f64, seed: u64) -> (f64, f64) {
    let chunks = 256;
    let per = photons.div_ceil(chunks);
    let sums: Vec<(f64, f64)> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut rng = Random(seed ^ (c as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
            let (mut s, mut s2) = (0.0, 0.0);
            for _ in 0..per {
                let w = photon(&mut rng, sigma_s, mu_a);
                s += w;
                s2 += w * w;
            }
            (s, s2)
        })
        .collect();
    let n = (per * chunks) as f64;
    let (s, s2) = sums.iter().fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
    let solid = 2.0 * std::f64::consts::PI * (1.0 - CONE_DEGREES.to_radians().cos());
    let power = std::f64::consts::PI * RADIUS * RADIUS; // irradiance 1 W/mm²
    let mean = s / n;
    let sd = ((s2 / n - mean * mean).max(0.0) / n).sqrt();
    (mean * power / solid, sd * power / solid)
}

/// The diffusion model's intensity (W/sr) per channel, with `radiance`
/// (in air) and with the printed Eq. 3 (`radiance_inside`).
#[allow(
    clippy::needless_range_loop,
    reason = "RGB loops index several per-channel arrays by one channel index"
)]
fn diffusion(material: Medium) -> Result<([f64; 3], [f64; 3]), String> {
    let data = std::env::var_os("TRILUX_DATA").unwrap_or_else(|| "../shared/data".into());
    let path = std::path::Path::new(&data)
        .join("tets")
        .join("sphere_200k.node");
    let file =
        trilux_io::tet::TetMesh::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mesh = TetMesh::new(&file.positions, &file.tets).map_err(|e| e.to_string())?;
    let mut o = Object::homogeneous(mesh, RADIUS, material, ETA).map_err(|e| e.to_string())?;
    o.add_light(Light::Directional {
        to_light: DVec3::Y,
        irradiance: [1.0; 3],
    })
    .map_err(|e| e.to_string())?;
    o.settings.tolerance = 1e-9;
    o.solve().map_err(|e| e.to_string())?;
    // Directions evenly over the cone (a Fibonacci spiral in cos θ).
    let cone = CONE_DEGREES.to_radians().cos();
    let k = 256;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let directions: Vec<DVec3> = (0..k)
        .map(|i| {
            let z = 1.0 - (1.0 - cone) * (i as f64 + 0.5) / k as f64;
            let r = (1.0 - z * z).sqrt();
            let a = golden * i as f64;
            DVec3::new(r * a.cos(), r * a.sin(), z)
        })
        .collect();
    let mesh = o.mesh();
    let area = RADIUS * RADIUS; // mesh units² → mm²
    let mut out = [[0.0; 3]; 2];
    for (slot, inside) in [(0, false), (1, true)] {
        for &w in &directions {
            let l = if inside {
                o.radiance_inside(Some(w))
            } else {
                o.radiance(Some(w))
            };
            for (j, &v) in mesh.boundary_vertices().iter().enumerate() {
                let v = v as usize;
                if mesh.positions()[v].y <= 0.0 {
                    continue;
                }
                let cos = mesh.vertex_normals()[v].dot(w).max(0.0);
                let s = mesh.vertex_areas()[v] / 3.0 * area;
                for c in 0..3 {
                    out[slot][c] += l[j][c] * cos * s / k as f64;
                }
            }
        }
    }
    Ok((out[0], out[1]))
}

#[allow(
    clippy::needless_range_loop,
    reason = "RGB loops index several per-channel arrays by one channel index"
)]
fn run() -> Result<(), String> {
    let mut photons = 200_000usize;
    let mut name = "marble".to_string();
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "--photons" => {
                photons = it
                    .next()
                    .and_then(|v| v.parse().ok())
                    .filter(|&n: &usize| n > 0)
                    .ok_or("--photons needs a positive whole number")?;
            }
            "--material" => name = it.next().ok_or("--material needs a name")?,
            other => return Err(format!("unknown argument {other}")),
        }
    }
    let m = Medium::measured(&name).map_err(|e| e.to_string())?;
    let (air, inside) = diffusion(m)?;
    println!(
        "{name}, R = {RADIUS} mm, η = {ETA}, light from +y, intensity toward +z (within {CONE_DEGREES}°) from y > 0, W/sr; {photons} photons per channel\n"
    );
    println!(
        "| channel | path traced | ± (1σ) | diffusion, radiance in air | ratio | Eq. 3 as printed | ratio |"
    );
    println!("|---|---|---|---|---|---|---|");
    for c in 0..3 {
        let (t, sd) = traced(photons, m.sigma_s_prime[c], m.sigma_a[c], 0x7A11 + c as u64);
        println!(
            "| {} | {t:.4} | {sd:.4} | {:.4} | {:.3} | {:.4} | {:.3} |",
            ["R", "G", "B"][c],
            air[c],
            air[c] / t,
            inside[c],
            inside[c] / t
        );
    }
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("pathtrace: {e}");
        std::process::exit(1);
    }
}
