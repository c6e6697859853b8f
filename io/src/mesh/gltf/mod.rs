//! glTF 2.0 (`.gltf` with external or `data:` buffers, and binary `.glb`),
//! in and out.
//!
//! # Reading
//!
//! [`read`] returns every triangle primitive of the default scene with its
//! node transforms applied; POSITION, NORMAL, the base-colour texture's
//! `TEXCOORD_n` (and `TEXCOORD_1` as [`TriMesh::uvs1`]) and indices;
//! base-colour factor and texture (embedded or external, decoded), with
//! its wrap modes. [`read_scene`] also returns what a [`TriMesh`] has no
//! place for: `COLOR_0` and application-specific `_NAME` attributes
//! ([`VertexData`]), and the `POINTS` primitives ([`Points`]).
//!
//! One decoder reads every accessor (glTF 2.0 Sec. 3.6.2): float and
//! integer component types, normalized integers mapped to `[0, 1]` or
//! `[-1, 1]` (Sec. 3.11), non-normalized integers as their values
//! (`KHR_mesh_quantization`), and sparse substitution over a buffer view
//! or over zeros. `KHR_texture_transform` on the base-colour texture is
//! applied to the UVs. A file that requires any other extension is refused
//! with an error naming it: a silently wrong mesh is worse than none.
//!
//! The `gltf` crate parses the JSON and GLB container (its headers checked
//! here first); buffers and images are resolved here, so that a file
//! cannot make the reader open anything outside its own folder: absolute
//! paths, `..` and remote schemes are refused unless
//! [`Options::allow_outside_folder`] is set. Every accessor is checked
//! against its buffer before it is read.
//!
//! # Writing
//!
//! [`write()`] (also [`TriMesh::write`] with `.glb` or `.gltf`), [`write_with`]
//! (vertex colours and `_NAME` attributes beside the mesh) and
//! [`write_points`] (a `POINTS` primitive) serialise through the gltf-rs
//! project's own JSON types (`gltf-json`). What [`read_scene`] returns
//! from a written file equals what was written (see each writer for the
//! conversions: normals normalised, textures as 8-bit sRGB PNG).
//!
//! ```
//! use trilux_io::glam::Vec3;
//! use trilux_io::mesh::gltf::{self, Attribute, AttributeValues, VertexData};
//! use trilux_io::mesh::TriMesh;
//!
//! let mesh = TriMesh {
//!     positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
//!     indices: vec![[0, 1, 2]],
//!     ..TriMesh::default()
//! };
//! let data = VertexData {
//!     colors: Some(vec![[1.0, 0.0, 0.0, 1.0]; 3]),
//!     attributes: vec![Attribute {
//!         name: "PHI".into(),
//!         values: AttributeValues::Scalar(vec![0.5, 1.0, 2.0]),
//!     }],
//! };
//! let path = std::env::temp_dir().join(format!("trilux-io-doc-{}.glb", std::process::id()));
//! gltf::write_with(&path, &mesh, &data)?;
//! let scene = gltf::read_scene(&path)?;
//! assert_eq!((scene.mesh.indices, scene.vertex_data), (mesh.indices, data));
//! # std::fs::remove_file(&path).unwrap();
//! # Ok::<(), trilux_io::Error>(())
//! ```

use glam::{DVec3, Vec2, Vec3};

use super::TriMesh;

mod read;
mod write;

pub use read::{
    MAX_ACCESSOR_VALUES, MAX_ZERO_FILLED_ELEMENTS, Options, from_bytes, read, read_scene,
    read_scene_with, read_with, scene_from_bytes,
};
pub(crate) use write::write_curves;
pub use write::{COLOR_SLACK, DEFAULT_MATERIAL, UNLIT_MATERIAL, write, write_points, write_with};

