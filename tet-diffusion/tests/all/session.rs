//! The interactive session: coalescing, progressive solves, the kept
//! hierarchy, undo/redo restoring the object and `φ` exactly, the memory
//! budget, and bit-identical replay on 1 and 2 threads.

use crate::common;

use std::sync::atomic::AtomicBool;

use common::*;
use tet_diffusion::glam::DVec3;
use tet_diffusion::{
    Cut, Edit, Error, Light, Medium, Method, Object, Session, SessionOptions, Stroke,
};

/// A lit marble ball solved with the V-cycle: these tests are about the
/// kept hierarchy (its refresh, undo, coarse previews), which the
/// automatic choice would not build for so small a system.
fn lit_ball(n: usize) -> Object {
    let mut o =
        Object::homogeneous(ball(n, 5.0), 1.0, Medium::measured("marble").unwrap(), 1.3).unwrap();
    o.settings.method = Method::VCyclePcg;
    o.add_light(Light::Directional {
        to_light: DVec3::new(0.3, 1.0, 0.2),
        irradiance: [1.0; 3],
    })
    .unwrap();
    o
}

fn dab(at: DVec3, material: &str) -> Stroke {
    Stroke {
        points: vec![at],
        radius: 1.0,
        medium: Medium::measured(material).unwrap(),
        strength: 1.0,
    }
}

/// A brush as a user paints with: a small fraction of the object per dab.
fn small_dab(at: DVec3) -> Stroke {
    Stroke {
        radius: 0.4,
        ..dab(at, "ketchup")
    }
}

fn light(x: f64) -> Edit {
    Edit::Lights(vec![Light::Directional {
        to_light: DVec3::new(x, 1.0, 0.3),
        irradiance: [1.0; 3],
    }])
}

fn stroke_cut() -> Edit {
    Edit::Cut(Cut::Stroke {
        points: vec![DVec3::new(-6.0, -6.0, 0.0), DVec3::new(6.0, 3.0, 0.0)],
        view: DVec3::new(0.0, 0.0, -1.0),
    })
}

/// Per piece: positions, tets, matrix values, φ (bits), media and lights.
type PieceBits = (
    Vec<[u64; 3]>,
    Vec<[u32; 4]>,
    Vec<u64>,
    Vec<[u64; 3]>,
    String,
);

/// Everything undo must restore: per piece the mesh, media, matrices'
/// values, lights and `φ` (bits).
#[derive(Debug, PartialEq)]
struct Snapshot {
    pieces: Vec<PieceBits>,
    offsets: Vec<[u64; 3]>,
}

fn snapshot(s: &Session) -> Snapshot {
    let bits = |v: DVec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
    Snapshot {
        pieces: s
            .pieces()
            .iter()
            .map(|o| {
                let m = o.mesh();
                let matrices = (0..3)
                    .flat_map(|c| o.matrix(c).data().iter().map(|x| x.to_bits()))
                    .collect();
                let phi = o.fluence().iter().map(|p| p.map(f64::to_bits)).collect();
                (
                    m.positions().iter().map(|&p| bits(p)).collect(),
                    m.tets().to_vec(),
                    matrices,
                    phi,
                    format!("{:?} {:?}", o.media(), o.lights()),
                )
            })
            .collect(),
        offsets: s.offsets().iter().map(|&o| bits(o)).collect(),
    }
}

fn apply_all(s: &mut Session) -> Vec<tet_diffusion::Applied> {
    let mut out = Vec::new();
    while let Some(r) = s.apply_pending() {
        out.push(r.unwrap());
        s.refine_now().unwrap();
    }
    out
}

#[test]
fn edits_coalesce_lights_keep_the_last_and_paint_dabs_are_all_painted() {
    let mut s = Session::new(lit_ball(6), SessionOptions::default()).unwrap();
    for k in 0..5 {
        s.push(light(k as f64 * 0.2)).unwrap();
    }
    for k in 0..3 {
        s.push(Edit::Paint(vec![dab(
            DVec3::new(k as f64, 0.0, 4.0),
            "ketchup",
        )]))
        .unwrap();
    }
    s.push(light(-1.0)).unwrap();
    let applied = apply_all(&mut s);
    let counts: Vec<(&str, usize)> = applied
        .iter()
        .map(|a| (a.edit.name(), a.coalesced))
        .collect();
    assert_eq!(counts, [("lights", 5), ("paint", 3), ("lights", 1)]);
    match &applied[0].edit {
        Edit::Lights(l) => {
            assert!(matches!(l[0], Light::Directional { to_light, .. } if to_light.x == 0.8))
        }
        other => panic!("{other:?}"),
    }
    // The three dabs together paint what painting them one by one does.
    let mut one_by_one = lit_ball(6);
    for k in 0..3 {
        one_by_one
            .paint(&dab(DVec3::new(k as f64, 0.0, 4.0), "ketchup"))
            .unwrap();
    }
    assert_eq!(s.pieces()[0].media(), one_by_one.media());
    assert_eq!(s.log().edits.len(), 3);
}

