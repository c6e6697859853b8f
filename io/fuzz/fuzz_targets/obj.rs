//! Wavefront OBJ: no panic; a mesh must be consistent.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = trilux_io::mesh::obj::from_bytes(data, Path::new("fuzz.obj")) {
        let n = mesh.positions.len();
        assert!(mesh.indices.iter().flatten().all(|&i| (i as usize) < n));
        assert!(mesh.positions.iter().all(|p| p.is_finite()));
        assert!(mesh.uvs.as_ref().is_none_or(|u| u.len() == n));
        assert!(mesh.normals.as_ref().is_none_or(|v| v.len() == n));
        let covered: usize = mesh.objects.iter().map(|o| o.triangles.len()).sum();
        assert_eq!(covered, mesh.indices.len());
    }
});
