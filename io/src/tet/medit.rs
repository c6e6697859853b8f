//! MEDIT `.mesh` files (ASCII, the format of MEDIT, MMG and libMeshb):
//! keyword blocks `Vertices`, `Tetrahedra`, `Triangles`, …, each a count
//! followed by records ending in a reference number, and `End`.

use std::fmt::Write as _;
use std::path::Path;

use glam::DVec3;

use super::TetMesh;
use crate::error::{Error, ErrorKind, Result};
use crate::text::Cursor;

/// Blocks this reader skips: keyword, integers per record, reals per record.
const SKIPPED: [(&str, u64, u64); 17] = [
    ("Edges", 3, 0),
    ("Triangles", 4, 0),
    ("Quadrilaterals", 5, 0),
    ("Hexahedra", 9, 0),
    ("Prisms", 7, 0),
    ("Pyramids", 6, 0),
    ("Corners", 1, 0),
    ("Ridges", 1, 0),
    ("RequiredVertices", 1, 0),
    ("RequiredEdges", 1, 0),
    ("RequiredTriangles", 1, 0),
    ("RequiredTetrahedra", 1, 0),
    ("Normals", 0, 3),
    ("NormalAtVertices", 2, 0),
    ("Tangents", 0, 3),
    ("TangentAtVertices", 2, 0),
    ("TangentAtEdges", 3, 0),
];

/// Reads a `.mesh` file.
///
/// # Errors
/// [`Error`] with the file and line: a malformed or truncated record, a
/// non-finite coordinate, a tetrahedron referencing a missing node, a
/// dimension other than 3, or an unknown keyword.
pub fn read(path: impl AsRef<Path>) -> Result<TetMesh> {
    let path = path.as_ref();
    let data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    from_bytes(&data, path)
}

/// Parses the contents of a `.mesh` file; `path` names it in errors.
///
/// # Errors
/// As for [`read`].
pub fn from_bytes(data: &[u8], path: impl AsRef<Path>) -> Result<TetMesh> {
    let path = path.as_ref();
    let mut c = Cursor::new(data, path, Some(b'#'));
    c.keyword("MeshVersionFormatted")?;
    let (at, version) = c.expect_token("the format version")?;
    if !matches!(version, b"1" | b"2" | b"3" | b"4") {
        return Err(c.syntax(at, "format version 1 to 4", version));
    }
    let mut positions: Option<Vec<DVec3>> = None;
    let mut raw_tets: Vec<([i64; 4], i32, usize)> = Vec::new();
    let mut dimension_seen = false;
    loop {
        let (at, keyword) = c.expect_token("a keyword or End")?;
        let word = String::from_utf8_lossy(keyword);
        if word.eq_ignore_ascii_case("End") {
            break;
        } else if word.eq_ignore_ascii_case("Dimension") {
            let (at, dim) = c.expect_token("the dimension")?;
            if dim != b"3" {
                return Err(c.syntax(at, "dimension 3", dim));
            }
            dimension_seen = true;
        } else if word.eq_ignore_ascii_case("Vertices") {
            let declared = c.u64("the number of vertices")?;
            let n = c.check_count("vertices", declared, 8)?;
            let mut list = Vec::with_capacity(n);
            for index in 0..n {
                let p = c.point(index)?;
                c.i64("a vertex reference")?;
                list.push(p);
            }
            positions = Some(list);
        } else if word.eq_ignore_ascii_case("Tetrahedra") {
            let declared = c.u64("the number of tetrahedra")?;
            let n = c.check_count("tetrahedra", declared, 10)?;
            raw_tets.reserve(n);
            for _ in 0..n {
                c.skip_space();
                let at = c.offset();
                let mut nodes = [0i64; 4];
                for slot in &mut nodes {
                    *slot = c.i64("a vertex index")?;
                }
                let reference = c.i64("a tetrahedron reference")?;
                let reference = i32::try_from(reference).map_err(|_| {
                    c.syntax(
                        at,
                        "a reference that fits 32 bits",
                        reference.to_string().as_bytes(),
                    )
                })?;
                raw_tets.push((nodes, reference, at));
            }
        } else if let Some(&(_, ints, reals)) = SKIPPED
            .iter()
            .find(|(name, _, _)| word.eq_ignore_ascii_case(name))
        {
            let declared = c.u64("a record count")?;
            let n = c.check_count("records", declared, 2 * (ints + reals) as usize)?;
            for _ in 0..n {
                for _ in 0..ints {
                    c.i64("an integer")?;
                }
                for _ in 0..reals {
                    c.f64("a real")?;
                }
            }
        } else {
            return Err(c.error_at(
                at,
                ErrorKind::Unsupported(format!("MEDIT keyword {word:?}")),
            ));
        }
    }
    if !dimension_seen {
        return Err(Error::new(
            path,
            ErrorKind::Truncated("a Dimension keyword".into()),
        ));
    }
    let positions = positions
        .ok_or_else(|| Error::new(path, ErrorKind::Truncated("a Vertices block".into())))?;
    let count = positions.len();
    let any_region = raw_tets.iter().any(|t| t.1 != 0);
    let mut tets = Vec::with_capacity(raw_tets.len());
    let mut regions = Vec::with_capacity(if any_region { raw_tets.len() } else { 0 });
    for (index, (nodes, reference, at)) in raw_tets.into_iter().enumerate() {
        let mut tet = [0u32; 4];
        for (slot, &node) in tet.iter_mut().zip(&nodes) {
            if node < 1 || node as u64 > count as u64 {
                return Err(c.error_at(
                    at,
                    ErrorKind::IndexOutOfRange {
                        element: "tetrahedron",
                        index,
                        node,
                        count,
                    },
                ));
            }
            *slot = (node - 1) as u32;
        }
        tets.push(tet);
        if any_region {
            regions.push(reference);
        }
    }
    Ok(TetMesh {
        positions,
        tets,
        regions,
        attributes: Vec::new(),
        warnings: Vec::new(),
    })
}

/// Writes a `.mesh` file: vertices, tetrahedra with their region as
/// reference, and the boundary triangles (reference 1), which MEDIT-family
/// viewers expect. Coordinates in shortest round-trip form.
///
/// # Errors
/// [`Error`] for a tetrahedron referencing a missing node, or an I/O error.
pub fn write(path: impl AsRef<Path>, mesh: &TetMesh) -> Result<()> {
    let path = path.as_ref();
    mesh.check_indices(path)?;
    let mut text = String::with_capacity(64 * mesh.positions.len() + 40 * mesh.tets.len());
    text.push_str("MeshVersionFormatted 2\nDimension 3\n");
    let _ = writeln!(text, "Vertices\n{}", mesh.positions.len());
    for p in &mesh.positions {
        let _ = writeln!(text, "{} {} {} 0", p.x, p.y, p.z);
    }
    let _ = writeln!(text, "Tetrahedra\n{}", mesh.tets.len());
    for (i, t) in mesh.tets.iter().enumerate() {
        let region = mesh.regions.get(i).copied().unwrap_or(0);
        let _ = writeln!(
            text,
            "{} {} {} {} {region}",
            t[0] + 1,
            t[1] + 1,
            t[2] + 1,
            t[3] + 1
        );
    }
    let boundary = mesh.boundary();
    let _ = writeln!(text, "Triangles\n{}", boundary.len());
    for f in &boundary {
        let _ = writeln!(text, "{} {} {} 1", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    text.push_str("End\n");
    std::fs::write(path, text).map_err(|e| Error::io(path, e))
}
