//! The painting system's document (Sec. 5.1): strokes, fills and detail
//! changes with their undo, the brush's modes, mirror and eye, and the
//! log that replays bit for bit on any number of threads.

use std::sync::Arc;

use crate::support;

use glam::Vec3;
use mesh_colors::session::{Brush, BrushMode, Changed, Dab, Edit, Occluder, PaintSession};
use mesh_colors::{Error, MeshColors, Topology};
use support::Rng;

/// A closed sphere of radius 1: an octahedron subdivided `n` times per
/// edge, projected outwards, counter-clockwise from outside.
fn sphere(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let corners = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z];
    let octants = [
        [0, 1, 2],
        [1, 3, 2],
        [3, 4, 2],
        [4, 0, 2],
        [1, 0, 5],
        [3, 1, 5],
        [4, 3, 5],
        [0, 4, 5],
    ];
    let mut positions: Vec<Vec3> = Vec::new();
    let mut faces = Vec::new();
    let index = |p: Vec3, positions: &mut Vec<Vec3>| -> u32 {
        let p = p.normalize();
        if let Some(i) = positions.iter().position(|q| q.distance(p) < 1e-5) {
            return i as u32;
        }
        positions.push(p);
        positions.len() as u32 - 1
    };
    for o in octants {
        let [a, b, c] = o.map(|k| corners[k]);
        let at =
            |i: u32, j: u32| a + (b - a) * (i as f32 / n as f32) + (c - a) * (j as f32 / n as f32);
        for i in 0..n {
            for j in 0..n - i {
                let p = [at(i, j), at(i + 1, j), at(i, j + 1)].map(|p| index(p, &mut positions));
                faces.push(p);
                if i + j + 1 < n {
                    let q = [at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]
                        .map(|p| index(p, &mut positions));
                    faces.push(q);
                }
            }
        }
    }
    (positions, faces)
}

/// Ray casts against the triangles by brute force: the test's occluder.
#[derive(Debug)]
struct Triangles {
    positions: Vec<Vec3>,
    faces: Vec<[u32; 3]>,
}

impl Occluder for Triangles {
    fn blocked(&self, eye: Vec3, point: Vec3) -> bool {
        let d = point - eye;
        let len = d.length();
        self.faces.iter().any(|f| {
            let [a, b, c] = f.map(|v| self.positions[v as usize]);
            let (e1, e2) = (b - a, c - a);
            let p = d.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-12 {
                return false;
            }
            let s = eye - a;
            let u = s.dot(p) / det;
            let q = s.cross(e1);
            let v = d.dot(q) / det;
            let t = e2.dot(q) / det;
            // Hits before the point's own neighbourhood only; a little
            // slack on the edges so that a ray through a shared vertex
            // or edge hits one of its faces.
            let e = 1e-5;
            u >= -e && v >= -e && u + v <= 1.0 + e && t > 0.0 && t * len < len - 1e-3
        })
    }
}

fn brush(mode: BrushMode, color: [f32; 3]) -> Brush {
    Brush {
        mode,
        color: color.to_vec(),
        first_channel: 0,
        strength: 1.0,
        hardness: 0.5,
        mirror_x: None,
        eye: None,
    }
}

/// A session on the sphere at resolution 4, grey, base grey.
fn session(n: u32) -> PaintSession {
    let (positions, faces) = sphere(n);
    let topology = Topology::new(positions.len(), &faces).unwrap();
    let mut colors = MeshColors::uniform(topology, 4, 3).unwrap();
    colors.samples_mut().fill(0.5);
    PaintSession::new(positions, colors, vec![0.5; 3], 100, None).unwrap()
}

fn bits(c: &MeshColors) -> Vec<u32> {
    c.samples().iter().map(|x| x.to_bits()).collect()
}

