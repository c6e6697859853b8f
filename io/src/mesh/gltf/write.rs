//! Writing glTF 2.0: a mesh with its materials and per-vertex data, or a
//! point cloud, as `.glb` (one file) or `.gltf` with its `.bin` (images
//! in the binary buffer, so the two files are the whole asset).
//!
//! The JSON is built from the gltf-rs project's own types (`gltf-json`).
//! What the specification requires of a writer is done here: POSITION
//! min/max, 4-byte aligned buffer views with their targets, unit normals,
//! 16-bit indices only when no index reaches 65 535 (the primitive-restart
//! value), no unsigned 32-bit custom attributes, and a GLB whose chunks
//! are padded (glTF 2.0 Sec. 3.6, 3.7, 4.4).

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;

use glam::{DVec3, Vec3};
use gltf::json::accessor::{ComponentType, GenericComponentType, Type};
use gltf::json::buffer::Target;
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::{Checked, Checked::Valid, USize64};
use gltf::json::{self, Index};

use super::{AttributeValues, FACE_ATTRIBUTE, FACE_ID_LIMIT, Points, VertexData};
use crate::error::{Error, ErrorKind, Result};
use crate::image::{self, PngDepth};
use crate::mesh::{Material, Object, TriMesh, Wrap};

/// Writes `mesh` as glTF, choosing the container by extension: `.glb`
/// (binary, one file) or `.gltf` (JSON beside a `.bin` of the same name).
/// See [`write_with`].
///
/// # Errors
/// As for [`write_with`].
pub fn write(path: impl AsRef<Path>, mesh: &TriMesh) -> Result<()> {
    write_with(path, mesh, &VertexData::default())
}

/// Writes `mesh` with per-vertex colours (`COLOR_0`) and custom
/// attributes (`_NAME`) as glTF (`.glb` or `.gltf` + `.bin`).
///
/// One glTF mesh and node per [`Object`] (named as it), or one for the
/// whole mesh when it has no objects. Objects whose triangles use
/// consecutive, disjoint runs of the vertices (the pieces of a fracture,
/// meshes put one after the other) have vertex accessors of their own, so
/// that each loads alone in any viewer; otherwise all share one set. Each material becomes a metallic-roughness
/// material (metallic 0, roughness 1, double-sided) with the base colour
/// as its factor and its texture embedded: the decoded image as an 8-bit
/// sRGB PNG, or the file it names (PNG and JPEG as they are, other
/// formats converted to PNG, values above 1 clipped). The global shift
/// ([`TriMesh::origin`]) is the node's translation, so viewers place the
/// mesh where the file it came from did; glTF stores it in `f32`, and
/// what `f32` cannot hold of it is added to the vertices.
///
/// Triangles without a material get [`UNLIT_MATERIAL`] when there are
/// vertex colours (shown as they are, as a radiance or baked result
/// means), else [`DEFAULT_MATERIAL`]: glTF's own default is a metal that
/// viewers draw nearly black. Reading the file back gives them that
/// material.
///
/// Normals are written normalised; a zero or non-finite one is replaced
/// by the normalised sum of its triangles' normals (`+z` for a vertex on
/// no triangle), as viewers need unit normals.
///
/// # Errors
/// [`ErrorKind::UnknownExtension`] for an extension other than `.glb` or
/// `.gltf`; [`ErrorKind::InvalidInput`] for arrays whose length is not
/// the vertex count, an index out of range, objects that do not cover the
/// triangles in order, a material out of range, vertices without
/// triangles, second UVs without first ones, a non-finite position, UV or attribute value, a colour
/// more than 10^-5 outside `[0, 1]` (closer ones are clamped into it), an attribute name that is not `[A-Za-z0-9_]+` or
/// appears twice, a texture file that does not exist or decode, or a GLB
/// over 4 GiB; an I/O error.
pub fn write_with(path: impl AsRef<Path>, mesh: &TriMesh, data: &VertexData) -> Result<()> {
    let path = path.as_ref();
    let container = Container::of(path)?;
    mesh.check_layout(path)?;
    let n = mesh.positions.len();
    check_vertex_data(path, data, n)?;
    if mesh.uvs1.is_some() && mesh.uvs.is_none() {
        return Err(invalid(
            path,
            "second UVs without first ones (glTF numbers TEXCOORD_n from 0)".into(),
        ));
    }
    if n > 0 && mesh.indices.is_empty() {
        return Err(invalid(
            path,
            format!("a mesh of {n} vertices and no triangles (write its vertices as points)"),
        ));
    }
    let mut doc = Document::new(path);
    if n > 0 {
        doc.mesh(mesh, data)?;
    }
    doc.save(container)
}

