//! Images the way image tools read them (second set of regression inputs
//! and their siblings): OpenEXR layouts the image crate refuses (a lone
//! `Y`, `Y RY BY`, half and float, any channel order) and Radiance HDR
//! files with the `#?RGBE` signature or any of the eight orientations.

use crate::support;

use std::path::{Path, PathBuf};

use exr::prelude::*;
use trilux_io::ErrorKind;
use trilux_io::image::{self, ReadOptions};

fn file(folder: &str, name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/regressions")
        .join(folder)
        .join(name)
}

/// `gray_y.exr` (a single `Y` channel): grey, R = G = B = Y, at the
/// README's values; `gray_rgb.exr` (the control) the same picture.
#[test]
fn exr_luminance_only_is_grey() {
    let grey = image::read(file("exr-luminance-only", "gray_y.exr")).unwrap();
    assert_eq!((grey.width, grey.height), (4, 2));
    let at = |x: usize, y: usize| grey.pixels[y * 4 + x];
    for ((x, y), v) in [
        ((0, 0), 0.25),
        ((3, 0), 2.0),
        ((1, 1), 8.0),
        ((3, 1), 0.125),
    ] {
        assert_eq!(at(x, y), [v, v, v, 1.0], "({x}, {y})");
    }
    let rgb = image::read(file("exr-luminance-only", "gray_rgb.exr")).unwrap();
    assert_eq!(rgb.pixels.len(), grey.pixels.len());
    for (a, b) in rgb.pixels.iter().zip(&grey.pixels) {
        assert!(
            (0..3).all(|c| (a[c] - b[c]).abs() <= 1e-3 * b[c].abs().max(1e-3)),
            "{a:?} {b:?}"
        );
    }
    // Usable as a density: the luminance is Y.
    assert!((grey.luminance()[4 + 1] - 8.0).abs() < 1e-5);
}

/// Writes an EXR with the given named channels of `width × height`.
fn write_channels(path: &Path, width: usize, height: usize, channels: Vec<(&str, FlatSamples)>) {
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .into_iter()
        .map(|(name, samples)| AnyChannel::new(name, samples))
        .collect();
    let layer = Layer::new(
        (width, height),
        LayerAttributes::named("main"),
        Encoding::UNCOMPRESSED,
        AnyChannels::sort(list),
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

/// `Y RY BY` in half and float, written in shuffled order: the RGB they
/// encode (R = (RY + 1) Y, B = (BY + 1) Y, G from the Rec. 709 Y).
#[test]
fn exr_luminance_chroma_and_any_order() {
    let dir = support::scratch("exr-layouts");
    let rgb = [[1.0f32, 0.5, 0.25], [0.0, 2.0, 4.0], [3.0, 3.0, 3.0]];
    let y: Vec<f32> = rgb.iter().map(|p| image::luminance(*p)).collect();
    let ry: Vec<f32> = rgb.iter().zip(&y).map(|(p, y)| (p[0] - y) / y).collect();
    let by: Vec<f32> = rgb.iter().zip(&y).map(|(p, y)| (p[2] - y) / y).collect();
    for half in [false, true] {
        let samples = |v: &[f32]| {
            if half {
                FlatSamples::F16(v.iter().map(|&x| f16::from_f32(x)).collect())
            } else {
                FlatSamples::F32(v.to_vec())
            }
        };
        let path = dir.join(format!("yc_{half}.exr"));
        write_channels(
            &path,
            3,
            1,
            vec![
                ("BY", samples(&by)),
                ("Y", samples(&y)),
                ("RY", samples(&ry)),
            ],
        );
        let decoded = image::read(&path).unwrap();
        let tolerance = if half { 4e-3 } else { 1e-5 };
        for (got, want) in decoded.pixels.iter().zip(&rgb) {
            for c in 0..3 {
                assert!(
                    (got[c] - want[c]).abs() <= tolerance * want[c].abs().max(1.0),
                    "{half}: {got:?} vs {want:?}"
                );
            }
            assert_eq!(got[3], 1.0);
        }
    }
    // R G B A with a layer prefix, alpha first in the file.
    let path = dir.join("prefixed.exr");
    write_channels(
        &path,
        2,
        1,
        vec![
            ("beauty.A", FlatSamples::F32(vec![0.5, 1.0])),
            ("beauty.B", FlatSamples::F32(vec![3.0, 6.0])),
            ("beauty.G", FlatSamples::F32(vec![2.0, 5.0])),
            ("beauty.R", FlatSamples::F32(vec![1.0, 4.0])),
        ],
    );
    let decoded = image::read(&path).unwrap();
    assert_eq!(
        decoded.pixels,
        vec![[1.0, 2.0, 3.0, 0.5], [4.0, 5.0, 6.0, 1.0]]
    );

    // A layout still not read: the error names the channels found.
    let path = dir.join("depth.exr");
    write_channels(&path, 2, 1, vec![("Z", FlatSamples::F32(vec![1.0, 2.0]))]);
    let e = image::read(&path).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Unsupported(_)), "{e}");
    assert!(e.to_string().contains("channels found: Z"), "{e}");

    // The memory budget holds on this path too.
    let path = dir.join("big_y.exr");
    write_channels(
        &path,
        64,
        64,
        vec![("Y", FlatSamples::F32(vec![1.0; 64 * 64]))],
    );
    let tight = ReadOptions {
        max_bytes: 64 * 64 * 8,
        ..ReadOptions::default()
    };
    let e = image::read_with(&path, tight).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::LimitExceeded(_)), "{e}");
    assert!(image::read(&path).is_ok());
}

