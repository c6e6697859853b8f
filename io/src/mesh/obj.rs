//! Wavefront OBJ: `v`, `vt`, `vn`, `f` (all four index forms, negative
//! indices, polygons fan-triangulated), `o`, `g`, `usemtl`, `mtllib` (with
//! `newmtl`, `Kd`, `map_Kd` and its options). Lines, points, smoothing
//! groups and free-form geometry are skipped.
//!
//! OBJ and MTL share one line pre-pass: a leading UTF-8 byte-order mark
//! is dropped, `\r\n` is a line end, a `#` starts a comment wherever it
//! is, and a `\` at the end of a line continues it. File names (`mtllib`,
//! `map_Kd`) are the rest of the line after the options, spaces included.
//! `vt` v coordinates are flipped to [`TriMesh`]'s v-down convention.
//!
//! Our own reader rather than `tobj`: errors must name the line, NaN and
//! infinite coordinates must be refused, and unused vertices must not
//! reach the samplers. A vertex is one distinct `v/vt/vn` triple, so UV
//! seams split vertices and unused `v` lines disappear.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use glam::{DVec3, Vec2, Vec3};

use super::{Material, Object, TriMesh, Wrap};
use crate::error::{Error, ErrorKind, Location, Result};
use crate::warning::Warning;

/// "No UV / no normal" in a vertex key.
const NONE: u32 = u32::MAX;

/// Kd of a material that no library defines (the MTL default).
const DEFAULT_DIFFUSE: [f32; 3] = [0.8, 0.8, 0.8];

/// Reads an `.obj` file and the material libraries it names (resolved
/// against its folder).
///
/// # Errors
/// [`Error`] with the file and line: a malformed number, a NaN or infinite
/// coordinate, a face with fewer than 3 vertices, a face index out of
/// range, or an unreadable file (a missing material library included).
pub fn read(path: impl AsRef<Path>) -> Result<TriMesh> {
    let path = path.as_ref();
    let data = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let parsed = parse(&data, path)?;
    let mut mesh = parsed.mesh;
    let folder = path.parent().unwrap_or(Path::new("."));
    let mut transforms: Vec<Option<UvTransform>> = vec![None; mesh.materials.len()];
    let mut defined = vec![false; mesh.materials.len()];
    for (line, names) in parsed.libraries {
        for library in library_files(folder, &names) {
            let lib_path = folder.join(&library);
            // A missing or unreadable library leaves the geometry intact:
            // the materials keep the MTL defaults, and the user is told.
            let text = match std::fs::read(&lib_path) {
                Ok(text) => text,
                Err(e) => {
                    mesh.warnings.push(Warning::new(
                        path,
                        Some(Location::Line(line)),
                        format!(
                            "material library {} could not be read ({e}); its materials keep \
                             the MTL defaults (Kd 0.8, no texture)",
                            lib_path.display()
                        ),
                    ));
                    continue;
                }
            };
            let library = parse_mtl(&text, &lib_path, folder)?;
            mesh.warnings.extend(library.warnings);
            for (found, transform) in library.materials {
                if let Some(i) = mesh.materials.iter().position(|m| m.name == found.name) {
                    mesh.materials[i] = found;
                    transforms.resize(mesh.materials.len(), None);
                    transforms[i] = transform;
                    defined[i] = true;
                }
            }
        }
    }
    for ((material, defined), line) in mesh
        .materials
        .iter()
        .zip(&defined)
        .zip(&parsed.usemtl_lines)
    {
        if !defined {
            mesh.warnings.push(Warning::new(
                path,
                Some(Location::Line(*line)),
                format!(
                    "usemtl {:?} names a material no material library defines; its triangles \
                     keep the MTL defaults (Kd 0.8, no texture)",
                    material.name
                ),
            ));
        }
    }
    check_textures(&mut mesh);
    apply_uv_transforms(&mut mesh, &transforms);
    Ok(mesh)
}

/// Warns about each `map_Kd` texture file that does not exist: the mesh
/// and its colours are intact without it. The path is kept (it is what
/// the library names), so that a caller decoding it names the file too.
fn check_textures(mesh: &mut TriMesh) {
    for material in &mesh.materials {
        let Some(file) = &material.diffuse_texture else {
            continue;
        };
        if !file.is_file() {
            mesh.warnings.push(Warning::new(
                file,
                None,
                format!(
                    "the texture of material {:?} does not exist; the mesh is read, the \
                     material has its Kd colour only",
                    material.name
                ),
            ));
        }
    }
}

