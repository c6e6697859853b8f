//! trilux-io images → `mesh_sampling::DensityTexture` and
//! `mesh_sampling::EmissionTexture`.

use mesh_sampling::{Channel, DensityTexture, EmissionTexture};
use trilux_io::image::Image;

use crate::Result;

/// A density texture from one channel of an image (`Channel::Index(0..4)`
/// for R, G, B, A) or its Rec. 709 luminance. Row 0 of the image is
/// `v = 0`, as for `TriMesh` UVs: no flip. The image's values are used as
/// they are (read a PNG with `ReadOptions { raw: true, .. }` to keep the
/// stored values instead of decoding sRGB).
///
/// # Errors
/// mesh-sampling's: a negative, NaN or infinite value (naming the texel),
/// a channel out of range.
///
/// # Example
/// ```
/// let sky = trilux::shapes::sky(64, 32);
/// let density = trilux::density_texture(&sky, mesh_sampling::Channel::Luminance)?;
/// assert_eq!((density.width(), density.height()), (64, 32));
/// # Ok::<(), trilux::Error>(())
/// ```
pub fn density_texture(image: &Image, channel: Channel) -> Result<DensityTexture> {
    let flat: Vec<f32> = image.pixels.iter().flatten().copied().collect();
    Ok(DensityTexture::from_channels(
        image.width as usize,
        image.height as usize,
        &flat,
        4,
        channel,
    )?)
}

/// An emission texture for a `mesh_sampling::Emitter` from an image: its
/// linear RGB as radiance (alpha ignored), row 0 at `v = 0` as for
/// `TriMesh` UVs. HDR and EXR values are used as they are; a PNG or JPEG
/// is decoded from sRGB to linear by default (read it with
/// `ReadOptions { raw: true, .. }` to keep the stored values). Mesh
/// colours emit through their atlas: [`crate::atlas_mesh`] gives the mesh
/// and the image to pass here. Set the material's wrap with
/// `.with_wrap(sampling_wrap(..))`.
///
/// # Errors
/// mesh-sampling's: a negative, NaN or infinite channel (naming the
/// texel).
///
/// # Example
/// ```
/// use mesh_sampling::{Emission, Emitter, EmitterOptions};
///
/// let sky = trilux::shapes::sky(64, 32);
/// let texture = trilux::emission_texture(&sky)?;
/// let torus = trilux::shapes::torus(48, 24);
/// let emission = Emission::Texture { texture: &texture, scale: 1.0 };
/// let emitter = Emitter::new(trilux::mesh_ref(&torus), emission, &EmitterOptions::default())?;
/// assert!(emitter.power() > 0.0);
/// # Ok::<(), trilux::Error>(())
/// ```
///
/// Mesh colours emit through their atlas. Colours fitted to a texture
/// with sharp edges can ring slightly below zero there (this checkerboard
/// does), which is no radiance: this function refuses a negative value,
/// naming the texel, so clamp first if that is what you mean:
/// ```
/// use mesh_sampling::{Emission, Emitter, EmitterOptions};
///
/// let torus = trilux::shapes::torus(48, 24);
/// let checker = trilux::shapes::checkerboard(128, 128, 8);
/// let (surface, colors) = trilux::to_mesh_colors(&torus, Some(&checker), &Default::default())?;
/// let atlas = mesh_colors::atlas::bake(&colors, &Default::default())?;
/// let (baked, mut image) = trilux::atlas_mesh(&surface, &atlas, None);
/// for p in &mut image.pixels {
///     p[..3].iter_mut().for_each(|c| *c = c.max(0.0));
/// }
/// let texture = trilux::emission_texture(&image)?;
/// let emission = Emission::Texture { texture: &texture, scale: 10.0 };
/// let emitter = Emitter::new(trilux::mesh_ref(&baked), emission, &EmitterOptions::default())?;
/// for s in emitter.sample_n(1, 1000)? {
///     assert!(s.radiance.iter().all(|&c| (0.0..=10.0 + 1e-3).contains(&c)));
/// }
/// # Ok::<(), trilux::Error>(())
/// ```
pub fn emission_texture(image: &Image) -> Result<EmissionTexture> {
    let rgb = image.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
    Ok(EmissionTexture::new(
        image.width as usize,
        image.height as usize,
        rgb,
    )?)
}

/// mesh-sampling's wrap mode for a material's (both follow glTF's
/// sampler semantics).
pub fn sampling_wrap(wrap: trilux_io::mesh::Wrap) -> mesh_sampling::Wrap {
    match wrap {
        trilux_io::mesh::Wrap::Repeat => mesh_sampling::Wrap::Repeat,
        trilux_io::mesh::Wrap::MirroredRepeat => mesh_sampling::Wrap::MirroredRepeat,
        trilux_io::mesh::Wrap::ClampToEdge => mesh_sampling::Wrap::ClampToEdge,
    }
}
