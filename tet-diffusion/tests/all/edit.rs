//! Cutting, painting, fracture and recombination.

use crate::common;

use common::*;
use tet_diffusion::glam::{DAffine3, DVec3};
use tet_diffusion::{Cut, CutMethod, Error, Light, Medium, Object, Stroke, TetMesh};

fn lit_ball(n: usize) -> Object {
    let mut o =
        Object::homogeneous(ball(n, 5.0), 1.0, Medium::measured("marble").unwrap(), 1.3).unwrap();
    o.add_light(Light::Directional {
        to_light: DVec3::new(0.3, 1.0, 0.2),
        irradiance: [1.0; 3],
    })
    .unwrap();
    o
}

fn min_dihedral(mesh: &TetMesh) -> Vec<f64> {
    (0..mesh.tets().len())
        .map(|t| {
            mesh.dihedral_angles(t)
                .into_iter()
                .fold(f64::INFINITY, f64::min)
                .to_degrees()
        })
        .collect()
}

fn check_cut(before: &Object, after: &Object, cut: &Cut) {
    let (old, new) = (before.mesh(), after.mesh());
    // Tet ids preserved: each remaining tet is the original tet of its id
    // (same vertices by position, up to the relaxation moving cut-side ones).
    for (t, &id) in new.original_ids().iter().enumerate() {
        let a = new.tets()[t].map(|v| new.positions()[v as usize]);
        let b = old.tets()[id as usize].map(|v| old.positions()[v as usize]);
        for k in 0..4 {
            assert!(a[k] == b[k] || cut.side(b[k]) > 0.0, "tet {t} (id {id})");
        }
    }
    // No orphaned vertex.
    let mut used = vec![false; new.vertex_count()];
    new.tets()
        .iter()
        .flatten()
        .for_each(|&v| used[v as usize] = true);
    assert!(used.iter().all(|&u| u));
    // No dihedral angle below 0.5° created.
    let before_min = min_dihedral(old);
    for (t, m) in min_dihedral(new).into_iter().enumerate() {
        let was = before_min[new.original_ids()[t] as usize];
        assert!(m >= 0.5f64.min(was) - 1e-9, "tet {t}: {m}° (was {was}°)");
    }
    // The new surface lies on the cut side: every boundary face that was not
    // a boundary face before has all its vertices on the cut side.
    for f in new.boundary() {
        let p = f.map(|v| new.positions()[v as usize]);
        let on_old_surface = p.iter().all(|x| x.length() > 5.0 - 1e-9);
        if !on_old_surface {
            assert!(p.iter().all(|x| cut.side(*x) >= 0.0), "{p:?}");
        }
    }
}

#[test]
fn plane_cut() {
    let mut o = lit_ball(8);
    o.solve().unwrap();
    let before = Object::new(o.mesh().clone(), 1.0, o.media().to_vec(), 1.3).unwrap();
    let cut = Cut::Plane {
        point: DVec3::new(0.0, 0.0, 1.0),
        normal: DVec3::new(0.2, 0.1, 1.0),
    };
    let report = o.cut(&cut, CutMethod::Relax { sweeps: 10 }).unwrap();
    assert!(report.removed_tets > 0 && report.removed_vertices > 0 && report.moved_vertices > 0);
    assert_eq!(
        o.mesh().tets().len() + report.removed_tets,
        before.mesh().tets().len()
    );
    check_cut(&before, &o, &cut);
    // Warm start from the carried φ beats a cold start.
    let warm = o.solve().unwrap();
    let mut cold = Object::new(o.mesh().clone(), 1.0, o.media().to_vec(), 1.3).unwrap();
    cold.add_light(Light::Directional {
        to_light: DVec3::new(0.3, 1.0, 0.2),
        irradiance: [1.0; 3],
    })
    .unwrap();
    let c = cold.solve().unwrap();
    assert!(warm.channels[1].iterations <= c.channels[1].iterations);
    // The cut object is a valid object for the manufactured solution too:
    // its matrix equals a fresh assembly on the cut mesh.
    for ch in 0..3 {
        assert_eq!(o.matrix(ch).data(), cold.matrix(ch).data());
    }
}

