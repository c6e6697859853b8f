//! Texture → mesh colours → atlas, written as OBJ + MTL + PNG that any
//! viewer opens, then read back with `trilux-io` and compared with the
//! source texture at random surface points.
//!
//! `cargo run --release -p mesh-colors --example bake -- [out_dir]`
//! (needs `$TRILUX_DATA`; writes `spot_atlas.{obj,mtl,png}`).

#[path = "../tests/support/data.rs"]
mod data;

use std::path::PathBuf;
use std::process::ExitCode;

use glam::Vec2;
use mesh_colors::{Texture, Topology, atlas, convert, file};
use trilux_io::image::{Image, linear_to_srgb, srgb_to_linear};
use trilux_io::mesh::{Material, Object, TriMesh};

fn main() -> ExitCode {
    // Errors print as the sentence their Display gives, not as Debug.
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("bake: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let Some(dir) = data::data_dir() else {
        eprintln!("TRILUX_DATA is not set: nothing to bake");
        return Ok(());
    };
    let out = std::env::args()
        .nth(1)
        .map_or_else(std::env::temp_dir, PathBuf::from);
    std::fs::create_dir_all(&out)?;
    let spot = data::textured_meshes(&dir)
        .into_iter()
        .next()
        .ok_or("the data folder has no spot mesh")?;
    let topology = Topology::new(spot.positions.len(), &spot.faces)?;
    let colors = convert::from_texture(
        topology,
        &spot.corner_uvs,
        &spot.texture,
        &Default::default(),
    )?;
    file::save(out.join("spot.meshcolors"), &colors, None)?;
    let baked = atlas::bake(
        &colors,
        &atlas::Options {
            gutter: 2,
            ..Default::default()
        },
    )?;

    // One OBJ vertex per corner (the atlas gives every face its own UVs).
    // TriMesh UVs follow the texture convention (v = 0 at image row 0),
    // as the atlas's do; the OBJ writer converts to OBJ's v-up.
    let mut mesh = TriMesh::default();
    for (f, face) in spot.faces.iter().enumerate() {
        let base = mesh.positions.len() as u32;
        for (k, &v) in face.iter().enumerate() {
            mesh.positions.push(spot.positions[v as usize]);
            let uv = baked.corner_uvs[f][k];
            mesh.uvs.get_or_insert_with(Vec::new).push(uv);
        }
        mesh.indices.push([base, base + 1, base + 2]);
    }
    let t = &baked.texture;
    let image = Image {
        width: t.width() as u32,
        height: t.height() as u32,
        pixels: t
            .data()
            .chunks_exact(3)
            .map(|c| {
                [
                    srgb_to_linear(c[0]),
                    srgb_to_linear(c[1]),
                    srgb_to_linear(c[2]),
                    1.0,
                ]
            })
            .collect(),
    };
    // The OBJ writer keeps the material: it writes the .mtl and the atlas
    // as a PNG beside the OBJ.
    mesh.materials.push(Material {
        name: "atlas".into(),
        diffuse: [1.0; 3],
        diffuse_texture: None,
        diffuse_image: Some(image),
        wrap: Default::default(),
        scalar_images: Vec::new(),
    });
    mesh.objects.push(Object {
        name: "spot".into(),
        triangles: 0..mesh.indices.len(),
        material: Some(0),
    });
    let obj = out.join("spot_atlas.obj");
    mesh.write(&obj)?;

    // Read both back as a user would, and compare with the source texture.
    let back = TriMesh::read(&obj)?;
    let atlas_png = back
        .materials
        .first()
        .and_then(|m| m.diffuse_texture.clone())
        .ok_or_else(|| {
            format!(
                "{}: the written OBJ reads back without its texture",
                obj.display()
            )
        })?;
    let png = trilux_io::image::read(&atlas_png)?;
    let data = png
        .pixels
        .iter()
        .flat_map(|p| [0, 1, 2].map(|c| linear_to_srgb(p[c])))
        .collect();
    let texture = Texture::new(png.width as usize, png.height as usize, 3, data)?;
    let uvs = back
        .uvs
        .ok_or_else(|| format!("{}: the written OBJ reads back without UVs", obj.display()))?;
    let points = data::surface_points(&spot.positions, &spot.faces, 1_000_000, 5);
    let (mut a, mut b) = ([0.0f32; 3], [0.0f32; 3]);
    let mut se = 0.0f64;
    for &(f, bary) in &points {
        let uv = spot.corner_uvs[f as usize];
        spot.texture.bilinear(
            (bary[0] * uv[0] + bary[1] * uv[1] + bary[2] * uv[2]).into(),
            &mut a,
        );
        let tri = back.indices[f as usize];
        let p: Vec2 = (0..3).map(|k| bary[k] * uvs[tri[k] as usize]).sum();
        texture.bilinear(p.into(), &mut b);
        se += (0..3).map(|c| f64::from(a[c] - b[c]).powi(2)).sum::<f64>();
    }
    let psnr = 10.0 * (1.0 / (se / (3 * points.len()) as f64)).log10();
    println!(
        "spot: {} colours -> {}×{} atlas ({} texels; source {}×{}), written to {}; \
         read back: {psnr:.2} dB against the source texture (8-bit PNG)",
        colors.sample_count(),
        t.width(),
        t.height(),
        t.width() * t.height(),
        spot.texture.width(),
        spot.texture.height(),
        out.display()
    );
    Ok(())
}
