//! Real TetGen meshes from `$TRILUX_DATA/tets`.

use crate::common;
use test_support::data as data_dir;

use common::*;
use tet_diffusion::glam::DVec3;
use tet_diffusion::multires::{self, SolveOptions};
use tet_diffusion::{Cut, CutMethod, Integration, Light, Medium, Object, TetMesh};

fn read(name: &str, scale: f64) -> TetMesh {
    let dir = data_dir::data_dir().expect("TRILUX_DATA is set");
    let file = trilux_io::tet::TetMesh::read(dir.join("tets").join(name)).unwrap();
    let p: Vec<DVec3> = file.positions.iter().map(|p| *p * scale).collect();
    TetMesh::new(&p, &file.tets).unwrap()
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn tetgen_spheres_converge_to_the_closed_form() {
    let coarse = read("sphere_20k.node", 10.0);
    let fine = read("sphere_200k.node", 10.0);
    assert_eq!(coarse.reoriented(), 0);
    let h = |m: &TetMesh| m.mean_edge_length();
    let ratio = h(&coarse) / h(&fine);
    let e0 = sphere_error(coarse, 0.01, 1.0, 10.0);
    let e1 = sphere_error(fine, 0.01, 1.0, 10.0);
    let order = (e0 / e1).ln() / ratio.ln();
    eprintln!(
        "TetGen spheres: L2 error {e0:.2e} (20k tets) → {e1:.2e} (200k tets), observed order {order:.2}"
    );
    assert!(order > 1.5, "{order}");
    assert!(e1 < 2e-3, "{e1}");
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn bunny_matches_p1_and_cuts_cleanly() {
    // The bunny is in metres: 1 unit = 1000 mm.
    let mesh = read("bunny_50k.node", 1.0);
    let q = mesh.quality();
    assert!(q.min_dihedral > 0.3 && q.max_dihedral < 180.0);
    let mut o =
        Object::homogeneous(mesh, 1000.0, Medium::measured("skimmilk").unwrap(), 1.3).unwrap();
    o.add_light(Light::Directional {
        to_light: DVec3::new(0.0, 1.0, 0.3),
        irradiance: [1.0; 3],
    })
    .unwrap();
    o.settings.tolerance = 1e-9;
    o.solve().unwrap();
    let a = o.boundary_factor();
    let p1 = o.fem_reference(Integration::ClosedForm);
    let system = p1.consistent(a);
    let mesh = o.mesh();
    let mut qv = vec![0.0; mesh.vertex_count()];
    for (k, &v) in mesh.boundary_vertices().iter().enumerate() {
        qv[v as usize] = o.incident()[k][0];
    }
    let b = p1.load(&qv, a, o.fdr());
    let mut x = vec![0.0; b.len()];
    let r = multires::cg(&system[0], &b, &mut x, &SolveOptions::new(1e-10, 20_000)).unwrap();
    assert!(r.converged());
    let l2 = rel_l2(mesh, o.phi(0), &x);
    eprintln!("bunny_50k: relative L2 difference to P1 {l2:.2e}");
    assert!(l2 < 0.02, "{l2}");
    // An exact plane cut through the middle, re-solved from the carried φ.
    let center = mesh.positions().iter().sum::<DVec3>() / mesh.vertex_count() as f64;
    let report = o
        .cut(
            &Cut::Plane {
                point: center,
                normal: DVec3::new(1.0, 0.0, 0.2),
            },
            CutMethod::Exact,
        )
        .unwrap();
    assert!(report.removed_tets > 10_000);
    o.settings.tolerance = 1e-6;
    o.solve().unwrap();
    assert!(
        o.radiance(None)
            .iter()
            .flatten()
            .all(|l| l.is_finite() && *l >= 0.0)
    );
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn manufactured_solution_on_tetgen_meshes() {
    // φ = exp(d·x/ℓ), ℓ = 10 mm on the 20 mm sphere and 30 mm on the bunny
    // (in mm), μa = 0.01 /mm.
    for (name, scale, l, bound) in [
        ("sphere_20k.node", 20.0, 10.0, 5e-3),
        ("bunny_50k.node", 1000.0, 30.0, 2e-2),
    ] {
        let mesh = read(name, scale);
        let mu = 0.01;
        let kappa = l * l * mu;
        let e = manufactured(mesh, mu, 1.0 / (3.0 * kappa) - mu);
        eprintln!("{name}: manufactured solution, relative L2 error {e:.2e}");
        assert!(e < bound, "{name}: {e}");
    }
}

fn manufactured(mesh: TetMesh, mu_a: f64, sigma_s: f64) -> f64 {
    let d = DVec3::new(1.0, 2.0, -0.5).normalize();
    let kappa = 1.0 / (3.0 * (mu_a + sigma_s));
    let l = (kappa / mu_a).sqrt();
    let fdr = tet_diffusion::fresnel::diffuse_reflectance(1.3);
    let a = tet_diffusion::fresnel::boundary_factor(1.3);
    let center = mesh.positions().iter().sum::<DVec3>() / mesh.vertex_count() as f64;
    let exact: Vec<f64> = mesh
        .positions()
        .iter()
        .map(|x| (d.dot(*x - center) / l).exp())
        .collect();
    let q: Vec<[f64; 3]> = mesh
        .boundary_vertices()
        .iter()
        .map(|&v| {
            let n = mesh.vertex_normals()[v as usize];
            [(1.0 - fdr) / 4.0
                * exact[v as usize]
                * (1.0 + 2.0 * a * (kappa * mu_a).sqrt() * d.dot(n)); 3]
        })
        .collect();
    let mut o = Object::homogeneous(mesh, 1.0, grey(mu_a, sigma_s), 1.3).unwrap();
    o.set_incident(q).unwrap();
    o.settings.tolerance = 1e-10;
    o.solve().unwrap();
    rel_l2(o.mesh(), o.phi(0), &exact)
}

/// Every TetGen mesh of the data with its scale and millimetres per unit:
/// the 10 mm spheres in mm, the bunnies in metres.
const TETGEN_MESHES: [(&str, f64, f64); 4] = [
    ("sphere_20k.node", 10.0, 1.0),
    ("sphere_200k.node", 1.0, 10.0),
    ("bunny_50k.node", 1.0, 1000.0),
    ("bunny_500k.node", 1.0, 1000.0),
];

/// `mesh` of one measured material, lit by one directional light.
fn lit(mesh: &TetMesh, material: &str, unit_mm: f64, eta: f64) -> Object {
    let m = Medium::measured(material).unwrap();
    let mut o = Object::homogeneous(mesh.clone(), unit_mm, m, eta).unwrap();
    o.add_light(Light::Directional {
        to_light: DVec3::new(0.3, 1.0, 0.5),
        irradiance: [1.0; 3],
    })
    .unwrap();
    o
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
#[allow(
    clippy::needless_range_loop,
    reason = "RGB loops index several per-channel arrays by one channel index"
)]
fn radiance_balances_the_power_on_every_tetgen_mesh() {
    // ∫∫ L cos θ dω dA over the boundary and the outgoing hemisphere =
    // power in − ∫ μa φ dV, to 1 %, for two materials and three indices
    // (the 10 mm spheres in mm, the bunnies in metres); Eq. 3 as printed
    // is η² off.
    for (name, scale, unit_mm) in TETGEN_MESHES {
        let mesh = read(name, scale);
        let big = mesh.tets().len() > 300_000;
        for material in ["marble", "skimmilk"] {
            for eta in [1.0, 1.3, 1.5] {
                // The largest mesh once per material (its solves are slow).
                if big && eta != if material == "marble" { 1.3 } else { 1.5 } {
                    continue;
                }
                let mut o = lit(&mesh, material, unit_mm, eta);
                o.settings.tolerance = 1e-9;
                o.solve().unwrap();
                let outside = radiance_balance(&o, |o, d| o.radiance(Some(d)), 1024);
                let inside = radiance_balance(&o, |o, d| o.radiance_inside(Some(d)), 64);
                for c in 0..3 {
                    let ratio = outside[c].0 / outside[c].1;
                    eprintln!("{name} {material} η = {eta} channel {c}: ratio {ratio:.5}");
                    assert!(
                        (ratio - 1.0).abs() < 0.01,
                        "{name} {material} η = {eta}: {ratio}"
                    );
                    if eta > 1.0 {
                        let published = inside[c].0 / inside[c].1;
                        assert!(published > 1.2, "{published}");
                    }
                }
            }
        }
    }
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn exact_plane_cuts_of_bunny_500k_lie_on_the_plane() {
    // Cut vertices on the plane to 1e-9 of the box, the documented angle
    // bound, the analytic clipped volume, the face's normal within 1°.
    let mesh = read("bunny_500k.node", 1.0);
    let centre = mesh.positions().iter().sum::<DVec3>() / mesh.vertex_count() as f64;
    let mut o =
        Object::homogeneous(mesh, 1000.0, Medium::measured("marble").unwrap(), 1.3).unwrap();
    o.set_shadows(false);
    let bound = tet_diffusion::created_angle_bound(o.mesh().quality().min_dihedral);
    for (point, normal) in [
        (centre, DVec3::new(1.0, 0.0, 0.2)),
        (
            centre + DVec3::new(0.0, 0.02, 0.0),
            DVec3::new(0.1, 1.0, -0.3),
        ),
        (centre + DVec3::new(0.0, 0.0, -0.01), DVec3::Z),
    ] {
        let mut cut = o.clone();
        let report = cut
            .cut(&Cut::Plane { point, normal }, CutMethod::Exact)
            .unwrap();
        assert!(report.min_created_dihedral >= bound, "{report:?}");
        let (off, deviation, vertices) = check_exact_plane_cut(o.mesh(), cut.mesh(), point, normal);
        let analytic = clipped_volume(o.mesh(), point, normal);
        let error = (cut.mesh().volume() / analytic - 1.0).abs();
        eprintln!(
            "bunny_500k, normal {normal}: {vertices} cut vertices within {off:.1e} of the box, \
             normals within {deviation:.1e}°, volume {error:.1e} off the analytic; {report:?}"
        );
        assert!(error < 1e-3, "{error}");
    }
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn the_chosen_solver_is_within_one_percent_on_every_tetgen_mesh() {
    // The default solve (Method::Auto, 10⁻⁶) against a reference by
    // V-cycle-PCG to 10⁻¹⁰, marble and skim milk: the choice never costs
    // accuracy.
    for (name, scale, unit_mm) in TETGEN_MESHES {
        let mesh = read(name, scale);
        for material in ["marble", "skimmilk"] {
            let mut o = lit(&mesh, material, unit_mm, 1.3);
            let mut reference = o.clone();
            reference.settings.method = tet_diffusion::Method::VCyclePcg;
            reference.settings.tolerance = 1e-10;
            reference.solve().unwrap();
            let report = o.solve().unwrap();
            eprintln!("{name} {material}: {}", report.choice);
            for c in 0..3 {
                let e = rel_l2(o.mesh(), o.phi(c), reference.phi(c));
                assert!(e < 0.01, "{name} {material} channel {c}: {e:e}");
            }
        }
    }
}