/// A flat (not run-length encoded) RGBE body: one byte each of R, G, B and
/// the shared exponent per pixel.
fn rgbe(value: [u8; 3], exponent: u8) -> [u8; 4] {
    [value[0], value[1], value[2], exponent]
}

/// The eight orientations of a 3 × 2 picture: each file stores the same
/// picture scanned another way; all read as the `-Y 2 +X 3` file does.
#[test]
fn hdr_signatures_and_every_orientation() {
    let (w, h) = (3usize, 2usize);
    // The picture, top-down rows: pixel (x, y) has R = 10 x + 1, G = y + 1.
    let picture = |x: usize, y: usize| rgbe([10 * x as u8 + 1, y as u8 + 1, 7], 129);
    let body = |first: &str, second: &str| {
        // Scan lines along the first axis, pixels along the second; -Y
        // runs top to bottom, +Y bottom to top, +X left to right, -X right
        // to left.
        let along = |axis: &str, k: usize| -> (Option<usize>, Option<usize>) {
            match axis {
                "-Y" => (None, Some(k)),
                "+Y" => (None, Some(h - 1 - k)),
                "+X" => (Some(k), None),
                _ => (Some(w - 1 - k), None),
            }
        };
        let extent = |axis: &str| if axis.ends_with('Y') { h } else { w };
        let mut out = Vec::new();
        for s in 0..extent(first) {
            for i in 0..extent(second) {
                let (x1, y1) = along(first, s);
                let (x2, y2) = along(second, i);
                out.extend_from_slice(&picture(x1.or(x2).unwrap(), y1.or(y2).unwrap()));
            }
        }
        out
    };
    let dir = support::scratch("hdr-orientations");
    let standard = {
        let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 3\n".to_vec();
        bytes.extend(body("-Y", "+X"));
        image::read(support::write(&dir, "standard.hdr", &bytes)).unwrap()
    };
    assert_eq!((standard.width, standard.height), (3, 2));
    let orientations = [
        ("-Y", "+X"),
        ("-Y", "-X"),
        ("+Y", "+X"),
        ("+Y", "-X"),
        ("+X", "-Y"),
        ("+X", "+Y"),
        ("-X", "-Y"),
        ("-X", "+Y"),
    ];
    for (k, (first, second)) in orientations.into_iter().enumerate() {
        for signature in ["#?RADIANCE", "#?RGBE"] {
            let size = |axis: &str| if axis.ends_with('Y') { h } else { w };
            let mut bytes = format!(
                "{signature}\n# made by hand\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1\n\n{first} {} {second} {}\n",
                size(first),
                size(second)
            )
            .into_bytes();
            bytes.extend(body(first, second));
            let path = support::write(&dir, &format!("o{k}{}.hdr", signature.len()), &bytes);
            let decoded = image::read(&path).unwrap_or_else(|e| panic!("{first} {second}: {e}"));
            assert_eq!(decoded, standard, "{signature} {first} {second}");
        }
    }
    // One by hand: `+Y 2 -X 3` is the picture turned 180°: its first
    // stored pixel is the bottom-right one, (2, 1).
    let mut bytes = b"#?RGBE\n\n+Y 2 -X 3\n".to_vec();
    bytes.extend(body("+Y", "-X"));
    assert_eq!(&bytes[bytes.len() - 24..bytes.len() - 20], &picture(2, 1));
    // Not a Radiance file, and a broken resolution string, are named.
    let e = image::decode(b"P6\n3 2\n", "x.hdr", ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("#?RADIANCE or #?RGBE"), "{e}");
    let e = image::decode(b"#?RGBE\n\n-Y 2 -Y 3\n", "x.hdr", ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("one X and one Y"), "{e}");
}
