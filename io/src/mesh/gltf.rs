//! glTF 2.0 (`.gltf` with external or `data:` buffers, and binary `.glb`):
//! every triangle primitive of the default scene with its node transforms
//! applied; POSITION, NORMAL, TEXCOORD_0 and indices; base-colour factor
//! and texture (embedded or external, decoded), with its wrap modes.
//!
//! The `gltf` crate parses the JSON and GLB container; buffers and images
//! are resolved here, so that a file cannot make the reader open anything
//! outside its own folder: absolute paths, `..` and remote schemes are
//! refused unless [`Options::allow_outside_folder`] is set. Every accessor
//! is checked against its buffer before it is read.

use std::path::{Component, Path, PathBuf};

use glam::{Mat3, Mat4, Vec2, Vec3};
use gltf::accessor::{Accessor, DataType, Dimensions};
use gltf::mesh::Mode;
use gltf::texture::WrappingMode;

use super::{Material, Object, TriMesh, Wrap};
use crate::error::{Error, ErrorKind, Result};
use crate::image::{self, ReadOptions};

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
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    from_bytes(&bytes, path, options)
}

/// Parses glTF JSON or GLB bytes; external URIs resolve against the
/// folder of `path`, which also names the data in errors.
///
/// # Errors
/// As for [`read`].
pub fn from_bytes(bytes: &[u8], path: impl AsRef<Path>, options: Options) -> Result<TriMesh> {
    let path = path.as_ref();
    let folder = path.parent().unwrap_or(Path::new("."));
    Reader {
        path,
        folder,
        options,
    }
    .read(bytes)
}

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

    fn read(&self, bytes: &[u8]) -> Result<TriMesh> {
        let codec = |e: gltf::Error| {
            self.error(ErrorKind::Codec {
                format: "glTF",
                source: Box::new(e),
            })
        };
        // The gltf crate's validation indexes the arrays a file references
        // without bounds checks (found by fuzzing: a primitive naming an
        // accessor that does not exist panics inside it), so every
        // reference is checked here first.
        let gltf::Gltf { document, blob } =
            gltf::Gltf::from_slice_without_validation(bytes).map_err(codec)?;
        if let Some(broken) = first_dangling_reference(document.as_json()) {
            return Err(self.invalid(broken));
        }
        let document = gltf::Document::from_json(document.into_json()).map_err(codec)?;
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

        let mut mesh = TriMesh::default();
        let mut normals: Vec<Option<Vec3>> = Vec::new();
        let mut uvs: Vec<Option<Vec2>> = Vec::new();
        let mut material_map: Vec<Option<usize>> = vec![None; document.materials().len()];
        let scene = document
            .default_scene()
            .or_else(|| document.scenes().next());
        let mut stack: Vec<(gltf::Node<'_>, Mat4)> = scene
            .map(|s| s.nodes().map(|n| (n, Mat4::IDENTITY)).collect())
            .unwrap_or_default();
        let mut visited = 0usize;
        while let Some((node, parent)) = stack.pop() {
            visited += 1;
            if visited > document.nodes().len() {
                return Err(self.invalid("a node hierarchy with a cycle".into()));
            }
            let global = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
            stack.extend(node.children().map(|c| (c, global)));
            let Some(gmesh) = node.mesh() else { continue };
            for primitive in gmesh.primitives() {
                let name = gmesh.name().or(node.name()).unwrap_or("").to_string();
                self.primitive(
                    &primitive,
                    global,
                    &buffers,
                    &mut mesh,
                    &mut normals,
                    &mut uvs,
                    name,
                    &mut material_map,
                )?;
            }
        }
        let any_normal = normals.iter().any(Option::is_some);
        let any_uv = uvs.iter().any(Option::is_some);
        mesh.normals =
            any_normal.then(|| normals.iter().map(|n| n.unwrap_or(Vec3::ZERO)).collect());
        mesh.uvs = any_uv.then(|| uvs.iter().map(|t| t.unwrap_or(Vec2::ZERO)).collect());
        Ok(mesh)
    }

    /// Checks that `accessor` has the layout its use requires (the gltf
    /// reader only debug-asserts it; found by fuzzing) and lies inside its
    /// buffer view and buffer.
    fn check(
        &self,
        accessor: &Accessor<'_>,
        buffers: &[Vec<u8>],
        dimensions: Dimensions,
        types: &[DataType],
    ) -> Result<()> {
        // The spec requires count >= 1; the gltf reader computes count - 1
        // (found by fuzzing).
        if accessor.count() == 0 {
            return Err(self.invalid(format!("accessor {} with count 0", accessor.index())));
        }
        if accessor.dimensions() != dimensions || !types.contains(&accessor.data_type()) {
            return Err(self.invalid(format!(
                "accessor {} of type {:?} {:?} where {dimensions:?} of {types:?} is required",
                accessor.index(),
                accessor.dimensions(),
                accessor.data_type()
            )));
        }
        if accessor.sparse().is_some() {
            return Err(self.error(ErrorKind::Unsupported("sparse accessors".into())));
        }
        let view = accessor.view().ok_or_else(|| {
            self.error(ErrorKind::Unsupported(
                "accessors without a buffer view".into(),
            ))
        })?;
        let buffer = &buffers[view.buffer().index()];
        let view_end = view.offset().checked_add(view.length());
        let size = accessor.size();
        let stride = view.stride().unwrap_or(size);
        let used = stride
            .checked_mul(accessor.count() - 1)
            .and_then(|s| s.checked_add(size))
            .and_then(|s| s.checked_add(accessor.offset()));
        match (view_end, used) {
            (Some(end), Some(used)) if end <= buffer.len() && used <= view.length() => Ok(()),
            _ => Err(self.error(ErrorKind::Truncated(format!(
                "accessor {} ({} elements) inside its buffer view",
                accessor.index(),
                accessor.count()
            )))),
        }
    }

    #[expect(
        clippy::too_many_arguments,
        reason = "the mesh under construction, in parts"
    )]
    fn primitive(
        &self,
        primitive: &gltf::Primitive<'_>,
        global: Mat4,
        buffers: &[Vec<u8>],
        mesh: &mut TriMesh,
        normals: &mut Vec<Option<Vec3>>,
        uvs: &mut Vec<Option<Vec2>>,
        name: String,
        material_map: &mut [Option<usize>],
    ) -> Result<()> {
        if !matches!(
            primitive.mode(),
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            return Ok(()); // points and lines have no surface
        }
        let float = &[DataType::F32][..];
        let uv_types = &[DataType::F32, DataType::U8, DataType::U16][..];
        let layouts = [
            (gltf::Semantic::Positions, Dimensions::Vec3, float),
            (gltf::Semantic::Normals, Dimensions::Vec3, float),
            (gltf::Semantic::TexCoords(0), Dimensions::Vec2, uv_types),
        ];
        for (semantic, dimensions, types) in layouts {
            if let Some(accessor) = primitive.get(&semantic) {
                self.check(&accessor, buffers, dimensions, types)?;
            }
        }
        if let Some(accessor) = primitive.indices() {
            let index_types = [DataType::U8, DataType::U16, DataType::U32];
            self.check(&accessor, buffers, Dimensions::Scalar, &index_types)?;
        }
        let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| self.invalid("a primitive without POSITION".into()))?
            .map(Vec3::from)
            .collect();
        let count = positions.len();
        let base = mesh.positions.len();
        let normal_matrix = Mat3::from_mat4(global).inverse().transpose();
        for (i, p) in positions.into_iter().enumerate() {
            let q = global.transform_point3(p);
            if !q.is_finite() {
                let value = q
                    .to_array()
                    .into_iter()
                    .find(|v| !v.is_finite())
                    .unwrap_or(f32::NAN);
                return Err(self.error(ErrorKind::NonFinite {
                    index: base + i,
                    value: f64::from(value),
                }));
            }
            mesh.positions.push(q);
        }
        match reader.read_normals() {
            Some(iter) => normals
                .extend(iter.map(|n| Some((normal_matrix * Vec3::from(n)).normalize_or_zero()))),
            None => normals.extend(std::iter::repeat_n(None, count)),
        }
        match reader.read_tex_coords(0) {
            Some(iter) => uvs.extend(iter.into_f32().map(|t| Some(Vec2::from(t)))),
            None => uvs.extend(std::iter::repeat_n(None, count)),
        }
        if normals.len() != base + count || uvs.len() != base + count {
            return Err(self.invalid("attributes of different lengths in one primitive".into()));
        }
        let raw: Vec<u32> = match reader.read_indices() {
            Some(indices) => indices.into_u32().collect(),
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
                return Err(self.error(ErrorKind::IndexOutOfRange {
                    element: "triangle",
                    index: start + t,
                    node: i64::from(bad),
                    count,
                }));
            }
            let [a, b, c] = tri.map(|i| i + base as u32);
            mesh.indices
                .push(if mirrored { [a, c, b] } else { [a, b, c] });
        }
        let material = match primitive.material().index() {
            Some(i) => Some(match material_map[i] {
                Some(m) => m,
                None => {
                    let m = self.material(&primitive.material(), buffers)?;
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

    fn material(&self, material: &gltf::Material<'_>, buffers: &[Vec<u8>]) -> Result<Material> {
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, _] = pbr.base_color_factor();
        let mut out = Material {
            name: material.name().unwrap_or("").to_string(),
            diffuse: [r, g, b],
            diffuse_texture: None,
            diffuse_image: None,
            wrap: [Wrap::Repeat; 2],
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
        let (bytes, file, mime) = match texture.source().source() {
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
        check("image", texture.source.value(), images);
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
