//! What an emitter emits: RGB radiance from a texture (times a scale), or
//! one RGB radiance per triangle.

use glam::DVec2;

use crate::{Channel, DensityTexture, Error, Filter, Wrap, luminance};

/// The emitted radiance of an [`Emitter`](crate::Emitter), in the caller's
/// units (W·sr⁻¹·m⁻² per RGB channel, or any consistent unit: the power is
/// in that unit times the mesh's length unit squared).
#[derive(Debug, Clone, Copy)]
pub enum Emission<'a> {
    /// Radiance from an RGB texture looked up at the mesh's UVs (filtered
    /// and wrapped as the texture says), times `scale` (≥ 0, finite).
    Texture {
        /// The texture.
        texture: &'a EmissionTexture,
        /// A factor on every texel (pbrt's and Mitsuba's `scale`).
        scale: f32,
    },
    /// One RGB radiance per triangle, constant over it.
    PerFace(&'a [[f32; 3]]),
}

/// An RGB emission texture: linear RGB radiance per texel, filtered and
/// wrapped like a [`DensityTexture`] (texel `(x, y)` covers
/// `u ∈ [x/W, (x+1)/W)`, `v ∈ [y/H, (y+1)/H)`, row 0 at `v = 0`: glTF's
/// convention, the one `trilux-io` images and meshes use). It keeps the
/// Rec. 709 [`luminance`] of its texels as a [`DensityTexture`]: the
/// density the texture strategies sample by, and what
/// [`Emitter::power`](crate::Emitter::power) integrates. Luminance is
/// linear in RGB, so the filtered luminance is the luminance of the
/// filtered RGB: the density is proportional to the luminance of the
/// radiance returned, everywhere.
///
/// # Example
/// ```
/// use mesh_sampling::EmissionTexture;
///
/// // 2×1 texels: black, and a warm white.
/// let texture = EmissionTexture::new(2, 1, vec![[0.0; 3], [1.0, 0.9, 0.8]])?;
/// assert!(texture.luminance().texels()[1] > 0.9);
/// # Ok::<(), mesh_sampling::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct EmissionTexture {
    rgb: Vec<[f32; 3]>,
    luminance: DensityTexture,
    /// Whether some texel has zero luminance (all three channels zero).
    dark_texel: bool,
}

impl EmissionTexture {
    /// A texture of `width × height` RGB texels, row by row.
    ///
    /// # Errors
    /// [`Error::InvalidRadianceTexel`] naming the first texel with a
    /// negative, NaN or infinite channel; [`Error::EmptyTexture`],
    /// [`Error::TextureTooLarge`], [`Error::TextureSize`] as for
    /// [`DensityTexture::new`].
    pub fn new(width: usize, height: usize, rgb: Vec<[f32; 3]>) -> Result<Self, Error> {
        if let Some((i, &value)) = rgb
            .iter()
            .flatten()
            .enumerate()
            .find(|(_, c)| !(c.is_finite() && **c >= 0.0))
        {
            let texel = i / 3;
            let w = width.max(1);
            return Err(Error::InvalidRadianceTexel {
                x: texel % w,
                y: texel / w,
                channel: i % 3,
                value,
            });
        }
        let texels: Vec<f32> = rgb.iter().map(|&c| luminance(c)).collect();
        let dark_texel = texels.contains(&0.0);
        let luminance = DensityTexture::new(width, height, texels)?;
        Ok(Self {
            rgb,
            luminance,
            dark_texel,
        })
    }

    /// A texture from interleaved pixels of `channels ≥ 3` channels, the
    /// first three linear RGB (a `trilux-io` RGBA image: 4; the rest,
    /// alpha, is ignored).
    ///
    /// # Errors
    /// [`Error::InvalidChannel`] for fewer than three channels,
    /// [`Error::TextureSize`] for data that is not `width · height ·
    /// channels` values, and the errors of [`new`](Self::new).
    pub fn from_channels(
        width: usize,
        height: usize,
        data: &[f32],
        channels: usize,
    ) -> Result<Self, Error> {
        if channels < 3 {
            return Err(Error::InvalidChannel {
                channel: Channel::Index(2),
                channels,
            });
        }
        let expected = width.saturating_mul(height).saturating_mul(channels);
        if data.len() != expected {
            return Err(Error::TextureSize {
                expected,
                len: data.len(),
            });
        }
        let rgb = data
            .chunks_exact(channels)
            .map(|p| [p[0], p[1], p[2]])
            .collect();
        Self::new(width, height, rgb)
    }

