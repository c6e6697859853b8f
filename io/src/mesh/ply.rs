//! Stanford PLY (Turk 1994; the layout MeshLab, Blender, Open3D and
//! CloudCompare read): ASCII, binary little-endian and binary big-endian
//! in, ASCII and binary little-endian out. Points or triangles with
//! optional normals (`nx ny nz`), colours (`red green blue [alpha]`,
//! uchar), texture coordinates (`s t`; `u v` and `texture_u texture_v`
//! are read too) and any extra per-vertex scalar properties. Faces are
//! `face` polygons (fan-triangulated) with optional per-corner texture
//! coordinates (MeshLab/VCGLIB's `property list uchar float texcoord`:
//! a vertex with several UVs is split per corner, as the OBJ reader
//! does), and `tristrips` (OpenGL strip order, `-1` restarts a strip);
//! `comment TextureFile NAME` names the texture. Elements and properties
//! not read are listed in [`PlyData::warnings`], never skipped in
//! silence.

use std::fmt::Write as _;
use std::path::Path;

use glam::{DVec3, Vec2, Vec3};

use crate::error::{Error, ErrorKind, Result};
use crate::text::Cursor;
use crate::warning::Warning;

/// A point cloud or triangle mesh with per-vertex attributes: what
/// [`read()`] returns and [`write()`] takes. For sampled points, fill
/// `positions` and whichever of `normals`, `uvs`, `face_ids` and `scalars`
/// the samples have:
///
/// ```
/// use trilux_io::glam::Vec3;
/// use trilux_io::mesh::ply::{self, Format, PlyData};
///
/// let cloud = PlyData {
///     positions: vec![Vec3::ZERO, Vec3::X],
///     face_ids: Some(vec![0, 7]),
///     ..PlyData::default()
/// };
/// let path = std::env::temp_dir().join("trilux-io-doc-points.ply");
/// ply::write(&path, &cloud, Format::default())?; // binary little-endian
/// assert_eq!(ply::read(&path)?, cloud);
/// # Ok::<(), trilux_io::Error>(())
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlyData {
    /// Vertex positions, relative to `origin`.
    pub positions: Vec<Vec3>,
    /// The global shift of far-from-origin coordinates, as
    /// [`TriMesh::origin`](super::TriMesh::origin): the reader parses
    /// coordinates in `f64` and keeps `origin + positions[i]`; the writer
    /// writes `double` coordinates when it is not zero.
    pub origin: DVec3,
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
    /// Per-vertex triangle indices (the face a sampled point lies on),
    /// stored as the integer property `face_id`.
    pub face_ids: Option<Vec<u32>>,
    /// Per-vertex integer ids (a hair strand's or a sample's index),
    /// stored as the integer property `id` (a float `id` is read as an
    /// ordinary scalar).
    pub ids: Option<Vec<u32>>,
    /// Other per-vertex scalar properties, by name, written as `float`.
    pub scalars: Vec<(String, Vec<f32>)>,
    /// The texture a `comment TextureFile NAME` header line names
    /// (MeshLab/VCGLIB), as written (relative to the file's folder);
    /// written back the same way.
    pub texture_file: Option<String>,
    /// What the reader skipped (elements and properties it does not read),
    /// each naming the file, the element and what was skipped. Not
    /// written.
    pub warnings: Vec<Warning>,
}

/// How to write the data section.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Format {
    /// Text, one element per line.
    Ascii,
    /// Binary little-endian: compact, and what most tools write.
    #[default]
    BinaryLittleEndian,
    /// Binary big-endian (older SGI and Java tools).
    BinaryBigEndian,
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

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
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
pub fn read(path: impl AsRef<Path>) -> Result<PlyData> {
    let path = path.as_ref();
    let data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    from_bytes(&data, path)
}

