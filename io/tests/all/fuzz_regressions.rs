//! Inputs on which a fuzz target once crashed (`tests/fuzz-regressions/<target>/`)
//! and the fuzzers' seeds (`fuzz/seeds/<target>/`), replayed through the
//! same reader and the same consistency checks as the target. The targets
//! are listed from `fuzz/fuzz_targets/`, so a new target without a replay
//! here fails this test instead of being forgotten.

use std::path::{Path, PathBuf};

use trilux_io::image;
use trilux_io::mesh::{TriMesh, gltf, obj, ply};
use trilux_io::tet::{TetMesh, gmsh, medit, tetgen};

#[path = "../../fuzz/inputs/gmsh_binary.rs"]
mod gmsh_binary_input;
use gmsh_binary_input::gmsh_binary_file;

fn manifest() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The fuzz targets, by file name.
fn targets() -> Vec<String> {
    let dir = manifest().join("fuzz/fuzz_targets");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| entry.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rs"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Every file under `dir` (none when it does not exist).
fn files(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut paths: Vec<PathBuf> = entries
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    paths.sort();
    paths
}

fn check_tri(mesh: &TriMesh) {
    let n = mesh.positions.len();
    assert!(mesh.indices.iter().flatten().all(|&i| (i as usize) < n));
    assert!(mesh.positions.iter().all(|p| p.is_finite()));
    assert!(mesh.uvs.as_ref().is_none_or(|u| u.len() == n));
    assert!(mesh.normals.as_ref().is_none_or(|v| v.len() == n));
}

fn check_tet(mesh: &TetMesh) {
    let n = mesh.positions.len();
    assert!(mesh.tets.iter().flatten().all(|&i| (i as usize) < n));
    assert!(mesh.positions.iter().all(|p| p.is_finite()));
    assert!(mesh.regions.is_empty() || mesh.regions.len() == mesh.tets.len());
    let _ = mesh.boundary();
}

/// Runs `data` through the reader of fuzz target `target` with its
/// checks; `None` when no replay exists for that target.
fn replay(target: &str, data: &[u8]) -> Option<()> {
    match target {
        "tetgen" => {
            let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
            let ele = data.get(split + 1..).unwrap_or(&[]);
            if let Ok(mesh) = tetgen::from_bytes(&data[..split], ele, "fuzz.node") {
                check_tet(&mesh);
            }
        }
        "gmsh" => {
            if let Ok(mesh) = gmsh::from_bytes(data, "fuzz.msh") {
                check_tet(&mesh);
            }
        }
        "gmsh_binary" => {
            if let Some(file) = gmsh_binary_file(data)
                && let Ok(mesh) = gmsh::from_bytes(&file, "fuzz.msh")
            {
                check_tet(&mesh);
            }
        }
        "medit" => {
            if let Ok(mesh) = medit::from_bytes(data, "fuzz.mesh") {
                check_tet(&mesh);
            }
        }
        "obj" => {
            if let Ok(mesh) = obj::from_bytes(data, "fuzz.obj") {
                check_tri(&mesh);
                let covered: usize = mesh.objects.iter().map(|o| o.triangles.len()).sum();
                assert_eq!(covered, mesh.indices.len());
            }
        }
        "ply" => {
            if let Ok(ply) = ply::from_bytes(data, "fuzz.ply") {
                let n = ply.positions.len();
                assert!(ply.triangles.iter().flatten().all(|&i| (i as usize) < n));
                assert!(ply.positions.iter().all(|p| p.is_finite()));
                assert!(ply.scalars.iter().all(|(_, s)| s.len() == n));
            }
        }
        "gltf" => {
            let path = Path::new("/nonexistent-trilux-fuzz/asset.gltf");
            if let Ok(scene) = gltf::scene_from_bytes(data, path, gltf::Options::default()) {
                check_tri(&scene.mesh);
                let check_data = |data: &gltf::VertexData, n: usize| {
                    assert!(data.colors.as_ref().is_none_or(|c| c.len() == n));
                    assert!(data.attributes.iter().all(|a| a.values.len() == n));
                };
                check_data(&scene.vertex_data, scene.mesh.positions.len());
                let points = &scene.points;
                let m = points.positions.len();
                assert!(points.positions.iter().all(|p| p.is_finite()));
                assert!(points.faces.as_ref().is_none_or(|f| f.len() == m));
                check_data(&points.vertex_data, m);
            }
        }
        "image" => {
            let Some((&pick, bytes)) = data.split_first() else {
                return Some(());
            };
            let name = ["fuzz.png", "fuzz.jpg", "fuzz.hdr", "fuzz.exr"][usize::from(pick % 4)];
            let options = image::ReadOptions {
                max_dimension: 4096,
                max_bytes: 64 << 20,
                ..image::ReadOptions::default()
            };
            if let Ok(picture) = image::decode(bytes, name, options) {
                let n = u64::from(picture.width) * u64::from(picture.height);
                assert_eq!(picture.pixels.len() as u64, n);
            }
        }
        _ => return None,
    }
    Some(())
}

#[test]
fn every_fuzz_target_replays_its_crashes_and_seeds() {
    let targets = targets();
    assert!(targets.len() >= 8, "fuzz targets: {targets:?}");
    let mut crashes = 0;
    for target in &targets {
        let crash_files = files(&manifest().join("tests/fuzz-regressions").join(target));
        let seed_files = files(&manifest().join("fuzz/seeds").join(target));
        assert!(
            !seed_files.is_empty() || !crash_files.is_empty(),
            "fuzz target {target} has neither seeds nor saved crashes to replay"
        );
        crashes += crash_files.len();
        for file in crash_files.iter().chain(&seed_files) {
            let data = std::fs::read(file).unwrap();
            assert!(
                replay(target, &data).is_some(),
                "fuzz target {target} has no replay here: add it to `replay`"
            );
        }
    }
    assert!(crashes >= 4, "the saved crash inputs are missing");
}

/// The `gmsh_binary` seeds are whole meshes in both byte orders, so the
/// fuzzer starts inside the binary section readers, not at their errors.
#[test]
fn the_gmsh_binary_seeds_are_meshes_in_both_byte_orders() {
    let seeds = files(&manifest().join("fuzz/seeds/gmsh_binary"));
    let mut orders = Vec::new();
    for seed in &seeds {
        let data = std::fs::read(seed).unwrap();
        let file = gmsh_binary_file(&data).unwrap();
        let mesh = gmsh::from_bytes(&file, seed).unwrap();
        assert!(!mesh.tets.is_empty(), "{}", seed.display());
        check_tet(&mesh);
        orders.push(data[0] % 2);
    }
    orders.sort_unstable();
    orders.dedup();
    assert_eq!(orders, [0, 1], "{seeds:?}");
}
