//! Integration tests of `multires`: one binary, one module a topic.

#[path = "../common/mod.rs"]
mod common;

mod files_and_limits;
mod hierarchy;
mod singular;
mod solvers;
