//! Painting: a dab changes exactly the samples within its radius, with the
//! falloff, at a cost that follows the samples touched.

use crate::support;

use glam::Vec3;
use mesh_colors::{Blend, Brush, MeshColors, Painter, Topology};

#[test]
fn a_dab_touches_exactly_the_samples_within_its_radius() {
    let (positions, faces) = support::grid(40, 0.2);
    let mut mc =
        MeshColors::uniform(Topology::new(positions.len(), &faces).unwrap(), 8, 3).unwrap();
    mc.samples_mut().fill(0.25);
    let painter = Painter::new(&mc, &positions, 0.05).unwrap();
    let before = mc.clone();
    let center = positions[20 * 41 + 17] + Vec3::new(0.004, -0.003, 0.01);
    let brush = Brush {
        center,
        radius: 0.05,
        color: &[1.0, 0.0, 0.5],
        strength: 1.0,
        blend: Blend::Mix,
    };
    let stroke = painter.paint(&mut mc, &brush).unwrap();
    let mut inside = 0;
    for (i, p) in painter.sample_positions().iter().enumerate() {
        let d = p.distance(center);
        let (old, new) = (before.sample(i).unwrap(), mc.sample(i).unwrap());
        if d <= brush.radius {
            inside += 1;
            let w = brush.weight(d);
            for c in 0..3 {
                let want = old[c] + w * (brush.color[c] - old[c]);
                assert!((new[c] - want).abs() < 1e-6, "sample {i} at {d}");
            }
        } else {
            assert_eq!(old, new, "sample {i} at distance {d} changed");
        }
    }
    assert_eq!(stroke.touched, inside);
    assert!(inside > 500, "{inside} samples inside");
    // The cost: the samples examined are a small multiple of those touched
    // and a small part of the mesh.
    assert!(stroke.examined < 12 * stroke.touched, "{stroke:?}");
    assert!(
        stroke.examined * 20 < mc.sample_count(),
        "{stroke:?} of {}",
        mc.sample_count()
    );
    // The falloff is smooth: full at the centre, zero at the rim.
    assert_eq!(brush.weight(0.0), 1.0);
    assert_eq!(brush.weight(brush.radius), 0.0);
    // Set and Add.
    let set = Brush {
        blend: Blend::Set,
        ..brush
    };
    painter.paint(&mut mc, &set).unwrap();
    let near = (0..mc.sample_count())
        .find(|&i| painter.sample_positions()[i].distance(center) < 0.04)
        .unwrap();
    assert_eq!(mc.sample(near).unwrap(), &[1.0, 0.0, 0.5]);
    let add = Brush {
        blend: Blend::Add,
        color: &[0.5, 0.5, 0.5],
        strength: 0.5,
        ..brush
    };
    painter.paint(&mut mc, &add).unwrap();
    let w = add.weight(painter.sample_positions()[near].distance(center));
    assert!((mc.sample(near).unwrap()[1] - 0.5 * w).abs() < 1e-6);
    // A huge brush scans occupied cells instead of empty space.
    let all = Brush {
        radius: 100.0,
        ..brush
    };
    let s = painter.paint(&mut mc, &all).unwrap();
    assert_eq!(s.touched, mc.sample_count());
    // A brush far away, or spanning an absurd number of cells, is cheap.
    let far = Brush {
        center: Vec3::splat(1e12),
        radius: 1.0,
        ..brush
    };
    assert_eq!(painter.paint(&mut mc, &far).unwrap().touched, 0);
    let wide = Brush {
        radius: 1e30,
        ..brush
    };
    assert_eq!(
        painter.paint(&mut mc, &wide).unwrap().touched,
        mc.sample_count()
    );
    // Bad input.
    assert!(
        painter
            .paint(
                &mut mc,
                &Brush {
                    color: &[1.0],
                    ..brush
                }
            )
            .is_err()
    );
    assert!(
        painter
            .paint(
                &mut mc,
                &Brush {
                    radius: f32::NAN,
                    ..brush
                }
            )
            .is_err()
    );
    assert!(Painter::new(&mc, &positions[..3], 0.1).is_err());
    let finer = mc.set_face_resolution(0, 16).unwrap();
    let mut finer = finer;
    assert!(
        painter.paint(&mut finer, &brush).is_err(),
        "a stale index is refused"
    );
}

#[test]
fn the_grid_finds_each_sample_within_the_radius_once_at_any_cell_size() {
    let (positions, faces) = support::grid(12, 0.3);
    let mc = MeshColors::uniform(Topology::new(positions.len(), &faces).unwrap(), 4, 3).unwrap();
    // Cells far smaller than the brush (many cells share a bucket), about
    // its size, and larger than the mesh.
    for cell in [0.004, 0.05, 3.0] {
        let painter = Painter::new(&mc, &positions, cell).unwrap();
        let all = painter.sample_positions();
        for k in 0..25 {
            let center = positions[(k * 31) % positions.len()] + Vec3::new(0.01, -0.02, 0.03);
            let radius = [0.01, 0.07, 0.3, 2.0, 0.0][k % 5];
            let mut found = Vec::new();
            painter.for_each_within(center, radius, |i, d| found.push((i, d.to_bits())));
            found.sort_unstable();
            let want: Vec<(usize, u32)> = (0..all.len())
                .map(|i| (i, all[i].distance(center)))
                .filter(|&(_, d)| d <= radius)
                .map(|(i, d)| (i, d.to_bits()))
                .collect();
            assert_eq!(found, want, "cell {cell}, dab {k}");
        }
    }
}
