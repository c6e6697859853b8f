//! Meshes built in code and the closed form of the homogeneous sphere.
#![allow(dead_code, reason = "each test binary uses a part of the helpers")]

use tet_diffusion::glam::DVec3;
use tet_diffusion::{Medium, Object, TetMesh};

/// An `n³` lattice of `[-1, 1]³`, each cube split into six tets around its
/// main diagonal.
pub(crate) fn cube(n: usize) -> (Vec<DVec3>, Vec<[u32; 4]>) {
    tet_diffusion::kuhn_lattice(n, -DVec3::ONE, DVec3::ONE)
}

/// A ball of radius `r`: the cube lattice mapped radially,
/// `x ← r x ‖x‖∞ / ‖x‖₂`, so that the boundary vertices lie on the sphere.
pub(crate) fn ball(n: usize, r: f64) -> TetMesh {
    let (p, t) = tet_diffusion::kuhn_ball(n, r);
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

/// `n` unit directions spread evenly over the sphere (a Fibonacci
/// lattice), each standing for `4π/n` steradians.
pub(crate) fn sphere_directions(n: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let a = golden * i as f64;
            DVec3::new(r * a.cos(), r * a.sin(), z)
        })
        .collect()
}

/// The energy balance of the radiance, per channel, in W: the radiance
/// of [`Object::radiance`] integrated over the boundary (each vertex's
/// share `S_i/3`) and every direction it is seen from
/// (`∫∫ L cos θ dω dA`, by `directions` points over the sphere, the
/// outgoing hemisphere of each vertex being where `cos θ > 0`), and the
/// power that entered (`∫ q dA`) minus the power absorbed (`∫ μa φ dV`,
/// lumped as the solver lumps it). Lengths in mm.
#[allow(
    clippy::needless_range_loop,
    reason = "RGB loops index several per-channel arrays by one channel index"
)]
pub(crate) fn radiance_balance(
    o: &Object,
    radiance: impl Fn(&Object, DVec3) -> Vec<[f64; 3]>,
    directions: usize,
) -> [(f64, f64); 3] {
    let mesh = o.mesh();
    let unit = o.length_unit_mm();
    let share: Vec<f64> = mesh
        .boundary_vertices()
        .iter()
        .map(|&v| mesh.vertex_areas()[v as usize] / 3.0 * unit * unit)
        .collect();
    let mut radiated = [0.0; 3];
    let dirs = sphere_directions(directions);
    let solid_angle = 4.0 * std::f64::consts::PI / directions as f64;
    for &d in &dirs {
        let l = radiance(o, d);
        for (k, &v) in mesh.boundary_vertices().iter().enumerate() {
            let cos = mesh.vertex_normals()[v as usize].dot(d);
            if cos > 0.0 {
                for c in 0..3 {
                    radiated[c] += l[k][c] * cos * share[k] * solid_angle;
                }
            }
        }
    }
    std::array::from_fn(|c| {
        let entered: f64 = o.incident().iter().zip(&share).map(|(q, s)| q[c] * s).sum();
        let absorbed: f64 = mesh
            .tets()
            .iter()
            .enumerate()
            .map(|(t, tet)| {
                let mean = tet.iter().map(|&v| o.phi(c)[v as usize]).sum::<f64>() / 4.0;
                mesh.tet_volume(t) * unit.powi(3) * o.medium(t).unwrap().sigma_a[c] * mean
            })
            .sum();
        (radiated[c], entered - absorbed)
    })
}

/// The volume of `mesh` on the side `(x − point) · normal ≤ 0`, computed
/// independently of any cut: each tet's faces are clipped by the plane
/// (Sutherland–Hodgman) and the clipped polygons coned from a point of the
/// plane, whose cone over the cap face is flat (divergence theorem).
pub(crate) fn clipped_volume(mesh: &TetMesh, point: DVec3, normal: DVec3) -> f64 {
    let n = normal.normalize();
    let d = |x: DVec3| (x - point).dot(n);
    let faces = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
    let mut total = 0.0;
    for t in 0..mesh.tets().len() {
        let c = mesh.corners(t);
        for f in faces {
            let poly: Vec<DVec3> = f.iter().map(|&k| c[k]).collect();
            let mut clipped = Vec::new();
            for i in 0..poly.len() {
                let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
                let (da, db) = (d(a), d(b));
                if da <= 0.0 {
                    clipped.push(a);
                }
                if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
                    clipped.push(a + (b - a) * (da / (da - db)));
                }
            }
            for k in 1..clipped.len().saturating_sub(1) {
                let (a, b, e) = (
                    clipped[0] - point,
                    clipped[k] - point,
                    clipped[k + 1] - point,
                );
                total += a.dot(b.cross(e)) / 6.0;
            }
        }
    }
    total
}