#[test]
fn stroke_cut() {
    let mut o = lit_ball(8);
    let before = Object::new(o.mesh().clone(), 1.0, o.media().to_vec(), 1.3).unwrap();
    // Looking down −Z, a stroke from left to right at y = 1 removes y > 1.
    let cut = Cut::Stroke {
        points: vec![
            DVec3::new(-9.0, 1.0, 9.0),
            DVec3::new(0.0, 1.5, 9.0),
            DVec3::new(9.0, 1.0, 9.0),
        ],
        view: DVec3::NEG_Z,
    };
    assert!(cut.side(DVec3::new(0.0, 4.0, 0.0)) > 0.0);
    assert!(cut.side(DVec3::new(0.0, -4.0, 0.0)) < 0.0);
    let report = o.cut(&cut, CutMethod::Relax { sweeps: 5 }).unwrap();
    assert!(report.removed_tets > 0);
    check_cut(&before, &o, &cut);
    o.solve().unwrap();
}

#[test]
fn bad_cuts_are_errors() {
    let mut o = lit_ball(3);
    let everything = Cut::Plane {
        point: DVec3::splat(-100.0),
        normal: DVec3::X,
    };
    assert!(matches!(
        o.cut(&everything, CutMethod::Exact),
        Err(Error::CutRemovesEverything { .. })
    ));
    let zero = Cut::Plane {
        point: DVec3::ZERO,
        normal: DVec3::ZERO,
    };
    assert!(o.cut(&zero, CutMethod::Exact).is_err());
    let nan = Cut::Stroke {
        points: vec![DVec3::ZERO, DVec3::NAN],
        view: DVec3::Z,
    };
    assert!(o.cut(&nan, CutMethod::Relax { sweeps: 1 }).is_err());
    // Nothing was lost.
    assert_eq!(o.mesh().tets().len(), 3 * 3 * 3 * 6);
}

#[test]
fn painting_updates_rows_exactly_as_a_full_assembly() {
    let mut o = lit_ball(8);
    o.solve().unwrap();
    let stroke = Stroke {
        points: vec![DVec3::new(0.0, 4.0, 0.0), DVec3::new(1.0, 4.0, 1.0)],
        radius: 1.0,
        medium: Medium::measured("ketchup").unwrap(),
        strength: 0.8,
    };
    let report = o.paint(&stroke).unwrap();
    assert!(report.tets > 0 && report.rows < o.mesh().vertex_count());
    let full = Object::new(o.mesh().clone(), 1.0, o.media().to_vec(), 1.3).unwrap();
    for c in 0..3 {
        assert_eq!(o.matrix(c).data(), full.matrix(c).data(), "channel {c}");
    }
    let before: Vec<f64> = o.phi(2).to_vec();
    o.solve().unwrap();
    // Ketchup absorbs blue: the painted side gets darker.
    let v = o
        .mesh()
        .boundary_vertices()
        .iter()
        .copied()
        .find(|&v| o.mesh().positions()[v as usize].distance(DVec3::new(0.0, 5.0, 0.0)) < 1.5);
    let v = v.unwrap() as usize;
    assert!(o.phi(2)[v] < before[v]);
    // Bad strokes.
    let mut bad = stroke.clone();
    bad.radius = 0.0;
    assert!(o.paint(&bad).is_err());
    bad = stroke.clone();
    bad.points[0].x = f64::NAN;
    assert!(o.paint(&bad).is_err());
    bad = stroke;
    bad.strength = 2.0;
    assert!(o.paint(&bad).is_err());
}

