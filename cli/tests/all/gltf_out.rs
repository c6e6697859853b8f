//! glTF outputs of `trilux colors bake`, `trilux sample` and `trilux
//! tetra --glb`: each file passes the Khronos glTF-Validator (no error,
//! no warning) and reads back with `trilux_io::mesh::gltf::read_scene`
//! holding what the command made (the atlas and its triangles, the points
//! with their normals, UVs and faces, the closed outward boundary of the
//! tetrahedra); outputs are not clobbered without `--force`, an
//! extension the command does not write or a folder in the way is refused
//! before any work; `trilux info` reports sampled glTF points as it
//! reports a PLY point cloud.

use std::path::{Path, PathBuf};

use crate::common;
use common::{blob, fails_with, json, no_partial_files, trilux};
use test_support::gltf::validate;
use trilux_io::glam::{DVec3, Vec3};
use trilux_io::mesh::TriMesh;
use trilux_io::mesh::gltf::{Scene, read_scene};

/// A built-in textured torus (16 × 8, 256 triangles) and a noise texture
/// written as files.
fn torus_and_noise(dir: &Path) -> (PathBuf, PathBuf) {
    common::torus_and_noise(dir, [16, 8], 32)
}

/// The file names of a report's `files`.
fn files(report: &serde_json::Value) -> Vec<String> {
    report["files"]
        .as_array()
        .unwrap_or_else(|| panic!("no files in {report}"))
        .iter()
        .map(|f| {
            let f = Path::new(f.as_str().unwrap());
            f.file_name().unwrap().to_string_lossy().into_owned()
        })
        .collect()
}

/// Validates `path` and reads it back.
fn checked(path: &Path) -> Scene {
    validate(path);
    read_scene(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn colors_bake_writes_one_glb_with_the_atlas_embedded_or_a_gltf_with_its_bin() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, noise) = torus_and_noise(d);
    let (torus, noise) = (torus.to_str().unwrap(), noise.to_str().unwrap());
    let args = ["colors", "convert", torus, "--texture", noise];
    json(d, &[&args[..], &["-o", "t.meshcolors"]].concat());
    let faces = 16 * 8 * 2;
    let bake = |out: &str| json(d, &["colors", "bake", torus, "t.meshcolors", "-o", out]);

    let report = bake("atlas.glb");
    assert_eq!(files(&report), ["atlas.glb"], "{report}");
    assert_eq!(report["faces"], faces);
    let size = [&report["atlas"][0], &report["atlas"][1]].map(|v| v.as_u64().unwrap() as u32);
    // One file: no .mtl, .png or .bin beside it.
    let mut names: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["atlas.glb", "noise.png", "t.meshcolors", "torus.obj"]
    );
    let glb = checked(&d.join("atlas.glb"));
    assert!(glb.points.positions.is_empty());
    assert_eq!(glb.mesh.indices.len(), faces);
    let material = &glb.mesh.materials[0];
    let image = material.diffuse_image.as_ref().expect("the atlas embedded");
    assert_eq!([image.width, image.height], size);
    assert!(glb.mesh.objects.iter().all(|o| o.material == Some(0)));
    let uvs = glb.mesh.uvs.as_ref().expect("atlas UVs");
    assert!(
        uvs.iter()
            .all(|uv| (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y))
    );

    // The same atlas as the OBJ's PNG, on the same triangles.
    bake("atlas.obj");
    let obj = TriMesh::read(d.join("atlas.obj")).unwrap();
    let png = obj.materials[0].diffuse_texture.as_ref().unwrap();
    assert_eq!(&trilux_io::image::read(png).unwrap(), image);
    assert_eq!(obj.indices.len(), glb.mesh.indices.len());
    let corners = |m: &TriMesh| -> Vec<(Vec3, trilux_io::glam::Vec2)> {
        let uvs = m.uvs.as_ref().unwrap();
        m.indices
            .iter()
            .flatten()
            .map(|&v| (m.positions[v as usize], uvs[v as usize]))
            .collect()
    };
    for (k, (a, b)) in corners(&obj)
        .into_iter()
        .zip(corners(&glb.mesh))
        .enumerate()
    {
        assert!(
            a.0.distance(b.0) < 1e-5 && a.1.distance(b.1) < 1e-5,
            "corner {k}: {a:?} vs {b:?}"
        );
    }

    // .gltf: the JSON and its .bin, holding what the .glb holds.
    let report = bake("atlas.gltf");
    assert_eq!(files(&report), ["atlas.bin", "atlas.gltf"], "{report}");
    let gltf = checked(&d.join("atlas.gltf"));
    assert_eq!(gltf.mesh.positions, glb.mesh.positions);
    assert_eq!(gltf.mesh.indices, glb.mesh.indices);
    assert_eq!(gltf.mesh.uvs, glb.mesh.uvs);
    assert_eq!(gltf.mesh.materials[0].diffuse_image.as_ref(), Some(image));
    no_partial_files(d);
}

