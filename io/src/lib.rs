//! `trilux-io`: the files trilux users already have, in and out.
//!
//! - **Triangle meshes** ([`mesh`]): OBJ (with MTL), glTF/GLB and PLY in;
//!   OBJ (with MTL and textures), PLY and glTF/GLB (textures embedded) out,
//!   chosen by extension ([`mesh::read`], [`mesh::TriMesh::write`]); PLY
//!   or glTF point clouds for sampled points, glTF vertex colours and
//!   custom attributes for per-vertex results ([`mesh::gltf`]). One index
//!   stream, materials with decoded glTF textures.
//! - **Curves** ([`curves`]): hair strands as USD text (`BasisCurves` and
//!   `Points`), Cem Yuksel's `.hair` and glTF lines with root points out;
//!   `.hair` in.
//! - **Images** ([`image`]): PNG, JPEG, Radiance HDR, OpenEXR in as linear
//!   `f32` RGBA; PNG (8/16 bit) and EXR (f32/f16) out.
//! - **Tetrahedral meshes** ([`tet`]): TetGen `.node`/`.ele` (+ `.face`),
//!   Gmsh `.msh` 2.2 (ASCII and binary) and 4.1 (ASCII), MEDIT `.mesh` in;
//!   TetGen, MEDIT and VTK `.vtu` (with scalar fields, for ParaView) out.
//!
//! Readers return plain data ([`glam`] vectors, `[u32; N]` indices) and
//! never a half-read mesh. One convention per concept: [`mesh::TriMesh`]
//! UVs are glTF's (v down, `v = 0` at image row 0; the OBJ and PLY
//! readers and writers flip, nothing else does), far-from-origin
//! coordinates keep their precision through [`mesh::TriMesh::origin`], and
//! luminance is Rec. 709 ([`image::luminance`]).
//!
//! Every failure is an [`Error`] that names the file, the line (or byte
//! offset) and what was wrong: a truncated record, a non-finite
//! coordinate, a tetrahedron that references a missing node, or a header
//! that declares more than the file can hold or the memory budget allows
//! (refused before allocating). A glTF's URIs are confined to its folder.
//!
//! # Example
//!
//! ```
//! # let folder = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regressions");
//! # let scratch = std::env::temp_dir().join(format!("trilux-io-doc-{}", std::process::id()));
//! # std::fs::create_dir_all(&scratch).unwrap();
//! // A CRLF OBJ with a byte-order mark and a material library.
//! let mesh = trilux_io::mesh::read(folder.join("obj-utf8-bom/model.obj"))?;
//! assert_eq!((mesh.indices.len(), mesh.materials[0].name.as_str()), (1, "red"));
//! mesh.write(scratch.join("copy.ply"))?; // binary PLY, chosen by extension
//! let tets = trilux_io::tet::read(folder.join("tetgen-real-attribute/mesh.node"))?;
//! assert_eq!(tets.attributes, vec![vec![1.0, 1.5]]); // TetGen attributes are reals
//! # Ok::<(), trilux_io::Error>(())
//! ```

#![forbid(unsafe_code)]

/// The vector types of every public position, normal and UV (`Vec3`,
/// `DVec3`, `Vec2`): this crate speaks glam 0.34.
pub use glam;

mod base64;
pub mod curves;
mod error;
pub mod image;
mod image_exr;
mod image_hdr;
pub mod mesh;
pub mod tet;
mod text;
mod warning;

pub use error::{Error, ErrorKind, Location, Reference, Result};
pub use warning::Warning;

/// The README's examples, compiled as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
