//! Images: the real PNG and HDR files of `$TRILUX_DATA`, sRGB handling,
//! round trips through PNG (8/16 bit) and EXR (f32/f16), and hostile or
//! broken files.

use crate::support;

use std::path::Path;

use support::{data_dir, scratch};

use trilux_io::ErrorKind;
use trilux_io::image::{self, ExrPrecision, Image, PngDepth, ReadOptions};

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn real_images_match_the_data_readme() {
    let data = data_dir().expect("TRILUX_DATA names the data folder");
    let spot = image::read(data.join("textures/spot_texture.png")).unwrap();
    assert_eq!((spot.width, spot.height), (1024, 1024));
    assert!(
        spot.pixels
            .iter()
            .all(|p| p[3] == 1.0 && p.iter().all(|c| (0.0..=1.0).contains(c)))
    );
    // HDR maps: size and luminance extremes from the data README.
    for (file, max_l, min_l) in [
        ("hdr/spiaggia_di_mondello_1k.hdr", 70_948.0, 0.00869),
        ("hdr/kloppenheim_06_1k.hdr", 19.87, 0.293),
    ] {
        let hdr = image::read(data.join(file)).unwrap();
        assert_eq!((hdr.width, hdr.height), (1024, 512), "{file}");
        let l = hdr.luminance();
        let max = l.iter().copied().fold(0.0f32, f32::max);
        let min = l.iter().copied().fold(f32::INFINITY, f32::min);
        assert!((max / max_l - 1.0).abs() < 0.01, "{file}: max {max}");
        assert!((min / min_l - 1.0).abs() < 0.01, "{file}: min {min}");
    }
    let helmet = data.join("gltf/FlightHelmet");
    let mut count = 0;
    for entry in std::fs::read_dir(&helmet).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "png") {
            let img = image::read(&path).unwrap();
            assert!(img.width == 512 || img.width == 32, "{}", path.display());
            count += 1;
        }
    }
    assert_eq!(count, 15);
}

fn gradient(width: u32, height: u32) -> Image {
    let pixels = (0..width * height)
        .map(|i| {
            let t = i as f32 / (width * height - 1) as f32;
            [t, 1.0 - t, t * t, 0.5 + 0.5 * t]
        })
        .collect();
    Image {
        width,
        height,
        pixels,
    }
}

#[test]
fn srgb_is_decoded_unless_raw() {
    let dir = scratch("srgb");
    let g = image::srgb_to_linear(128.0 / 255.0);
    let grey = Image {
        width: 1,
        height: 1,
        pixels: vec![[g, g, g, 1.0]],
    };
    let path = dir.join("grey.png");
    image::write_png(&path, &grey, PngDepth::Eight).unwrap();
    let decoded = image::read(&path).unwrap();
    assert!(
        (decoded.pixels[0][0] - 0.215_860_5).abs() < 1e-6,
        "{:?}",
        decoded.pixels[0]
    );
    let raw = image::read_with(
        &path,
        ReadOptions {
            raw: true,
            ..ReadOptions::default()
        },
    )
    .unwrap();
    assert!((raw.pixels[0][0] - 128.0 / 255.0).abs() < 1e-6);
    for c in [0.0f32, 0.001, 0.04, 0.2, 0.5, 0.9, 1.0] {
        assert!((image::srgb_to_linear(image::linear_to_srgb(c)) - c).abs() < 1e-6);
    }
}

#[test]
fn png_and_exr_round_trips() {
    let dir = scratch("roundtrip");
    let img = gradient(37, 23);
    let cases: [(&str, f32); 4] = [
        ("a8.png", 0.01),
        ("a16.png", 1e-4),
        ("f32.exr", 0.0),
        ("f16.exr", 1e-3),
    ];
    for (name, tolerance) in cases {
        let path = dir.join(name);
        match name {
            "a8.png" => image::write_png(&path, &img, PngDepth::Eight).unwrap(),
            "a16.png" => image::write_png(&path, &img, PngDepth::Sixteen).unwrap(),
            "f32.exr" => image::write_exr(&path, &img, ExrPrecision::F32).unwrap(),
            _ => image::write_exr(&path, &img, ExrPrecision::F16).unwrap(),
        }
        let back = image::read(&path).unwrap();
        assert_eq!((back.width, back.height), (37, 23), "{name}");
        let worst = back
            .pixels
            .iter()
            .zip(&img.pixels)
            .flat_map(|(a, b)| (0..4).map(move |k| (a[k] - b[k]).abs()))
            .fold(0.0f32, f32::max);
        assert!(worst <= tolerance, "{name}: worst error {worst}");
    }
    // HDR values survive EXR.
    let bright = Image {
        width: 1,
        height: 1,
        pixels: vec![[70_948.0, 1e-4, 3.5, 1.0]],
    };
    let path = dir.join("bright.exr");
    image::write_exr(&path, &bright, ExrPrecision::F32).unwrap();
    assert_eq!(image::read(&path).unwrap(), bright);
}

