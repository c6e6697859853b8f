//! End-to-end tests of the `trilux` binary: outputs exist, parse back with
//! trilux-io and carry the right counts; bad inputs fail with a message
//! naming the problem and the file; outputs are never clobbered or left
//! half-written.

use std::path::{Path, PathBuf};

use crate::common;
use common::{
    data, fails, fails_with, have_data, json, no_partial_files, run, stderr, trilux, trilux_bin,
};
use trilux_io::mesh::TriMesh;

/// A built-in textured torus and a noise texture written as files.
fn inputs(dir: &Path) -> (PathBuf, PathBuf) {
    common::torus_and_noise(dir, [48, 24], 64)
}

#[test]
fn every_subcommand_has_help_with_an_example() {
    let dir = tempfile::tempdir().unwrap();
    for sub in [
        &["info"][..],
        &["sample"],
        &["colors", "convert"],
        &["colors", "bake"],
        &["colors", "render"],
        &["demo"],
        &["bench"],
        &["tetra"],
        &["diffuse"],
    ] {
        let mut args = sub.to_vec();
        args.push("--help");
        let out = trilux(dir.path()).args(&args).output().unwrap();
        assert!(out.status.success(), "{args:?}");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("Example"), "{args:?}: {text}");
    }
}

#[test]
fn sample_writes_binary_or_ascii_ply_with_normals_uvs_and_faces() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, noise) = inputs(d);
    let torus = torus.to_str().unwrap();
    let out = trilux(d)
        .args([
            "sample",
            torus,
            "-n",
            "5000",
            "--density",
            noise.to_str().unwrap(),
            "-o",
            "a.ply",
            "--preview",
            "a.png",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["points"], 5000);
    assert_eq!(json["method"], "subdivision");
    let ply = trilux_io::mesh::ply::read(d.join("a.ply")).unwrap();
    assert_eq!(ply.positions.len(), 5000);
    assert!(ply.normals.is_some() && ply.uvs.is_some());
    let mesh = TriMesh::read(torus).unwrap();
    assert!(
        ply.face_ids
            .as_ref()
            .unwrap()
            .iter()
            .all(|&f| (f as usize) < mesh.indices.len())
    );
    assert!(
        std::fs::read(d.join("a.ply"))
            .unwrap()
            .starts_with(b"ply\nformat binary_little_endian")
    );
    let preview = trilux_io::image::read(d.join("a.png")).unwrap();
    assert_eq!((preview.width, preview.height), (768, 768));
    // ASCII, other methods, same seed → same points on any thread count.
    for (method, threads) in [("exact", "1"), ("rejection", "2"), ("subdivision", "1")] {
        let out = trilux(d)
            .args([
                "-q",
                "sample",
                torus,
                "-n",
                "3000",
                "--density",
                noise.to_str().unwrap(),
                "--method",
                method,
                "--threads",
                threads,
                "--ascii",
                "-o",
                &format!("{method}{threads}.ply"),
            ])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        let text = std::fs::read_to_string(d.join(format!("{method}{threads}.ply"))).unwrap();
        assert!(text.starts_with("ply\nformat ascii"));
        assert_eq!(
            trilux_io::mesh::ply::read(d.join(format!("{method}{threads}.ply")))
                .unwrap()
                .positions
                .len(),
            3000
        );
    }
    let one = trilux_io::mesh::ply::read(d.join("subdivision1.ply")).unwrap();
    trilux(d)
        .args([
            "-q",
            "sample",
            torus,
            "-n",
            "3000",
            "--density",
            noise.to_str().unwrap(),
            "--threads",
            "2",
            "--ascii",
            "-o",
            "two.ply",
        ])
        .assert()
        .success();
    assert_eq!(
        one.positions,
        trilux_io::mesh::ply::read(d.join("two.ply"))
            .unwrap()
            .positions
    );
    // Uniform and per-face weights.
    let weights: String = (0..mesh.indices.len())
        .map(|f| format!("{}\n", f % 3))
        .collect();
    std::fs::write(d.join("w.txt"), weights).unwrap();
    trilux(d)
        .args(["sample", torus, "-n", "100", "-o", "u.ply"])
        .assert()
        .success();
    trilux(d)
        .args([
            "sample",
            torus,
            "-n",
            "100",
            "--face-weights",
            "w.txt",
            "-o",
            "w.ply",
        ])
        .assert()
        .success();
    let w = trilux_io::mesh::ply::read(d.join("w.ply")).unwrap();
    assert!(
        w.face_ids.unwrap().iter().all(|f| f % 3 != 0),
        "weight-0 faces get no points"
    );
    no_partial_files(d);
}

