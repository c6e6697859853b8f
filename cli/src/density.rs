//! trilux-io images → `mesh_sampling::DensityTexture`.

use mesh_sampling::{Channel, DensityTexture};
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

/// mesh-sampling's wrap mode for a material's (both follow glTF's
/// sampler semantics).
pub fn sampling_wrap(wrap: trilux_io::mesh::Wrap) -> mesh_sampling::Wrap {
    match wrap {
        trilux_io::mesh::Wrap::Repeat => mesh_sampling::Wrap::Repeat,
        trilux_io::mesh::Wrap::MirroredRepeat => mesh_sampling::Wrap::MirroredRepeat,
        trilux_io::mesh::Wrap::ClampToEdge => mesh_sampling::Wrap::ClampToEdge,
    }
}
