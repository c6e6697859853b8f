//! Batch resolution changes (Sec. 3.2, Sec. 5.1's detail brush): equal to
//! one-at-a-time changes, continuous across shared edges for every
//! filter, undone bit for bit, and refused before any change on bad input.

use crate::filtering::edge_points;
use crate::support;

use mesh_colors::{Error, MeshColors, Topology};
use support::Rng;

/// A random mesh: a bumpy grid of random size, levels 0..=4, random RGB.
fn random_colors(rng: &mut Rng) -> MeshColors {
    let n = 2 + rng.below(6) as u32;
    let (positions, faces) = support::grid(n, 0.3);
    let levels: Vec<u32> = (0..faces.len()).map(|_| 1 << rng.below(5)).collect();
    let topology = Topology::new(positions.len(), &faces).unwrap();
    let mut mc = MeshColors::new(topology, &levels, 3).unwrap();
    for x in mc.samples_mut() {
        *x = rng.f32();
    }
    mc
}

/// Random requests, some faces repeated, some at their own resolution.
fn random_changes(mc: &MeshColors, rng: &mut Rng) -> Vec<(usize, u32)> {
    let count = 1 + rng.below(2 * mc.face_count() as u64) as usize;
    (0..count)
        .map(|_| {
            let f = rng.below(mc.face_count() as u64) as usize;
            (f, 1 << rng.below(6))
        })
        .collect()
}

#[test]
fn a_batch_equals_one_change_at_a_time_bit_for_bit() {
    let mut rng = Rng(45);
    for round in 0..60 {
        let mut mc = random_colors(&mut rng);
        let changes = random_changes(&mc, &mut rng);
        let mut one_by_one = mc.clone();
        for &(f, r) in &changes {
            one_by_one = one_by_one.set_face_resolution(f, r).unwrap();
        }
        let change = mc.set_face_resolutions(&changes).unwrap();
        // Samples, levels and every per-primitive index.
        assert_eq!(mc, one_by_one, "round {round}: {changes:?}");
        // The record names each resampled face once, with its levels.
        let mut seen = std::collections::HashSet::new();
        for (f, _, after) in change.faces() {
            assert!(seen.insert(f), "face {f} recorded twice");
            assert_eq!(mc.face_resolution(f), Some(after));
        }
        assert_eq!(change.requests(), changes);
    }
}

#[test]
fn every_filter_is_continuous_across_shared_edges_after_a_batch() {
    let mut rng = Rng(7);
    let mut mixed_points = 0;
    for _ in 0..6 {
        let mut mc = random_colors(&mut rng);
        let changes = random_changes(&mc, &mut rng);
        mc.set_face_resolutions(&changes).unwrap();
        let mip = mc.mip_map();
        let (mut a, mut b) = ([0.0f32; 3], [0.0f32; 3]);
        for (f0, b0, f1, b1) in edge_points(&mc, &mut rng) {
            if mc.face_level(f0) != mc.face_level(f1) {
                mixed_points += 1;
            }
            mc.linear(f0, b0, &mut a).unwrap();
            mc.linear(f1, b1, &mut b).unwrap();
            assert_eq!(a, b, "linear, faces {f0}/{f1} at {b0:?}");
            mc.nearest(f0, b0, &mut a).unwrap();
            mc.nearest(f1, b1, &mut b).unwrap();
            assert_eq!(a, b, "nearest, faces {f0}/{f1} at {b0:?}");
            for level in 0..=5 {
                mip.at_level(f0, b0, level, &mut a).unwrap();
                mip.at_level(f1, b1, level, &mut b).unwrap();
                assert_eq!(a, b, "MIP level {level}, faces {f0}/{f1}");
            }
            for footprint in [0.7, 0.2, 0.04] {
                mip.trilinear(f0, b0, footprint, &mut a).unwrap();
                mip.trilinear(f1, b1, footprint, &mut b).unwrap();
                assert_eq!(a, b, "trilinear {footprint}, faces {f0}/{f1}");
            }
            let d = [0.01, -0.004, -0.006];
            let e = [0.002, 0.003, -0.005];
            mip.anisotropic(f0, b0, d, e, 1, &mut a).unwrap();
            mip.anisotropic(f1, b1, d, e, 1, &mut b).unwrap();
            assert_eq!(a, b, "anisotropic (one probe), faces {f0}/{f1}");
        }
    }
    assert!(mixed_points > 500, "{mixed_points} points on mixed edges");
}