#[test]
fn bad_edits_are_refused_when_pushed_and_leave_the_session_as_it_was() {
    let mut s = Session::new(lit_ball(5), SessionOptions::default()).unwrap();
    let before = snapshot(&s);
    let mut nan = dab(DVec3::ZERO, "apple");
    nan.points[0].y = f64::NAN;
    let e = s.push(Edit::Paint(vec![nan])).unwrap_err();
    assert!(e.to_string().contains("paint stroke point 0"), "{e}");
    let e = s
        .push(Edit::Lights(vec![Light::Directional {
            to_light: DVec3::ZERO,
            irradiance: [1.0; 3],
        }]))
        .unwrap_err();
    assert!(matches!(e, Error::BadArgument { .. }), "{e}");
    assert_eq!(s.pending(), 0);
    // Errors the object finds: the session is unchanged and goes on.
    s.push(Edit::Move {
        piece: 3,
        offset: DVec3::X,
    })
    .unwrap();
    let e = s.apply_pending().unwrap().unwrap_err();
    assert!(e.to_string().contains("piece"), "{e}");
    s.push(Edit::Cut(Cut::Plane {
        point: DVec3::splat(-100.0),
        normal: DVec3::X,
    }))
    .unwrap();
    assert!(matches!(
        s.apply_pending().unwrap(),
        Err(Error::CutRemovesEverything { .. })
    ));
    s.push(Edit::Recombine { a: 0, b: 0 }).unwrap_err();
    assert_eq!(snapshot(&s), before);
    assert!(!s.can_undo());
}

#[test]
fn the_hierarchy_is_built_once_across_paint_light_and_material_edits() {
    let mut s = Session::new(lit_ball(8), SessionOptions::default()).unwrap();
    s.refine_now().unwrap();
    assert_eq!(s.pieces()[0].hierarchy_builds(), 1);
    for k in 0..4 {
        s.push(light(0.1 * k as f64)).unwrap();
        apply_all(&mut s);
        s.push(Edit::Paint(vec![dab(DVec3::new(0.0, 0.0, 4.0), "skin1")]))
            .unwrap();
        apply_all(&mut s);
    }
    s.push(Edit::Material(Medium::measured("apple").unwrap()))
        .unwrap();
    let a = apply_all(&mut s);
    assert!(a[0].solves.iter().all(|r| !r.hierarchy_built));
    assert_eq!(s.pieces()[0].hierarchy_builds(), 1);
    // A cut builds a new one, once.
    s.push(stroke_cut()).unwrap();
    let a = apply_all(&mut s);
    assert!(a[0].solves[0].hierarchy_built && a[0].topology_changed);
    assert_eq!(s.pieces()[0].hierarchy_builds(), 2);
    s.push(light(0.7)).unwrap();
    apply_all(&mut s);
    assert_eq!(s.pieces()[0].hierarchy_builds(), 2);
    // The kept hierarchy still solves the painted object to the
    // tolerance: the same φ (to it) as a fresh object's solve.
    let mut fresh = s.pieces()[0].clone();
    fresh.forget_hierarchy();
    fresh
        .set_phi([0, 1, 2].map(|c| vec![0.0; fresh.phi(c).len()]))
        .unwrap();
    fresh.solve().unwrap();
    for c in 0..3 {
        let e = rel_l2(fresh.mesh(), s.pieces()[0].phi(c), fresh.phi(c));
        assert!(e < 1e-5, "channel {c}: {e}");
    }
}

