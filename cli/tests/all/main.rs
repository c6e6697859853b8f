//! Integration tests of `trilux`: one binary, one module a topic.

#[path = "../common/mod.rs"]
mod common;

mod cli;
mod cmd;
mod gltf_clients;
mod gltf_out;
mod hair_cli;
mod help;
mod info_warnings;
mod paint_browser;
mod paint_protocol;
mod paint_shader;
mod scatter_cli;
mod tet_cli;
mod view_browser;
mod view_protocol;
mod view_session;
