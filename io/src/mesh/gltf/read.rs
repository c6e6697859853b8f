//! Reading glTF: the triangles (and points) of the default scene.

use std::path::{Component, Path, PathBuf};

use glam::{DVec3, Mat3, Mat4, Vec2, Vec3};
use gltf::accessor::sparse::IndexType;
use gltf::accessor::{Accessor, DataType, Dimensions};
use gltf::mesh::Mode;
use gltf::texture::WrappingMode;

use super::{Attribute, AttributeValues, Points, Scene, VertexData};
use crate::error::{Error, ErrorKind, Result};
use crate::image::{self, ReadOptions};
use crate::mesh::{Material, Object, TriMesh, Wrap};
use crate::warning::Warning;

/// How to read a glTF file.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Options {
    /// Let buffer and image URIs name files outside the glTF's folder
    /// (absolute paths or `..`). Off by default: a downloaded asset should
    /// not be able to read arbitrary files.
    pub allow_outside_folder: bool,
}

/// Reads a `.gltf` or `.glb` file with the default [`Options`].
///
/// # Errors
/// [`Error`]: an unreadable or invalid file, a URI outside the folder, a
/// buffer shorter than its accessors, a non-finite position, an index out
/// of range, or a texture that does not decode.
pub fn read(path: impl AsRef<Path>) -> Result<TriMesh> {
    let path = path.as_ref();
    read_with(path, Options::default())
}

/// Reads a `.gltf` or `.glb` file.
///
/// # Errors
/// As for [`read`].
pub fn read_with(path: impl AsRef<Path>, options: Options) -> Result<TriMesh> {
    let path = path.as_ref();
    Ok(read_scene_with(path, options)?.into_mesh(path))
}

/// Reads everything [`read`] does and what a [`TriMesh`] has no place
/// for: vertex colours and `_NAME` attributes of the triangles, and the
/// `POINTS` primitives (see [`Scene`]).
///
/// # Errors
/// As for [`read`].
pub fn read_scene(path: impl AsRef<Path>) -> Result<Scene> {
    read_scene_with(path, Options::default())
}

/// As [`read_scene`], with [`Options`].
///
/// # Errors
/// As for [`read`].
pub fn read_scene_with(path: impl AsRef<Path>, options: Options) -> Result<Scene> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    scene_from_bytes(&bytes, path, options)
}

/// Parses glTF JSON or GLB bytes; external URIs resolve against the
/// folder of `path`, which also names the data in errors.
///
/// # Errors
/// As for [`read`].
pub fn from_bytes(bytes: &[u8], path: impl AsRef<Path>, options: Options) -> Result<TriMesh> {
    let path = path.as_ref();
    Ok(scene_from_bytes(bytes, path, options)?.into_mesh(path))
}

/// Parses glTF JSON or GLB bytes into a [`Scene`], as [`from_bytes`].
///
/// # Errors
/// As for [`read`].
pub fn scene_from_bytes(bytes: &[u8], path: impl AsRef<Path>, options: Options) -> Result<Scene> {
    let path = path.as_ref();
    let folder = path.parent().unwrap_or(Path::new("."));
    Reader {
        path,
        folder,
        options,
    }
    .read(bytes)
}

/// The extensions a file may require: what they change is decoded.
const HONOURED_EXTENSIONS: &[&str] = &["KHR_mesh_quantization", "KHR_texture_transform"];

/// The most values (components) one accessor may decode to: 2^27, 1 GiB
/// as the `f64` the decoder works in. An accessor backed by a buffer view
/// is also bounded by its buffer.
pub const MAX_ACCESSOR_VALUES: u64 = 1 << 27;

/// The most elements an accessor without a buffer view (zeros, plus its
/// sparse values) may declare: 2^24. Nothing in the file bounds its count,
/// so a few bytes of JSON could otherwise ask for gigabytes.
pub const MAX_ZERO_FILLED_ELEMENTS: u64 = 1 << 24;

struct Reader<'a> {
    path: &'a Path,
    folder: &'a Path,
    options: Options,
}

/// Where a URI's bytes come from.
enum Resolved {
    Data(Vec<u8>),
    File(PathBuf),
}