#[test]
fn jpeg_is_read_and_srgb_decoded() {
    // The data set has no JPEG: encode one with the image crate.
    let dir = scratch("jpeg");
    let path = dir.join("flat.jpg");
    let rgb = ::image::RgbImage::from_pixel(16, 8, ::image::Rgb([200, 100, 50]));
    rgb.save(&path).unwrap();
    let img = image::read(&path).unwrap();
    assert_eq!((img.width, img.height), (16, 8));
    let expected = [200.0f32, 100.0, 50.0].map(|c| image::srgb_to_linear(c / 255.0));
    for p in &img.pixels {
        for k in 0..3 {
            assert!((p[k] - expected[k]).abs() < 0.02, "{p:?} vs {expected:?}");
        }
        assert_eq!(p[3], 1.0);
    }
}

/// CRC-32 (PNG's polynomial), to forge a valid header in the test.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

#[test]
fn hostile_and_broken_images_are_refused() {
    let dir = scratch("hostile");
    // A 60-byte PNG whose header claims 100000 × 100000 RGBA pixels (40 GB).
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend_from_slice(&100_000u32.to_be_bytes());
    ihdr.extend_from_slice(&100_000u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 6, 0, 0, 0]);
    png.extend_from_slice(&13u32.to_be_bytes());
    png.extend_from_slice(&ihdr);
    png.extend_from_slice(&crc32(&ihdr).to_be_bytes());
    let path = dir.join("huge.png");
    std::fs::write(&path, &png).unwrap();
    let err = image::read(&path).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::LimitExceeded(_)), "{err}");

    // A real image beyond a caller's smaller limit.
    let small = gradient(64, 64);
    let path = dir.join("ok.png");
    image::write_png(&path, &small, PngDepth::Eight).unwrap();
    let limited = ReadOptions {
        max_dimension: 32,
        ..ReadOptions::default()
    };
    let err = image::read_with(&path, limited).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::LimitExceeded(_)), "{err}");

    // Truncated data is a codec error with the codec's message behind it.
    let bytes = std::fs::read(&path).unwrap();
    let cut = dir.join("cut.png");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let err = image::read(&cut).unwrap_err();
    assert!(
        matches!(
            err.kind,
            ErrorKind::Codec { format: "PNG", .. } | ErrorKind::Io(_)
        ),
        "{err}"
    );
    assert!(std::error::Error::source(&err).is_some());

    let err = image::read(dir.join("picture.gif")).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::UnknownExtension(..)), "{err}");
    let err = image::read(dir.join("missing.png")).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::Io(_)), "{err}");
    let wrong = Image {
        width: 2,
        height: 2,
        pixels: vec![[0.0; 4]; 3],
    };
    let err = image::write_png(dir.join("w.png"), &wrong, PngDepth::Eight).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::InvalidInput(_)), "{err}");
}

/// The f32 RGBA conversion after decoding has its own budget: a 64×64
/// image needs 131,072 bytes at the conversion's peak, so a budget of
/// 100,000 refuses it with that number, before anything is decoded.
#[test]
fn the_rgba_conversion_is_checked_against_the_budget() {
    let dir = scratch("budget");
    let path = dir.join("g.png");
    image::write_png(&path, &gradient(64, 64), PngDepth::Eight).unwrap();
    let tight = ReadOptions {
        max_bytes: 100_000,
        ..ReadOptions::default()
    };
    let err = image::read_with(&path, tight).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::LimitExceeded(_)), "{err}");
    let text = err.to_string();
    assert!(text.contains("131072") && text.contains("100000"), "{text}");
    let enough = ReadOptions {
        max_bytes: 131_072 + 64 * 64 * 4,
        ..ReadOptions::default()
    };
    assert_eq!(image::read_with(&path, enough).unwrap().width, 64);
}