/// A random gesture on the unit sphere.
fn random_edit(rng: &mut Rng, faces: usize) -> Edit {
    let on_sphere = |rng: &mut Rng| {
        Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5).normalize_or(Vec3::Z)
    };
    match rng.below(10) {
        0..=4 => {
            let modes = [
                BrushMode::Mix,
                BrushMode::Add,
                BrushMode::Multiply,
                BrushMode::Erase,
            ];
            let mut b = brush(
                modes[rng.below(4) as usize],
                [rng.f32(), rng.f32(), rng.f32()],
            );
            b.hardness = rng.f32();
            b.strength = rng.f32();
            b.mirror_x = (rng.below(2) == 0).then_some(0.0);
            b.eye = (rng.below(2) == 0).then(|| on_sphere(rng) * 3.0);
            let start = on_sphere(rng);
            let dabs = (0..1 + rng.below(6))
                .map(|k| Dab {
                    center: (start + Vec3::splat(0.05 * k as f32)).normalize(),
                    radius: 0.1 + 0.3 * rng.f32(),
                    pressure: rng.f32(),
                })
                .collect();
            Edit::Stroke { brush: b, dabs }
        }
        5 => Edit::Fill {
            face: rng.below(faces as u64) as usize,
            brush: brush(BrushMode::Mix, [0.9, 0.1, 0.1]),
        },
        6 => Edit::Detail {
            center: on_sphere(rng),
            radius: 0.3,
            levels: if rng.below(2) == 0 { 1 } else { -1 },
        },
        7 => Edit::Undo,
        8 => Edit::Redo,
        _ => Edit::Resolution {
            level: rng.below(4) as u8,
        },
    }
}

#[test]
fn the_log_replays_bit_for_bit_on_one_and_two_threads() {
    let mut rng = Rng(7);
    let mut live = session(4);
    let faces = live.colors().face_count();
    for _ in 0..60 {
        let edit = random_edit(&mut rng, faces);
        live.apply(edit).unwrap();
    }
    assert!(live.history().undo_len() > 0);
    let replay = || {
        let s = session(4);
        let (p, c) = (s.positions().to_vec(), s.colors().clone());
        PaintSession::replay(p, c, vec![0.5; 3], 100, None, live.log()).unwrap()
    };
    let replayed = replay();
    assert_eq!(bits(replayed.colors()), bits(live.colors()));
    assert_eq!(replayed.colors(), live.colors());
    #[cfg(feature = "rayon")]
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let again = pool.install(replay);
        assert_eq!(
            bits(again.colors()),
            bits(live.colors()),
            "{threads} threads"
        );
    }
}

#[test]
fn undoing_every_step_restores_the_start_and_redoing_restores_the_end() {
    let mut rng = Rng(11);
    let mut s = session(4);
    let start = s.colors().clone();
    let faces = s.colors().face_count();
    let mut applied = 0;
    while applied < 30 {
        let edit = random_edit(&mut rng, faces);
        if matches!(edit, Edit::Undo | Edit::Redo) {
            continue;
        }
        s.apply(edit).unwrap();
        applied += 1;
    }
    let end = s.colors().clone();
    let steps = s.history().undo_len();
    for _ in 0..steps {
        s.apply(Edit::Undo).unwrap();
    }
    assert_eq!(bits(s.colors()), bits(&start));
    assert_eq!(s.colors(), &start);
    assert_eq!(s.apply(Edit::Undo).unwrap(), Changed::Nothing);
    for _ in 0..steps {
        s.apply(Edit::Redo).unwrap();
    }
    assert_eq!(s.colors(), &end);
}

#[test]
fn the_changed_samples_are_exactly_those_whose_bits_changed() {
    let mut rng = Rng(3);
    let mut s = session(4);
    let faces = s.colors().face_count();
    for _ in 0..40 {
        let before = bits(s.colors());
        let layout = s.colors().face_count() == faces;
        let edit = random_edit(&mut rng, faces);
        match s.apply(edit).unwrap() {
            Changed::Samples(list) => {
                let after = bits(s.colors());
                let c = s.colors().channels();
                let differ: Vec<u32> = (0..s.colors().sample_count() as u32)
                    .filter(|&i| {
                        let r = i as usize * c..(i as usize + 1) * c;
                        before[r.clone()] != after[r]
                    })
                    .collect();
                assert_eq!(list, differ);
            }
            Changed::Nothing => assert_eq!(before, bits(s.colors())),
            Changed::Layout(faces) => assert!(layout && !faces.is_empty()),
        }
    }
}

