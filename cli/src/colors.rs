//! trilux-io meshes and images ↔ mesh colours: textures, the welded
//! surface mesh colours live on (seams and non-manifold edges handled),
//! conversion of a textured mesh, and the baked atlas back to a mesh and an
//! image to write.
//!
//! Colours are stored **linear** (as trilux-io decodes images); PNG
//! writing sRGB-encodes them again.
//!
//! **Accuracy** (PSNR of the mesh colours' linear filter against the
//! texture's bilinear filter at random surface points, on sRGB-encoded
//! values, [`psnr`]): with the default budget (one sample per texel),
//! Spot's 1024² texture converts at about 45 dB, smooth textures at
//! more than 35 dB; a checkerboard's hard edges at about 32 dB. The baked
//! atlas ([`atlas_mesh`]) read back with bilinear filtering loses less
//! than 1 dB more (tested: ≥ 38 dB for Spot in memory, ≥ 36 dB through
//! an 8-bit PNG).

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use mesh_colors::atlas::Atlas;
use mesh_colors::{MeshColors, Texture, Topology};
use trilux_io::image::Image;
use trilux_io::mesh::{Material, Object, TriMesh};

use crate::{Error, Result};

/// A mesh-colours texture of the image's linear RGB (3 channels), row 0 at
/// `v = 0` like `TriMesh` UVs (no flip).
pub fn texture(image: &Image) -> Result<Texture> {
    let data = image
        .pixels
        .iter()
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    Ok(Texture::new(
        image.width as usize,
        image.height as usize,
        3,
        data,
    )?)
}

/// A linear RGBA image of a mesh-colours texture: 1 channel becomes grey,
/// 2 grey + alpha, 3 RGB with alpha 1, 4 and more the first four.
pub fn texture_image(texture: &Texture) -> Image {
    let c = texture.channels();
    let pixels = texture
        .data()
        .chunks_exact(c)
        .map(|t| match c {
            1 => [t[0], t[0], t[0], 1.0],
            2 => [t[0], t[0], t[0], t[1]],
            3 => [t[0], t[1], t[2], 1.0],
            _ => [t[0], t[1], t[2], t[3]],
        })
        .collect();
    Image {
        width: texture.width() as u32,
        height: texture.height() as u32,
        pixels,
    }
}

/// mesh-colors' wrap mode for a material's (both follow glTF's sampler
/// semantics).
pub fn colors_wrap(wrap: trilux_io::mesh::Wrap) -> mesh_colors::Wrap {
    match wrap {
        trilux_io::mesh::Wrap::Repeat => mesh_colors::Wrap::Repeat,
        trilux_io::mesh::Wrap::MirroredRepeat => mesh_colors::Wrap::MirroredRepeat,
        trilux_io::mesh::Wrap::ClampToEdge => mesh_colors::Wrap::ClampToEdge,
    }
}

/// The surface of a `TriMesh` as mesh colours need it: readers split a
/// vertex wherever its UV or normal changes (a seam), while mesh colours
/// live on the connectivity of the surface itself. Triangle `f` here is
/// triangle `f` of the `TriMesh`.
///
/// Built by [`ColorMesh::new`] ([`mesh_colors::convert::weld_manifold`]):
/// vertices with equal positions are welded
/// and unused vertices dropped; a triangle that would repeat a vertex
/// after welding, or be the third on an edge (which mesh colours cannot
/// colour consistently), keeps vertices of its own (counted in
/// [`detached`](Self::detached)). The construction is deterministic, so a
/// `.meshcolors` file made from a mesh fits the same mesh read again.
#[derive(Debug, Clone, PartialEq)]
pub struct ColorMesh {
    /// Welded positions.
    pub positions: Vec<Vec3>,
    /// Triangles over [`positions`](Self::positions), in the mesh's order.
    pub faces: Vec<[u32; 3]>,
    /// The UVs of each triangle's corners (glTF convention), when the mesh
    /// has UVs.
    pub corner_uvs: Option<Vec<[Vec2; 3]>>,
    /// The normals of each triangle's corners, when the mesh has normals.
    pub corner_normals: Option<Vec<[Vec3; 3]>>,
    /// Triangles that kept vertices of their own (degenerate after welding,
    /// or a third triangle on an edge).
    pub detached: usize,
    /// The mesh's origin: positions are relative to it (see
    /// `TriMesh::origin`).
    pub origin: glam::DVec3,
}