/// Writes a point cloud as a glTF `POINTS` primitive (`.glb` or `.gltf` +
/// `.bin`): positions, unit normals, `TEXCOORD_0`, `COLOR_0`, the face of
/// each point as `_FACE` (`f32`) and the other attributes as `_NAME`.
///
/// # Errors
/// As for [`write_with`], and a face id of 2^24 or more (which `f32`
/// cannot hold exactly; glTF attributes may not be 32-bit integers) or
/// an attribute named `FACE` beside [`Points::faces`].
pub fn write_points(path: impl AsRef<Path>, points: &Points) -> Result<()> {
    let path = path.as_ref();
    let container = Container::of(path)?;
    let n = points.positions.len();
    let lengths = [
        ("normals", points.normals.as_ref().map(Vec::len)),
        ("UVs", points.uvs.as_ref().map(Vec::len)),
        ("face ids", points.faces.as_ref().map(Vec::len)),
    ];
    for (what, len) in lengths {
        if let Some(len) = len.filter(|&l| l != n) {
            return Err(invalid(path, format!("{len} {what} for {n} points")));
        }
    }
    check_vertex_data(path, &points.vertex_data, n)?;
    let mut data = points.vertex_data.clone();
    if let Some(faces) = &points.faces {
        if data.attribute(FACE_ATTRIBUTE).is_some() {
            return Err(invalid(
                path,
                format!("an attribute named {FACE_ATTRIBUTE} beside the face ids"),
            ));
        }
        if let Some((i, f)) = faces.iter().enumerate().find(|(_, f)| **f >= FACE_ID_LIMIT) {
            return Err(invalid(
                path,
                format!(
                    "point {i} lies on face {f}; glTF attributes hold face ids below 2^24 \
                     exactly (write PLY for larger meshes)"
                ),
            ));
        }
        data.attributes.push(super::Attribute {
            name: FACE_ATTRIBUTE.into(),
            values: AttributeValues::Scalar(faces.iter().map(|&f| f as f32).collect()),
        });
    }
    let mut doc = Document::new(path);
    if n > 0 {
        let normals = match &points.normals {
            Some(normals) => Some(unit_normals(path, normals, &[], &points.positions)?),
            None => None,
        };
        let vertices = Vertices {
            positions: &points.positions,
            origin: points.origin,
            normals: normals.as_deref(),
            uvs: points.uvs.as_deref(),
            uvs1: None,
            data: &data,
        };
        let attributes = doc.vertices(&vertices)?;
        let primitive = bare_primitive(attributes, None, Mode::Points);
        doc.node("points", primitive, points.origin.as_vec3());
    }
    doc.save(container)
}

/// The curves as one `LINES` primitive and their roots as a `POINTS`
/// primitive ([`crate::curves::write_gltf`], which checks them first).
pub(crate) fn write_curves(path: &Path, curves: &crate::curves::Curves) -> Result<()> {
    let container = Container::of(path)?;
    if let Some((c, f)) = curves
        .faces
        .iter()
        .flatten()
        .enumerate()
        .find(|(_, f)| **f >= FACE_ID_LIMIT)
    {
        return Err(invalid(
            path,
            format!(
                "curve {c}'s root lies on face {f}; glTF attributes hold face ids below 2^24 \
                 exactly"
            ),
        ));
    }
    let mut doc = Document::new(path);
    if !curves.points.is_empty() {
        let data = VertexData {
            colors: None,
            attributes: curves
                .widths
                .iter()
                .map(|w| super::Attribute {
                    name: "WIDTH".into(),
                    values: AttributeValues::Scalar(w.clone()),
                })
                .collect(),
        };
        let vertices = Vertices {
            positions: &curves.points,
            origin: DVec3::ZERO,
            normals: None,
            uvs: None,
            uvs1: None,
            data: &data,
        };
        let attributes = doc.vertices(&vertices)?;
        let segments = curves.points.len() - curves.counts.len();
        let mut pairs: Vec<[u32; 2]> = Vec::with_capacity(segments);
        for (first, &count) in curves.offsets().into_iter().zip(&curves.counts) {
            let first = first as u32;
            pairs.extend((first..first + count - 1).map(|i| [i, i + 1]));
        }
        let indices = doc.index_pairs(&pairs, curves.points.len());
        let lines = bare_primitive(attributes, Some(indices), Mode::Lines);
        doc.node("strands", lines, Vec3::ZERO);

        let first = curves.offsets();
        let roots: Vec<Vec3> = first.iter().map(|&i| curves.points[i]).collect();
        let mut data = VertexData::default();
        if let Some(faces) = &curves.faces {
            data.attributes.push(super::Attribute {
                name: FACE_ATTRIBUTE.into(),
                values: AttributeValues::Scalar(faces.iter().map(|&f| f as f32).collect()),
            });
        }
        if let Some(b) = &curves.barycentrics {
            data.attributes.push(super::Attribute {
                name: "BARYCENTRIC".into(),
                values: AttributeValues::Vec3(b.iter().map(|&b| Vec3::from_array(b)).collect()),
            });
        }
        let normals = match &curves.normals {
            Some(n) => Some(unit_normals(path, n, &[], &roots)?),
            None => None,
        };
        let vertices = Vertices {
            positions: &roots,
            origin: DVec3::ZERO,
            normals: normals.as_deref(),
            uvs: curves.uvs.as_deref(),
            uvs1: None,
            data: &data,
        };
        let attributes = doc.vertices(&vertices)?;
        let points = bare_primitive(attributes, None, Mode::Points);
        doc.node("roots", points, Vec3::ZERO);
    }
    doc.save(container)
}

