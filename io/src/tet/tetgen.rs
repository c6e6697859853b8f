//! TetGen's `.node` / `.ele` / `.face` files (TetGen manual, Sec. 5.2):
//! ASCII, `#` comments, 0- or 1-based numbering (the first node decides),
//! optional attributes and boundary markers.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use glam::DVec3;

use super::TetMesh;
use crate::error::{Error, ErrorKind, Result};
use crate::text::Cursor;

/// A TetGen mesh with what the files say beyond the tetrahedra.
#[derive(Debug, Clone, PartialEq)]
pub struct TetGenFiles {
    /// Nodes, tetrahedra and region attributes.
    pub mesh: TetMesh,
    /// The index of the first node as written (0 or 1).
    pub first_index: i64,
    /// The `.face` file's triangles (0-based), when the file exists. Kept
    /// for reference only: [`TetMesh::boundary`] derives the boundary from
    /// the tetrahedra.
    pub faces: Option<Vec<[u32; 3]>>,
}

/// The `.node`, `.ele` and `.face` paths beside `path` (either of the first
/// two may be given).
fn sibling(path: &Path, ext: &str) -> PathBuf {
    path.with_extension(ext)
}

fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| Error::io(path, e))
}

/// Reads `<name>.node` and `<name>.ele` given either path.
///
/// # Errors
/// [`Error`] with the file and line: a missing file, a malformed or
/// truncated record, a non-finite coordinate, a tetrahedron referencing a
/// missing node, numbering that is not consecutive, or a header count the
/// file cannot hold.
pub fn read(path: impl AsRef<Path>) -> Result<TetMesh> {
    let path = path.as_ref();
    let node = read_bytes(&sibling(path, "node"))?;
    let ele = read_bytes(&sibling(path, "ele"))?;
    from_bytes(&node, &ele, path)
}

/// Parses the contents of a `.node` and an `.ele` file, for data that is
/// not in files (archives, network, fuzzing). `path` names them in errors:
/// its `.node` and `.ele` siblings.
///
/// # Errors
/// As for [`read`].
pub fn from_bytes(node: &[u8], ele: &[u8], path: impl AsRef<Path>) -> Result<TetMesh> {
    let path = path.as_ref();
    parse_pair(node, ele, path).map(|(mesh, _)| mesh)
}

/// The mesh of a `.node` and an `.ele` file, and the first node index.
fn parse_pair(node: &[u8], ele: &[u8], path: &Path) -> Result<(TetMesh, i64)> {
    let (positions, first_index) = parse_nodes(node, &sibling(path, "node"))?;
    let (tets, attributes) =
        parse_elements(ele, &sibling(path, "ele"), first_index, positions.len())?;
    let mesh = TetMesh {
        positions,
        tets,
        regions: region_tags(&attributes),
        attributes,
        warnings: Vec::new(),
    };
    Ok((mesh, first_index))
}

/// Reads the mesh and, if it exists, the `.face` file beside it.
///
/// # Errors
/// As for [`read`], and for the `.face` file.
pub fn read_all(path: impl AsRef<Path>) -> Result<TetGenFiles> {
    let path = path.as_ref();
    let node = read_bytes(&sibling(path, "node"))?;
    let ele = read_bytes(&sibling(path, "ele"))?;
    let (mesh, first_index) = parse_pair(&node, &ele, path)?;
    let face_path = sibling(path, "face");
    let faces = match std::fs::read(&face_path) {
        Ok(data) => Some(parse_faces(
            &data,
            &face_path,
            first_index,
            mesh.positions.len(),
        )?),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
        Err(e) => return Err(Error::io(&face_path, e)),
    };
    Ok(TetGenFiles {
        mesh,
        first_index,
        faces,
    })
}