impl ColorMesh {
    /// Welds `mesh` (see the type's docs).
    ///
    /// # Errors
    /// [`Error::Invalid`] for a triangle that references a missing vertex.
    pub fn new(mesh: &TriMesh) -> Result<Self> {
        let n = mesh.positions.len();
        if let Some((t, _)) = mesh
            .indices
            .iter()
            .enumerate()
            .find(|(_, tri)| tri.iter().any(|&v| v as usize >= n))
        {
            return Err(Error::Invalid(format!(
                "triangle {t} references a vertex beyond the {n} the mesh has"
            )));
        }
        let welded = mesh_colors::convert::weld_manifold(&mesh.positions, &mesh.indices)?;
        let corners = |attr: &[Vec2]| {
            mesh.indices
                .iter()
                .map(|t| t.map(|v| attr[v as usize]))
                .collect()
        };
        Ok(Self {
            positions: welded.positions,
            faces: welded.faces,
            corner_uvs: mesh.uvs.as_deref().map(corners),
            corner_normals: mesh.normals.as_deref().map(|n| {
                mesh.indices
                    .iter()
                    .map(|t| t.map(|v| n[v as usize]))
                    .collect()
            }),
            detached: welded.detached,
            origin: mesh.origin,
        })
    }

    /// The mesh-colours topology of the welded mesh.
    ///
    /// # Errors
    /// mesh-colors' (not expected: the welding removed what it refuses).
    pub fn topology(&self) -> Result<Topology> {
        Ok(Topology::new(self.positions.len(), &self.faces)?)
    }

    /// Checks that `colors` (read from `path`) were made for this mesh.
    ///
    /// # Errors
    /// [`Error::WrongMesh`] with the counts, or the first face that differs.
    pub fn check(&self, colors: &MeshColors, path: &Path) -> Result<()> {
        let t = colors.topology();
        let detail =
            if t.vertex_count() == self.positions.len() && t.faces().len() == self.faces.len() {
                match t.faces().iter().zip(&self.faces).position(|(a, b)| a != b) {
                    None => return Ok(()),
                    Some(f) => format!(" (face {f} differs)"),
                }
            } else {
                String::new()
            };
        Err(Error::WrongMesh {
            path: path.to_path_buf(),
            file_vertices: t.vertex_count(),
            file_faces: t.faces().len(),
            mesh_vertices: self.positions.len(),
            mesh_faces: self.faces.len(),
            detail,
        })
    }
}

/// How to convert a textured mesh to mesh colours: mesh-colors' own
/// options (`max_samples: None` is the texel count of all the textures).
pub use mesh_colors::convert::Options as ConvertOptions;
use mesh_colors::convert::Source;

/// The textures of `mesh`'s materials (decoded by the reader, or read from
/// the material's file), and per triangle what colours it. `texture`
/// replaces the materials' textures.
fn sources(mesh: &TriMesh, texture: Option<&Image>) -> Result<(Vec<Texture>, Vec<Source>)> {
    let n = mesh.indices.len();
    if let Some(image) = texture {
        return Ok((vec![self::texture(image)?], vec![Source::Texture(0); n]));
    }
    let mut textures = Vec::new();
    let mut by_material: Vec<Option<usize>> = Vec::with_capacity(mesh.materials.len());
    for m in &mesh.materials {
        by_material.push(material_texture(m)?.map(|t| {
            textures.push(t);
            textures.len() - 1
        }));
    }
    let mut out = vec![Source::Flat([0.8; 3]); n];
    for o in &mesh.objects {
        let source = match o.material {
            Some(m) => match by_material.get(m).copied().flatten() {
                Some(t) => Source::Texture(t),
                None => Source::Flat(mesh.materials.get(m).map_or([0.8; 3], |m| m.diffuse)),
            },
            None => continue,
        };
        for s in out.get_mut(o.triangles.clone()).into_iter().flatten() {
            *s = source;
        }
    }
    if textures.is_empty() {
        return Err(Error::MissingTexture);
    }
    Ok((textures, out))
}

fn material_texture(m: &Material) -> Result<Option<Texture>> {
    let wrap = colors_wrap(m.wrap[0]);
    if let Some(image) = &m.diffuse_image {
        return Ok(Some(texture(image)?.with_wrap(wrap)));
    }
    match &m.diffuse_texture {
        Some(path) => Ok(Some(
            texture(&trilux_io::image::read(path)?)?.with_wrap(wrap),
        )),
        None => Ok(None),
    }
}