#[test]
fn reverting_restores_the_samples_exactly_and_redo_repeats_the_change() {
    let mut rng = Rng(12);
    for round in 0..60 {
        let original = random_colors(&mut rng);
        let mut mc = original.clone();
        // Two changes in a row, undone last first.
        let first = mc
            .set_face_resolutions(&random_changes(&mc, &mut rng))
            .unwrap();
        let after_first = mc.clone();
        let second = mc
            .set_face_resolutions(&random_changes(&mc, &mut rng))
            .unwrap();
        let after_second = mc.clone();
        // Out of order is refused when it would not fit (and changes nothing).
        if let Err(e) = mc.revert_resolutions(&first) {
            assert!(matches!(e, Error::StaleUndo { .. }), "{e}");
            assert_eq!(mc, after_second);
        } else {
            // It fitted (the changes touched disjoint faces): put it back.
            mc.set_face_resolutions(&first.requests()).unwrap();
        }
        mc = after_second.clone();
        mc.revert_resolutions(&second).unwrap();
        assert_eq!(mc, after_first, "round {round}: second undo");
        mc.revert_resolutions(&first).unwrap();
        assert_eq!(mc, original, "round {round}: first undo");
        // Undoing twice is refused.
        if !first.is_empty() {
            assert!(matches!(
                mc.revert_resolutions(&first),
                Err(Error::StaleUndo { .. })
            ));
        }
        // Redo: the same requests give the same samples and record.
        let again = mc.set_face_resolutions(&first.requests()).unwrap();
        assert_eq!(again, first);
        assert_eq!(mc, after_first);
        // The record holds only what was resampled.
        let touched: usize = first
            .faces()
            .map(|(_, before, _)| mesh_colors::samples_per_face(before) as usize)
            .sum::<usize>()
            + first
                .edges()
                .map(|(_, before, _)| mesh_colors::samples_per_edge(before) as usize)
                .sum::<usize>();
        // Exactly: the old values (3 channels of 4 bytes), 8 bytes per
        // resampled primitive and per request, and the record itself.
        let entries = first.faces().len() + first.edges().len() + first.requests().len();
        assert_eq!(
            first.memory_bytes(),
            12 * touched + 8 * entries + std::mem::size_of::<mesh_colors::edit::ResolutionChange>()
        );
    }
}

#[test]
fn bad_requests_name_the_element_and_change_nothing() {
    let mut rng = Rng(3);
    let mut mc = random_colors(&mut rng);
    let before = mc.clone();
    let n = mc.face_count();
    assert_eq!(
        mc.set_face_resolutions(&[(0, 4), (n + 3, 2)]),
        Err(Error::MissingFace {
            face: n + 3,
            count: n
        })
    );
    assert_eq!(
        mc.set_face_resolutions(&[(1, 2), (2, 6)]),
        Err(Error::BadResolution {
            face: 2,
            resolution: 6
        })
    );
    assert!(matches!(
        mc.set_face_resolutions(&[(0, 0)]),
        Err(Error::BadResolution { face: 0, .. })
    ));
    assert!(matches!(
        mc.set_face_resolutions(&[(1, 1 << 11)]),
        Err(Error::BadResolution { face: 1, .. })
    ));
    assert_eq!(mc, before);
    // Over the budget: a large grid at the cap everywhere.
    let (positions, faces) = support::grid(64, 0.0);
    let mut big =
        MeshColors::uniform(Topology::new(positions.len(), &faces).unwrap(), 1, 64).unwrap();
    let all: Vec<(usize, u32)> = (0..big.face_count()).map(|f| (f, 1 << 10)).collect();
    let small = big.clone();
    assert!(matches!(
        big.set_face_resolutions(&all),
        Err(Error::TooLarge { .. })
    ));
    assert_eq!(big, small);
    // Nothing to do is fine and records nothing.
    let same: Vec<(usize, u32)> = (0..n)
        .map(|f| (f, mc.face_resolution(f).unwrap()))
        .collect();
    let change = mc.set_face_resolutions(&same).unwrap();
    assert!(change.is_empty());
    assert_eq!(mc, before);
    let text = Error::StaleUndo {
        what: "face",
        index: 7,
        reason: "is not at the resolution the change left it at",
    }
    .to_string();
    assert!(text.contains("face 7"), "{text}");
}

