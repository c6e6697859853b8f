//! Integration tests of `trilux-io`: one binary, one module a topic.

#[path = "../support/mod.rs"]
mod support;

mod curves;
mod fuzz_regressions;
mod gltf;
mod gltf_roundtrip;
mod images;
mod images_second;
mod meshes;
mod ply_roundtrip;
mod regressions;
mod regressions_second;
mod second_set_properties;
mod tets;
