//! Filtering: exact continuity across edges of mixed resolution for every
//! filter, affine reproduction, MIP means, and Eq. 5 / Eq. 6 by hand.

use crate::support;

use glam::Vec3;
use mesh_colors::{MeshColors, MipMap, Topology};
use support::Rng;

/// A bumpy grid with levels 0..=4 spread over the faces and random RGB.
fn mixed(seed: u64) -> (Vec<Vec3>, Vec<[u32; 3]>, MeshColors) {
    let (positions, faces) = support::grid(6, 0.4);
    let mut rng = Rng(seed);
    let levels: Vec<u32> = (0..faces.len()).map(|_| 1 << rng.below(5)).collect();
    let topology = Topology::new(positions.len(), &faces).unwrap();
    let mut mc = MeshColors::new(topology, &levels, 3).unwrap();
    for x in mc.samples_mut() {
        *x = rng.f32();
    }
    (positions, faces, mc)
}

/// For every interior edge and many parameters `t`, the barycentrics of
/// the point from each of its two faces.
pub(crate) fn edge_points(
    mc: &MeshColors,
    rng: &mut Rng,
) -> Vec<(usize, [f32; 3], usize, [f32; 3])> {
    let t = mc.topology();
    let mut out = Vec::new();
    for (e, fs) in t.edge_faces().iter().enumerate() {
        if fs[1] == mesh_colors::NO_FACE {
            continue;
        }
        let [a, b] = t.edges()[e];
        let mut params: Vec<f32> = (0..=64).map(|i| i as f32 / 64.0).collect();
        params.extend((0..64).map(|_| rng.f32()));
        for s in params {
            let bary = |f: usize| {
                let face = t.faces()[f];
                face.map(|v| {
                    if v == a {
                        1.0 - s
                    } else if v == b {
                        s
                    } else {
                        0.0
                    }
                })
            };
            let (f0, f1) = (fs[0] as usize, fs[1] as usize);
            out.push((f0, bary(f0), f1, bary(f1)));
        }
    }
    out
}

#[test]
fn linear_nearest_and_mip_are_identical_on_edges_from_both_faces() {
    let mut rng = Rng(11);
    for seed in 0..4 {
        let (_, _, mc) = mixed(seed);
        let mip = mc.mip_map();
        let points = edge_points(&mc, &mut rng);
        let (mut a, mut b) = ([0.0f32; 3], [0.0f32; 3]);
        let mut checked = 0;
        let mut mixed_edges = 0;
        for &(f0, b0, f1, b1) in &points {
            if mc.face_level(f0).unwrap() != mc.face_level(f1).unwrap() {
                mixed_edges += 1;
            }
            mc.linear(f0, b0, &mut a).unwrap();
            mc.linear(f1, b1, &mut b).unwrap();
            assert_eq!(a, b, "linear, faces {f0}/{f1} at {b0:?}");
            mc.nearest(f0, b0, &mut a).unwrap();
            mc.nearest(f1, b1, &mut b).unwrap();
            assert_eq!(a, b, "nearest, faces {f0}/{f1}");
            for level in 0..=5 {
                mip.at_level(f0, b0, level, &mut a).unwrap();
                mip.at_level(f1, b1, level, &mut b).unwrap();
                assert_eq!(a, b, "MIP level {level}, faces {f0}/{f1}");
            }
            for footprint in [1.0, 0.7, 0.3, 0.2, 0.09, 0.04, 0.011] {
                mip.trilinear(f0, b0, footprint, &mut a).unwrap();
                mip.trilinear(f1, b1, footprint, &mut b).unwrap();
                assert_eq!(a, b, "trilinear {footprint}, faces {f0}/{f1}");
            }
            checked += 1;
        }
        assert!(
            checked > 1000 && mixed_edges > 500,
            "{checked} points, {mixed_edges} on mixed edges"
        );
    }
}

#[test]
fn values_near_an_edge_converge_to_the_edge_value_from_both_sides() {
    // Exact equality on the edge is by construction; this checks there is
    // no jump just off it (a finer face must interpolate the coarse edge).
    let (_, _, mc) = mixed(3);
    let mip = mc.mip_map();
    let mut rng = Rng(5);
    let (mut on, mut off) = ([0.0f32; 3], [0.0f32; 3]);
    let mut worst = 0.0f32;
    for (f0, b0, f1, b1) in edge_points(&mc, &mut rng) {
        for (f, b) in [(f0, b0), (f1, b1)] {
            let m = (0..3).find(|&k| b[k] == 0.0).unwrap();
            let mut inside = b.map(|x| x * (1.0 - 1e-4));
            inside[m] = 1e-4;
            mc.linear(f, b, &mut on).unwrap();
            mc.linear(f, inside, &mut off).unwrap();
            worst = worst.max((0..3).map(|c| (on[c] - off[c]).abs()).fold(0.0, f32::max));
            for level in 0..4 {
                mip.at_level(f, b, level, &mut on).unwrap();
                mip.at_level(f, inside, level, &mut off).unwrap();
                worst = worst.max((0..3).map(|c| (on[c] - off[c]).abs()).fold(0.0, f32::max));
            }
        }
    }
    // Samples are in [0, 1] and at most 16 per edge: a jump would be O(0.1).
    assert!(worst < 0.01, "largest jump next to an edge: {worst}");
}