#[test]
fn sample_writes_glb_points_with_normals_uvs_and_faces_as_the_ply_has_them() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, _) = torus_and_noise(d);
    let torus = torus.to_str().unwrap();
    let n = 500;
    let sample = |out: &str| json(d, &["sample", torus, "-n", "500", "--seed", "3", "-o", out]);
    let report = sample("p.glb");
    assert_eq!(files(&report), ["p.glb"], "{report}");
    let scene = checked(&d.join("p.glb"));
    assert!(scene.mesh.indices.is_empty());
    let points = &scene.points;
    assert_eq!(points.positions.len(), n);
    let normals = points.normals.as_ref().expect("normals");
    assert!(normals.iter().all(|v| (v.length() - 1.0).abs() < 1e-5));
    let uvs = points.uvs.as_ref().expect("the torus has UVs");
    let faces = points.faces.as_ref().expect("face ids");
    assert!(faces.iter().all(|&f| f < 16 * 8 * 2), "{faces:?}");

    // The same seed gives the same points as the PLY.
    sample("p.ply");
    let ply = trilux_io::mesh::ply::read(d.join("p.ply")).unwrap();
    assert_eq!(ply.face_ids.as_ref(), Some(faces));
    let close = |a: &[Vec3], b: &[Vec3]| a.iter().zip(b).all(|(a, b)| a.distance(*b) < 1e-5);
    assert!(close(&ply.positions, &points.positions));
    assert!(close(ply.normals.as_ref().unwrap(), normals));
    let ply_uvs = ply.uvs.as_ref().unwrap();
    assert!(ply_uvs.iter().zip(uvs).all(|(a, b)| a.distance(*b) < 1e-5));
    // Each point lies on its face.
    let mesh = trilux::shapes::torus(16, 8);
    for (p, &f) in points.positions.iter().zip(faces) {
        let [a, b, c] = mesh.indices[f as usize].map(|v| mesh.positions[v as usize]);
        let normal = (b - a).cross(c - a).normalize();
        assert!((*p - a).dot(normal).abs() < 1e-5, "{p} off face {f}");
    }

    // A mesh without UVs, as .gltf with its .bin: no TEXCOORD_0.
    trilux::shapes::icosphere(2)
        .write(d.join("ball.obj"))
        .unwrap();
    let report = json(d, &["sample", "ball.obj", "-n", "100", "-o", "q.gltf"]);
    assert_eq!(files(&report), ["q.bin", "q.gltf"], "{report}");
    let scene = checked(&d.join("q.gltf"));
    assert_eq!(scene.points.positions.len(), 100);
    assert!(scene.points.uvs.is_none());
    assert!(scene.points.normals.is_some());
    let faces = scene.points.faces.as_ref().unwrap();
    assert!(faces.iter().all(|&f| f < 320));
    assert!(
        scene
            .points
            .positions
            .iter()
            .all(|p| (p.length() - 1.0).abs() < 0.2)
    );

    // ASCII is a PLY encoding.
    fails_with(
        d,
        2,
        &["sample", torus, "-n", "10", "--ascii", "-o", "a.glb"],
        &["--ascii", "a.glb", ".ply"],
    );
    assert!(!d.join("a.glb").exists());
    no_partial_files(d);
}