/// Parses the contents of a `.ply` file; `path` names it in errors.
///
/// # Errors
/// As for [`read`].
pub fn from_bytes(data: &[u8], path: impl AsRef<Path>) -> Result<PlyData> {
    let path = path.as_ref();
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
    let mut texture_file = None;
    loop {
        let (at, word) = c.expect_token("end_header")?;
        match word {
            b"end_header" => break,
            b"comment" => {
                // MeshLab/VCGLIB name the texture in a comment.
                let start = c.offset();
                c.skip_line();
                let line = String::from_utf8_lossy(&data[start..c.offset()]);
                let line = line.trim();
                if let Some(name) = line
                    .strip_prefix("TextureFile")
                    .filter(|rest| rest.starts_with(char::is_whitespace))
                    .map(str::trim)
                    .filter(|name| !name.is_empty())
                {
                    texture_file = Some(name.to_string());
                }
            }
            b"obj_info" => c.skip_line(),
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

    let mut out = PlyData {
        texture_file,
        ..PlyData::default()
    };
    let mut corners = CornerUvs::default();
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
            "face" => read_faces(&mut reader, element, &mut out, &mut corners)?,
            "tristrips" => read_strips(&mut reader, element, &mut out)?,
            _ => {
                if element.count > 0 {
                    out.warnings.push(Warning::new(
                        path,
                        None,
                        format!(
                            "element `{}` ({} records{}) is not read",
                            element.name,
                            element.count,
                            if element.name == "vertex" {
                                ", a second vertex element"
                            } else {
                                ""
                            }
                        ),
                    ));
                }
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
                ErrorKind::ReferenceOutOfRange(Box::new(crate::error::Reference {
                    what: "vertex",
                    reference: i64::from(bad),
                    element: "triangle",
                    index,
                    count: n,
                    records: "vertices",
                })),
            ));
        }
    }
    corners.split_vertices(&mut out);
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

    /// The offset where the next record starts. ASCII records may be
    /// preceded by whitespace; a binary record never is, and its first
    /// byte may well be 0x0a or 0x20 (a float's low byte), so nothing is
    /// skipped there.
    fn record_start(&mut self) -> usize {
        if self.ascii {
            self.c.skip_space();
        }
        self.c.offset()
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
            ErrorKind::Syntax {
                expected: "vertex properties x, y and z".into(),
                found: "a vertex element without them".into(),
            },
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
    // An integer `face_id` is a sampled point's triangle; a float one is
    // kept as an ordinary scalar.
    let face_id = find(&["face_id"]).filter(|&i| !element.properties[i].kind.is_float());
    let id = find(&["id"]).filter(|&i| !element.properties[i].kind.is_float());
    let known: Vec<usize> = [Some(x), Some(y), Some(z), alpha, face_id, id]
        .into_iter()
        .chain(normal)
        .chain(color)
        .chain(uv)
        .flatten()
        .collect();
    let extra: Vec<usize> = (0..element.properties.len())
        .filter(|i| !known.contains(i) && element.properties[*i].list.is_none())
        .collect();
    let lists: Vec<usize> = (0..element.properties.len())
        .filter(|&i| element.properties[i].list.is_some())
        .collect();
    if !lists.is_empty() {
        let read: Vec<usize> = (0..element.properties.len())
            .filter(|i| !lists.contains(i))
            .collect();
        warn_unread(r, element, &read, out);
    }

    let n = element.count;
    let has_normal = normal.iter().all(Option::is_some);
    let has_color = color.iter().all(Option::is_some);
    let has_uv = uv.iter().all(Option::is_some);
    let mut points: Vec<DVec3> = Vec::with_capacity(n);
    let mut normals = Vec::with_capacity(if has_normal { n } else { 0 });
    let mut colors = Vec::with_capacity(if has_color { n } else { 0 });
    let mut uvs = Vec::with_capacity(if has_uv { n } else { 0 });
    let mut face_ids = Vec::with_capacity(if face_id.is_some() { n } else { 0 });
    let mut ids = Vec::with_capacity(if id.is_some() { n } else { 0 });
    let mut scalars: Vec<(String, Vec<f32>)> = extra
        .iter()
        .map(|&i| (element.properties[i].name.clone(), Vec::with_capacity(n)))
        .collect();
    let mut values = vec![0.0f64; element.properties.len()];
    let to_u8 = |v: f64, kind: Scalar| {
        if kind.is_float() {
            (v.clamp(0.0, 1.0) * 255.0).round() as u8
        } else {
            v.clamp(0.0, 255.0) as u8
        }
    };
    for index in 0..n {
        let at = r.record_start();
        for (slot, p) in values.iter_mut().zip(&element.properties) {
            *slot = r.property(p)?;
        }
        let p = DVec3::new(values[x], values[y], values[z]);
        if let Some(value) = p.to_array().into_iter().find(|v| !v.is_finite()) {
            return Err(r.located(at, ErrorKind::NonFinite { index, value }));
        }
        points.push(p);
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
        if let Some(i) = face_id {
            let v = values[i];
            if !(0.0..=f64::from(u32::MAX)).contains(&v) {
                return Err(r.located(
                    at,
                    ErrorKind::Syntax {
                        expected: format!("a face_id from 0 to {} at vertex {index}", u32::MAX),
                        found: v.to_string(),
                    },
                ));
            }
            face_ids.push(v as u32);
        }
        if let Some(i) = id {
            let v = values[i];
            if !(0.0..=f64::from(u32::MAX)).contains(&v) {
                return Err(r.located(
                    at,
                    ErrorKind::Syntax {
                        expected: format!("an id from 0 to {} at vertex {index}", u32::MAX),
                        found: v.to_string(),
                    },
                ));
            }
            ids.push(v as u32);
        }
        for ((_, column), &i) in scalars.iter_mut().zip(&extra) {
            column.push(values[i] as f32);
        }
    }
    let (origin, positions) = super::recenter(&points);
    if let Some(index) = positions.iter().position(|p| !p.is_finite()) {
        let value = points[index].max_element();
        return Err(Error::new(
            r.c.path(),
            ErrorKind::OutOfRange(format!(
                "vertex {index} is at {value}, too far from the other vertices for f32 positions"
            )),
        ));
    }
    out.origin = origin;
    out.positions = positions;
    out.normals = has_normal.then_some(normals);
    out.colors = has_color.then_some(colors);
    out.uvs = has_uv.then_some(uvs);
    out.face_ids = face_id.map(|_| face_ids);
    out.ids = id.map(|_| ids);
    out.scalars = scalars;
    Ok(())
}

