//! `import trilux`: the trilux crates as a Python package (PyO3 + numpy),
//! over the `trilux` library's adapters so that every conversion exists
//! once.
//!
//! | Python | Rust |
//! |---|---|
//! | `load`, `save`, `Mesh` | trilux-io meshes ([`mesh`]); glTF colours and attributes, in and out ([`gltf`]) |
//! | `sample_surface`, `blue_noise`, `sample_surface_even`, `scatter` | mesh-sampling ([`sampling`]) |
//! | `grow_hair` | mesh-sampling's strands, trilux-io's curves ([`hair`]) |
//! | `Distribution1D`, `Distribution2D` | discrete-sampling ([`discrete`]) |
//! | `Emitter` | mesh-sampling's light sampling ([`emitter`]) |
//! | `MeshColors` | mesh-colors via `trilux::to_mesh_colors` ([`colors`]) |
//! | `tetrahedralize`, `load_tets`, `save_tets`, `save_points` | stuffing, trilux-io ([`tets`]), PLY or glTF points |
//! | `load_points`, `Points` | PLY or glTF points back in ([`points`]) |
//! | `Object`, `render`, `media` | tet-diffusion ([`transcut`]) |
//! | `Error`, `InputError`, `FileError`, `InternalError` | every crate's error, message unchanged ([`error`]) |
//!
//! Arrays come in as any array-like of a real dtype (C-contiguous or
//! not) and go out as numpy arrays that own the Rust vectors (no copy):
//! float64 positions, int64 indices, as trimesh returns them. Every call
//! that does real work releases the GIL (`Python::detach`), so rayon uses
//! all cores and other Python threads run meanwhile; a Rust panic becomes
//! `trilux.InternalError`.
//!
//! Built as the extension module `trilux._trilux` by maturin
//! (`python/pyproject.toml`); the `rlib` is for Rust-side tests.

pub mod arrays;
pub mod colors;
pub mod discrete;
pub mod emitter;
pub mod error;
pub mod gltf;
pub mod hair;
pub mod mesh;
pub mod points;
pub mod sampling;
pub mod tets;
pub mod transcut;

use pyo3::prelude::*;

/// The extension module `trilux._trilux` (re-exported by `trilux`).
#[pymodule]
fn _trilux(m: &Bound<'_, PyModule>) -> PyResult<()> {
    error::register(m)?;
    m.add_class::<mesh::Mesh>()?;
    m.add_function(wrap_pyfunction!(mesh::load, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::save, m)?)?;
    m.add_function(wrap_pyfunction!(sampling::sample_surface, m)?)?;
    m.add_function(wrap_pyfunction!(sampling::blue_noise, m)?)?;
    m.add_function(wrap_pyfunction!(sampling::sample_surface_even, m)?)?;
    m.add_function(wrap_pyfunction!(sampling::scatter, m)?)?;
    m.add_function(wrap_pyfunction!(hair::grow_hair, m)?)?;
    m.add_class::<discrete::Distribution1D>()?;
    m.add_class::<discrete::Distribution2D>()?;
    m.add_class::<emitter::Emitter>()?;
    m.add_class::<colors::MeshColors>()?;
    m.add_function(wrap_pyfunction!(tets::tetrahedralize, m)?)?;
    m.add_function(wrap_pyfunction!(tets::load_tets, m)?)?;
    m.add_function(wrap_pyfunction!(tets::save_tets, m)?)?;
    m.add_function(wrap_pyfunction!(tets::save_points, m)?)?;
    m.add_class::<points::Points>()?;
    m.add_function(wrap_pyfunction!(points::load_points, m)?)?;
    m.add_class::<transcut::Object>()?;
    m.add_function(wrap_pyfunction!(transcut::render, m)?)?;
    m.add_function(wrap_pyfunction!(transcut::media, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
