//! `trilux-io`: the files trilux users already have, in and out.
//!
//! - **Triangle meshes** ([`mesh`]): OBJ and glTF/GLB in, PLY in and out,
//!   OBJ out; one index stream, materials with decoded glTF textures.
//! - **Images** ([`image`]): PNG, JPEG, Radiance HDR, OpenEXR in as linear
//!   `f32` RGBA; PNG (8/16 bit) and EXR (f32/f16) out.
//! - **Tetrahedral meshes** ([`tet`]): TetGen `.node`/`.ele` (+ `.face`),
//!   Gmsh `.msh` 2.2 (ASCII and binary) and 4.1 (ASCII), MEDIT `.mesh` in;
//!   TetGen, MEDIT and VTK `.vtu` (with scalar fields, for ParaView) out.
//!
//! Readers return plain data (`glam` vectors, `[u32; N]` indices) and
//! never a half-read mesh. Every
//! failure is an [`Error`] that names the file, the line (or byte offset)
//! and what was wrong: a truncated record, a non-finite coordinate, a
//! tetrahedron that references a missing node, or a header that declares
//! more records than the file can hold (refused before allocating). The
//! boundary surface is derived from the tetrahedra
//! ([`tet::TetMesh::boundary`]), not trusted from a file's face list.
//!
//! A glTF's URIs are confined to its folder, and image dimensions and
//! header counts are checked before anything is allocated, so hostile files
//! fail cleanly.
//!
//! # Example
//!
//! ```no_run
//! use trilux_io::tet::TetMesh;
//!
//! let mesh = TetMesh::read("bunny.node")?; // finds bunny.ele beside it
//! println!("{} nodes, {} tets", mesh.positions.len(), mesh.tets.len());
//! let surface = mesh.boundary(); // outward triangles
//! trilux_io::tet::tetgen::write(std::path::Path::new("copy.node"), &mesh)?;
//! # Ok::<(), trilux_io::Error>(())
//! ```

#![forbid(unsafe_code)]

/// The vector types of every public position, normal and UV (`Vec3`,
/// `DVec3`, `Vec2`): this crate speaks glam 0.34.
pub use glam;

mod base64;
mod error;
pub mod image;
pub mod mesh;
pub mod tet;
mod text;

pub use error::{Error, ErrorKind, Location, Result};
