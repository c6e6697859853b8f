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
