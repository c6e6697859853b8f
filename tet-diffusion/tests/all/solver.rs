//! The solver against closed forms, the P1 reference, conservation, units
//! and thread counts.

use crate::common;

use common::*;
use tet_diffusion::glam::DVec3;
use tet_diffusion::multires::{self, SolveOptions};
use tet_diffusion::{Error, Integration, Light, Medium, Method, Noise, Object, TetMesh, fresnel};

#[test]
fn closed_form_reference_values() {
    // The reference values of the homogeneous sphere (q = 1, η = 1.3).
    let (c, l) = sphere_closed_form(0.01, 1.0, 10.0, 1.0, 1.3);
    assert!((c - 22.74845111).abs() < 1e-6, "{c}");
    assert!((sphere_phi(c, l, 0.0) - 3.959799).abs() < 1e-6);
    assert!((sphere_phi(c, l, 10.0) - 6.2852535).abs() < 1e-6);
    let (c, l) = sphere_closed_form(0.1, 2.0, 5.0, 1.0, 1.3);
    assert!((c - 0.9135460499).abs() < 1e-8, "{c}");
    assert!((sphere_phi(c, l, 0.0) - 0.7251047).abs() < 1e-6);
    assert!((sphere_phi(c, l, 5.0) - 4.8320129).abs() < 1e-6);
}

#[test]
fn sphere_converges_to_the_closed_form() {
    for (mu, s, r) in [(0.01, 1.0, 10.0), (0.1, 2.0, 5.0)] {
        let coarse = sphere_error(ball(6, r), mu, s, r);
        let fine = sphere_error(ball(12, r), mu, s, r);
        let order = (coarse / fine).log2();
        eprintln!("sphere μa={mu}: L2 error {coarse:.2e} → {fine:.2e}, observed order {order:.2}");
        assert!(order > 1.5, "order {order}");
        assert!(fine < 0.02, "{fine}");
    }
}

/// `φ = exp(d·x/ℓ)` solves the PDE; its boundary source is
/// `q = (1 − F_dr)/4 · φ · (1 + 2A √(κ μa) (d·n))`.
fn manufactured_error(mesh: TetMesh, mu_a: f64, sigma_s: f64) -> f64 {
    let d = DVec3::new(1.0, 2.0, -0.5).normalize();
    let kappa = 1.0 / (3.0 * (mu_a + sigma_s));
    let l = (kappa / mu_a).sqrt();
    let fdr = fresnel::diffuse_reflectance(1.3);
    let a = fresnel::boundary_factor(1.3);
    let exact: Vec<f64> = mesh
        .positions()
        .iter()
        .map(|x| (d.dot(*x) / l).exp())
        .collect();
    let q: Vec<[f64; 3]> = mesh
        .boundary_vertices()
        .iter()
        .map(|&v| {
            let n = mesh.vertex_normals()[v as usize];
            let qv = (1.0 - fdr) / 4.0
                * exact[v as usize]
                * (1.0 + 2.0 * a * (kappa * mu_a).sqrt() * d.dot(n));
            [qv; 3]
        })
        .collect();
    let mut o = Object::homogeneous(mesh, 1.0, grey(mu_a, sigma_s), 1.3).unwrap();
    o.set_incident(q).unwrap();
    o.settings.tolerance = 1e-10;
    o.solve().unwrap();
    rel_l2(o.mesh(), o.phi(0), &exact)
}

#[test]
fn manufactured_solution_converges_at_second_order() {
    let coarse = manufactured_error(ball(6, 3.0), 0.2, 1.0);
    let fine = manufactured_error(ball(12, 3.0), 0.2, 1.0);
    let order = (coarse / fine).log2();
    eprintln!("manufactured: {coarse:.2e} → {fine:.2e}, order {order:.2}");
    assert!(order > 1.6, "order {order}");
}

fn noisy(n: usize) -> Object {
    let mesh = ball(n, 4.0);
    let noise = Noise {
        a: Medium::measured("marble").unwrap(),
        b: Medium::measured("apple").unwrap(),
        scale: 2.0,
        octaves: 2,
        seed: 3,
    };
    let media = noise.media(&mesh).unwrap();
    let mut o = Object::new(mesh, 1.0, media, 1.3).unwrap();
    o.add_light(Light::Directional {
        to_light: DVec3::new(0.2, 0.3, 1.0),
        irradiance: [1.0, 0.8, 0.6],
    })
    .unwrap();
    o
}

fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() / y.abs().max(1e-300))
        .fold(0.0, f64::max)
}

#[test]
fn the_exact_relation_to_p1() {
    let o = noisy(5);
    let a = o.boundary_factor();
    let closed = o.fem_reference(Integration::ClosedForm);
    let quad = o.fem_reference(Integration::Quadrature);
    for c in 0..3 {
        // Two independent P1 assemblies agree to rounding …
        let (x, y) = (closed.stiffness[c].data(), quad.stiffness[c].data());
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(x.iter().zip(y).all(|(p, q)| (p - q).abs() <= 1e-12 * scale));
        let (x, y) = (closed.mass[c].data(), quad.mass[c].data());
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(x.iter().zip(y).all(|(p, q)| (p - q).abs() <= 1e-12 * scale));
        // … and M = 4 (K + lumped Mμ + lumped B / 2A) to rounding.
        let m = o.matrix(c);
        let lumped = &closed.lumped_times_four(a)[c];
        assert_eq!(m.indices(), lumped.indices());
        let scale = m.data().iter().fold(0.0f64, |s, v| s.max(v.abs()));
        for (p, q) in m.data().iter().zip(lumped.data()) {
            assert!((p - q).abs() <= 1e-12 * scale, "{p} vs {q}");
        }
    }
    let (x, y) = (closed.boundary.data(), quad.boundary.data());
    assert!(x.iter().zip(y).all(|(p, q)| (p - q).abs() <= 1e-13));
    // b = 4 × the lumped P1 load.
    let fdr = o.fdr();
    let mesh = o.mesh();
    for c in 0..3 {
        for (k, &v) in mesh.boundary_vertices().iter().enumerate() {
            let row = closed.boundary.outer_view(v as usize).unwrap();
            let lumped: f64 = row.iter().map(|(_, b)| b).sum::<f64>();
            let load = 4.0 * 2.0 / (a * (1.0 - fdr)) * lumped * o.incident()[k][c];
            let b = o.rhs(c)[v as usize];
            assert!((b - load).abs() <= 1e-12 * b.abs().max(1e-300));
        }
    }
}

#[test]
fn close_to_the_p1_solution() {
    // Marble and apple on a 4 mm ball (lattice mesh), one-sided light; the
    // diffusion lengths (≥ 1.9 mm) are resolved by the 0.8 mm cells.
    let mut o = noisy(10);
    o.settings.tolerance = 1e-10;
    o.solve().unwrap();
    let a = o.boundary_factor();
    let fem = o.fem_reference(Integration::ClosedForm).consistent(a);
    let p1 = o.fem_reference(Integration::ClosedForm);
    let mesh = o.mesh();
    for (c, system) in fem.iter().enumerate() {
        let mut q = vec![0.0; mesh.vertex_count()];
        for (k, &v) in mesh.boundary_vertices().iter().enumerate() {
            q[v as usize] = o.incident()[k][c];
        }
        let b = p1.load(&q, a, o.fdr());
        let mut x = vec![0.0; b.len()];
        let r = multires::cg(system, &b, &mut x, &SolveOptions::new(1e-10, 10_000)).unwrap();
        assert!(r.converged());
        let l2 = rel_l2(mesh, o.phi(c), &x);
        eprintln!("channel {c}: relative L2 difference to P1 {l2:.2e}");
        assert!(l2 < 0.02, "{l2}");
    }
}

#[test]
fn energy_balance() {
    // Σ_i (M φ)_i = Σ_i b_i: absorbed + exiting = entering.
    let mut o = noisy(6);
    o.settings.tolerance = 1e-11;
    o.solve().unwrap();
    let mesh = o.mesh();
    let a = o.boundary_factor();
    let fdr = o.fdr();
    let coefficient = |t: usize| o.medium(t).unwrap().sigma_a;
    for c in 0..3 {
        let phi = o.phi(c);
        let mut absorbed = 0.0;
        for (t, tet) in mesh.tets().iter().enumerate() {
            let m = mesh.tet_volume(t) * coefficient(t)[c];
            absorbed += m * tet.iter().map(|&v| phi[v as usize]).sum::<f64>() / 4.0;
        }
        let (mut entering, mut exiting) = (0.0, 0.0);
        for (k, &v) in mesh.boundary_vertices().iter().enumerate() {
            let s = mesh.vertex_areas()[v as usize] / 3.0;
            entering += s * 4.0 * o.incident()[k][c] / (1.0 - fdr) / (2.0 * a);
            exiting += s * phi[v as usize] / (2.0 * a);
        }
        let balance = (absorbed + exiting - entering).abs() / entering;
        assert!(balance < 1e-8, "channel {c}: {balance:e}");
        assert!(absorbed > 0.0 && exiting > 0.0);
    }
}