/// A `map_Kd` `-s` and `-o` (u and v; w only matters to 3D textures): the
/// texture is looked up at `uv * scale + offset` in OBJ's v-up UVs.
#[derive(Debug, Clone, Copy, PartialEq)]
struct UvTransform {
    scale: Vec2,
    offset: Vec2,
}

impl UvTransform {
    /// Applies it to a UV in TriMesh's v-down convention.
    fn apply(self, uv: Vec2) -> Vec2 {
        let up = Vec2::new(uv.x, 1.0 - uv.y);
        let t = up * self.scale + self.offset;
        Vec2::new(t.x, 1.0 - t.y)
    }
}

/// Applies each material's texture transform to the UVs of its triangles,
/// so that `uvs` index the texture directly. A vertex shared by triangles
/// whose materials transform differently is split first.
fn apply_uv_transforms(mesh: &mut TriMesh, transforms: &[Option<UvTransform>]) {
    if transforms.iter().all(Option::is_none) || mesh.uvs.is_none() {
        return;
    }
    // The transform group of each vertex: the material index whose
    // transform it takes, or usize::MAX for none.
    const PLAIN: usize = usize::MAX;
    let mut owner: Vec<Option<usize>> = vec![None; mesh.positions.len()];
    let mut copies: HashMap<(u32, usize), u32> = HashMap::new();
    for object in mesh.objects.clone() {
        let group = object
            .material
            .filter(|&m| transforms.get(m).copied().flatten().is_some())
            .unwrap_or(PLAIN);
        for t in object.triangles.clone() {
            for corner in 0..3 {
                let v = mesh.indices[t][corner];
                match owner[v as usize] {
                    None => owner[v as usize] = Some(group),
                    Some(g) if g == group => {}
                    Some(_) => {
                        let copy = *copies.entry((v, group)).or_insert_with(|| {
                            let i = v as usize;
                            mesh.positions.push(mesh.positions[i]);
                            if let Some(uvs) = mesh.uvs.as_mut() {
                                uvs.push(uvs[i]);
                            }
                            if let Some(normals) = mesh.normals.as_mut() {
                                normals.push(normals[i]);
                            }
                            owner.push(Some(group));
                            (mesh.positions.len() - 1) as u32
                        });
                        mesh.indices[t][corner] = copy;
                    }
                }
            }
        }
    }
    if let Some(uvs) = mesh.uvs.as_mut() {
        for (uv, group) in uvs.iter_mut().zip(&owner) {
            if let Some(transform) = group.and_then(|g| transforms.get(g).copied().flatten()) {
                *uv = transform.apply(*uv);
            }
        }
    }
}

/// The files an `mtllib` line names: the whole rest of the line when a
/// file of that name exists (names with spaces), else its
/// whitespace-separated words (the statement's list form). When none of
/// the words exists either, the whole name, so that the error names what
/// the line says.
fn library_files(folder: &Path, names: &str) -> Vec<String> {
    let words: Vec<String> = names.split_whitespace().map(str::to_string).collect();
    if words.len() <= 1
        || folder.join(names).is_file()
        || !words.iter().any(|w| folder.join(w).is_file())
    {
        return vec![names.to_string()];
    }
    words
}

/// Parses the contents of an `.obj` file; `path` names it in errors.
/// Material libraries are not opened: materials carry only their names
/// (and the MTL defaults).
///
/// # Errors
/// As for [`read`], without the files.
///
/// # Example
/// ```
/// // A quad is split into two triangles; `v` is flipped to glTF's convention.
/// let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
/// let mesh = trilux_io::mesh::obj::from_bytes(obj, "quad.obj")?;
/// assert_eq!(mesh.indices.len(), 2);
/// assert_eq!(mesh.uvs.as_ref().map(|uv| uv[0].y), Some(1.0));
/// // A face that names a missing vertex is an error at its line.
/// let e = trilux_io::mesh::obj::from_bytes(b"v 0 0 0\nf 1 2 3\n", "bad.obj").unwrap_err();
/// assert!(e.to_string().starts_with("bad.obj: line 2: "), "{e}");
/// # Ok::<(), trilux_io::Error>(())
/// ```
pub fn from_bytes(data: &[u8], path: impl AsRef<Path>) -> Result<TriMesh> {
    parse(data, path.as_ref()).map(|parsed| parsed.mesh)
}

