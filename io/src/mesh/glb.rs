//! The binary glTF container (glTF 2.0 Sec. 4.4, "GLB File Format
//! Specification"), checked before the `gltf` crate splits it.
//!
//! Layout, all integers little-endian `u32`: a 12-byte header (magic
//! `glTF`, version 2, total length including the header), then chunks of
//! an 8-byte header (data length, type) and their data; the first chunk is
//! `JSON`, an optional second one `BIN\0`.
//!
//! Why here: the crate subtracts 12 from the declared total length before
//! comparing it with the data (its `binary.rs`), which overflows on a
//! length below 12 (found by fuzzing: a 19-byte file panics with overflow
//! checks on, and wraps to a huge length without them). Every field the
//! crate does arithmetic with is checked here first, and the error names
//! the field and its byte offset.

use std::path::Path;

use crate::error::{Error, ErrorKind, Location, Result};

/// The header's size: magic, version, total length.
const HEADER_BYTES: usize = 12;
/// A chunk header's size: data length, type.
const CHUNK_HEADER_BYTES: usize = 8;

/// Whether `bytes` is meant as GLB: the test the `gltf` crate applies.
pub(crate) fn is_glb(bytes: &[u8]) -> bool {
    bytes.starts_with(b"glTF")
}

/// Checks the GLB header and chunk headers of `bytes` (which start with
/// the magic `glTF`): version 2, a total length of at least the header and
/// at most the data, a first chunk of type `JSON` and every chunk's data
/// inside the data.
///
/// # Errors
/// [`ErrorKind::Truncated`] when the data ends inside a header or a chunk,
/// [`ErrorKind::Syntax`] for a wrong magic, total length or chunk type,
/// [`ErrorKind::Unsupported`] for a version other than 2; each at the
/// byte offset of the field, in `path`.
pub(crate) fn check(bytes: &[u8], path: &Path) -> Result<()> {
    let at = |offset: usize, kind: ErrorKind| Error {
        path: path.to_path_buf(),
        location: Some(Location::Byte(offset)),
        kind,
    };
    let header = bytes.get(..HEADER_BYTES).ok_or_else(|| {
        at(
            bytes.len(),
            ErrorKind::Truncated(format!(
                "a {HEADER_BYTES}-byte GLB header (magic, version, length), {} bytes present",
                bytes.len()
            )),
        )
    })?;
    if &header[..4] != b"glTF" {
        return Err(at(
            0,
            ErrorKind::Syntax {
                expected: "the GLB magic \"glTF\"".into(),
                found: String::from_utf8_lossy(&header[..4]).into_owned(),
            },
        ));
    }
    let version = le_u32(header, 4);
    if version != 2 {
        return Err(at(
            4,
            ErrorKind::Unsupported(format!("GLB version {version} (only version 2 exists)")),
        ));
    }
    let length = le_u32(header, 8) as usize;
    if length < HEADER_BYTES || length > bytes.len() {
        return Err(at(
            8,
            ErrorKind::Syntax {
                expected: format!(
                    "a GLB total length between {HEADER_BYTES} (the header) and {} (the file)",
                    bytes.len()
                ),
                found: length.to_string(),
            },
        ));
    }
    let mut offset = HEADER_BYTES;
    let mut chunk = 0usize;
    while offset < bytes.len() && chunk < 2 {
        let head = bytes
            .get(offset..offset + CHUNK_HEADER_BYTES)
            .ok_or_else(|| {
                at(
                    offset,
                    ErrorKind::Truncated(format!(
                        "the {CHUNK_HEADER_BYTES}-byte header of GLB chunk {chunk}, {} bytes present",
                        bytes.len() - offset
                    )),
                )
            })?;
        let data_length = le_u32(head, 0) as usize;
        let kind = &head[4..];
        let wanted: &[u8] = if chunk == 0 { b"JSON" } else { b"BIN\0" };
        if kind != wanted {
            return Err(at(
                offset + 4,
                ErrorKind::Syntax {
                    expected: format!(
                        "GLB chunk {chunk} of type {:?}",
                        String::from_utf8_lossy(wanted)
                    ),
                    found: String::from_utf8_lossy(kind).into_owned(),
                },
            ));
        }
        let data_start = offset + CHUNK_HEADER_BYTES;
        let left = bytes.len() - data_start;
        if data_length > left {
            return Err(at(
                offset,
                ErrorKind::Truncated(format!(
                    "GLB chunk {chunk} ({}) of {data_length} bytes, {left} present",
                    String::from_utf8_lossy(wanted).trim_end_matches('\0')
                )),
            ));
        }
        offset = data_start + data_length;
        chunk += 1;
    }
    if chunk == 0 {
        return Err(at(
            offset,
            ErrorKind::Truncated("GLB chunk 0 (JSON) after the header".into()),
        ));
    }
    Ok(())
}