/// `Error::source()` reaches the codec's own error and the I/O error, and
/// the chain can be walked to its end.
#[test]
fn error_sources_form_a_chain() {
    let dir = scratch("sources");
    let path = dir.join("g.png");
    image::write_png(&path, &gradient(8, 8), PngDepth::Eight).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    let n = bytes.len();
    bytes[n - 20] ^= 0xFF; // corrupt the image data's checksum region
    bytes.truncate(n - 12);
    let broken = dir.join("broken.png");
    std::fs::write(&broken, &bytes).unwrap();
    let err = image::read(&broken).unwrap_err();
    let mut chain = vec![err.to_string()];
    let mut source = std::error::Error::source(&err);
    while let Some(s) = source {
        chain.push(s.to_string());
        source = s.source();
    }
    assert!(chain.len() >= 2, "{chain:?}");
    assert!(
        chain[0].starts_with(&broken.display().to_string()),
        "{chain:?}"
    );

    let err = image::read(dir.join("missing.png")).unwrap_err();
    let io = std::error::Error::source(&err).expect("the I/O error");
    assert!(io.downcast_ref::<std::io::Error>().is_some());
    assert_eq!(
        io.downcast_ref::<std::io::Error>().unwrap().kind(),
        std::io::ErrorKind::NotFound
    );

    let err = trilux_io::mesh::gltf::from_bytes(b"{ not json", "bad.gltf", Default::default())
        .unwrap_err();
    assert!(matches!(err.kind, ErrorKind::Codec { format: "glTF", .. }));
    assert!(std::error::Error::source(&err).is_some(), "{err}");
}

/// Rec. 709 luminance: the values every trilux crate tests
/// (0.2126·0.5 + 0.7152·0.25 + 0.0722·2 = 0.4295).
#[test]
fn luminance_is_rec_709() {
    for (rgb, y) in [
        ([1.0, 0.0, 0.0], 0.2126),
        ([0.0, 1.0, 0.0], 0.7152),
        ([0.0, 0.0, 1.0], 0.0722),
        ([0.5, 0.25, 2.0], 0.4295),
    ] {
        assert!((image::luminance(rgb) - y).abs() < 1e-6, "{rgb:?}");
    }
    let picture = Image {
        width: 2,
        height: 1,
        pixels: vec![[1.0, 0.0, 0.0, 0.5], [0.5, 0.25, 2.0, 1.0]],
    };
    let y = picture.luminance();
    assert!((y[0] - 0.2126).abs() < 1e-6 && (y[1] - 0.4295).abs() < 1e-6);
}

#[test]
fn write_picks_the_format_by_extension() {
    let dir = scratch("write-ext");
    let picture = gradient(4, 3);
    image::write(dir.join("a.png"), &picture).unwrap();
    image::write(dir.join("a.exr"), &picture).unwrap();
    let exr = image::read(dir.join("a.exr")).unwrap();
    assert_eq!(exr, picture, "EXR f32 is exact");
    assert_eq!(image::read(dir.join("a.png")).unwrap().height, 3);
    let err = image::write(dir.join("a.tga"), &picture).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::UnknownExtension(..)), "{err}");
}

/// An OpenEXR file of 3×2 pixels whose header declares 16,777,024×64
/// tiles (found by fuzzing): refused from the header, with the bytes it
/// would need, instead of letting the codec allocate gigabytes.
#[test]
fn exr_blocks_are_checked_against_the_budget() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz-regressions/image");
    let file = dir.join("oom-b2b0ea4ec0adfb2e3826f7438fa9d496d9b0ef1c");
    let data = std::fs::read(file).unwrap();
    let err = image::decode(&data[1..], "tiles.exr", ReadOptions::default()).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::LimitExceeded(_)), "{err}");
    assert!(err.to_string().contains("16777024×64"), "{err}");
}

/// A B44-compressed OpenEXR file on which the codec's decompression
/// overflows (found by fuzzing): the panic inside the codec comes back as
/// a codec error.
#[test]
fn a_codec_panic_is_an_error() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz-regressions/image");
    let data = std::fs::read(dir.join("crash-cad39f76bdd3f9ffaed8ac4fdf5abf694d75a820")).unwrap();
    let options = ReadOptions {
        max_dimension: 4096,
        max_bytes: 64 << 20,
        ..ReadOptions::default()
    };
    // Overflow checks are on in test builds, as in the fuzzer.
    if let Err(err) = image::decode(&data[1..], "b44.exr", options) {
        assert!(
            matches!(
                err.kind,
                ErrorKind::Codec {
                    format: "OpenEXR",
                    ..
                }
            ),
            "{err}"
        );
    }
}
