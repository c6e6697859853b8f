//! Real TetGen meshes from `$TRILUX_DATA/tets`.

mod common;

use std::path::PathBuf;

use common::*;
use tet_diffusion::glam::DVec3;
use tet_diffusion::multires::{self, SolveOptions};
use tet_diffusion::{Cut, Integration, Light, Medium, Object, TetMesh};

fn read(name: &str, scale: f64) -> TetMesh {
    let dir = PathBuf::from(std::env::var_os("TRILUX_DATA").expect("TRILUX_DATA is set"));
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
    let r = multires::cg(
        &system[0],
        &b,
        &mut x,
        &SolveOptions {
            tolerance: 1e-10,
            max_iterations: 20_000,
        },
    )
    .unwrap();
    assert!(r.converged());
    let l2 = rel_l2(mesh, o.phi(0), &x);
    eprintln!("bunny_50k: relative L2 difference to P1 {l2:.2e}");
    assert!(l2 < 0.02, "{l2}");
    // A plane cut through the middle, relaxed, re-solved from the carried φ.
    let center = mesh.positions().iter().sum::<DVec3>() / mesh.vertex_count() as f64;
    let report = o
        .cut(
            &Cut::Plane {
                point: center,
                normal: DVec3::new(1.0, 0.0, 0.2),
            },
            5,
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