/// `Σ a · (b × c) / 6` over the triangles: the enclosed volume, positive
/// when the triangles face out (of a closed surface, whatever the origin:
/// the positions are taken relative to the mesh's).
fn signed_volume(mesh: &TriMesh) -> f64 {
    mesh.indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize].as_dvec3());
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

#[test]
fn tetra_writes_the_closed_outward_boundary_of_its_tetrahedra_as_gltf() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let blob = blob(d);
    let blob = blob.to_str().unwrap();
    let report = json(
        d,
        &[
            "tetra",
            blob,
            "--spacing",
            "0.15",
            "-o",
            "blob.node",
            "--glb",
            "boundary.glb",
        ],
    );
    assert_eq!(
        files(&report),
        ["blob.ele", "blob.node", "boundary.glb"],
        "{report}"
    );
    let tets = trilux_io::tet::read(d.join("blob.node")).unwrap();
    let boundary = tets.boundary();
    let scene = checked(&d.join("boundary.glb"));
    let mesh = &scene.mesh;
    assert!(scene.points.positions.is_empty());
    assert_eq!(mesh.indices.len(), boundary.len());
    assert_eq!(report["boundary_triangles"], boundary.len());
    // Only the boundary's nodes, each where the .node file has it.
    let mut nodes: Vec<u32> = boundary.iter().flatten().copied().collect();
    nodes.sort_unstable();
    nodes.dedup();
    assert_eq!(mesh.positions.len(), nodes.len());
    for p in &mesh.positions {
        let p = p.as_dvec3() + mesh.origin;
        let nearest = nodes
            .iter()
            .map(|&v| tets.positions[v as usize].distance(p))
            .fold(f64::INFINITY, f64::min);
        assert!(nearest < 1e-6, "{p} is no boundary node");
    }
    // Closed, and facing out: it encloses the tetrahedra's volume.
    let shape = trilux::mesh::shape(mesh);
    assert_eq!((shape.boundary_edges, shape.non_manifold_edges), (0, 0));
    let (enclosed, volume) = (signed_volume(mesh), tets.volume());
    assert!(
        (enclosed - volume).abs() < 1e-5 * volume,
        "{enclosed} vs {volume}"
    );

    // .gltf beside another format: the same surface, with its .bin.
    let report = json(
        d,
        &[
            "tetra",
            blob,
            "--spacing",
            "0.15",
            "-o",
            "blob.vtu",
            "--glb",
            "boundary.gltf",
            "--preview",
            "boundary.png",
        ],
    );
    assert_eq!(
        files(&report),
        ["blob.vtu", "boundary.bin", "boundary.gltf", "boundary.png"],
        "{report}"
    );
    let gltf = checked(&d.join("boundary.gltf"));
    assert_eq!(gltf.mesh.indices, mesh.indices);
    assert_eq!(gltf.mesh.positions, mesh.positions);
    no_partial_files(d);
}

#[test]
fn tetra_boundary_far_from_the_origin_keeps_its_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let at = DVec3::new(250_000.0, -40_000.0, 7.5);
    let mut far = trilux::shapes::blob(1);
    far.origin = at;
    far.write(d.join("far.ply")).unwrap();
    json(
        d,
        &[
            "tetra",
            "far.ply",
            "--spacing",
            "0.2",
            "-o",
            "far.node",
            "--glb",
            "far.glb",
        ],
    );
    let scene = checked(&d.join("far.glb"));
    let tets = trilux_io::tet::read(d.join("far.node")).unwrap();
    let (enclosed, volume) = (signed_volume(&scene.mesh), tets.volume());
    assert!(
        (enclosed - volume).abs() < 1e-4 * volume,
        "{enclosed} vs {volume}"
    );
    // Every vertex within f32's step of the unit-size blob's, not of
    // 250000's (1/64).
    let centre = scene
        .mesh
        .positions
        .iter()
        .fold(DVec3::ZERO, |s, p| s + p.as_dvec3() + scene.mesh.origin)
        / scene.mesh.positions.len() as f64;
    assert!(centre.distance(at) < 0.2, "{centre}");
    let shape = trilux::mesh::shape(&scene.mesh);
    assert_eq!((shape.boundary_edges, shape.non_manifold_edges), (0, 0));
}