/// What [`parse`] finds in an OBJ file besides the mesh.
struct Parsed {
    mesh: TriMesh,
    /// Each `mtllib` line: its number and the rest of the line.
    libraries: Vec<(usize, String)>,
    /// The line of the first `usemtl` of each material, in the order of
    /// [`TriMesh::materials`].
    usemtl_lines: Vec<usize>,
}

/// One line's location for errors.
struct At<'a> {
    path: &'a Path,
    line: usize,
}

impl At<'_> {
    fn error(&self, kind: ErrorKind) -> Error {
        Error {
            path: self.path.to_path_buf(),
            location: Some(Location::Line(self.line)),
            kind,
        }
    }

    fn syntax(&self, expected: &str, found: &str) -> Error {
        self.error(ErrorKind::Syntax {
            expected: expected.to_string(),
            found: found.chars().take(40).collect(),
        })
    }
}

/// The line pre-pass shared by OBJ and MTL: splits the data into logical
/// lines with the 1-based number of their first physical line. Drops a
/// leading UTF-8 byte-order mark, `\r` before `\n`, and comments (from a
/// `#` wherever it starts to the end of the line); joins lines ending in
/// `\`; trims surrounding whitespace. Empty lines are skipped.
pub(crate) fn lines(data: &[u8]) -> impl Iterator<Item = (usize, String)> + '_ {
    let data = data.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(data);
    let mut number = 0;
    let mut pending: Option<(usize, String)> = None;
    let mut raw = data.split(|&b| b == b'\n');
    std::iter::from_fn(move || {
        loop {
            let Some(bytes) = raw.next() else {
                return pending.take().filter(|(_, text)| !text.trim().is_empty());
            };
            number += 1;
            let bytes = match bytes.iter().position(|&b| b == b'#') {
                Some(hash) => &bytes[..hash],
                None => bytes,
            };
            let text = String::from_utf8_lossy(bytes);
            let text = text.trim_end();
            let (first, mut joined) = pending.take().unwrap_or((number, String::new()));
            if let Some(head) = text.strip_suffix('\\') {
                joined.push_str(head);
                joined.push(' ');
                pending = Some((first, joined));
                continue;
            }
            joined.push_str(text);
            // Trimmed in place: one allocation per line.
            let start = joined.len() - joined.trim_start().len();
            joined.drain(..start);
            if joined.is_empty() {
                continue;
            }
            return Some((first, joined));
        }
    })
}

/// The rest of `line` after its first word, trimmed: a name that may
/// contain spaces.
fn rest_of(line: &str) -> &str {
    let line = line.trim_start();
    let end = line.find(char::is_whitespace).unwrap_or(line.len());
    line[end..].trim()
}

fn number64(at: &At<'_>, token: Option<&str>, what: &str) -> Result<f64> {
    let token = token.ok_or_else(|| at.error(ErrorKind::Truncated(what.to_string())))?;
    token.parse::<f64>().map_err(|_| at.syntax(what, token))
}

fn number(at: &At<'_>, token: Option<&str>, what: &str) -> Result<f32> {
    let token = token.ok_or_else(|| at.error(ErrorKind::Truncated(what.to_string())))?;
    token.parse::<f32>().map_err(|_| at.syntax(what, token))
}

fn vec3(at: &At<'_>, tokens: &mut std::str::SplitWhitespace<'_>, what: &str) -> Result<Vec3> {
    let v = Vec3::new(
        number(at, tokens.next(), what)?,
        number(at, tokens.next(), what)?,
        number(at, tokens.next(), what)?,
    );
    Ok(v)
}

/// What a face corner's index refers to, for errors in the file's words.
#[derive(Clone, Copy)]
struct Indexed {
    what: &'static str,
    records: &'static str,
}

const VERTEX: Indexed = Indexed {
    what: "vertex",
    records: "`v` lines",
};
const TEXCOORD: Indexed = Indexed {
    what: "texture coordinate",
    records: "`vt` lines",
};
const NORMAL: Indexed = Indexed {
    what: "normal",
    records: "`vn` lines",
};

/// A 1-based or negative (relative) OBJ index into a list of `len`.
fn resolve(at: &At<'_>, token: &str, len: usize, indexed: Indexed, face: usize) -> Result<u32> {
    let raw: i64 = token
        .parse()
        .map_err(|_| at.syntax(&format!("a {} index", indexed.what), token))?;
    let index = if raw > 0 { raw - 1 } else { len as i64 + raw };
    if raw == 0 || index < 0 || index >= len as i64 {
        return Err(at.error(ErrorKind::ReferenceOutOfRange(Box::new(
            crate::error::Reference {
                what: indexed.what,
                reference: raw,
                element: "face",
                index: face,
                count: len,
                records: indexed.records,
            },
        ))));
    }
    Ok(index as u32)
}