/// Reads the record index, which must continue the numbering.
fn record_index(c: &mut Cursor<'_>, expected: i64, what: &str) -> Result<()> {
    let (at, tok) = c.expect_token(what)?;
    match std::str::from_utf8(tok)
        .ok()
        .and_then(|s| s.parse::<i64>().ok())
    {
        Some(i) if i == expected => Ok(()),
        _ => Err(c.syntax(
            at,
            &format!("{what} {expected} (consecutive numbering)"),
            tok,
        )),
    }
}

/// A node reference converted to a 0-based index, checked against the
/// node count.
#[inline]
fn node_ref(
    c: &mut Cursor<'_>,
    first_index: i64,
    count: usize,
    element: &'static str,
    index: usize,
) -> Result<u32> {
    let at = {
        c.skip_space();
        c.offset()
    };
    let raw = c.i64("a node index")?;
    let zero_based = raw - first_index;
    if zero_based < 0 || zero_based as u64 >= count as u64 {
        return Err(c.error_at(
            at,
            ErrorKind::IndexOutOfRange {
                element,
                index,
                node: raw,
                count,
            },
        ));
    }
    Ok(zero_based as u32)
}

/// The smallest size of a record of `fields + extra` tokens (one byte and
/// one separator each), saturating: a header may declare absurd numbers
/// of attributes (found by fuzzing).
fn min_record_bytes(fields: u64, extra: u64) -> usize {
    usize::try_from(fields.saturating_add(extra).saturating_mul(2)).unwrap_or(usize::MAX)
}

/// Skips `n` tokens (attributes, markers, extra nodes).
fn skip_tokens(c: &mut Cursor<'_>, n: u64, what: &str) -> Result<()> {
    for _ in 0..n {
        c.expect_token(what)?;
    }
    Ok(())
}

/// Fails if anything but comments follows the last declared record.
fn expect_end(c: &mut Cursor<'_>, what: &str) -> Result<()> {
    if c.at_end() {
        return Ok(());
    }
    let (at, tok) = c.expect_token("the end of the file")?;
    Err(c.syntax(
        at,
        &format!("the end of the file after the last {what}"),
        tok,
    ))
}

/// Parses a `.node` file: positions and the first index (0 or 1).
pub(crate) fn parse_nodes(data: &[u8], path: &Path) -> Result<(Vec<DVec3>, i64)> {
    let mut c = Cursor::new(data, path, Some(b'#'));
    let declared = c.u64("the number of nodes")?;
    let (at, dim_tok) = c.expect_token("the dimension")?;
    if dim_tok != b"3" {
        return Err(c.syntax(at, "dimension 3", dim_tok));
    }
    let attributes = c.u64("the number of node attributes")?;
    let (at, marker_tok) = c.expect_token("the number of boundary markers")?;
    let markers = match marker_tok {
        b"0" => 0,
        b"1" => 1,
        _ => return Err(c.syntax(at, "0 or 1 boundary markers", marker_tok)),
    };
    if declared == 0 {
        return Err(c.error_at(
            at,
            ErrorKind::Unsupported(
                "a .node file with 0 points (the points are in a .poly file)".into(),
            ),
        ));
    }
    // Smallest record: "i x y z" plus attributes and markers, one byte and
    // one separator each.
    let count = c.check_count(
        "nodes",
        declared,
        min_record_bytes(4 + markers as u64, attributes),
    )?;
    let mut positions = Vec::with_capacity(count);
    let mut first_index = 0;
    for k in 0..count {
        if k == 0 {
            let (at, tok) = c.expect_token("the first node's index")?;
            first_index = match tok {
                b"0" => 0,
                b"1" => 1,
                _ => return Err(c.syntax(at, "first node index 0 or 1", tok)),
            };
        } else {
            record_index(&mut c, first_index + k as i64, "node")?;
        }
        let p = c.point(k)?;
        positions.push(p);
        skip_tokens(
            &mut c,
            attributes + markers as u64,
            "a node attribute or marker",
        )?;
    }
    expect_end(&mut c, "node")?;
    Ok((positions, first_index))
}