/// The colour a textured mesh shows: per triangle its material's texture
/// (bilinear at the interpolated UV) or flat colour — the reference mesh
/// colours are converted from and compared against.
#[derive(Debug, Clone)]
pub struct SurfaceTexture {
    textures: Vec<Texture>,
    sources: Vec<Source>,
    corner_uvs: Vec<[Vec2; 3]>,
}

impl SurfaceTexture {
    /// The materials' textures of `mesh` (decoded by the reader or read
    /// from the material's file), or `texture` for every triangle.
    ///
    /// # Errors
    /// [`Error::MissingUvs`], [`Error::MissingTexture`], a texture file
    /// that cannot be read.
    pub fn new(mesh: &TriMesh, texture: Option<&Image>) -> Result<Self> {
        let Some(uvs) = &mesh.uvs else {
            return Err(Error::MissingUvs {
                what: "a textured surface",
            });
        };
        let (textures, sources) = sources(mesh, texture)?;
        let corner_uvs = mesh
            .indices
            .iter()
            .map(|t| t.map(|v| uvs.get(v as usize).copied().unwrap_or_default()))
            .collect();
        Ok(Self {
            textures,
            sources,
            corner_uvs,
        })
    }

    /// The linear RGB colour at barycentrics `b` of triangle `face`
    /// (black for a face that does not exist).
    pub fn color(&self, face: u32, b: [f32; 3]) -> [f32; 3] {
        let f = face as usize;
        match self.sources.get(f) {
            Some(Source::Texture(t)) => {
                let uv = self.corner_uvs[f];
                let p = uv[0] * b[0] + uv[1] * b[1] + uv[2] * b[2];
                let mut out = [0.0f32; 3];
                self.textures[*t].bilinear([p.x, p.y], &mut out);
                out
            }
            Some(Source::Flat(c)) => *c,
            None => [0.0; 3],
        }
    }
}

/// Peak signal-to-noise ratio, in dB, between two colourings of a surface
/// at the points `(face, barycentrics)`, on sRGB-encoded values in
/// `[0, 1]` (as 8-bit images store them; the figure PSNR is usually
/// quoted on). Infinite when they agree.
pub fn psnr(
    points: &[(u32, [f32; 3])],
    a: impl Fn(u32, [f32; 3]) -> [f32; 3] + Sync,
    b: impl Fn(u32, [f32; 3]) -> [f32; 3] + Sync,
) -> f64 {
    use rayon::prelude::*;
    let encode = trilux_io::image::linear_to_srgb;
    let sse: f64 = points
        .par_iter()
        .map(|&(f, w)| {
            let (x, y) = (a(f, w), b(f, w));
            (0..3)
                .map(|c| f64::from(encode(x[c]) - encode(y[c])).powi(2))
                .sum::<f64>()
        })
        .sum();
    let mse = sse / (3 * points.len().max(1)) as f64;
    10.0 * (1.0 / mse).log10()
}

/// Converts a textured mesh to linear-RGB mesh colours: welds it
/// ([`ColorMesh`]), gives each face a resolution from the texels its UVs
/// cover, and fills every sample with the bilinear texture value at its UV,
/// averaged over its distinct UVs where it lies on a seam
/// ([`mesh_colors::convert::from_textures`]). Each triangle reads its
/// material's texture (`texture` replaces them all); triangles whose
/// material has none take its flat diffuse colour.
///
/// # Errors
/// [`Error::MissingUvs`], [`Error::MissingTexture`], a texture file that
/// cannot be read, mesh-colors' errors.
///
/// # Example
/// ```
/// let torus = trilux::shapes::torus(32, 16);
/// let checker = trilux::shapes::checkerboard(64, 64, 8);
/// let (surface, colors) =
///     trilux::to_mesh_colors(&torus, Some(&checker), &Default::default())?;
/// assert_eq!(colors.face_count(), torus.indices.len());
/// # Ok::<(), trilux::Error>(())
/// ```
pub fn to_mesh_colors(
    mesh: &TriMesh,
    texture: Option<&Image>,
    options: &ConvertOptions,
) -> Result<(ColorMesh, MeshColors)> {
    let surface = ColorMesh::new(mesh)?;
    let Some(corner_uvs) = &surface.corner_uvs else {
        return Err(Error::MissingUvs {
            what: "converting a texture to mesh colours",
        });
    };
    let SurfaceTexture {
        textures, sources, ..
    } = SurfaceTexture::new(mesh, texture)?;
    let colors = mesh_colors::convert::from_textures(
        surface.topology()?,
        corner_uvs,
        &textures,
        &sources,
        options,
    )?;
    Ok((surface, colors))
}