impl Reader<'_> {
    fn error(&self, kind: ErrorKind) -> Error {
        Error::new(self.path, kind)
    }

    fn invalid(&self, what: String) -> Error {
        self.error(ErrorKind::Syntax {
            expected: "a consistent glTF file".into(),
            found: what,
        })
    }

    /// A `data:` URI's bytes, or the file a relative URI names.
    fn resolve(&self, uri: &str) -> Result<Resolved> {
        if let Some(rest) = uri.strip_prefix("data:") {
            let (_, payload) = rest.split_once(";base64,").ok_or_else(|| {
                self.error(ErrorKind::Unsupported(
                    "a data: URI that is not base64".into(),
                ))
            })?;
            return crate::base64::decode(payload.as_bytes())
                .map(Resolved::Data)
                .ok_or_else(|| self.invalid("a data: URI with invalid base64".into()));
        }
        let decoded = percent_decode(uri).ok_or_else(|| self.invalid(format!("URI {uri:?}")))?;
        let relative = Path::new(&decoded);
        let has_scheme = decoded
            .split_once(':')
            .is_some_and(|(scheme, _)| !scheme.contains(['/', '\\']));
        let escapes = relative.is_absolute()
            || has_scheme
            || relative.components().any(|c| {
                matches!(
                    c,
                    Component::ParentDir | Component::Prefix(_) | Component::RootDir
                )
            });
        if escapes && !self.options.allow_outside_folder {
            return Err(self.error(ErrorKind::OutsideFolder(uri.to_string())));
        }
        Ok(Resolved::File(self.folder.join(relative)))
    }

    fn load(&self, uri: &str) -> Result<(Vec<u8>, Option<PathBuf>)> {
        match self.resolve(uri)? {
            Resolved::Data(bytes) => Ok((bytes, None)),
            Resolved::File(file) => {
                let bytes = std::fs::read(&file).map_err(|e| Error::io(&file, e))?;
                Ok((bytes, Some(file)))
            }
        }
    }

    fn read(&self, bytes: &[u8]) -> Result<Scene> {
        let codec = |e: gltf::Error| {
            self.error(ErrorKind::Codec {
                format: "glTF",
                source: Box::new(e),
            })
        };
        // The gltf crate's GLB split subtracts before it compares (an
        // overflow on a total length below 12, found by fuzzing), so the
        // container is checked here first.
        if crate::mesh::glb::is_glb(bytes) {
            crate::mesh::glb::check(bytes, self.path)?;
        }
        // The gltf crate's validation indexes the arrays a file references
        // without bounds checks (found by fuzzing: a primitive naming an
        // accessor that does not exist panics inside it), so every
        // reference is checked here first.
        let gltf::Gltf { document, blob } =
            gltf::Gltf::from_slice_without_validation(bytes).map_err(codec)?;
        if let Some(broken) = first_dangling_reference(document.as_json()) {
            return Err(self.invalid(broken));
        }
        // The gltf crate unwraps these when asked for an image's source
        // (found by fuzzing), so they are checked here first.
        if let Some(problem) = first_image_without_source(document.as_json()) {
            return Err(self.invalid(problem));
        }
        let mut json = document.into_json();
        if let Some(missing) = json
            .extensions_required
            .iter()
            .find(|e| !HONOURED_EXTENSIONS.contains(&e.as_str()))
        {
            return Err(self.error(ErrorKind::Unsupported(format!(
                "the required extension {missing}"
            ))));
        }
        // Checked above; the gltf crate's validation would refuse the
        // extensions it does not model itself (KHR_mesh_quantization).
        json.extensions_required.clear();
        let document = gltf::Document::from_json(json).map_err(codec)?;
        let mut buffers = Vec::new();
        for buffer in document.buffers() {
            let mut data = match buffer.source() {
                gltf::buffer::Source::Bin => blob.clone().ok_or_else(|| {
                    self.invalid("a buffer in a GLB chunk that is missing".into())
                })?,
                gltf::buffer::Source::Uri(uri) => self.load(uri)?.0,
            };
            if data.len() < buffer.length() {
                return Err(self.error(ErrorKind::Truncated(format!(
                    "buffer {} of {} bytes, {} present",
                    buffer.index(),
                    buffer.length(),
                    data.len()
                ))));
            }
            // Views must fit the declared length (the spec), not whatever
            // the file happens to hold beyond it (GLB chunk padding).
            data.truncate(buffer.length());
            buffers.push(data);
        }

        let mut parts = Parts::default();
        let mut material_map: Vec<Option<usize>> = vec![None; document.materials().len()];
        let scene = document
            .default_scene()
            .or_else(|| document.scenes().next());
        // Depth first in the file's order (the stack pops the last pushed,
        // so siblings go on reversed): objects come out as the file lists
        // them.
        let mut stack: Vec<(gltf::Node<'_>, Mat4)> = scene
            .map(|s| s.nodes().map(|n| (n, Mat4::IDENTITY)).collect())
            .unwrap_or_default();
        stack.reverse();
        let mut visited = 0usize;
        while let Some((node, parent)) = stack.pop() {
            visited += 1;
            if visited > document.nodes().len() {
                return Err(self.invalid("a node hierarchy with a cycle".into()));
            }
            let global = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
            let first_child = stack.len();
            stack.extend(node.children().map(|c| (c, global)));
            stack[first_child..].reverse();
            let Some(gmesh) = node.mesh() else { continue };
            for primitive in gmesh.primitives() {
                let name = gmesh.name().or(node.name()).unwrap_or("").to_string();
                self.primitive(
                    &primitive,
                    global,
                    &buffers,
                    &mut parts,
                    name,
                    &mut material_map,
                )?;
            }
        }
        parts.finish(self.path)
    }

    /// Decodes accessor `accessor` (glTF 2.0 Sec. 3.6.2) to `f64`
    /// components, `dimensions` per element, after checking that its
    /// layout is one `types` allows and that it lies inside its buffers:
    /// the dense data (or zeros without a buffer view), integers
    /// normalized when the accessor says so (Sec. 3.11), then the sparse
    /// values substituted.
    fn decode(
        &self,
        accessor: &Accessor<'_>,
        buffers: &[Vec<u8>],
        what: &str,
        dimensions: Dimensions,
        types: &[DataType],
    ) -> Result<Vec<f64>> {
        let index = accessor.index();
        if accessor.dimensions() != dimensions || !types.contains(&accessor.data_type()) {
            return Err(self.invalid(format!(
                "accessor {index} ({what}) of type {:?} {:?} where {dimensions:?} of {types:?} is required",
                accessor.dimensions(),
                accessor.data_type()
            )));
        }
        let count = accessor.count();
        let width = components(dimensions);
        let values = (count as u64).saturating_mul(width as u64);
        if values > MAX_ACCESSOR_VALUES {
            return Err(self.error(ErrorKind::LimitExceeded(format!(
                "accessor {index} ({what}) declares {count} elements, {values} values, more than \
                 the {MAX_ACCESSOR_VALUES} one accessor may decode to"
            ))));
        }
        if accessor.view().is_none() && count as u64 > MAX_ZERO_FILLED_ELEMENTS {
            return Err(self.error(ErrorKind::LimitExceeded(format!(
                "accessor {index} ({what}) has no buffer view and declares {count} elements, more \
                 than the {MAX_ZERO_FILLED_ELEMENTS} allowed for one filled with zeros"
            ))));
        }
        let kind = accessor.data_type();
        let normalized = accessor.normalized();
        let element = width * kind.size();
        let mut out = vec![0.0f64; count * width];
        if let Some(view) = accessor.view() {
            let stride = view.stride().unwrap_or(element);
            let bytes = self.view_bytes(&view, buffers, || format!("accessor {index} ({what})"))?;
            let used = count
                .checked_sub(1)
                .and_then(|last| stride.checked_mul(last))
                .and_then(|s| s.checked_add(element))
                .and_then(|s| s.checked_add(accessor.offset()));
            if count > 0 && used.is_none_or(|u| u > bytes.len()) {
                return Err(self.error(ErrorKind::Truncated(format!(
                    "accessor {index} ({what}, {count} elements) inside its buffer view"
                ))));
            }
            for (e, chunk) in out.chunks_exact_mut(width).enumerate() {
                let at = accessor.offset() + e * stride;
                for (c, slot) in chunk.iter_mut().enumerate() {
                    *slot = component(&bytes[at + c * kind.size()..], kind, normalized);
                }
            }
        }
        if let Some(sparse) = accessor.sparse() {
            let n = sparse.count();
            if n > count {
                return Err(self.invalid(format!(
                    "accessor {index} ({what}) with {n} sparse values for {count} elements"
                )));
            }
            let indices = sparse.indices();
            let index_size = match indices.index_type() {
                IndexType::U8 => 1,
                IndexType::U16 => 2,
                IndexType::U32 => 4,
            };
            let index_kind = match indices.index_type() {
                IndexType::U8 => DataType::U8,
                IndexType::U16 => DataType::U16,
                IndexType::U32 => DataType::U32,
            };
            let index_bytes = self.view_bytes(&indices.view(), buffers, || {
                format!("the sparse indices of accessor {index}")
            })?;
            let value_bytes = self.view_bytes(&sparse.values().view(), buffers, || {
                format!("the sparse values of accessor {index}")
            })?;
            let index_end = n
                .checked_mul(index_size)
                .and_then(|b| b.checked_add(indices.offset()));
            let value_end = n
                .checked_mul(element)
                .and_then(|b| b.checked_add(sparse.values().offset()));
            if index_end.is_none_or(|e| e > index_bytes.len())
                || value_end.is_none_or(|e| e > value_bytes.len())
            {
                return Err(self.error(ErrorKind::Truncated(format!(
                    "the {n} sparse indices and values of accessor {index} ({what}) inside their buffer views"
                ))));
            }
            for k in 0..n {
                let target = component(
                    &index_bytes[indices.offset() + k * index_size..],
                    index_kind,
                    false,
                );
                if target >= count as f64 {
                    return Err(self.invalid(format!(
                        "sparse index {target} of accessor {index} ({what}), which has {count} elements"
                    )));
                }
                let at = sparse.values().offset() + k * element;
                let target = target as usize;
                for c in 0..width {
                    out[target * width + c] =
                        component(&value_bytes[at + c * kind.size()..], kind, normalized);
                }
            }
        }
        Ok(out)
    }

    /// The bytes of a buffer view, checked against its buffer.
    fn view_bytes<'b>(
        &self,
        view: &gltf::buffer::View<'_>,
        buffers: &'b [Vec<u8>],
        what: impl Fn() -> String,
    ) -> Result<&'b [u8]> {
        let buffer = &buffers[view.buffer().index()];
        match view.offset().checked_add(view.length()) {
            Some(end) if end <= buffer.len() => Ok(&buffer[view.offset()..end]),
            _ => Err(self.error(ErrorKind::Truncated(format!(
                "buffer view {} of {} inside buffer {}",
                view.index(),
                what(),
                view.buffer().index()
            )))),
        }
    }

    fn primitive(
        &self,
        primitive: &gltf::Primitive<'_>,
        global: Mat4,
        buffers: &[Vec<u8>],
        parts: &mut Parts,
        name: String,
        material_map: &mut [Option<usize>],
    ) -> Result<()> {
        let is_points = primitive.mode() == Mode::Points;
        if !is_points
            && !matches!(
                primitive.mode(),
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            )
        {
            // Lines have no surface; said, not skipped in silence.
            parts.mesh.warnings.push(Warning::new(
                self.path,
                None,
                format!(
                    "primitive {} of mesh {:?} is drawn as {:?}, not triangles or points; it \
                     is not read",
                    primitive.index(),
                    name,
                    primitive.mode()
                ),
            ));
            return Ok(());
        }
        if is_points && primitive.indices().is_some() {
            parts.mesh.warnings.push(Warning::new(
                self.path,
                None,
                format!(
                    "the indices of points primitive {} of mesh {:?} are not applied; every \
                     vertex is read as a point",
                    primitive.index(),
                    name
                ),
            ));
        }
        let Parts {
            mesh,
            surface,
            points,
        } = parts;
        let vertices = if is_points { points } else { surface };
        // Primitives that share their vertex accessors (one mesh split by
        // material) share their vertices.
        let key = VertexKey::of(primitive, global, is_points);
        let (base, count) = match key.as_ref().and_then(|k| vertices.shared.get(k)) {
            Some(&found) => found,
            None => {
                let found = self.vertices(primitive, global, buffers, vertices)?;
                if let Some(key) = key {
                    vertices.shared.insert(key, found);
                }
                found
            }
        };
        use DataType::{U8, U16, U32};
        if is_points {
            return Ok(());
        }

        if let Some(a) = primitive.indices().filter(|a| a.normalized()) {
            return Err(self.invalid(format!("index accessor {} marked normalized", a.index())));
        }
        let raw: Vec<u32> = match primitive.indices() {
            Some(a) => self
                .decode(&a, buffers, "indices", Dimensions::Scalar, &[U8, U16, U32])?
                .into_iter()
                .map(|i| i as u32)
                .collect(),
            None => (0..count as u32).collect(),
        };
        let triangles: Vec<[u32; 3]> = match primitive.mode() {
            Mode::TriangleStrip => (2..raw.len())
                .map(|k| {
                    if k % 2 == 0 {
                        [raw[k - 2], raw[k - 1], raw[k]]
                    } else {
                        [raw[k - 1], raw[k - 2], raw[k]]
                    }
                })
                .collect(),
            Mode::TriangleFan => (2..raw.len())
                .map(|k| [raw[0], raw[k - 1], raw[k]])
                .collect(),
            _ => raw.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        };
        let mirrored = global.determinant() < 0.0;
        let start = mesh.indices.len();
        for (t, tri) in triangles.into_iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&i| i as usize >= count) {
                return Err(self.error(ErrorKind::ReferenceOutOfRange(Box::new(
                    crate::error::Reference {
                        what: "vertex",
                        reference: i64::from(bad),
                        element: "triangle",
                        index: start + t,
                        count,
                        records: "vertices in its primitive",
                    },
                ))));
            }
            let [a, b, c] = tri.map(|i| i + base as u32);
            mesh.indices
                .push(if mirrored { [a, c, b] } else { [a, b, c] });
        }
        let material = match primitive.material().index() {
            Some(i) => Some(match material_map[i] {
                Some(m) => m,
                None => {
                    let m = self.material(&primitive.material(), buffers, &mut mesh.warnings)?;
                    mesh.materials.push(m);
                    material_map[i] = Some(mesh.materials.len() - 1);
                    mesh.materials.len() - 1
                }
            }),
            None => None,
        };
        mesh.objects.push(Object {
            name,
            triangles: start..mesh.indices.len(),
            material,
        });
        Ok(())
    }

    /// Decodes the vertices of `primitive` into `vertices`: their first
    /// index there and their count.
    fn vertices(
        &self,
        primitive: &gltf::Primitive<'_>,
        global: Mat4,
        buffers: &[Vec<u8>],
        vertices: &mut Vertices,
    ) -> Result<(usize, usize)> {
        use DataType::{F32, I8, I16, U8, U16};
        let positions = primitive
            .get(&gltf::Semantic::Positions)
            .ok_or_else(|| self.invalid("a primitive without POSITION".into()))?;
        // KHR_mesh_quantization widens POSITION, NORMAL and TEXCOORD to
        // 8- and 16-bit integers; the core allows normalized ones for UVs.
        let positions = self.decode(
            &positions,
            buffers,
            "POSITION",
            Dimensions::Vec3,
            &[F32, I8, U8, I16, U16],
        )?;
        let count = positions.len() / 3;
        let base = vertices.positions.len();
        let normal_matrix = Mat3::from_mat4(global).inverse().transpose();
        // In f64, so that a node translation far from the origin (a
        // georeferenced tile) keeps the precision of the vertices; the
        // shift is chosen once all primitives are in (TriMesh::origin).
        let global64 = global.as_dmat4();
        for (i, p) in positions.chunks_exact(3).enumerate() {
            // The file's components are f32 (or integers); the decoder's
            // f64 holds them exactly.
            let q = global64.transform_point3(DVec3::new(p[0], p[1], p[2]));
            if let Some(value) = q.to_array().into_iter().find(|v| !v.is_finite()) {
                return Err(self.error(ErrorKind::NonFinite {
                    index: base + i,
                    value,
                }));
            }
            vertices.positions.push(q);
        }
        let length_error = |what: &str, n: usize| {
            self.invalid(format!(
                "a primitive with {count} positions but {n} {what} values"
            ))
        };
        match primitive.get(&gltf::Semantic::Normals) {
            Some(a) => {
                let values =
                    self.decode(&a, buffers, "NORMAL", Dimensions::Vec3, &[F32, I8, I16])?;
                if values.len() != 3 * count {
                    return Err(length_error("NORMAL", values.len() / 3));
                }
                vertices.normals.extend(values.chunks_exact(3).map(|n| {
                    let n = Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32);
                    Some((normal_matrix * n).normalize_or_zero())
                }));
            }
            None => vertices.normals.extend(std::iter::repeat_n(None, count)),
        }

        let material = primitive.material();
        let texture_info = material.pbr_metallic_roughness().base_color_texture();
        let transform = texture_info.as_ref().and_then(|t| t.texture_transform());
        // The set the base colour texture reads (KHR_texture_transform may
        // override the material's texCoord).
        let set = texture_info
            .as_ref()
            .map(|t| {
                transform
                    .as_ref()
                    .and_then(|x| x.tex_coord())
                    .unwrap_or(t.tex_coord())
            })
            .unwrap_or(0);
        let uv_types = &[F32, I8, U8, I16, U16][..];
        let read_set = |set: u32| -> Result<Option<Vec<Vec2>>> {
            let Some(a) = primitive.get(&gltf::Semantic::TexCoords(set)) else {
                return Ok(None);
            };
            let values = self.decode(
                &a,
                buffers,
                &format!("TEXCOORD_{set}"),
                Dimensions::Vec2,
                uv_types,
            )?;
            if values.len() != 2 * count {
                return Err(length_error(&format!("TEXCOORD_{set}"), values.len() / 2));
            }
            Ok(Some(
                values
                    .chunks_exact(2)
                    .map(|t| Vec2::new(t[0] as f32, t[1] as f32))
                    .collect(),
            ))
        };
        let mut uvs = read_set(set)?;
        if texture_info.is_some() && uvs.is_none() {
            return Err(self.invalid(format!(
                "a primitive whose base colour texture reads TEXCOORD_{set}, which it does not have"
            )));
        }
        if let (Some(uvs), Some(t)) = (uvs.as_mut(), transform.as_ref()) {
            let (sin, cos) = t.rotation().sin_cos();
            let [su, sv] = t.scale();
            let [ou, ov] = t.offset();
            // The extension's matrix: translation · rotation · scale, with
            // the rotation's columns (cos, sin) and (-sin, cos).
            for uv in uvs.iter_mut() {
                let (u, v) = (uv.x * su, uv.y * sv);
                *uv = Vec2::new(cos * u - sin * v + ou, sin * u + cos * v + ov);
            }
        }
        if let Some(bad) = uvs.iter().flatten().position(|uv| !uv.is_finite()) {
            return Err(self.invalid(format!(
                "a non-finite texture coordinate at vertex {} (TEXCOORD_{set}, after any texture transform)",
                base + bad
            )));
        }
        match uvs {
            Some(uvs) => vertices.uvs.extend(uvs.into_iter().map(Some)),
            None => vertices.uvs.extend(std::iter::repeat_n(None, count)),
        }
        match read_set(1)? {
            Some(uvs1) => vertices.uvs1.extend(uvs1.into_iter().map(Some)),
            None => vertices.uvs1.extend(std::iter::repeat_n(None, count)),
        }

        self.colors_and_attributes(primitive, buffers, vertices, count)?;
        Ok((base, count))
    }

    /// Reads `COLOR_0` and the `_NAME` attributes of a primitive with
    /// `count` vertices into `vertices`, padding the attributes it lacks
    /// (and the earlier vertices of one it brings first) with zeros.
    fn colors_and_attributes(
        &self,
        primitive: &gltf::Primitive<'_>,
        buffers: &[Vec<u8>],
        vertices: &mut Vertices,
        count: usize,
    ) -> Result<()> {
        use DataType::{F32, I8, I16, U8, U16};
        let length_error = |what: &str, n: usize| {
            self.invalid(format!(
                "a primitive with {count} positions but {n} {what} values"
            ))
        };
        match primitive.get(&gltf::Semantic::Colors(0)) {
            Some(a) => {
                let dimensions = a.dimensions();
                let n = match dimensions {
                    Dimensions::Vec3 => 3,
                    Dimensions::Vec4 => 4,
                    other => {
                        return Err(self.invalid(format!(
                            "COLOR_0 accessor {} of type {other:?} (VEC3 or VEC4 expected)",
                            a.index()
                        )));
                    }
                };
                let values = self.decode(&a, buffers, "COLOR_0", dimensions, &[F32, U8, U16])?;
                if values.len() != n * count {
                    return Err(length_error("COLOR_0", values.len() / n));
                }
                vertices.colors.extend(values.chunks_exact(n).map(|c| {
                    let alpha = if n == 4 { c[3] as f32 } else { 1.0 };
                    Some([c[0] as f32, c[1] as f32, c[2] as f32, alpha])
                }));
            }
            None => vertices.colors.extend(std::iter::repeat_n(None, count)),
        }
        let before = vertices.positions.len() - count;
        let mut seen = Vec::new();
        for (semantic, a) in primitive.attributes() {
            let gltf::Semantic::Extras(name) = semantic else {
                continue;
            };
            let dimensions = a.dimensions();
            let n = components(dimensions);
            if !matches!(
                dimensions,
                Dimensions::Scalar | Dimensions::Vec2 | Dimensions::Vec3 | Dimensions::Vec4
            ) {
                return Err(self.invalid(format!(
                    "attribute _{name} (accessor {}) of type {dimensions:?}; SCALAR or VEC2-4 \
                     are read",
                    a.index()
                )));
            }
            let what = format!("_{name}");
            let values = self.decode(&a, buffers, &what, dimensions, &[F32, I8, U8, I16, U16])?;
            if values.len() != n * count {
                return Err(length_error(&what, values.len() / n));
            }
            let column = match vertices.attributes.iter().position(|(m, ..)| *m == name) {
                Some(k) => &mut vertices.attributes[k],
                None => {
                    vertices
                        .attributes
                        .push((name.clone(), n, vec![0.0; n * before]));
                    vertices.attributes.last_mut().expect("just pushed")
                }
            };
            if column.1 != n {
                return Err(self.invalid(format!(
                    "attribute _{name} has {n} components here and {} in an earlier primitive",
                    column.1
                )));
            }
            column.2.extend(values.into_iter().map(|v| v as f32));
            seen.push(name);
        }
        for (name, n, values) in &mut vertices.attributes {
            if !seen.contains(name) {
                values.resize(*n * vertices.positions.len(), 0.0);
            }
        }
        Ok(())
    }

    fn material(
        &self,
        material: &gltf::Material<'_>,
        buffers: &[Vec<u8>],
        warnings: &mut Vec<Warning>,
    ) -> Result<Material> {
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, _] = pbr.base_color_factor();
        let mut out = Material {
            name: material.name().unwrap_or("").to_string(),
            diffuse: [r, g, b],
            diffuse_texture: None,
            diffuse_image: None,
            wrap: [Wrap::Repeat; 2],
            scalar_images: Vec::new(),
        };
        let Some(info) = pbr.base_color_texture() else {
            return Ok(out);
        };
        let texture = info.texture();
        let sampler = texture.sampler();
        let wrap = |mode| match mode {
            WrappingMode::Repeat => Wrap::Repeat,
            WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        };
        out.wrap = [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())];
        let Some(image) = texture.source() else {
            let extensions: Vec<&str> = texture
                .extensions()
                .map(|e| e.keys().map(String::as_str).collect())
                .unwrap_or_default();
            let texture_name = match texture.name() {
                Some(name) => format!("texture {} ({name:?})", texture.index()),
                None => format!("texture {}", texture.index()),
            };
            let place = if extensions.is_empty() {
                "no image at all".to_string()
            } else {
                format!("its image only in {}", extensions.join(", "))
            };
            warnings.push(Warning::new(
                self.path,
                None,
                format!(
                    "{texture_name} has no `source` ({place}, not decoded here); material {:?} \
                     is read without its base colour texture",
                    out.name
                ),
            ));
            return Ok(out);
        };
        let (bytes, file, mime) = match image.source() {
            gltf::image::Source::View { view, mime_type } => {
                let buffer = &buffers[view.buffer().index()];
                let end = view
                    .offset()
                    .checked_add(view.length())
                    .filter(|&e| e <= buffer.len());
                let end = end.ok_or_else(|| {
                    self.error(ErrorKind::Truncated("an image buffer view".into()))
                })?;
                (buffer[view.offset()..end].to_vec(), None, Some(mime_type))
            }
            gltf::image::Source::Uri { uri, mime_type } => {
                let (bytes, file) = self.load(uri)?;
                (bytes, file, mime_type)
            }
        };
        let name = match (mime, &file) {
            (Some("image/jpeg"), _) => PathBuf::from("texture.jpg"),
            (Some("image/png"), _) => PathBuf::from("texture.png"),
            (_, Some(file)) => file.clone(),
            _ => PathBuf::from("texture.png"),
        };
        let decoded = image::decode(&bytes, &name, ReadOptions::default()).map_err(|mut e| {
            e.path = file.clone().unwrap_or_else(|| self.path.to_path_buf());
            e
        })?;
        out.diffuse_texture = file;
        out.diffuse_image = Some(decoded);
        Ok(out)
    }
}