#[test]
fn the_falloff_is_full_in_the_hard_core_and_zero_at_the_rim() {
    let mut b = brush(BrushMode::Mix, [1.0; 3]);
    b.hardness = 0.5;
    b.strength = 0.8;
    assert_eq!(b.weight(0.0, 2.0, 1.0), 0.8);
    assert_eq!(b.weight(1.0, 2.0, 0.5), 0.4);
    assert_eq!(b.weight(2.0, 2.0, 1.0), 0.0);
    assert_eq!(b.weight(3.0, 2.0, 1.0), 0.0);
    // Decreasing and continuous through the rim.
    let w: Vec<f32> = (0..=100)
        .map(|k| b.weight(k as f32 * 0.02, 2.0, 1.0))
        .collect();
    assert!(
        w.windows(2).all(|p| p[1] <= p[0] && p[0] - p[1] < 0.05),
        "{w:?}"
    );
    assert!(b.weight(1.98, 2.0, 1.0) < 2e-3);
}

/// How many samples differ from `before`.
fn painted(s: &PaintSession, before: &[u32]) -> usize {
    let c = s.colors().channels();
    let after = bits(s.colors());
    (0..s.colors().sample_count())
        .filter(|&i| before[i * c..(i + 1) * c] != after[i * c..(i + 1) * c])
        .count()
}

#[test]
fn each_mode_blends_as_documented() {
    let dab = Dab {
        center: Vec3::Z,
        radius: 0.4,
        pressure: 1.0,
    };
    // The colour at the vertex at +z, the dab's centre.
    let mut s = session(4);
    let (f, k) = s
        .colors()
        .topology()
        .faces()
        .iter()
        .enumerate()
        .find_map(|(f, t)| {
            t.iter()
                .position(|&v| s.positions()[v as usize] == Vec3::Z)
                .map(|k| (f, k))
        })
        .unwrap();
    let mut b = [0.0f32; 3];
    b[k] = 1.0;
    let top = |s: &PaintSession| s.pick(f, b).unwrap();
    let hard = |mode, color| Brush {
        hardness: 1.0,
        ..brush(mode, color)
    };
    let stroke = |s: &mut PaintSession, brush: Brush| {
        s.apply(Edit::Stroke {
            brush,
            dabs: vec![dab],
        })
        .unwrap();
    };
    stroke(&mut s, hard(BrushMode::Mix, [1.0, 0.0, 0.25]));
    assert_eq!(top(&s), vec![1.0, 0.0, 0.25]);
    stroke(&mut s, hard(BrushMode::Add, [0.5, 0.5, 0.5]));
    assert_eq!(top(&s), vec![1.5, 0.5, 0.75]);
    stroke(&mut s, hard(BrushMode::Multiply, [0.5, 1.0, 2.0]));
    assert_eq!(top(&s), vec![0.75, 0.5, 1.5]);
    stroke(&mut s, hard(BrushMode::Erase, [0.0; 3]));
    assert_eq!(top(&s), vec![0.5, 0.5, 0.5]);
    // A brush on channel 1 alone leaves 0 and 2.
    let single = Brush {
        color: vec![0.0],
        first_channel: 1,
        ..hard(BrushMode::Mix, [0.0; 3])
    };
    stroke(&mut s, single);
    assert_eq!(top(&s), vec![0.5, 0.0, 0.5]);
}