/// Per-corner texture coordinates of the triangles read from `face`
/// elements (`texcoord` lists), in TriMesh's v-down convention, until the
/// vertices are split.
#[derive(Default)]
struct CornerUvs {
    /// `(triangle, its three corner UVs)`.
    triangles: Vec<(usize, [Vec2; 3])>,
}

impl CornerUvs {
    /// Gives each corner its own UV (MeshLab's per-wedge texture
    /// coordinates): a vertex keeps the first UV a corner gives it, and
    /// every other distinct UV makes a copy of the vertex with all its
    /// attributes, as the OBJ reader splits `v/vt` pairs. Vertices no
    /// corner gives a UV keep the per-vertex one, or (0, 0).
    fn split_vertices(self, out: &mut PlyData) {
        if self.triangles.is_empty() {
            return;
        }
        let n = out.positions.len();
        let mut uvs: Vec<Option<Vec2>> = match out.uvs.take() {
            Some(uvs) => uvs.into_iter().map(Some).collect(),
            None => vec![None; n],
        };
        let mut given = vec![false; n];
        let mut copies: std::collections::HashMap<(u32, [u32; 2]), u32> = Default::default();
        for (t, corner_uvs) in self.triangles {
            for (corner, uv) in corner_uvs.into_iter().enumerate() {
                let v = out.triangles[t][corner] as usize;
                let key = (v as u32, [uv.x.to_bits(), uv.y.to_bits()]);
                if !given[v] {
                    given[v] = true;
                    uvs[v] = Some(uv);
                    copies.insert(key, v as u32);
                    continue;
                }
                let copy = *copies.entry(key).or_insert_with(|| {
                    copy_vertex(out, v);
                    uvs.push(Some(uv));
                    given.push(true);
                    (out.positions.len() - 1) as u32
                });
                out.triangles[t][corner] = copy;
            }
        }
        out.uvs = Some(uvs.into_iter().map(Option::unwrap_or_default).collect());
    }
}

/// Appends a copy of vertex `v` with every per-vertex attribute but UVs.
fn copy_vertex(out: &mut PlyData, v: usize) {
    out.positions.push(out.positions[v]);
    if let Some(normals) = out.normals.as_mut() {
        normals.push(normals[v]);
    }
    if let Some(colors) = out.colors.as_mut() {
        colors.push(colors[v]);
    }
    if let Some(ids) = out.face_ids.as_mut() {
        ids.push(ids[v]);
    }
    if let Some(ids) = out.ids.as_mut() {
        ids.push(ids[v]);
    }
    for (_, column) in &mut out.scalars {
        column.push(column[v]);
    }
}

/// Reads one list of vertex indices (a polygon or a strip) into `into`;
/// `-1` is kept as `None` only when `restart` allows it (strips).
fn index_list(
    r: &mut DataReader<'_>,
    p: &Property,
    count_kind: Scalar,
    at: usize,
    restart: bool,
    into: &mut Vec<Option<u32>>,
) -> Result<usize> {
    let n = r.list_len(count_kind)?;
    into.clear();
    for _ in 0..n {
        let v = r.scalar(p.kind)?;
        if restart && v == -1.0 {
            into.push(None);
            continue;
        }
        if !(v >= 0.0 && v <= f64::from(u32::MAX - 1) && v.fract() == 0.0) {
            return Err(r.located(
                at,
                ErrorKind::Syntax {
                    expected: if restart {
                        "a vertex index or -1 (a strip restart)".into()
                    } else {
                        "a vertex index".into()
                    },
                    found: v.to_string(),
                },
            ));
        }
        into.push(Some(v as u32));
    }
    Ok(n)
}