#[test]
fn units_do_not_change_phi() {
    let mesh_mm = ball(5, 4.0);
    let m_positions: Vec<DVec3> = mesh_mm.positions().iter().map(|p| *p / 1000.0).collect();
    let mesh_m = TetMesh::new(&m_positions, mesh_mm.tets()).unwrap();
    let medium = Medium::measured("skin1").unwrap();
    let light = Light::Point {
        position: DVec3::new(10.0, 2.0, 3.0),
        intensity: [1.0, 2.0, 3.0],
    };
    let mut a = Object::homogeneous(mesh_mm, 1.0, medium, 1.4).unwrap();
    let mut b = Object::homogeneous(mesh_m, 1000.0, medium, 1.4).unwrap();
    a.add_light(light.clone()).unwrap();
    b.add_light(Light::Point {
        position: DVec3::new(0.010, 0.002, 0.003),
        intensity: [1.0, 2.0, 3.0],
    })
    .unwrap();
    for o in [&mut a, &mut b] {
        o.settings.tolerance = 1e-12;
        o.solve().unwrap();
    }
    for c in 0..3 {
        let d = max_rel(b.phi(c), a.phi(c));
        assert!(d < 1e-8, "channel {c}: {d:e}");
    }
    // A marble bunny in metres is not milk: the unit matters for κ.
    let mut c = Object::homogeneous(ball(5, 0.004), 1.0, medium, 1.4).unwrap();
    c.add_light(Light::Point {
        position: DVec3::new(0.010, 0.002, 0.003),
        intensity: [1.0, 2.0, 3.0],
    })
    .unwrap();
    c.solve().unwrap();
    assert!(max_rel(c.phi(0), b.phi(0)) > 0.1);
}