/// A corner's optional texture-coordinate or normal index: `NONE` when
/// absent, or when the file has no lines of that kind at all (the index
/// dangles; `dropped` counts it, and the caller warns once).
fn optional_index(
    at: &At<'_>,
    token: Option<&str>,
    len: usize,
    indexed: Indexed,
    face: usize,
    dropped: &mut (usize, usize),
) -> Result<u32> {
    match token {
        None | Some("") => Ok(NONE),
        Some(_) if len == 0 => {
            if dropped.0 == 0 {
                dropped.1 = at.line;
            }
            dropped.0 += 1;
            Ok(NONE)
        }
        Some(t) => resolve(at, t, len, indexed, face),
    }
}

/// The mesh, the rest of each `mtllib` line and where each material is
/// first used.
fn parse(data: &[u8], path: &Path) -> Result<Parsed> {
    let mut v: Vec<DVec3> = Vec::new();
    let mut vt: Vec<Vec2> = Vec::new();
    let mut vn: Vec<Vec3> = Vec::new();
    let mut keys: HashMap<(u32, u32, u32), u32> = HashMap::new();
    let mut vertices: Vec<(u32, u32, u32)> = Vec::new();
    let mut indices: Vec<[u32; 3]> = Vec::new();
    let mut objects: Vec<Object> = Vec::new();
    let mut materials: Vec<Material> = Vec::new();
    let mut libraries = Vec::new();
    let mut usemtl_lines = Vec::new();
    // Corner UV and normal indices dropped because the file has no `vt`
    // (`vn`) lines at all, and the first line with one.
    let mut dropped_uv = (0usize, 0usize);
    let mut dropped_normal = (0usize, 0usize);
    let mut faces = 0usize;
    let mut name = String::new();
    let mut object_name = String::new();
    let mut material: Option<usize> = None;
    let mut polygon: Vec<u32> = Vec::new();

    // Closes the current run of triangles into an object range.
    let close = |objects: &mut Vec<Object>, name: &str, material, end: usize| {
        let start = objects.last().map_or(0, |o: &Object| o.triangles.end);
        if end > start {
            objects.push(Object {
                name: name.to_string(),
                triangles: start..end,
                material,
            });
        }
    };

    for (line, text) in lines(data) {
        let at = At { path, line };
        let mut tokens = text.split_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        match keyword {
            "v" => {
                // f64, so that far-from-origin files keep their precision
                // until the shift (TriMesh::origin) is known.
                let mut p = [0.0f64; 3];
                for slot in &mut p {
                    *slot = number64(&at, tokens.next(), "a vertex coordinate")?;
                }
                if let Some(value) = p.into_iter().find(|x| !x.is_finite()) {
                    return Err(at.error(ErrorKind::NonFinite {
                        index: v.len(),
                        value,
                    }));
                }
                v.push(DVec3::from(p));
            }
            "vt" => {
                let u = number(&at, tokens.next(), "a texture coordinate")?;
                let w = match tokens.next() {
                    Some(t) => t
                        .parse::<f32>()
                        .map_err(|_| at.syntax("a texture coordinate", t))?,
                    None => 0.0,
                };
                if !(u.is_finite() && w.is_finite()) {
                    return Err(at.syntax("a finite texture coordinate", &text));
                }
                // OBJ's v grows upwards; TriMesh's grows downwards (glTF).
                vt.push(Vec2::new(u, 1.0 - w));
            }
            "vn" => {
                let n = vec3(&at, &mut tokens, "a normal coordinate")?;
                if !n.is_finite() {
                    return Err(at.syntax("a finite normal", &text));
                }
                vn.push(n);
            }
            "f" => {
                polygon.clear();
                for corner in tokens {
                    let mut parts = corner.split('/');
                    let pv = resolve(&at, parts.next().unwrap_or(""), v.len(), VERTEX, faces)?;
                    let (t, n) = (parts.next(), parts.next());
                    let pt = optional_index(&at, t, vt.len(), TEXCOORD, faces, &mut dropped_uv)?;
                    let pn = optional_index(&at, n, vn.len(), NORMAL, faces, &mut dropped_normal)?;
                    let key = (pv, pt, pn);
                    let next = vertices.len() as u32;
                    let id = *keys.entry(key).or_insert_with(|| {
                        vertices.push(key);
                        next
                    });
                    polygon.push(id);
                }
                if polygon.len() < 3 {
                    return Err(at.syntax("a face with at least 3 vertices", &text));
                }
                for k in 1..polygon.len() - 1 {
                    indices.push([polygon[0], polygon[k], polygon[k + 1]]);
                }
                faces += 1;
            }
            "o" | "g" => {
                close(&mut objects, &name, material, indices.len());
                let given = tokens.collect::<Vec<_>>().join(" ");
                // A bare `g` returns to the default group: its triangles
                // stay in the current `o` object, under its name.
                name = match keyword {
                    "g" if given.is_empty() => object_name.clone(),
                    _ => given,
                };
                if keyword == "o" {
                    object_name = name.clone();
                }
            }
            "usemtl" => {
                close(&mut objects, &name, material, indices.len());
                let wanted = rest_of(&text).to_string();
                material = Some(match materials.iter().position(|m| m.name == wanted) {
                    Some(i) => i,
                    None => {
                        materials.push(Material {
                            name: wanted,
                            diffuse: DEFAULT_DIFFUSE,
                            diffuse_texture: None,
                            diffuse_image: None,
                            wrap: [Wrap::Repeat; 2],
                            scalar_images: Vec::new(),
                        });
                        usemtl_lines.push(line);
                        materials.len() - 1
                    }
                });
            }
            "mtllib" => {
                let names = rest_of(&text);
                if names.is_empty() {
                    return Err(at.error(ErrorKind::Truncated(
                        "a material library file name after mtllib".into(),
                    )));
                }
                libraries.push((line, names.to_string()));
            }
            // Smoothing groups, lines, points, free-form geometry: skipped.
            "s" | "l" | "p" | "vp" | "cstype" | "deg" | "curv" | "curv2" | "surf" | "parm"
            | "trim" | "hole" | "end" | "bmat" | "step" | "con" | "mg" | "lod" | "shadow_obj"
            | "trace_obj" | "ctech" | "stech" | "bevel" | "c_interp" | "d_interp" => {}
            other => return Err(at.syntax("an OBJ keyword", other)),
        }
    }
    close(&mut objects, &name, material, indices.len());

    let has_uv = vertices.iter().any(|k| k.1 != NONE);
    let has_normal = vertices.iter().any(|k| k.2 != NONE);
    let used: Vec<DVec3> = vertices.iter().map(|k| v[k.0 as usize]).collect();
    let (origin, positions) = super::recenter(&used);
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::new(
            path,
            ErrorKind::OutOfRange(format!(
                "vertex {} at {} is too far from the others for f32 positions",
                vertices[i].0 + 1,
                used[i]
            )),
        ));
    }
    let mut warnings = Vec::new();
    for ((count, line), what, records) in [
        (dropped_uv, "texture-coordinate", "`vt`"),
        (dropped_normal, "normal", "`vn`"),
    ] {
        if count > 0 {
            warnings.push(Warning::new(
                path,
                Some(Location::Line(line)),
                format!(
                    "{count} face corners name a {what} index, but the file has no {records} \
                     lines; those indices were dropped (the geometry is read)"
                ),
            ));
        }
    }
    let mesh = TriMesh {
        positions,
        origin,
        warnings,
        uvs1: None,
        uvs: has_uv.then(|| {
            vertices
                .iter()
                .map(|k| vt.get(k.1 as usize).copied().unwrap_or(Vec2::ZERO))
                .collect()
        }),
        normals: has_normal.then(|| {
            vertices
                .iter()
                .map(|k| vn.get(k.2 as usize).copied().unwrap_or(Vec3::ZERO))
                .collect()
        }),
        indices,
        objects,
        materials,
    };
    Ok(Parsed {
        mesh,
        libraries,
        usemtl_lines,
    })
}