#[test]
fn colors_convert_bake_render_and_sample_by_mesh_colours() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, noise) = inputs(d);
    let (torus, noise) = (torus.to_str().unwrap(), noise.to_str().unwrap());
    let out = trilux(d)
        .args([
            "colors",
            "convert",
            torus,
            "--texture",
            noise,
            "-o",
            "t.meshcolors",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(json["psnr_db"].as_f64().unwrap() > 30.0, "{json}");
    let (colors, _) = mesh_colors::file::load(d.join("t.meshcolors")).unwrap();
    assert_eq!(colors.face_count(), 48 * 24 * 2);
    trilux(d)
        .args([
            "colors",
            "bake",
            torus,
            "t.meshcolors",
            "-o",
            "atlas.obj",
            "--mip",
            "2",
        ])
        .assert()
        .success();
    let baked = TriMesh::read(d.join("atlas.obj")).unwrap();
    assert_eq!(baked.indices.len(), colors.face_count());
    assert!(
        baked.materials[0]
            .diffuse_texture
            .as_ref()
            .unwrap()
            .exists()
    );
    for filter in ["nearest", "linear", "mip", "aniso"] {
        trilux(d)
            .args([
                "colors",
                "render",
                torus,
                "t.meshcolors",
                "--filter",
                filter,
                "--size",
                "64",
                "-o",
                &format!("{filter}.png"),
            ])
            .assert()
            .success();
        assert_eq!(
            trilux_io::image::read(d.join(format!("{filter}.png")))
                .unwrap()
                .width,
            64
        );
    }
    trilux(d)
        .args([
            "colors",
            "render",
            torus,
            "t.meshcolors",
            "--size",
            "32",
            "-o",
            "r.exr",
        ])
        .assert()
        .success();
    trilux(d)
        .args([
            "sample",
            torus,
            "-n",
            "2000",
            "--density-meshcolors",
            "t.meshcolors",
            "--channel",
            "r",
            "-o",
            "mc.ply",
        ])
        .assert()
        .success();
    assert_eq!(
        trilux_io::mesh::ply::read(d.join("mc.ply"))
            .unwrap()
            .positions
            .len(),
        2000
    );
    trilux(d)
        .args([
            "colors",
            "render",
            torus,
            "t.meshcolors",
            "--size",
            "32",
            "--view",
            "1,0,0",
            "-o",
            "side.png",
        ])
        .assert()
        .success();
    fails(
        d,
        &[
            "colors",
            "render",
            torus,
            "t.meshcolors",
            "--view",
            "0,0,0",
            "-o",
            "zero.png",
        ],
        &["--view"],
    );
    // Mesh colours of another mesh are refused, naming the file.
    trilux::shapes::torus(20, 10)
        .write(d.join("other.obj"))
        .unwrap();
    fails(
        d,
        &[
            "colors",
            "render",
            "other.obj",
            "t.meshcolors",
            "-o",
            "x.png",
        ],
        &["t.meshcolors", "belong to a mesh"],
    );
    no_partial_files(d);
}

#[test]
fn info_describes_meshes_images_point_clouds_and_mesh_colours() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, noise) = inputs(d);
    let out = trilux(d)
        .args(["info", torus.to_str().unwrap(), "--json"])
        .output()
        .unwrap();
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["triangles"], 48 * 24 * 2);
    assert_eq!(json["holes"], 0);
    assert_eq!(json["parts"], 1);
    assert_eq!(json["welded_vertices"], 48 * 24);
    let out = trilux(d)
        .args(["info", noise.to_str().unwrap(), "--json"])
        .output()
        .unwrap();
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["width"], 64);
    let out = trilux(d)
        .args(["info", torus.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stdout).contains("triangles: 2304"));
}

