//! Triangle meshes: the plain data every triangle-mesh reader returns.

use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec2, Vec3};

use crate::error::{Error, ErrorKind, Result};
use crate::image::Image;
use crate::warning::Warning;

mod glb;
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
/// a texture atlas usually holds (multiples of powers of two) and
/// otherwise within half an `f32` step of `max(1, |v|)`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions, relative to [`origin`](Self::origin): the point a
    /// file puts vertex `i` at is `origin + positions[i].as_dvec3()`.
    pub positions: Vec<Vec3>,
    /// The global shift (as CloudCompare calls it) that keeps the
    /// precision of a file whose coordinates are far from zero: zero for
    /// ordinary files, and otherwise the centre of the bounding box (whole
    /// units when the mesh is at least one unit across). The readers
    /// parse coordinates in `f64` and subtract it before storing `f32`, so
    /// a georeferenced scan at x ≈ 4·10^5, y ≈ 4.6·10^6 keeps millimetre
    /// triangles instead of collapsing them. Shifted when the largest
    /// coordinate magnitude is at least 10^5 (CloudCompare's default; the
    /// `f32` step there is 1/128) or more than 2^12 times the mesh's size.
    /// Writers add it back in `f64`. glTF stores `f32` vertices, but its
    /// node transforms may carry them far away (a georeferenced tile): the
    /// reader applies them in `f64` and picks the shift the same way.
    pub origin: DVec3,
    /// Three 0-based vertex indices per triangle, counter-clockwise as the
    /// file orders them.
    pub indices: Vec<[u32; 3]>,
    /// Per-vertex normals, when the file has them.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, when the file has them; v down,
    /// `v = 0` at image row 0 (see the [UV convention](#uv-convention)).
    pub uvs: Option<Vec<Vec2>>,
    /// A second set of texture coordinates: glTF's `TEXCOORD_1` as stored
    /// (lightmap or detail UVs; no texture transform applied), when the
    /// file has it. OBJ and PLY have one set only.
    pub uvs1: Option<Vec<Vec2>>,
    /// Consecutive triangle ranges per object, group or material.
    pub objects: Vec<Object>,
    /// Materials, indexed by [`Object::material`].
    pub materials: Vec<Material>,
    /// What the reader skipped or replaced by a default without refusing
    /// the file, each naming the file, the element and what was skipped:
    /// a PLY element or property it does not read, a missing `.mtl` or
    /// texture, a `usemtl` no library defines, `f v/vt/vn` corners in a
    /// file without `vt` lines (the UV indices dropped), a glTF texture
    /// whose image is only in an extension. Empty for a file read whole.
    pub warnings: Vec<Warning>,
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
    /// The diffuse (base colour) texture file the mesh file names,
    /// resolved against its folder. It may not exist: the readers then
    /// say so in [`TriMesh::warnings`] and read the mesh anyway.
    pub diffuse_texture: Option<PathBuf>,
    /// The decoded base colour texture, when the reader decodes it (glTF:
    /// embedded or external). OBJ leaves it to the caller
    /// ([`crate::image::read`] of `diffuse_texture`).
    pub diffuse_image: Option<Image>,
    /// How the texture repeats outside `[0, 1]` along u and v.
    pub wrap: [Wrap; 2],
    /// Scalar textures on the same UVs, by name: `roughness`, `metallic`,
    /// `occlusion`, or any other (a painted `density`), the value in each
    /// pixel's red channel, linear, 0–1. The glTF writer puts `roughness`
    /// and `metallic` into the material's metallic-roughness texture (G
    /// and B, factors 1), `occlusion` into its occlusion texture, and any
    /// other into a texture of its own, named after it and listed in the
    /// material's `extras` as `{"scalar_textures": {name: texture index}}`
    /// (glTF has no slot for it; a viewer shows the material without it).
    /// The OBJ writer and the readers leave them out.
    pub scalar_images: Vec<(String, Image)>,
}

/// Texture wrap mode (glTF sampler modes; OBJ/MTL textures repeat unless
/// `-clamp on`). The same enum, with the same meaning, is used by every
/// trilux crate that has wrap modes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Wrap {
    /// Tile the texture.
    #[default]
    Repeat,
    /// Tile, mirroring every other copy.
    MirroredRepeat,
    /// Extend the edge texels.
    ClampToEdge,
}

/// The largest coordinate magnitude kept without a shift (CloudCompare's
/// default threshold).
const SHIFT_ABOVE: f64 = 1e5;
/// A shift also happens when the coordinates are this many times larger
/// than the bounding box: the `f32` step would exceed 2^-12 of the size.
const SHIFT_RATIO: f64 = 4096.0;