/// The name of the material given to triangles without one when the mesh
/// has vertex colours: unlit (`KHR_materials_unlit`), white, double-sided.
pub const UNLIT_MATERIAL: &str = "vertex colours (unlit)";

/// The name of the material given to triangles without one otherwise:
/// white, metallic 0, roughness 1, double-sided.
pub const DEFAULT_MATERIAL: &str = "default";

/// `.glb` or `.gltf`.
#[derive(Clone, Copy)]
enum Container {
    Binary,
    Json,
}

impl Container {
    fn of(path: &Path) -> Result<Self> {
        match crate::error::extension(path).as_str() {
            "glb" => Ok(Container::Binary),
            "gltf" => Ok(Container::Json),
            other => Err(Error::new(
                path,
                ErrorKind::UnknownExtension(other.to_string(), ".glb, .gltf"),
            )),
        }
    }
}

fn invalid(path: &Path, what: String) -> Error {
    Error::new(path, ErrorKind::InvalidInput(what))
}

/// How far outside `[0, 1]` a colour may be and still be written (clamped
/// into it): the rounding of a filter or a conversion that should have
/// stayed inside (a texture lookup giving 1.0000001).
pub const COLOR_SLACK: f64 = 1e-5;

/// Checks colours and attributes against `n` vertices.
fn check_vertex_data(path: &Path, data: &VertexData, n: usize) -> Result<()> {
    if let Some(colors) = &data.colors {
        if colors.len() != n {
            return Err(invalid(
                path,
                format!("{} colours for {n} vertices", colors.len()),
            ));
        }
        let range = -COLOR_SLACK..=1.0 + COLOR_SLACK;
        let bad = |c: &[f32; 4]| c.iter().any(|&v| !range.contains(&f64::from(v)));
        if let Some((i, c)) = colors.iter().enumerate().find(|(_, c)| bad(c)) {
            let problem = if c.iter().all(|v| v.is_finite()) {
                "is not in [0, 1] (scale or clamp it)"
            } else {
                "is not finite"
            };
            return Err(invalid(
                path,
                format!("the colour of vertex {i}, {c:?}, {problem}"),
            ));
        }
    }
    for (k, a) in data.attributes.iter().enumerate() {
        let name = &a.name;
        let ok = |c: char| c.is_ascii_alphanumeric() || c == '_';
        if name.is_empty() || !name.chars().all(ok) {
            return Err(invalid(
                path,
                format!("attribute name {name:?} (letters, digits and '_' only)"),
            ));
        }
        if data.attributes[..k].iter().any(|b| b.name == *name) {
            return Err(invalid(path, format!("attribute {name} appears twice")));
        }
        if a.values.len() != n {
            return Err(invalid(
                path,
                format!(
                    "attribute {name} has {} values for {n} vertices",
                    a.values.len()
                ),
            ));
        }
        let c = a.values.components();
        if let Some(i) = a.values.flat().iter().position(|v| !v.is_finite()) {
            return Err(invalid(
                path,
                format!("attribute {name} is not finite at vertex {}", i / c),
            ));
        }
    }
    Ok(())
}

/// The normals, normalised; a zero or non-finite one replaced by the
/// normalised sum of the normals of `triangles` at its vertex (`+z` when
/// there are none).
fn unit_normals(
    path: &Path,
    normals: &[Vec3],
    triangles: &[[u32; 3]],
    positions: &[Vec3],
) -> Result<Vec<Vec3>> {
    if normals.len() != positions.len() {
        return Err(invalid(
            path,
            format!("{} normals for {} vertices", normals.len(), positions.len()),
        ));
    }
    let mut out: Vec<Option<Vec3>> = normals
        .iter()
        .map(|n| n.try_normalize().filter(|u| u.is_finite()))
        .collect();
    if out.iter().all(Option::is_some) {
        return Ok(out.into_iter().flatten().collect());
    }
    let mut sums = vec![Vec3::ZERO; normals.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let face = (b - a).cross(c - a);
        for &i in t {
            sums[i as usize] += face;
        }
    }
    for (i, n) in out.iter_mut().enumerate() {
        if n.is_none() {
            *n = Some(sums[i].try_normalize().unwrap_or(Vec3::Z));
        }
    }
    Ok(out.into_iter().flatten().collect())
}

