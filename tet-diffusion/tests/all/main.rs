//! Integration tests of `tet-diffusion`: one binary, one module a topic.

#[path = "../common/mod.rs"]
mod common;

mod choice;
mod data;
mod edit;
mod lights;
mod session;
mod solver;
