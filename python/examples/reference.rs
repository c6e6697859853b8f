//! The Rust side of the Python package's bit-for-bit tests: the points
//! that the Rust crates draw for a mesh file, a count and a seed, written
//! as raw little-endian arrays that `tests/test_reference.py` compares
//! with `trilux.sample_surface` and `trilux.blue_noise`.
//!
//! ```sh
//! cargo run --release -p trilux-python --example reference -- MESH N SEED OUT_PREFIX [DENSITY.png]
//! ```
//!
//! Writes `OUT_PREFIX.uniform.f64` (N × 3 positions, the mesh's origin
//! added in f64) and `.uniform.i64` (face ids); with a density image also
//! `.density.f64` / `.density.i64` (subdivision, luminance of the stored
//! values); `.blue.f64` / `.blue.i64` (blue noise of N / 10 points by
//! elimination) and `.dense.f64` / `.dense.i64` (the dense packing, the
//! Python default).

use std::io::Write;
use std::path::Path;

use mesh_sampling::{
    BlueNoiseOptions, BlueNoiseTarget, Channel, Density, DensitySampler, SurfacePoint,
    SurfaceSampler, UniformSampler,
};

fn write(
    prefix: &str,
    what: &str,
    origin: glam::DVec3,
    points: &[SurfacePoint],
) -> std::io::Result<()> {
    let mut pos = std::fs::File::create(format!("{prefix}.{what}.f64"))?;
    let mut bytes = Vec::with_capacity(points.len() * 24);
    for p in points {
        for x in (origin + p.position.as_dvec3()).to_array() {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
    }
    pos.write_all(&bytes)?;
    let faces: Vec<u8> = points
        .iter()
        .flat_map(|p| i64::from(p.face).to_le_bytes())
        .collect();
    std::fs::write(format!("{prefix}.{what}.i64"), faces)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [mesh, n, seed, prefix, rest @ ..] = args.as_slice() else {
        return Err("usage: reference MESH N SEED OUT_PREFIX [DENSITY.png]".into());
    };
    let mesh = trilux_io::mesh::TriMesh::read(Path::new(mesh))?;
    let (n, seed): (usize, u64) = (n.parse()?, seed.parse()?);
    let uniform = UniformSampler::new(trilux::mesh_ref(&mesh))?;
    write(prefix, "uniform", mesh.origin, &uniform.sample_n(seed, n)?)?;
    let blue = mesh_sampling::blue_noise(
        &uniform,
        BlueNoiseTarget::Count(n / 10),
        seed,
        &BlueNoiseOptions::default(),
    )?;
    write(prefix, "blue", mesh.origin, &blue)?;
    let dense = mesh_sampling::blue_noise(
        &uniform,
        BlueNoiseTarget::Count(n / 10),
        seed,
        &BlueNoiseOptions::dense(),
    )?;
    write(prefix, "dense", mesh.origin, &dense)?;
    if let Some(density) = rest.first() {
        let image = trilux_io::image::read_with(
            density,
            trilux_io::image::ReadOptions {
                raw: true,
                ..Default::default()
            },
        )?;
        let texture = trilux::density_texture(&image, Channel::Luminance)?;
        let sampler = DensitySampler::new(trilux::mesh_ref(&mesh), Density::Texture(&texture))?;
        write(prefix, "density", mesh.origin, &sampler.sample_n(seed, n)?)?;
    }
    Ok(())
}