/// Warns about the properties of `element` other than those at `read`.
fn warn_unread(r: &DataReader<'_>, element: &Element, read: &[usize], out: &mut PlyData) {
    let skipped: Vec<&str> = (0..element.properties.len())
        .filter(|i| !read.contains(i))
        .map(|i| element.properties[i].name.as_str())
        .collect();
    if !skipped.is_empty() && element.count > 0 {
        out.warnings.push(Warning::new(
            r.c.path(),
            None,
            format!(
                "property `{}` of element `{}` is not read",
                skipped.join("`, `"),
                element.name
            ),
        ));
    }
}

fn read_faces(
    r: &mut DataReader<'_>,
    element: &Element,
    out: &mut PlyData,
    corners: &mut CornerUvs,
) -> Result<()> {
    let list_named = |names: &[&str]| {
        element
            .properties
            .iter()
            .position(|p| p.list.is_some() && names.contains(&p.name.as_str()))
    };
    let indices = list_named(&["vertex_indices", "vertex_index"]);
    let texcoord = list_named(&["texcoord"]).filter(|&i| element.properties[i].kind.is_float());
    let Some(indices) = indices else {
        if element.count > 0 {
            return Err(Error::new(
                r.c.path(),
                ErrorKind::Syntax {
                    expected: "a face element with a vertex_indices list".into(),
                    found: format!("{} faces without one", element.count),
                },
            ));
        }
        return Ok(());
    };
    warn_unread(
        r,
        element,
        &[Some(indices), texcoord].map(|i| i.unwrap_or(usize::MAX)),
        out,
    );
    let mut polygon: Vec<Option<u32>> = Vec::new();
    let mut uvs: Vec<Vec2> = Vec::new();
    for face in 0..element.count {
        let at = r.record_start();
        let first = out.triangles.len();
        uvs.clear();
        for (i, p) in element.properties.iter().enumerate() {
            let Some(count_kind) = p.list.filter(|_| i == indices || Some(i) == texcoord) else {
                r.property(p)?;
                continue;
            };
            if Some(i) == texcoord {
                let n = r.list_len(count_kind)?;
                let mut values = Vec::with_capacity(n);
                for _ in 0..n {
                    values.push(r.scalar(p.kind)? as f32);
                }
                if n % 2 != 0 || values.iter().any(|v| !v.is_finite()) {
                    return Err(r.located(
                        at,
                        ErrorKind::Syntax {
                            expected: format!("finite u v pairs in the texcoord of face {face}"),
                            found: format!("{n} values"),
                        },
                    ));
                }
                // PLY's v grows upwards; TriMesh's grows downwards.
                uvs.extend(
                    values
                        .chunks_exact(2)
                        .map(|uv| Vec2::new(uv[0], 1.0 - uv[1])),
                );
                continue;
            }
            let n = index_list(r, p, count_kind, at, false, &mut polygon)?;
            if n < 3 {
                return Err(r.located(
                    at,
                    ErrorKind::Syntax {
                        expected: "a face with at least 3 vertices".into(),
                        found: format!("{n} vertices"),
                    },
                ));
            }
            let polygon: Vec<u32> = polygon.iter().flatten().copied().collect();
            for k in 1..n - 1 {
                out.triangles.push([polygon[0], polygon[k], polygon[k + 1]]);
            }
        }
        if texcoord.is_some() {
            let corners_in_face = out.triangles.len() - first + 2;
            if uvs.len() != corners_in_face {
                return Err(r.located(
                    at,
                    ErrorKind::Syntax {
                        expected: format!(
                            "one texcoord pair per corner of face {face} ({corners_in_face})"
                        ),
                        found: format!("{} pairs", uvs.len()),
                    },
                ));
            }
            for (k, t) in (first..out.triangles.len()).enumerate() {
                corners
                    .triangles
                    .push((t, [uvs[0], uvs[k + 1], uvs[k + 2]]));
            }
        }
    }
    Ok(())
}