#[test]
fn gltf_outputs_are_not_overwritten_without_force_and_other_extensions_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, noise) = torus_and_noise(d);
    let (torus, noise) = (torus.to_str().unwrap(), noise.to_str().unwrap());
    let blob = blob(d);
    let blob = blob.to_str().unwrap();
    json(
        d,
        &[
            "colors",
            "convert",
            torus,
            "--texture",
            noise,
            "-o",
            "t.meshcolors",
        ],
    );
    let precious = |name: &str| std::fs::write(d.join(name), "precious").unwrap();
    let kept = |name: &str| {
        assert_eq!(
            std::fs::read_to_string(d.join(name)).unwrap(),
            "precious",
            "{name}"
        )
    };
    for name in ["p.glb", "atlas.glb", "surface.glb", "q.bin"] {
        precious(name);
    }
    let sample = ["sample", torus, "-n", "10"];
    let bake = ["colors", "bake", torus, "t.meshcolors"];
    let tetra = ["tetra", blob, "--spacing", "0.2", "-o", "b.node"];
    fails_with(
        d,
        1,
        &[&sample[..], &["-o", "p.glb"]].concat(),
        &["p.glb", "--force"],
    );
    fails_with(
        d,
        1,
        &[&bake[..], &["-o", "atlas.glb"]].concat(),
        &["atlas.glb", "--force"],
    );
    // Refused before the stuffing: no tetrahedra written either.
    fails_with(
        d,
        1,
        &[&tetra[..], &["--glb", "surface.glb"]].concat(),
        &["surface.glb", "--force"],
    );
    assert!(!d.join("b.node").exists());
    // A .gltf's .bin is an output too.
    fails_with(
        d,
        1,
        &[&sample[..], &["-o", "q.gltf"]].concat(),
        &["q.bin", "--force"],
    );
    assert!(!d.join("q.gltf").exists());
    for name in ["p.glb", "atlas.glb", "surface.glb", "q.bin"] {
        kept(name);
    }
    // --force replaces them.
    trilux(d)
        .args(sample)
        .args(["-o", "p.glb", "--force"])
        .assert()
        .success();
    assert_eq!(checked(&d.join("p.glb")).points.positions.len(), 10);
    trilux(d)
        .args(sample)
        .args(["-o", "q.gltf", "--force"])
        .assert()
        .success();
    assert_eq!(checked(&d.join("q.gltf")).points.positions.len(), 10);
    trilux(d)
        .args(bake)
        .args(["-o", "atlas.glb", "--force"])
        .assert()
        .success();
    assert_eq!(checked(&d.join("atlas.glb")).mesh.indices.len(), 256);
    trilux(d)
        .args(tetra)
        .args(["--glb", "surface.glb", "--force"])
        .assert()
        .success();
    assert!(!checked(&d.join("surface.glb")).mesh.indices.is_empty());

    // Extensions the commands do not write: usage errors naming the
    // option, the file and what they write.
    fails_with(
        d,
        2,
        &[&sample[..], &["-o", "p.fbx"]].concat(),
        &["error: -o p.fbx: expected .ply, .glb or .gltf"],
    );
    fails_with(
        d,
        2,
        &[&bake[..], &["-o", "atlas.fbx"]].concat(),
        &["error: -o atlas.fbx: expected .obj, .glb or .gltf"],
    );
    fails_with(
        d,
        2,
        &[&tetra[..], &["--glb", "surface.obj", "--force"]].concat(),
        &["error: --glb surface.obj: expected .glb or .gltf"],
    );
    for name in ["p.fbx", "atlas.fbx", "surface.obj"] {
        assert!(!d.join(name).exists(), "{name}");
    }
    no_partial_files(d);
}

