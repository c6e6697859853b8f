//! Stanford PLY (Turk 1994; the layout MeshLab, Blender, Open3D and
//! CloudCompare read): ASCII, binary little-endian and binary big-endian
//! in, ASCII and binary little-endian out. Points or triangles with
//! optional normals (`nx ny nz`), colours (`red green blue [alpha]`,
//! uchar), texture coordinates (`s t`; `u v` and `texture_u texture_v`
//! are read too) and any extra per-vertex scalar properties.

use std::fmt::Write as _;
use std::path::Path;

use glam::{Vec2, Vec3};

use crate::error::{Error, ErrorKind, Result};
use crate::text::Cursor;

/// A point cloud or triangle mesh with per-vertex attributes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlyData {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles (0-based); empty for a point cloud. Polygons read from a
    /// file are fan-triangulated.
    pub triangles: Vec<[u32; 3]>,
    /// Per-vertex normals.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex colours, RGBA 8-bit (alpha 255 when the file has none).
    pub colors: Option<Vec<[u8; 4]>>,
    /// Per-vertex texture coordinates in [`TriMesh`](super::TriMesh)'s
    /// convention (v down, `v = 0` at image row 0): the file's `t` (v up)
    /// is read as `1 - t` and written back as `1 - v`.
    pub uvs: Option<Vec<Vec2>>,
    /// Other per-vertex scalar properties, by name, written as `float`.
    pub scalars: Vec<(String, Vec<f32>)>,
}

/// How to write the data section.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Text, one element per line.
    Ascii,
    /// Binary little-endian: compact, and what most tools write.
    BinaryLittleEndian,
}

/// The scalar types of the format, by size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &[u8]) -> Option<Self> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// Decodes one value from `bytes` (exactly `size()` long).
    fn decode(self, bytes: &[u8], big_endian: bool) -> f64 {
        let mut b = [0u8; 8];
        b[..bytes.len()].copy_from_slice(bytes);
        if big_endian {
            b[..bytes.len()].reverse();
        }
        match self {
            Scalar::I8 => f64::from(b[0] as i8),
            Scalar::U8 => f64::from(b[0]),
            Scalar::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            Scalar::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            Scalar::I32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F64 => f64::from_le_bytes(b),
        }
    }
}

/// A property: a scalar, or a list with a count type and an item type.
#[derive(Debug, Clone)]
struct Property {
    name: String,
    list: Option<Scalar>,
    kind: Scalar,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

/// Reads a `.ply` file.
///
/// # Errors
/// [`Error`] with the file and line (header, ASCII data) or byte offset
/// (binary data): a malformed header, a missing `x y z`, a truncated
/// element, a non-finite coordinate, a face with fewer than 3 vertices or
/// referencing a missing vertex, or a count the file cannot hold.
pub fn read(path: &Path) -> Result<PlyData> {
    let data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    from_bytes(&data, path)
}

/// Parses the contents of a `.ply` file; `path` names it in errors.
///
/// # Errors
/// As for [`read`].
pub fn from_bytes(data: &[u8], path: &Path) -> Result<PlyData> {
    let mut c = Cursor::new(data, path, None);
    c.keyword("ply")?;
    c.keyword("format")?;
    let (at, format) = c.expect_token("ascii, binary_little_endian or binary_big_endian")?;
    let (ascii, big_endian) = match format {
        b"ascii" => (true, false),
        b"binary_little_endian" => (false, false),
        b"binary_big_endian" => (false, true),
        _ => {
            return Err(c.syntax(
                at,
                "ascii, binary_little_endian or binary_big_endian",
                format,
            ));
        }
    };
    let (at, version) = c.expect_token("the format version")?;
    if version != b"1.0" {
        return Err(c.syntax(at, "version 1.0", version));
    }
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let (at, word) = c.expect_token("end_header")?;
        match word {
            b"end_header" => break,
            b"comment" | b"obj_info" => c.skip_line(),
            b"element" => {
                let (_, name) = c.expect_token("an element name")?;
                let count = c.u64("an element count")?;
                let count =
                    usize::try_from(count).map_err(|_| c.syntax(at, "a smaller count", b"huge"))?;
                elements.push(Element {
                    name: String::from_utf8_lossy(name).into_owned(),
                    count,
                    properties: Vec::new(),
                });
            }
            b"property" => {
                let element = elements
                    .last_mut()
                    .ok_or_else(|| c.syntax(at, "an element before its properties", word))?;
                let (at, kind) = c.expect_token("a property type")?;
                let property = if kind == b"list" {
                    let (at_count, count_kind) = c.expect_token("a list count type")?;
                    let count = Scalar::parse(count_kind)
                        .filter(|s| !matches!(s, Scalar::F32 | Scalar::F64))
                        .ok_or_else(|| {
                            c.syntax(at_count, "an integer list count type", count_kind)
                        })?;
                    let (at_item, item) = c.expect_token("a list item type")?;
                    let item = Scalar::parse(item)
                        .ok_or_else(|| c.syntax(at_item, "a scalar type", item))?;
                    let (_, name) = c.expect_token("a property name")?;
                    Property {
                        name: String::from_utf8_lossy(name).into_owned(),
                        list: Some(count),
                        kind: item,
                    }
                } else {
                    let scalar =
                        Scalar::parse(kind).ok_or_else(|| c.syntax(at, "a property type", kind))?;
                    let (_, name) = c.expect_token("a property name")?;
                    Property {
                        name: String::from_utf8_lossy(name).into_owned(),
                        list: None,
                        kind: scalar,
                    }
                };
                element.properties.push(property);
            }
            other => return Err(c.syntax(at, "a header keyword", other)),
        }
    }
    // The data starts after the end_header line.
    c.skip_line();
    let mut reader = DataReader {
        c,
        ascii,
        big_endian,
    };

