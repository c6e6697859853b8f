//! The paper's Table I on the CPU: mesh colour lookups (nearest, linear,
//! MIP, anisotropic) against bilinear and trilinear lookups into the
//! source texture at the same random surface points, plus conversion time,
//! colour vs texel counts and PSNR for every textured mesh of
//! `$TRILUX_DATA` (default `../shared/data`).
//!
//! `cargo run --release -p mesh-colors --example lookup -- [--json]`

#[path = "../tests/support/data.rs"]
mod data;

use std::hint::black_box;
use std::time::Instant;

use mesh_colors::{Topology, convert};

/// Lookups per measurement; the median of `REPEATS` interleaved runs is
/// kept (the machine is shared; interleaving spreads load bursts over all
/// filters alike, the median drops the disturbed runs).
const POINTS: usize = 1_000_000;

/// One mesh colour lookup: (point index, face, barycentrics, output).
type Lookup<'a> = &'a dyn Fn(usize, usize, [f32; 3], &mut [f32; 3]);
const REPEATS: usize = 5;

fn main() {
    let json = std::env::args().any(|a| a == "--json");
    let dir = data::data_dir().or_else(|| {
        let d = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data");
        d.is_dir().then_some(d)
    });
    let Some(dir) = dir else {
        eprintln!("TRILUX_DATA is not set and ../shared/data does not exist: nothing to measure");
        return;
    };
    let mut speed_rows = Vec::new();
    let mut mesh_rows = Vec::new();
    for m in data::textured_meshes(&dir) {
        let t = Instant::now();
        let converted = Topology::new(m.positions.len(), &m.faces).and_then(|topology| {
            convert::from_texture(topology, &m.corner_uvs, &m.texture, &Default::default())
        });
        let mc = match converted {
            Ok(mc) => mc,
            Err(e) => {
                eprintln!("{}: skipped: {e}", m.name);
                continue;
            }
        };
        let convert_ms = t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let mip = mc.mip_map();
        let mip_ms = t.elapsed().as_secs_f64() * 1e3;
        let points = data::surface_points(&m.positions, &m.faces, POINTS, 7);
        let psnr = match convert::psnr(&mc, &m.corner_uvs, &m.texture, &points, 1.0) {
            Ok(psnr) => psnr,
            Err(e) => {
                eprintln!("{}: skipped: {e}", m.name);
                continue;
            }
        };
        let texels = m.texture.width() * m.texture.height();
        mesh_rows.push((
            m.name.clone(),
            mc.sample_count(),
            texels,
            psnr,
            convert_ms,
            mip_ms,
        ));

        // The same points for every filter: UVs for the texture, (face,
        // barycentrics) for mesh colours; a level of detail in [0, 3) per
        // point, as texels for the texture and as the matching footprint
        // (2^lod samples of the face) for mesh colours.
        let uvs: Vec<[f32; 2]> = points
            .iter()
            .map(|&(f, b)| {
                let uv = m.corner_uvs[f as usize];
                (b[0] * uv[0] + b[1] * uv[1] + b[2] * uv[2]).into()
            })
            .collect();
        let lods: Vec<f32> = (0..POINTS).map(|i| (i % 300) as f32 / 100.0).collect();
        let footprints: Vec<f32> = points
            .iter()
            .zip(&lods)
            .map(|(&(f, _), &lod)| lod.exp2() / mc.face_resolution(f as usize).unwrap() as f32)
            .collect();
        let mut texture = m.texture.clone();
        texture.build_mips();
        // One pass of 10^6 lookups per filter; the passes of all six
        // filters are interleaved and repeated, and each keeps its fastest,
        // so a burst of load on the shared machine hits every filter alike.
        let pass_mc = |lookup: Lookup<'_>| -> f32 {
            let mut out = [0.0f32; 3];
            let mut acc = 0.0f32;
            for (i, &(f, b)) in points.iter().enumerate() {
                lookup(i, f as usize, b, &mut out);
                acc += out[0];
            }
            acc
        };
        let nearest = |_: usize, f: usize, b: [f32; 3], out: &mut [f32; 3]| {
            let _ = mc.nearest(f, b, out);
        };
        let linear = |_: usize, f: usize, b: [f32; 3], out: &mut [f32; 3]| {
            let _ = mc.linear(f, b, out);
        };
        let mipf = |i: usize, f: usize, b: [f32; 3], out: &mut [f32; 3]| {
            let _ = mip.trilinear(f, b, footprints[i], out);
        };
        // A footprint four times longer along one edge than across it.
        let aniso = |i: usize, f: usize, b: [f32; 3], out: &mut [f32; 3]| {
            let s = footprints[i];
            let _ = mip.anisotropic(f, b, [4.0 * s, -4.0 * s, 0.0], [0.0, s, -s], 8, out);
        };
        let bilinear = || {
            let mut out = [0.0f32; 3];
            let mut acc = 0.0f32;
            for uv in &uvs {
                texture.bilinear(*uv, &mut out);
                acc += out[0];
            }
            acc
        };
        let trilinear = || {
            let mut out = [0.0f32; 3];
            let mut acc = 0.0f32;
            for (uv, &lod) in uvs.iter().zip(&lods) {
                texture.trilinear(*uv, lod, &mut out);
                acc += out[0];
            }
            acc
        };
        let mut times: [Vec<f64>; 6] = Default::default();
        for _ in 0..REPEATS {
            let passes: [&dyn Fn() -> f32; 6] = [
                &|| pass_mc(&nearest),
                &|| pass_mc(&linear),
                &|| pass_mc(&mipf),
                &|| pass_mc(&aniso),
                &bilinear,
                &trilinear,
            ];
            for (k, pass) in passes.iter().enumerate() {
                let t = Instant::now();
                black_box(pass());
                times[k].push(t.elapsed().as_secs_f64());
            }
        }
        let rate = times.map(|mut t| {
            t.sort_by(f64::total_cmp);
            POINTS as f64 / t[t.len() / 2] / 1e6
        });
        let [nearest, linear, mipr, aniso, bilinear, trilinear] = rate;
        for (filter, v) in [
            ("nearest", nearest),
            ("linear", linear),
            ("mip", mipr),
            ("aniso", aniso),
            ("tex-bilinear", bilinear),
            ("tex-trilinear", trilinear),
        ] {
            speed_rows.push((m.name.clone(), filter, v, bilinear, trilinear));
        }
    }
    if json {
        for (mesh, filter, v, _, _) in &speed_rows {
            println!("{{\"mesh\":\"{mesh}\",\"filter\":\"{filter}\",\"mlookups_per_s\":{v:.3}}}");
        }
        for (mesh, colors, texels, psnr, ms, _) in &mesh_rows {
            println!(
                "{{\"mesh\":\"{mesh}\",\"colors\":{colors},\"texels\":{texels},\"psnr_db\":{psnr:.3},\"convert_ms\":{ms:.1}}}"
            );
        }
        return;
    }
    println!("| mesh | filter | Mlookups/s | cost vs texture |");
    println!("|---|---|---:|---:|");
    for (mesh, filter, v, bilinear, trilinear) in &speed_rows {
        let baseline = if matches!(*filter, "mip" | "aniso" | "tex-trilinear") {
            trilinear
        } else {
            bilinear
        };
        let name = if matches!(*filter, "mip" | "aniso" | "tex-trilinear") {
            "trilinear"
        } else {
            "bilinear"
        };
        println!(
            "| {mesh} | {filter} | {v:.1} | {:.2}× {name} |",
            baseline / v
        );
    }
    println!();
    println!(
        "| mesh | colours | texels | colours/texels | PSNR (dB) | convert (ms) | MIP build (ms) |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for (mesh, colors, texels, psnr, ms, mip_ms) in &mesh_rows {
        println!(
            "| {mesh} | {colors} | {texels} | {:.2} | {psnr:.2} | {ms:.0} | {mip_ms:.0} |",
            *colors as f64 / *texels as f64
        );
    }
}
