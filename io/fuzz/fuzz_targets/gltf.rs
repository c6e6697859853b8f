//! glTF JSON or GLB bytes (external URIs point into a folder that does not
//! exist): no panic; a mesh must be consistent.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;
use trilux_io::mesh::gltf::{Options, from_bytes};

fuzz_target!(|data: &[u8]| {
    let path = Path::new("/nonexistent-trilux-fuzz/asset.gltf");
    if let Ok(mesh) = from_bytes(data, path, Options::default()) {
        let n = mesh.positions.len();
        assert!(mesh.indices.iter().flatten().all(|&i| (i as usize) < n));
        assert!(mesh.positions.iter().all(|p| p.is_finite()));
    }
});
