//! The `.meshcolors` file: binary, versioned, little-endian.
//!
//! ```text
//! offset  size             field
//! 0       8                magic  b"MESHCOLR"
//! 8       4                version (2; 1 is read too)
//! 12      4                channels (1..=64)
//! 16      4                vertex count V
//! 20      4                face count F
//! 24      4                flags: bit 0 = MIP data present; others 0
//! 28      8                topology hash of the mesh (version 2 only; see
//!                          Fingerprint)
//! 36      12·F             faces: three u32 vertex indices each (28 in v1)
//! …       F                face levels n (R = 2^n), one byte each
//! …       4·S·channels     samples (f32), S from the layout of MeshColors
//! …       4·M              optional MIP data (f32), M from the layout of MipMap
//! ```
//!
//! The reader checks every count against the bytes left before allocating,
//! rebuilds the topology (so a face naming a missing vertex or a
//! non-manifold edge is an error with its byte offset), checks the stored
//! topology hash against the faces, and requires the file to end exactly
//! after the data. Values are stored bit for bit.
//!
//! The counts and the hash are the [`Fingerprint`] of the mesh the colours
//! belong to: [`load_for`] (and [`read_for`], [`from_bytes_for`]) refuse a
//! file made for another mesh, which would otherwise colour the wrong
//! faces without a word.

use std::io::{Read, Write};
use std::path::Path;

use crate::mip::MipMap;
use crate::structure::{MeshColors, layout_sample_count};
use crate::topology::{Fingerprint, Topology};
use crate::{Error, MAX_CHANNELS, MAX_LEVEL};

/// The first eight bytes of every `.meshcolors` file.
pub const MAGIC: [u8; 8] = *b"MESHCOLR";
/// The format version this crate writes (it reads 1 and 2).
pub const VERSION: u32 = 2;
/// Header bytes of version 1 and of version 2 (which adds the hash).
const HEADER_V1: usize = 28;
const HEADER_V2: usize = 36;
const FLAG_MIP: u32 = 1;