#[test]
fn the_coarse_result_comes_first_and_refines_to_the_plain_solve() {
    let mut s = Session::new(lit_ball(8), SessionOptions::default()).unwrap();
    s.refine_now().unwrap();
    s.push(Edit::Paint(vec![dab(DVec3::new(0.0, 4.0, 0.0), "ketchup")]))
        .unwrap();
    let a = s.apply_pending().unwrap().unwrap();
    let coarse = a.solves[0].channels;
    assert!(coarse.iter().all(|r| r.converged() && r.residual <= 1e-2));
    assert!(s.needs_refinement());
    let fine = s.refine_now().unwrap();
    assert!(!s.needs_refinement());
    assert!(fine[0].channels.iter().all(|r| r.residual <= 1e-6));
    let mut plain = lit_ball(8);
    plain
        .paint(&dab(DVec3::new(0.0, 4.0, 0.0), "ketchup"))
        .unwrap();
    plain.solve().unwrap();
    for c in 0..3 {
        let e = rel_l2(plain.mesh(), s.pieces()[0].phi(c), plain.phi(c));
        assert!(e < 1e-5, "channel {c}: {e}");
    }
}

#[test]
fn a_cut_is_seen_before_its_solve_with_the_phi_carried_over() {
    let mut s = Session::new(lit_ball(8), SessionOptions::default()).unwrap();
    s.refine_now().unwrap();
    let before = s.pieces()[0].fluence();
    s.push(stroke_cut()).unwrap();
    let mut seen = Vec::new();
    let a = s
        .apply_pending_with(|s, edit| {
            let o = &s.pieces()[0];
            seen.push((edit.name(), o.mesh().tets().len(), o.fluence()));
        })
        .unwrap()
        .unwrap();
    assert!(a.topology_changed);
    let [(name, tets, phi)] = &seen[..] else {
        panic!("called {} times", seen.len());
    };
    assert_eq!(*name, "cut");
    // The cut's mesh, not the solve's φ: the solve came after.
    let after = &s.pieces()[0];
    assert_eq!(*tets, after.mesh().tets().len());
    assert!(*tets < lit_ball(8).mesh().tets().len());
    assert_eq!(phi.len(), after.fluence().len());
    assert_ne!(*phi, after.fluence());
    assert!(a.solves[0].channels.iter().all(|r| r.iterations > 0));
    // The φ seen is the one before, carried over: a vertex away from
    // the cut keeps its value.
    let kept = phi.iter().filter(|v| before.contains(v)).count();
    assert!(kept * 2 > phi.len(), "{kept} of {}", phi.len());
    // An edit that fails is not seen.
    s.push(Edit::Cut(Cut::Plane {
        point: DVec3::splat(-100.0),
        normal: DVec3::X,
    }))
    .unwrap();
    let mut called = false;
    assert!(s.apply_pending_with(|_, _| called = true).unwrap().is_err());
    assert!(!called);
}

#[test]
fn a_cancelled_refinement_puts_the_coarse_result_back() {
    let mut s = Session::new(lit_ball(8), SessionOptions::default()).unwrap();
    s.push(light(0.5)).unwrap();
    s.apply_pending().unwrap().unwrap();
    let coarse = snapshot(&s);
    let cancel = AtomicBool::new(true);
    let (_, finished) = s.refine(&cancel).unwrap();
    assert!(!finished && s.needs_refinement());
    assert_eq!(snapshot(&s), coarse);
    assert!(!s.log().edits[0].refined);
    // A deadline in the past interrupts a plain solve, which says so.
    let mut o = s.pieces()[0].clone();
    let r = o
        .solve_monitored(&tet_diffusion::Budget {
            deadline: Some(std::time::Instant::now()),
            tolerance: Some(1e-12),
            ..Default::default()
        })
        .unwrap();
    assert!(r.interrupted);
}

