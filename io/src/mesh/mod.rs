//! Triangle meshes: the plain data every triangle-mesh reader returns.

use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use crate::error::{Error, ErrorKind, Result};
use crate::image::Image;

pub mod gltf;
pub mod obj;
pub mod ply;

/// A triangle mesh as plain data, with one index stream: attributes are
/// per vertex, and a vertex that has several UVs or normals in the file
/// (a seam) is split into several vertices.
///
/// # UV convention
///
/// Texture coordinates follow glTF: the origin is the top-left corner of
/// the image and v grows downwards, so `uv * (width, height)` is a texel
/// coordinate with row 0 the first row stored in the image file (the row
/// [`Image::pixels`] starts with). OBJ and PLY files store v upwards:
/// their readers in this crate turn it into `1 - v` and their writers
/// turn it back, which is the only place a flip happens. glTF UVs are kept
/// as stored. Values outside `[0, 1]` (tiling) are kept; the material's
/// [`Wrap`] says what they mean. Flipping in `f32` is exact for the values
/// a texture atlas usually holds (multiples of powers of two) and within
/// 2^-24 otherwise.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Three 0-based vertex indices per triangle, counter-clockwise as the
    /// file orders them.
    pub indices: Vec<[u32; 3]>,
    /// Per-vertex normals, when the file has them.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, when the file has them; v down,
    /// `v = 0` at image row 0 (see the [UV convention](#uv-convention)).
    pub uvs: Option<Vec<Vec2>>,
    /// Consecutive triangle ranges per object, group or material.
    pub objects: Vec<Object>,
    /// Materials, indexed by [`Object::material`].
    pub materials: Vec<Material>,
}

/// A named run of triangles with one material.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    /// The object or group name (empty when the file gives none).
    pub name: String,
    /// The triangles, as a range of [`TriMesh::indices`].
    pub triangles: Range<usize>,
    /// Index into [`TriMesh::materials`], if the triangles have one.
    pub material: Option<usize>,
}

/// What a renderer or sampler needs of a material.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// The material name.
    pub name: String,
    /// Diffuse (base) colour, linear RGB.
    pub diffuse: [f32; 3],
    /// The diffuse (base colour) texture file, resolved against the mesh
    /// file's folder, when it is a file.
    pub diffuse_texture: Option<PathBuf>,
    /// The decoded base colour texture, when the reader decodes it (glTF:
    /// embedded or external). OBJ leaves it to the caller
    /// ([`crate::image::read`] of `diffuse_texture`).
    pub diffuse_image: Option<Image>,
    /// How the texture repeats outside `[0, 1]` along u and v.
    pub wrap: [Wrap; 2],
}

/// Texture wrap mode (glTF sampler modes; OBJ/MTL textures repeat).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wrap {
    /// Tile the texture.
    Repeat,
    /// Tile, mirroring every other copy.
    MirroredRepeat,
    /// Extend the edge texels.
    ClampToEdge,
}

impl TriMesh {
    /// Reads a triangle mesh, choosing the format by extension: `.obj`,
    /// `.gltf`, `.glb` (URIs confined to the file's folder), `.ply`.
    ///
    /// # Errors
    /// [`Error`] naming the file, the line, and what was wrong.
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        match crate::error::extension(path).as_str() {
            "obj" => obj::read(path),
            "gltf" | "glb" => gltf::read(path),
            "ply" => {
                let ply = ply::read(path)?;
                Ok(TriMesh {
                    objects: vec![Object {
                        name: String::new(),
                        triangles: 0..ply.triangles.len(),
                        material: None,
                    }],
                    positions: ply.positions,
                    indices: ply.triangles,
                    normals: ply.normals,
                    uvs: ply.uvs,
                    materials: Vec::new(),
                })
            }
            other => Err(Error::new(
                path,
                ErrorKind::UnknownExtension(other.to_string(), ".obj, .gltf, .glb, .ply"),
            )),
        }
    }

    /// The total surface area.
    pub fn area(&self) -> f64 {
        self.indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize].as_dvec3());
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }
}
