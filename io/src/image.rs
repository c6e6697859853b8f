//! Images in and out: PNG, JPEG, Radiance HDR and OpenEXR in; PNG (8 or
//! 16 bit, sRGB-encoded) and OpenEXR (f32 or f16, linear) out. Pixels are
//! always linear `f32` RGBA, so samplers and colour conversion see the same
//! numbers whatever the file.
//!
//! Files are read the way image tools read them: Radiance HDR with the
//! `#?RGBE` signature as well as `#?RADIANCE`, and any of the eight
//! orientations of its resolution line (`-Y H +X W` … `+X W -Y H`),
//! rotated into top-down rows; OpenEXR layouts the image crate refuses
//! (a lone `Y` channel as grey, `Y RY BY` luminance/chroma, half, float or
//! uint samples, channels in any order) through the `exr` crate.

use std::io::Cursor as IoCursor;
use std::path::Path;

use image::{DynamicImage, ImageError, ImageFormat, ImageReader, Limits};

use crate::error::{Error, ErrorKind, Result};

/// A linear RGBA image, row-major, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `width · height` pixels, linear RGBA (alpha straight, not
    /// premultiplied).
    pub pixels: Vec<[f32; 4]>,
}

/// How to read an image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadOptions {
    /// Keep 8- and 16-bit values as stored (scaled to `[0, 1]`) instead of
    /// decoding sRGB: for data textures such as densities, masks or normal
    /// maps. Float formats are always linear.
    pub raw: bool,
    /// The largest width and height accepted.
    pub max_dimension: u32,
    /// The most memory reading may take, in bytes: the decoder's buffers,
    /// and separately the conversion to linear `f32` RGBA (32 bytes per
    /// pixel at its peak), checked from the header before either
    /// allocates. 4 GiB by default.
    pub max_bytes: u64,
}

impl Default for ReadOptions {
    fn default() -> Self {
        Self {
            raw: false,
            max_dimension: 32_768,
            max_bytes: 4 << 30,
        }
    }
}

/// PNG sample depth.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PngDepth {
    /// 8 bits per channel.
    Eight,
    /// 16 bits per channel.
    Sixteen,
}

/// EXR sample precision.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExrPrecision {
    /// 16-bit half floats.
    F16,
    /// 32-bit floats.
    F32,
}

/// The format for an extension, or the error naming the extensions known.
fn format_of(path: &Path) -> Result<ImageFormat> {
    let ext = crate::error::extension(path);
    match ext.as_str() {
        "png" => Ok(ImageFormat::Png),
        "jpg" | "jpeg" => Ok(ImageFormat::Jpeg),
        "hdr" => Ok(ImageFormat::Hdr),
        "exr" => Ok(ImageFormat::OpenExr),
        _ => Err(Error::new(
            path,
            ErrorKind::UnknownExtension(ext, ".png, .jpg, .jpeg, .hdr, .exr"),
        )),
    }
}

fn format_name(format: ImageFormat) -> &'static str {
    match format {
        ImageFormat::Png => "PNG",
        ImageFormat::Jpeg => "JPEG",
        ImageFormat::Hdr => "Radiance HDR",
        ImageFormat::OpenExr => "OpenEXR",
        _ => "image",
    }
}

/// Reads an image as linear RGBA with the default options (sRGB decoded,
/// at most 32768 pixels a side).
///
/// # Errors
/// [`Error`]: a missing file, an unknown extension, data the codec cannot
/// decode, or dimensions beyond the limits.
pub fn read(path: impl AsRef<Path>) -> Result<Image> {
    read_with(path.as_ref(), ReadOptions::default())
}

/// Reads an image with explicit options.
///
/// # Errors
/// As for [`read`].
pub fn read_with(path: impl AsRef<Path>, options: ReadOptions) -> Result<Image> {
    let path = path.as_ref();
    format_of(path)?;
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    decode(&bytes, path, options)
}

