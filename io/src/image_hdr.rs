//! Radiance HDR headers (Ward, "Real Pixels", Graphics Gems II, and the
//! Radiance file-format notes): the `#?PROGRAM` signature line (`#?RADIANCE`
//! or `#?RGBE`), variable lines up to an empty line, then the resolution
//! string `A N B M`: `N` scan lines along axis `A`, each of `M` pixels along
//! axis `B`, where `-Y` runs top to bottom, `+Y` bottom to top, `+X` left to
//! right and `-X` right to left. The image crate reads only `#?RADIANCE`
//! and `-Y N +X M`; other files are given to it with those two lines
//! rewritten, and the decoded scan lines are then put where the
//! resolution string says.

use std::path::Path;

use crate::error::{Error, ErrorKind, Result};
use crate::image::Image;

/// The signature the image crate expects.
const RADIANCE: &[u8] = b"#?RADIANCE";

/// The most header bytes searched for the resolution string: Radiance
/// writes a few lines; a file without one ends the search here.
const MAX_HEADER: usize = 1 << 16;

/// Where a stored pixel goes: the resolution string's two axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Orientation {
    /// The scan-line axis is X (`±X N ±Y M`), not Y.
    scan_along_x: bool,
    /// The scan lines run against the image's reading order (`+Y` bottom
    /// to top, or `-X` right to left).
    scan_reversed: bool,
    /// The pixels of a scan line run against reading order.
    pixel_reversed: bool,
}

/// A parsed header: its orientation and where its two rewritten lines are.
#[derive(Debug)]
pub(crate) struct Header {
    pub(crate) orientation: Orientation,
    /// The signature line's end (its `\n`).
    signature_end: usize,
    /// Whether the signature is already `#?RADIANCE`.
    radiance: bool,
    /// The resolution line: start, end (its `\n`), scan lines and pixels.
    resolution: (usize, usize, u64, u64),
}

/// Parses the header of HDR `bytes`.
///
/// # Errors
/// [`ErrorKind::Syntax`] for a missing `#?` signature or resolution
/// string, naming what was found.
pub(crate) fn parse(bytes: &[u8], name: &Path) -> Result<Header> {
    let syntax = |expected: &str, found: &[u8]| {
        Error::new(
            name,
            ErrorKind::Syntax {
                expected: expected.to_string(),
                found: String::from_utf8_lossy(&found[..found.len().min(40)]).into_owned(),
            },
        )
    };
    let head = &bytes[..bytes.len().min(MAX_HEADER)];
    let line_end = |from: usize| {
        head[from..]
            .iter()
            .position(|&b| b == b'\n')
            .map(|k| from + k)
    };
    let signature_end =
        line_end(0).ok_or_else(|| syntax("a #?RADIANCE or #?RGBE signature line", head))?;
    let signature = trim(&head[..signature_end]);
    if !signature.starts_with(b"#?") {
        return Err(syntax("a #?RADIANCE or #?RGBE signature line", signature));
    }
    // Header lines up to the empty line.
    let mut at = signature_end + 1;
    loop {
        let end = line_end(at).ok_or_else(|| {
            syntax(
                "an empty line ending the header",
                &head[at.min(head.len())..],
            )
        })?;
        let line = trim(&head[at..end]);
        at = end + 1;
        if line.is_empty() {
            break;
        }
    }
    let end = line_end(at).ok_or_else(|| {
        syntax(
            "a resolution string such as -Y 512 +X 768",
            &head[at.min(head.len())..],
        )
    })?;
    let line = String::from_utf8_lossy(trim(&head[at..end])).into_owned();
    let words: Vec<&str> = line.split_whitespace().collect();
    let [a, n, b, m] = words[..] else {
        return Err(syntax(
            "a resolution string such as -Y 512 +X 768",
            line.as_bytes(),
        ));
    };
    let (Ok(n), Ok(m)) = (n.parse::<u64>(), m.parse::<u64>()) else {
        return Err(syntax(
            "two sizes in the resolution string",
            line.as_bytes(),
        ));
    };
    let axis = |t: &str| match t {
        "-Y" => Some(('Y', false)),
        "+Y" => Some(('Y', true)),
        "+X" => Some(('X', false)),
        "-X" => Some(('X', true)),
        _ => None,
    };
    let (Some((first, scan_reversed)), Some((second, pixel_reversed))) = (axis(a), axis(b)) else {
        return Err(syntax(
            "axes -Y, +Y, +X or -X in the resolution string",
            line.as_bytes(),
        ));
    };
    if first == second {
        return Err(syntax(
            "one X and one Y axis in the resolution string",
            line.as_bytes(),
        ));
    }
    Ok(Header {
        orientation: Orientation {
            scan_along_x: first == 'X',
            scan_reversed,
            pixel_reversed,
        },
        signature_end,
        radiance: signature == RADIANCE,
        resolution: (at, end, n, m),
    })
}

fn trim(line: &[u8]) -> &[u8] {
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    line.trim_ascii()
}

impl Header {
    /// The file with `#?RADIANCE` and `-Y N +X M` (the stored scan lines
    /// as rows), or `None` when it already has both.
    pub(crate) fn rewritten(&self, bytes: &[u8]) -> Option<Vec<u8>> {
        let standard = self.orientation
            == Orientation {
                scan_along_x: false,
                scan_reversed: false,
                pixel_reversed: false,
            };
        if standard && self.radiance {
            return None;
        }
        let (start, end, n, m) = self.resolution;
        let mut out = Vec::with_capacity(bytes.len() + 16);
        out.extend_from_slice(RADIANCE);
        out.extend_from_slice(&bytes[self.signature_end..start]);
        out.extend_from_slice(format!("-Y {n} +X {m}").as_bytes());
        out.extend_from_slice(&bytes[end..]);
        Some(out)
    }
}

impl Orientation {
    /// The image in top-down rows of left-to-right pixels, from `stored`
    /// (one row per scan line, as the file stores them).
    pub(crate) fn to_top_down(self, stored: Image) -> Image {
        let (scans, per_scan) = (stored.height as usize, stored.width as usize);
        let (width, height) = if self.scan_along_x {
            (scans, per_scan)
        } else {
            (per_scan, scans)
        };
        let mut pixels = vec![[0.0f32; 4]; stored.pixels.len()];
        for s in 0..scans {
            let s_pos = if self.scan_reversed { scans - 1 - s } else { s };
            for i in 0..per_scan {
                let i_pos = if self.pixel_reversed {
                    per_scan - 1 - i
                } else {
                    i
                };
                let (col, row) = if self.scan_along_x {
                    (s_pos, i_pos)
                } else {
                    (i_pos, s_pos)
                };
                pixels[row * width + col] = stored.pixels[s * per_scan + i];
            }
        }
        Image {
            width: width as u32,
            height: height as u32,
            pixels,
        }
    }
}
