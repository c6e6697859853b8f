//! Lights, shadows, the environment map and outgoing radiance.

use crate::common;

use std::sync::Arc;

use common::*;
use tet_diffusion::glam::DVec3;
use tet_diffusion::{Environment, Light, Object, TetMesh, fresnel};

/// A cube of side 2 and one of side 1 behind it along X: the second is in
/// the first one's shadow for light from −X.
fn two_cubes() -> TetMesh {
    let (p, t) = cube(2);
    let mut positions: Vec<DVec3> = p.clone();
    positions.extend(p.iter().map(|x| *x * 0.5 + DVec3::new(3.0, 0.0, 0.0)));
    let off = p.len() as u32;
    let mut tets = t.clone();
    tets.extend(t.iter().map(|tet| tet.map(|v| v + off)));
    TetMesh::new(&positions, &tets).unwrap()
}

#[test]
fn directional_light_and_shadows() {
    let mesh = two_cubes();
    let light = Light::Directional {
        to_light: DVec3::NEG_X,
        irradiance: [2.0, 1.0, 0.5],
    };
    let mut o = Object::homogeneous(mesh, 1.0, grey(0.1, 1.0), 1.3).unwrap();
    o.add_light(light).unwrap();
    let m = o.mesh().clone();
    // The centre vertex of each cube's −X face.
    let face_centre = |x: f64| {
        m.boundary_vertices()
            .iter()
            .position(|&v| m.positions()[v as usize].distance(DVec3::new(x, 0.0, 0.0)) < 1e-9)
            .unwrap()
    };
    let (lit, shadowed) = (face_centre(-1.0), face_centre(2.5));
    let ft = fresnel::transmittance(1.0, 1.3);
    assert!((o.incident()[lit][0] - 2.0 * ft).abs() < 1e-12);
    assert!((o.incident()[lit][2] - 0.5 * ft).abs() < 1e-12);
    assert_eq!(o.incident()[shadowed], [0.0; 3]);
    // Back faces get nothing.
    let back = m
        .boundary_vertices()
        .iter()
        .position(|&v| m.positions()[v as usize].distance(DVec3::new(1.0, 0.0, 0.0)) < 1e-9)
        .unwrap();
    assert_eq!(o.incident()[back], [0.0; 3]);
    // Without shadows the second cube is lit like the first.
    o.set_shadows(false);
    assert!((o.incident()[shadowed][0] - 2.0 * ft).abs() < 1e-12);
    o.set_shadows(true);
    // A colour change keeps the cached visibility.
    o.set_light_color(0, [4.0, 2.0, 1.0]).unwrap();
    assert!((o.incident()[lit][0] - 4.0 * ft).abs() < 1e-12);
    assert_eq!(o.incident()[shadowed], [0.0; 3]);
    o.solve().unwrap();
    let vertex = |k: usize| m.boundary_vertices()[k] as usize;
    assert!(o.phi(0)[vertex(lit)] > 10.0 * o.phi(0)[vertex(shadowed)]);
    // Eq. 3 where q = 0: L = F_t / 4π · (1 + 1/A) φ just inside, and that
    // over η² in air.
    let inside = o.radiance_inside(None);
    let expected = ft / (4.0 * std::f64::consts::PI)
        * (1.0 + 1.0 / o.boundary_factor())
        * o.phi(1)[vertex(back)];
    assert!((inside[back][1] - expected).abs() < 1e-12 * expected);
    let l = o.radiance(None);
    let in_air = expected / (o.eta() * o.eta());
    assert!((l[back][1] - in_air).abs() < 1e-12 * in_air);
    assert!(l.iter().flatten().all(|x| x.is_finite() && *x >= 0.0));
    // Seen at grazing angles, less light leaves.
    let grazing = o.radiance(Some(DVec3::new(1.0, 0.0, 0.1)));
    assert!(grazing[back][1] < l[back][1]);
}

#[test]
fn point_light_falls_off_with_the_square_of_the_distance_in_mm() {
    let ball_mesh = ball(4, 1.0);
    let top = ball_mesh
        .boundary_vertices()
        .iter()
        .position(|&v| ball_mesh.positions()[v as usize].distance(DVec3::Z) < 1e-9)
        .unwrap();
    let q_at = |height: f64, unit: f64| {
        let mut o = Object::homogeneous(ball_mesh.clone(), unit, grey(0.1, 1.0), 1.3).unwrap();
        o.add_light(Light::Point {
            position: DVec3::new(0.0, 0.0, height),
            intensity: [1.0; 3],
        })
        .unwrap();
        o.incident()[top][0]
    };
    // The light is on the vertex's axis, so cos θ and F_t are the same.
    let (near, far, tenfold) = (q_at(3.0, 1.0), q_at(5.0, 1.0), q_at(3.0, 10.0));
    assert!(near > 0.2 && near < 0.25, "{near}");
    assert!((near / far - 4.0).abs() < 1e-12);
    assert!((near / tenfold - 100.0).abs() < 1e-9);
}

#[test]
fn uniform_environment_gives_uniform_light() {
    // A white sky of radiance 1: q = 2π ∫ cos θ F_t(θ) sin θ dθ everywhere on
    // a convex object (no shadows on a ball).
    let (w, h) = (32, 16);
    let env = Arc::new(Environment::new(&vec![[1.0; 3]; w * h], w, h, 2048).unwrap());
    let mut o = Object::homogeneous(ball(4, 1.0), 1.0, grey(0.1, 1.0), 1.3).unwrap();
    o.add_light(Light::Environment(env)).unwrap();
    let steps = 100_000;
    let exact: f64 = (0..steps)
        .map(|k| {
            let t = (k as f64 + 0.5) / steps as f64 * std::f64::consts::FRAC_PI_2;
            t.cos() * fresnel::transmittance(t.cos(), 1.3) * t.sin()
        })
        .sum::<f64>()
        * std::f64::consts::FRAC_PI_2
        / steps as f64
        * 2.0
        * std::f64::consts::PI;
    let q = o.incident();
    let mean = q.iter().map(|v| v[0]).sum::<f64>() / q.len() as f64;
    assert!((mean - exact).abs() < 0.02 * exact, "{mean} vs {exact}");
    for v in q {
        assert!((v[0] - exact).abs() < 0.1 * exact, "{} vs {exact}", v[0]);
    }
    // A bright sun in one direction: the side facing it gets more.
    let mut sky = vec![[0.01f32; 3]; w * h];
    sky[2 * w + 5] = [1000.0; 3]; // near the +Z pole
    let env = Arc::new(Environment::new(&sky, w, h, 256).unwrap());
    let mut o = Object::homogeneous(ball(4, 1.0), 1.0, grey(0.1, 1.0), 1.3).unwrap();
    o.add_light(Light::Environment(env)).unwrap();
    let m = o.mesh();
    let at = |p: DVec3| {
        let k = m
            .boundary_vertices()
            .iter()
            .position(|&v| m.positions()[v as usize].distance(p) < 1e-9)
            .unwrap();
        o.incident()[k][0]
    };
    assert!(at(DVec3::Z) > 10.0 * at(DVec3::NEG_Z));
}
