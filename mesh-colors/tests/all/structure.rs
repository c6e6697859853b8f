//! The structure: sample counts (Eq. 1–3), positions (Eq. 4), the layout
//! and the errors for bad input.

use crate::support;

use mesh_colors::{
    Error, MeshColors, Topology, lattice_points, sample_position, samples_per_edge,
    samples_per_face,
};

#[test]
fn sample_counts_follow_eq_1_to_3_for_r_1_to_64() {
    for n in 0..=6u32 {
        let r = 1u32 << n;
        assert_eq!(samples_per_edge(r), r - 1);
        assert_eq!(samples_per_face(r), (r - 1) * r.saturating_sub(2) / 2);
        // One triangle: 3 vertices (Eq. 1), 3 edges (Eq. 2), a face (Eq. 3).
        let one = MeshColors::uniform(Topology::new(3, &[[0, 1, 2]]).unwrap(), r, 1).unwrap();
        let expected = 3 + 3 * (r - 1) + (r - 1) * r.saturating_sub(2) / 2;
        assert_eq!(one.sample_count(), expected as usize, "R = {r}");
        // ... which is every lattice point of the face, (R+1)(R+2)/2.
        assert_eq!(expected, (r + 1) * (r + 2) / 2);
        // A closed octahedron: V − E + F = 2, every edge shared.
        let octa = [
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        let mc = MeshColors::uniform(Topology::new(6, &octa).unwrap(), r, 4).unwrap();
        let expected = 6 + 12 * (r - 1) + 8 * samples_per_face(r);
        assert_eq!(mc.sample_count(), expected as usize, "R = {r}");
        assert_eq!(mc.samples().len(), expected as usize * 4);
    }
    // Every R from 1 to 64 that is not a power of two is refused.
    for r in 1..=64u32 {
        let result = MeshColors::uniform(Topology::new(3, &[[0, 1, 2]]).unwrap(), r, 1);
        assert_eq!(result.is_ok(), r.is_power_of_two(), "R = {r}");
    }
}

#[test]
fn every_lattice_point_maps_to_one_sample_and_sites_follow_eq_4() {
    let (positions, faces) = support::grid(3, 0.3);
    let topology = Topology::new(positions.len(), &faces).unwrap();
    let levels: Vec<u32> = (0..faces.len()).map(|f| 1 << (f % 4)).collect();
    let mc = MeshColors::new(topology, &levels, 2).unwrap();
    let mut hits = vec![0u32; mc.sample_count()];
    for f in 0..mc.face_count() {
        let r = mc.face_resolution(f).unwrap();
        let mut seen = std::collections::HashSet::new();
        for a in lattice_points(r) {
            if let Some(i) = mc.lattice_index(f, a) {
                assert!(seen.insert(i), "face {f}: sample {i} twice");
                hits[i] += 1;
            }
        }
    }
    assert!(hits.iter().all(|&h| h >= 1), "a sample no face reaches");
    // Eq. 4 by hand for one point, and the sites of a single face.
    assert_eq!(sample_position(8, 3, 2), [0.375, 0.25, 0.375]);
    let one = MeshColors::uniform(Topology::new(3, &[[0, 1, 2]]).unwrap(), 8, 1).unwrap();
    let sites = one.sites();
    for a in lattice_points(8) {
        let i = one.lattice_index(0, a).unwrap();
        let b = sites[i].barycentric;
        assert_eq!(
            b,
            [a[0] as f64 / 8.0, a[1] as f64 / 8.0, a[2] as f64 / 8.0],
            "{a:?}"
        );
    }
    // The layout of Fig. 10: vertices first, each edge's run, each face's.
    assert_eq!(one.vertex_index(2).unwrap(), 2);
    assert_eq!(one.edge_index(0).unwrap(), 3);
    assert_eq!(one.face_index(0).unwrap(), 3 + 3 * 7);
    assert_eq!(one.lattice_index(0, [8, 0, 0]), Some(0));
    assert_eq!(one.lattice_index(0, [1, 1, 6]), Some(24));
    assert_eq!(
        one.lattice_index(0, [1, 1, 1]),
        None,
        "not on the R = 8 lattice"
    );
    assert_eq!(one.lattice_index(0, [u32::MAX, 1, 8]), None);
    assert_eq!(one.lattice_index(1, [8, 0, 0]), None, "no face 1");
}

#[test]
fn canonical_edges_are_shared_in_opposite_directions() {
    // Face 0 runs 1 → 2, face 1 runs 2 → 1: one edge, one sample row.
    let t = Topology::new(4, &[[0, 1, 2], [2, 1, 3]]).unwrap();
    assert_eq!(t.edges().len(), 5);
    let e = t.face_edges()[0][1];
    assert_eq!(t.face_edges()[1][0], e);
    assert_eq!(t.edges()[e as usize], [1, 2]);
    assert_eq!(t.edge_between(2, 1), Some(e));
    let mc = MeshColors::uniform(t, 4, 1).unwrap();
    // Lattice points on the shared edge name the same samples from both
    // faces: face 0 (a1 = weight of v1), face 1 (a1 = weight of v1).
    for w in 1..4u32 {
        let from0 = mc.lattice_index(0, [0, w, 4 - w]);
        let from1 = mc.lattice_index(1, [4 - w, w, 0]);
        assert_eq!(from0, from1);
    }
}

#[test]
fn bad_input_is_an_error_naming_the_place() {
    assert_eq!(
        Topology::new(3, &[[0, 1, 2], [0, 1, 7]]),
        Err(Error::MissingVertex {
            face: 1,
            vertex: 7,
            count: 3
        })
    );
    assert_eq!(
        Topology::new(3, &[[0, 1, 1]]),
        Err(Error::DegenerateFace { face: 0, vertex: 1 })
    );
    assert_eq!(
        Topology::new(5, &[[0, 1, 2], [1, 0, 3], [0, 1, 4]]),
        Err(Error::NonManifoldEdge {
            a: 0,
            b: 1,
            faces: [0, 1, 2]
        })
    );
    let t = Topology::new(3, &[[0, 1, 2]]).unwrap();
    assert_eq!(
        MeshColors::new(t.clone(), &[3], 1),
        Err(Error::BadResolution {
            face: 0,
            resolution: 3
        })
    );
    assert_eq!(
        MeshColors::new(t.clone(), &[2048], 1),
        Err(Error::BadResolution {
            face: 0,
            resolution: 2048
        })
    );
    assert_eq!(
        MeshColors::new(t.clone(), &[0], 1),
        Err(Error::BadResolution {
            face: 0,
            resolution: 0
        })
    );
    assert_eq!(
        MeshColors::new(t.clone(), &[2, 2], 1),
        Err(Error::ResolutionCount { got: 2, faces: 1 })
    );
    assert_eq!(
        MeshColors::new(t.clone(), &[2], 0),
        Err(Error::BadChannels(0))
    );
    let mc = MeshColors::new(t, &[2], 3).unwrap();
    let mut two = [0.0; 2];
    assert_eq!(
        mc.linear(0, [0.3, 0.3, 0.4], &mut two),
        Err(Error::ChannelMismatch {
            what: "lookup output",
            expected: 3,
            got: 2
        })
    );
    let mut three = [0.0; 3];
    assert_eq!(
        mc.linear(1, [0.3, 0.3, 0.4], &mut three),
        Err(Error::MissingFace { face: 1, count: 1 })
    );
}
