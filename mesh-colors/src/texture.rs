//! A plain 2D texture with bilinear and trilinear lookups: the source of
//! a conversion, the target of a bake, and the baseline the benchmarks
//! compare mesh colour lookups against.

use crate::{Error, MAX_CHANNELS};

/// How lookups outside `[0, 1]` behave: glTF's sampler wrap modes, with
/// the same names and meaning in every trilux crate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Wrap {
    /// Tile the texture (glTF `REPEAT`, the OBJ/MTL default).
    #[default]
    Repeat,
    /// Tile, mirroring every other copy (glTF `MIRRORED_REPEAT`): texel
    /// `-1` reads texel 0, texel `n` reads texel `n − 1`.
    MirroredRepeat,
    /// Extend the edge texels (glTF `CLAMP_TO_EDGE`).
    ClampToEdge,
}

/// The texel that index `i` reads among `n` (≥ 1) under `wrap`.
#[inline]
pub(crate) fn wrap_index(wrap: Wrap, i: i64, n: usize) -> usize {
    let n = n as i64;
    match wrap {
        Wrap::Repeat => i.rem_euclid(n) as usize,
        Wrap::MirroredRepeat => {
            let k = i.rem_euclid(2 * n);
            (if k < n { k } else { 2 * n - 1 - k }) as usize
        }
        Wrap::ClampToEdge => i.clamp(0, n - 1) as usize,
    }
}

/// A `width × height` texture of `channels` `f32` channels, row-major,
/// row 0 at `v = 0` (glTF's convention, and `trilux-io`'s `TriMesh` UVs
/// for every format it reads). Texel `(x, y)` has its centre at
/// `((x + ½)/width, (y + ½)/height)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    width: usize,
    height: usize,
    channels: usize,
    wrap: Wrap,
    data: Vec<f32>,
    /// Coarser levels for trilinear lookups, each half the size (box
    /// filtered), down to 1×1; empty until [`Texture::build_mips`].
    mips: Vec<Texture>,
}

impl Texture {
    /// A texture from its texels.
    ///
    /// # Errors
    /// [`Error::BadTexture`] when a size is zero or `data.len()` is not
    /// `width · height · channels`; [`Error::BadChannels`].
    ///
    /// # Example
    /// ```
    /// use mesh_colors::Texture;
    /// // 2×1 grey texels, row 0 first (`v = 0` is row 0).
    /// let t = Texture::new(2, 1, 1, vec![0.0, 1.0])?;
    /// let mut out = [0.0];
    /// t.bilinear([0.5, 0.5], &mut out); // between the two texel centres
    /// assert!((out[0] - 0.5).abs() < 1e-6);
    /// assert!(Texture::new(2, 1, 1, vec![0.0]).is_err()); // too few texels
    /// # Ok::<(), mesh_colors::Error>(())
    /// ```
    pub fn new(
        width: usize,
        height: usize,
        channels: usize,
        data: Vec<f32>,
    ) -> Result<Self, Error> {
        if channels == 0 || channels > MAX_CHANNELS {
            return Err(Error::BadChannels(channels));
        }
        let expected = width.saturating_mul(height).saturating_mul(channels);
        if width == 0 || height == 0 || data.len() != expected {
            return Err(Error::BadTexture {
                width,
                height,
                channels,
                expected,
                got: data.len(),
            });
        }
        Ok(Self {
            width,
            height,
            channels,
            wrap: Wrap::Repeat,
            data,
            mips: Vec::new(),
        })
    }

    /// The same texture with another wrap mode.
    pub fn with_wrap(mut self, wrap: Wrap) -> Self {
        self.wrap = wrap;
        for m in &mut self.mips {
            m.wrap = wrap;
        }
        self
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Channels per texel.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The wrap mode.
    pub fn wrap(&self) -> Wrap {
        self.wrap
    }

    /// The texels.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// Texel `(x, y)`, `None` outside the texture.
    pub fn texel(&self, x: usize, y: usize) -> Option<&[f32]> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let i = (y * self.width + x) * self.channels;
        Some(&self.data[i..i + self.channels])
    }

    #[inline]
    fn wrap_index(&self, i: i64, n: usize) -> usize {
        wrap_index(self.wrap, i, n)
    }