    let mut out = PlyData::default();
    let mut vertex_seen = false;
    for element in &elements {
        // Smallest encoded element: one byte (binary) or two (ASCII) per
        // property.
        let per = element.properties.len().max(1) * if ascii { 2 } else { 1 };
        reader
            .c
            .check_count(counted_noun(&element.name), element.count as u64, per)?;
        match element.name.as_str() {
            "vertex" if !vertex_seen => {
                vertex_seen = true;
                read_vertices(&mut reader, element, &mut out)?;
            }
            "face" => read_faces(&mut reader, element, &mut out)?,
            _ => {
                for _ in 0..element.count {
                    for p in &element.properties {
                        reader.property(p)?;
                    }
                }
            }
        }
    }
    if !vertex_seen {
        return Err(Error::new(
            path,
            ErrorKind::Truncated("a vertex element".into()),
        ));
    }
    let n = out.positions.len();
    for (index, tri) in out.triangles.iter().enumerate() {
        if let Some(&bad) = tri.iter().find(|&&i| i as usize >= n) {
            return Err(Error::new(
                path,
                ErrorKind::IndexOutOfRange {
                    element: "face",
                    index,
                    node: i64::from(bad),
                    count: n,
                },
            ));
        }
    }
    Ok(out)
}

/// What an element count counts, for error messages: the standard
/// elements by name, others generically.
fn counted_noun(name: &str) -> &'static str {
    match name {
        "vertex" => "vertices",
        "face" => "faces",
        _ => "elements",
    }
}

/// Reads the values of the data section, ASCII or binary.
struct DataReader<'a> {
    c: Cursor<'a>,
    ascii: bool,
    big_endian: bool,
}

impl DataReader<'_> {
    fn scalar(&mut self, kind: Scalar) -> Result<f64> {
        if self.ascii {
            return self.c.f64("a property value");
        }
        let bytes = self.c.take(kind.size(), "a property value")?;
        Ok(kind.decode(bytes, self.big_endian))
    }

    /// One property: a scalar, or a list (its items appended to `items`).
    fn property(&mut self, p: &Property) -> Result<f64> {
        match p.list {
            None => self.scalar(p.kind),
            Some(count_kind) => {
                let n = self.list_len(count_kind)?;
                for _ in 0..n {
                    self.scalar(p.kind)?;
                }
                Ok(n as f64)
            }
        }
    }

    fn list_len(&mut self, count_kind: Scalar) -> Result<usize> {
        let at = self.c.offset();
        let n = self.scalar(count_kind)?;
        if !(n >= 0.0 && n.fract() == 0.0 && n <= 1e6) {
            return Err(self.located(
                at,
                ErrorKind::Syntax {
                    expected: "a list length from 0 to 10^6".into(),
                    found: n.to_string(),
                },
            ));
        }
        Ok(n as usize)
    }

    fn located(&self, at: usize, kind: ErrorKind) -> Error {
        if self.ascii {
            self.c.error_at(at, kind)
        } else {
            self.c.error_at_byte(at, kind)
        }
    }
}