/// The scene under construction: the surface's and the points' vertices,
/// with attributes that some primitives may lack.
#[derive(Default)]
struct Parts {
    mesh: TriMesh,
    surface: Vertices,
    points: Vertices,
}

/// Per-vertex values of the primitives read so far.
#[derive(Default)]
struct Vertices {
    /// Positions with the node transforms applied, in f64 until the
    /// global shift is known.
    positions: Vec<DVec3>,
    normals: Vec<Option<Vec3>>,
    uvs: Vec<Option<Vec2>>,
    uvs1: Vec<Option<Vec2>>,
    colors: Vec<Option<[f32; 4]>>,
    /// `_NAME` attributes by name (without the underscore): components
    /// per element and the values, zeros for the vertices of primitives
    /// without it. Each holds `components · positions.len()` values
    /// between primitives.
    attributes: Vec<(String, usize, Vec<f32>)>,
    /// The first vertex and count of each set of vertex accessors read.
    shared: std::collections::HashMap<VertexKey, (usize, usize)>,
}

/// What decides a primitive's vertices: its attribute accessors, the node
/// transform applied to them, and points or surface.
#[derive(PartialEq, Eq, Hash)]
struct VertexKey {
    transform: [u32; 16],
    attributes: Vec<(String, usize)>,
    points: bool,
    uv_set: u32,
}