/// The global shift for points with coordinates `points` (see
/// [`TriMesh::origin`]) and the points relative to it as `f32`: what the
/// readers do, for meshes made of arrays elsewhere (the Python package).
pub fn recenter(points: &[DVec3]) -> (DVec3, Vec<Vec3>) {
    let origin = shift_for(points);
    let relative = points.iter().map(|&p| (p - origin).as_vec3()).collect();
    (origin, relative)
}

/// The origin [`recenter`] uses: zero unless the coordinates are far from
/// it relative to the box.
pub(crate) fn shift_for(points: &[DVec3]) -> DVec3 {
    let Some(first) = points.first() else {
        return DVec3::ZERO;
    };
    let (lo, hi) = points
        .iter()
        .fold((*first, *first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let magnitude = lo.abs().max(hi.abs()).max_element();
    let extent = (hi - lo).max_element();
    // A single point (zero extent) shifts only beyond the absolute bound.
    let far = magnitude >= SHIFT_ABOVE || (extent > 0.0 && magnitude > SHIFT_RATIO * extent);
    if !far || !magnitude.is_finite() {
        return DVec3::ZERO;
    }
    let center = 0.5 * (lo + hi);
    if extent >= 1.0 {
        center.round()
    } else {
        center
    }
}

/// Reads a triangle mesh, choosing the format by extension (see
/// [`TriMesh::read`]).
///
/// # Errors
/// [`Error`] naming the file, the line, and what was wrong.
pub fn read(path: impl AsRef<Path>) -> Result<TriMesh> {
    TriMesh::read(path)
}

/// Writes a triangle mesh, choosing the format by extension (see
/// [`TriMesh::write`]).
///
/// # Errors
/// As for [`TriMesh::write`].
pub fn write(path: impl AsRef<Path>, mesh: &TriMesh) -> Result<()> {
    mesh.write(path)
}

/// The triangle mesh of a PLY file: one object, and a material when the
/// header names a texture (`comment TextureFile`), which is resolved
/// against the file's folder (a warning when it does not exist).
fn from_ply(path: &Path, ply: ply::PlyData) -> TriMesh {
    let mut warnings = ply.warnings;
    let mut materials = Vec::new();
    if let Some(name) = &ply.texture_file {
        let folder = path.parent().unwrap_or(Path::new("."));
        let file = folder.join(name);
        if !file.is_file() {
            warnings.push(Warning::new(
                &file,
                None,
                format!(
                    "the texture named by `comment TextureFile` in {} does not exist; the mesh \
                     is read without it",
                    path.display()
                ),
            ));
        }
        materials.push(Material {
            name: Path::new(name)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            diffuse: [1.0; 3],
            diffuse_texture: Some(file),
            diffuse_image: None,
            wrap: [Wrap::Repeat; 2],
            scalar_images: Vec::new(),
        });
    }
    TriMesh {
        origin: ply.origin,
        uvs1: None,
        objects: vec![Object {
            name: String::new(),
            triangles: 0..ply.triangles.len(),
            material: (!materials.is_empty()).then_some(0),
        }],
        positions: ply.positions,
        indices: ply.triangles,
        normals: ply.normals,
        uvs: ply.uvs,
        materials,
        warnings,
    }
}

impl TriMesh {
    /// The positions as the file has them, in `f64`: `origin + p`.
    pub fn absolute_positions(&self) -> Vec<DVec3> {
        self.positions
            .iter()
            .map(|p| self.origin + p.as_dvec3())
            .collect()
    }

    /// Reads a triangle mesh, choosing the format by extension: `.obj`,
    /// `.gltf`, `.glb` (URIs confined to the file's folder), `.ply`.
    ///
    /// # Errors
    /// [`Error`] naming the file, the line, and what was wrong.
    ///
    /// # Example
    /// ```
    /// use trilux_io::mesh::TriMesh;
    /// let path = std::env::temp_dir().join(format!("trilux-io-doc-{}.obj", std::process::id()));
    /// std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    /// let mesh = TriMesh::read(&path)?;
    /// assert_eq!((mesh.positions.len(), mesh.indices), (3, vec![[0, 1, 2]]));
    /// # std::fs::remove_file(&path).unwrap();
    /// // An unknown extension is refused, naming the file.
    /// let e = TriMesh::read("model.stl").unwrap_err();
    /// assert!(e.to_string().starts_with("model.stl: "));
    /// # Ok::<(), trilux_io::Error>(())
    /// ```
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        match crate::error::extension(path).as_str() {
            "obj" => obj::read(path),
            "gltf" | "glb" => gltf::read(path),
            "ply" => Ok(from_ply(path, ply::read(path)?)),
            other => Err(Error::new(
                path,
                ErrorKind::UnknownExtension(other.to_string(), ".obj, .gltf, .glb, .ply"),
            )),
        }
    }

    /// Writes the mesh, choosing the format by extension: `.obj` (with its
    /// `.mtl` and textures, see [`obj::write`]), `.ply` (binary
    /// little-endian with normals and UVs; objects and materials are not
    /// part of PLY and are not written, see [`ply::write`]), or `.glb` /
    /// `.gltf` (with objects, materials and embedded textures, see
    /// [`gltf::write`]).
    ///
    /// # Errors
    /// [`ErrorKind::UnknownExtension`] for other extensions; the writer's
    /// errors.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        match crate::error::extension(path).as_str() {
            "obj" => obj::write(path, self),
            "gltf" | "glb" => gltf::write(path, self),
            "ply" => {
                // A texture file is named as MeshLab does, when the first
                // material has one inside the file's folder.
                let folder = path.parent().unwrap_or(Path::new(""));
                let texture_file = self
                    .materials
                    .first()
                    .and_then(|m| m.diffuse_texture.as_ref())
                    .and_then(|t| t.strip_prefix(folder).ok())
                    .and_then(|t| t.to_str())
                    .map(str::to_string);
                let data = ply::PlyData {
                    texture_file,
                    positions: self.positions.clone(),
                    origin: self.origin,
                    triangles: self.indices.clone(),
                    normals: self.normals.clone(),
                    uvs: self.uvs.clone(),
                    ..ply::PlyData::default()
                };
                ply::write(path, &data, ply::Format::BinaryLittleEndian)
            }
            other => Err(Error::new(
                path,
                ErrorKind::UnknownExtension(other.to_string(), ".obj, .ply, .glb, .gltf"),
            )),
        }
    }

    /// The objects, or one unnamed object of every triangle without a
    /// material when the mesh has none: what a writer writes as groups.
    pub(crate) fn objects_or_whole(&self) -> std::borrow::Cow<'_, [Object]> {
        if self.objects.is_empty() {
            std::borrow::Cow::Owned(vec![Object {
                name: String::new(),
                triangles: 0..self.indices.len(),
                material: None,
            }])
        } else {
            std::borrow::Cow::Borrowed(&self.objects)
        }
    }

    /// Checks what every writer needs of the layout: attribute arrays of
    /// the vertex count, indices in range, objects that cover the
    /// triangles in order with materials that exist, a finite origin.
    ///
    /// # Errors
    /// [`ErrorKind::InvalidInput`] naming `path`, the element and the
    /// problem.
    pub(crate) fn check_layout(&self, path: &Path) -> Result<()> {
        let invalid = |what: String| Error::new(path, ErrorKind::InvalidInput(what));
        let n = self.positions.len();
        let arrays = [
            ("UVs", self.uvs.as_ref().map(Vec::len)),
            ("second UVs", self.uvs1.as_ref().map(Vec::len)),
            ("normals", self.normals.as_ref().map(Vec::len)),
        ];
        for (what, len) in arrays {
            if let Some(len) = len.filter(|&l| l != n) {
                return Err(invalid(format!("{len} {what} for {n} positions")));
            }
        }
        if let Some((t, _)) = self
            .indices
            .iter()
            .enumerate()
            .find(|(_, tri)| tri.iter().any(|&i| i as usize >= n))
        {
            return Err(invalid(format!("triangle {t} references a missing vertex")));
        }
        let mut end = 0;
        for o in &self.objects {
            if o.triangles.start != end || o.triangles.end < o.triangles.start {
                return Err(invalid(format!(
                    "object {:?} does not continue at triangle {end}",
                    o.name
                )));
            }
            end = o.triangles.end;
            if let Some(m) = o.material.filter(|&m| m >= self.materials.len()) {
                return Err(invalid(format!(
                    "object {:?} uses material {m}, but there are {}",
                    o.name,
                    self.materials.len()
                )));
            }
        }
        if !self.objects.is_empty() && end != self.indices.len() {
            return Err(invalid(format!(
                "the objects cover {end} of {} triangles",
                self.indices.len()
            )));
        }
        if !self.origin.is_finite() {
            return Err(invalid(format!("origin {} is not finite", self.origin)));
        }
        Ok(())
    }

    /// The total surface area, in the square of the mesh's unit (summed in
    /// `f64`). NaN when a triangle references a vertex that does not exist
    /// (the readers never return such a mesh; one built by hand may).
    pub fn area(&self) -> f64 {
        self.indices
            .iter()
            .map(|t| {
                let corner = |i: u32| self.positions.get(i as usize).map(|p| p.as_dvec3());
                match (corner(t[0]), corner(t[1]), corner(t[2])) {
                    (Some(a), Some(b), Some(c)) => 0.5 * (b - a).cross(c - a).length(),
                    _ => f64::NAN,
                }
            })
            .sum()
    }
}