fn read_vertices(r: &mut DataReader<'_>, element: &Element, out: &mut PlyData) -> Result<()> {
    let find = |names: &[&str]| {
        element
            .properties
            .iter()
            .position(|p| p.list.is_none() && names.contains(&p.name.as_str()))
    };
    let (Some(x), Some(y), Some(z)) = (find(&["x"]), find(&["y"]), find(&["z"])) else {
        return Err(Error::new(
            r.c.path(),
            ErrorKind::Truncated("vertex properties x, y and z".into()),
        ));
    };
    let normal = [find(&["nx"]), find(&["ny"]), find(&["nz"])];
    let color = [
        find(&["red", "r"]),
        find(&["green", "g"]),
        find(&["blue", "b"]),
    ];
    let alpha = find(&["alpha", "a"]);
    let uv = [
        find(&["s", "u", "texture_u"]),
        find(&["t", "v", "texture_v"]),
    ];
    let known: Vec<usize> = [Some(x), Some(y), Some(z), alpha]
        .into_iter()
        .chain(normal)
        .chain(color)
        .chain(uv)
        .flatten()
        .collect();
    let extra: Vec<usize> = (0..element.properties.len())
        .filter(|i| !known.contains(i) && element.properties[*i].list.is_none())
        .collect();

    let n = element.count;
    let has_normal = normal.iter().all(Option::is_some);
    let has_color = color.iter().all(Option::is_some);
    let has_uv = uv.iter().all(Option::is_some);
    out.positions.reserve(n);
    let mut normals = Vec::with_capacity(if has_normal { n } else { 0 });
    let mut colors = Vec::with_capacity(if has_color { n } else { 0 });
    let mut uvs = Vec::with_capacity(if has_uv { n } else { 0 });
    let mut scalars: Vec<(String, Vec<f32>)> = extra
        .iter()
        .map(|&i| (element.properties[i].name.clone(), Vec::with_capacity(n)))
        .collect();
    let mut values = vec![0.0f64; element.properties.len()];
    let to_u8 = |v: f64, kind: Scalar| {
        if matches!(kind, Scalar::F32 | Scalar::F64) {
            (v.clamp(0.0, 1.0) * 255.0).round() as u8
        } else {
            v.clamp(0.0, 255.0) as u8
        }
    };
    for index in 0..n {
        r.c.skip_space();
        let at = r.c.offset();
        for (slot, p) in values.iter_mut().zip(&element.properties) {
            *slot = r.property(p)?;
        }
        let p = Vec3::new(values[x] as f32, values[y] as f32, values[z] as f32);
        if !p.is_finite() {
            let value = [values[x], values[y], values[z]]
                .into_iter()
                .find(|v| !(*v as f32).is_finite())
                .unwrap_or(f64::NAN);
            return Err(r.located(at, ErrorKind::NonFinite { index, value }));
        }
        out.positions.push(p);
        if has_normal {
            normals.push(Vec3::from(normal.map(|i| values[i.unwrap_or(0)] as f32)));
        }
        if has_color {
            let k = |i: Option<usize>| i.map(|i| to_u8(values[i], element.properties[i].kind));
            colors.push([
                k(color[0]).unwrap_or(0),
                k(color[1]).unwrap_or(0),
                k(color[2]).unwrap_or(0),
                k(alpha).unwrap_or(255),
            ]);
        }
        if has_uv {
            // PLY's t grows upwards (as OBJ's v); ours grows downwards.
            uvs.push(Vec2::new(
                values[uv[0].unwrap_or(0)] as f32,
                1.0 - values[uv[1].unwrap_or(0)] as f32,
            ));
        }
        for ((_, column), &i) in scalars.iter_mut().zip(&extra) {
            column.push(values[i] as f32);
        }
    }
    out.normals = has_normal.then_some(normals);
    out.colors = has_color.then_some(colors);
    out.uvs = has_uv.then_some(uvs);
    out.scalars = scalars;
    Ok(())
}