#[test]
fn the_brush_grid_paints_the_tets_testing_every_centre_would() {
    // Strokes of several radii (a grid cell is a few tets wide), points
    // inside, on and outside the ball, one on a lattice plane.
    let mut o = lit_ball(9);
    let ketchup = Medium::measured("ketchup").unwrap();
    let strokes = [
        (vec![DVec3::new(0.0, 4.9, 0.0)], 0.05),
        (
            vec![DVec3::new(0.3, -2.0, 1.1), DVec3::new(1.0, -1.0, 1.5)],
            0.7,
        ),
        (vec![DVec3::new(5.5, 0.0, 0.0)], 0.4),
        (vec![DVec3::new(0.0, 0.0, 0.0)], 3.0),
        (vec![DVec3::new(9.0, 9.0, 9.0)], 0.5),
    ];
    for (points, radius) in strokes {
        let before = o.media().to_vec();
        let stroke = Stroke {
            points: points.clone(),
            radius,
            medium: ketchup,
            strength: 0.7,
        };
        let report = o.paint(&stroke).unwrap();
        let mesh = o.mesh();
        let mut painted = 0;
        for t in 0..mesh.tets().len() {
            let c = mesh.tet_center(t);
            let d2 = points
                .iter()
                .map(|p| p.distance_squared(c))
                .fold(f64::INFINITY, f64::min);
            let id = mesh.original_ids()[t] as usize;
            let want = if d2 <= (3.0 * radius).powi(2) {
                painted += 1;
                let w = 0.7 * (-d2 / (2.0 * radius * radius)).exp();
                before[id].lerp(&ketchup, w)
            } else {
                before[id]
            };
            assert_eq!(o.media()[id], want, "tet {t}, radius {radius}");
        }
        assert_eq!(report.tets, painted, "radius {radius}");
    }
}

#[test]
fn painting_a_half_space_fills_the_tets_on_its_side_exactly_as_a_full_assembly() {
    let mut o = lit_ball(8);
    let skin = Medium::measured("skin1").unwrap();
    let (point, normal) = (DVec3::new(0.0, 1.5, 0.0), DVec3::new(0.0, 2.0, 0.0));
    let report = o.paint_half_space(point, normal, skin).unwrap();
    let mesh = o.mesh();
    let above: Vec<usize> = (0..mesh.tets().len())
        .filter(|&t| mesh.tet_center(t).y > 1.5)
        .collect();
    assert!(!above.is_empty() && above.len() < mesh.tets().len());
    assert_eq!(report.tets, above.len());
    assert!(report.rows > 0 && report.rows < mesh.vertex_count());
    let marble = Medium::measured("marble").unwrap();
    for t in 0..mesh.tets().len() {
        let m = o.media()[mesh.original_ids()[t] as usize];
        assert_eq!(m, if above.contains(&t) { skin } else { marble }, "tet {t}");
    }
    let full = Object::new(o.mesh().clone(), 1.0, o.media().to_vec(), 1.3).unwrap();
    for c in 0..3 {
        assert_eq!(o.matrix(c).data(), full.matrix(c).data(), "channel {c}");
    }
    // The side beyond the whole ball paints nothing.
    let none = o
        .paint_half_space(DVec3::new(0.0, 6.0, 0.0), DVec3::Y, skin)
        .unwrap();
    assert_eq!((none.tets, none.rows), (0, 0));
    // Bad planes.
    for (p, n) in [
        (DVec3::new(f64::NAN, 0.0, 0.0), DVec3::Y),
        (DVec3::ZERO, DVec3::new(0.0, f64::INFINITY, 0.0)),
        (DVec3::ZERO, DVec3::ZERO),
    ] {
        assert!(
            matches!(
                o.paint_half_space(p, n, skin),
                Err(Error::BadArgument { .. })
            ),
            "{p} {n}"
        );
    }
}