#[test]
fn a_folder_in_the_way_of_a_gltf_or_its_bin_is_refused_even_with_force() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, _) = torus_and_noise(d);
    let torus = torus.to_str().unwrap();
    let sample = ["--force", "sample", torus, "-n", "10", "-o"];
    std::fs::create_dir(d.join("x.bin")).unwrap();
    // Before sampling: the .bin the .gltf needs is a folder.
    let message = fails_with(
        d,
        1,
        &[&sample[..], &["x.gltf"]].concat(),
        &["error: x.bin: a folder is in the way of the .bin written beside x.gltf"],
    );
    assert_eq!(message.lines().count(), 1, "{message}");
    assert!(!d.join("x.gltf").exists(), "a .gltf without its .bin");
    assert!(d.join("x.bin").is_dir());
    // The output itself a folder: a usage error naming the option.
    std::fs::create_dir(d.join("y.glb")).unwrap();
    fails_with(
        d,
        2,
        &[&sample[..], &["y.glb"]].concat(),
        &[
            "error: -o y.glb: a folder, not a file (expected a file name ending in .ply, .glb or .gltf)",
        ],
    );
    // A file where the output's folder should be.
    std::fs::write(d.join("afile"), "").unwrap();
    fails_with(
        d,
        1,
        &[&sample[..], &["afile/x.glb"]].concat(),
        &["error: afile/x.glb: afile is a file, not a folder"],
    );
    no_partial_files(d);
}

/// `trilux info FILE --json`.
fn info(dir: &Path, file: &str) -> serde_json::Value {
    json(dir, &["info", file])
}

/// `trilux info FILE` as text.
fn info_text(dir: &Path, file: &str) -> String {
    let out = trilux(dir).args(["info", file]).output().unwrap();
    assert!(out.status.success(), "{out:?}");
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn info_reports_sampled_gltf_points_as_it_reports_a_ply_point_cloud() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, _) = torus_and_noise(d);
    let torus = torus.to_str().unwrap();
    let sample = |out: &str| json(d, &["sample", torus, "-n", "40", "--seed", "5", "-o", out]);
    for out in ["p.glb", "p.gltf", "p.ply"] {
        sample(out);
    }
    let ply = info(d, "p.ply");
    for file in ["p.glb", "p.gltf"] {
        let glb = info(d, file);
        assert_eq!(glb["kind"], "point cloud", "{glb}");
        assert_eq!(glb["points"], 40);
        assert_eq!(glb["attributes"], ply["attributes"], "{glb} vs {ply}");
        assert_eq!(
            glb["attributes"],
            serde_json::json!(["normals", "uvs", "face ids"])
        );
        assert_eq!(glb["normals"], true);
        assert_eq!(glb["colors"], serde_json::Value::Null);
        assert_eq!(glb["custom_attributes"], serde_json::json!([]));
        let faces = glb["face_ids"].as_array().expect("a face id range");
        assert!(faces[1].as_u64().unwrap() < 256, "{glb}");
        let u = glb["uvs"]["u"].as_array().expect("a UV range");
        assert!(u[0].as_f64().unwrap() <= u[1].as_f64().unwrap());
        // The same points: the same bounds, to f32 precision.
        for (a, b) in [0, 1].map(|k| (&glb["bounds"][k], &ply["bounds"][k])) {
            for c in 0..3 {
                let (a, b) = (a[c].as_f64().unwrap(), b[c].as_f64().unwrap());
                assert!((a - b).abs() < 1e-5, "{glb} vs {ply}");
            }
        }
        assert_eq!(glb["warnings"], serde_json::json!([]));
        let text = info_text(d, file);
        assert!(
            text.starts_with(&format!("{file}: point cloud\n")),
            "{text}"
        );
        for line in [
            "  points: 40\n",
            "  attributes: normals, uvs, face ids (_FACE)\n",
            "  face ids: ",
            "  UVs: u ",
        ] {
            assert!(text.contains(line), "{line:?} not in {text}");
        }
        assert!(!text.contains("triangle mesh"), "{text}");
    }
}
