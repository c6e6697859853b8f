//! Meshes built in code and the closed form of the homogeneous sphere.
#![allow(dead_code, reason = "each test binary uses a part of the helpers")]

use tet_diffusion::glam::DVec3;
use tet_diffusion::{Medium, Object, TetMesh};

mod kuhn;

/// An `n³` lattice of `[-1, 1]³`, each cube split into six tets around its
/// main diagonal.
pub(crate) fn cube(n: usize) -> (Vec<DVec3>, Vec<[u32; 4]>) {
    let (p, tets) = kuhn::cube(n, 2.0);
    (p.into_iter().map(|x| x - DVec3::ONE).collect(), tets)
}

/// A ball of radius `r`: the cube lattice mapped radially,
/// `x ← r x ‖x‖∞ / ‖x‖₂`, so that the boundary vertices lie on the sphere.
pub(crate) fn ball(n: usize, r: f64) -> TetMesh {
    let (p, t) = cube(n);
    let p: Vec<DVec3> = p
        .into_iter()
        .map(|x| {
            let l = x.length();
            if l == 0.0 {
                x
            } else {
                x * (r * x.abs().max_element() / l)
            }
        })
        .collect();
    TetMesh::new(&p, &t).unwrap()
}

/// The closed form of a homogeneous sphere under uniform `q`:
/// `φ(r) = C sinh(r/ℓ) / r`. Returns `(C, ℓ)`.
pub(crate) fn sphere_closed_form(
    mu_a: f64,
    sigma_s: f64,
    radius: f64,
    q: f64,
    eta: f64,
) -> (f64, f64) {
    let kappa = 1.0 / (3.0 * (mu_a + sigma_s));
    let l = (kappa / mu_a).sqrt();
    let fdr = tet_diffusion::fresnel::diffuse_reflectance(eta);
    let a = (1.0 + fdr) / (1.0 - fdr);
    let g = 4.0 * q / (1.0 - fdr);
    let x = radius / l;
    let c = g * radius
        / (x.sinh() * (1.0 - 2.0 * a * kappa / radius) + (2.0 * a * kappa / l) * x.cosh());
    (c, l)
}

/// `φ(r)` of the closed form.
pub(crate) fn sphere_phi(c: f64, l: f64, r: f64) -> f64 {
    if r < 1e-12 {
        c / l
    } else {
        c * (r / l).sinh() / r
    }
}

/// A homogeneous medium with the same coefficients in all channels.
pub(crate) fn grey(mu_a: f64, sigma_s: f64) -> Medium {
    Medium {
        sigma_a: [mu_a; 3],
        sigma_s_prime: [sigma_s; 3],
    }
}

/// Lumped vertex volumes `V_i / 4`.
pub(crate) fn vertex_volumes(mesh: &TetMesh) -> Vec<f64> {
    let mut v = vec![0.0; mesh.vertex_count()];
    for (t, tet) in mesh.tets().iter().enumerate() {
        let vol = mesh.tet_volume(t) / 4.0;
        for &i in tet {
            v[i as usize] += vol;
        }
    }
    v
}

/// Volume-weighted relative L2 difference of `a` against `b`.
pub(crate) fn rel_l2(mesh: &TetMesh, a: &[f64], b: &[f64]) -> f64 {
    let w = vertex_volumes(mesh);
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..a.len() {
        num += w[i] * (a[i] - b[i]).powi(2);
        den += w[i] * b[i] * b[i];
    }
    (num / den).sqrt()
}

/// Solves the sphere problem on `mesh` (in mm) and returns the relative L2
/// error of channel 0 against the closed form.
pub(crate) fn sphere_error(mesh: TetMesh, mu_a: f64, sigma_s: f64, radius: f64) -> f64 {
    let (c, l) = sphere_closed_form(mu_a, sigma_s, radius, 1.0, 1.3);
    let exact: Vec<f64> = mesh
        .positions()
        .iter()
        .map(|p| sphere_phi(c, l, p.length()))
        .collect();
    let nb = mesh.boundary_vertices().len();
    let mut o = Object::homogeneous(mesh, 1.0, grey(mu_a, sigma_s), 1.3).unwrap();
    o.set_incident(vec![[1.0; 3]; nb]).unwrap();
    o.settings.tolerance = 1e-10;
    o.solve().unwrap();
    rel_l2(o.mesh(), o.phi(0), &exact)
}