/// Per-vertex values beyond positions, normals and UVs that glTF carries:
/// vertex colours and application-specific attributes. Every array has
/// one entry per vertex.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VertexData {
    /// `COLOR_0`: linear RGBA in `[0, 1]`, which glTF viewers multiply
    /// into the base colour. Written as `VEC3` when every alpha is 1.
    pub colors: Option<Vec<[f32; 4]>>,
    /// Application-specific attributes (glTF 2.0 Sec. 3.7.2.1), written
    /// as `_NAME` accessors of `f32` components. three.js exposes them as
    /// `geometry.attributes._name` (lower case), Blender as attributes
    /// named `_NAME`.
    pub attributes: Vec<Attribute>,
}

/// A named per-vertex attribute.
#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    /// The name without glTF's leading underscore (`PHI` is stored as
    /// `_PHI`): ASCII letters, digits and `_`.
    pub name: String,
    /// One value per vertex.
    pub values: AttributeValues,
}

/// The values of an [`Attribute`]: glTF's `SCALAR`, `VEC2`, `VEC3` or
/// `VEC4` accessor types, in `f32` (application-specific attributes may
/// not use unsigned 32-bit integers, so indices such as a face id are
/// stored as floats, exact below 2^24).
#[derive(Debug, Clone, PartialEq)]
pub enum AttributeValues {
    /// One number per vertex.
    Scalar(Vec<f32>),
    /// Two numbers per vertex.
    Vec2(Vec<Vec2>),
    /// Three numbers per vertex (a linear RGB radiance, a vector).
    Vec3(Vec<Vec3>),
    /// Four numbers per vertex.
    Vec4(Vec<[f32; 4]>),
}

impl AttributeValues {
    /// The number of vertices the attribute has values for.
    pub fn len(&self) -> usize {
        match self {
            AttributeValues::Scalar(v) => v.len(),
            AttributeValues::Vec2(v) => v.len(),
            AttributeValues::Vec3(v) => v.len(),
            AttributeValues::Vec4(v) => v.len(),
        }
    }

    /// Whether there are no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The number of components per vertex (1 to 4).
    pub fn components(&self) -> usize {
        match self {
            AttributeValues::Scalar(_) => 1,
            AttributeValues::Vec2(_) => 2,
            AttributeValues::Vec3(_) => 3,
            AttributeValues::Vec4(_) => 4,
        }
    }

    /// The values as a flat array, `components()` per vertex.
    pub fn flat(&self) -> Vec<f32> {
        match self {
            AttributeValues::Scalar(v) => v.clone(),
            AttributeValues::Vec2(v) => v.iter().flat_map(|x| x.to_array()).collect(),
            AttributeValues::Vec3(v) => v.iter().flat_map(|x| x.to_array()).collect(),
            AttributeValues::Vec4(v) => v.iter().flatten().copied().collect(),
        }
    }

    /// From `components` (1 to 4; otherwise treated as 1) values per
    /// vertex.
    fn from_components(components: usize, values: Vec<f32>) -> Self {
        match components {
            2 => AttributeValues::Vec2(
                values
                    .chunks_exact(2)
                    .map(|c| Vec2::new(c[0], c[1]))
                    .collect(),
            ),
            3 => AttributeValues::Vec3(
                values
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2]))
                    .collect(),
            ),
            4 => AttributeValues::Vec4(
                values
                    .chunks_exact(4)
                    .map(|c| [c[0], c[1], c[2], c[3]])
                    .collect(),
            ),
            _ => AttributeValues::Scalar(values),
        }
    }
}