#[test]
fn undo_and_redo_restore_the_object_and_phi_exactly() {
    let mut s = Session::new(lit_ball(7), SessionOptions::default()).unwrap();
    s.refine_now().unwrap();
    let edits = vec![
        Edit::Paint(vec![
            dab(DVec3::new(0.0, 0.0, 4.0), "ketchup"),
            dab(DVec3::new(0.5, 0.0, 4.0), "ketchup"),
        ]),
        light(-0.4),
        Edit::Lights(vec![Light::Point {
            position: DVec3::new(0.0, 9.0, 0.0),
            intensity: [50.0; 3],
        }]),
        Edit::Material(Medium::measured("skin2").unwrap()),
        stroke_cut(),
        Edit::Paint(vec![dab(DVec3::new(1.0, -1.0, 0.0), "apple")]),
        Edit::Fracture {
            piece: 0,
            point: DVec3::ZERO,
            normal: DVec3::new(1.0, 0.2, 0.0),
        },
        Edit::Move {
            piece: 1,
            offset: DVec3::new(3.0, 0.0, 0.0),
        },
        Edit::Paint(vec![dab(DVec3::new(4.0, 0.0, 0.0), "skin1")]),
        Edit::Recombine { a: 0, b: 1 },
    ];
    let mut states = vec![snapshot(&s)];
    for e in &edits {
        s.push(e.clone()).unwrap();
        apply_all(&mut s);
        states.push(snapshot(&s));
    }
    assert_eq!(s.pieces().len(), 1);
    for k in (0..edits.len()).rev() {
        let undone = s.undo().unwrap().unwrap();
        assert_eq!(undone.name(), edits[k].name());
        assert!(
            snapshot(&s) == states[k],
            "undo of edit {k} ({})",
            edits[k].name()
        );
    }
    assert!(s.undo().unwrap().is_none());
    for k in 0..edits.len() {
        s.redo().unwrap().unwrap();
        assert!(
            snapshot(&s) == states[k + 1],
            "redo of edit {k} ({})",
            edits[k].name()
        );
    }
    assert!(s.redo().unwrap().is_none());
    // A new edit after an undo drops the redo branch.
    s.undo().unwrap();
    s.push(light(0.9)).unwrap();
    apply_all(&mut s);
    assert!(!s.can_redo());
    assert_eq!(s.history().0.len(), edits.len());
}

#[test]
fn a_redone_coarse_edit_is_refined_when_idle_as_a_replay_is() {
    let mut s = Session::new(lit_ball(7), SessionOptions::default()).unwrap();
    s.refine_now().unwrap();
    s.push(light(0.3)).unwrap();
    apply_all(&mut s);
    // The last edit keeps its coarse result: undone before any refinement.
    s.push(Edit::Paint(vec![dab(DVec3::new(0.0, 0.0, 4.0), "ketchup")]))
        .unwrap();
    s.apply_pending().unwrap().unwrap();
    assert!(s.needs_refinement());
    let coarse = snapshot(&s);
    s.undo().unwrap().unwrap();
    assert!(!s.needs_refinement());
    s.undo().unwrap().unwrap();
    // With an edit still to redo, the redone one stays as it was logged.
    s.redo().unwrap().unwrap();
    assert!(!s.needs_refinement() && s.can_redo());
    s.redo().unwrap().unwrap();
    assert!(snapshot(&s) == coarse);
    assert!(
        s.needs_refinement(),
        "the redone coarse paint waits for refinement"
    );
    s.refine_now().unwrap();
    assert!(s.log().edits[1].refined);
    let replayed = Session::replay(lit_ball(7), SessionOptions::default(), &s.log()).unwrap();
    assert!(snapshot(&replayed) == snapshot(&s));
    assert!(snapshot(&s) != coarse);
}