impl VertexKey {
    /// The key, or `None` when a texture transform makes the decoded UVs
    /// depend on the material too (such primitives are read alone).
    fn of(primitive: &gltf::Primitive<'_>, global: Mat4, points: bool) -> Option<Self> {
        let texture = primitive
            .material()
            .pbr_metallic_roughness()
            .base_color_texture();
        if texture
            .as_ref()
            .is_some_and(|t| t.texture_transform().is_some())
        {
            return None;
        }
        let mut attributes: Vec<(String, usize)> = primitive
            .attributes()
            .map(|(semantic, a)| (semantic.to_string(), a.index()))
            .collect();
        attributes.sort();
        Some(VertexKey {
            transform: global.to_cols_array().map(f32::to_bits),
            attributes,
            points,
            uv_set: texture.map_or(0, |t| t.tex_coord()),
        })
    }
}

/// An attribute when any primitive has it (zeros for the vertices of
/// those that do not).
fn fill<T: Copy + Default>(values: Vec<Option<T>>) -> Option<Vec<T>> {
    values
        .iter()
        .any(Option::is_some)
        .then(|| values.into_iter().map(Option::unwrap_or_default).collect())
}

impl Vertices {
    /// Positions relative to the global shift of these vertices.
    fn recentered(&self, path: &Path) -> Result<(DVec3, Vec<Vec3>)> {
        let (origin, positions) = crate::mesh::recenter(&self.positions);
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::new(
                path,
                ErrorKind::OutOfRange(format!(
                    "vertex {i} at {} is too far from the others for f32 positions",
                    self.positions[i]
                )),
            ));
        }
        Ok((origin, positions))
    }

    /// The colours and custom attributes, as [`VertexData`].
    fn vertex_data(
        colors: Vec<Option<[f32; 4]>>,
        attributes: Vec<(String, usize, Vec<f32>)>,
    ) -> VertexData {
        VertexData {
            colors: fill(colors),
            attributes: attributes
                .into_iter()
                .map(|(name, components, values)| Attribute {
                    name,
                    values: AttributeValues::from_components(components, values),
                })
                .collect(),
        }
    }
}

