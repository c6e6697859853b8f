//! Undo of strokes and detail changes (Sec. 5.1): exact in both
//! directions, through any mix of steps, and small — 50 strokes within 10%
//! of the colours' memory.

use crate::support;

use glam::Vec3;
use mesh_colors::undo::{History, Recorder, Step};
use mesh_colors::{Blend, Brush, Error, MeshColors, Painter, Topology};
use support::Rng;

/// One stroke: `dabs` dabs along a random segment of the unit square,
/// recorded. Returns the delta.
fn stroke(
    painter: &Painter,
    positions: &[Vec3],
    mc: &mut MeshColors,
    rng: &mut Rng,
    radius: f32,
    length: f32,
) -> mesh_colors::undo::Delta {
    let start = Vec3::new(rng.f32(), rng.f32(), 0.0);
    let angle = rng.f32() * std::f32::consts::TAU;
    let dir = Vec3::new(angle.cos(), angle.sin(), 0.0);
    let colour = [rng.f32(), rng.f32(), rng.f32()];
    let blend = [Blend::Mix, Blend::Add, Blend::Set][rng.below(3) as usize];
    let mut recorder = Recorder::new(mc);
    // Dabs a quarter radius apart: most samples are reached several times.
    let dabs = ((length / (0.25 * radius)) as usize).max(1);
    for k in 0..dabs {
        let mut center = start + dir * (k as f32 * 0.25 * radius);
        // On the surface (the grid is bumped in z): the nearest vertex's z.
        let nearest = positions
            .iter()
            .min_by(|a, b| {
                a.truncate()
                    .distance(center.truncate())
                    .total_cmp(&b.truncate().distance(center.truncate()))
            })
            .unwrap();
        center.z = nearest.z;
        let brush = Brush {
            center,
            radius,
            color: &colour,
            strength: 0.3 + 0.7 * rng.f32(),
            blend,
        };
        painter.paint_recorded(mc, &brush, &mut recorder).unwrap();
    }
    recorder.finish()
}

#[test]
fn undo_and_redo_restore_strokes_and_detail_changes_exactly() {
    let mut rng = Rng(51);
    for round in 0..4 {
        let (positions, faces) = support::grid(8, 0.2);
        let levels: Vec<u32> = (0..faces.len()).map(|_| 1 << rng.below(4)).collect();
        let mut mc =
            MeshColors::new(Topology::new(positions.len(), &faces).unwrap(), &levels, 3).unwrap();
        for x in mc.samples_mut() {
            *x = rng.f32();
        }
        let mut states = vec![mc.clone()];
        let mut history = History::new(100);
        for _ in 0..12 {
            if rng.below(3) == 0 {
                let changes: Vec<(usize, u32)> = (0..1 + rng.below(10))
                    .map(|_| (rng.below(faces.len() as u64) as usize, 1 << rng.below(5)))
                    .collect();
                let change = mc.set_face_resolutions(&changes).unwrap();
                history.push(Step::Resolution(change));
            } else {
                let painter = Painter::new(&mc, &positions, 0.1).unwrap();
                let delta = stroke(&painter, &positions, &mut mc, &mut rng, 0.15, 0.4);
                history.push(Step::Paint(delta));
            }
            states.push(mc.clone());
        }
        for k in (0..12).rev() {
            assert!(history.undo(&mut mc).unwrap().is_some());
            assert_eq!(mc, states[k], "round {round}: undo to step {k}");
        }
        assert!(history.undo(&mut mc).unwrap().is_none());
        for (k, state) in states.iter().enumerate().skip(1) {
            assert!(history.redo(&mut mc).unwrap().is_some());
            assert_eq!(&mc, state, "round {round}: redo to step {k}");
        }
        assert!(history.redo(&mut mc).unwrap().is_none());
        // A new step after undoing drops the redo tail.
        history.undo(&mut mc).unwrap();
        history.undo(&mut mc).unwrap();
        let painter = Painter::new(&mc, &positions, 0.1).unwrap();
        let delta = stroke(&painter, &positions, &mut mc, &mut rng, 0.15, 0.2);
        history.push(Step::Paint(delta));
        assert_eq!((history.undo_len(), history.redo_len()), (11, 0));
    }
}

