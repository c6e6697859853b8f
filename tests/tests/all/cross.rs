//! Cross-crate tests: mesh colours feeding mesh-sampling as a density, and
//! every trilux-io mesh format through every algorithm crate.

use mesh_sampling::{Channel, Density, DensitySampler, SurfaceSampler, UniformSampler};
use trilux::shapes;
use trilux_io::mesh::TriMesh;
use trilux_tests::data;

/// Mean of `x` over points drawn with density `1 + x` on the unit sphere:
/// ∫x(1+x) dA / ∫(1+x) dA = (4π/3) / 4π = 1/3 (the polyhedral sphere is
/// within 0.2 % at 4 subdivisions).
#[test]
fn mesh_colours_feed_mesh_sampling_as_a_density() {
    let sphere = shapes::icosphere(4);
    let surface = trilux::ColorMesh::new(&sphere).unwrap();
    let topology = surface.topology().unwrap();
    let mut colors = mesh_colors::MeshColors::uniform(topology, 4, 1).unwrap();
    colors
        .fill(&surface.positions, |p, out| out[0] = (1.0 + p.x) as f32)
        .unwrap();
    let density = trilux::colors::color_density(&surface, &colors, Channel::Index(0)).unwrap();
    let sampler =
        DensitySampler::new(density.mesh_ref(), Density::Texture(&density.texture)).unwrap();
    let n = 200_000;
    let pts = sampler.sample_n(9, n).unwrap();
    let mean = |xs: &[f64]| xs.iter().sum::<f64>() / xs.len() as f64;
    let xs: Vec<f64> = pts.iter().map(|p| f64::from(p.position.x)).collect();
    let m = mean(&xs);
    let var = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1) as f64;
    let se = (var / n as f64).sqrt();
    assert!(
        (m - 1.0 / 3.0).abs() < 4.0 * se + 2e-3,
        "mean x {m} (se {se})"
    );
    // Faces index the original mesh: the points lie on its triangles.
    for p in pts.iter().take(1000) {
        let t = sphere.indices[p.face as usize].map(|v| sphere.positions[v as usize]);
        let q = t[0] * p.barycentric[0] + t[1] * p.barycentric[1] + t[2] * p.barycentric[2];
        assert!((q - p.position).length() < 1e-5);
    }
    // Chi-square on the counts per face against the exact masses: the
    // density is affine on each flat face, so its mass is the area times
    // its value at the centroid, and the subdivision's midpoint values are
    // exact for it.
    let masses: Vec<f64> = sphere
        .indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| sphere.positions[v as usize].as_dvec3());
            0.5 * (b - a).cross(c - a).length() * (1.0 + (a.x + b.x + c.x) / 3.0)
        })
        .collect();
    let total: f64 = masses.iter().sum();
    let chi_square = |points: &[mesh_sampling::SurfacePoint]| {
        let mut counts = vec![0.0f64; masses.len()];
        for p in points {
            counts[p.face as usize] += 1.0;
        }
        counts
            .iter()
            .zip(&masses)
            .map(|(o, m)| {
                let e = m / total * points.len() as f64;
                (o - e).powi(2) / e
            })
            .sum::<f64>()
    };
    let limit = trilux_tests::chi_square_quantile((masses.len() - 1) as f64, 3.09);
    let x2 = chi_square(&pts);
    assert!(x2 < limit, "chi-square {x2} over {limit}");
    // The same tests reject area-uniform points (mean x = 0).
    let uniform = UniformSampler::new(trilux::mesh_ref(&sphere))
        .unwrap()
        .sample_n(9, n)
        .unwrap();
    let u: Vec<f64> = uniform.iter().map(|p| f64::from(p.position.x)).collect();
    assert!((mean(&u) - 1.0 / 3.0).abs() > 4.0 * se + 2e-3);
    assert!(chi_square(&uniform) > limit);
}