/// The materials of one MTL library and what it skipped.
struct MtlLibrary {
    materials: Vec<(Material, Option<UvTransform>)>,
    warnings: Vec<Warning>,
}

/// MTL statements that do not change what a diffuse lookup reads (the
/// other colours, exponents, transparency, illumination model, the other
/// maps): known, so not counted as unknown.
const MTL_IGNORED: &[&str] = &[
    "ka",
    "ks",
    "ke",
    "kt",
    "ns",
    "ni",
    "d",
    "tr",
    "tf",
    "illum",
    "sharpness",
    "map_ka",
    "map_ks",
    "map_ke",
    "map_ns",
    "map_d",
    "map_tr",
    "map_bump",
    "bump",
    "map_disp",
    "disp",
    "decal",
    "refl",
    "norm",
    "map_norm",
    "pr",
    "pm",
    "ps",
    "pc",
    "pcr",
    "aniso",
    "anisor",
    "map_pr",
    "map_pm",
    "map_ps",
    "map_refl",
    "map_aat",
];

/// Parses an MTL library: `newmtl`, `Kd`, `map_Kd` (options parsed, the
/// rest of the line is the file, spaces included). Keywords are compared
/// ignoring ASCII case, as exporters write `map_kd`, `Map_Kd` or `KD` and
/// every common reader accepts them. `-clamp on` makes the
/// texture [`Wrap::ClampToEdge`]; `-s` and `-o` come back as the
/// material's UV transform (applied to the UVs by [`read`]); the other
/// options (`-bm`, `-blendu`, `-blendv`, `-boost`, `-cc`, `-imfchan`,
/// `-mm`, `-t`, `-texres`, `-type`) do not change which texel a diffuse
/// lookup reads and are skipped. Statements that are neither read nor in
/// the MTL specification's list are counted in one warning.
fn parse_mtl(data: &[u8], path: &Path, folder: &Path) -> Result<MtlLibrary> {
    let mut materials: Vec<(Material, Option<UvTransform>)> = Vec::new();
    // Unknown statements: how many, the first line and its keyword.
    let mut unknown: Option<(usize, usize, String)> = None;
    for (line, text) in lines(data) {
        let at = At { path, line };
        let mut tokens = text.split_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        match keyword.to_ascii_lowercase().as_str() {
            "newmtl" => materials.push((
                Material {
                    name: rest_of(&text).to_string(),
                    diffuse: DEFAULT_DIFFUSE,
                    diffuse_texture: None,
                    diffuse_image: None,
                    wrap: [Wrap::Repeat; 2],
                    scalar_images: Vec::new(),
                },
                None,
            )),
            "kd" => {
                let kd = vec3(&at, &mut tokens, "a diffuse colour")?;
                let (current, _) = materials
                    .last_mut()
                    .ok_or_else(|| at.syntax("newmtl before Kd", &text))?;
                current.diffuse = kd.to_array();
            }
            "map_kd" => {
                let map = texture_map(&at, rest_of(&text))?;
                let (current, transform) = materials
                    .last_mut()
                    .ok_or_else(|| at.syntax("newmtl before map_Kd", &text))?;
                current.diffuse_texture = Some(folder.join(map.file));
                if map.clamp {
                    current.wrap = [Wrap::ClampToEdge; 2];
                }
                *transform = map.transform;
            }
            known if MTL_IGNORED.contains(&known) => {}
            _ => match &mut unknown {
                Some((count, _, _)) => *count += 1,
                None => unknown = Some((1, line, keyword.chars().take(40).collect())),
            },
        }
    }
    let warnings = unknown
        .map(|(count, line, first)| {
            Warning::new(
                path,
                Some(Location::Line(line)),
                format!(
                    "{count} statement(s) of unknown kind skipped, the first `{first}` (MTL \
                     keywords are compared ignoring case)"
                ),
            )
        })
        .into_iter()
        .collect();
    Ok(MtlLibrary {
        materials,
        warnings,
    })
}

