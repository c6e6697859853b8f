//! TetGen: the input is a `.node` file and an `.ele` file separated by the
//! first NUL byte. Any result is fine except a panic; a mesh must be
//! consistent.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
    let (node, ele) = (&data[..split], data.get(split + 1..).unwrap_or(&[]));
    if let Ok(mesh) = trilux_io::tet::tetgen::from_bytes(node, ele, Path::new("fuzz.node")) {
        let n = mesh.positions.len();
        assert!(mesh.tets.iter().flatten().all(|&i| (i as usize) < n));
        assert!(mesh.regions.is_empty() || mesh.regions.len() == mesh.tets.len());
        let _ = mesh.boundary();
    }
});