/// Encodes mesh colours, with their MIP pyramid if given (it must have been
/// built from `colors`, or an error names the mismatch).
///
/// # Errors
/// [`Error::ChannelMismatch`] if `mip` does not belong to `colors`.
pub fn to_bytes(colors: &MeshColors, mip: Option<&MipMap>) -> Result<Vec<u8>, Error> {
    if let Some(m) = mip
        && (m.colors.topology != colors.topology || m.colors.face_level != colors.face_level)
    {
        return Err(Error::ChannelMismatch {
            what: "MIP pyramid built from other mesh colours",
            expected: colors.samples.len(),
            got: m.colors.samples.len(),
        });
    }
    let t = &colors.topology;
    let mut out = Vec::with_capacity(
        HEADER_V2
            + 13 * t.faces.len()
            + 4 * colors.samples.len()
            + mip.map_or(0, |m| 4 * m.data.len()),
    );
    out.extend_from_slice(&MAGIC);
    for x in [
        VERSION,
        colors.channels as u32,
        t.vertex_count as u32,
        t.faces.len() as u32,
        if mip.is_some() { FLAG_MIP } else { 0 },
    ] {
        out.extend_from_slice(&x.to_le_bytes());
    }
    out.extend_from_slice(&t.fingerprint().topology_hash.to_le_bytes());
    for f in &t.faces {
        for v in f {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out.extend_from_slice(&colors.face_level);
    for x in &colors.samples {
        out.extend_from_slice(&x.to_le_bytes());
    }
    if let Some(m) = mip {
        for x in &m.data {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    Ok(out)
}

/// `e` as [`Error::Io`], naming `path` when there is one.
fn io_error(path: Option<&Path>, e: std::io::Error) -> Error {
    Error::Io {
        path: path.map(Path::to_path_buf),
        source: crate::IoError(std::sync::Arc::new(e)),
    }
}

/// Writes mesh colours (and optionally their MIP pyramid) to a stream.
///
/// # Errors
/// [`Error::Io`], or as for [`to_bytes`].
pub fn write(mut to: impl Write, colors: &MeshColors, mip: Option<&MipMap>) -> Result<(), Error> {
    to.write_all(&to_bytes(colors, mip)?)
        .map_err(|e| io_error(None, e))
}

/// Saves to a `.meshcolors` file.
///
/// # Errors
/// [`Error::Io`] with `path` set, or as for [`to_bytes`].
pub fn save(
    path: impl AsRef<Path>,
    colors: &MeshColors,
    mip: Option<&MipMap>,
) -> Result<(), Error> {
    let path = path.as_ref();
    std::fs::write(path, to_bytes(colors, mip)?).map_err(|e| io_error(Some(path), e))
}

/// Reads a `.meshcolors` stream (see [`from_bytes`]).
///
/// # Errors
/// [`Error::Io`], or as for [`from_bytes`].
pub fn read(mut from: impl Read) -> Result<(MeshColors, Option<MipMap>), Error> {
    let mut bytes = Vec::new();
    from.read_to_end(&mut bytes)
        .map_err(|e| io_error(None, e))?;
    from_bytes(&bytes)
}

/// Loads a `.meshcolors` file.
///
/// # Errors
/// [`Error::Io`] or [`Error::File`] with `path` set, else as for
/// [`from_bytes`].
pub fn load(path: impl AsRef<Path>) -> Result<(MeshColors, Option<MipMap>), Error> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| io_error(Some(path), e))?;
    from_bytes(&bytes).map_err(|e| with_path(e, path))
}

/// Loads a `.meshcolors` file made for the mesh of fingerprint `mesh`
/// (`Fingerprint::of(vertex_count, &faces)` of the welded mesh you draw).
///
/// # Errors
/// [`Error::WrongMesh`] when the file belongs to another mesh, and the
/// errors of [`load`].
pub fn load_for(
    path: impl AsRef<Path>,
    mesh: &Fingerprint,
) -> Result<(MeshColors, Option<MipMap>), Error> {
    let loaded = load(path)?;
    check_mesh(loaded, mesh)
}

/// Reads a `.meshcolors` stream made for the mesh of fingerprint `mesh`.
///
/// # Errors
/// [`Error::WrongMesh`], and the errors of [`read`].
pub fn read_for(
    from: impl Read,
    mesh: &Fingerprint,
) -> Result<(MeshColors, Option<MipMap>), Error> {
    check_mesh(read(from)?, mesh)
}

/// Decodes a `.meshcolors` file made for the mesh of fingerprint `mesh`.
///
/// # Errors
/// [`Error::WrongMesh`], and the errors of [`from_bytes`].
pub fn from_bytes_for(
    bytes: &[u8],
    mesh: &Fingerprint,
) -> Result<(MeshColors, Option<MipMap>), Error> {
    check_mesh(from_bytes(bytes)?, mesh)
}

fn check_mesh(
    loaded: (MeshColors, Option<MipMap>),
    mesh: &Fingerprint,
) -> Result<(MeshColors, Option<MipMap>), Error> {
    let stored = loaded.0.topology.fingerprint();
    if stored == *mesh {
        Ok(loaded)
    } else {
        Err(Error::WrongMesh {
            stored,
            expected: *mesh,
        })
    }
}

/// A file error with the file it was found in.
fn with_path(e: Error, path: &Path) -> Error {
    match e {
        Error::File { offset, reason, .. } => Error::File {
            path: Some(path.to_path_buf()),
            offset,
            reason,
        },
        other => other,
    }
}

fn bad(offset: usize, reason: impl Into<String>) -> Error {
    Error::File {
        path: None,
        offset: offset as u64,
        reason: reason.into(),
    }
}

fn u32_at(bytes: &[u8], at: usize) -> Result<u32, Error> {
    bytes
        .get(at..at + 4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .ok_or_else(|| bad(at, "truncated: the file ends inside the header"))
}

fn floats(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// Decodes a `.meshcolors` file: the mesh colours and, when stored, their
/// MIP pyramid.
///
/// # Errors
/// [`Error::File`] with the byte offset: wrong magic, unknown version or
/// flags, zero or too many channels, a truncated file, a face naming a
/// missing or repeated vertex, a non-manifold edge, a level above
/// [`MAX_LEVEL`], or bytes after the data.
pub fn from_bytes(bytes: &[u8]) -> Result<(MeshColors, Option<MipMap>), Error> {
    if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
        return Err(bad(0, "not a .meshcolors file (wrong magic number)"));
    }
    let version = u32_at(bytes, 8)?;
    let header = match version {
        1 => HEADER_V1,
        2 => HEADER_V2,
        _ => {
            return Err(bad(
                8,
                format!("version {version} is not supported (this reader knows 1 and 2)"),
            ));
        }
    };
    let channels = u32_at(bytes, 12)? as usize;
    if channels == 0 || channels > MAX_CHANNELS {
        return Err(bad(
            12,
            format!("{channels} channels (1..={MAX_CHANNELS} supported)"),
        ));
    }
    let vertex_count = u32_at(bytes, 16)? as usize;
    let face_count = u32_at(bytes, 20)? as usize;
    let flags = u32_at(bytes, 24)?;
    if flags & !FLAG_MIP != 0 {
        return Err(bad(24, format!("unknown flags {flags:#x}")));
    }
    let stored_hash = if version >= 2 {
        let lo = u64::from(u32_at(bytes, 28)?);
        let hi = u64::from(u32_at(bytes, 32)?);
        Some(lo | hi << 32)
    } else {
        None
    };
    let left = bytes.len().saturating_sub(header) as u64;
    // Every vertex has a sample and every face 13 bytes: refuse counts the
    // file cannot hold before allocating anything sized by them.
    let least = 13 * face_count as u64 + 4 * (vertex_count as u64) * channels as u64;
    if least > left {
        return Err(bad(
            bytes.len(),
            format!(
                "truncated: {vertex_count} vertices and {face_count} faces need at least {least} bytes after the header, {left} present"
            ),
        ));
    }
    let mut faces = Vec::with_capacity(face_count);
    for f in 0..face_count {
        let at = header + 12 * f;
        faces.push([
            u32_at(bytes, at)?,
            u32_at(bytes, at + 4)?,
            u32_at(bytes, at + 8)?,
        ]);
    }
    let levels_at = header + 12 * face_count;
    let levels = bytes[levels_at..levels_at + face_count].to_vec();
    if let Some(f) = levels.iter().position(|&n| n > MAX_LEVEL) {
        return Err(bad(
            levels_at + f,
            format!("face {f} has level {} (at most {MAX_LEVEL})", levels[f]),
        ));
    }
    let topology = Topology::new(vertex_count, &faces).map_err(|e| {
        let face = match &e {
            Error::MissingVertex { face, .. } | Error::DegenerateFace { face, .. } => *face,
            Error::NonManifoldEdge { faces, .. } => faces[2],
            _ => 0,
        };
        bad(header + 12 * face, e.to_string())
    })?;
    if let Some(hash) = stored_hash {
        let computed = topology.fingerprint().topology_hash;
        if hash != computed {
            return Err(bad(
                28,
                format!(
                    "the stored topology hash {hash:016x} does not match the faces ({computed:016x}): the file is damaged"
                ),
            ));
        }
    }
    // The sample count from the layout, checked before allocating it.
    let count = layout_sample_count(&topology, &levels);
    let samples_at = levels_at + face_count;
    let sample_bytes = 4 * count * channels as u64;
    if sample_bytes > (bytes.len() - samples_at) as u64 {
        return Err(bad(
            bytes.len(),
            format!(
                "truncated: {count} samples of {channels} channels need {sample_bytes} bytes, {} present",
                bytes.len() - samples_at
            ),
        ));
    }
    let colors = MeshColors::with_levels(topology, levels, channels)
        .map_err(|e| bad(levels_at, e.to_string()))?;
    let mip_bytes = if flags & FLAG_MIP != 0 {
        4 * MipMap::len_for(&colors)
    } else {
        0
    };
    let have = (bytes.len() - samples_at) as u64;
    if have < sample_bytes + mip_bytes {
        return Err(bad(
            bytes.len(),
            format!(
                "truncated: the samples{} need {} bytes, {have} present",
                if mip_bytes > 0 { " and MIP data" } else { "" },
                sample_bytes + mip_bytes
            ),
        ));
    }
    if have > sample_bytes + mip_bytes {
        return Err(bad(
            samples_at + (sample_bytes + mip_bytes) as usize,
            format!(
                "{} bytes after the end of the data",
                have - sample_bytes - mip_bytes
            ),
        ));
    }
    let mut colors = colors;
    let mip_at = samples_at + sample_bytes as usize;
    colors.samples = floats(&bytes[samples_at..mip_at]);
    let mip = if mip_bytes > 0 {
        let mut m = MipMap::zeroed(colors.clone());
        m.set_data(floats(&bytes[mip_at..]))?;
        Some(m)
    } else {
        None
    };
    Ok((colors, mip))
}