/// The vertex run of each object when the objects' triangles use
/// consecutive, disjoint runs of vertices that together are all of them
/// (object k's indices within run k); `None` otherwise, or for a single
/// object.
fn vertex_runs(mesh: &TriMesh, objects: &[&Object]) -> Option<Vec<Range<usize>>> {
    if objects.len() < 2 {
        return None;
    }
    let mut runs = Vec::with_capacity(objects.len());
    let mut next = 0;
    for object in objects {
        let triangles = mesh.indices[object.triangles.clone()].iter().flatten();
        let (lo, hi) = triangles.fold((u32::MAX, 0), |(lo, hi), &i| (lo.min(i), hi.max(i)));
        if lo as usize != next {
            return None;
        }
        next = hi as usize + 1;
        runs.push(lo as usize..next);
    }
    (next == mesh.positions.len()).then_some(runs)
}

impl VertexData {
    /// The colours and attributes of the vertices in `run`.
    fn slice(&self, run: Range<usize>) -> VertexData {
        let values = |v: &AttributeValues| match v {
            AttributeValues::Scalar(x) => AttributeValues::Scalar(x[run.clone()].to_vec()),
            AttributeValues::Vec2(x) => AttributeValues::Vec2(x[run.clone()].to_vec()),
            AttributeValues::Vec3(x) => AttributeValues::Vec3(x[run.clone()].to_vec()),
            AttributeValues::Vec4(x) => AttributeValues::Vec4(x[run.clone()].to_vec()),
        };
        VertexData {
            colors: self.colors.as_ref().map(|c| c[run.clone()].to_vec()),
            attributes: self
                .attributes
                .iter()
                .map(|a| super::Attribute {
                    name: a.name.clone(),
                    values: values(&a.values),
                })
                .collect(),
        }
    }
}

/// The per-vertex arrays of one set of vertex accessors.
struct Vertices<'a> {
    positions: &'a [Vec3],
    origin: DVec3,
    normals: Option<&'a [Vec3]>,
    uvs: Option<&'a [glam::Vec2]>,
    uvs1: Option<&'a [glam::Vec2]>,
    data: &'a VertexData,
}

impl<'a> Vertices<'a> {
    /// The vertices of `mesh` in `run` (with `normals`, made unit length),
    /// with `data` for them.
    fn run(
        mesh: &'a TriMesh,
        normals: Option<&'a [Vec3]>,
        run: Range<usize>,
        data: &'a VertexData,
    ) -> Self {
        Vertices {
            positions: &mesh.positions[run.clone()],
            origin: mesh.origin,
            normals: normals.map(|n| &n[run.clone()]),
            uvs: mesh.uvs.as_deref().map(|t| &t[run.clone()]),
            uvs1: mesh.uvs1.as_deref().map(|t| &t[run.clone()]),
            data,
        }
    }
}

/// The JSON under construction and the one binary buffer it refers to.
struct Document<'a> {
    path: &'a Path,
    root: json::Root,
    bin: Vec<u8>,
}

impl<'a> Document<'a> {
    fn new(path: &'a Path) -> Self {
        let mut root = json::Root {
            asset: json::Asset {
                generator: Some(format!("trilux-io {}", env!("CARGO_PKG_VERSION"))),
                ..Default::default()
            },
            ..Default::default()
        };
        let scene = root.push(json::Scene {
            extensions: None,
            extras: Default::default(),
            name: None,
            nodes: Vec::new(),
        });
        root.scene = Some(scene);
        Document {
            path,
            root,
            bin: Vec::new(),
        }
    }

