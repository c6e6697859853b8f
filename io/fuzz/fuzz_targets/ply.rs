//! PLY (ASCII and binary, both byte orders): no panic; data must be
//! consistent.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(ply) = trilux_io::mesh::ply::from_bytes(data, Path::new("fuzz.ply")) {
        let n = ply.positions.len();
        assert!(ply.triangles.iter().flatten().all(|&i| (i as usize) < n));
        assert!(ply.positions.iter().all(|p| p.is_finite()));
        assert!(ply.colors.as_ref().is_none_or(|c| c.len() == n));
        assert!(ply.scalars.iter().all(|(_, s)| s.len() == n));
    }
});