/// Reads `element tristrips` (Stanford's scans, MeshLab): each record is
/// one list of vertex indices in OpenGL `GL_TRIANGLE_STRIP` order, `-1`
/// restarting the strip. Triangle `k` of a strip is `(s[k], s[k+1],
/// s[k+2])` for even `k` and `(s[k+1], s[k], s[k+2])` for odd `k`, so that
/// every triangle keeps the first one's winding (OpenGL 4.6 core
/// specification, Sec. 10.1.8); triangles with a repeated vertex (the
/// degenerate ones that join strips) are dropped.
fn read_strips(r: &mut DataReader<'_>, element: &Element, out: &mut PlyData) -> Result<()> {
    let Some(indices) = element
        .properties
        .iter()
        .position(|p| p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index"))
    else {
        if element.count > 0 {
            return Err(Error::new(
                r.c.path(),
                ErrorKind::Syntax {
                    expected: "a tristrips element with a vertex_indices list".into(),
                    found: format!("{} strips without one", element.count),
                },
            ));
        }
        return Ok(());
    };
    warn_unread(r, element, &[indices], out);
    let mut strip: Vec<Option<u32>> = Vec::new();
    for _ in 0..element.count {
        let at = r.record_start();
        for (i, p) in element.properties.iter().enumerate() {
            let Some(count_kind) = p.list.filter(|_| i == indices) else {
                r.property(p)?;
                continue;
            };
            index_list(r, p, count_kind, at, true, &mut strip)?;
            for run in strip.split(Option::is_none) {
                for k in 0..run.len().saturating_sub(2) {
                    let (a, b, c) = (
                        run[k].unwrap_or(0),
                        run[k + 1].unwrap_or(0),
                        run[k + 2].unwrap_or(0),
                    );
                    if a == b || b == c || a == c {
                        continue;
                    }
                    out.triangles
                        .push(if k % 2 == 0 { [a, b, c] } else { [b, a, c] });
                }
            }
        }
    }
    Ok(())
}

/// Writes `data` as a `.ply` file: `float` coordinates (`double` when
/// [`PlyData::origin`] is not zero, with the origin added back), then
/// normals `nx ny nz`, colours `red green blue alpha` (uchar), texture
/// coordinates `s t` (v up, as PLY tools expect), `uint face_id`, `uint id`, and the
/// extra scalars as `float`; faces as `list uchar int vertex_indices`.
///
/// # Errors
/// [`ErrorKind::InvalidInput`] for attribute arrays of the wrong length,
/// a scalar name PLY cannot hold, or triangles referencing missing
/// vertices; an I/O error.
pub fn write(path: impl AsRef<Path>, data: &PlyData, format: Format) -> Result<()> {
    let path = path.as_ref();
    let bytes = to_bytes(path, data, format)?;
    std::fs::write(path, bytes).map_err(|e| Error::io(path, e))
}

/// Appends one value in the format's encoding.
trait Encode: Copy + std::fmt::Display {
    fn le(self, out: &mut Vec<u8>);
    fn be(self, out: &mut Vec<u8>);
}

macro_rules! encode {
    ($($t:ty),*) => {$(
        impl Encode for $t {
            fn le(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
            fn be(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_be_bytes());
            }
        }
    )*};
}
encode!(u8, i32, u32, f32, f64);

/// Writes values in one of the three encodings.
struct Sink {
    out: Vec<u8>,
    format: Format,
    /// Whether the current ASCII line has a value yet.
    started: bool,
}

impl Sink {
    fn put<T: Encode>(&mut self, value: T) {
        match self.format {
            Format::Ascii => {
                if self.started {
                    self.out.push(b' ');
                }
                let _ = write!(AsciiOut(&mut self.out), "{value}");
                self.started = true;
            }
            Format::BinaryLittleEndian => value.le(&mut self.out),
            Format::BinaryBigEndian => value.be(&mut self.out),
        }
    }

    fn end_record(&mut self) {
        if self.format == Format::Ascii {
            self.out.push(b'\n');
            self.started = false;
        }
    }
}

/// `fmt::Write` into a byte vector.
struct AsciiOut<'a>(&'a mut Vec<u8>);

impl std::fmt::Write for AsciiOut<'_> {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0.extend_from_slice(s.as_bytes());
        Ok(())
    }
}