/// A baked atlas as a mesh and an image to write: one vertex per triangle
/// corner (the atlas gives every face its own UVs) at the welded
/// positions, the corners' normals (the file's, else the welded surface's
/// smooth area-weighted ones), the atlas
/// UVs as they are (glTF convention, like every `TriMesh`; the OBJ writer
/// converts), and one material whose texture is `texture_file`. Triangle
/// `f` is triangle `f` of the surface.
pub fn atlas_mesh(
    surface: &ColorMesh,
    atlas: &Atlas,
    texture_file: Option<PathBuf>,
) -> (TriMesh, Image) {
    let n = surface.faces.len();
    let mut positions = Vec::with_capacity(3 * n);
    let mut uvs = Vec::with_capacity(3 * n);
    for (face, corner_uvs) in surface.faces.iter().zip(&atlas.corner_uvs) {
        positions.extend(face.map(|v| surface.positions[v as usize]));
        uvs.extend_from_slice(corner_uvs);
    }
    // The file's own normals, else smooth ones of the welded surface: a
    // viewer given none shades every face flat.
    let normals = Some(match &surface.corner_normals {
        Some(n) => n.iter().flatten().copied().collect(),
        None => {
            let smooth = crate::shapes::vertex_normals(&surface.positions, &surface.faces);
            surface
                .faces
                .iter()
                .flat_map(|f| f.map(|v| smooth[v as usize]))
                .collect()
        }
    });
    let image = texture_image(&atlas.texture);
    let material = Material {
        name: "atlas".into(),
        diffuse: [1.0; 3],
        diffuse_texture: texture_file,
        diffuse_image: Some(image.clone()),
        wrap: [trilux_io::mesh::Wrap::ClampToEdge; 2],
        scalar_images: Vec::new(),
    };
    let mesh = TriMesh {
        origin: surface.origin,
        uvs1: None,
        positions,
        indices: (0..n as u32)
            .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
            .collect(),
        normals,
        uvs: Some(uvs),
        objects: vec![Object {
            name: "atlas".into(),
            triangles: 0..n,
            material: Some(0),
        }],
        materials: vec![material],
        warnings: Vec::new(),
    };
    (mesh, image)
}

/// Splits a baked atlas of colours with scalar channels (`trilux paint`'s
/// RGB then `names`, e.g. `roughness`, `density`) between the material
/// [`atlas_mesh`] made: its base colour keeps RGB only, opaque (the fourth
/// channel is not alpha), and each scalar channel becomes one of its
/// [`Material::scalar_images`], which the glTF writer puts into the
/// metallic-roughness or occlusion texture or a texture of its own.
///
/// # Errors
/// [`Error::Invalid`] when `baked` has no material or the atlas does not
/// have `3 + names.len()` channels.
pub fn attach_scalar_channels(baked: &mut TriMesh, atlas: &Atlas, names: &[String]) -> Result<()> {
    let texture = &atlas.texture;
    let c = texture.channels();
    if c != 3 + names.len() {
        return Err(Error::Invalid(format!(
            "the atlas has {c} channels, not RGB and the {} scalar channels {names:?}",
            names.len()
        )));
    }
    let material = baked
        .materials
        .first_mut()
        .ok_or_else(|| Error::Invalid("the baked mesh has no material for its textures".into()))?;
    let (width, height) = (texture.width() as u32, texture.height() as u32);
    let channel = |k: usize| Image {
        width,
        height,
        pixels: texture
            .data()
            .chunks_exact(c)
            .map(|t| [t[k], t[k], t[k], 1.0])
            .collect(),
    };
    material.diffuse_image = Some(Image {
        width,
        height,
        pixels: texture
            .data()
            .chunks_exact(c)
            .map(|t| [t[0], t[1], t[2], 1.0])
            .collect(),
    });
    material.scalar_images = names
        .iter()
        .enumerate()
        .map(|(k, n)| (n.clone(), channel(3 + k)))
        .collect();
    Ok(())
}