#[test]
fn fracture_and_recombine() {
    let mut o = lit_ball(6);
    o.solve().unwrap();
    let [mut a, mut b] = o.fracture(DVec3::ZERO, DVec3::new(1.0, 0.2, 0.1)).unwrap();
    // The tets the plane crosses are split: more tets than before.
    assert!(a.mesh().tets().len() + b.mesh().tets().len() > o.mesh().tets().len());
    // The faces between the pieces are duplicated.
    assert!(a.mesh().vertex_count() + b.mesh().vertex_count() > o.mesh().vertex_count());
    // Each piece solves on its own (its light now also enters the crack).
    a.solve().unwrap();
    b.solve().unwrap();
    b.set_transform(DAffine3::from_translation(DVec3::new(3.0, 0.0, 0.0)));
    assert!(
        (b.display_positions()[0] - b.mesh().positions()[0] - DVec3::new(3.0, 0.0, 0.0)).length()
            < 1e-12
    );
    let back = Object::recombine(&a, &b).unwrap();
    // The recombined object is the original split along the plane: every
    // tet on one side, the same volume up to the vertices snapped onto the
    // plane, and its system is a fresh assembly's.
    assert_eq!(
        back.mesh().tets().len(),
        a.mesh().tets().len() + b.mesh().tets().len()
    );
    assert!(back.mesh().tets().len() > o.mesh().tets().len());
    let volume = (back.mesh().volume() / o.mesh().volume() - 1.0).abs();
    assert!(volume < 1e-2, "{volume}");
    let mut fresh = Object::new(back.mesh().clone(), 1.0, back.media().to_vec(), 1.3).unwrap();
    fresh
        .add_light(Light::Directional {
            to_light: DVec3::new(0.3, 1.0, 0.2),
            irradiance: [1.0; 3],
        })
        .unwrap();
    for c in 0..3 {
        assert_eq!(back.matrix(c).data(), fresh.matrix(c).data());
        assert_eq!(back.matrix(c).indices(), fresh.matrix(c).indices());
        assert_eq!(back.rhs(c), fresh.rhs(c));
    }
    // Both crack faces lie on the plane: fracturing the recombined object
    // again splits nothing and gives the same pieces.
    let [a2, b2] = back
        .fracture(DVec3::ZERO, DVec3::new(1.0, 0.2, 0.1))
        .unwrap();
    assert_eq!(a2.mesh().tets(), a.mesh().tets());
    assert_eq!(a2.mesh().positions(), a.mesh().positions());
    assert_eq!(b2.mesh().tets(), b.mesh().tets());
    assert_eq!(b2.mesh().positions(), b.mesh().positions());
    // Pieces of different fractures do not recombine.
    let [c, _] = o.fracture(DVec3::ZERO, DVec3::Y).unwrap();
    assert!(matches!(
        Object::recombine(&a, &c),
        Err(Error::NotMatchingPieces)
    ));
    assert!(matches!(
        o.fracture(DVec3::splat(100.0), DVec3::X),
        Err(Error::EmptyPiece { .. })
    ));
}

#[test]
fn paint_on_a_piece_survives_recombination() {
    let o = lit_ball(5);
    let [mut a, b] = o.fracture(DVec3::ZERO, DVec3::X).unwrap();
    a.paint(&Stroke {
        points: vec![DVec3::new(-3.0, 0.0, 0.0)],
        radius: 1.0,
        medium: Medium::measured("skin1").unwrap(),
        strength: 1.0,
    })
    .unwrap();
    let back = Object::recombine(&a, &b).unwrap();
    let fresh = Object::new(back.mesh().clone(), 1.0, back.media().to_vec(), 1.3).unwrap();
    for c in 0..3 {
        assert_eq!(back.matrix(c).data(), fresh.matrix(c).data());
    }
    assert_ne!(back.media(), o.media());
}