#[test]
fn demo_writes_every_pipeline_with_a_preview_and_refuses_to_overwrite() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = trilux(d)
        .args(["demo", "--out", "demo", "--size", "96", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let pipelines = json["pipelines"].as_array().unwrap();
    assert!(pipelines.len() >= 7);
    assert!(
        pipelines.iter().any(|p| p["name"] == "translucent"),
        "no translucent pipeline"
    );
    for p in pipelines {
        let files = p["files"].as_array().unwrap();
        assert!(
            files.iter().any(|f| f.as_str().unwrap().ends_with(".png")),
            "{p}"
        );
        for f in files {
            let f = d.join(f.as_str().unwrap());
            assert!(f.exists(), "{}", f.display());
            match f.extension().unwrap().to_str().unwrap() {
                "ply" => assert!(!trilux_io::mesh::ply::read(&f).unwrap().positions.is_empty()),
                "obj" => assert!(!TriMesh::read(&f).unwrap().indices.is_empty()),
                "png" | "exr" => assert!(trilux_io::image::read(&f).unwrap().width > 0),
                "meshcolors" => assert!(mesh_colors::file::load(&f).unwrap().0.sample_count() > 0),
                "node" => assert!(!trilux_io::tet::read(&f).unwrap().tets.is_empty()),
                _ => {}
            }
        }
    }
    fails(d, &["demo", "--out", "demo"], &["demo", "--force"]);
    trilux(d)
        .args(["demo", "--out", "demo", "--size", "32", "--force"])
        .assert()
        .success();
}

#[test]
fn bad_inputs_fail_with_a_message_naming_the_problem_and_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, _) = inputs(d);
    let torus = torus.to_str().unwrap();
    fails(
        d,
        &["sample", "missing.obj", "-n", "10", "-o", "a.ply"],
        &["missing.obj"],
    );
    std::fs::write(
        d.join("corrupt.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n",
    )
    .unwrap();
    fails(
        d,
        &["sample", "corrupt.obj", "-n", "10", "-o", "a.ply"],
        &["corrupt.obj", "line 4"],
    );
    std::fs::write(d.join("fake.png"), "this is not a PNG").unwrap();
    fails(
        d,
        &[
            "sample",
            torus,
            "-n",
            "10",
            "--density",
            "fake.png",
            "-o",
            "a.ply",
        ],
        &["fake.png", "PNG"],
    );
    fails(d, &["info", "fake.png"], &["fake.png"]);
    fails(d, &["sample", torus, "-n", "-5", "-o", "a.ply"], &["-5"]);
    fails(d, &["sample", torus, "-n", "0", "-o", "a.ply"], &["-n 0"]);
    fails(
        d,
        &[
            "sample", torus, "-n", "10", "--method", "magic", "-o", "a.ply",
        ],
        &["magic"],
    );
    fails(
        d,
        &["sample", torus, "-n", "10", "-o", "a.txt"],
        &["a.txt", ".ply"],
    );
    fails(
        d,
        &["sample", torus, "-n", "10", "-o", "nowhere/a.ply"],
        &["nowhere"],
    );
    fails(
        d,
        &["sample", torus, "-n", "10", "--threads", "0", "-o", "a.ply"],
        &["--threads"],
    );
    std::fs::write(d.join("w.txt"), "1\n2\nthree\n").unwrap();
    fails(
        d,
        &[
            "sample",
            torus,
            "-n",
            "10",
            "--face-weights",
            "w.txt",
            "-o",
            "a.ply",
        ],
        &["w.txt", "line 3", "three"],
    );
    fails(
        d,
        &["colors", "convert", torus, "-o", "t.meshcolors"],
        &["torus.obj", "--texture"],
    );
    fails(
        d,
        &[
            "colors",
            "convert",
            torus,
            "--texture",
            "fake.png",
            "--max-res",
            "100",
            "-o",
            "t.meshcolors",
        ],
        &["--max-res 100"],
    );
    std::fs::write(d.join("bad.meshcolors"), "MESHCOLR garbage").unwrap();
    fails(
        d,
        &["colors", "render", torus, "bad.meshcolors", "-o", "x.png"],
        &["bad.meshcolors"],
    );
    fails(d, &["info", "notes.xyz"], &["notes.xyz"]);
    no_partial_files(d);
    assert!(!d.join("a.ply").exists());
}