#[test]
fn linear_filter_reproduces_affine_functions_of_position() {
    let (positions, faces, mut mc) = mixed(7);
    let affine = |p: Vec3| {
        [
            0.3 + 2.0 * p.x - p.y + 0.5 * p.z,
            -1.0 + 0.25 * p.y + 3.0 * p.z,
            7.0 * p.x,
        ]
    };
    mc.fill(&positions, |p, out| {
        let v = affine(p.as_vec3());
        out.copy_from_slice(&v);
    })
    .unwrap();
    let mut rng = Rng(9);
    let mut got = [0.0f32; 3];
    let mut worst = 0.0f32;
    for _ in 0..100_000 {
        let f = rng.below(faces.len() as u64) as usize;
        let b = rng.barycentric();
        mc.linear(f, b, &mut got).unwrap();
        let want = affine(support::point(&positions, faces[f], b));
        for c in 0..3 {
            worst = worst.max((got[c] - want[c]).abs());
        }
    }
    assert!(worst < 2e-5, "affine error {worst}");
    // A quadratic is not reproduced: the test can fail.
    mc.fill(&positions, |p, out| out.fill((p.x * p.x * 9.0) as f32))
        .unwrap();
    let mut worst_q = 0.0f32;
    for _ in 0..10_000 {
        let f = rng.below(faces.len() as u64) as usize;
        let b = rng.barycentric();
        mc.linear(f, b, &mut got).unwrap();
        let p = support::point(&positions, faces[f], b);
        worst_q = worst_q.max((got[0] - 9.0 * p.x * p.x).abs());
    }
    assert!(worst_q > 1e-3);
}

/// Every sample of every MIP level, with its barycentrics in one face.
fn mip_levels_equal(
    mip: &MipMap,
    faces: &[[u32; 3]],
    keep: impl Fn(usize, [f32; 3]) -> bool,
    want: impl Fn(usize, [f32; 3]) -> f32,
) -> f32 {
    let mc = mip.colors();
    let mut worst = 0.0f32;
    let mut out = [0.0f32];
    for f in 0..faces.len() {
        for level in 0..=mc.face_level(f).unwrap() {
            let r = 1u32 << level;
            for a in mesh_colors::lattice_points(r) {
                let b = a.map(|x| x as f32 / r as f32);
                if !keep(f, b) {
                    continue;
                }
                mip.at_level(f, b, level, &mut out).unwrap();
                worst = worst.max((out[0] - want(f, b)).abs());
            }
        }
    }
    worst
}

#[test]
fn mip_levels_keep_constants_and_linear_fields() {
    let (_, faces, mut mc) = mixed(2);
    let mut single = MeshColors::new(mc.topology().clone(), &vec![16; faces.len()], 1).unwrap();
    mc.samples_mut().fill(0.625);
    let mip = mc.mip_map();
    let mut out = [0.0f32; 3];
    for f in 0..faces.len() {
        for level in 0..=4 {
            mip.at_level(f, [0.2, 0.3, 0.5], level, &mut out).unwrap();
            assert!(out.iter().all(|&x| (x - 0.625).abs() < 1e-6), "{out:?}");
        }
    }
    // A linear field on the flat regular grid: Eq. 5, the edge rule and
    // Eq. 6 are symmetric stencils there, so every level reproduces it on
    // primitives whose stencils stay inside the mesh, hence its mean too.
    let (flat, _) = support::grid(6, 0.0);
    let field = |p: Vec3| 0.5 + 3.0 * p.x - 2.0 * p.y;
    single
        .fill(&flat, |p, out| out[0] = field(p.as_vec3()))
        .unwrap();
    let mip = single.mip_map();
    let inside = |f: usize, b: [f32; 3]| {
        let p = support::point(&flat, faces[f], b);
        p.x > 0.17 && p.x < 0.83 && p.y > 0.17 && p.y < 0.83
    };
    let worst = mip_levels_equal(&mip, &faces, inside, |f, b| {
        field(support::point(&flat, faces[f], b))
    });
    assert!(
        worst < 1e-5,
        "linear field changed by {worst} on a coarser level"
    );
}