/// A `map_*` statement: the file and the options that matter.
#[derive(Debug, PartialEq)]
struct TextureMap<'a> {
    file: &'a str,
    clamp: bool,
    /// `-s` and `-o`, when either is not the identity.
    transform: Option<UvTransform>,
}

/// Parses `[options] file name` of a `map_*` statement (MTL spec, "Texture
/// map statements"): each option takes a fixed number of arguments, `-o`,
/// `-s` and `-t` one to three numbers.
fn texture_map<'a>(at: &At<'_>, mut rest: &'a str) -> Result<TextureMap<'a>> {
    let mut clamp = false;
    let mut transform = UvTransform {
        scale: Vec2::ONE,
        offset: Vec2::ZERO,
    };
    // The next word of `rest` and what follows it.
    fn word(rest: &str) -> (&str, &str) {
        let rest = rest.trim_start();
        let end = rest.find(char::is_whitespace).unwrap_or(rest.len());
        (&rest[..end], &rest[end..])
    }
    loop {
        let (option, after) = word(rest);
        if !option.starts_with('-') || option.len() < 2 {
            break;
        }
        let mut args = |min: usize, max: usize, numeric: bool| -> Result<Vec<&'a str>> {
            let mut taken = Vec::new();
            let mut tail = after;
            while taken.len() < max {
                let (w, next) = word(tail);
                let is_number = w.parse::<f64>().is_ok();
                if w.is_empty() || (numeric && !is_number) || (taken.len() >= min && !is_number) {
                    break;
                }
                taken.push(w);
                tail = next;
            }
            if taken.len() < min {
                return Err(at.syntax(&format!("{min} argument(s) after {option}"), after.trim()));
            }
            rest = tail;
            Ok(taken)
        };
        match option {
            "-blendu" | "-blendv" | "-cc" | "-imfchan" | "-type" => {
                args(1, 1, false)?;
            }
            "-clamp" => {
                clamp = args(1, 1, false)?[0].eq_ignore_ascii_case("on");
            }
            "-bm" | "-boost" | "-texres" => {
                args(1, 1, true)?;
            }
            "-mm" => {
                args(2, 2, true)?;
            }
            "-t" => {
                args(1, 3, true)?;
            }
            "-o" | "-s" => {
                let values = args(1, 3, true)?;
                let default = if option == "-o" { 0.0 } else { 1.0 };
                // Missing components take the spec's defaults (0 for -o,
                // 1 for -s).
                let number = |k: usize| {
                    values
                        .get(k)
                        .and_then(|v| v.parse::<f32>().ok())
                        .unwrap_or(default)
                };
                let pair = Vec2::new(number(0), number(1));
                if !pair.is_finite() {
                    return Err(at.syntax(&format!("finite numbers after {option}"), after.trim()));
                }
                if option == "-o" {
                    transform.offset = pair;
                } else {
                    transform.scale = pair;
                }
            }
            other => {
                return Err(at.syntax(
                    "a texture map option (-blendu, -bm, -clamp, -o, -s, ...)",
                    other,
                ));
            }
        }
    }
    let file = rest.trim();
    if file.is_empty() {
        return Err(at.error(ErrorKind::Truncated("a texture file name".into())));
    }
    let identity = transform.scale == Vec2::ONE && transform.offset == Vec2::ZERO;
    Ok(TextureMap {
        file,
        clamp,
        transform: (!identity).then_some(transform),
    })
}