#[test]
fn an_existing_output_is_kept_without_force_and_replaced_with_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, _) = inputs(d);
    let torus = torus.to_str().unwrap();
    std::fs::write(d.join("out.ply"), "precious").unwrap();
    fails(
        d,
        &["sample", torus, "-n", "10", "-o", "out.ply"],
        &["out.ply", "--force"],
    );
    assert_eq!(
        std::fs::read_to_string(d.join("out.ply")).unwrap(),
        "precious"
    );
    trilux(d)
        .args(["sample", torus, "-n", "10", "-o", "out.ply", "--force"])
        .assert()
        .success();
    assert_eq!(
        trilux_io::mesh::ply::read(d.join("out.ply"))
            .unwrap()
            .positions
            .len(),
        10
    );
    no_partial_files(d);
}

#[test]
fn an_interrupted_run_leaves_no_output_file_or_a_complete_one() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, _) = inputs(d);
    let mut child = std::process::Command::new(trilux_bin())
        .current_dir(d)
        .args([
            "-q",
            "sample",
            torus.to_str().unwrap(),
            "-n",
            "3000000",
            "-o",
            "big.ply",
        ])
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(300));
    let _ = child.kill();
    let _ = child.wait();
    let out = d.join("big.ply");
    if out.exists() {
        assert_eq!(
            trilux_io::mesh::ply::read(&out).unwrap().positions.len(),
            3_000_000
        );
    }
}

