//! OpenEXR layouts the image crate refuses, read through the `exr` crate:
//! a lone luminance channel `Y` (grey), luminance/chroma `Y RY BY`
//! (OpenEXR's `RgbaYca`, *Technical Introduction to OpenEXR*, "Luminance/
//! Chroma Images": `RY = (R − Y) / Y`, `BY = (B − Y) / Y`, with Rec. 709
//! weights for `Y`), and `R G B [A]` in any order, with `f16`, `f32` or
//! `u32` samples. The first layer is read; its channels may carry a layer
//! prefix (`diffuse.R`). Anything else is an error naming the channels
//! found.

use std::io::Cursor as IoCursor;
use std::path::Path;

use exr::prelude::traits::*;
use exr::prelude::{AnyChannels, FlatSamples, Image as ExrImage, Layer};
use image::ImageFormat;

use crate::error::{Error, ErrorKind, Result};
use crate::image::{Image, ReadOptions, check_conversion_budget, contain_codec_panic};

/// Decodes `bytes` through the exr crate after the image crate refused
/// them with `refused` (kept in the error when the layout is not read
/// here either).
pub(crate) fn decode(
    bytes: &[u8],
    name: &Path,
    options: ReadOptions,
    refused: Error,
) -> Result<Image> {
    let codec = |source: Box<dyn std::error::Error + Send + Sync>| {
        Error::new(
            name,
            ErrorKind::Codec {
                format: "OpenEXR",
                source,
            },
        )
    };
    // The budget of the first layer's pixels, from the header, before the
    // samples are allocated (the blocks were checked by the caller).
    let read_meta = || exr::meta::MetaData::read_from_buffered(IoCursor::new(bytes), false);
    let meta = contain_codec_panic(name, ImageFormat::OpenExr, read_meta)?
        .map_err(|e| codec(Box::new(e)))?;
    let Some(header) = meta.headers.first() else {
        return Err(refused);
    };
    let size = header.layer_size;
    let (width, height) = (
        u32::try_from(size.0).unwrap_or(u32::MAX),
        u32::try_from(size.1).unwrap_or(u32::MAX),
    );
    check_conversion_budget(name, width, height, options)?;
    let read = || {
        exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_buffered(IoCursor::new(bytes))
    };
    let image: ExrImage<Layer<AnyChannels<FlatSamples>>> =
        contain_codec_panic(name, ImageFormat::OpenExr, read)?.map_err(|e| codec(Box::new(e)))?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.0, layer.size.1);
    check_conversion_budget(
        name,
        u32::try_from(w).unwrap_or(u32::MAX),
        u32::try_from(h).unwrap_or(u32::MAX),
        options,
    )?;
    let channels = &layer.channel_data.list;
    let names: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
    // A channel by its name without a layer prefix ("diffuse.R" is "R").
    let find = |wanted: &str| {
        channels.iter().position(|c| {
            let name = c.name.to_string();
            name.rsplit('.').next() == Some(wanted)
        })
    };
    let pixels = w * h;
    let values = |k: usize| -> Option<Vec<f32>> {
        let c = &channels[k];
        // Subsampled channels hold fewer samples than pixels.
        (c.sample_data.len() == pixels && c.sampling == exr::math::Vec2(1, 1))
            .then(|| c.sample_data.values_as_f32().collect())
    };
    let unread = |why: &str| {
        Error::new(
            name,
            ErrorKind::Unsupported(format!(
                "an OpenEXR channel layout {why} (channels found: {}; read are R G B [A], Y, \
                 Y RY BY)",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )),
        )
    };
    let alpha = match find("A") {
        Some(k) => Some(values(k).ok_or_else(|| unread("with a subsampled A"))?),
        None => None,
    };
    let rgb: [Vec<f32>; 3] = match (find("R"), find("G"), find("B"), find("Y")) {
        (Some(r), Some(g), Some(b), _) => [r, g, b].map(|k| values(k).unwrap_or_default()),
        (_, _, _, Some(y)) => {
            let luminance = values(y).ok_or_else(|| unread("with a subsampled Y"))?;
            match (find("RY"), find("BY")) {
                (Some(ry), Some(by)) => {
                    let (Some(ry), Some(by)) = (values(ry), values(by)) else {
                        return Err(unread("with subsampled chroma RY BY"));
                    };
                    from_luminance_chroma(&luminance, &ry, &by)
                }
                _ => [luminance.clone(), luminance.clone(), luminance],
            }
        }
        _ => return Err(unread("without R G B or Y")),
    };
    if rgb.iter().any(|c| c.len() != pixels) {
        return Err(unread("with a subsampled R, G or B"));
    }
    let pixels = (0..pixels)
        .map(|i| {
            [
                rgb[0][i],
                rgb[1][i],
                rgb[2][i],
                alpha.as_ref().map_or(1.0, |a| a[i]),
            ]
        })
        .collect();
    Ok(Image {
        width: w as u32,
        height: h as u32,
        pixels,
    })
}

/// Rec. 709 luminance weights (OpenEXR's default chromaticities).
const WEIGHTS: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// `R G B` from `Y RY BY`: `R = (RY + 1) Y`, `B = (BY + 1) Y`, and `G`
/// from `Y = wr R + wg G + wb B`.
fn from_luminance_chroma(y: &[f32], ry: &[f32], by: &[f32]) -> [Vec<f32>; 3] {
    let r: Vec<f32> = y.iter().zip(ry).map(|(y, ry)| (ry + 1.0) * y).collect();
    let b: Vec<f32> = y.iter().zip(by).map(|(y, by)| (by + 1.0) * y).collect();
    let g = y
        .iter()
        .zip(r.iter().zip(&b))
        .map(|(y, (r, b))| (y - WEIGHTS[0] * r - WEIGHTS[2] * b) / WEIGHTS[1])
        .collect();
    [r, g, b]
}