#[test]
fn a_delta_keeps_each_sample_once_and_refuses_misuse() {
    let (positions, faces) = support::grid(10, 0.0);
    let mut mc =
        MeshColors::uniform(Topology::new(positions.len(), &faces).unwrap(), 4, 3).unwrap();
    mc.samples_mut().fill(0.5);
    let before = mc.clone();
    let painter = Painter::new(&mc, &positions, 0.1).unwrap();
    let mut recorder = Recorder::new(&mc);
    let brush = Brush {
        center: Vec3::new(0.5, 0.5, 0.0),
        radius: 0.2,
        color: &[1.0, 0.0, 0.0],
        strength: 0.5,
        blend: Blend::Mix,
    };
    // The same dab three times: the samples are recorded once, with the
    // value before the first dab.
    for _ in 0..3 {
        painter
            .paint_recorded(&mut mc, &brush, &mut recorder)
            .unwrap();
    }
    let changed = (0..mc.sample_count())
        .filter(|&i| mc.sample(i) != before.sample(i))
        .count();
    assert_eq!(recorder.len(), changed);
    let mut delta = recorder.finish();
    assert_eq!(delta.samples(), changed);
    let in_runs: u32 = delta.runs().iter().map(|r| r.1).sum();
    assert_eq!(in_runs as usize, changed);
    assert!(delta.runs().windows(2).all(|w| w[0].0 + w[0].1 < w[1].0));
    let after = mc.clone();
    delta.undo(&mut mc).unwrap();
    assert_eq!(mc, before);
    assert!(matches!(delta.undo(&mut mc), Err(Error::StaleUndo { .. })));
    assert_eq!(mc, before);
    delta.redo(&mut mc).unwrap();
    assert_eq!(mc, after);
    assert!(matches!(delta.redo(&mut mc), Err(Error::StaleUndo { .. })));
    // Other colours (another layout) are refused, and name what differs.
    let mut other = mc.set_face_resolution(0, 8).unwrap();
    let e = delta.undo(&mut other).unwrap_err();
    assert!(e.to_string().contains("sample count"), "{e}");
    let mut recorder = Recorder::new(&before);
    assert!(matches!(
        recorder.record(&before, before.sample_count()),
        Err(Error::StaleUndo { what: "sample", .. })
    ));
    assert!(recorder.record(&before, 3).unwrap());
    assert!(!recorder.record(&before, 3).unwrap());
    assert!(matches!(
        painter.paint_recorded(&mut other, &brush, &mut recorder),
        Err(Error::StaleUndo { .. })
    ));
    // An unrecorded stroke paints exactly as a recorded one.
    let (mut a, mut b) = (before.clone(), before.clone());
    painter.paint(&mut a, &brush).unwrap();
    let mut recorder = Recorder::new(&b);
    painter
        .paint_recorded(&mut b, &brush, &mut recorder)
        .unwrap();
    assert_eq!(a, b);
}

#[test]
fn fifty_strokes_of_undo_take_under_a_tenth_of_the_colours_memory() {
    // About 6.4·10^5 RGB samples: a 100 × 100 grid (2·10^4 faces) at
    // resolution 8.
    let (positions, faces) = support::grid(100, 0.05);
    let mut mc =
        MeshColors::uniform(Topology::new(positions.len(), &faces).unwrap(), 8, 3).unwrap();
    let mut rng = Rng(50);
    for x in mc.samples_mut() {
        *x = rng.f32();
    }
    assert!((100_000..=1_000_000).contains(&mc.sample_count()));
    let original = mc.clone();
    let painter = Painter::new(&mc, &positions, 0.02).unwrap();
    let mut history = History::new(50);
    let mut touched = 0;
    for _ in 0..50 {
        // A brush of 1% of the model's size, strokes of 2–10% of it.
        let length = 0.02 + 0.08 * rng.f32();
        let delta = stroke(&painter, &positions, &mut mc, &mut rng, 0.01, length);
        touched += delta.samples();
        history.push(Step::Paint(delta));
    }
    let ratio = history.memory_bytes() as f64 / mc.memory_bytes() as f64;
    let of_samples = history.memory_bytes() as f64 / (4 * mc.samples().len()) as f64;
    println!(
        "undo of 50 strokes: {} bytes for {touched} samples changed; colours {} bytes \
         ({} samples): {:.2}% ({:.2}% of the sample values alone)",
        history.memory_bytes(),
        mc.memory_bytes(),
        mc.sample_count(),
        100.0 * ratio,
        100.0 * of_samples
    );
    assert!(of_samples <= 0.10, "{:.2}%", 100.0 * of_samples);
    while history.undo(&mut mc).unwrap().is_some() {}
    assert_eq!(mc, original);
}