#[test]
fn real_files_through_every_subcommand() {
    if !have_data("real_files_through_every_subcommand") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bunny = data("meshes/stanford-bunny.obj");
    let spot = data("meshes/spot.obj");
    let texture = data("textures/spot_texture.png");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    trilux(d)
        .args([
            "sample",
            &s(&bunny),
            "-n",
            "20000",
            "-o",
            "bunny.ply",
            "--preview",
            "bunny.png",
        ])
        .assert()
        .success();
    let ply = trilux_io::mesh::ply::read(d.join("bunny.ply")).unwrap();
    assert_eq!(ply.positions.len(), 20000);
    assert!(ply.uvs.is_none());
    trilux(d)
        .args([
            "sample",
            &s(&spot),
            "-n",
            "20000",
            "--density",
            &s(&texture),
            "-o",
            "spot.ply",
        ])
        .assert()
        .success();
    trilux(d)
        .args([
            "colors",
            "convert",
            &s(&spot),
            "--texture",
            &s(&texture),
            "-o",
            "spot.meshcolors",
        ])
        .assert()
        .success();
    trilux(d)
        .args([
            "colors",
            "bake",
            &s(&spot),
            "spot.meshcolors",
            "-o",
            "spot_atlas.obj",
        ])
        .assert()
        .success();
    assert_eq!(
        TriMesh::read(d.join("spot_atlas.obj"))
            .unwrap()
            .indices
            .len(),
        5856
    );
    trilux(d)
        .args([
            "colors",
            "render",
            &s(&spot),
            "spot.meshcolors",
            "--filter",
            "aniso",
            "-o",
            "spot.png",
        ])
        .assert()
        .success();
    // A glTF with embedded texture converts without --texture.
    let fox = data("gltf/Fox.glb");
    trilux(d)
        .args(["colors", "convert", &s(&fox), "-o", "fox.meshcolors"])
        .assert()
        .success();
    for (file, key, value) in [
        ("meshes/stanford-bunny.obj", "holes", 5),
        ("meshes/teapot.obj", "welded_vertices", 3_241),
        ("tets/sphere_20k.node", "tetrahedra", 19_443),
        ("tets/bunny_500k.msh", "nodes", 93_375),
        ("tets/bunny_50k.face", "faces", 7_108),
    ] {
        let out = trilux(d)
            .args(["info", &s(&data(file)), "--json"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{file}: {}", stderr(&out));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(json[key], value, "{file}: {json}");
    }
    // Mesh colours made for spot are refused for the bunny.
    fails(
        d,
        &[
            "colors",
            "render",
            &s(&bunny),
            "spot.meshcolors",
            "-o",
            "x.png",
        ],
        &["spot.meshcolors"],
    );
    fails(
        d,
        &[
            "sample",
            &s(&bunny),
            "-n",
            "10",
            "--density",
            &s(&texture),
            "-o",
            "x.ply",
        ],
        &["stanford-bunny.obj", "texture coordinates"],
    );
}

#[test]
fn info_on_an_obj_without_faces_says_so_and_does_not_call_it_closed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("empty.obj"), "").unwrap();
    std::fs::write(d.join("points.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
    for file in ["empty.obj", "points.obj"] {
        let out = run(d, &["info", file]);
        assert!(out.status.success(), "{file}: {}", stderr(&out));
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("no faces"), "{file}: {text}");
        assert!(
            !text.contains("closed") && !text.contains("watertight"),
            "{file}: {text}"
        );
        assert!(!text.contains("-0"), "{file}: negative zero in {text}");
        let report = json(d, &["info", file]);
        assert_eq!(report["triangles"], 0, "{file}: {report}");
        assert_eq!(report["closed"], false, "{file}: {report}");
    }
}

#[test]
fn sample_channel_without_a_density_image_or_mesh_colours_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (_, noise) = inputs(d);
    let noise = noise.to_str().unwrap();
    fails_with(
        d,
        2,
        &[
            "sample",
            "torus.obj",
            "-n",
            "10",
            "--channel",
            "r",
            "-o",
            "a.ply",
        ],
        &["--channel"],
    );
    // Per-face weights have no channels either.
    std::fs::write(d.join("w.txt"), "1\n".repeat(48 * 24 * 2)).unwrap();
    fails_with(
        d,
        2,
        &[
            "sample",
            "torus.obj",
            "-n",
            "10",
            "--face-weights",
            "w.txt",
            "--channel",
            "g",
            "-o",
            "a.ply",
        ],
        &["--channel", "--face-weights"],
    );
    assert!(!d.join("a.ply").exists());
    let report = json(
        d,
        &[
            "sample",
            "torus.obj",
            "-n",
            "10",
            "--density",
            noise,
            "--channel",
            "r",
            "-o",
            "a.ply",
        ],
    );
    assert_eq!(report["points"], 10);
}