#[test]
fn the_edits_of_one_gesture_undo_and_redo_as_one_step() {
    let mut s = Session::new(lit_ball(7), SessionOptions::default()).unwrap();
    s.refine_now().unwrap();
    let start = snapshot(&s);
    // One paint stroke sent as three messages, applied one by one (a
    // fast machine solves each before the next arrives).
    for k in 0..3 {
        let dab = dab(DVec3::new(0.4 * k as f64, 0.0, 4.0), "ketchup");
        s.push_in(Edit::Paint(vec![dab]), Some(5)).unwrap();
        apply_all(&mut s);
    }
    let painted = snapshot(&s);
    // One light drag, then a lone material change.
    for k in 0..3 {
        s.push_in(light(0.2 * k as f64), Some(6)).unwrap();
        apply_all(&mut s);
    }
    let lit = snapshot(&s);
    s.push(Edit::Material(Medium::measured("skin1").unwrap()))
        .unwrap();
    apply_all(&mut s);
    assert_eq!(s.history().0, ["paint", "lights", "material"]);
    assert_eq!(s.log().edits.len(), 7);
    // The log keeps the gestures: a replay groups its undo alike.
    let mut replayed = Session::replay(lit_ball(7), SessionOptions::default(), &s.log()).unwrap();
    assert!(snapshot(&replayed) == snapshot(&s));
    for session in [&mut s, &mut replayed] {
        assert_eq!(session.undo().unwrap().unwrap().name(), "material");
        assert!(snapshot(session) == lit);
        assert_eq!(session.undo().unwrap().unwrap().name(), "lights");
        assert!(
            snapshot(session) == painted,
            "the whole light drag is undone"
        );
        session.undo().unwrap().unwrap();
        assert!(snapshot(session) == start, "the whole stroke is undone");
        assert!(!session.can_undo());
        assert_eq!(session.history().1, ["paint", "lights", "material"]);
        session.redo().unwrap().unwrap();
        assert!(snapshot(session) == painted, "the whole stroke is redone");
        session.redo().unwrap().unwrap();
        assert!(snapshot(session) == lit);
    }
    // Edits of different gestures do not coalesce; of one, they do.
    s.push_in(light(0.5), Some(8)).unwrap();
    s.push_in(light(0.6), Some(9)).unwrap();
    assert_eq!(s.apply_pending().unwrap().unwrap().coalesced, 1);
    assert_eq!(s.apply_pending().unwrap().unwrap().coalesced, 1);
    s.push_in(light(0.7), Some(10)).unwrap();
    s.push_in(light(0.8), Some(10)).unwrap();
    assert_eq!(s.apply_pending().unwrap().unwrap().coalesced, 2);
}

fn paint_steps(s: &mut Session, steps: usize) -> Vec<Snapshot> {
    let mut states = vec![snapshot(s)];
    for k in 0..steps {
        let x = -3.0 + 0.3 * k as f64;
        s.push(Edit::Paint(vec![small_dab(DVec3::new(x, 0.0, 4.0))]))
            .unwrap();
        apply_all(s);
        states.push(snapshot(s));
    }
    states
}

#[test]
fn undo_of_20_paint_steps_holds_at_most_a_tenth_of_the_object_and_restores_phi_exactly() {
    let mut s = Session::new(lit_ball(8), SessionOptions::default()).unwrap();
    s.refine_now().unwrap();
    let states = paint_steps(&mut s, 20);
    let memory = s.undo_memory();
    assert_eq!(
        memory.object_bytes,
        s.pieces()[0].memory_bytes(),
        "{memory:?}"
    );
    eprintln!(
        "undo of 20 paint steps: {} of {} bytes ({:.1}%)",
        memory.undo_bytes,
        memory.object_bytes,
        100.0 * memory.fraction()
    );
    // The budget of #26: 20 paint steps of undo ≤ 10% of the object.
    assert!(
        memory.fraction() <= 0.10,
        "{memory:?}: {}",
        memory.fraction()
    );
    // φ copies: the anchors before edits 0, 8 and 16, and the newest.
    let phi_copy = 3 * 8 * s.pieces()[0].mesh().vertex_count();
    assert_eq!(memory.phi_bytes, 4 * phi_copy, "{memory:?}");
    assert_eq!(
        memory.media_bytes + memory.phi_bytes + memory.hierarchy_bytes,
        memory.undo_bytes
    );
    // Every undo gives the state before its paint bit for bit (φ
    // included, recomputed from an anchor where no copy is kept) ...
    for k in (0..20).rev() {
        s.undo().unwrap().unwrap();
        assert!(snapshot(&s) == states[k], "undo to {k}");
    }
    assert!(s.undo().unwrap().is_none());
    // ... and every redo the state after it.
    for k in 0..20 {
        s.redo().unwrap().unwrap();
        assert!(snapshot(&s) == states[k + 1], "redo to {k}");
    }
    // Undo after a redo, and in the middle of an interval.
    for k in (14..20).rev() {
        s.undo().unwrap().unwrap();
        assert!(snapshot(&s) == states[k], "second undo to {k}");
    }
    // Every edit keeping φ (the old way) holds far more.
    let mut every = Session::new(
        lit_ball(8),
        SessionOptions {
            phi_interval: 1,
            ..SessionOptions::default()
        },
    )
    .unwrap();
    every.refine_now().unwrap();
    let again = paint_steps(&mut every, 20);
    assert!(again == states, "the anchor interval changes no result");
    assert!(every.undo_memory().undo_bytes > 3 * memory.undo_bytes);
}

