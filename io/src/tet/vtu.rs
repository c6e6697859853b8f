//! VTK XML unstructured grids (`.vtu`) for ParaView: the tetrahedra with
//! per-node and per-tetrahedron scalar fields, as ASCII or as inline base64
//! ("binary" in VTK's words; a UInt64 byte count, then little-endian data).

use std::fmt::Write as _;
use std::path::Path;

use super::TetMesh;
use crate::base64::encode_into as base64_into;
use crate::error::{Error, ErrorKind, Result};

/// How the data arrays are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// Numbers as text: readable, larger, exact (shortest round-trip form).
    Ascii,
    /// Inline base64: about a third of the ASCII size, exact.
    Base64,
}

/// A named scalar field: one value per node or per tetrahedron.
#[derive(Debug, Clone, Copy)]
pub struct Field<'a> {
    /// The name ParaView shows.
    pub name: &'a str,
    /// The values.
    pub values: &'a [f64],
}

/// VTK's cell type for a linear tetrahedron.
const VTK_TETRA: u8 = 10;

/// Writes `mesh` with `point_fields` (one value per node) and `cell_fields`
/// (one value per tetrahedron) to a `.vtu` file.
///
/// # Errors
/// [`ErrorKind::InvalidInput`] for a field of the wrong length or a
/// tetrahedron referencing a missing node; an I/O error.
pub fn write(
    path: impl AsRef<Path>,
    mesh: &TetMesh,
    point_fields: &[Field<'_>],
    cell_fields: &[Field<'_>],
    encoding: Encoding,
) -> Result<()> {
    let path = path.as_ref();
    let text = to_string(path, mesh, point_fields, cell_fields, encoding)?;
    std::fs::write(path, text).map_err(|e| Error::io(path, e))
}

/// The `.vtu` document as a string; `path` names it in errors.
///
/// # Errors
/// As for [`write()`], without the I/O.
pub fn to_string(
    path: impl AsRef<Path>,
    mesh: &TetMesh,
    point_fields: &[Field<'_>],
    cell_fields: &[Field<'_>],
    encoding: Encoding,
) -> Result<String> {
    let path = path.as_ref();
    mesh.check_indices(path)?;
    for (fields, expected, what) in [
        (point_fields, mesh.positions.len(), "nodes"),
        (cell_fields, mesh.tets.len(), "tetrahedra"),
    ] {
        if let Some(f) = fields.iter().find(|f| f.values.len() != expected) {
            return Err(Error::new(
                path,
                ErrorKind::InvalidInput(format!(
                    "field {:?} has {} values for {expected} {what}",
                    f.name,
                    f.values.len()
                )),
            ));
        }
    }
    let format = match encoding {
        Encoding::Ascii => "ascii",
        Encoding::Base64 => "binary",
    };
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\"?>\n");
    out.push_str("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n");
    let _ = writeln!(
        out,
        "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        mesh.positions.len(),
        mesh.tets.len()
    );
    for (tag, fields) in [("PointData", point_fields), ("CellData", cell_fields)] {
        let _ = writeln!(out, "<{tag}>");
        for f in fields {
            let _ = writeln!(
                out,
                "<DataArray type=\"Float64\" Name=\"{}\" format=\"{format}\">",
                escape(f.name)
            );
            array(
                &mut out,
                encoding,
                f.values.iter().copied(),
                f64::to_le_bytes,
            );
            out.push_str("</DataArray>\n");
        }
        let _ = writeln!(out, "</{tag}>");
    }
    let _ = writeln!(
        out,
        "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"{format}\">"
    );
    array(
        &mut out,
        encoding,
        mesh.positions.iter().flat_map(|p| p.to_array()),
        f64::to_le_bytes,
    );
    out.push_str("</DataArray>\n</Points>\n<Cells>\n");
    let _ = writeln!(
        out,
        "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"{format}\">"
    );
    array(
        &mut out,
        encoding,
        mesh.tets.iter().flatten().map(|&i| i64::from(i)),
        i64::to_le_bytes,
    );
    let _ = writeln!(
        out,
        "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"{format}\">"
    );
    array(
        &mut out,
        encoding,
        (1..=mesh.tets.len() as i64).map(|k| 4 * k),
        i64::to_le_bytes,
    );
    let _ = writeln!(
        out,
        "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"{format}\">"
    );
    array(
        &mut out,
        encoding,
        std::iter::repeat_n(VTK_TETRA, mesh.tets.len()),
        u8::to_le_bytes,
    );
    out.push_str("</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    Ok(out)
}

/// Writes one data array's content and a newline.
fn array<T: std::fmt::Display + Copy, const N: usize>(
    out: &mut String,
    encoding: Encoding,
    values: impl Iterator<Item = T>,
    to_bytes: fn(T) -> [u8; N],
) {
    match encoding {
        Encoding::Ascii => {
            for (i, v) in values.enumerate() {
                if i > 0 {
                    out.push(if i % 12 == 0 { '\n' } else { ' ' });
                }
                let _ = write!(out, "{v}");
            }
        }
        Encoding::Base64 => {
            let mut bytes = vec![0u8; 8];
            for v in values {
                bytes.extend_from_slice(&to_bytes(v));
            }
            let len = (bytes.len() - 8) as u64;
            bytes[..8].copy_from_slice(&len.to_le_bytes());
            base64_into(out, &bytes);
        }
    }
    out.push('\n');
}

/// Escapes a name for an XML attribute.
fn escape(name: &str) -> String {
    let mut s = String::with_capacity(name.len());
    for ch in name.chars() {
        match ch {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&apos;"),
            c => s.push(c),
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_escaped() {
        assert_eq!(escape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&apos;");
    }
}