/// Writes an `.obj` file: positions (plus [`TriMesh::origin`], in `f64`),
/// UVs (flipped back to OBJ's v up) and normals when present, one `o` line
/// per object, faces in the matching `v/vt/vn` form. Floats are written in
/// shortest round-trip form.
///
/// When the mesh has materials, their library is written beside it
/// (`name.obj` → `name.mtl`, named by `mtllib`) with `Kd` and `map_Kd`,
/// and each object with a material gets its `usemtl`. A texture file is
/// referenced where it is (relative to the OBJ's folder when inside it); a
/// decoded texture without a file (glTF's embedded images) is written as
/// `name_<material>.png` beside the OBJ. MTL holds one wrap mode for both
/// axes: `-clamp on` when both are [`Wrap::ClampToEdge`], repeat otherwise
/// (MTL has no mirrored repeat). Materials without a name are written as
/// `material_<index>`.
///
/// # Errors
/// [`ErrorKind::InvalidInput`] for an index out of range, attribute
/// arrays of the wrong length, objects that do not cover the triangles in
/// order, a material index out of range, or a name that a `#` or a line
/// break would cut; an I/O error.
pub fn write(path: impl AsRef<Path>, mesh: &TriMesh) -> Result<()> {
    let path = path.as_ref();
    mesh.check_layout(path)?;
    for o in &mesh.objects {
        check_name(path, "object", &o.name)?;
    }
    let names = material_names(path, mesh)?;
    let mut out = String::with_capacity(40 * mesh.positions.len() + 30 * mesh.indices.len());
    out.push_str("# written by trilux-io\n");
    if !mesh.materials.is_empty() {
        let library = path.with_extension("mtl");
        write_mtl(path, &library, mesh, &names)?;
        let file = library
            .file_name()
            .map(|f| f.to_string_lossy().into_owned());
        let _ = writeln!(out, "mtllib {}", file.unwrap_or_default());
    }
    let shifted = mesh.origin != DVec3::ZERO;
    for p in &mesh.positions {
        if shifted {
            let q = mesh.origin + p.as_dvec3();
            let _ = writeln!(out, "v {} {} {}", q.x, q.y, q.z);
        } else {
            let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
        }
    }
    for t in mesh.uvs.iter().flatten() {
        // Back to OBJ's v-up convention (the reader's flip, undone).
        let _ = writeln!(out, "vt {} {}", t.x, 1.0 - t.y);
    }
    for q in mesh.normals.iter().flatten() {
        let _ = writeln!(out, "vn {} {} {}", q.x, q.y, q.z);
    }
    let corner = |out: &mut String, i: u32| {
        let i = i + 1;
        let _ = match (mesh.uvs.is_some(), mesh.normals.is_some()) {
            (false, false) => write!(out, " {i}"),
            (true, false) => write!(out, " {i}/{i}"),
            (false, true) => write!(out, " {i}//{i}"),
            (true, true) => write!(out, " {i}/{i}/{i}"),
        };
    };
    for object in mesh.objects_or_whole().iter() {
        if !object.name.is_empty() {
            let _ = writeln!(out, "o {}", object.name);
        }
        if let Some(m) = object.material {
            let _ = writeln!(out, "usemtl {}", names[m]);
        }
        for tri in &mesh.indices[object.triangles.clone()] {
            out.push('f');
            for &i in tri {
                corner(&mut out, i);
            }
            out.push('\n');
        }
    }
    std::fs::write(path, out).map_err(|e| Error::io(path, e))
}