#[test]
fn the_budget_drops_the_oldest_entries_and_what_stays_undoes_exactly() {
    let mut s = Session::new(lit_ball(8), SessionOptions::default()).unwrap();
    paint_steps(&mut s, 20);
    let full = s.undo_bytes();
    let tight = SessionOptions {
        undo_budget_bytes: full / 2,
        ..SessionOptions::default()
    };
    let mut t = Session::new(lit_ball(8), tight).unwrap();
    let states = paint_steps(&mut t, 20);
    assert!(t.undo_bytes() <= full / 2, "{} vs {full}", t.undo_bytes());
    let kept = t.history().0.len();
    assert!((1..20).contains(&kept), "{kept}");
    assert_eq!(t.log().edits.len(), 20);
    for k in (20 - kept..20).rev() {
        t.undo().unwrap().unwrap();
        assert!(snapshot(&t) == states[k], "undo to {k}");
    }
    assert!(t.undo().unwrap().is_none());
    // A budget below one entry keeps only the newest; the log keeps all.
    let one = SessionOptions {
        undo_budget_bytes: 1,
        ..SessionOptions::default()
    };
    let mut u = Session::new(lit_ball(6), one).unwrap();
    let states = (0..4)
        .map(|k| {
            u.push(light(0.1 * k as f64)).unwrap();
            apply_all(&mut u);
            snapshot(&u)
        })
        .collect::<Vec<_>>();
    assert_eq!(u.history().0.len(), 1);
    assert_eq!(u.log().edits.len(), 4);
    u.undo().unwrap().unwrap();
    assert!(snapshot(&u) == states[2]);
}

#[test]
fn a_large_paint_refreshes_the_kept_operators_and_still_converges_fast() {
    let mut s = Session::new(lit_ball(10), SessionOptions::default()).unwrap();
    s.refine_now().unwrap();
    // Reference: iterations of a solve from zero with a fresh hierarchy.
    let fresh_iterations = |o: &Object| {
        let mut f = o.clone();
        f.forget_hierarchy();
        f.set_phi([0, 1, 2].map(|c| vec![0.0; o.phi(c).len()]))
            .unwrap();
        let r = f.solve().unwrap();
        (r.channels.map(|c| c.iterations), f)
    };
    let (before, _) = fresh_iterations(&s.pieces()[0]);
    // Half the ball painted with skin (σa 30–100× marble's).
    let big = Stroke {
        points: vec![DVec3::new(0.0, 0.0, 2.5)],
        radius: 2.5,
        medium: Medium::measured("skin1").unwrap(),
        strength: 1.0,
    };
    s.push(Edit::Paint(vec![big])).unwrap();
    let a = s.apply_pending().unwrap().unwrap();
    assert!(a.solves[0].hierarchy_refreshed, "{:?}", a.solves[0]);
    assert!(!a.solves[0].hierarchy_built);
    let fine = s.refine_now().unwrap();
    let o = &s.pieces()[0];
    assert_eq!((o.hierarchy_builds(), o.hierarchy_refreshes()), (1, 1));
    // The replaced operators are not stored: undo re-derives them.
    assert_eq!(s.undo_memory().hierarchy_bytes, 0);
    // The warm-started refinement with the refreshed operators needs no
    // more iterations than a fresh hierarchy from zero.
    let (after, plain) = fresh_iterations(o);
    for c in 0..3 {
        let it = fine[0].channels[c].iterations;
        assert!(
            it <= after[c].max(before[c]),
            "channel {c}: {it} vs {after:?}"
        );
        let e = rel_l2(plain.mesh(), o.phi(c), plain.phi(c));
        assert!(e < 1e-5, "channel {c}: {e}");
    }
    // Undo puts the kept operators back (and φ), so a later edit solves
    // as a replay of the log without the big paint would.
    let initial = {
        let mut r = Session::new(lit_ball(10), SessionOptions::default()).unwrap();
        r.refine_now().unwrap();
        r
    };
    s.undo().unwrap().unwrap();
    assert!(snapshot(&s) == snapshot(&initial));
    s.push(Edit::Paint(vec![small_dab(DVec3::new(0.0, 0.0, 4.0))]))
        .unwrap();
    apply_all(&mut s);
    let log = s.log();
    let replayed = Session::replay(lit_ball(10), SessionOptions::default(), &log).unwrap();
    assert!(snapshot(&replayed) == snapshot(&s));
    assert_eq!(s.pieces()[0].hierarchy_refreshes(), 1);
}