/// The region tags of [`TetMesh::regions`]: the first attribute column
/// when every value of it is an integer in `i32`'s range, else none.
fn region_tags(attributes: &[Vec<f64>]) -> Vec<i32> {
    let Some(first) = attributes.first() else {
        return Vec::new();
    };
    let range = f64::from(i32::MIN)..=f64::from(i32::MAX);
    if first.iter().all(|v| v.fract() == 0.0 && range.contains(v)) {
        first.iter().map(|&v| v as i32).collect()
    } else {
        Vec::new()
    }
}

/// How many attribute columns are kept in memory; more are read and
/// skipped (their values still have to parse). A budget, since the header
/// sets the allocation.
const MAX_ATTRIBUTES: u64 = 64;

/// Per-tetrahedron attributes, one column per attribute.
type Columns = Vec<Vec<f64>>;

/// Parses a `.ele` file: tetrahedra (0-based) and their attributes, one
/// column per attribute.
pub(crate) fn parse_elements(
    data: &[u8],
    path: &Path,
    first_index: i64,
    node_count: usize,
) -> Result<(Vec<[u32; 4]>, Columns)> {
    let mut c = Cursor::new(data, path, Some(b'#'));
    let declared = c.u64("the number of tetrahedra")?;
    let (at, per_tok) = c.expect_token("the number of nodes per tetrahedron")?;
    let per_tet = match per_tok {
        b"4" => 4,
        b"10" => 10,
        _ => return Err(c.syntax(at, "4 or 10 nodes per tetrahedron", per_tok)),
    };
    let attributes = c.u64("the number of tetrahedron attributes")?;
    let count = c.check_count(
        "tetrahedra",
        declared,
        min_record_bytes(1 + per_tet, attributes),
    )?;
    if attributes > MAX_ATTRIBUTES {
        return Err(c.error_at(
            0,
            ErrorKind::LimitExceeded(format!(
                "{attributes} attributes per tetrahedron (at most {MAX_ATTRIBUTES} are read)"
            )),
        ));
    }
    let mut tets = Vec::with_capacity(count);
    let mut columns: Vec<Vec<f64>> = (0..attributes).map(|_| Vec::with_capacity(count)).collect();
    for k in 0..count {
        record_index(&mut c, first_index + k as i64, "tetrahedron")?;
        let mut tet = [0u32; 4];
        for slot in &mut tet {
            *slot = node_ref(&mut c, first_index, node_count, "tetrahedron", k)?;
        }
        // Quadratic tetrahedra: the six edge nodes follow the corners.
        skip_tokens(&mut c, per_tet - 4, "an edge node")?;
        tets.push(tet);
        for column in &mut columns {
            let at = {
                c.skip_space();
                c.offset()
            };
            let value = c.f64("a tetrahedron attribute")?;
            if !value.is_finite() {
                return Err(c.syntax(
                    at,
                    "a finite tetrahedron attribute",
                    value.to_string().as_bytes(),
                ));
            }
            column.push(value);
        }
    }
    expect_end(&mut c, "tetrahedron")?;
    Ok((tets, columns))
}

/// Parses a `.face` file: triangles (0-based).
pub(crate) fn parse_faces(
    data: &[u8],
    path: &Path,
    first_index: i64,
    node_count: usize,
) -> Result<Vec<[u32; 3]>> {
    let mut c = Cursor::new(data, path, Some(b'#'));
    let declared = c.u64("the number of faces")?;
    let (at, marker_tok) = c.expect_token("the boundary marker flag")?;
    let markers = match marker_tok {
        b"0" => 0,
        b"1" => 1,
        _ => return Err(c.syntax(at, "a boundary marker flag of 0 or 1", marker_tok)),
    };
    let count = c.check_count("faces", declared, 2 * (4 + markers as usize))?;
    let mut faces = Vec::with_capacity(count);
    for k in 0..count {
        record_index(&mut c, first_index + k as i64, "face")?;
        let mut face = [0u32; 3];
        for slot in &mut face {
            *slot = node_ref(&mut c, first_index, node_count, "face", k)?;
        }
        faces.push(face);
        skip_tokens(&mut c, markers, "a boundary marker")?;
    }
    expect_end(&mut c, "face")?;
    Ok(faces)
}