/// The `_FACE` attribute as face ids, taken out of `data`, when every
/// value is a non-negative integer below 2^24 (what the writer stores).
fn take_faces(data: &mut VertexData) -> Option<Vec<u32>> {
    let k = data
        .attributes
        .iter()
        .position(|a| a.name == super::FACE_ATTRIBUTE)?;
    let AttributeValues::Scalar(values) = &data.attributes[k].values else {
        return None;
    };
    let exact = |v: f32| v >= 0.0 && v < super::FACE_ID_LIMIT as f32 && v.fract() == 0.0;
    if !values.iter().all(|&v| exact(v)) {
        return None;
    }
    let faces = values.iter().map(|&v| v as u32).collect();
    data.attributes.remove(k);
    Some(faces)
}

impl Parts {
    /// The scene, positions relative to their global shifts.
    fn finish(self, path: &Path) -> Result<Scene> {
        let (origin, positions) = self.surface.recentered(path)?;
        let mesh = TriMesh {
            positions,
            origin,
            normals: fill(self.surface.normals),
            uvs: fill(self.surface.uvs),
            uvs1: fill(self.surface.uvs1),
            ..self.mesh
        };
        let vertex_data = Vertices::vertex_data(self.surface.colors, self.surface.attributes);
        let (origin, positions) = self.points.recentered(path)?;
        let mut point_data = Vertices::vertex_data(self.points.colors, self.points.attributes);
        let faces = take_faces(&mut point_data);
        Ok(Scene {
            mesh,
            vertex_data,
            points: Points {
                positions,
                origin,
                normals: fill(self.points.normals),
                uvs: fill(self.points.uvs),
                faces,
                vertex_data: point_data,
            },
        })
    }
}