/// Checks an exact cut by the plane (`point`, `normal`, removing the side
/// the normal points to) of `before` into `after`: every boundary vertex
/// the cut made (not an old boundary vertex where it was) lies on the plane
/// to `1e-9` of the bounding box; every tet has a dihedral angle of at
/// least `created_angle_bound(before's smallest)` (each tet the cut
/// made is above its parent's bound, which is at least that); the cut face's normal is within
/// 1° of the plane's at every vertex of it; the mesh is the one built from
/// scratch from its positions and tets. Returns (the largest distance
/// of a cut vertex from the plane relative to the box, the largest normal
/// deviation in degrees, the number of cut vertices).
pub(crate) fn check_exact_plane_cut(
    before: &TetMesh,
    after: &TetMesh,
    point: DVec3,
    normal: DVec3,
) -> (f64, f64, usize) {
    // The cut mesh, derived from `before` around the split, is the mesh
    // built from scratch from its positions and tets.
    let scratch = TetMesh::new(after.positions(), after.tets()).unwrap();
    assert_eq!(scratch.reoriented(), 0);
    assert_eq!(after.tet_neighbors(), scratch.tet_neighbors());
    assert_eq!(after.boundary(), scratch.boundary());
    assert_eq!(after.boundary_vertices(), scratch.boundary_vertices());
    assert_eq!(after.vertex_areas(), scratch.vertex_areas());
    assert_eq!(after.vertex_normals(), scratch.vertex_normals());
    for v in 0..after.vertex_count() {
        assert_eq!(after.one_ring(v), scratch.one_ring(v));
        assert_eq!(after.vertex_tets(v), scratch.vertex_tets(v));
    }
    let n = normal.normalize();
    let (lo, hi) = before
        .positions()
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &p| {
            (a.min(p), b.max(p))
        });
    let size = (hi - lo).length();
    let old_surface: std::collections::HashSet<[u64; 3]> = before
        .boundary_vertices()
        .iter()
        .map(|&v| before.positions()[v as usize].to_array().map(f64::to_bits))
        .collect();
    let on_plane = |x: DVec3| (x - point).dot(n).abs() <= 1e-9 * size;
    let mut farthest = 0.0f64;
    let mut cut_vertices = vec![false; after.vertex_count()];
    for &v in after.boundary_vertices() {
        let x = after.positions()[v as usize];
        if !old_surface.contains(&x.to_array().map(f64::to_bits)) {
            let dist = (x - point).dot(n).abs() / size;
            farthest = farthest.max(dist);
            assert!(
                dist <= 1e-9,
                "boundary vertex {v} at {x} is {dist:e} of the box off the plane"
            );
            cut_vertices[v as usize] = true;
        }
    }
    // Angles.
    let min_of = |m: &TetMesh| {
        (0..m.tets().len())
            .map(|t| {
                m.dihedral_angles(t)
                    .into_iter()
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(f64::INFINITY, f64::min)
            .to_degrees()
    };
    let (was, now) = (min_of(before), min_of(after));
    let bound = tet_diffusion::created_angle_bound(was);
    assert!(
        now >= bound - 1e-9,
        "smallest dihedral {now}° (before {was}°, bound {bound}°)"
    );
    // The cut face: boundary faces with every vertex on the plane.
    let mut face_normal = vec![DVec3::ZERO; after.vertex_count()];
    for f in after.boundary() {
        let p = f.map(|v| after.positions()[v as usize]);
        if p.iter().all(|&x| on_plane(x)) {
            let cross = (p[1] - p[0]).cross(p[2] - p[0]);
            for &v in f {
                face_normal[v as usize] += cross;
            }
        }
    }
    let mut worst = 0.0f64;
    let mut count = 0;
    for (v, &is_cut) in cut_vertices.iter().enumerate() {
        if is_cut {
            let m = face_normal[v];
            assert!(m.length() > 0.0, "cut vertex {v} has no face on the plane");
            let angle = m.normalize().dot(n).clamp(-1.0, 1.0).acos().to_degrees();
            worst = worst.max(angle);
            count += 1;
        }
    }
    assert!(worst < 1.0, "the cut face's normal deviates by {worst}°");
    (farthest, worst, count)
}

/// `f` run on a pool of `threads` threads (the determinism tests).
pub(crate) fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}