/// Decodes image data (embedded textures, archives); the extension of
/// `name` gives the format, and `name` labels errors.
///
/// # Errors
/// As for [`read`].
pub fn decode(bytes: &[u8], name: impl AsRef<Path>, options: ReadOptions) -> Result<Image> {
    let name = name.as_ref();
    let format = format_of(name)?;
    match format {
        ImageFormat::Hdr => {
            // Other signatures and orientations than the image crate's
            // `#?RADIANCE` `-Y H +X W`: rewritten for it, then rotated.
            let header = crate::image_hdr::parse(bytes, name)?;
            let Some(rewritten) = header.rewritten(bytes) else {
                return decode_with_image(bytes, name, format, options);
            };
            let stored = decode_with_image(&rewritten, name, format, options)?;
            Ok(header.orientation.to_top_down(stored))
        }
        ImageFormat::OpenExr => {
            check_exr_blocks(bytes, name, options)?;
            match decode_with_image(bytes, name, format, options) {
                Ok(image) => Ok(image),
                // Layouts the image crate refuses (a lone `Y`, `Y RY BY`,
                // channels without R G B): read through the exr crate.
                Err(e) if matches!(e.kind, ErrorKind::Codec { .. }) => {
                    crate::image_exr::decode(bytes, name, options, e)
                }
                Err(e) => Err(e),
            }
        }
        _ => decode_with_image(bytes, name, format, options),
    }
}

/// Decodes through the image crate, with the budgets checked first.
fn decode_with_image(
    bytes: &[u8],
    name: &Path,
    format: ImageFormat,
    options: ReadOptions,
) -> Result<Image> {
    let mut limits = Limits::default();
    limits.max_image_width = Some(options.max_dimension);
    limits.max_image_height = Some(options.max_dimension);
    limits.max_alloc = Some(options.max_bytes);
    // The header's size, checked against the budget of the f32 RGBA
    // conversion before the decoder allocates anything.
    let mut probe = ImageReader::with_format(IoCursor::new(bytes), format);
    probe.limits(limits.clone());
    let (width, height) = contain_codec_panic(name, format, || probe.into_dimensions())?
        .map_err(|e| codec_error(name, format, e))?;
    check_conversion_budget(name, width, height, options)?;
    let mut reader = ImageReader::with_format(IoCursor::new(bytes), format);
    reader.limits(limits);
    let image = contain_codec_panic(name, format, || reader.decode())?
        .map_err(|e| codec_error(name, format, e))?;
    // A decoder may report other dimensions than its header (it should
    // not); the budget is checked on what came out as well.
    check_conversion_budget(name, image.width(), image.height(), options)?;
    Ok(to_linear(image, options.raw))
}

/// Runs a codec, turning a panic inside it into an error: the decoders are
/// other crates', and fuzzing found inputs on which one panics (an
/// arithmetic overflow in OpenEXR's B44 decompression, with overflow
/// checks on). Our own code never runs inside.
pub(crate) fn contain_codec_panic<T>(
    name: &Path,
    format: ImageFormat,
    codec: impl FnOnce() -> T,
) -> Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(codec)).map_err(|payload| {
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "no message".to_string());
        Error::new(
            name,
            ErrorKind::Codec {
                format: format_name(format),
                source: format!("the decoder panicked on this data: {message}").into(),
            },
        )
    })
}

/// How many times its raw size a decoder may need for one block of an
/// OpenEXR file (the compressed and the decompressed block, and the
/// samples converted to f32).
const EXR_BLOCK_FACTOR: u128 = 4;

/// Checks every layer of an OpenEXR file against the budget before the
/// codec allocates for it: the layer's pixels, and the largest block (a
/// tile or a group of scan lines), which the header sets independently of
/// the image size (found by fuzzing: a 3×2 image with 16,777,024×64
/// tiles made the codec allocate gigabytes).
fn check_exr_blocks(bytes: &[u8], name: &Path, options: ReadOptions) -> Result<()> {
    let read = || exr::meta::MetaData::read_from_buffered(IoCursor::new(bytes), false);
    let meta = contain_codec_panic(name, ImageFormat::OpenExr, read)?.map_err(|e| {
        Error::new(
            name,
            ErrorKind::Codec {
                format: "OpenEXR",
                // exr's I/O variant prints its cause and returns it.
                source: Box::new(crate::error::Whole(Box::new(e))),
            },
        )
    })?;
    for (index, header) in meta.headers.iter().enumerate() {
        let per_pixel = header.channels.bytes_per_pixel as u128;
        let block = header.max_block_pixel_size();
        let block_bytes = block.0 as u128 * block.1 as u128 * per_pixel * EXR_BLOCK_FACTOR;
        let layer_bytes = header.layer_size.0 as u128 * header.layer_size.1 as u128 * per_pixel;
        for (what, needed) in [("a block of", block_bytes), ("the pixels of", layer_bytes)] {
            if needed > u128::from(options.max_bytes) {
                return Err(Error::new(
                    name,
                    ErrorKind::LimitExceeded(format!(
                        "decoding {what} layer {index} ({}×{} pixels a block) needs {needed} bytes, \
                         more than the budget of {} bytes (ReadOptions::max_bytes)",
                        block.0, block.1, options.max_bytes
                    )),
                ));
            }
        }
    }
    Ok(())
}