/// The number of components of an element.
fn components(dimensions: Dimensions) -> usize {
    match dimensions {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 | Dimensions::Mat2 => 4,
        Dimensions::Mat3 => 9,
        Dimensions::Mat4 => 16,
    }
}

/// One little-endian component at the start of `bytes` (the caller has
/// checked the length), normalized to `[0, 1]` or `[-1, 1]` when asked
/// (glTF 2.0 Sec. 3.11: `max(c / (2^(n-1) - 1), -1)` for signed types).
fn component(bytes: &[u8], kind: DataType, normalized: bool) -> f64 {
    let b = |i: usize| bytes[i];
    let (value, scale) = match kind {
        DataType::I8 => (f64::from(b(0) as i8), 127.0),
        DataType::U8 => (f64::from(b(0)), 255.0),
        DataType::I16 => (f64::from(i16::from_le_bytes([b(0), b(1)])), 32_767.0),
        DataType::U16 => (f64::from(u16::from_le_bytes([b(0), b(1)])), 65_535.0),
        DataType::U32 => (
            f64::from(u32::from_le_bytes([b(0), b(1), b(2), b(3)])),
            4_294_967_295.0,
        ),
        DataType::F32 => (f64::from(f32::from_le_bytes([b(0), b(1), b(2), b(3)])), 1.0),
    };
    if normalized && kind != DataType::F32 {
        (value / scale).max(-1.0)
    } else {
        value
    }
}