#[test]
fn any_bit_pattern_survives_undo_and_redo_in_any_channel_count() {
    let mut rng = Rng(64);
    let (positions, faces) = support::grid(4, 0.0);
    for channels in [1, 3, 4, 5, 7, 64] {
        let topology = Topology::new(positions.len(), &faces).unwrap();
        let mut mc = MeshColors::uniform(topology, 4, channels).unwrap();
        // NaNs with payloads, ±0, subnormals, infinities, and neighbours
        // that differ in one bit or in all of them.
        let special = [
            f32::NAN.to_bits() | 0x1234,
            0x8000_0000,
            0,
            1,
            f32::INFINITY.to_bits(),
            f32::NEG_INFINITY.to_bits(),
            0x3f80_0001,
            0x3f80_0000,
        ];
        for x in mc.samples_mut() {
            let bits = if rng.below(3) == 0 {
                special[rng.below(special.len() as u64) as usize]
            } else {
                rng.next_u64() as u32
            };
            *x = f32::from_bits(bits);
        }
        let bits = |m: &MeshColors| m.samples().iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let before = bits(&mc);
        let mut recorder = Recorder::new(&mc);
        for _ in 0..mc.sample_count() / 2 {
            let i = rng.below(mc.sample_count() as u64) as usize;
            recorder.record(&mc, i).unwrap();
            for x in mc.sample_mut(i).unwrap() {
                *x = f32::from_bits(if rng.below(2) == 0 {
                    x.to_bits() ^ 1
                } else {
                    rng.next_u64() as u32
                });
            }
        }
        let after = bits(&mc);
        let mut delta = recorder.finish();
        for _ in 0..3 {
            delta.undo(&mut mc).unwrap();
            assert_eq!(bits(&mc), before, "{channels} channels: undo");
            delta.redo(&mut mc).unwrap();
            assert_eq!(bits(&mc), after, "{channels} channels: redo");
        }
    }
}

#[test]
fn strokes_over_a_flat_base_colour_cost_little() {
    // A new document: one base colour everywhere; the old values of the
    // first strokes are all that colour and compress to almost nothing.
    let (positions, faces) = support::grid(60, 0.0);
    let mut mc =
        MeshColors::uniform(Topology::new(positions.len(), &faces).unwrap(), 8, 3).unwrap();
    for s in mc.samples_mut().chunks_mut(3) {
        s.copy_from_slice(&[0.8, 0.7, 0.6]);
    }
    let painter = Painter::new(&mc, &positions, 0.02).unwrap();
    let mut rng = Rng(7);
    let mut history = History::new(50);
    let mut touched = 0;
    for _ in 0..50 {
        let delta = stroke(&painter, &positions, &mut mc, &mut rng, 0.02, 0.1);
        touched += delta.samples();
        history.push(Step::Paint(delta));
    }
    let per_sample = history.memory_bytes() as f64 / touched as f64;
    println!(
        "50 strokes over a flat base: {touched} samples changed, {:.2} bytes each, \
         {:.2}% of the colours",
        per_sample,
        100.0 * history.memory_bytes() as f64 / mc.memory_bytes() as f64
    );
    // Strokes overlap, so later ones overwrite painted (varied) values;
    // still far below the 12 bytes of three raw f32s.
    assert!(per_sample < 8.0, "{per_sample:.2} bytes per sample");
}

#[test]
fn a_history_with_a_budget_drops_its_oldest_steps_and_undoes_the_rest_exactly() {
    let (positions, faces) = support::grid(30, 0.05);
    let mut mc =
        MeshColors::uniform(Topology::new(positions.len(), &faces).unwrap(), 4, 3).unwrap();
    let mut rng = Rng(11);
    for x in mc.samples_mut() {
        *x = rng.f32();
    }
    let painter = Painter::new(&mc, &positions, 0.05).unwrap();
    let mut states = vec![mc.clone()];
    let mut deltas = Vec::new();
    for _ in 0..12 {
        deltas.push(stroke(&painter, &positions, &mut mc, &mut rng, 0.08, 0.3));
        states.push(mc.clone());
    }
    // A budget of about four strokes.
    let budget = deltas[..4].iter().map(|d| d.memory_bytes()).sum::<usize>()
        + std::mem::size_of::<History>();
    let mut history = History::with_budget(100, budget);
    for d in deltas {
        history.push(Step::Paint(d));
        assert!(history.memory_bytes() <= budget || history.undo_len() == 1);
    }
    let kept = history.undo_len();
    assert!((2..12).contains(&kept), "{kept} steps kept");
    // The kept steps undo to the state before the oldest of them.
    while history.undo(&mut mc).unwrap().is_some() {}
    assert_eq!(mc, states[12 - kept]);
    // A smaller budget drops nothing undone (redo walks them in order)...
    history.set_budget(0);
    assert_eq!(history.redo_len(), kept);
    while history.redo(&mut mc).unwrap().is_some() {}
    assert_eq!(mc, states[12]);
    // ...and, once they are applied again, keeps the newest alone.
    history.set_budget(0);
    assert_eq!((history.undo_len(), history.redo_len()), (1, 0));
    history.undo(&mut mc).unwrap();
    assert_eq!(mc, states[11]);
    // A step larger than the budget is kept (the newest always is).
    let mut tiny = History::with_budget(100, 1);
    tiny.push(Step::Paint(stroke(
        &painter, &positions, &mut mc, &mut rng, 0.08, 0.3,
    )));
    assert_eq!(tiny.undo_len(), 1);
}