    /// The same texture with wrap mode `wrap`.
    #[must_use]
    pub fn with_wrap(mut self, wrap: Wrap) -> Self {
        self.luminance = self.luminance.with_wrap(wrap);
        self
    }

    /// The same texture with filter `filter`.
    #[must_use]
    pub fn with_filter(mut self, filter: Filter) -> Self {
        self.luminance = self.luminance.with_filter(filter);
        self
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.luminance.width()
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.luminance.height()
    }

    /// The RGB texels, row by row.
    pub fn texels(&self) -> &[[f32; 3]] {
        &self.rgb
    }

    /// The texels' Rec. 709 luminance, with this texture's wrap and
    /// filter: the density the texture strategies sample by.
    pub fn luminance(&self) -> &DensityTexture {
        &self.luminance
    }

    /// Whether some texel is black (zero luminance), so that the
    /// filtered emission can be zero on part of a sub-triangle whose
    /// barycenter sees none of it (see
    /// [`EmitterOptions::defensive_fraction`](crate::EmitterOptions::defensive_fraction)).
    pub fn has_black_texel(&self) -> bool {
        self.dark_texel
    }

    /// Heap memory used (RGB texels and the luminance texture), in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.rgb.len() * size_of::<[f32; 3]>() + self.luminance.memory_bytes()
    }

    /// The filtered RGB at texture coordinate `uv` (without an emitter's
    /// scale): the same taps and weights as the luminance's
    /// [`DensityTexture::eval`].
    pub fn eval(&self, uv: DVec2) -> [f64; 3] {
        let mut rgb = [0.0; 3];
        for (i, w) in self.luminance.taps(uv) {
            for (c, &t) in rgb.iter_mut().zip(&self.rgb[i]) {
                *c += w * f64::from(t);
            }
        }
        rgb
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The filtered RGB's luminance is the filtered luminance, for both
    /// filters and every wrap, inside and outside the unit square.
    #[test]
    fn the_filtered_rgb_has_the_filtered_luminance() {
        let rgb: Vec<[f32; 3]> = (0..12)
            .map(|k| [(k % 5) as f32, (k * 7 % 3) as f32, 0.5 * (k % 2) as f32])
            .collect();
        for filter in [Filter::Bilinear, Filter::Nearest] {
            for wrap in [Wrap::Repeat, Wrap::MirroredRepeat, Wrap::ClampToEdge] {
                let t = EmissionTexture::new(4, 3, rgb.clone())
                    .unwrap()
                    .with_filter(filter)
                    .with_wrap(wrap);
                for k in 0..200 {
                    let uv = DVec2::new(k as f64 * 0.0173 - 0.7, k as f64 * 0.0291 - 1.3);
                    let c = t.eval(uv);
                    let y = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                    let want = t.luminance().eval(uv);
                    assert!(
                        (y - want).abs() <= 1e-5 * want.max(1.0),
                        "{uv}: {y} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn bad_texels_and_sizes_are_errors() {
        let e = EmissionTexture::new(2, 2, vec![[1.0; 3], [1.0; 3], [1.0, -1.0, 0.0], [0.0; 3]]);
        let e = e.unwrap_err();
        assert_eq!(
            e,
            Error::InvalidRadianceTexel {
                x: 0,
                y: 1,
                channel: 1,
                value: -1.0
            }
        );
        assert_eq!(
            e.to_string(),
            "emission texel (0, 1) has G = -1: radiance must be finite and >= 0"
        );
        let e = EmissionTexture::new(2, 2, vec![[f32::NAN, 0.0, 0.0]; 4]).unwrap_err();
        assert!(e.to_string().contains("(0, 0) has R = NaN"), "{e}");
        assert!(matches!(
            EmissionTexture::new(2, 2, vec![[1.0; 3]; 3]),
            Err(Error::TextureSize {
                expected: 4,
                len: 3
            })
        ));
        assert!(matches!(
            EmissionTexture::from_channels(1, 1, &[1.0, 1.0], 2),
            Err(Error::InvalidChannel { channels: 2, .. })
        ));
        assert!(matches!(
            EmissionTexture::from_channels(2, 1, &[1.0; 7], 4),
            Err(Error::TextureSize {
                expected: 8,
                len: 7
            })
        ));
        let t = EmissionTexture::from_channels(2, 1, &[1.0, 2.0, 3.0, 0.5, 0.0, 0.0, 0.0, 1.0], 4)
            .unwrap();
        assert_eq!(t.texels(), &[[1.0, 2.0, 3.0], [0.0, 0.0, 0.0]]);
        assert!(t.has_black_texel());
    }
}