#[test]
fn exact_plane_cut_lies_on_the_plane() {
    let mut o = lit_ball(8);
    o.solve().unwrap();
    let before = o.clone();
    let (point, normal) = (DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.2, 0.1, 1.0));
    let cut = Cut::Plane { point, normal };
    let report = o.cut(&cut, CutMethod::Exact).unwrap();
    assert!(report.split_tets > 0 && report.created_vertices > 0 && report.created_tets > 0);
    let bound = tet_diffusion::created_angle_bound(before.mesh().quality().min_dihedral);
    assert!(report.min_created_dihedral >= bound, "{report:?}");
    let (off, deviation, vertices) = check_exact_plane_cut(before.mesh(), o.mesh(), point, normal);
    eprintln!(
        "{vertices} cut vertices, at most {off:e} of the box off the plane, normals within {deviation:.2e}°; {report:?}"
    );
    // The volume left is the analytic clipped volume, up to the vertices
    // snapped onto the plane (each moved at most half an edge).
    let analytic = clipped_volume(before.mesh(), point, normal);
    let left = o.mesh().volume();
    let error = (left / analytic - 1.0).abs();
    eprintln!("volume {left} vs analytic {analytic}: {error:.2e}");
    assert!(error < 2e-3, "{error}");
    // The system is a fresh assembly's on the cut mesh, φ carried over is a
    // good warm start, and the new vertices got interpolated φ.
    let fresh = Object::new(o.mesh().clone(), 1.0, o.media().to_vec(), 1.3).unwrap();
    for c in 0..3 {
        assert_eq!(o.matrix(c).data(), fresh.matrix(c).data());
        assert!(o.phi(c).iter().all(|&p| p > 0.0));
    }
    let warm = o.solve().unwrap();
    let mut cold = fresh;
    cold.add_light(Light::Directional {
        to_light: DVec3::new(0.3, 1.0, 0.2),
        irradiance: [1.0; 3],
    })
    .unwrap();
    let c = cold.solve().unwrap();
    assert!(warm.channels[1].iterations < c.channels[1].iterations);
}

#[test]
fn exact_cuts_split_pieces_paint_alone_and_undo_by_a_clone() {
    let mut o = lit_ball(6);
    o.solve().unwrap();
    let kept = o.clone();
    let cut = Cut::Stroke {
        points: vec![DVec3::new(-9.0, 1.0, 9.0), DVec3::new(9.0, 1.3, 9.0)],
        view: DVec3::NEG_Z,
    };
    let report = o.cut(&cut, CutMethod::Exact).unwrap();
    assert!(report.split_tets > 0);
    // Every vertex lies on the kept side, those of the cut face on the
    // stroke's surface.
    for &x in o.mesh().positions() {
        assert!(cut.side(x) <= 1e-9, "{x}");
    }
    // Each piece of a split tet has its own id: painting one piece leaves
    // its siblings alone, and the painted rows equal a full assembly.
    let ids = o.mesh().original_ids().to_vec();
    let mut sorted = ids.clone();
    sorted.sort_unstable();
    sorted.dedup();
    assert_eq!(sorted.len(), ids.len());
    let stroke = Stroke {
        points: vec![DVec3::new(0.0, 1.1, 0.0)],
        radius: 0.5,
        medium: Medium::measured("ketchup").unwrap(),
        strength: 1.0,
    };
    let painted = o.paint(&stroke).unwrap();
    assert!(painted.tets > 0);
    let full = Object::new(o.mesh().clone(), 1.0, o.media().to_vec(), 1.3).unwrap();
    for c in 0..3 {
        assert_eq!(o.matrix(c).data(), full.matrix(c).data());
    }
    o.solve().unwrap();
    // Undo is the clone taken before: untouched by the cut and the paint.
    assert!(kept.mesh().tets().len() < o.mesh().tets().len() + report.removed_tets + 1);
    let again = Object::new(kept.mesh().clone(), 1.0, kept.media().to_vec(), 1.3).unwrap();
    for c in 0..3 {
        assert_eq!(kept.matrix(c).data(), again.matrix(c).data());
    }
}

#[test]
fn fracture_pieces_meet_on_the_plane_with_the_analytic_volumes() {
    let o = lit_ball(6);
    let (point, normal) = (DVec3::new(0.3, 0.0, 0.0), DVec3::new(1.0, 0.2, 0.1));
    let [a, b] = o.fracture(point, normal).unwrap();
    let below = clipped_volume(o.mesh(), point, normal);
    let above = clipped_volume(o.mesh(), point, -normal);
    for (piece, analytic, n) in [(&a, below, normal), (&b, above, -normal)] {
        let error = (piece.mesh().volume() / analytic - 1.0).abs();
        assert!(error < 5e-3, "{error}");
        check_exact_plane_cut(o.mesh(), piece.mesh(), point, n);
    }
}