/// Small paints, a big one (which refreshes the kept operators), small
/// paints: the snapshots after each, and whether the big one refreshed.
fn paints_across_a_refresh(s: &mut Session) -> (Vec<Snapshot>, bool) {
    let mut states = vec![snapshot(s)];
    let mut refreshed = false;
    for k in 0..9 {
        let x = -3.0 + 0.5 * k as f64;
        let stroke = if k == 4 {
            Stroke {
                points: vec![DVec3::new(0.0, 0.0, 2.5)],
                radius: 2.5,
                ..dab(DVec3::ZERO, "skin1")
            }
        } else {
            small_dab(DVec3::new(x, 0.0, 4.0))
        };
        s.push(Edit::Paint(vec![stroke])).unwrap();
        let a = apply_all(s);
        refreshed |= a[0].solves[0].hierarchy_refreshed;
        states.push(snapshot(s));
    }
    (states, refreshed)
}

/// After undoing: a new small paint gives what a replay of the log gives,
/// so the hierarchy undo put back is the one of that time (a wrong one
/// changes the coarse solve's bits).
fn continue_as_replay(s: &mut Session, options: SessionOptions) {
    s.push(Edit::Paint(vec![small_dab(DVec3::new(1.0, 1.0, 4.0))]))
        .unwrap();
    apply_all(s);
    let replayed = Session::replay(lit_ball(10), options, &s.log()).unwrap();
    assert!(snapshot(&replayed) == snapshot(s));
}

#[test]
fn undo_across_a_refresh_stores_no_hierarchy_and_restores_the_bits() {
    let options = SessionOptions::default();
    let mut s = Session::new(lit_ball(10), options).unwrap();
    s.refine_now().unwrap();
    let (states, refreshed) = paints_across_a_refresh(&mut s);
    assert!(refreshed, "the big paint must refresh for this test");
    let memory = s.undo_memory();
    assert_eq!(memory.hierarchy_bytes, 0, "{memory:?}");
    assert_eq!(memory.undo_bytes, memory.media_bytes + memory.phi_bytes);
    for k in (0..9).rev() {
        s.undo().unwrap().unwrap();
        assert!(snapshot(&s) == states[k], "undo to {k}");
    }
    for k in 0..9 {
        s.redo().unwrap().unwrap();
        assert!(snapshot(&s) == states[k + 1], "redo to {k}");
    }
    // Back to before the big paint (φ recomputed from an anchor on the
    // way: the edits re-done with the re-derived hierarchy), then on.
    for k in (4..9).rev() {
        s.undo().unwrap().unwrap();
        assert!(snapshot(&s) == states[k], "second undo to {k}");
    }
    continue_as_replay(&mut s, options);
}

#[test]
fn undo_across_a_refresh_after_the_budget_dropped_the_older_entries() {
    let mut full = Session::new(lit_ball(10), SessionOptions::default()).unwrap();
    full.refine_now().unwrap();
    paints_across_a_refresh(&mut full);
    // A budget that drops the first small paints, not the big one.
    let options = SessionOptions {
        undo_budget_bytes: full.undo_bytes() * 3 / 4,
        phi_interval: 1,
        ..SessionOptions::default()
    };
    let mut s = Session::new(lit_ball(10), options).unwrap();
    s.refine_now().unwrap();
    let (states, _) = paints_across_a_refresh(&mut s);
    let kept = s.history().0.len();
    assert!((2..6).contains(&kept), "{kept} entries kept");
    assert_eq!(s.undo_memory().hierarchy_bytes, 0);
    for k in (9 - kept..9).rev() {
        s.undo().unwrap().unwrap();
        assert!(snapshot(&s) == states[k], "undo to {k}");
    }
    assert!(s.undo().unwrap().is_none());
    continue_as_replay(&mut s, options);
}