    /// Bilinear lookup at `uv` into `out` (`channels()` values). Non-finite
    /// UVs read texel (0, 0).
    #[inline]
    pub fn bilinear(&self, uv: [f32; 2], out: &mut [f32]) {
        let x = uv[0] * self.width as f32 - 0.5;
        let y = uv[1] * self.height as f32 - 0.5;
        let (x, y) = if x.is_finite() && y.is_finite() {
            (x, y)
        } else {
            (0.0, 0.0)
        };
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let xa = self.wrap_index(x0, self.width);
        // Wrapping: a coordinate beyond ±2⁶³ saturates the cast, and its
        // neighbour must not overflow (such a lookup reads an edge texel).
        let xb = self.wrap_index(x0.wrapping_add(1), self.width);
        let ya = self.wrap_index(y0, self.height);
        let yb = self.wrap_index(y0.wrapping_add(1), self.height);
        let c = self.channels;
        let (ra, rb) = (ya * self.width, yb * self.width);
        let t00 = &self.data[(ra + xa) * c..(ra + xa + 1) * c];
        let t10 = &self.data[(ra + xb) * c..(ra + xb + 1) * c];
        let t01 = &self.data[(rb + xa) * c..(rb + xa + 1) * c];
        let t11 = &self.data[(rb + xb) * c..(rb + xb + 1) * c];
        let (w00, w10, w01, w11) = (
            (1.0 - fx) * (1.0 - fy),
            fx * (1.0 - fy),
            (1.0 - fx) * fy,
            fx * fy,
        );
        for (ch, o) in out.iter_mut().enumerate().take(c) {
            *o = w00 * t00[ch] + w10 * t10[ch] + w01 * t01[ch] + w11 * t11[ch];
        }
    }

    /// Builds the MIP chain (2×2 box filter, odd sizes round up by clamping)
    /// for [`Texture::trilinear`].
    pub fn build_mips(&mut self) {
        self.mips.clear();
        let mut level = self.clone_base();
        while level.width > 1 || level.height > 1 {
            let (w, h) = (level.width.div_ceil(2), level.height.div_ceil(2));
            let c = level.channels;
            let mut data = vec![0.0f32; w * h * c];
            for y in 0..h {
                for x in 0..w {
                    let xs = [2 * x, (2 * x + 1).min(level.width - 1)];
                    let ys = [2 * y, (2 * y + 1).min(level.height - 1)];
                    for ch in 0..c {
                        let mut s = 0.0;
                        for &yy in &ys {
                            for &xx in &xs {
                                s += level.data[(yy * level.width + xx) * c + ch];
                            }
                        }
                        data[(y * w + x) * c + ch] = 0.25 * s;
                    }
                }
            }
            let next = Texture {
                width: w,
                height: h,
                channels: c,
                wrap: self.wrap,
                data,
                mips: Vec::new(),
            };
            self.mips.push(next.clone_base());
            level = next;
        }
    }

    fn clone_base(&self) -> Texture {
        Texture {
            width: self.width,
            height: self.height,
            channels: self.channels,
            wrap: self.wrap,
            data: self.data.clone(),
            mips: Vec::new(),
        }
    }

    /// Trilinear lookup: `lod` is the MIP level (0 = this texture, the
    /// log2 of the footprint in texels), blended between the two levels
    /// around it. Without [`Texture::build_mips`] it is bilinear.
    #[inline]
    pub fn trilinear(&self, uv: [f32; 2], lod: f32, out: &mut [f32]) {
        let top = self.mips.len() as f32;
        let lod = if lod.is_nan() {
            0.0
        } else {
            lod.clamp(0.0, top)
        };
        let l0 = lod.floor();
        let frac = lod - l0;
        let l0 = l0 as usize;
        let level = |l: usize| if l == 0 { self } else { &self.mips[l - 1] };
        level(l0).bilinear(uv, out);
        if frac > 0.0 && l0 < self.mips.len() {
            let mut fine = [0.0f32; MAX_CHANNELS];
            let c = self.channels;
            level(l0 + 1).bilinear(uv, &mut fine[..c]);
            for (o, &x) in out.iter_mut().zip(&fine[..c]) {
                *o = (1.0 - frac) * *o + frac * x;
            }
        }
    }
}
