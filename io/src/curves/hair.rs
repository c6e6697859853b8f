//! Cem Yuksel's HAIR file (`.hair`, cyHairFile; the format of his hair
//! models, read by research renderers): a 128-byte little-endian header
//! — the signature `HAIR`, the hair and point counts, a bit field of the
//! arrays present (1 segments, 2 points, 4 thickness, 8 transparency,
//! 16 colour), the default segments, thickness, transparency and colour,
//! and an 88-byte information string — then the arrays in that order:
//! `u16` segments per hair (points = segments + 1), `f32` xyz points,
//! `f32` thickness, transparency and rgb colour per point.
//!
//! trilux writes points, segments (only when the curves differ in length)
//! and thickness (from [`Curves::widths`], when present); it reads every
//! array, keeping points, segments and thickness. Coordinates are written
//! as they are (no axis swap). Root data (faces, UVs) has no place in the
//! format and is not written.

use std::path::Path;

use glam::Vec3;

use super::Curves;
use crate::error::{Error, ErrorKind, Location, Result};

const SIGNATURE: &[u8; 4] = b"HAIR";
const HEADER: usize = 128;
const SEGMENTS_BIT: u32 = 1;
const POINTS_BIT: u32 = 2;
const THICKNESS_BIT: u32 = 4;
const TRANSPARENCY_BIT: u32 = 8;
const COLORS_BIT: u32 = 16;
const INFO: &str = "written by trilux-io";

/// The most segments the format's `u16` holds per hair.
pub const MAX_SEGMENTS: u32 = u16::MAX as u32;

/// Writes `curves` as a `.hair` file.
///
/// # Errors
/// As [`Curves::check`]; a curve of more than [`MAX_SEGMENTS`] segments,
/// more than 2^32 − 1 curves or points; an I/O error.
pub fn write(path: impl AsRef<Path>, curves: &Curves) -> Result<()> {
    let path = path.as_ref();
    let bytes = to_bytes(path, curves)?;
    std::fs::write(path, bytes).map_err(|e| Error::io(path, e))
}