/// The first reference of the JSON to an array element that does not
/// exist, described, or `None` when every reference resolves.
fn first_dangling_reference(root: &gltf::json::Root) -> Option<String> {
    let mut problems = Vec::new();
    let mut check = |what: &str, index: usize, len: usize| {
        if index >= len && problems.is_empty() {
            problems.push(format!("{what} {index} of {len}"));
        }
    };
    let (accessors, views, buffers) = (
        root.accessors.len(),
        root.buffer_views.len(),
        root.buffers.len(),
    );
    let (nodes, meshes, materials) = (root.nodes.len(), root.meshes.len(), root.materials.len());
    let (textures, images, samplers) =
        (root.textures.len(), root.images.len(), root.samplers.len());
    if let Some(scene) = root.scene {
        check("scene", scene.value(), root.scenes.len());
    }
    for scene in &root.scenes {
        scene
            .nodes
            .iter()
            .for_each(|n| check("node", n.value(), nodes));
    }
    for node in &root.nodes {
        node.children
            .iter()
            .flatten()
            .for_each(|n| check("node", n.value(), nodes));
        node.mesh
            .iter()
            .for_each(|m| check("mesh", m.value(), meshes));
        node.skin
            .iter()
            .for_each(|s| check("skin", s.value(), root.skins.len()));
        node.camera
            .iter()
            .for_each(|c| check("camera", c.value(), root.cameras.len()));
    }
    for mesh in &root.meshes {
        for primitive in &mesh.primitives {
            primitive
                .attributes
                .values()
                .for_each(|a| check("accessor", a.value(), accessors));
            primitive
                .indices
                .iter()
                .for_each(|a| check("accessor", a.value(), accessors));
            primitive
                .material
                .iter()
                .for_each(|m| check("material", m.value(), materials));
            for target in primitive.targets.iter().flatten() {
                [target.positions, target.normals, target.tangents]
                    .into_iter()
                    .flatten()
                    .for_each(|a| check("accessor", a.value(), accessors));
            }
        }
    }
    for accessor in &root.accessors {
        accessor
            .buffer_view
            .iter()
            .for_each(|v| check("buffer view", v.value(), views));
        if let Some(sparse) = &accessor.sparse {
            check("buffer view", sparse.indices.buffer_view.value(), views);
            check("buffer view", sparse.values.buffer_view.value(), views);
        }
    }
    root.buffer_views
        .iter()
        .for_each(|v| check("buffer", v.buffer.value(), buffers));
    for material in &root.materials {
        let pbr = &material.pbr_metallic_roughness;
        [
            &pbr.base_color_texture,
            &pbr.metallic_roughness_texture,
            &material.emissive_texture,
        ]
        .into_iter()
        .flatten()
        .for_each(|t| check("texture", t.index.value(), textures));
        material
            .normal_texture
            .iter()
            .for_each(|t| check("texture", t.index.value(), textures));
        material
            .occlusion_texture
            .iter()
            .for_each(|t| check("texture", t.index.value(), textures));
    }
    for texture in &root.textures {
        // No `source` (the image is only in an extension) is not a
        // dangling reference: the material is read without it.
        if texture.source.value() != u32::MAX as usize {
            check("image", texture.source.value(), images);
        }
        texture
            .sampler
            .iter()
            .for_each(|s| check("sampler", s.value(), samplers));
    }
    root.images
        .iter()
        .flat_map(|i| i.buffer_view)
        .for_each(|v| check("buffer view", v.value(), views));
    for skin in &root.skins {
        skin.joints
            .iter()
            .for_each(|n| check("node", n.value(), nodes));
        skin.skeleton
            .iter()
            .for_each(|n| check("node", n.value(), nodes));
        skin.inverse_bind_matrices
            .iter()
            .for_each(|a| check("accessor", a.value(), accessors));
    }
    for animation in &root.animations {
        for channel in &animation.channels {
            check(
                "animation sampler",
                channel.sampler.value(),
                animation.samplers.len(),
            );
            check("node", channel.target.node.value(), nodes);
        }
        for sampler in &animation.samplers {
            check("accessor", sampler.input.value(), accessors);
            check("accessor", sampler.output.value(), accessors);
        }
    }
    problems.pop().map(|p| format!("a reference to {p}"))
}

/// The first image whose data cannot be found as the specification
/// says (a `bufferView` with its `mimeType`, or a `uri`), described.
fn first_image_without_source(root: &gltf::json::Root) -> Option<String> {
    root.images.iter().enumerate().find_map(|(i, image)| {
        match (&image.buffer_view, &image.mime_type, &image.uri) {
            (Some(_), None, _) => Some(format!(
                "image {i} in a buffer view without the mimeType the specification requires"
            )),
            (None, _, None) => Some(format!("image {i} with neither a uri nor a buffer view")),
            _ => None,
        }
    })
}

/// Decodes `%XX` escapes; `None` for a malformed escape or non-UTF-8.
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}