/// The little-endian `u32` at `offset` of `bytes` (the caller checked
/// the length).
fn le_u32(bytes: &[u8], offset: usize) -> u32 {
    let mut word = [0; 4];
    word.copy_from_slice(&bytes[offset..offset + 4]);
    u32::from_le_bytes(word)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A GLB of `json` and, when given, a `BIN` chunk, with its real
    /// total length.
    fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend([0; 4]);
        out.extend((json.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(json);
        if let Some(bin) = bin {
            out.extend((bin.len() as u32).to_le_bytes());
            out.extend(b"BIN\0");
            out.extend(bin);
        }
        let total = out.len() as u32;
        out[8..12].copy_from_slice(&total.to_le_bytes());
        out
    }

    fn message(bytes: &[u8]) -> String {
        check(bytes, Path::new("a.glb")).unwrap_err().to_string()
    }

    #[test]
    fn well_formed_containers_pass() {
        check(&glb(b"{}  ", None), Path::new("a.glb")).unwrap();
        check(&glb(b"{}  ", Some(&[1, 2, 3, 4])), Path::new("a.glb")).unwrap();
        check(&glb(b"", Some(&[])), Path::new("a.glb")).unwrap();
    }

    #[test]
    fn the_fuzzers_19_bytes_are_refused_by_the_length_field() {
        // A total length of 1: the gltf crate computes `1 - 12`.
        let bytes = b"glTFdxte\x01\x00\x00\x00nsUsem ";
        let version = message(bytes);
        assert!(version.contains("a.glb: byte 4:"), "{version}");
        assert!(version.contains("GLB version 1702131812"), "{version}");
        let mut fixed = bytes.to_vec();
        fixed[4..8].copy_from_slice(&2u32.to_le_bytes());
        let length = message(&fixed);
        assert!(length.contains("a.glb: byte 8:"), "{length}");
        assert!(length.contains("GLB total length between 12"), "{length}");
        assert!(length.contains("found \"1\""), "{length}");
    }

    #[test]
    fn each_field_is_named_where_it_is_wrong() {
        let good = glb(b"{}  ", Some(&[0; 8]));
        assert!(message(&good[..7]).contains("byte 7: the file ends early"));
        let mut long = good.clone();
        long[8..12].copy_from_slice(&(good.len() as u32 + 1).to_le_bytes());
        assert!(message(&long).contains("byte 8:"));
        let mut json_type = good.clone();
        json_type[16..20].copy_from_slice(b"BIN\0");
        let m = message(&json_type);
        assert!(
            m.contains("byte 16:") && m.contains("chunk 0 of type \"JSON\""),
            "{m}"
        );
        let mut json_length = good.clone();
        json_length[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        let m = message(&json_length);
        assert!(
            m.contains("byte 12:") && m.contains("chunk 0 (JSON) of 4294967295 bytes"),
            "{m}"
        );
        let mut bin_length = good.clone();
        bin_length[24..28].copy_from_slice(&9u32.to_le_bytes());
        let m = message(&bin_length);
        assert!(
            m.contains("byte 24:") && m.contains("chunk 1 (BIN) of 9 bytes, 8 present"),
            "{m}"
        );
        let m = message(&good[..good.len() - 10]);
        assert!(m.contains("byte 8:"), "{m}");
        let mut lone = glb(b"", None)[..12].to_vec();
        lone[8..12].copy_from_slice(&12u32.to_le_bytes());
        let m = message(&lone);
        assert!(
            m.contains("byte 12:") && m.contains("chunk 0 (JSON)"),
            "{m}"
        );
    }

    #[test]
    fn no_prefix_of_a_container_panics() {
        let good = glb(b"{\"asset\":{}}", Some(&[7; 12]));
        for end in 0..=good.len() {
            let mut bytes = good[..end].to_vec();
            if end >= 12 {
                bytes[8..12].copy_from_slice(&(end as u32).to_le_bytes());
            }
            let result = check(&bytes, Path::new("a.glb"));
            // Whole chunks only: the JSON chunk alone ends at 32.
            assert_eq!(result.is_ok(), end == 32 || end == good.len(), "{end}");
        }
    }
}