/// A point cloud as glTF stores it: a `POINTS` primitive. Sampled points
/// carry their normals, UVs, and the triangle each lies on (`From<&PlyData>`
/// makes one from the [`PlyData`](super::ply::PlyData) trilux's samplers
/// fill).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Points {
    /// Positions, relative to `origin`.
    pub positions: Vec<Vec3>,
    /// The global shift of far-from-origin coordinates, as
    /// [`TriMesh::origin`]; written as the node's translation.
    pub origin: DVec3,
    /// Per-point unit normals (`NORMAL`).
    pub normals: Option<Vec<Vec3>>,
    /// Per-point texture coordinates (`TEXCOORD_0`, glTF's v-down
    /// convention, as [`TriMesh::uvs`]).
    pub uvs: Option<Vec<Vec2>>,
    /// The triangle each point lies on, stored as the `_FACE` attribute
    /// (`f32`, so below 2^24: [`write_points`] refuses larger ids). The
    /// reader returns a `_FACE` attribute here when every value is a
    /// non-negative integer below 2^24.
    pub faces: Option<Vec<u32>>,
    /// Per-point colours and other attributes.
    pub vertex_data: VertexData,
}

/// The name of the attribute that holds each sampled point's triangle.
pub const FACE_ATTRIBUTE: &str = "FACE";

/// Face ids below this (2^24) are exact in the `f32` `_FACE` attribute
/// ([`write_points`] refuses larger ones; glTF attributes may not be
/// 32-bit integers).
pub const FACE_ID_LIMIT: u32 = 1 << 24;

impl From<&super::ply::PlyData> for Points {
    /// The points of PLY data: positions, origin, normals, UVs and face
    /// ids as they are; RGBA 8-bit colours as linear `[0, 1]`, RGB decoded
    /// from sRGB (PLY colours are display values, as 8-bit images are;
    /// viewers then show them as other tools do) and alpha as `c / 255`;
    /// other scalars as attributes under their names. Triangles, if any,
    /// are not part of a point cloud and are left out.
    fn from(ply: &super::ply::PlyData) -> Self {
        Points {
            positions: ply.positions.clone(),
            origin: ply.origin,
            normals: ply.normals.clone(),
            uvs: ply.uvs.clone(),
            faces: ply.face_ids.clone(),
            vertex_data: VertexData {
                colors: ply.colors.as_ref().map(|c| {
                    c.iter()
                        .map(|p| {
                            let [r, g, b, a] = p.map(|v| f32::from(v) / 255.0);
                            let decode = crate::image::srgb_to_linear;
                            [decode(r), decode(g), decode(b), a]
                        })
                        .collect()
                }),
                attributes: ply
                    .scalars
                    .iter()
                    .map(|(name, values)| Attribute {
                        name: name.clone(),
                        values: AttributeValues::Scalar(values.clone()),
                    })
                    .collect(),
            },
        }
    }
}

impl Points {
    /// The values of attribute `name`, if the points have it.
    pub fn attribute(&self, name: &str) -> Option<&AttributeValues> {
        self.vertex_data.attribute(name)
    }
}

impl VertexData {
    /// The values of attribute `name`, if present.
    pub fn attribute(&self, name: &str) -> Option<&AttributeValues> {
        self.attributes
            .iter()
            .find(|a| a.name == name)
            .map(|a| &a.values)
    }
}

/// What a glTF file's default scene holds: the triangles as one
/// [`TriMesh`] (what [`read`] returns) with their colours and custom
/// attributes, and the points of its `POINTS` primitives.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scene {
    /// Every triangle primitive, as [`read`] returns it.
    pub mesh: TriMesh,
    /// `COLOR_0` and `_NAME` attributes of the mesh's vertices.
    pub vertex_data: VertexData,
    /// Every `POINTS` primitive, concatenated (empty when there is none).
    pub points: Points,
}

impl Scene {
    /// The triangle mesh, with a warning when the file also held points
    /// (which a [`TriMesh`] cannot hold).
    fn into_mesh(self, path: &std::path::Path) -> TriMesh {
        let mut mesh = self.mesh;
        if !self.points.positions.is_empty() {
            mesh.warnings.push(crate::Warning::new(
                path,
                None,
                format!(
                    "the file also holds {} points (POINTS primitives), which a triangle mesh \
                     does not keep; gltf::read_scene returns them",
                    self.points.positions.len()
                ),
            ));
        }
        mesh
    }
}