/// Every error is one line, `error: WHERE: WHAT`, where WHERE is the file
/// or the argument as typed (named once), with no closing full stop.
#[test]
fn errors_are_one_line_naming_the_file_or_argument_first_in_every_subcommand() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    inputs(d);
    std::fs::write(d.join("bad.meshcolors"), "MESHCOLR garbage").unwrap();
    std::fs::write(d.join("fake.png"), "this is not a PNG").unwrap();
    let cases: &[(&[&str], &str)] = &[
        // A missing input, whichever subcommand and argument names it.
        (&["info", "missing.obj"], "missing.obj: no such file"),
        (
            &["sample", "missing.obj", "-n", "10", "-o", "a.ply"],
            "missing.obj: no such file",
        ),
        (
            &[
                "sample",
                "torus.obj",
                "-n",
                "10",
                "--density",
                "missing.png",
                "-o",
                "a.ply",
            ],
            "missing.png: no such file",
        ),
        (
            &[
                "sample",
                "torus.obj",
                "-n",
                "10",
                "--face-weights",
                "missing.txt",
                "-o",
                "a.ply",
            ],
            "missing.txt: no such file",
        ),
        (
            &[
                "colors",
                "render",
                "torus.obj",
                "missing.meshcolors",
                "-o",
                "x.png",
            ],
            "missing.meshcolors: no such file",
        ),
        (
            &[
                "colors",
                "convert",
                "torus.obj",
                "--texture",
                "missing.png",
                "-o",
                "t.meshcolors",
            ],
            "missing.png: no such file",
        ),
        (
            &["tetra", "missing.obj", "-o", "m.node"],
            "missing.obj: no such file",
        ),
        (
            &["diffuse", "missing.node", "-o", "a.png"],
            "missing.node: no such file",
        ),
        // A bad file, named once.
        (
            &[
                "colors",
                "render",
                "torus.obj",
                "bad.meshcolors",
                "-o",
                "x.png",
            ],
            "bad.meshcolors: ",
        ),
        (&["info", "fake.png"], "fake.png: "),
        // An argument as typed, then what is wrong with it.
        (
            &[
                "sample",
                "torus.obj",
                "-n",
                "10",
                "--threads",
                "0",
                "-o",
                "a.ply",
            ],
            "--threads 0: ",
        ),
        (
            &[
                "colors",
                "convert",
                "torus.obj",
                "--budget",
                "0",
                "-o",
                "t.meshcolors",
            ],
            "--budget 0: ",
        ),
        (&["bench", "sampling", "--repeats", "0"], "--repeats 0: "),
        // Checked before gigabytes of colours are built.
        (&["paint", "--resolution", "1024"], "--resolution 1024: "),
    ];
    for &(args, start) in cases {
        fails(d, args, &[start]);
        let err = stderr(&run(d, args));
        let line = err.strip_suffix('\n').unwrap_or(&err);
        assert!(
            !line.contains('\n'),
            "{args:?}: more than one line: {err:?}"
        );
        assert!(
            line.starts_with(&format!("error: {start}")),
            "{args:?}: {line:?} does not start with {start:?}"
        );
        assert!(!line.ends_with('.'), "{args:?}: {line:?}");
        let place = start.split(": ").next().unwrap();
        assert_eq!(line.matches(place).count(), 1, "{args:?}: {line:?}");
    }
    assert!(!d.join("demo").exists(), "a refused demo made its folder");
}

#[test]
fn a_bad_spec_is_a_usage_error_naming_the_argument_before_any_work() {
    // The output exists and the input does not: a spec checked after
    // either would report those instead.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("exists.png"), "an earlier picture").unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["--material", "jade"],
            "'jade' for '--material <MATERIAL>'",
        ),
        (&["--light", "dir:0,1"], "'dir:0,1' for '--light <SPEC>'"),
        (
            &["--cut", "plane:0,0,0,1"],
            "'plane:0,0,0,1' for '--cut <SPEC>'",
        ),
        (
            &["--paint", "0,0,0:0:ketchup"],
            "'0,0,0:0:ketchup' for '--paint <SPEC>'",
        ),
        (&["--fracture", "x"], "'x' for '--fracture <SPEC>'"),
        (&["--view", "0,0,0"], "'0,0,0' for '--view <X,Y,Z>'"),
        (&["--size", "0"], "'0' for '--size <SIZE>'"),
        (&["--unit-mm=-1"], "'-1' for '--unit-mm <X>'"),
    ];
    for &(spec, named) in cases {
        let args = [&["diffuse", "missing.node", "-o", "exists.png"][..], spec].concat();
        let err = fails_with(d, 2, &args, &[]);
        assert!(
            err.starts_with(&format!("error: invalid value {named}: ")),
            "{args:?}: {err:?}"
        );
    }
    let err = fails_with(
        d,
        2,
        &[
            "colors",
            "render",
            "missing.obj",
            "missing.meshcolors",
            "--view",
            "1,2",
            "-o",
            "exists.png",
        ],
        &[],
    );
    assert!(
        err.starts_with("error: invalid value '1,2' for '--view <X,Y,Z>': "),
        "{err:?}"
    );
    assert_eq!(
        std::fs::read(d.join("exists.png")).unwrap(),
        b"an earlier picture"
    );
}