/// Bytes per pixel at the peak of the conversion to linear RGBA: the
/// codec's `f32` RGBA buffer and our `[f32; 4]` pixels.
const CONVERSION_BYTES_PER_PIXEL: u64 = 32;

pub(crate) fn check_conversion_budget(
    name: &Path,
    width: u32,
    height: u32,
    options: ReadOptions,
) -> Result<()> {
    if width > options.max_dimension || height > options.max_dimension {
        return Err(Error::new(
            name,
            ErrorKind::LimitExceeded(format!(
                "the image is {width}×{height} pixels, more than the {} a side allowed",
                options.max_dimension
            )),
        ));
    }
    let needed = u64::from(width) * u64::from(height) * CONVERSION_BYTES_PER_PIXEL;
    if needed > options.max_bytes {
        return Err(Error::new(
            name,
            ErrorKind::LimitExceeded(format!(
                "converting the {width}×{height} image to f32 RGBA needs {needed} bytes, \
                 more than the budget of {} bytes (ReadOptions::max_bytes)",
                options.max_bytes
            )),
        ));
    }
    Ok(())
}

fn codec_error(path: &Path, format: ImageFormat, e: ImageError) -> Error {
    let kind = match e {
        ImageError::Limits(l) => ErrorKind::LimitExceeded(format!(
            "{l} (the limits are ReadOptions::max_dimension and max_bytes)"
        )),
        ImageError::IoError(io) => ErrorKind::Io(io),
        other => ErrorKind::Codec {
            format: format_name(format),
            source: Box::new(crate::error::Whole(Box::new(other))),
        },
    };
    Error::new(path, kind)
}

/// sRGB-encoded value in `[0, 1]` to linear (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear value to sRGB-encoded, clamped to `[0, 1]`.
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

fn to_linear(image: DynamicImage, raw: bool) -> Image {
    let float_source = matches!(
        image,
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)
    );
    // Converted in place where it already is f32 RGBA; otherwise the
    // decoded buffer is freed once converted, so the peak stays within
    // CONVERSION_BYTES_PER_PIXEL.
    let rgba = match image {
        DynamicImage::ImageRgba32F(buffer) => buffer,
        other => other.to_rgba32f(),
    };
    let (width, height) = rgba.dimensions();
    let decode = !raw && !float_source;
    let pixels = rgba
        .into_raw()
        .chunks_exact(4)
        .map(|p| {
            let mut px = [p[0], p[1], p[2], p[3]];
            if decode {
                for c in &mut px[..3] {
                    *c = srgb_to_linear(*c);
                }
            }
            px
        })
        .collect();
    Image {
        width,
        height,
        pixels,
    }
}

/// The Rec. 709 (sRGB primaries) luminance of a linear RGB colour:
/// `0.2126 r + 0.7152 g + 0.0722 b` (ITU-R BT.709-6, item 3.2). The same
/// function, with the same name and test values, exists in every trilux
/// crate that needs it.
pub fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

impl Image {
    /// [`luminance`] of each pixel, row-major (for density textures and
    /// maps); alpha is ignored.
    pub fn luminance(&self) -> Vec<f32> {
        self.pixels
            .iter()
            .map(|p| luminance([p[0], p[1], p[2]]))
            .collect()
    }

    pub(crate) fn check(&self, path: &Path) -> Result<()> {
        let expected = u64::from(self.width) * u64::from(self.height);
        if self.pixels.len() as u64 != expected || self.width == 0 || self.height == 0 {
            return Err(Error::new(
                path,
                ErrorKind::InvalidInput(format!(
                    "{} pixels for a {}×{} image",
                    self.pixels.len(),
                    self.width,
                    self.height
                )),
            ));
        }
        Ok(())
    }
}

/// Writes an image, choosing the format by extension: `.png` (8-bit,
/// sRGB-encoded, see [`write_png`]) or `.exr` (f32, linear, see
/// [`write_exr`]).
///
/// # Errors
/// [`ErrorKind::UnknownExtension`] for other extensions; the writer's
/// errors.
pub fn write(path: impl AsRef<Path>, image: &Image) -> Result<()> {
    let path = path.as_ref();
    match crate::error::extension(path).as_str() {
        "png" => write_png(path, image, PngDepth::Eight),
        "exr" => write_exr(path, image, ExrPrecision::F32),
        other => Err(Error::new(
            path,
            ErrorKind::UnknownExtension(other.to_string(), ".png, .exr"),
        )),
    }
}

