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
fn a_stuffed_cube_is_a_valid_diffusion_mesh() {
    // A unit cube with outward faces, split into triangles.
    let p: Vec<DVec3> = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let tris: Vec<[u32; 3]> = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    accepted("cube", &p, &tris, 0.15);
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn every_stuffed_data_mesh_is_a_valid_diffusion_mesh() {
    let dir = trilux_tests::data("meshes");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("the meshes folder")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    files.sort();
    assert!(
        files.len() >= 6,
        "expected the six meshes of the data README"
    );
    for f in &files {
        let m = trilux_io::mesh::TriMesh::read(f).expect("a readable mesh");
        let p: Vec<DVec3> = m.positions.iter().map(|p| p.as_dvec3()).collect();
        let name = f.file_stem().unwrap().to_string_lossy().into_owned();
        accepted(&name, &p, &m.indices, diagonal(&p, &m.indices) / 30.0);
    }
    let tets = trilux_io::tet::TetMesh::read(trilux_tests::data("tets/bunny_500k.node")).unwrap();
    let boundary = tets.boundary();
    let h = diagonal(&tets.positions, &boundary) / 30.0;
    accepted("bunny_500k boundary", &tets.positions, &boundary, h);
}