#[test]
fn the_mirror_paints_the_reflected_side_alike() {
    let mut s = session(6);
    let before = bits(s.colors());
    let mut b = brush(BrushMode::Mix, [1.0, 0.0, 0.0]);
    b.mirror_x = Some(0.0);
    let center = Vec3::new(0.6, 0.3, 0.5).normalize();
    s.apply(Edit::Stroke {
        brush: b,
        dabs: vec![Dab {
            center,
            radius: 0.35,
            pressure: 1.0,
        }],
    })
    .unwrap();
    assert!(painted(&s, &before) > 0);
    // The sphere's vertices are symmetric in x: each painted vertex's
    // mirror image carries the same colour.
    let p = s.positions().to_vec();
    for (v, q) in p.iter().enumerate() {
        let m = p
            .iter()
            .position(|r| r.distance(Vec3::new(-q.x, q.y, q.z)) < 1e-5)
            .unwrap();
        let (a, b) = (s.colors().sample(v).unwrap(), s.colors().sample(m).unwrap());
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() < 1e-5, "vertex {v} {a:?} vs {m} {b:?}");
        }
    }
}

#[test]
fn a_brush_with_an_eye_paints_what_it_sees_not_through_the_wall() {
    // A dab as large as the sphere, seen from +z: only the near side.
    let dab = Dab {
        center: Vec3::Z,
        radius: 2.5,
        pressure: 1.0,
    };
    let mut seen = session(6);
    let before = bits(seen.colors());
    let mut b = brush(BrushMode::Mix, [1.0, 0.0, 0.0]);
    b.hardness = 1.0;
    b.eye = Some(Vec3::Z * 4.0);
    seen.apply(Edit::Stroke {
        brush: b.clone(),
        dabs: vec![dab],
    })
    .unwrap();
    let sites = seen.colors().sites();
    let positions = seen.positions().to_vec();
    let topology = seen.colors().topology().clone();
    let c = seen.colors().channels();
    let after = bits(seen.colors());
    for (i, site) in sites.iter().enumerate() {
        let p = site.position(&topology, &positions).unwrap();
        let changed = before[i * c..(i + 1) * c] != after[i * c..(i + 1) * c];
        // Facing the eye at 4 z: z > 1/4 on the unit sphere (with the
        // faceting's slack around that circle).
        if p.z > 0.35 {
            assert!(changed, "sample {i} at {p} faces the eye");
        }
        if p.z < 0.15 {
            assert!(!changed, "sample {i} at {p} is on the far side");
        }
    }
    // The wrong twin: without the eye the far side is painted too.
    let mut through = session(6);
    b.eye = None;
    through
        .apply(Edit::Stroke {
            brush: b,
            dabs: vec![dab],
        })
        .unwrap();
    assert_eq!(painted(&through, &before), through.colors().sample_count());
}

#[test]
fn an_occluder_keeps_a_hidden_part_unpainted() {
    // Two spheres on the z axis: the front one (at z = 3) hides the back
    // one's cap from an eye at z = 10.
    let (p, f) = sphere(4);
    let mut positions = p.clone();
    positions.extend(p.iter().map(|q| *q + Vec3::Z * 3.0));
    let n = p.len() as u32;
    let mut faces = f.clone();
    faces.extend(f.iter().map(|t| t.map(|v| v + n)));
    let topology = Topology::new(positions.len(), &faces).unwrap();
    let colors = MeshColors::uniform(topology, 2, 3).unwrap();
    let occluder = Arc::new(Triangles {
        positions: positions.clone(),
        faces: faces.clone(),
    });
    let mut b = brush(BrushMode::Mix, [1.0, 1.0, 1.0]);
    b.hardness = 1.0;
    b.eye = Some(Vec3::Z * 10.0);
    let edit = Edit::Stroke {
        brush: b,
        dabs: vec![Dab {
            center: Vec3::Z,
            radius: 0.5,
            pressure: 1.0,
        }],
    };
    let mut hidden = PaintSession::new(
        positions.clone(),
        colors.clone(),
        vec![0.0; 3],
        10,
        Some(occluder),
    )
    .unwrap();
    assert_eq!(hidden.apply(edit.clone()).unwrap(), Changed::Nothing);
    // Without the occluder the facing cap is painted (the wrong twin).
    let mut open = PaintSession::new(positions, colors, vec![0.0; 3], 10, None).unwrap();
    assert!(matches!(open.apply(edit).unwrap(), Changed::Samples(v) if !v.is_empty()));
}

