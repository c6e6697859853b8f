//! Where `tet-stuffing` meets `tet-diffusion`: every stuffed mesh is
//! accepted by the diffusion's validation, with no poorly shaped
//! tetrahedron and bounded cotangent weights (the reason stuffing bounds
//! dihedral angles, TransCut Sec. 6). The crates do not depend on each
//! other, so the check lives here.

use glam::DVec3;
use tet_stuffing::{Options, tetrahedralize};

/// Stuffs `positions`/`triangles` at spacing `h` and checks what
/// `tet-diffusion` makes of the result; returns the weight range over
/// the mean edge length.
fn accepted(name: &str, positions: &[DVec3], triangles: &[[u32; 3]], h: f64) -> [f64; 2] {
    let m = tetrahedralize(positions, triangles, &Options::new(h))
        .unwrap_or_else(|e| panic!("{name}: stuffing failed: {e}"));
    let td = tet_diffusion::TetMesh::new(&m.positions, &m.tets)
        .unwrap_or_else(|e| panic!("{name}: tet-diffusion refused the mesh: {e}"));
    let q = td.quality();
    let w = q.edge_weight_range.map(|x| x / q.mean_edge_length);
    eprintln!(
        "{name}: {} tets, cotangent edge weights / mean edge length {:.3} .. {:.3}",
        m.tets.len(),
        w[0],
        w[1]
    );
    assert_eq!(q.poor_tets, 0, "{name}: poorly shaped tetrahedra");
    assert!(w[0] > -5.0 && w[1] < 5.0, "{name}: weights {w:?}");
    w
}

/// Bounding-box diagonal of the vertices the triangles use.
fn diagonal(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let used = triangles.iter().flatten().map(|&v| positions[v as usize]);
    let (lo, hi) = used.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(p), hi.max(p))
    });
    lo.distance(hi)
}

#[test]
fn the_stuffed_blob_is_a_valid_diffusion_mesh() {
    // The demo's closed, bumpy blob (about 2 units across).
    let blob = trilux::shapes::blob(2);
    let p: Vec<DVec3> = blob.positions.iter().map(|p| p.as_dvec3()).collect();
    accepted("blob", &p, &blob.indices, 0.1);
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn every_stuffed_data_mesh_is_a_valid_diffusion_mesh() {
    let files = trilux_tests::MESHES.map(|n| trilux_tests::data(&format!("meshes/{n}.obj")));
    for f in &files {
        let m = trilux_io::mesh::TriMesh::read(f).expect("a readable mesh");
        let p: Vec<DVec3> = m.positions.iter().map(|p| p.as_dvec3()).collect();
        let name = f.display().to_string();
        accepted(&name, &p, &m.indices, diagonal(&p, &m.indices) / 30.0);
    }
    let tets = trilux_io::tet::TetMesh::read(trilux_tests::data("tets/bunny_500k.node")).unwrap();
    let boundary = tets.boundary();
    let h = diagonal(&tets.positions, &boundary) / 30.0;
    accepted("bunny_500k boundary", &tets.positions, &boundary, h);
}