/// The `.hair` file as bytes; `path` names it in errors.
///
/// # Errors
/// As [`write()`], without the I/O.
pub fn to_bytes(path: &Path, curves: &Curves) -> Result<Vec<u8>> {
    curves.check(path)?;
    let invalid = |what: String| Error::new(path, ErrorKind::InvalidInput(what));
    if let Some(c) = curves.counts.iter().position(|&c| c - 1 > MAX_SEGMENTS) {
        return Err(invalid(format!(
            "curve {c} has {} segments; a .hair file holds at most {MAX_SEGMENTS} per hair",
            curves.counts[c] - 1
        )));
    }
    let count = |n: usize, what: &str| {
        u32::try_from(n)
            .map_err(|_| invalid(format!("{n} {what}: a .hair file holds at most 2^32 - 1")))
    };
    let hairs = count(curves.counts.len(), "curves")?;
    let points = count(curves.points.len(), "points")?;
    let uniform = curves
        .counts
        .first()
        .filter(|&&c| curves.counts.iter().all(|&d| d == c));
    let mut arrays = POINTS_BIT;
    if uniform.is_none() && !curves.counts.is_empty() {
        arrays |= SEGMENTS_BIT;
    }
    if curves.widths.is_some() {
        arrays |= THICKNESS_BIT;
    }
    let mut out = Vec::with_capacity(HEADER + curves.points.len() * 16 + curves.counts.len() * 2);
    out.extend_from_slice(SIGNATURE);
    for v in [hairs, points, arrays, uniform.map_or(0, |c| c - 1)] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    // Default thickness, transparency and colour (used for absent arrays).
    for v in [1.0f32, 0.0, 1.0, 1.0, 1.0] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let mut info = [0u8; 88];
    info[..INFO.len()].copy_from_slice(INFO.as_bytes());
    out.extend_from_slice(&info);
    debug_assert_eq!(out.len(), HEADER);
    if arrays & SEGMENTS_BIT != 0 {
        for &c in &curves.counts {
            out.extend_from_slice(&((c - 1) as u16).to_le_bytes());
        }
    }
    for p in &curves.points {
        for v in p.to_array() {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    if let Some(widths) = &curves.widths {
        for w in widths {
            out.extend_from_slice(&w.to_le_bytes());
        }
    }
    Ok(out)
}

/// Reads a `.hair` file: points, counts (from the segments array or the
/// default), and widths from the thickness array (absent when the file
/// has none). Transparency and colour arrays are read past.
///
/// # Errors
/// A missing signature, a file shorter than its header declares (refused
/// before allocating), a hair of 0 segments or segments that do not sum
/// to the points, a non-finite point; each names the file and the byte.
pub fn read(path: impl AsRef<Path>) -> Result<Curves> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    from_bytes(&bytes, path)
}

/// Reads a `.hair` file from its bytes; `path` names it in errors.
///
/// # Errors
/// As [`read`], without the I/O.
pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Curves> {
    let at = |byte: usize, kind: ErrorKind| Error {
        path: path.to_path_buf(),
        location: Some(Location::Byte(byte)),
        kind,
    };
    if bytes.len() < HEADER {
        return Err(at(
            bytes.len(),
            ErrorKind::Truncated(format!("a {HEADER}-byte HAIR header")),
        ));
    }
    if &bytes[..4] != SIGNATURE {
        return Err(at(
            0,
            ErrorKind::Syntax {
                expected: "the signature HAIR".into(),
                found: String::from_utf8_lossy(&bytes[..4]).into_owned(),
            },
        ));
    }
    let word = |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    let (hairs, points, arrays, default_segments) = (word(4), word(8), word(12), word(16));
    let (hairs, n) = (hairs as usize, points as usize);
    let per_point = |bit: u32, size: usize| if arrays & bit != 0 { size * n } else { 0 };
    let segment_bytes = if arrays & SEGMENTS_BIT != 0 {
        2 * hairs
    } else {
        0
    };
    let need = segment_bytes as u64
        + [
            (POINTS_BIT, 12),
            (THICKNESS_BIT, 4),
            (TRANSPARENCY_BIT, 4),
            (COLORS_BIT, 12),
        ]
        .into_iter()
        .map(|(bit, size)| per_point(bit, size) as u64)
        .sum::<u64>();
    let left = bytes.len() - HEADER;
    if need > left as u64 {
        return Err(at(
            HEADER,
            ErrorKind::CountTooLarge {
                what: "bytes of arrays",
                declared: need,
                bytes_left: left,
                fit: left as u64,
            },
        ));
    }
    let mut offset = HEADER;
    let counts: Vec<u32> = if arrays & SEGMENTS_BIT != 0 {
        let s = (0..hairs)
            .map(|h| {
                u32::from(u16::from_le_bytes([
                    bytes[offset + 2 * h],
                    bytes[offset + 2 * h + 1],
                ])) + 1
            })
            .collect();
        offset += segment_bytes;
        s
    } else {
        vec![default_segments.saturating_add(1); hairs]
    };
    if let Some(h) = counts.iter().position(|&c| c < 2) {
        let byte = if arrays & SEGMENTS_BIT != 0 {
            HEADER + 2 * h
        } else {
            16
        };
        return Err(at(
            byte,
            ErrorKind::Syntax {
                expected: "at least 1 segment per hair".into(),
                found: format!("hair {h} with 0 segments"),
            },
        ));
    }
    let total: u64 = counts.iter().map(|&c| u64::from(c)).sum();
    if total != n as u64 {
        return Err(at(
            8,
            ErrorKind::Syntax {
                expected: format!("{total} points (the hairs' segments + 1, summed)"),
                found: format!("{n} points"),
            },
        ));
    }
    if arrays & POINTS_BIT == 0 {
        return Err(at(
            12,
            ErrorKind::Syntax {
                expected: "a points array (bit 2 of the array flags)".into(),
                found: format!("flags {arrays:#x}"),
            },
        ));
    }
    let float = |i: usize| f32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    let mut positions = Vec::with_capacity(n);
    for i in 0..n {
        let b = offset + 12 * i;
        let p = Vec3::new(float(b), float(b + 4), float(b + 8));
        if !p.is_finite() {
            return Err(at(
                b,
                ErrorKind::NonFinite {
                    index: i,
                    value: f64::from(
                        [p.x, p.y, p.z]
                            .into_iter()
                            .find(|v| !v.is_finite())
                            .unwrap_or(f32::NAN),
                    ),
                },
            ));
        }
        positions.push(p);
    }
    offset += 12 * n;
    let widths =
        (arrays & THICKNESS_BIT != 0).then(|| (0..n).map(|i| float(offset + 4 * i)).collect());
    Ok(Curves {
        points: positions,
        counts,
        widths,
        ..Curves::default()
    })
}