#[test]
fn eq_5_face_rule_by_hand() {
    // One face at R = 8 holding f = i² (i = the lattice weight of corner 0).
    let mut mc = MeshColors::uniform(Topology::new(3, &[[0, 1, 2]]).unwrap(), 8, 1).unwrap();
    for a in mesh_colors::lattice_points(8) {
        let i = mc.lattice_index(0, a).unwrap();
        mc.sample_mut(i).unwrap()[0] = (a[0] * a[0]) as f32;
    }
    let mip = mc.mip_map();
    let mut out = [0.0f32];
    // C'_(1,1) at level 2 from C_(2,2) = 4 and its six neighbours
    // (3,1) = 9, (1,3) = 1, (3,2) = 9, (1,2) = 1, (2,3) = 4, (2,1) = 4:
    // (4 + 28/2) / 4 = 4.5.
    mip.at_level(0, [0.25, 0.25, 0.5], 2, &mut out).unwrap();
    assert_eq!(out[0], 4.5);
    // An edge sample at level 2 (boundary edge, one face): C(2,2,4)... on
    // edge a2 = 0 at level 3: centre (4,4,0) = 16, on-edge (5,3,0) = 25,
    // (3,5,0) = 9, off-edge (3,4,1) = 9, (4,3,1) = 16; four neighbours:
    // (16 + 59/2) / 3 = 15.1666…
    mip.at_level(0, [0.5, 0.5, 0.0], 2, &mut out).unwrap();
    assert!((out[0] - 45.5 / 3.0).abs() < 1e-5, "{}", out[0]);
}

#[test]
fn eq_6_vertex_rule_by_hand() {
    // One face at R = 2: vertex 0 = 1, its edges' samples 2 and 4, valence
    // 2: C' = 2/(2 + 2) · (1 + (2 + 4)/2) = 2.
    let t = Topology::new(3, &[[0, 1, 2]]).unwrap();
    let mut mc = MeshColors::uniform(t, 2, 1).unwrap();
    mc.sample_mut(0).unwrap()[0] = 1.0;
    let e01 = mc.topology().face_edges()[0][0] as usize;
    let e20 = mc.topology().face_edges()[0][2] as usize;
    let i01 = mc.edge_index(e01).unwrap();
    let i20 = mc.edge_index(e20).unwrap();
    mc.sample_mut(i01).unwrap()[0] = 2.0;
    mc.sample_mut(i20).unwrap()[0] = 4.0;
    let mip = mc.mip_map();
    let mut out = [0.0f32];
    mip.at_level(0, [1.0, 0.0, 0.0], 0, &mut out).unwrap();
    assert_eq!(out[0], 2.0);
    // The finest level is untouched.
    mip.at_level(0, [1.0, 0.0, 0.0], 1, &mut out).unwrap();
    assert_eq!(out[0], 1.0);
}

#[test]
fn anisotropic_filter_averages_along_the_long_axis() {
    let (positions, faces, mut mc) = mixed(4);
    mc.fill(&positions, |p, out| out.fill(p.x as f32)).unwrap();
    let mip = mc.mip_map();
    let mut out = [0.0f32; 3];
    // Isotropic derivatives: the same as trilinear at that footprint.
    let mut tri = [0.0f32; 3];
    let b = [0.3, 0.3, 0.4];
    mip.anisotropic(5, b, [0.01, -0.01, 0.0], [0.0, 0.01, -0.01], 16, &mut out)
        .unwrap();
    mip.trilinear(5, b, 0.01, &mut tri).unwrap();
    assert!((out[0] - tri[0]).abs() < 1e-6);
    // Probes spread along the long axis at the finest level: their mean
    // for an affine field is the value at the centre.
    let mut rng = Rng(1);
    let mut lin = [0.0f32; 3];
    for _ in 0..1000 {
        let f = rng.below(faces.len() as u64) as usize;
        let b = rng.barycentric().map(|x| 0.25 + 0.25 * x);
        let s = 1.0 / (b[0] + b[1] + b[2]);
        let b = b.map(|x| x * s);
        mip.anisotropic(
            f,
            b,
            [0.02, -0.02, 0.0],
            [0.0005, 0.0, -0.0005],
            8,
            &mut out,
        )
        .unwrap();
        mc.linear(f, b, &mut lin).unwrap();
        assert!((out[0] - lin[0]).abs() < 1e-5, "{} vs {}", out[0], lin[0]);
    }
    // A field that is not affine along the axis is averaged (differs).
    mc.fill(&positions, |p, out| out.fill((40.0 * p.x).sin() as f32))
        .unwrap();
    let mip = mc.mip_map();
    let mut differs = 0;
    let fine: Vec<usize> = (0..faces.len())
        .filter(|&f| mc.face_level(f).unwrap() >= 3)
        .collect();
    for _ in 0..1000 {
        let f = fine[rng.below(fine.len() as u64) as usize];
        let b = [0.4, 0.3, 0.3];
        mip.anisotropic(f, b, [0.3, -0.3, 0.0], [0.0005, 0.0, -0.0005], 8, &mut out)
            .unwrap();
        mc.linear(f, b, &mut lin).unwrap();
        differs += usize::from((out[0] - lin[0]).abs() > 1e-3);
    }
    assert!(differs > 500, "{differs}");
}

