//! How close the paper's piecewise-constant `p′` (Šik & Křivánek 2013,
//! Eq. 2) comes to the exact density `p = f / ∫ f dA` of the bilinearly
//! filtered texture (Eq. 1), for the two depth rules: [`Depth::Nearest`]
//! (`4^L` nearest to the texels a triangle covers) and
//! [`Depth::AtMostOneTexel`] (the paper's "sub-triangles smaller than a
//! texel", `L = ⌈log₄ texels⌉`), and for the latter with
//! [`Options::merge_tolerance`] 1%, 5% and 20% (fewer pieces, a smaller
//! table: its megabytes are printed too).
//!
//! The total-variation distance `½ ∫ |p′ − p| dA` is estimated by Monte
//! Carlo over area-uniform points (the same points for both rules), with
//! its standard error. No piece budget, so each rule is measured as it is.
//!
//! ```text
//! TRILUX_DATA=… cargo run --release -p mesh-sampling --example depth
//! ```

use std::path::PathBuf;
use std::process::ExitCode;

use glam::{Vec2, Vec3};
use mesh_sampling::{
    Density, DensitySampler, DensityTexture, Depth, MeshRef, Options, RejectionSampler,
    SurfaceSampler, UniformSampler, luminance, spherical_uvs,
};

const SIZE: usize = 1024;
const N: usize = 1_000_000;

/// Smooth value noise with 64 cells across, in [0.1, 1.1].
fn noise() -> Vec<f32> {
    let hash = |x: u64, y: u64| {
        let mut h = x.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ y.wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
        h ^= h >> 29;
        h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        (h >> 11) as f32 / (1u64 << 53) as f32
    };
    (0..SIZE * SIZE)
        .map(|i| {
            let (x, y) = ((i % SIZE) as f32 / 16.0, (i / SIZE) as f32 / 16.0);
            let (x0, y0) = (x.floor(), y.floor());
            let (fx, fy) = (x - x0, y - y0);
            let at = |dx: f32, dy: f32| hash((x0 + dx) as u64 % 64, (y0 + dy) as u64 % 64);
            let top = at(0.0, 0.0) + (at(1.0, 0.0) - at(0.0, 0.0)) * fx;
            let bottom = at(0.0, 1.0) + (at(1.0, 1.0) - at(0.0, 1.0)) * fx;
            0.1 + top + (bottom - top) * fy
        })
        .collect()
}

/// The luminance of an HDR image, resampled (nearest) to 1024².
fn hdr(file: &std::path::Path) -> Result<Vec<f32>, String> {
    let image = trilux_io::image::read(file).map_err(|e| e.to_string())?;
    let (w, h) = (image.width as usize, image.height as usize);
    Ok((0..SIZE * SIZE)
        .map(|i| {
            let p = image.pixels[((i / SIZE) * h / SIZE) * w + (i % SIZE) * w / SIZE];
            luminance([p[0], p[1], p[2]])
        })
        .collect())
}

fn run() -> Result<(), String> {
    let dir = PathBuf::from(std::env::var_os("TRILUX_DATA").ok_or("set TRILUX_DATA")?);
    let mut densities = vec![("noise64".to_string(), noise())];
    densities.push((
        "hdr kloppenheim".into(),
        hdr(&dir.join("hdr/kloppenheim_06_1k.hdr"))?,
    ));
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir.join("meshes"))
        .map_err(|e| e.to_string())?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    files.sort();
    println!("| mesh | density | rule | tolerance | pieces | table MB | TV(p′, p) | ± (1 s.e.) |");
    println!("|---|---|---|---:|---:|---:|---:|---:|");
    for file in files {
        let m = trilux_io::mesh::TriMesh::read(&file).map_err(|e| e.to_string())?;
        let (positions, uvs, indices): (Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>) = match m.uvs {
            Some(uvs) => (m.positions, uvs, m.indices),
            None => spherical_uvs(&m.positions, &m.indices).map_err(|e| e.to_string())?,
        };
        let mesh = MeshRef {
            uvs: Some(&uvs),
            ..MeshRef::new(&positions, &indices)
        };
        let uniform = UniformSampler::new(mesh).map_err(|e| e.to_string())?;
        let points = uniform.sample_n(7, N).map_err(|e| e.to_string())?;
        let area = uniform.total_area();
        let name = file.file_name().unwrap_or_default().to_string_lossy();
        for (density, texels) in &densities {
            let t = DensityTexture::new(SIZE, SIZE, texels.clone()).map_err(|e| e.to_string())?;
            // The exact density: f / ∫ f dA, the integral exact.
            let exact = RejectionSampler::new(mesh, &t).map_err(|e| e.to_string())?;
            let rules = [
                (Depth::Nearest, 0.0),
                (Depth::AtMostOneTexel, 0.0),
                (Depth::AtMostOneTexel, 0.01),
                (Depth::AtMostOneTexel, 0.05),
                (Depth::AtMostOneTexel, 0.2),
            ];
            for (depth, merge_tolerance) in rules {
                let options = Options {
                    depth,
                    merge_tolerance,
                    max_pieces: usize::MAX,
                    ..Options::default()
                };
                let s = DensitySampler::with_options(mesh, Density::Texture(&t), &options)
                    .map_err(|e| e.to_string())?;
                // ½ ∫ |p′ − p| dA = ½ A E[|p′ − p|] over uniform points.
                let d: Vec<f64> = points
                    .iter()
                    .map(|q| {
                        let f = q.face as usize;
                        let a = f64::from(s.pdf(f, q.barycentric));
                        let b = f64::from(exact.pdf(f, q.barycentric));
                        0.5 * area * (a - b).abs()
                    })
                    .collect();
                let mean = d.iter().sum::<f64>() / N as f64;
                let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (N - 1) as f64;
                println!(
                    "| {name} | {density} | {depth:?} | {merge_tolerance} | {} | {:.1} | {mean:.4} | {:.4} |",
                    s.pieces(),
                    s.table_bytes() as f64 / 1e6,
                    (var / N as f64).sqrt()
                );
            }
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