/// Writes a PNG: colour sRGB-encoded (values above 1 are clipped; tone map
/// first), alpha linear.
///
/// # Errors
/// [`ErrorKind::InvalidInput`] for a pixel count that does not match the
/// size; codec and I/O errors.
pub fn write_png(path: impl AsRef<Path>, image: &Image, depth: PngDepth) -> Result<()> {
    let path = path.as_ref();
    let bytes = encode_png(image, depth, path)?;
    std::fs::write(path, bytes).map_err(|e| Error::io(path, e))
}

/// The PNG file [`write_png`] writes, in memory (`path` names the image
/// in errors): what a glTF writer embeds.
///
/// # Errors
/// As for [`write_png`], without I/O.
pub fn encode_png(image: &Image, depth: PngDepth, path: impl AsRef<Path>) -> Result<Vec<u8>> {
    encode(image, depth, path.as_ref(), true)
}

/// A PNG of data, not colour, in memory: every channel stored as it is
/// (clamped to [0, 1], scaled and rounded), without the sRGB curve — what
/// glTF asks of metallic-roughness and occlusion textures and any scalar
/// map (roughness, a painted density).
///
/// # Errors
/// As for [`encode_png`].
pub fn encode_data_png(image: &Image, depth: PngDepth, path: impl AsRef<Path>) -> Result<Vec<u8>> {
    encode(image, depth, path.as_ref(), false)
}

fn encode(image: &Image, depth: PngDepth, path: &Path, srgb: bool) -> Result<Vec<u8>> {
    image.check(path)?;
    // sRGB-encode colour (unless it is data), keep alpha linear; image's
    // conversion to 8 or 16 bits then clamps to [0, 1], scales and rounds.
    let curve = |c: f32| if srgb { linear_to_srgb(c) } else { c };
    let encoded: Vec<f32> = image
        .pixels
        .iter()
        .flat_map(|p| [curve(p[0]), curve(p[1]), curve(p[2]), p[3]])
        .collect();
    let buffer = image::Rgba32FImage::from_raw(image.width, image.height, encoded)
        .ok_or_else(|| Error::new(path, ErrorKind::InvalidInput("pixel buffer size".into())))?;
    let float = DynamicImage::ImageRgba32F(buffer);
    let dynamic = match depth {
        PngDepth::Eight => DynamicImage::ImageRgba8(float.to_rgba8()),
        PngDepth::Sixteen => DynamicImage::ImageRgba16(float.to_rgba16()),
    };
    let mut bytes = std::io::Cursor::new(Vec::new());
    dynamic
        .write_to(&mut bytes, ImageFormat::Png)
        .map_err(|e| codec_error(path, ImageFormat::Png, e))?;
    Ok(bytes.into_inner())
}

/// Writes an OpenEXR file: linear RGBA, f32 or f16 samples.
///
/// # Errors
/// [`ErrorKind::InvalidInput`] for a pixel count that does not match the
/// size; codec and I/O errors.
pub fn write_exr(path: impl AsRef<Path>, image: &Image, precision: ExrPrecision) -> Result<()> {
    let path = path.as_ref();
    use exr::prelude::f16;
    image.check(path)?;
    let (w, h) = (image.width as usize, image.height as usize);
    let pixel = |x: usize, y: usize| image.pixels[y * w + x];
    let result = match precision {
        ExrPrecision::F32 => exr::prelude::write_rgba_file(path, w, h, |x, y| {
            let p = pixel(x, y);
            (p[0], p[1], p[2], p[3])
        }),
        ExrPrecision::F16 => exr::prelude::write_rgba_file(path, w, h, |x, y| {
            let p = pixel(x, y);
            (
                f16::from_f32(p[0]),
                f16::from_f32(p[1]),
                f16::from_f32(p[2]),
                f16::from_f32(p[3]),
            )
        }),
    };
    result.map_err(|e| match e {
        exr::error::Error::Io(io) => Error::io(path, io),
        other => Error::new(
            path,
            ErrorKind::Codec {
                format: "OpenEXR",
                source: Box::new(other),
            },
        ),
    })
}