#[test]
fn mip_finest_level_and_small_footprints_are_the_linear_filter() {
    let (_, faces, mc) = mixed(9);
    let mip = mc.mip_map();
    let mut rng = Rng(10);
    let (mut a, mut b, mut c) = ([0.0f32; 3], [0.0f32; 3], [0.0f32; 3]);
    for _ in 0..20_000 {
        let f = rng.below(faces.len() as u64) as usize;
        let bary = rng.barycentric();
        mc.linear(f, bary, &mut a).unwrap();
        mip.at_level(f, bary, mesh_colors::FINEST_LEVEL, &mut b)
            .unwrap();
        mip.trilinear(f, bary, 1e-6, &mut c).unwrap();
        // The pyramid's lookup cache holds interpolated edge values ready
        // made, so a lattice triangle that touches a coarser edge rounds
        // once instead of twice: equal to a few ulp.
        let d = (0..3)
            .map(|k| (a[k] - b[k]).abs().max((a[k] - c[k]).abs()))
            .fold(0.0, f32::max);
        assert!(d < 1e-6, "{a:?} {b:?} {c:?}");
    }
}

#[test]
fn odd_barycentrics_do_not_panic() {
    let (_, _, mc) = mixed(1);
    let mip = mc.mip_map();
    let mut out = [0.0f32; 3];
    for b in [
        [f32::NAN; 3],
        [-1.0, -2.0, -3.0],
        [0.0, 0.0, 0.0],
        [f32::INFINITY, 1.0, 0.0],
        [1e30, 1e-30, 5.0],
        [-0.5, 0.75, 0.75],
    ] {
        mc.linear(3, b, &mut out).unwrap();
        mc.nearest(3, b, &mut out).unwrap();
        mip.trilinear(3, b, f32::NAN, &mut out).unwrap();
        mip.anisotropic(3, b, [f32::NAN; 3], [1.0, 0.0, -1.0], 16, &mut out)
            .unwrap();
    }
    // Negative weights are clamped: a point outside across edge 1-2 reads
    // the edge.
    let (mut a, mut b) = ([0.0f32; 3], [0.0f32; 3]);
    mc.linear(3, [-0.5, 0.75, 0.75], &mut a).unwrap();
    mc.linear(3, [0.0, 0.5, 0.5], &mut b).unwrap();
    assert_eq!(a, b);
}

#[test]
fn batch_lookups_equal_single_lookups() {
    let (_, faces, mc) = mixed(13);
    let mip = mc.mip_map();
    let mut rng = Rng(14);
    let points: Vec<(u32, [f32; 3])> = (0..10_000)
        .map(|_| (rng.below(faces.len() as u64) as u32, rng.barycentric()))
        .collect();
    let footprints: Vec<f32> = (0..points.len())
        .map(|i| 0.01 + (i % 50) as f32 / 60.0)
        .collect();
    let mut batch = vec![0.0f32; 3 * points.len()];
    let mut one = [0.0f32; 3];
    mc.linear_into(&points, &mut batch).unwrap();
    for (i, &(f, b)) in points.iter().enumerate() {
        mc.linear(f as usize, b, &mut one).unwrap();
        assert_eq!(&batch[3 * i..3 * i + 3], &one);
    }
    mip.trilinear_into(&points, &footprints, &mut batch)
        .unwrap();
    for (i, &(f, b)) in points.iter().enumerate() {
        mip.trilinear(f as usize, b, footprints[i], &mut one)
            .unwrap();
        assert_eq!(&batch[3 * i..3 * i + 3], &one);
    }
    assert!(mc.linear_into(&points, &mut batch[1..]).is_err());
    assert!(mc.linear_into(&[(9999, [0.3; 3])], &mut [0.0; 3]).is_err());
    assert!(
        mip.trilinear_into(&points, &footprints[1..], &mut batch)
            .is_err()
    );
}