#[test]
fn the_mip_map_follows_a_resolution_change_as_a_rebuild_would() {
    let mut rng = Rng(77);
    for round in 0..30 {
        let mut mc = random_colors(&mut rng);
        let mut mip = mc.mip_map();
        if round % 2 == 0 {
            // A lookup builds the lookup cache, which the refresh must
            // then keep up to date (odd rounds: it is built afterwards).
            mip.at_level(0, [0.2, 0.3, 0.5], 1, &mut [0.0; 3]).unwrap();
        }
        let changes = random_changes(&mc, &mut rng);
        let change = mc.set_face_resolutions(&changes).unwrap();
        let faces: Vec<usize> = change.faces().map(|f| f.0).collect();
        mip.refresh_resolutions(&mc, &faces).unwrap();
        let want = mc.mip_map();
        assert_eq!(mip.colors(), want.colors(), "round {round}: colours");
        let (a, b) = (mip.data(), want.data());
        assert_eq!(a.len(), b.len());
        let bad: Vec<usize> = (0..a.len())
            .filter(|&i| a[i].to_bits() != b[i].to_bits())
            .collect();
        assert!(
            bad.is_empty(),
            "round {round}: {} values differ, first {:?}",
            bad.len(),
            &bad[..bad.len().min(10)]
        );
        assert!(mip == want, "round {round}: the pyramids differ");
        assert_same_lookups(&mip, &want, &format!("round {round}"));
        mc.revert_resolutions(&change).unwrap();
        mip.refresh_resolutions(&mc, &faces).unwrap();
        assert_eq!(mip, mc.mip_map(), "round {round}: reverted");
        assert_same_lookups(&mip, &mc.mip_map(), &format!("round {round}, reverted"));
    }
    // Leaving out a changed face, or another mesh, is refused by name.
    let mut mc = random_colors(&mut rng);
    let mut mip = mc.mip_map();
    let before = mip.clone();
    let f = (0..mc.face_count())
        .find(|&f| mc.face_resolution(f) != Some(8))
        .unwrap();
    mc.set_face_resolutions(&[(f, 8)]).unwrap();
    let e = mip.refresh_resolutions(&mc, &[]).unwrap_err();
    assert!(e.to_string().contains("`faces`"), "{e}");
    assert!(matches!(
        mip.refresh_resolutions(&mc, &[mc.face_count()]),
        Err(Error::MissingFace { .. })
    ));
    let (positions, faces) = support::grid(9, 0.0);
    let other = MeshColors::uniform(Topology::new(positions.len(), &faces).unwrap(), 2, 3).unwrap();
    let e = mip.refresh_resolutions(&other, &[0]).unwrap_err();
    assert!(e.to_string().contains("`colors`"), "{e}");
    assert_eq!(mip, before);
}

/// Every level's lookups (which read the pyramid's lookup cache inside
/// faces) are the same bits from `a` and `b`.
fn assert_same_lookups(a: &mesh_colors::MipMap, b: &mesh_colors::MipMap, what: &str) {
    let points = [[0.2, 0.3, 0.5], [0.61, 0.13, 0.26], [0.05, 0.9, 0.05]];
    let (mut x, mut y) = ([0.0f32; 3], [0.0f32; 3]);
    for f in 0..a.colors().face_count() {
        for b3 in points {
            for q in (0..=6).chain([mesh_colors::FINEST_LEVEL]) {
                a.at_level(f, b3, q, &mut x).unwrap();
                b.at_level(f, b3, q, &mut y).unwrap();
                assert_eq!(
                    x.map(f32::to_bits),
                    y.map(f32::to_bits),
                    "{what}: face {f} at {b3:?}, level {q}"
                );
            }
        }
    }
}

/// A batch large enough that its independent steps are resampled on all
/// threads (waves of 16,384 samples or more) still equals one change at a time:
/// the detail brush's case, many neighbouring faces up or down at once.
#[test]
fn a_large_batch_of_neighbours_equals_one_change_at_a_time() {
    let mut rng = Rng(451);
    let (positions, faces) = support::grid(24, 0.3);
    let topology = Topology::new(positions.len(), &faces).unwrap();
    for round in 0..3 {
        // Fine enough that a wave holds more samples than the threshold
        // for other threads.
        let levels: Vec<u32> = (0..faces.len()).map(|_| 8 << rng.below(3)).collect();
        let mut mc = MeshColors::new(topology.clone(), &levels, 3).unwrap();
        for x in mc.samples_mut() {
            *x = rng.f32();
        }
        // Most faces once, up or down one level, some twice.
        let mut changes: Vec<(usize, u32)> = Vec::new();
        for f in 0..mc.face_count() {
            let r = mc.face_resolution(f).unwrap();
            match rng.below(4) {
                0 => {}
                1 => changes.push((f, (r / 2).max(1))),
                _ => changes.push((f, r * 2)),
            }
        }
        for _ in 0..40 {
            let f = rng.below(mc.face_count() as u64) as usize;
            changes.push((f, 1 << rng.below(5)));
        }
        let mut one_by_one = mc.clone();
        for &(f, r) in &changes {
            one_by_one = one_by_one.set_face_resolution(f, r).unwrap();
        }
        let before = mc.clone();
        let change = mc.set_face_resolutions(&changes).unwrap();
        assert_eq!(mc, one_by_one, "round {round}");
        mc.revert_resolutions(&change).unwrap();
        assert_eq!(mc, before, "round {round}: undo");
    }
}