/// Refuses a name that the OBJ/MTL line pre-pass would cut (`#` starts a
/// comment, a line break ends the statement).
fn check_name(path: &Path, what: &str, name: &str) -> Result<()> {
    if name.contains(['#', '\n', '\r']) || name.ends_with('\\') {
        return Err(Error::new(
            path,
            ErrorKind::InvalidInput(format!(
                "{what} name {name:?} cannot be written to OBJ (a '#', a line break or a \
                 trailing backslash would cut it)"
            )),
        ));
    }
    Ok(())
}

/// The name each material is written under: its own, or
/// `material_<index>` when empty or taken by an earlier one.
fn material_names(path: &Path, mesh: &TriMesh) -> Result<Vec<String>> {
    let mut names: Vec<String> = Vec::with_capacity(mesh.materials.len());
    for (i, m) in mesh.materials.iter().enumerate() {
        check_name(path, "material", &m.name)?;
        let name = m.name.trim();
        let name = if name.is_empty() || names.iter().any(|n| n == name) {
            format!("material_{i}")
        } else {
            name.to_string()
        };
        names.push(name);
    }
    Ok(names)
}

/// Writes the material library of `mesh` to `library`, and the decoded
/// textures that have no file beside `obj`.
fn write_mtl(obj: &Path, library: &Path, mesh: &TriMesh, names: &[String]) -> Result<()> {
    let folder = obj.parent().unwrap_or(Path::new(""));
    let stem = obj
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut text = String::from("# written by trilux-io\n");
    for (i, m) in mesh.materials.iter().enumerate() {
        let [r, g, b] = m.diffuse;
        let _ = writeln!(text, "newmtl {}\nKd {r} {g} {b}", names[i]);
        let texture = match (&m.diffuse_texture, &m.diffuse_image) {
            (Some(file), _) => Some(reference(folder, file)),
            (None, Some(image)) => {
                let name = format!("{stem}_{i}.png");
                crate::image::write_png(folder.join(&name), image, crate::image::PngDepth::Eight)?;
                Some(name)
            }
            (None, None) => None,
        };
        if let Some(texture) = texture {
            check_name(library, "texture file", &texture)?;
            let clamp = if m.wrap == [Wrap::ClampToEdge; 2] {
                "-clamp on "
            } else {
                ""
            };
            let _ = writeln!(text, "map_Kd {clamp}{texture}");
        }
    }
    std::fs::write(library, text).map_err(|e| Error::io(library, e))
}

/// How an MTL beside `folder` names `file`: relative when inside the
/// folder, else absolute.
fn reference(folder: &Path, file: &Path) -> String {
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (folder_abs, file_abs) = (absolute(folder), absolute(file));
    match file_abs.strip_prefix(&folder_abs) {
        Ok(relative) => relative.to_string_lossy().into_owned(),
        Err(_) => file_abs.to_string_lossy().into_owned(),
    }
}