#[test]
fn one_and_two_threads_agree_bit_for_bit() {
    let run = |threads: usize| {
        on_threads(threads, || {
            let mut o = noisy(6);
            o.solve().unwrap();
            let m: Vec<Vec<f64>> = (0..3).map(|c| o.matrix(c).data().to_vec()).collect();
            let phi: Vec<Vec<f64>> = (0..3).map(|c| o.phi(c).to_vec()).collect();
            (m, phi, o.incident().to_vec())
        })
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn methods_agree_and_warm_start_helps() {
    let mut reference = noisy(7);
    reference.settings.tolerance = 1e-11;
    reference.solve().unwrap();
    for method in [
        Method::VCyclePcg,
        Method::Cascade,
        Method::CascadeGalerkin,
        Method::JacobiPcg,
    ] {
        for share in [true, false] {
            let mut o = noisy(7);
            o.settings.method = method;
            o.settings.share_hierarchy = share;
            o.settings.tolerance = 1e-8;
            let cold = o.solve().unwrap();
            for c in 0..3 {
                let e = rel_l2(o.mesh(), o.phi(c), reference.phi(c));
                assert!(e < 1e-5, "{method:?}: {e:e}");
            }
            // Warm start after a small colour change of the light.
            o.set_light_color(0, [1.05, 0.8, 0.6]).unwrap();
            let warm = o.solve().unwrap();
            assert!(
                warm.channels[0].iterations < cold.channels[0].iterations,
                "{method:?}: {} vs {}",
                warm.channels[0].iterations,
                cold.channels[0].iterations
            );
        }
    }
}

#[test]
fn non_convergence_reports_the_true_residual() {
    let mut o = noisy(5);
    o.settings.method = Method::JacobiPcg;
    o.settings.max_iterations = 2;
    o.settings.tolerance = 1e-12;
    match o.solve() {
        Err(Error::NotConverged {
            channel,
            residual,
            iterations,
            ..
        }) => {
            assert_eq!((channel, iterations), ("red", 2));
            assert!(residual > 1e-12 && residual.is_finite());
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn bad_coefficients_are_errors() {
    let mesh = ball(2, 1.0);
    let mut bad = grey(0.1, 1.0);
    bad.sigma_s_prime[2] = 0.0;
    let e = Object::homogeneous(mesh.clone(), 1.0, bad, 1.3).unwrap_err();
    assert!(
        e.to_string().contains("sigma_s_prime[2] of tetrahedron 0"),
        "{e}"
    );
    let mut bad = grey(0.1, 1.0);
    bad.sigma_a[0] = -0.1;
    assert!(Object::homogeneous(mesh.clone(), 1.0, bad, 1.3).is_err());
    assert!(Object::homogeneous(mesh.clone(), 1.0, grey(0.1, 1.0), 0.0).is_err());
    assert!(Object::homogeneous(mesh.clone(), f64::NAN, grey(0.1, 1.0), 1.3).is_err());
    let mut o = Object::homogeneous(mesh, 1.0, grey(0.1, 1.0), 1.3).unwrap();
    assert!(
        o.add_light(Light::Directional {
            to_light: DVec3::new(f64::NAN, 0.0, 1.0),
            irradiance: [1.0; 3]
        })
        .is_err()
    );
    assert!(
        o.add_light(Light::Point {
            position: DVec3::ZERO,
            intensity: [1.0, f64::INFINITY, 1.0]
        })
        .is_err()
    );
    assert!(o.set_incident(vec![[1.0; 3]; 3]).is_err());
    assert!(o.set_light_color(0, [1.0; 3]).is_err());
}

#[test]
fn warns_when_the_mesh_cannot_resolve_the_material() {
    // Ketchup's blue diffusion length is 0.4 mm; a 40 mm ball of 4 cells cannot resolve it.
    let o = Object::homogeneous(
        ball(4, 20.0),
        1.0,
        Medium::measured("ketchup").unwrap(),
        1.3,
    )
    .unwrap();
    let w = o.warnings();
    assert!(w.iter().any(|w| w.channel == 2), "{w:?}");
    assert!(w[0].to_string().contains("diffusion length"));
    let o =
        Object::homogeneous(ball(4, 2.0), 1.0, Medium::measured("marble").unwrap(), 1.3).unwrap();
    assert!(o.warnings().is_empty());
}

#[test]
fn manufactured_solution_after_a_cut() {
    // The cut surface (exact or relaxed) is a boundary like any other.
    let whole = manufactured_error(ball(12, 3.0), 0.2, 1.0);
    for method in [
        tet_diffusion::CutMethod::Exact,
        tet_diffusion::CutMethod::Relax { sweeps: 5 },
    ] {
        let mut o = Object::homogeneous(ball(12, 3.0), 1.0, grey(0.2, 1.0), 1.3).unwrap();
        o.cut(
            &tet_diffusion::Cut::Plane {
                point: DVec3::new(0.0, 0.0, 0.7),
                normal: DVec3::new(0.3, 0.0, 1.0),
            },
            method,
        )
        .unwrap();
        let cut = manufactured_error(o.mesh().clone(), 0.2, 1.0);
        eprintln!("manufactured, {method:?}: whole {whole:.2e}, cut {cut:.2e}");
        assert!(cut < 3.0 * whole, "{cut} vs {whole}");
    }
}

#[test]
#[allow(
    clippy::needless_range_loop,
    reason = "RGB loops index several per-channel arrays by one channel index"
)]
fn radiance_lets_out_the_power_that_entered_and_was_not_absorbed() {
    // ∫∫ L cos θ dω dA = ∫ q dA − ∫ μa φ dV, independent of any camera;
    // Eq. 3 as printed (the radiance inside) breaks it by η².
    for (material, eta) in [("marble", 1.3), ("skimmilk", 1.5), ("marble", 1.0)] {
        let mut o =
            Object::homogeneous(ball(6, 10.0), 1.0, Medium::measured(material).unwrap(), eta)
                .unwrap();
        o.add_light(Light::Directional {
            to_light: DVec3::new(0.3, 1.0, 0.2),
            irradiance: [1.0, 0.8, 0.6],
        })
        .unwrap();
        o.settings.tolerance = 1e-10;
        o.solve().unwrap();
        let outside = radiance_balance(&o, |o, d| o.radiance(Some(d)), 4096);
        let inside = radiance_balance(&o, |o, d| o.radiance_inside(Some(d)), 4096);
        for c in 0..3 {
            let (radiated, balance) = outside[c];
            let ratio = radiated / balance;
            eprintln!("{material} η = {eta} channel {c}: radiated / (in − absorbed) = {ratio:.5}");
            assert!(
                (ratio - 1.0).abs() < 0.01,
                "{material} η = {eta} channel {c}: {ratio}"
            );
            let published = inside[c].0 / inside[c].1;
            assert!((published / ratio - eta * eta).abs() < 1e-9 * eta * eta);
        }
    }
}
