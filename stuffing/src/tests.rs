//! End-to-end tests of the stuffing pipeline on code-built shapes.

use std::f64::consts::PI;

use glam::DVec3;

use super::*;

mod envelope;

/// A triangle soup: positions and counter-clockwise triangles.
type Soup = (Vec<DVec3>, Vec<[u32; 3]>);
/// Every face of `tets` (4 each) as sorted vertex triples, sorted: a face
/// shared by two tetrahedra appears twice in a row.
pub(crate) fn sorted_faces(tets: &[[u32; 4]]) -> Vec<[u32; 3]> {
    let mut faces: Vec<[u32; 3]> = tets
        .iter()
        .flat_map(|t| {
            [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]].map(|f| {
                let mut face = f.map(|k| t[k]);
                face.sort_unstable();
                face
            })
        })
        .collect();
    faces.sort_unstable();
    faces
}

/// A surface to check boundary vertices against, with a tolerance.
type Reference<'a> = (&'a [DVec3], &'a [[u32; 3]], f64);

/// An outward-oriented UV sphere.
pub(crate) fn sphere(n: u32, radius: f64, centre: DVec3) -> Soup {
    let mut p = vec![centre + DVec3::new(0.0, 0.0, radius)];
    for i in 1..n {
        let th = PI * f64::from(i) / f64::from(n);
        for j in 0..2 * n {
            let ph = PI * f64::from(j) / f64::from(n);
            p.push(
                centre + radius * DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()),
            );
        }
    }
    p.push(centre - DVec3::new(0.0, 0.0, radius));
    let ring = |i: u32, j: u32| 1 + (i - 1) * 2 * n + (j % (2 * n));
    let south = p.len() as u32 - 1;
    let mut t = Vec::new();
    for j in 0..2 * n {
        t.push([0, ring(1, j), ring(1, j + 1)]);
        t.push([south, ring(n - 1, j + 1), ring(n - 1, j)]);
    }
    for i in 1..n - 1 {
        for j in 0..2 * n {
            t.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
            t.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
        }
    }
    (p, t)
}