/// The `.ply` file as bytes; `path` names it in errors.
///
/// # Errors
/// As for [`write()`], without the I/O.
pub fn to_bytes(path: impl AsRef<Path>, data: &PlyData, format: Format) -> Result<Vec<u8>> {
    let path = path.as_ref();
    let n = data.positions.len();
    let invalid = |what: String| Error::new(path, ErrorKind::InvalidInput(what));
    let lengths = [
        ("normals", data.normals.as_ref().map(Vec::len)),
        ("colors", data.colors.as_ref().map(Vec::len)),
        ("uvs", data.uvs.as_ref().map(Vec::len)),
        ("face ids", data.face_ids.as_ref().map(Vec::len)),
        ("ids", data.ids.as_ref().map(Vec::len)),
    ];
    for (name, len) in lengths {
        if let Some(len) = len.filter(|&l| l != n) {
            return Err(invalid(format!("{len} {name} for {n} vertices")));
        }
    }
    let reserved = [
        "x", "y", "z", "nx", "ny", "nz", "red", "green", "blue", "alpha", "s", "t", "face_id", "id",
    ];
    for (name, column) in &data.scalars {
        if column.len() != n {
            return Err(invalid(format!(
                "scalar {name:?} has {} values for {n} vertices",
                column.len()
            )));
        }
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_graphic()) {
            return Err(invalid(format!(
                "scalar name {name:?} is not a PLY property name (printable ASCII, no spaces)"
            )));
        }
        if reserved.contains(&name.as_str()) {
            return Err(invalid(format!(
                "scalar name {name:?} is taken by a standard vertex property"
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
    if !data.origin.is_finite() {
        return Err(invalid(format!("origin {} is not finite", data.origin)));
    }
    let shifted = data.origin != DVec3::ZERO;

    let mut header = String::from("ply\n");
    header.push_str(match format {
        Format::Ascii => "format ascii 1.0\n",
        Format::BinaryLittleEndian => "format binary_little_endian 1.0\n",
        Format::BinaryBigEndian => "format binary_big_endian 1.0\n",
    });
    header.push_str("comment written by trilux-io\n");
    if let Some(texture) = &data.texture_file {
        if texture.trim().is_empty() || texture.trim() != texture || texture.contains(['\n', '\r'])
        {
            return Err(invalid(format!(
                "texture file {texture:?} cannot be written as a PLY comment (empty, a line \
                 break, or surrounding spaces)"
            )));
        }
        let _ = writeln!(header, "comment TextureFile {texture}");
    }
    let _ = writeln!(header, "element vertex {n}");
    let coordinate = if shifted { "double" } else { "float" };
    for axis in ["x", "y", "z"] {
        let _ = writeln!(header, "property {coordinate} {axis}");
    }
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
    if data.face_ids.is_some() {
        header.push_str("property uint face_id\n");
    }
    if data.ids.is_some() {
        header.push_str("property uint id\n");
    }
    for (name, _) in &data.scalars {
        let _ = writeln!(header, "property float {name}");
    }
    if !data.triangles.is_empty() {
        let _ = writeln!(header, "element face {}", data.triangles.len());
        header.push_str("property list uchar int vertex_indices\n");
    }
    header.push_str("end_header\n");

    let mut sink = Sink {
        out: header.into_bytes(),
        format,
        started: false,
    };
    for i in 0..n {
        let p = data.positions[i];
        if shifted {
            let q = data.origin + p.as_dvec3();
            [q.x, q.y, q.z].into_iter().for_each(|v| sink.put(v));
        } else {
            [p.x, p.y, p.z].into_iter().for_each(|v| sink.put(v));
        }
        if let Some(normals) = &data.normals {
            normals[i].to_array().into_iter().for_each(|v| sink.put(v));
        }
        if let Some(colors) = &data.colors {
            colors[i].into_iter().for_each(|v| sink.put(v));
        }
        if let Some(uvs) = &data.uvs {
            // Back to PLY's v-up convention (the reader's flip, undone).
            sink.put(uvs[i].x);
            sink.put(1.0 - uvs[i].y);
        }
        if let Some(ids) = &data.face_ids {
            sink.put(ids[i]);
        }
        if let Some(ids) = &data.ids {
            sink.put(ids[i]);
        }
        for (_, column) in &data.scalars {
            sink.put(column[i]);
        }
        sink.end_record();
    }
    for t in &data.triangles {
        sink.put(3u8);
        for &i in t {
            // `i < n`, and a vertex count beyond i32::MAX cannot be
            // written as PLY's `int` indices.
            let index = i32::try_from(i).map_err(|_| {
                invalid(format!(
                    "vertex index {i} does not fit the int vertex_indices of PLY"
                ))
            })?;
            sink.put(index);
        }
        sink.end_record();
    }
    Ok(sink.out)
}
