//! Mesh colours from a textured mesh, checked against their mesh, and
//! pictures of them (`colors`, `sample`, `bench`, `demo`).

use std::path::Path;

use clap::ValueEnum;
use mesh_colors::{MeshColors, MipMap};
use mesh_sampling::{SurfaceSampler, UniformSampler};
use trilux::{ColorMesh, SurfaceTexture};
use trilux_io::mesh::TriMesh;

use crate::app::{Context, Result, file_cause};

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum Filter {
    Nearest,
    Linear,
    Mip,
    Aniso,
}

/// `n` uniform surface points as `(face, barycentrics)`.
pub(crate) fn surface_points(mesh: &TriMesh, n: usize, seed: u64) -> Result<Vec<(u32, [f32; 3])>> {
    Ok(UniformSampler::new(trilux::mesh_ref(mesh))?
        .sample_n(seed, n)?
        .iter()
        .map(|p| (p.face, p.barycentric))
        .collect())
}

/// Converts, and measures the PSNR against the source at 200,000 points.
pub(crate) fn convert_mesh(
    context: &mut Context,
    mesh: &TriMesh,
    texture: Option<&trilux_io::image::Image>,
    options: &trilux::ConvertOptions,
) -> Result<(ColorMesh, MeshColors, f64)> {
    let (surface, colors) = context.step("converting to mesh colours", || {
        trilux::to_mesh_colors(mesh, texture, options)
    })?;
    let source = SurfaceTexture::new(mesh, texture)?;
    let points = surface_points(mesh, 200_000, 1)?;
    let psnr = context.step("measuring PSNR", || psnr_against(&points, &source, &colors));
    Ok((surface, colors, psnr))
}

/// The PSNR of mesh colours (linear filter) against the surface texture
/// they were converted from, at `points` (`(face, barycentrics)`).
pub(crate) fn psnr_against(
    points: &[(u32, [f32; 3])],
    source: &SurfaceTexture,
    colors: &MeshColors,
) -> f64 {
    trilux::colors::psnr(
        points,
        |f, b| source.color(f, b),
        |f, b| {
            let mut out = [0.0f32; 3];
            let _ = colors.linear(f as usize, b, &mut out);
            out
        },
    )
}

/// Loads mesh colours and checks they belong to the mesh (read from
/// `mesh_path`).
pub(crate) fn load_for(
    mesh: &TriMesh,
    mesh_path: &Path,
    path: &Path,
) -> Result<(ColorMesh, MeshColors)> {
    crate::app::check_input(path)?;
    let (colors, _) = mesh_colors::file::load(path).map_err(|e| file_cause(path, e))?;
    let surface = ColorMesh::new(mesh).map_err(|e| crate::app::at(mesh_path.display(), e))?;
    surface.check(&colors, path)?;
    Ok((surface, colors))
}

/// A picture of mesh colours on their surface, filtered per pixel.
pub(crate) fn render_colors(
    surface: &ColorMesh,
    colors: &MeshColors,
    filter: Filter,
    size: u32,
) -> trilux_io::image::Image {
    render_colors_from(surface, colors, filter, size, None)
}

/// [`render_colors`] looking from direction `view` (towards the centre).
pub(crate) fn render_colors_from(
    surface: &ColorMesh,
    colors: &MeshColors,
    filter: Filter,
    size: u32,
    view: Option<glam::Vec3>,
) -> trilux_io::image::Image {
    use trilux::preview::{Camera, Renderer, lambert};
    let Some((lo, hi)) = trilux::preview::bounds(&surface.positions) else {
        return trilux::preview::render_mesh(&[], &[], size, size);
    };
    let mip: Option<MipMap> =
        matches!(filter, Filter::Mip | Filter::Aniso).then(|| colors.mip_map());
    let c = colors.channels();
    let camera = match view {
        Some(v) => Camera::fit_from(lo, hi, v),
        None => Camera::fit(lo, hi),
    };
    let mut r = Renderer::new(size, size, camera);
    r.draw_mesh(&surface.positions, &surface.faces, |frag| {
        let mut out = [0.0f32; mesh_colors::MAX_CHANNELS];
        let out = &mut out[..c];
        let face = frag.face as usize;
        let b = frag.barycentric;
        let _ = match (filter, &mip) {
            (Filter::Nearest, _) => colors.nearest(face, b, out),
            (Filter::Mip, Some(m)) => {
                let width = |d: [f32; 3]| d.iter().fold(0.0f32, |a, x| a.max(x.abs()));
                m.trilinear(face, b, width(frag.db_dx).max(width(frag.db_dy)), out)
            }
            (Filter::Aniso, Some(m)) => m.anisotropic(face, b, frag.db_dx, frag.db_dy, 16, out),
            _ => colors.linear(face, b, out),
        };
        let rgb = match c {
            1 | 2 => [out[0]; 3],
            _ => [out[0], out[1], out[2]],
        };
        lambert(rgb.map(|x| x.max(0.0) * 1.1), frag)
    });
    r.image()
}