#[test]
fn a_fill_paints_the_connected_part_only() {
    let (p, f) = sphere(3);
    let mut positions = p.clone();
    positions.extend(p.iter().map(|q| *q + Vec3::X * 5.0));
    let n = p.len() as u32;
    let mut faces = f.clone();
    faces.extend(f.iter().map(|t| t.map(|v| v + n)));
    let topology = Topology::new(positions.len(), &faces).unwrap();
    let colors = MeshColors::uniform(topology, 4, 3).unwrap();
    let mut s = PaintSession::new(positions, colors, vec![0.0; 3], 10, None).unwrap();
    s.apply(Edit::Fill {
        face: f.len() + 2,
        brush: brush(BrushMode::Mix, [0.0, 1.0, 0.0]),
    })
    .unwrap();
    for face in 0..faces.len() {
        let v = s.pick(face, [0.2, 0.3, 0.5]).unwrap();
        let want = if face < f.len() { 0.0 } else { 1.0 };
        assert_eq!(v[1], want, "face {face}");
    }
}

#[test]
fn the_detail_brush_raises_the_faces_it_touches_and_undo_restores_them() {
    let mut s = session(4);
    let start = s.colors().clone();
    let center = Vec3::new(0.0, 0.0, 1.0);
    let changed = s
        .apply(Edit::Detail {
            center,
            radius: 0.3,
            levels: 1,
        })
        .unwrap();
    assert!(
        matches!(&changed, Changed::Layout(f) if !f.is_empty()),
        "{changed:?}"
    );
    let t = s.colors().topology().clone();
    let mut raised = 0;
    for (f, face) in t.faces().iter().enumerate() {
        let near = face
            .iter()
            .any(|&v| s.positions()[v as usize].distance(center) <= 0.3);
        let level = s.colors().face_level(f).unwrap();
        if near {
            assert_eq!(level, 3, "face {f}");
            raised += 1;
        } else if level != 2 {
            // A face reaches the brush only with its interior or an edge.
            assert_eq!(level, 3, "face {f}");
        }
    }
    assert!(raised > 0);
    let Changed::Layout(listed) = changed else {
        unreachable!()
    };
    let up: Vec<usize> = (0..t.faces().len())
        .filter(|&f| s.colors().face_level(f) == Some(3))
        .collect();
    assert_eq!(listed, up);
    assert!(s.colors().sample_count() > start.sample_count());
    // The memory reported is what the samples need, not spare capacity.
    let need = 4 * s.colors().channels() * s.colors().sample_count();
    assert!(
        s.colors().memory_bytes() < need + need / 4,
        "{} for {need}",
        s.colors().memory_bytes()
    );
    s.apply(Edit::Undo).unwrap();
    assert_eq!(s.colors(), &start);
    // Lowered below the coarsest level: nothing to do.
    let mut coarse = session(2);
    coarse.apply(Edit::Resolution { level: 0 }).unwrap();
    assert_eq!(
        coarse
            .apply(Edit::Detail {
                center,
                radius: 5.0,
                levels: -1,
            })
            .unwrap(),
        Changed::Nothing
    );
}

