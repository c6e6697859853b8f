//! glTF JSON or GLB bytes (external URIs point into a folder that does not
//! exist): no panic; a scene must be consistent (the triangles' indices in
//! range, finite positions, one colour and attribute value per vertex of
//! the mesh and of the points).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;
use trilux_io::mesh::gltf::{Options, VertexData, scene_from_bytes};

fn check_data(data: &VertexData, n: usize) {
    assert!(data.colors.as_ref().is_none_or(|c| c.len() == n));
    assert!(data.attributes.iter().all(|a| a.values.len() == n));
}

fuzz_target!(|data: &[u8]| {
    let path = Path::new("/nonexistent-trilux-fuzz/asset.gltf");
    if let Ok(scene) = scene_from_bytes(data, path, Options::default()) {
        let mesh = &scene.mesh;
        let n = mesh.positions.len();
        assert!(mesh.indices.iter().flatten().all(|&i| (i as usize) < n));
        assert!(mesh.positions.iter().all(|p| p.is_finite()));
        check_data(&scene.vertex_data, n);
        let points = &scene.points;
        let m = points.positions.len();
        assert!(points.positions.iter().all(|p| p.is_finite()));
        assert!(points.faces.as_ref().is_none_or(|f| f.len() == m));
        check_data(&points.vertex_data, m);
    }
});
