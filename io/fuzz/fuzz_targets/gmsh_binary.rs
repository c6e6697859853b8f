//! Gmsh 4.1 binary sections: the first byte picks the byte order (even:
//! little-endian, odd: big-endian), the rest follows a valid binary
//! `$MeshFormat` header, so every run reaches the binary section readers
//! (`$Entities`, `$Nodes`, `$Elements`) instead of the header check. No
//! panic; a mesh must be consistent.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

#[path = "../inputs/gmsh_binary.rs"]
mod input;

fuzz_target!(|data: &[u8]| {
    let Some(file) = input::gmsh_binary_file(data) else {
        return;
    };
    if let Ok(mesh) = trilux_io::tet::gmsh::from_bytes(&file, Path::new("fuzz.msh")) {
        let n = mesh.positions.len();
        assert!(mesh.tets.iter().flatten().all(|&i| (i as usize) < n));
        assert!(mesh.positions.iter().all(|p| p.is_finite()));
        assert!(mesh.regions.is_empty() || mesh.regions.len() == mesh.tets.len());
        let _ = mesh.boundary();
    }
});
