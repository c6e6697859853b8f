//! The painting system's operations (Sec. 5.1, 5.3) on about 10⁶ samples,
//! each against the whole-structure operation it replaces, in the same
//! process: a detail change of 1,000 faces (`set_face_resolutions`)
//! against one face by the copying `set_face_resolution`; a dab's MIP and
//! texture update (`MipMap::refresh` + `GpuLayout::refresh`) against a
//! rebuild (`MipMap::new` + `GpuLayout::update`); the undo memory of 50
//! strokes. Prints a Markdown table; medians of five runs.
//!
//! `cargo run --release -p mesh-colors --example paint`

use std::time::Instant;

// The tests' meshes: the flat grid is theirs with no bump.
#[path = "../tests/support/mod.rs"]
mod support;

use mesh_colors::glam::Vec3;
use mesh_colors::gpu::GpuLayout;
use mesh_colors::undo::{History, Recorder, Step};
use mesh_colors::{Blend, Brush, MeshColors, Painter, Topology};

/// Median milliseconds of five runs of `f`.
fn median_ms(mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..5)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[2]
}

fn main() -> Result<(), mesh_colors::Error> {
    let (positions, faces) = support::grid(120, 0.0);
    let topology = Topology::new(positions.len(), &faces)?;
    let mut colors = MeshColors::uniform(topology, 8, 3)?;
    for (i, x) in colors.samples_mut().iter_mut().enumerate() {
        *x = (i % 97) as f32 / 97.0;
    }
    println!(
        "{} faces, {} samples ({} MB of colours)\n",
        colors.face_count(),
        colors.sample_count(),
        colors.memory_bytes() / 1_000_000
    );
    println!("| operation | new (ms) | replaces (ms) | ratio |\n|---|---:|---:|---:|");

    // Detail: 1,000 neighbouring faces one level up, with the pyramid and
    // the texture, against one face by the copying API and a rebuild.
    let patch: Vec<(usize, u32)> = (0..1000).map(|k| (10_000 + k, 16)).collect();
    let patch_faces: Vec<usize> = patch.iter().map(|p| p.0).collect();
    let base_mip = colors.mip_map();
    let base_layout = GpuLayout::new(&base_mip, 4096)?;
    let (mut copy_ms, mut detail_ms) = (Vec::new(), Vec::new());
    let mut steps: Vec<[f64; 3]> = Vec::new();
    for _ in 0..5 {
        let (mut c, mut m, mut l) = (colors.clone(), base_mip.clone(), base_layout.clone());
        let s = Instant::now();
        let change = c.set_face_resolutions(&patch)?;
        let t1 = s.elapsed().as_secs_f64() * 1e3;
        m.refresh_resolutions(&c, &patch_faces)?;
        let t2 = s.elapsed().as_secs_f64() * 1e3;
        l.update(&m)?;
        detail_ms.push(s.elapsed().as_secs_f64() * 1e3);
        steps.push([t1, t2 - t1, detail_ms[detail_ms.len() - 1] - t2]);
        let _ = change;
        let mut l = base_layout.clone();
        let s = Instant::now();
        let one = colors.set_face_resolution(10_000, 16)?;
        l.update(&one.mip_map())?;
        copy_ms.push(s.elapsed().as_secs_f64() * 1e3);
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[2]
    };
    let (detail, one) = (median(detail_ms), median(copy_ms));
    let step = |k: usize| median(steps.iter().map(|s| s[k]).collect());
    let (batch, pyramid, texture) = (step(0), step(1), step(2));
    println!(
        "| 1,000 faces up one level + `refresh_resolutions` + `update` vs **one** face by `set_face_resolution` + `mip_map` + `update` | {detail:.1} | {one:.1} | {:.2}× |",
        detail / one
    );
    println!(
        "| (of which `set_face_resolutions` / `refresh_resolutions` / `GpuLayout::update`) | {batch:.1} / {pyramid:.1} / {texture:.1} | | |"
    );

    // A dab: paint, then the pyramid and the texture.
    let painter = Painter::new(&colors, &positions, 0.02)?;
    let mut mip = colors.mip_map();
    let mut layout = GpuLayout::new(&mip, 4096)?;
    let brush = Brush {
        center: Vec3::new(0.5, 0.5, 0.0),
        radius: 0.02,
        color: &[1.0, 0.2, 0.1],
        strength: 0.5,
        blend: Blend::Mix,
    };
    let mut uploaded = 0;
    let incremental = median_ms(|| {
        let mut recorder = Recorder::new(&colors);
        painter
            .paint_recorded(&mut colors, &brush, &mut recorder)
            .expect("valid");
        let delta = recorder.finish();
        let spans = mip.refresh(&colors, delta.runs()).expect("same layout");
        let changes = layout.refresh(&mip, &spans).expect("same layout");
        uploaded = changes
            .samples
            .iter()
            .map(|r| r.width * r.height)
            .sum::<u32>();
    });
    let rebuild = median_ms(|| {
        painter.paint(&mut colors, &brush).expect("valid");
        let mip = colors.mip_map();
        layout.update(&mip).expect("fits");
    });
    println!(
        "| dab + `MipMap::refresh` + `GpuLayout::refresh` ({uploaded} texels to upload) vs dab + `mip_map` + `update` | {incremental:.2} | {rebuild:.1} | {:.3}× |",
        incremental / rebuild
    );

    // Undo memory of 50 strokes of 20 dabs.
    let mut history = History::new(50);
    for s in 0..50 {
        let mut recorder = Recorder::new(&colors);
        let start = Vec3::new(0.1 + 0.016 * s as f32, 0.2, 0.0);
        for k in 0..20 {
            let brush = Brush {
                center: start + Vec3::new(0.0, 0.004 * k as f32, 0.0),
                ..brush
            };
            painter.paint_recorded(&mut colors, &brush, &mut recorder)?;
        }
        history.push(Step::Paint(recorder.finish()));
    }
    println!(
        "\nUndo of 50 strokes (20 dabs of radius 0.02 each, 0.08 long): {} kB = {:.1}% of the colours' {} kB.",
        history.memory_bytes() / 1000,
        100.0 * history.memory_bytes() as f64 / colors.memory_bytes() as f64,
        colors.memory_bytes() / 1000
    );
    Ok(())
}