/// An outward-oriented torus around the z axis.
pub(crate) fn torus(n: u32, m: u32, major: f64, minor: f64) -> Soup {
    let mut p = Vec::new();
    for i in 0..n {
        let u = 2.0 * PI * f64::from(i) / f64::from(n);
        for j in 0..m {
            let v = 2.0 * PI * f64::from(j) / f64::from(m);
            let r = major + minor * v.cos();
            p.push(DVec3::new(r * u.cos(), r * u.sin(), minor * v.sin()));
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..m {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (p, t)
}

/// An outward-oriented axis-aligned box.
pub(crate) fn cuboid(lo: DVec3, hi: DVec3) -> Soup {
    let p: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let t = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    (p, t)
}

fn join(a: (Vec<DVec3>, Vec<[u32; 3]>), b: (Vec<DVec3>, Vec<[u32; 3]>)) -> Soup {
    let (mut p, mut t) = a;
    let off = p.len() as u32;
    p.extend(b.0);
    t.extend(b.1.iter().map(|f| f.map(|v| v + off)));
    (p, t)
}

/// Volume enclosed by a closed, outward-oriented surface.
pub(crate) fn enclosed_volume(p: &[DVec3], t: &[[u32; 3]]) -> f64 {
    t.iter()
        .map(|f| p[f[0] as usize].dot(p[f[1] as usize].cross(p[f[2] as usize])) / 6.0)
        .sum()
}

/// Distance from `q` to the triangle `(a, b, c)` (Ericson, Real-Time
/// Collision Detection, 5.1.5).
pub(crate) fn point_triangle_distance(q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, q - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return q.distance(a);
    }
    let bp = q - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return q.distance(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return q.distance(a + ab * (d1 / (d1 - d3)));
    }
    let cp = q - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return q.distance(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return q.distance(a + ac * (d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return q.distance(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    let denom = 1.0 / (va + vb + vc);
    q.distance(a + ab * (vb * denom) + ac * (vc * denom))
}

/// Everything a valid stuffed mesh must satisfy; `Err` says what failed.
///
/// * every vertex used, no two vertices at the same position;
/// * every tetrahedron positively oriented;
/// * every face in at most two tetrahedra; the boundary an oriented
///   2-manifold without border (each directed edge once, with its twin);
/// * every boundary vertex on the input surface (`surface_tol`), which a
///   non-conforming split of a shared quadrilateral violates: it exposes
///   inside lattice vertices;
/// * every dihedral angle within `bounds`.
pub(crate) fn check_mesh(
    m: &TetMesh,
    surface: Option<Reference<'_>>,
    bounds: (f64, f64),
) -> Result<(), String> {
    let n = m.positions.len();
    let mut used = vec![false; n];
    for t in &m.tets {
        for &v in t {
            used[v as usize] = true;
        }
        let p = t.map(|v| m.positions[v as usize]);
        if signed_volume(p) <= 0.0 {
            return Err(format!("tetrahedron {t:?} is not positively oriented"));
        }
        for a in dihedral_angles(p) {
            let d = a.to_degrees();
            if !(d >= bounds.0 && d <= bounds.1) {
                return Err(format!("dihedral angle {d}° outside {bounds:?} in {t:?}"));
            }
        }
    }
    if let Some(v) = used.iter().position(|u| !u) {
        return Err(format!("vertex {v} is unused"));
    }
    let mut keys: Vec<[u64; 3]> = m
        .positions
        .iter()
        .map(|p| p.to_array().map(f64::to_bits))
        .collect();
    keys.sort_unstable();
    if keys.windows(2).any(|w| w[0] == w[1]) {
        return Err("two vertices share a position".into());
    }
    // Faces in at most two tetrahedra.
    let faces = sorted_faces(&m.tets);
    let mut run = 1;
    for w in faces.windows(2) {
        if w[0] == w[1] {
            run += 1;
            if run > 2 {
                return Err(format!("face {:?} is in more than two tetrahedra", w[0]));
            }
        } else {
            run = 1;
        }
    }
    // Oriented, closed boundary.
    let mut directed: Vec<(u32, u32)> = m
        .boundary
        .iter()
        .flat_map(|f| [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])])
        .collect();
    directed.sort_unstable();
    if directed.windows(2).any(|w| w[0] == w[1]) {
        return Err("a directed boundary edge appears twice (non-manifold or flipped)".into());
    }
    for &(a, b) in &directed {
        if directed.binary_search(&(b, a)).is_err() {
            return Err(format!(
                "boundary edge ({a}, {b}) has no twin: the boundary has a border"
            ));
        }
    }
    if let Some((p, t, tol)) = surface {
        let mut on_boundary: Vec<u32> = m.boundary.iter().flatten().copied().collect();
        on_boundary.sort_unstable();
        on_boundary.dedup();
        for v in on_boundary {
            let q = m.positions[v as usize];
            let d = t
                .iter()
                .map(|f| {
                    point_triangle_distance(q, p[f[0] as usize], p[f[1] as usize], p[f[2] as usize])
                })
                .fold(f64::INFINITY, f64::min);
            if d > tol {
                return Err(format!(
                    "boundary vertex {v} at {q} is {d} from the surface"
                ));
            }
        }
    }
    Ok(())
}

fn mesh_volume(m: &TetMesh) -> f64 {
    m.tets
        .iter()
        .map(|t| signed_volume(t.map(|v| m.positions[v as usize])))
        .sum()
}

fn shapes() -> Vec<(&'static str, Soup, f64)> {
    vec![
        ("sphere", sphere(24, 1.0, DVec3::ZERO), 0.23),
        ("torus", torus(48, 24, 1.0, 0.4), 0.17),
        (
            "thick plate",
            cuboid(DVec3::new(-1.0, -1.0, -0.3), DVec3::new(1.0, 1.0, 0.3)),
            0.21,
        ),
        (
            "thin plate (thinner than h)",
            cuboid(DVec3::new(-1.0, -1.0, -0.06), DVec3::new(1.0, 1.0, 0.09)),
            0.2,
        ),
        (
            "touching spheres",
            join(
                sphere(20, 0.7, DVec3::new(-0.7, 0.0, 0.0)),
                sphere(20, 0.7, DVec3::new(0.7, 0.0, 0.0)),
            ),
            0.19,
        ),
    ]
}

#[test]
fn every_shape_gives_a_valid_mesh_within_the_angle_bounds() {
    for params in [Params::Angles10_7, Params::Angles8_9] {
        for (name, (p, t), h) in shapes() {
            let mut options = Options::new(h);
            options.params = params;
            let m = tetrahedralize(&p, &t, &options).unwrap();
            // Boundary vertices are cut points or warped vertices: on the
            // surface up to rounding, for these closed shapes.
            let result = check_mesh(&m, Some((&p, &t, 1e-9)), params.dihedral_bounds_deg());
            assert!(result.is_ok(), "{name}, {params:?}: {result:?}");
            eprintln!(
                "{name} {params:?}: {} tets, dihedral {:.2}°..{:.2}°",
                m.report.tets, m.report.min_dihedral_deg, m.report.max_dihedral_deg
            );
        }
    }
}

#[test]
fn the_stated_bounds_widen_only_with_the_envelope() {
    let mut options = Options::new(0.1);
    assert_eq!(options.dihedral_bounds_deg(), (9.0, 162.0));
    options.params = Params::Angles8_9;
    assert_eq!(options.dihedral_bounds_deg(), (7.0, 165.0));
    options.params = Params::Angles10_7;
    options.envelope = Some(2e-3);
    assert_eq!(options.dihedral_bounds_deg(), (9.0, 165.0));
}

#[test]
fn a_stencil_table_without_the_parity_rule_fails_the_same_check() {
    let mut failures = 0;
    for (name, (p, t), h) in shapes() {
        let options = Options::new(h);
        let m = run(&p, &t, &options, FaceRule::TetLocal).unwrap();
        let result = check_mesh(
            &m,
            Some((&p, &t, 1e-9)),
            options.params.dihedral_bounds_deg(),
        );
        eprintln!("{name} without the parity rule: {result:?}");
        failures += usize::from(result.is_err());
    }
    assert!(
        failures >= 2,
        "only {failures} shapes caught the wrong stencil"
    );
}

#[test]
fn graded_meshes_are_valid_and_smaller() {
    for (name, (p, t), h) in [
        ("sphere", sphere(32, 1.0, DVec3::ZERO), 0.08),
        ("torus", torus(64, 32, 1.0, 0.5), 0.06),
    ] {
        let mut options = Options::new(h);
        let uniform = tetrahedralize(&p, &t, &options).unwrap();
        let result = check_mesh(
            &uniform,
            Some((&p, &t, 1e-9)),
            options.params.dihedral_bounds_deg(),
        );
        assert!(result.is_ok(), "{name} uniform: {result:?}");
        options.graded = true;
        options.graded_levels = 3;
        let graded = tetrahedralize(&p, &t, &options).unwrap();
        let result = check_mesh(
            &graded,
            Some((&p, &t, 1e-9)),
            options.params.dihedral_bounds_deg(),
        );
        assert!(result.is_ok(), "{name}: {result:?}");
        let (vu, vg) = (mesh_volume(&uniform), mesh_volume(&graded));
        assert!((vu - vg).abs() < 1e-9 * vu, "{name}: volumes {vu} and {vg}");
        eprintln!(
            "{name}: graded {} tets, uniform {} ({:.0}%), graded dihedral {:.2}°..{:.2}°",
            graded.report.tets,
            uniform.report.tets,
            100.0 * graded.report.tets as f64 / uniform.report.tets as f64,
            graded.report.min_dihedral_deg,
            graded.report.max_dihedral_deg
        );
        assert!(graded.report.tets < uniform.report.tets * 3 / 5);
    }
}

#[test]
fn volume_converges_to_the_enclosed_volume() {
    let (p, t) = sphere(64, 1.0, DVec3::ZERO);
    let exact = enclosed_volume(&p, &t);
    let mut last = f64::INFINITY;
    for h in [0.4, 0.2, 0.1] {
        let m = tetrahedralize(&p, &t, &Options::new(h)).unwrap();
        let err = (mesh_volume(&m) - exact).abs() / exact;
        eprintln!("h = {h}: relative volume error {err:.5}");
        assert!(err < last, "error {err} did not shrink from {last}");
        last = err;
    }
    assert!(last < 0.02, "{last}");
}

#[test]
fn boundary_vertices_are_within_h_of_the_surface_also_across_holes() {
    // A sphere with a small cap removed: across the hole the boundary
    // follows the winding number's 1/2 level set, which stays within h of
    // the sphere the hole was cut from.
    let (p, t) = sphere(24, 1.0, DVec3::ZERO);
    let open: Vec<[u32; 3]> = t
        .iter()
        .copied()
        .filter(|f| f.iter().any(|&v| p[v as usize].z < 0.95))
        .collect();
    let h = 0.15;
    let m = tetrahedralize(&p, &open, &Options::new(h)).unwrap();
    let result = check_mesh(
        &m,
        Some((&p, &t, h)),
        Params::Angles10_7.dihedral_bounds_deg(),
    );
    assert!(result.is_ok(), "{result:?}");
}

#[test]
fn the_same_input_gives_the_same_mesh_on_one_and_two_threads() {
    let (p, t) = torus(40, 20, 1.0, 0.45);
    let mut options = Options::new(0.09);
    let run_on = |threads: usize, options: &Options| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| tetrahedralize(&p, &t, options).unwrap())
    };
    for (graded, envelope) in [
        (false, None),
        (true, None),
        (false, Some(1e-3)),
        (true, Some(1e-3)),
    ] {
        options.graded = graded;
        options.envelope = envelope;
        let a = run_on(1, &options);
        let b = run_on(2, &options);
        assert_eq!(a.tets, b.tets);
        assert_eq!(a.boundary, b.boundary);
        assert_eq!(a.report.distance, b.report.distance);
        assert!(
            a.positions
                .iter()
                .zip(&b.positions)
                .all(|(x, y)| x.to_array().map(f64::to_bits) == y.to_array().map(f64::to_bits))
        );
    }
}

#[test]
fn flipped_patches_and_overlapping_parts_still_have_an_interior() {
    // Two overlapping spheres (their union is the interior) with a band of
    // triangles of one of them flipped.
    let (p, mut t) = join(
        sphere(20, 1.0, DVec3::ZERO),
        sphere(20, 1.0, DVec3::new(0.8, 0.0, 0.0)),
    );
    for f in t.iter_mut().step_by(17) {
        f.swap(1, 2);
    }
    let m = tetrahedralize(&p, &t, &Options::new(0.15)).unwrap();
    assert!(check_mesh(&m, None, Params::Angles10_7.dihedral_bounds_deg()).is_ok());
    let v = mesh_volume(&m);
    // The union of two unit balls 0.8 apart: 2 * (4/3)π - lens.
    let d: f64 = 0.8;
    let lens = PI * (4.0 + d) * (2.0 - d).powi(2) / 12.0;
    let union = 2.0 * 4.0 / 3.0 * PI - lens;
    assert!((v - union).abs() / union < 0.08, "{v} vs {union}");
}

#[test]
fn bad_input_is_refused_with_the_reason() {
    let (p, t) = sphere(8, 1.0, DVec3::ZERO);
    assert_eq!(
        tetrahedralize(&p, &t, &Options::new(0.0)).unwrap_err(),
        Error::InvalidSpacing { h: 0.0 }
    );
    assert!(matches!(
        tetrahedralize(&p, &t, &Options::new(f64::NAN)),
        Err(Error::InvalidSpacing { .. })
    ));
    assert!(matches!(
        tetrahedralize(&p, &t, &Options::new(-1.0)),
        Err(Error::InvalidSpacing { .. })
    ));
    let mut nan = p.clone();
    nan[3].y = f64::NAN;
    assert_eq!(
        tetrahedralize(&nan, &t, &Options::new(0.3)).unwrap_err(),
        Error::NonFinitePosition { vertex: 3 }
    );
    let mut bad = t.clone();
    bad[5][1] = 10_000;
    assert!(matches!(
        tetrahedralize(&p, &bad, &Options::new(0.3)),
        Err(Error::IndexOutOfRange {
            triangle: 5,
            index: 10_000,
            ..
        })
    ));
    assert_eq!(
        tetrahedralize::<DVec3>(&p, &[], &Options::new(0.3)).unwrap_err(),
        Error::NoTriangles
    );
    // A single triangle encloses nothing at any spacing, and says so
    // without asking for a smaller one; a slab thinner than the lattice
    // does ask.
    let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
    let e = tetrahedralize(&tri, &[[0, 1, 2]], &Options::new(0.1)).unwrap_err();
    assert_eq!(e, Error::OpenSurface { triangles: 1 });
    assert!(e.to_string().contains("no spacing changes that"), "{e}");
    let (slab, slab_t) = cuboid(DVec3::ZERO, DVec3::new(1.0, 1.0, 0.01));
    assert!(matches!(
        tetrahedralize(&slab, &slab_t, &Options::new(0.3)),
        Err(Error::EmptyVolume { .. })
    ));
    // A lattice beyond the memory bound is refused before allocation, and
    // an absurd spacing says so without a 39-digit count.
    assert!(matches!(
        tetrahedralize(&p, &t, &Options::new(1e-6)),
        Err(Error::LatticeTooLarge { .. })
    ));
    let absurd = tetrahedralize(&p, &t, &Options::new(1e-300)).unwrap_err();
    assert!(absurd.to_string().contains("more than 10^36"), "{absurd}");
    // So is an output beyond the tetrahedron bound, once the inside is
    // known: this shape has far more than 1000 tetrahedra at h = 0.1.
    let mut small = Options::new(0.1);
    small.max_tets = 1000;
    let err = tetrahedralize(&p, &t, &small).unwrap_err();
    assert!(
        matches!(err, Error::TooManyTetrahedra { estimated, limit: 1000, .. } if estimated > 1000),
        "{err:?}"
    );
    small.max_tets = 1 << 24;
    assert!(tetrahedralize(&p, &t, &small).is_ok());
    let mut opts = Options::new(0.3);
    opts.winding_beta = 0.5;
    assert!(matches!(
        tetrahedralize(&p, &t, &opts),
        Err(Error::InvalidBeta { .. })
    ));
    opts = Options::new(0.3);
    opts.graded = true;
    opts.graded_levels = 0;
    assert!(matches!(
        tetrahedralize(&p, &t, &opts),
        Err(Error::InvalidGrading { .. })
    ));
    // Every message names the problem.
    let msg = Error::IndexOutOfRange {
        triangle: 5,
        index: 9,
        vertices: 3,
    }
    .to_string();
    assert!(msg.contains("triangle 5") && msg.contains("vertex 9"));
}

#[test]
fn the_distance_between_concentric_spheres_is_the_difference_of_their_radii() {
    let (p, t) = sphere(48, 1.0, DVec3::ZERO);
    let (q, u) = sphere(48, 1.1, DVec3::ZERO);
    let wn = winding::WindingNumber::new(&p, &t, winding::DEFAULT_BETA).unwrap();
    let d = distance::measure(&wn, &distance::bounding_triangles(&wn), &q, &u, 20_000);
    // Each facet of the 48-ring spheres sags at most r (1 - cos(pi/48))
    // (0.0024 at r = 1.1) below the round sphere.
    for x in [d.hausdorff, d.input_to_tets, d.tets_to_input, d.mean] {
        assert!((x - 0.1).abs() < 0.005, "{d:?}");
    }
    assert!((d.diagonal - 2.0 * 3f64.sqrt()).abs() < 1e-9, "{d:?}");
    assert_eq!(d.left_out_triangles, 0);
    // Samples plus every vertex (fewer than the samples).
    assert_eq!(d.input_samples, 20_000 + p.len());
    assert_eq!(d.boundary_samples, 20_000 + q.len());
}

#[test]
fn an_open_sheet_is_left_out_and_counted_not_measured() {
    // A unit sphere and, far from it, a square sheet of side 2: it
    // encloses no volume, so its distance to the boundary (about 5) must
    // not count, and its area share is reported.
    let sheet: Soup = (
        vec![
            DVec3::new(5.0, -1.0, -1.0),
            DVec3::new(5.0, 1.0, -1.0),
            DVec3::new(5.0, 1.0, 1.0),
            DVec3::new(5.0, -1.0, 1.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    );
    let (p, t) = join(sphere(32, 1.0, DVec3::ZERO), sheet);
    let m = tetrahedralize(&p, &t, &Options::new(0.15)).unwrap();
    let d = m.report.distance.unwrap();
    assert_eq!(d.left_out_triangles, 2, "{d:?}");
    let sphere_area: f64 = t[..t.len() - 2]
        .iter()
        .map(|f| {
            0.5 * (p[f[1] as usize] - p[f[0] as usize])
                .cross(p[f[2] as usize] - p[f[0] as usize])
                .length()
        })
        .sum();
    assert!(
        (d.left_out_area - 4.0 / (4.0 + sphere_area)).abs() < 1e-9,
        "{d:?}"
    );
    assert!(d.input_to_tets < 0.15, "{d:?}");
    // The boundary is measured against every input triangle.
    assert!(d.tets_to_input < 0.15, "{d:?}");
}

#[test]
fn a_stuffed_sphere_reports_its_distance_within_the_lattice_spacing() {
    let (p, t) = sphere(48, 1.0, DVec3::ZERO);
    let h = 0.15;
    let m = tetrahedralize(&p, &t, &Options::new(h)).unwrap();
    let d = m.report.distance.clone().unwrap();
    assert!(
        d.hausdorff < h && d.mean < d.hausdorff && d.mean > 0.0,
        "{d:?}"
    );
    assert!((d.hausdorff_fraction() - d.hausdorff / d.diagonal).abs() < 1e-15);
    // Measured again, the same figures to the bit.
    let again = surface_distance(&p, &t, &m.positions, &m.boundary, 1 << 16).unwrap();
    assert_eq!(&again, &d);
    // A bad second surface is named as such.
    let e = surface_distance(&p, &t, &m.positions, &[[0, 1, u32::MAX]], 10).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("the boundary surface: triangle 0"),
        "{e}"
    );
    let e = surface_distance(&p, &t, &[DVec3::NAN; 3], &[[0, 1, 2]], 10).unwrap_err();
    assert!(e.to_string().contains("vertex 0 has a NaN"), "{e}");
    let e = surface_distance(&p, &[], &m.positions, &m.boundary, 10).unwrap_err();
    assert_eq!(e, Error::NoTriangles);
    let mut options = Options::new(h);
    options.distance_samples = 0;
    assert!(
        tetrahedralize(&p, &t, &options)
            .unwrap()
            .report
            .distance
            .is_none()
    );
}

/// A sphere with a hole around its north pole (the triangles above
/// z = 0.8 removed, a hole of radius 0.6): the boundary caps the hole on
/// the ½ level set, and those cap points are counted apart instead of
/// setting `tets_to_input` to about the hole's radius; the closed sphere
/// has no cap points. (Item 2 of issue #48.)
#[test]
fn a_boundary_capping_a_hole_is_reported_apart_from_the_distance() {
    let (p, t) = sphere(32, 1.0, DVec3::ZERO);
    let h = 0.08;
    let closed = tetrahedralize(&p, &t, &Options::new(h)).unwrap();
    let d = closed.report.distance.unwrap();
    assert_eq!(d.hole_caps, 0.0, "{d:?}");
    assert_eq!(d.hole_caps_to_input, 0.0, "{d:?}");
    let open: Vec<[u32; 3]> = t
        .iter()
        .copied()
        .filter(|f| f.iter().any(|&v| p[v as usize].z < 0.8))
        .collect();
    let holed = tetrahedralize(&p, &open, &Options::new(h)).unwrap();
    let d = holed.report.distance.unwrap();
    // The cap is a few percent of the boundary, and its farthest point is
    // most of the hole's radius away from the input.
    assert!(d.hole_caps > 0.01 && d.hole_caps < 0.15, "{d:?}");
    assert!(d.hole_caps_to_input > 0.3, "{d:?}");
    // Without the cap, the boundary is as near the input as the closed
    // sphere's, within the lattice spacing.
    assert!(d.tets_to_input < 0.5 * h, "{d:?}");
    assert!(d.hausdorff < 0.5 * h, "{d:?}");
}
