//! `trilux-io`: the files trilux users already have, in and out.
//!
//! This first part reads and writes **tetrahedral meshes**: TetGen
//! `.node`/`.ele` (+ `.face`), Gmsh `.msh` 2.2 (ASCII and binary) and 4.1
//! (ASCII), MEDIT `.mesh`, and VTK `.vtu` output with scalar fields for
//! ParaView. Readers return plain data ([`tet::TetMesh`]: `glam`
//! positions and `[u32; 4]` tetrahedra) and never a half-read mesh. Every
//! failure is an [`Error`] that names the file, the line (or byte offset)
//! and what was wrong: a truncated record, a non-finite coordinate, a
//! tetrahedron that references a missing node, or a header that declares
//! more records than the file can hold (refused before allocating). The
//! boundary surface is derived from the tetrahedra
//! ([`tet::TetMesh::boundary`]), not trusted from a file's face list.
//!
//! Triangle meshes (OBJ, glTF, PLY) and images are still to come (issue 3).
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

mod error;
pub mod image;
pub mod mesh;
pub mod tet;
mod text;

pub use error::{Error, ErrorKind, Location, Result};
