//! Integration tests of `mesh-sampling`: one binary, one module a topic.

mod blue_noise;
mod density;
mod emitter;
mod luminaire;
mod multi;
mod robustness;
mod stability;
mod tiled;
mod tolerance;
mod uniform;
