//! MEDIT `.mesh`: no panic; a mesh must be consistent.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = trilux_io::tet::medit::from_bytes(data, Path::new("fuzz.mesh")) {
        let n = mesh.positions.len();
        assert!(mesh.tets.iter().flatten().all(|&i| (i as usize) < n));
        assert!(mesh.positions.iter().all(|p| p.is_finite()));
        let _ = mesh.boundary();
    }
});