#[test]
fn the_log_replays_bit_identically_on_one_and_two_threads() {
    let build = || {
        let mut s = Session::new(lit_ball(7), SessionOptions::default()).unwrap();
        s.refine_now().unwrap();
        s.push(Edit::Paint(vec![dab(DVec3::new(0.0, 2.0, 3.0), "ketchup")]))
            .unwrap();
        s.apply_pending().unwrap().unwrap();
        // Not refined: new input came first.
        s.push(light(0.6)).unwrap();
        s.push(light(0.2)).unwrap();
        s.apply_pending().unwrap().unwrap();
        s.refine_now().unwrap();
        s.push(stroke_cut()).unwrap();
        s.apply_pending().unwrap().unwrap();
        s.refine_now().unwrap();
        s.push(Edit::Paint(vec![dab(DVec3::new(1.0, 0.0, 0.0), "skin1")]))
            .unwrap();
        s.apply_pending().unwrap().unwrap();
        s.refine_now().unwrap();
        s.undo().unwrap();
        s
    };
    let live = build();
    let log = live.log();
    assert_eq!(
        log.edits.iter().map(|l| l.refined).collect::<Vec<_>>(),
        [false, true, true]
    );
    let replay = |threads: usize| {
        on_threads(threads, || {
            Session::replay(lit_ball(7), SessionOptions::default(), &log).unwrap()
        })
    };
    let one = replay(1);
    let two = replay(2);
    assert!(snapshot(&one) == snapshot(&live));
    assert!(snapshot(&two) == snapshot(&live));
}

/// Options under which the ball's first results come from a coarse level
/// of its hierarchy (as a large mesh's do by default).
fn coarse_first() -> SessionOptions {
    SessionOptions {
        preview_above: 100,
        preview_rows: 300,
        ..SessionOptions::default()
    }
}

#[test]
fn a_coarse_level_first_result_refines_to_the_plain_solve_and_replays_exactly() {
    let build = || {
        let mut s = Session::new(lit_ball(8), coarse_first()).unwrap();
        let mut levels = Vec::new();
        s.push(Edit::Paint(vec![dab(DVec3::new(0.0, 4.0, 0.0), "ketchup")]))
            .unwrap();
        levels.push(s.apply_pending().unwrap().unwrap().solves[0].coarse_level);
        // Not refined: the next edit warm-starts from the coarse result.
        s.push(light(0.6)).unwrap();
        levels.push(s.apply_pending().unwrap().unwrap().solves[0].coarse_level);
        let cancel = AtomicBool::new(true);
        let coarse = snapshot(&s);
        assert!(!s.refine(&cancel).unwrap().1);
        assert!(snapshot(&s) == coarse, "a cancelled refinement keeps it");
        s.refine_now().unwrap();
        s.push(Edit::Paint(vec![dab(DVec3::new(1.0, 0.0, 4.0), "skin1")]))
            .unwrap();
        levels.push(s.apply_pending().unwrap().unwrap().solves[0].coarse_level);
        (s, levels)
    };
    let (mut live, levels) = build();
    assert!(
        levels.iter().all(|l| l.is_some_and(|l| l >= 1)),
        "{levels:?}"
    );
    let log = live.log();
    let replay = |threads: usize| {
        on_threads(threads, || {
            Session::replay(lit_ball(8), coarse_first(), &log).unwrap()
        })
    };
    assert!(snapshot(&replay(1)) == snapshot(&live));
    assert!(snapshot(&replay(2)) == snapshot(&live));
    // Undo and redo give the coarse results' bits back.
    let after = snapshot(&live);
    live.undo().unwrap();
    live.undo().unwrap();
    live.redo().unwrap();
    live.redo().unwrap();
    assert!(snapshot(&live) == after);
    // The preview is close to the solution, and refines to it.
    let preview = live.pieces()[0].clone();
    let mut refined = preview.clone();
    refined.solve().unwrap();
    let mut plain = lit_ball(8);
    plain
        .paint(&dab(DVec3::new(0.0, 4.0, 0.0), "ketchup"))
        .unwrap();
    plain.clear_lights();
    if let Edit::Lights(l) = light(0.6) {
        plain.add_light(l[0].clone()).unwrap();
    }
    plain
        .paint(&dab(DVec3::new(1.0, 0.0, 4.0), "skin1"))
        .unwrap();
    plain.solve().unwrap();
    for c in 0..3 {
        let e = rel_l2(plain.mesh(), refined.phi(c), plain.phi(c));
        assert!(e < 1e-5, "channel {c}: {e}");
        let e = rel_l2(plain.mesh(), preview.phi(c), plain.phi(c));
        assert!(e < 0.2, "the preview of channel {c}: {e}");
    }
}