    /// The meshes and nodes of `mesh`: one per object.
    fn mesh(&mut self, mesh: &TriMesh, data: &VertexData) -> Result<()> {
        let normals = match &mesh.normals {
            Some(normals) => Some(unit_normals(
                self.path,
                normals,
                &mesh.indices,
                &mesh.positions,
            )?),
            None => None,
        };
        let all = 0..mesh.positions.len();
        let normals = normals.as_deref();
        let materials = mesh
            .materials
            .iter()
            .map(|m| self.material(m))
            .collect::<Result<Vec<_>>>()?;
        let objects = mesh.objects_or_whole();
        let live: Vec<&Object> = objects.iter().filter(|o| !o.triangles.is_empty()).collect();
        // Objects over consecutive runs of vertices (the pieces of a
        // fracture, concatenated meshes) get accessors of their own, so
        // each loads alone; others share one set.
        let runs = vertex_runs(mesh, &live);
        let shared = match runs {
            Some(_) => None,
            None => Some(self.vertices(&Vertices::run(mesh, normals, all, data))?),
        };
        let origin = mesh.origin.as_vec3();
        let mut fallback = None;
        for (k, object) in live.iter().enumerate() {
            let material = match object.material {
                Some(m) => materials[m],
                None => *fallback.get_or_insert_with(|| self.fallback_material(data)),
            };
            let triangles = &mesh.indices[object.triangles.clone()];
            let (attributes, indices) = match (&shared, &runs) {
                (Some(attributes), _) => (
                    attributes.clone(),
                    self.indices(triangles, mesh.positions.len()),
                ),
                (None, Some(runs)) => {
                    let run = runs[k].clone();
                    let own = data.slice(run.clone());
                    let attributes =
                        self.vertices(&Vertices::run(mesh, normals, run.clone(), &own))?;
                    let first = run.start as u32;
                    let local: Vec<[u32; 3]> =
                        triangles.iter().map(|t| t.map(|i| i - first)).collect();
                    (attributes, self.indices(&local, run.len()))
                }
                (None, None) => unreachable!("one of the two is set"),
            };
            let primitive = json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(indices),
                material: Some(material),
                mode: Valid(Mode::Triangles),
                targets: None,
            };
            self.node(&object.name, primitive, origin);
        }
        Ok(())
    }

    /// Adds a node with one mesh of one primitive to the scene, at the
    /// `f32` part of the global shift (the vertices hold the rest, see
    /// [`Document::vertices`]).
    fn node(&mut self, name: &str, primitive: json::mesh::Primitive, translation: Vec3) {
        let name = (!name.is_empty()).then(|| name.to_string());
        let mesh = self.root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: name.clone(),
            primitives: vec![primitive],
            weights: None,
        });
        let node = self.root.push(json::Node {
            mesh: Some(mesh),
            name,
            translation: (translation != Vec3::ZERO).then(|| translation.to_array()),
            ..Default::default()
        });
        self.root.scenes[0].nodes.push(node);
    }

    /// The vertex accessors: POSITION (with min/max), NORMAL,
    /// TEXCOORD_0/1, COLOR_0 and `_NAME`.
    fn vertices(
        &mut self,
        v: &Vertices<'_>,
    ) -> Result<BTreeMap<Checked<Semantic>, Index<json::Accessor>>> {
        let mut attributes = BTreeMap::new();
        // The part of the shift f32 cannot hold moves into the vertices.
        let residual = (v.origin - v.origin.as_vec3().as_dvec3()).as_vec3();
        let positions: Vec<f32> = v
            .positions
            .iter()
            .flat_map(|&p| (p + residual).to_array())
            .collect();
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(invalid(
                self.path,
                format!("vertex {} has a non-finite position", i / 3),
            ));
        }
        attributes.insert(
            Valid(Semantic::Positions),
            self.floats(&positions, Type::Vec3, true),
        );
        if let Some(normals) = v.normals {
            let flat: Vec<f32> = normals.iter().flat_map(|n| n.to_array()).collect();
            attributes.insert(
                Valid(Semantic::Normals),
                self.floats(&flat, Type::Vec3, false),
            );
        }
        for (set, uvs) in [(0, v.uvs), (1, v.uvs1)] {
            let Some(uvs) = uvs else { continue };
            if let Some(i) = uvs.iter().position(|t| !t.is_finite()) {
                return Err(invalid(
                    self.path,
                    format!("vertex {i} has a non-finite TEXCOORD_{set}"),
                ));
            }
            if uvs.len() != v.positions.len() {
                return Err(invalid(
                    self.path,
                    format!(
                        "{} TEXCOORD_{set} for {} vertices",
                        uvs.len(),
                        v.positions.len()
                    ),
                ));
            }
            let flat: Vec<f32> = uvs.iter().flat_map(|t| t.to_array()).collect();
            attributes.insert(
                Valid(Semantic::TexCoords(set)),
                self.floats(&flat, Type::Vec2, false),
            );
        }
        if let Some(colors) = &v.data.colors {
            // Within COLOR_SLACK of [0, 1] (checked): into it.
            let colors: Vec<[f32; 4]> = colors
                .iter()
                .map(|c| c.map(|v| v.clamp(0.0, 1.0)))
                .collect();
            let opaque = colors.iter().all(|c| c[3] == 1.0);
            let (flat, type_): (Vec<f32>, _) = if opaque {
                let flat = colors.iter().flat_map(|c| [c[0], c[1], c[2]]).collect();
                (flat, Type::Vec3)
            } else {
                (colors.iter().flatten().copied().collect(), Type::Vec4)
            };
            attributes.insert(Valid(Semantic::Colors(0)), self.floats(&flat, type_, false));
        }
        for a in &v.data.attributes {
            let type_ = match a.values.components() {
                1 => Type::Scalar,
                2 => Type::Vec2,
                3 => Type::Vec3,
                _ => Type::Vec4,
            };
            let accessor = self.floats(&a.values.flat(), type_, false);
            attributes.insert(Valid(Semantic::Extras(a.name.clone())), accessor);
        }
        Ok(attributes)
    }

    /// Appends `bytes` to the buffer at a 4-byte boundary as a new view.
    fn view(&mut self, bytes: &[u8], target: Option<Target>) -> Index<json::buffer::View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    /// A tightly packed `f32` vertex accessor of `type_`, with per
    /// component min/max when `bounds` (required for POSITION).
    fn floats(&mut self, values: &[f32], type_: Type, bounds: bool) -> Index<json::Accessor> {
        let c = type_.multiplicity();
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(Target::ArrayBuffer));
        let (min, max) = if bounds {
            let mut lo = vec![f32::INFINITY; c];
            let mut hi = vec![f32::NEG_INFINITY; c];
            for e in values.chunks_exact(c) {
                for k in 0..c {
                    lo[k] = lo[k].min(e[k]);
                    hi[k] = hi[k].max(e[k]);
                }
            }
            (Some(json::Value::from(lo)), Some(json::Value::from(hi)))
        } else {
            (None, None)
        };
        self.accessor(view, values.len() / c, ComponentType::F32, type_, min, max)
    }

    /// The index accessor of `triangles`: `u16` when every index is below
    /// 65 535 (which is the primitive-restart value), else `u32`.
    fn indices(&mut self, triangles: &[[u32; 3]], vertices: usize) -> Index<json::Accessor> {
        self.index_accessor(triangles.as_flattened(), vertices)
    }

    /// The index accessor of line segments (`u16` below 65 535 vertices).
    fn index_pairs(&mut self, pairs: &[[u32; 2]], vertices: usize) -> Index<json::Accessor> {
        self.index_accessor(pairs.as_flattened(), vertices)
    }

    /// An accessor of indices into `vertices` vertices, `u16` when they
    /// all fit below the primitive-restart value 65 535, else `u32`.
    fn index_accessor(&mut self, flat: &[u32], vertices: usize) -> Index<json::Accessor> {
        let (bytes, kind): (Vec<u8>, _) = if vertices <= usize::from(u16::MAX) {
            (
                flat.iter()
                    .flat_map(|&i| (i as u16).to_le_bytes())
                    .collect(),
                ComponentType::U16,
            )
        } else {
            (
                flat.iter().flat_map(|i| i.to_le_bytes()).collect(),
                ComponentType::U32,
            )
        };
        let view = self.view(&bytes, Some(Target::ElementArrayBuffer));
        self.accessor(view, flat.len(), kind, Type::Scalar, None, None)
    }

    fn accessor(
        &mut self,
        view: Index<json::buffer::View>,
        count: usize,
        component: ComponentType,
        type_: Type,
        min: Option<json::Value>,
        max: Option<json::Value>,
    ) -> Index<json::Accessor> {
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// The material of triangles without one: glTF's default is metallic
    /// and single-sided, which viewers draw nearly black (and not at all
    /// from behind). With vertex colours, an unlit one
    /// (`KHR_materials_unlit`) that shows them as they are (a radiance
    /// result is the final colour); otherwise a white dielectric.
    fn fallback_material(&mut self, data: &VertexData) -> Index<json::Material> {
        let unlit = data.colors.is_some();
        let mut material = json::Material {
            name: Some(
                if unlit {
                    UNLIT_MATERIAL
                } else {
                    DEFAULT_MATERIAL
                }
                .into(),
            ),
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(1.0),
                ..Default::default()
            },
            double_sided: true,
            ..Default::default()
        };
        if unlit {
            material.extensions = Some(json::extensions::material::Material {
                unlit: Some(json::extensions::material::Unlit {}),
                ..Default::default()
            });
            self.root.extensions_used.push("KHR_materials_unlit".into());
        }
        self.root.push(material)
    }

    /// A metallic-roughness material for `m`, with its textures embedded.
    fn material(&mut self, m: &Material) -> Result<Index<json::Material>> {
        let texture = self.texture(m)?;
        let scalars = self.scalar_textures(m)?;
        let [r, g, b] = m.diffuse;
        if let Some(bad) = [r, g, b].into_iter().find(|v| !v.is_finite()) {
            return Err(invalid(
                self.path,
                format!(
                    "material {:?} has a non-finite diffuse colour {bad}",
                    m.name
                ),
            ));
        }
        let info = |index| json::texture::Info {
            index,
            tex_coord: 0,
            extensions: None,
            extras: Default::default(),
        };
        // With a metallic-roughness texture the factors scale it: 1.
        let textured = scalars.metallic_roughness.is_some();
        let pbr = json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor([
                r.max(0.0),
                g.max(0.0),
                b.max(0.0),
                1.0,
            ]),
            base_color_texture: texture.map(info),
            metallic_factor: json::material::StrengthFactor(if textured { 1.0 } else { 0.0 }),
            roughness_factor: json::material::StrengthFactor(1.0),
            metallic_roughness_texture: scalars.metallic_roughness.map(info),
            ..Default::default()
        };
        let occlusion_texture = scalars
            .occlusion
            .map(|index| json::material::OcclusionTexture {
                index,
                strength: json::material::StrengthFactor(1.0),
                tex_coord: 0,
                extensions: None,
                extras: Default::default(),
            });
        Ok(self.root.push(json::Material {
            name: (!m.name.is_empty()).then(|| m.name.clone()),
            pbr_metallic_roughness: pbr,
            occlusion_texture,
            // Scanned and converted meshes often have faces wound both
            // ways; a viewer must not show them as holes.
            double_sided: true,
            extras: scalars.extras,
            ..Default::default()
        }))
    }

    /// The material's base colour texture: its decoded image as PNG, or
    /// its file's bytes (PNG and JPEG as they are, others as PNG).
    fn texture(&mut self, m: &Material) -> Result<Option<Index<json::Texture>>> {
        let (bytes, mime) = match (&m.diffuse_image, &m.diffuse_texture) {
            (Some(image), _) => (
                image::encode_png(image, PngDepth::Eight, self.path)?,
                "image/png",
            ),
            (None, Some(file)) => {
                let bytes = std::fs::read(file).map_err(|e| {
                    invalid(
                        self.path,
                        format!(
                            "the texture {} of material {:?} cannot be read ({e})",
                            file.display(),
                            m.name
                        ),
                    )
                })?;
                if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
                    (bytes, "image/png")
                } else if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
                    (bytes, "image/jpeg")
                } else {
                    let decoded = image::decode(&bytes, file, image::ReadOptions::default())?;
                    (
                        image::encode_png(&decoded, PngDepth::Eight, file)?,
                        "image/png",
                    )
                }
            }
            (None, None) => return Ok(None),
        };
        let name = (!m.name.is_empty()).then(|| m.name.clone());
        Ok(Some(self.embed_texture(&bytes, mime, name, m.wrap)))
    }

    /// The material's scalar textures ([`Material::scalar_images`]) as
    /// data PNGs: roughness and metallic packed into one
    /// metallic-roughness texture (G, B), occlusion in R of its own, the
    /// others each in a gray texture listed in the extras.
    fn scalar_textures(&mut self, m: &Material) -> Result<ScalarTextures> {
        let mut out = ScalarTextures::default();
        let images = &m.scalar_images;
        for (k, (name, image)) in images.iter().enumerate() {
            image.check(self.path)?;
            if images[..k].iter().any(|(other, _)| other == name) {
                return Err(invalid(
                    self.path,
                    format!(
                        "material {:?} has two scalar textures named {name:?}",
                        m.name
                    ),
                ));
            }
        }
        let find = |wanted: &str| images.iter().find(|(n, _)| n == wanted).map(|(_, i)| i);
        let (roughness, metallic) = (find("roughness"), find("metallic"));
        if let Some(first) = roughness.or(metallic) {
            if let (Some(r), Some(mt)) = (roughness, metallic)
                && (r.width, r.height) != (mt.width, mt.height)
            {
                return Err(invalid(
                    self.path,
                    format!(
                        "material {:?}: roughness is {}×{} and metallic {}×{}; glTF packs them \
                         into one texture, so they must be the same size",
                        m.name, r.width, r.height, mt.width, mt.height
                    ),
                ));
            }
            // Absent, roughness is 1 and metallic 0: glTF's factors then
            // leave the material as it would be without the texture.
            let value = |image: Option<&image::Image>, i: usize, default: f32| {
                image.map_or(default, |image| image.pixels[i][0])
            };
            let pixels = (0..first.pixels.len())
                .map(|i| [1.0, value(roughness, i, 1.0), value(metallic, i, 0.0), 1.0])
                .collect();
            let packed = image::Image {
                width: first.width,
                height: first.height,
                pixels,
            };
            let name = format!("{} metallic-roughness", m.name).trim().to_string();
            out.metallic_roughness = Some(self.data_texture(&packed, name, m.wrap)?);
        }
        if let Some(occlusion) = find("occlusion") {
            let name = format!("{} occlusion", m.name).trim().to_string();
            out.occlusion = Some(self.data_texture(&gray(occlusion), name, m.wrap)?);
        }
        let mut listed = serde_json::Map::new();
        for (name, image) in images {
            if !["roughness", "metallic", "occlusion"].contains(&name.as_str()) {
                let index = self.data_texture(&gray(image), name.clone(), m.wrap)?;
                listed.insert(name.clone(), index.value().into());
            }
        }
        if !listed.is_empty() {
            let extras = serde_json::json!({ "scalar_textures": listed });
            out.extras = serde_json::value::to_raw_value(&extras).ok();
        }
        Ok(out)
    }

    /// A data texture (no sRGB curve) embedded as PNG.
    fn data_texture(
        &mut self,
        image: &image::Image,
        name: String,
        wrap: [Wrap; 2],
    ) -> Result<Index<json::Texture>> {
        let bytes = image::encode_data_png(image, PngDepth::Eight, self.path)?;
        Ok(self.embed_texture(&bytes, "image/png", Some(name), wrap))
    }

    /// An image in the binary buffer, its sampler and its texture.
    fn embed_texture(
        &mut self,
        bytes: &[u8],
        mime: &str,
        name: Option<String>,
        wrap: [Wrap; 2],
    ) -> Index<json::Texture> {
        let view = self.view(bytes, None);
        let source = self.root.push(json::Image {
            buffer_view: Some(view),
            mime_type: Some(json::image::MimeType(mime.into())),
            name: name.clone(),
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        let mode = |w: Wrap| {
            Valid(match w {
                Wrap::Repeat => json::texture::WrappingMode::Repeat,
                Wrap::MirroredRepeat => json::texture::WrappingMode::MirroredRepeat,
                Wrap::ClampToEdge => json::texture::WrappingMode::ClampToEdge,
            })
        };
        let sampler = self.root.push(json::texture::Sampler {
            wrap_s: mode(wrap[0]),
            wrap_t: mode(wrap[1]),
            ..Default::default()
        });
        self.root.push(json::Texture {
            name,
            sampler: Some(sampler),
            source,
            extensions: None,
            extras: Default::default(),
        })
    }

    /// Writes the file (and the `.bin` of a `.gltf`).
    fn save(mut self, container: Container) -> Result<()> {
        let path = self.path;
        if !self.bin.is_empty() {
            let uri = match container {
                Container::Binary => None,
                Container::Json => Some(percent_encode(&bin_name(path))),
            };
            self.root.buffers.push(json::Buffer {
                byte_length: USize64::from(self.bin.len()),
                name: None,
                uri,
                extensions: None,
                extras: Default::default(),
            });
        }
        let json = self.root.to_vec().map_err(|e| {
            Error::new(
                path,
                ErrorKind::Codec {
                    format: "glTF",
                    source: Box::new(e),
                },
            )
        })?;
        let bytes = match container {
            Container::Json => {
                if !self.bin.is_empty() {
                    let bin = path.with_file_name(bin_name(path));
                    std::fs::write(&bin, &self.bin).map_err(|e| Error::io(&bin, e))?;
                }
                json
            }
            Container::Binary => {
                // 12-byte header, two 8-byte chunk headers, padding.
                let total = 28 + json.len() + self.bin.len() + 6;
                if u32::try_from(total).is_err() {
                    return Err(invalid(
                        path,
                        format!(
                            "{total} bytes do not fit a GLB (4 GiB at most); write .gltf, whose \
                             .bin has no such limit"
                        ),
                    ));
                }
                let glb = gltf::binary::Glb {
                    header: gltf::binary::Header {
                        magic: *b"glTF",
                        version: 2,
                        length: total as u32,
                    },
                    json: Cow::Owned(json),
                    bin: (!self.bin.is_empty()).then_some(Cow::Owned(self.bin)),
                };
                glb.to_vec().map_err(|e| {
                    Error::new(
                        path,
                        ErrorKind::Codec {
                            format: "GLB",
                            source: Box::new(e),
                        },
                    )
                })?
            }
        };
        std::fs::write(path, bytes).map_err(|e| Error::io(path, e))
    }
}

/// The name of a `.gltf`'s buffer file: its own name with `.bin`.
/// What [`Document::scalar_textures`] embedded for one material.
#[derive(Default)]
struct ScalarTextures {
    metallic_roughness: Option<Index<json::Texture>>,
    occlusion: Option<Index<json::Texture>>,
    /// `{"scalar_textures": {name: index}}` for the ones glTF has no slot for.
    extras: json::extras::Extras,
}

/// A scalar image (its red channel) as gray, opaque.
fn gray(image: &image::Image) -> image::Image {
    let pixels = image
        .pixels
        .iter()
        .map(|p| [p[0], p[0], p[0], 1.0])
        .collect();
    image::Image {
        width: image.width,
        height: image.height,
        pixels,
    }
}

fn bin_name(path: &Path) -> String {
    path.with_extension("bin")
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "buffer.bin".into())
}

/// `name` as a relative URI reference: RFC 3986's unreserved characters
/// as they are, every other byte percent-encoded.
fn percent_encode(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    for b in name.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// A primitive without a material (points, lines): its attributes, its
/// indices if any, and how they are drawn.
fn bare_primitive(
    attributes: BTreeMap<Checked<Semantic>, Index<json::Accessor>>,
    indices: Option<Index<json::Accessor>>,
    mode: Mode,
) -> json::mesh::Primitive {
    json::mesh::Primitive {
        attributes,
        extensions: None,
        extras: Default::default(),
        indices,
        material: None,
        mode: Valid(mode),
        targets: None,
    }
}