/// Writes `<name>.node` and `<name>.ele` (1-based, TetGen's default). The
/// `.ele` attributes are [`TetMesh::attributes`] when there are any
/// (then [`TetMesh::regions`], if given, must equal the first column), else
/// one region attribute per tetrahedron when the mesh has regions.
/// Coordinates are written in Rust's shortest round-trip form, so reading
/// them back gives the same bits.
///
/// # Errors
/// [`Error`] for a tetrahedron referencing a missing node, or an I/O error.
pub fn write(path: impl AsRef<Path>, mesh: &TetMesh) -> Result<()> {
    let path = path.as_ref();
    let node_path = sibling(path, "node");
    let ele_path = sibling(path, "ele");
    mesh.check_indices(&ele_path)?;
    if !mesh.regions.is_empty() && mesh.regions.len() != mesh.tets.len() {
        return Err(Error::new(
            &ele_path,
            ErrorKind::InvalidInput(format!(
                "{} region tags for {} tetrahedra",
                mesh.regions.len(),
                mesh.tets.len()
            )),
        ));
    }
    let columns: Vec<Vec<f64>> = if mesh.attributes.is_empty() {
        (!mesh.regions.is_empty())
            .then(|| mesh.regions.iter().map(|&r| f64::from(r)).collect())
            .into_iter()
            .collect()
    } else {
        if let Some(k) = mesh
            .attributes
            .iter()
            .position(|c| c.len() != mesh.tets.len())
        {
            return Err(Error::new(
                &ele_path,
                ErrorKind::InvalidInput(format!(
                    "attribute {k} has {} values for {} tetrahedra",
                    mesh.attributes[k].len(),
                    mesh.tets.len()
                )),
            ));
        }
        let first = &mesh.attributes[0];
        if !mesh.regions.is_empty()
            && mesh
                .regions
                .iter()
                .zip(first)
                .any(|(&r, &a)| f64::from(r) != a)
        {
            return Err(Error::new(
                &ele_path,
                ErrorKind::InvalidInput(
                    "the region tags differ from the first attribute column, and the .ele file \
                     holds only one of them"
                        .into(),
                ),
            ));
        }
        mesh.attributes.clone()
    };
    let mut text = String::with_capacity(mesh.positions.len() * 64);
    text.push_str("# written by trilux-io; 1-based\n");
    let _ = writeln!(text, "{} 3 0 0", mesh.positions.len());
    for (i, p) in mesh.positions.iter().enumerate() {
        let _ = writeln!(text, "{} {} {} {}", i + 1, p.x, p.y, p.z);
    }
    write_text(&node_path, &text)?;

    text.clear();
    let attributes = columns.len();
    text.push_str("# written by trilux-io; 1-based\n");
    let _ = writeln!(text, "{} 4 {attributes}", mesh.tets.len());
    for (i, t) in mesh.tets.iter().enumerate() {
        let _ = write!(
            text,
            "{} {} {} {} {}",
            i + 1,
            t[0] + 1,
            t[1] + 1,
            t[2] + 1,
            t[3] + 1
        );
        for column in &columns {
            let _ = write!(text, " {}", column[i]);
        }
        text.push('\n');
    }
    write_text(&ele_path, &text)
}

fn write_text(path: &Path, text: &str) -> Result<()> {
    let mut file = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
    file.write_all(text.as_bytes())
        .and_then(|()| file.flush())
        .map_err(|e| Error::io(path, e))
}