fn read_faces(r: &mut DataReader<'_>, element: &Element, out: &mut PlyData) -> Result<()> {
    let indices = element
        .properties
        .iter()
        .position(|p| p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index"));
    let mut polygon: Vec<u32> = Vec::new();
    for _ in 0..element.count {
        r.c.skip_space();
        let at = r.c.offset();
        for (i, p) in element.properties.iter().enumerate() {
            if Some(i) != indices {
                r.property(p)?;
                continue;
            }
            let Some(count_kind) = p.list else { continue };
            let n = r.list_len(count_kind)?;
            polygon.clear();
            for _ in 0..n {
                let v = r.scalar(p.kind)?;
                if !(v >= 0.0 && v <= f64::from(u32::MAX - 1) && v.fract() == 0.0) {
                    return Err(r.located(
                        at,
                        ErrorKind::Syntax {
                            expected: "a vertex index".into(),
                            found: v.to_string(),
                        },
                    ));
                }
                polygon.push(v as u32);
            }
            if n < 3 {
                return Err(r.located(
                    at,
                    ErrorKind::Syntax {
                        expected: "a face with at least 3 vertices".into(),
                        found: format!("{n} vertices"),
                    },
                ));
            }
            for k in 1..n - 1 {
                out.triangles.push([polygon[0], polygon[k], polygon[k + 1]]);
            }
        }
    }
    Ok(())
}

/// Writes `data` as a `.ply` file.
///
/// # Errors
/// [`ErrorKind::InvalidInput`] for attribute arrays of the wrong length or
/// triangles referencing missing vertices; an I/O error.
pub fn write(path: &Path, data: &PlyData, format: Format) -> Result<()> {
    let bytes = to_bytes(path, data, format)?;
    std::fs::write(path, bytes).map_err(|e| Error::io(path, e))
}

/// The `.ply` file as bytes; `path` names it in errors.
///
/// # Errors
/// As for [`write()`], without the I/O.
pub fn to_bytes(path: &Path, data: &PlyData, format: Format) -> Result<Vec<u8>> {
    let n = data.positions.len();
    let invalid = |what: String| Error::new(path, ErrorKind::InvalidInput(what));
    let lengths = [
        ("normals", data.normals.as_ref().map(Vec::len)),
        ("colors", data.colors.as_ref().map(Vec::len)),
        ("uvs", data.uvs.as_ref().map(Vec::len)),
    ];
    for (name, len) in lengths {
        if let Some(len) = len.filter(|&l| l != n) {
            return Err(invalid(format!("{len} {name} for {n} vertices")));
        }
    }
    for (name, column) in &data.scalars {
        if column.len() != n {
            return Err(invalid(format!(
                "scalar {name:?} has {} values for {n} vertices",
                column.len()
            )));
        }
        if name.is_empty() || name.contains(char::is_whitespace) {
            return Err(invalid(format!(
                "scalar name {name:?} is not a PLY property name"
            )));
        }
    }
    if let Some((t, _)) = data
        .triangles
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&i| i as usize >= n))
    {
        return Err(invalid(format!("triangle {t} references a missing vertex")));
    }

    let mut header = String::from("ply\n");
    header.push_str(match format {
        Format::Ascii => "format ascii 1.0\n",
        Format::BinaryLittleEndian => "format binary_little_endian 1.0\n",
    });
    header.push_str("comment written by trilux-io\n");
    let _ = writeln!(header, "element vertex {n}");
    header.push_str("property float x\nproperty float y\nproperty float z\n");
    if data.normals.is_some() {
        header.push_str("property float nx\nproperty float ny\nproperty float nz\n");
    }
    if data.colors.is_some() {
        header.push_str(
            "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n",
        );
    }
    if data.uvs.is_some() {
        header.push_str("property float s\nproperty float t\n");
    }
    for (name, _) in &data.scalars {
        let _ = writeln!(header, "property float {name}");
    }
    if !data.triangles.is_empty() {
        let _ = writeln!(header, "element face {}", data.triangles.len());
        header.push_str("property list uchar int vertex_indices\n");
    }
    header.push_str("end_header\n");

    let mut out = header.into_bytes();
    match format {
        Format::Ascii => {
            let mut line = String::new();
            for i in 0..n {
                line.clear();
                let p = data.positions[i];
                let _ = write!(line, "{} {} {}", p.x, p.y, p.z);
                if let Some(normals) = &data.normals {
                    let q = normals[i];
                    let _ = write!(line, " {} {} {}", q.x, q.y, q.z);
                }
                if let Some(colors) = &data.colors {
                    let [r, g, b, a] = colors[i];
                    let _ = write!(line, " {r} {g} {b} {a}");
                }
                if let Some(uvs) = &data.uvs {
                    let _ = write!(line, " {} {}", uvs[i].x, 1.0 - uvs[i].y);
                }
                for (_, column) in &data.scalars {
                    let _ = write!(line, " {}", column[i]);
                }
                line.push('\n');
                out.extend_from_slice(line.as_bytes());
            }
            for t in &data.triangles {
                out.extend_from_slice(format!("3 {} {} {}\n", t[0], t[1], t[2]).as_bytes());
            }
        }
        Format::BinaryLittleEndian => {
            for i in 0..n {
                let mut floats = data.positions[i].to_array().to_vec();
                if let Some(normals) = &data.normals {
                    floats.extend(normals[i].to_array());
                }
                for f in floats {
                    out.extend_from_slice(&f.to_le_bytes());
                }
                if let Some(colors) = &data.colors {
                    out.extend_from_slice(&colors[i]);
                }
                if let Some(uvs) = &data.uvs {
                    out.extend_from_slice(&uvs[i].x.to_le_bytes());
                    out.extend_from_slice(&(1.0 - uvs[i].y).to_le_bytes());
                }
                for (_, column) in &data.scalars {
                    out.extend_from_slice(&column[i].to_le_bytes());
                }
            }
            for t in &data.triangles {
                out.push(3);
                for &i in t {
                    out.extend_from_slice(&(i as i32).to_le_bytes());
                }
            }
        }
    }
    Ok(out)
}