#[test]
fn bad_gestures_are_refused_by_name_and_change_nothing() {
    let mut s = session(2);
    let before = s.colors().clone();
    let dab = Dab {
        center: Vec3::Z,
        radius: 0.3,
        pressure: 1.0,
    };
    let cases: Vec<(Edit, &str)> = vec![
        (
            Edit::Stroke {
                brush: Brush {
                    first_channel: 2,
                    ..brush(BrushMode::Mix, [1.0; 3])
                },
                dabs: vec![dab],
            },
            "brush.color",
        ),
        (
            Edit::Stroke {
                brush: Brush {
                    strength: f32::NAN,
                    ..brush(BrushMode::Mix, [1.0; 3])
                },
                dabs: vec![dab],
            },
            "brush.strength",
        ),
        (
            Edit::Stroke {
                brush: brush(BrushMode::Mix, [1.0; 3]),
                dabs: vec![Dab {
                    radius: -1.0,
                    ..dab
                }],
            },
            "dab.radius",
        ),
        (
            Edit::Stroke {
                brush: brush(BrushMode::Mix, [1.0; 3]),
                dabs: vec![
                    dab,
                    Dab {
                        pressure: 2.0,
                        ..dab
                    },
                ],
            },
            "dab.pressure",
        ),
        (
            Edit::Detail {
                center: Vec3::NAN,
                radius: 1.0,
                levels: 1,
            },
            "dab.center",
        ),
        (Edit::Resolution { level: 200 }, "level"),
        (
            Edit::Fill {
                face: 10_000,
                brush: brush(BrushMode::Mix, [1.0; 3]),
            },
            "face 10000",
        ),
    ];
    for (edit, needle) in cases {
        let e = s.apply(edit.clone()).unwrap_err();
        assert!(e.to_string().contains(needle), "{edit:?}: {e}");
    }
    assert_eq!(s.colors(), &before);
    assert!(s.log().is_empty());
    assert!(matches!(
        PaintSession::new(vec![Vec3::ZERO; 3], before.clone(), vec![0.0; 2], 1, None),
        Err(Error::ChannelMismatch { .. })
    ));
}

#[test]
fn a_stroke_painted_as_its_dabs_arrive_is_one_step_that_replays_alike() {
    let mut rng = Rng(21);
    let dabs: Vec<Dab> = (0..12)
        .map(|k| Dab {
            center: Vec3::new(0.1 * k as f32 - 0.6, 0.2, 0.9).normalize(),
            radius: 0.2,
            pressure: 0.5 + 0.5 * rng.f32(),
        })
        .collect();
    let mut b = brush(BrushMode::Mix, [0.9, 0.2, 0.1]);
    b.mirror_x = Some(0.0);
    let mut live = session(4);
    let start = live.colors().clone();
    live.begin_stroke(b.clone()).unwrap();
    let mut union = Vec::new();
    for chunk in dabs.chunks(5) {
        let before = bits(live.colors());
        match live.add_dabs(chunk).unwrap() {
            Changed::Samples(list) => {
                // Exactly the samples this chunk changed.
                let c = live.colors().channels();
                let after = bits(live.colors());
                for i in 0..live.colors().sample_count() {
                    let differs = before[i * c..(i + 1) * c] != after[i * c..(i + 1) * c];
                    assert_eq!(
                        differs,
                        list.binary_search(&(i as u32)).is_ok(),
                        "sample {i}"
                    );
                }
                union.extend(list);
            }
            other => panic!("{other:?}"),
        }
    }
    assert!(
        live.add_dabs(&[Dab {
            radius: 0.0,
            ..dabs[0]
        }])
        .is_err()
    );
    live.end_stroke();
    assert_eq!(live.history().undo_len(), 1);
    assert_eq!(
        live.log(),
        &[Edit::Stroke {
            brush: b.clone(),
            dabs: dabs.clone()
        }]
    );
    let mut whole = session(4);
    whole.apply(Edit::Stroke { brush: b, dabs }).unwrap();
    assert_eq!(bits(whole.colors()), bits(live.colors()));
    live.apply(Edit::Undo).unwrap();
    assert_eq!(live.colors(), &start);
    // Dabs with no stroke begun are refused.
    assert!(live.add_dabs(&[]).is_err());
}