/// A graph Laplacian (plus identity) of the tetrahedra's edges: the
/// shape of a diffusion matrix, for multires' hierarchy.
fn edge_matrix(mesh: &trilux_io::tet::TetMesh) -> multires::sprs::CsMat<f64> {
    let n = mesh.positions.len();
    let mut tri = multires::sprs::TriMat::new((n, n));
    for i in 0..n {
        tri.add_triplet(i, i, 1.0);
    }
    let mut edges = std::collections::HashSet::new();
    for t in &mesh.tets {
        for a in 0..4 {
            for b in a + 1..4 {
                let (i, j) = (t[a].min(t[b]) as usize, t[a].max(t[b]) as usize);
                if edges.insert((i, j)) {
                    tri.add_triplet(i, i, 1.0);
                    tri.add_triplet(j, j, 1.0);
                    tri.add_triplet(i, j, -1.0);
                    tri.add_triplet(j, i, -1.0);
                }
            }
        }
    }
    tri.to_csr()
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn every_mesh_format_goes_through_every_algorithm_crate() {
    let dir = tempfile::tempdir().unwrap();
    let spot = TriMesh::read(data("meshes/spot.obj")).unwrap();
    let texture = trilux_io::image::read(data("textures/spot_texture.png")).unwrap();
    let ply = dir.path().join("spot.ply");
    spot.write(&ply).unwrap();
    let cases: Vec<(String, TriMesh, Option<&trilux_io::image::Image>)> = vec![
        ("spot.obj".into(), spot.clone(), Some(&texture)),
        (
            "spot.ply".into(),
            TriMesh::read(&ply).unwrap(),
            Some(&texture),
        ),
        (
            "BoxTextured.gltf".into(),
            TriMesh::read(data("gltf/BoxTextured/BoxTextured.gltf")).unwrap(),
            None,
        ),
        (
            "Fox.glb".into(),
            TriMesh::read(data("gltf/Fox.glb")).unwrap(),
            None,
        ),
        (
            "FlightHelmet.gltf".into(),
            TriMesh::read(data("gltf/FlightHelmet/FlightHelmet.gltf")).unwrap(),
            None,
        ),
    ];
    for (name, mesh, tex) in &cases {
        // mesh-sampling: uniform and by the texture's luminance.
        let uniform = UniformSampler::new(trilux::mesh_ref(mesh)).unwrap();
        let pts = uniform.sample_n(1, 1000).unwrap();
        assert_eq!(
            trilux::point_cloud(mesh, &pts).positions.len(),
            1000,
            "{name}"
        );
        let image = tex
            .cloned()
            .or_else(|| mesh.materials.iter().find_map(|m| m.diffuse_image.clone()))
            .unwrap();
        let density = trilux::density_texture(&image, Channel::Luminance).unwrap();
        DensitySampler::new(trilux::mesh_ref(mesh), Density::Texture(&density))
            .unwrap()
            .sample_n(1, 1000)
            .unwrap();
        // mesh-colors: converted with its material's (or the given) texture.
        let (surface, colors) = trilux::to_mesh_colors(mesh, *tex, &Default::default()).unwrap();
        assert_eq!(colors.face_count(), mesh.indices.len(), "{name}");
        surface.check(&colors, std::path::Path::new(name)).unwrap();
    }
    // Tetrahedral formats → positions for multires' hierarchy.
    for file in ["tets/sphere_20k.node", "tets/bunny_50k.node"] {
        let tet = trilux_io::tet::TetMesh::read(data(file)).unwrap();
        let medit = dir.path().join("copy.mesh");
        trilux_io::tet::medit::write(&medit, &tet).unwrap();
        for mesh in [tet.clone(), trilux_io::tet::TetMesh::read(&medit).unwrap()] {
            let a = edge_matrix(&mesh);
            let positions = trilux::tet::positions_f64(&mesh);
            let h = multires::Hierarchy::new(
                &a,
                multires::Weights::Positions(&positions),
                &Default::default(),
            )
            .unwrap();
            assert!(h.levels() > 1, "{file}");
            let surface = trilux::tet::surface(&mesh);
            UniformSampler::new(trilux::mesh_ref(&surface)).unwrap();
        }
    }
    let msh = trilux_io::tet::TetMesh::read(data("tets/bunny_500k.msh")).unwrap();
    assert_eq!(msh.tets.len(), 507_125);
}
