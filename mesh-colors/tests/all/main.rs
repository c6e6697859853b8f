//! Integration tests of `mesh-colors`: one binary, one module a topic.

#[path = "../support/mod.rs"]
mod support;

// The textured meshes of the data folder (shared with the `lookup` example).
#[path = "../support/data.rs"]
mod data;

mod atlas;
mod convert;
mod edit;
mod file;
mod filtering;
mod gpu;
mod limits;
mod paint;
mod resolution;
mod session;
mod structure;
mod texture;
mod undo;