/// One channel of mesh colours as a sampling density: the colours baked
/// to an atlas (bilinear filtering of the atlas reproduces the mesh
/// colours' linear filter, exactly for colours affine on each face) over a
/// copy of the surface with one vertex per triangle corner. Triangle `f`
/// is triangle `f` of the surface (and of the `TriMesh` it came from), so
/// sampled points' faces and barycentrics apply to the original mesh.
#[derive(Debug, Clone)]
pub struct ColorDensity {
    /// The atlas channel, clamped at the atlas's edges.
    pub texture: mesh_sampling::DensityTexture,
    /// Three vertices per triangle.
    pub positions: Vec<Vec3>,
    /// Their atlas UVs.
    pub uvs: Vec<Vec2>,
    /// `[3f, 3f + 1, 3f + 2]`.
    pub indices: Vec<[u32; 3]>,
}

impl ColorDensity {
    /// The mesh to hand to a mesh-sampling sampler with
    /// `Density::Texture(&self.texture)`.
    pub fn mesh_ref(&self) -> mesh_sampling::MeshRef<'_> {
        mesh_sampling::MeshRef {
            uvs: Some(&self.uvs),
            ..mesh_sampling::MeshRef::new(&self.positions, &self.indices)
        }
    }
}

/// The density of one sample (or texel) for `channel`.
fn density_of(sample: &[f32], channel: mesh_sampling::Channel) -> f32 {
    match channel {
        mesh_sampling::Channel::Luminance => {
            0.2126 * sample[0] + 0.7152 * sample[1] + 0.0722 * sample[2]
        }
        mesh_sampling::Channel::Index(i) => sample.get(i).copied().unwrap_or(f32::NAN),
    }
}

/// A sampling density from one channel (or the Rec. 709 luminance of the
/// first three) of mesh colours on `surface` (see [`ColorDensity`]).
///
/// # Errors
/// [`Error::Invalid`] for a channel the colours do not have or a sample
/// whose density is negative or not finite (naming the sample);
/// mesh-colors' and mesh-sampling's errors.
///
/// # Example
/// ```
/// use mesh_sampling::{Channel, Density, DensitySampler, SurfaceSampler};
/// let torus = trilux::shapes::torus(32, 16);
/// let checker = trilux::shapes::checkerboard(64, 64, 4);
/// let (surface, colors) = trilux::to_mesh_colors(&torus, Some(&checker), &Default::default())?;
/// let density = trilux::colors::color_density(&surface, &colors, Channel::Luminance)?;
/// let sampler = DensitySampler::new(density.mesh_ref(), Density::Texture(&density.texture))?;
/// let cloud = trilux::point_cloud(&torus, &sampler.sample_n(3, 1000)?);
/// # Ok::<(), trilux::Error>(())
/// ```
pub fn color_density(
    surface: &ColorMesh,
    colors: &MeshColors,
    channel: mesh_sampling::Channel,
) -> Result<ColorDensity> {
    let c = colors.channels();
    let needed = match channel {
        mesh_sampling::Channel::Luminance => 3,
        mesh_sampling::Channel::Index(i) => i + 1,
    };
    if c < needed {
        return Err(Error::Invalid(format!(
            "the mesh colours have {c} channel(s); {channel:?} needs {needed}"
        )));
    }
    if let Some(i) = colors
        .samples()
        .chunks_exact(c)
        .position(|s| !(density_of(s, channel) >= 0.0 && density_of(s, channel).is_finite()))
    {
        return Err(Error::Invalid(format!(
            "mesh colour sample {i} gives density {} (densities must be finite and >= 0)",
            colors
                .sample(i)
                .map_or(f32::NAN, |s| density_of(s, channel))
        )));
    }
    let atlas = mesh_colors::atlas::bake(colors, &Default::default())?;
    let t = &atlas.texture;
    // The atlas extrapolates past each face's hypotenuse (exact for affine
    // colours); where that dips below zero next to a zero density, zero is
    // the density's floor.
    let texels: Vec<f32> = t
        .data()
        .chunks_exact(c)
        .map(|s| density_of(s, channel).max(0.0))
        .collect();
    let texture = mesh_sampling::DensityTexture::new(t.width(), t.height(), texels)?
        .with_wrap(mesh_sampling::Wrap::ClampToEdge);
    let positions = surface
        .faces
        .iter()
        .flat_map(|f| f.map(|v| surface.positions[v as usize]))
        .collect();
    let uvs = atlas.corner_uvs.iter().flatten().copied().collect();
    let indices = (0..surface.faces.len() as u32)
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    Ok(ColorDensity {
        texture,
        positions,
        uvs,
        indices,
    })
}