#[test]
fn with_json_a_failure_is_one_json_object_on_stdout_with_the_same_exit_code() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    inputs(d);
    let cases: &[(&[&str], i32, &str)] = &[
        // A run error, --json after or before the subcommand.
        (&["info", "missing.obj", "--json"], 1, "missing.obj"),
        (&["--json", "info", "missing.obj"], 1, "missing.obj"),
        // A usage error found by trilux, and two found by the parser.
        (
            &[
                "sample",
                "torus.obj",
                "-n",
                "10",
                "--channel",
                "r",
                "-o",
                "a.ply",
                "--json",
            ],
            2,
            "--channel",
        ),
        (&["sample", "torus.obj", "--json"], 2, "--count"),
        (
            &[
                "--json",
                "sample",
                "torus.obj",
                "-n",
                "10",
                "--method",
                "magic",
                "-o",
                "a.ply",
            ],
            2,
            "magic",
        ),
        (&["--json", "frobnicate"], 2, "frobnicate"),
    ];
    for &(args, code, needle) in cases {
        let out = run(d, args);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {}", stderr(&out));
        let stdout = String::from_utf8(out.stdout.clone()).unwrap();
        assert_eq!(stdout.lines().count(), 1, "{args:?}: {stdout:?}");
        let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        assert_eq!(report.as_object().unwrap().len(), 2, "{report}");
        assert_eq!(report["exit_code"], code, "{report}");
        let message = report["error"].as_str().unwrap();
        assert!(message.contains(needle), "{args:?}: {report}");
        // The human message is on stderr too.
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
        // Without --json: the same exit code, and nothing on stdout.
        let plain: Vec<&str> = args.iter().copied().filter(|a| *a != "--json").collect();
        let out = run(d, &plain);
        assert_eq!(out.status.code(), Some(code), "{plain:?}");
        assert!(out.stdout.is_empty(), "{plain:?}");
    }
    // Help is still help.
    let out = run(d, &["sample", "--help", "--json"]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("Example"));
}

#[test]
fn global_options_are_listed_once_under_their_own_heading() {
    let dir = tempfile::tempdir().unwrap();
    for sub in [
        &[][..],
        &["info"],
        &["sample"],
        &["colors", "convert"],
        &["colors", "render"],
        &["tetra"],
        &["diffuse"],
        &["demo"],
        &["bench"],
    ] {
        let mut args = sub.to_vec();
        args.push("--help");
        let out = run(dir.path(), &args);
        assert!(out.status.success(), "{args:?}");
        let text = String::from_utf8_lossy(&out.stdout);
        let lines: Vec<&str> = text.lines().collect();
        let heading = lines
            .iter()
            .position(|l| *l == "Global options:")
            .unwrap_or_else(|| panic!("{args:?}: no global options heading in\n{text}"));
        // `info` writes nothing: its help does not offer --force.
        let writes = args[0] != "info";
        if !writes {
            assert!(
                !lines.iter().any(|l| l.trim_start().starts_with("--force")),
                "{args:?}: --force listed in\n{text}"
            );
        }
        let flags: &[&str] = if writes {
            &["--json", "--quiet", "--force"]
        } else {
            &["--json", "--quiet"]
        };
        for &flag in flags {
            let defined: Vec<usize> = (0..lines.len())
                .filter(|&i| {
                    let l = lines[i].trim_start();
                    l.starts_with(flag) || l.starts_with(&format!("-q, {flag}"))
                })
                .collect();
            assert_eq!(defined.len(), 1, "{args:?}: {flag} in\n{text}");
            // Under the heading: after it, with no other heading between.
            let at = defined[0];
            assert!(at > heading, "{args:?}: {flag} above the heading\n{text}");
            assert!(
                lines[heading + 1..at].iter().all(|l| l.starts_with(' ')),
                "{args:?}: {flag} not under the heading\n{text}"
            );
        }
    }
}

