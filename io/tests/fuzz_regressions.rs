//! Inputs on which a fuzz target once crashed (`fuzz/`), kept so the bug
//! stays fixed. Each must now give `Ok` or a clean `Err`, never a panic.
//! Add a file under `tests/fuzz-regressions/<target>/` for every new find.

use std::path::Path;

use trilux_io::mesh::{gltf, obj};
use trilux_io::tet::{gmsh, medit, tetgen};

fn replay(target: &str, run: impl Fn(&[u8])) -> usize {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz-regressions")
        .join(target);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return 0;
    };
    let mut count = 0;
    for entry in entries {
        let path = entry.unwrap().path();
        run(&std::fs::read(&path).unwrap());
        count += 1;
    }
    count
}

#[test]
fn saved_fuzz_crashes_stay_fixed() {
    let total = replay("tetgen", |data| {
        let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
        let ele = data.get(split + 1..).unwrap_or(&[]);
        let _ = tetgen::from_bytes(&data[..split], ele, Path::new("fuzz.node"));
    }) + replay("gmsh", |data| {
        let _ = gmsh::from_bytes(data, Path::new("fuzz.msh"));
    }) + replay("medit", |data| {
        let _ = medit::from_bytes(data, Path::new("fuzz.mesh"));
    }) + replay("obj", |data| {
        let _ = obj::from_bytes(data, Path::new("fuzz.obj"));
    }) + replay("gltf", |data| {
        let path = Path::new("/nonexistent-trilux-fuzz/asset.gltf");
        let _ = gltf::from_bytes(data, path, gltf::Options::default());
    });
    assert!(total >= 2, "the saved crash inputs are missing");
}