#[test]
fn sample_blue_noise_writes_the_library_points_for_the_seed() {
    use mesh_sampling::{BlueNoiseOptions, BlueNoiseTarget, blue_noise};
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, noise) = inputs(d);
    let mesh = TriMesh::read(&torus).unwrap();
    let options = BlueNoiseOptions {
        progressive: true,
        ..BlueNoiseOptions::default()
    };
    let written = |args: &[&str], name: &str| -> Vec<glam::Vec3> {
        let out = trilux(d)
            .args(["-q", "sample", torus.to_str().unwrap(), "--blue-noise"])
            .args(args)
            .args(["--seed", "11", "-o", name])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        trilux_io::mesh::ply::read(d.join(name)).unwrap().positions
    };
    let positions = |points: Vec<mesh_sampling::SurfacePoint>| -> Vec<glam::Vec3> {
        points.iter().map(|p| p.position).collect()
    };
    // Uniform, by count and by radius, on 1 and 2 threads.
    let uniform = mesh_sampling::UniformSampler::new(trilux::mesh_ref(&mesh)).unwrap();
    let library = blue_noise(&uniform, BlueNoiseTarget::Count(1500), 11, &options).unwrap();
    assert_eq!(written(&["-n", "1500"], "b1.ply"), positions(library));
    assert_eq!(
        written(&["-n", "1500", "--threads", "2"], "b2.ply"),
        written(&["-n", "1500", "--threads", "1"], "b3.ply")
    );
    let library = blue_noise(&uniform, BlueNoiseTarget::Radius(0.05), 11, &options).unwrap();
    assert!(library.len() > 100);
    assert_eq!(written(&["--radius", "0.05"], "r.ply"), positions(library));
    // A density texture, as the command reads it: values as stored.
    let raw = trilux_io::image::ReadOptions {
        raw: true,
        ..Default::default()
    };
    let image = trilux_io::image::read_with(&noise, raw).unwrap();
    let texture = trilux::density_texture(&image, mesh_sampling::Channel::Luminance).unwrap();
    let sampler = mesh_sampling::DensitySampler::new(
        trilux::mesh_ref(&mesh),
        mesh_sampling::Density::Texture(&texture),
    )
    .unwrap();
    let library = blue_noise(&sampler, BlueNoiseTarget::Count(1000), 11, &options).unwrap();
    let cli = written(
        &["-n", "1000", "--density", noise.to_str().unwrap()],
        "d.ply",
    );
    assert_eq!(cli, positions(library));
    // The dense packing, uniform and with the density, the same points as
    // the library's dense options in progressive order.
    let dense = BlueNoiseOptions {
        progressive: true,
        ..BlueNoiseOptions::dense()
    };
    let library = blue_noise(&uniform, BlueNoiseTarget::Count(1500), 11, &dense).unwrap();
    let cli = written(&["-n", "1500", "--packing", "dense"], "dense.ply");
    assert_eq!(cli, positions(library));
    let library = blue_noise(&sampler, BlueNoiseTarget::Count(1000), 11, &dense).unwrap();
    let cli = written(
        &[
            "-n",
            "1000",
            "--packing",
            "dense",
            "--density",
            noise.to_str().unwrap(),
        ],
        "dd.ply",
    );
    assert_eq!(cli, positions(library));
    // Rejection cannot give candidates; a radius must be positive and
    // needs --blue-noise, as does --packing.
    let t = torus.to_str().unwrap();
    fails_with(
        d,
        2,
        &["sample", t, "-n", "10", "--packing", "dense", "-o", "x.ply"],
        &["--blue-noise"],
    );
    fails_with(
        d,
        2,
        &[
            "sample",
            t,
            "--blue-noise",
            "-n",
            "10",
            "--packing",
            "tight",
            "-o",
            "x.ply",
        ],
        &["tight", "elimination", "dense"],
    );
    let n = noise.to_str().unwrap();
    let rejection = ["sample", t, "--blue-noise", "-n", "10", "--density", n];
    let rejection = [&rejection[..], &["--method", "rejection", "-o", "x.ply"]].concat();
    fails_with(d, 2, &rejection, &["--method rejection", "blue noise"]);
    fails_with(
        d,
        2,
        &["sample", t, "--blue-noise", "--radius=-1", "-o", "x.ply"],
        &["--radius", "positive"],
    );
    fails_with(
        d,
        2,
        &["sample", t, "--radius", "0.1", "-o", "x.ply"],
        &["--blue-noise"],
    );
    no_partial_files(d);
}
