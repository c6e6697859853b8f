//! End-to-end tests of `trilux tetra` and `trilux diffuse`: the files they
//! write parse back with trilux-io and carry the counts the command
//! reported; bad inputs fail with a message naming the problem and the
//! file or argument; outputs are not clobbered without `--force`.

use std::path::Path;

use crate::common;
use common::{blob, data, fails, fails_with, have_data, json, run, trilux};
use glam::Vec3;
use trilux_io::mesh::TriMesh;

/// The blob tetrahedralized at spacing `size` into `blob.node` (+ `.ele`).
fn stuffed_blob(dir: &Path, size: &str) {
    let blob = blob(dir);
    trilux(dir)
        .args([
            "tetra",
            blob.to_str().unwrap(),
            "--spacing",
            size,
            "-o",
            "blob.node",
        ])
        .assert()
        .success();
}

#[test]
fn tetra_writes_tetgen_medit_and_vtu_with_the_reported_counts() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let blob = blob(d);
    let blob = blob.to_str().unwrap();
    for out in ["blob.node", "blob.mesh"] {
        let report = json(d, &["tetra", blob, "--spacing", "0.15", "-o", out]);
        let mesh = trilux_io::tet::read(d.join(out)).unwrap();
        assert!(!mesh.tets.is_empty());
        assert_eq!(report["tetrahedra"], mesh.tets.len());
        assert_eq!(report["vertices"], mesh.positions.len());
        let [lo, hi] = [
            &report["dihedral_degrees"][0],
            &report["dihedral_degrees"][1],
        ]
        .map(|v| v.as_f64().unwrap());
        assert!(0.0 < lo && lo <= hi && hi < 180.0, "{lo} {hi}");
    }
    // The same lattice gives the same mesh in every format.
    let report = json(d, &["tetra", blob, "--spacing", "0.15", "-o", "blob.vtu"]);
    let vtu = std::fs::read_to_string(d.join("blob.vtu")).unwrap();
    let cells = format!("NumberOfCells=\"{}\"", report["tetrahedra"]);
    assert!(vtu.contains(&cells), "{cells} not in the VTU header");
    // Grading keeps the surface's resolution with fewer tetrahedra inside.
    let graded = json(
        d,
        &[
            "tetra",
            blob,
            "--spacing",
            "0.05",
            "--graded",
            "-o",
            "g.node",
        ],
    );
    let uniform = json(d, &["tetra", blob, "--spacing", "0.05", "-o", "u.node"]);
    assert!(
        graded["tetrahedra"].as_u64() < uniform["tetrahedra"].as_u64(),
        "graded {} vs uniform {}",
        graded["tetrahedra"],
        uniform["tetrahedra"]
    );
}

#[test]
fn tetra_reports_how_far_the_boundary_lies_from_the_surface_and_what_it_left_out() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The blob (about unit size) and, beside it, a square sheet of two
    // triangles that encloses nothing.
    let mut surface = trilux::shapes::blob(2);
    let base = surface.positions.len() as u32;
    surface.positions.extend(
        [
            [3.0, -0.5, -0.5],
            [3.0, 0.5, -0.5],
            [3.0, 0.5, 0.5],
            [3.0, -0.5, 0.5],
        ]
        .map(Vec3::from),
    );
    surface
        .indices
        .extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    surface.normals = None;
    surface.uvs = None;
    surface.objects.clear();
    surface.write(d.join("blob_sheet.obj")).unwrap();
    let args = [
        "tetra",
        "blob_sheet.obj",
        "--spacing",
        "0.1",
        "-o",
        "b.node",
        "--force",
    ];
    let report = json(d, &args);
    let distance = &report["distance"];
    let get = |key: &str| {
        distance[key]
            .as_f64()
            .unwrap_or_else(|| panic!("{key} in {report}"))
    };
    assert_eq!(distance["left_out_triangles"], 2, "{report}");
    // Within the lattice spacing, and the sheet (2 units away) not counted.
    assert!(
        get("hausdorff") < 0.1 && get("mean") < get("hausdorff"),
        "{report}"
    );
    assert!((get("hausdorff_fraction") - get("hausdorff") / get("diagonal")).abs() < 1e-12);
    assert!(get("input_points") >= 65536.0 && get("boundary_points") >= 65536.0);
    let out = run(d, &args);
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("; boundary within "), "{stdout}");
    let stderr = common::stderr(&out);
    assert!(
        stderr.contains("blob_sheet.obj: 2 triangles") && stderr.contains("left out"),
        "{stderr}"
    );
}

#[test]
fn tetra_fits_the_boundary_to_an_envelope_and_says_how_near_it_came() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let blob = blob(d);
    let blob = blob.to_str().unwrap();
    let plain = json(d, &["tetra", blob, "--spacing", "0.1", "-o", "p.node"]);
    let args = [
        "tetra",
        blob,
        "--spacing",
        "0.1",
        "--envelope",
        "0.002",
        "-o",
        "e.node",
    ];
    let fitted = json(d, &args);
    assert_eq!(fitted["envelope"], 0.002, "{fitted}");
    assert!(fitted["fitted_vertices"].as_u64().unwrap() > 0, "{fitted}");
    // The fit may split boundary edges where moves are not enough, within
    // three times the stuffed count.
    let count = |r: &serde_json::Value| r["tetrahedra"].as_u64().unwrap();
    assert!(
        count(&fitted) >= count(&plain) && count(&fitted) <= 3 * count(&plain),
        "{fitted} vs {plain}"
    );
    assert!(
        fitted["dihedral_degrees"][0].as_f64().unwrap() >= 10.0,
        "{fitted}"
    );
    // The stated bound: the stencils' 9°–162° widened to 165° by the fit.
    assert_eq!(
        fitted["dihedral_bound_degrees"],
        serde_json::json!([9.0, 165.0])
    );
    assert_eq!(
        plain["dihedral_bound_degrees"],
        serde_json::json!([9.0, 162.0])
    );
    let hausdorff = |r: &serde_json::Value| r["distance"]["hausdorff"].as_f64().unwrap();
    assert!(
        hausdorff(&fitted) <= hausdorff(&plain),
        "{fitted} vs {plain}"
    );
    assert!(plain["envelope"].is_null() && plain["fitted_vertices"] == 0);
    // The summary gives the spacing to 4 digits with its share of the
    // diagonal, and the envelope.
    let out = run(d, &[&args[..7], &["e2.node"]].concat());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("at spacing 0.1 (1/"), "{stdout}");
    assert!(
        stdout.contains("fitted to an envelope of 0.2% of the diagonal"),
        "{stdout}"
    );
    // Whether the envelope was reached, said in words and in --json.
    let reached = hausdorff(&fitted) / fitted["diagonal"].as_f64().unwrap() <= 0.002;
    assert_eq!(fitted["envelope_reached"], reached, "{fitted}");
    let verdict = if reached {
        ", within the envelope"
    } else {
        ", NOT within the 0.2% envelope"
    };
    assert!(stdout.contains(verdict), "{stdout}");
    assert!(plain["envelope_reached"].is_null(), "{plain}");
    // A wrong argument: exit code 2, naming the option, negative too.
    fails_with(
        d,
        2,
        &["tetra", blob, "--envelope", "1.5", "-o", "bad.node"],
        &["--envelope 1.5", "between 0 and 1"],
    );
    fails_with(
        d,
        2,
        &["tetra", blob, "--envelope", "-1", "-o", "bad.node"],
        &["--envelope -1", "between 0 and 1"],
    );
}

#[test]
fn tetra_refuses_a_surface_that_encloses_nothing_and_keeps_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let triangle = TriMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        indices: vec![[0, 1, 2]],
        ..TriMesh::default()
    };
    triangle.write(d.join("triangle.obj")).unwrap();
    fails(
        d,
        &["tetra", "triangle.obj", "--spacing", "0.1", "-o", "t.node"],
        &["triangle.obj", "encloses nothing"],
    );
    assert!(!d.join("t.node").exists() && !d.join("t.ele").exists());
    // An open sheet: a grid of triangles in a plane.
    let n = 8u32;
    let sheet = TriMesh {
        positions: (0..=n)
            .flat_map(|j| (0..=n).map(move |i| Vec3::new(i as f32, j as f32, 0.0) / n as f32))
            .collect(),
        indices: (0..n)
            .flat_map(|j| {
                (0..n).flat_map(move |i| {
                    let a = j * (n + 1) + i;
                    [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]
                })
            })
            .collect(),
        ..TriMesh::default()
    };
    sheet.write(d.join("sheet.obj")).unwrap();
    // No spacing gives a sheet a volume: the message says what is wrong
    // instead of asking for a smaller spacing.
    let err = fails_with(
        d,
        1,
        &["tetra", "sheet.obj", "--spacing", "0.1", "-o", "s.node"],
        &[
            "sheet.obj",
            "encloses nothing",
            "none of its 128 triangles bounds a volume",
        ],
    );
    assert!(!err.contains("smaller"), "{err}");
    fails(
        d,
        &["tetra", "missing.obj", "-o", "m.node"],
        &["missing.obj"],
    );
    let blob = blob(d);
    let blob = blob.to_str().unwrap();
    fails(
        d,
        &["tetra", blob, "--spacing=-1", "-o", "neg.node"],
        &["--spacing"],
    );
    // An existing output is kept without --force, replaced with it.
    std::fs::write(d.join("kept.mesh"), "precious").unwrap();
    fails(
        d,
        &["tetra", blob, "--spacing", "0.2", "-o", "kept.mesh"],
        &["kept.mesh", "--force"],
    );
    assert_eq!(
        std::fs::read_to_string(d.join("kept.mesh")).unwrap(),
        "precious"
    );
    trilux(d)
        .args([
            "tetra",
            blob,
            "--spacing",
            "0.2",
            "-o",
            "kept.mesh",
            "--force",
        ])
        .assert()
        .success();
    assert!(
        !trilux_io::tet::read(d.join("kept.mesh"))
            .unwrap()
            .tets
            .is_empty()
    );
}

#[test]
fn diffuse_renders_a_cut_translucent_blob_to_png_exr_and_vtu() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    stuffed_blob(d, "0.12");
    let tets = trilux_io::tet::read(d.join("blob.node")).unwrap();
    // The scene, rendered below with the chosen and a forced solver.
    let scene = [
        "diffuse",
        "blob.node",
        "--material",
        "marble",
        "--unit-mm",
        "20",
        "--light",
        "dir:0.3,1,0.6",
        "--light",
        "point:2,2,2:0.5,0.5,1",
        "--cut",
        "plane:0,0,1,0.2",
        "--size",
        "96",
    ];
    let report = json(
        d,
        &[
            &scene[..],
            &[
                "-o",
                "marble.png",
                "--exr",
                "marble.exr",
                "--vtu",
                "marble.vtu",
            ],
        ]
        .concat(),
    );
    assert_eq!(report["objects"], 1);
    // A small, well-conditioned blob: the automatic choice stays with
    // Jacobi-PCG, and the report says so and why.
    assert_eq!(report["solver"], "Jacobi-PCG", "{report:#}");
    // One reason per object.
    let why = report["solver_choice"].as_array().unwrap();
    assert_eq!(why.len(), 1);
    assert!(why[0].as_str().unwrap().starts_with("Jacobi-PCG (auto"));
    // --solver forces one; the picture is the same to 8 bits but for
    // rounding at the solver's tolerance.
    let forced = json(
        d,
        &[&scene[..], &["--solver", "vcycle", "-o", "vcycle.png"]].concat(),
    );
    assert_eq!(forced["solver"], "V-cycle-PCG", "{forced:#}");
    assert_eq!(forced["solver_choice"][0], "V-cycle-PCG (as set)");
    let vcycle = trilux_io::image::read(d.join("vcycle.png")).unwrap();
    let auto = trilux_io::image::read(d.join("marble.png")).unwrap();
    let worst = auto
        .pixels
        .iter()
        .zip(&vcycle.pixels)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
        .fold(0.0f32, f32::max);
    assert!(worst <= 2.0 / 255.0, "{worst}");
    // The cut removes the cap above z = 0.2 (splitting the tetrahedra it
    // crosses): fewer remain than were stuffed, but most of the blob.
    let cut = report["tetrahedra"].as_u64().unwrap();
    let stuffed = tets.tets.len() as u64;
    assert!(stuffed / 3 < cut && cut < stuffed, "{cut} of {stuffed}");
    let png = trilux_io::image::read(d.join("marble.png")).unwrap();
    assert_eq!((png.width, png.height), (96, 96));
    let lit = png
        .pixels
        .iter()
        .filter(|p| p[0] + p[1] + p[2] > 0.05 && **p != png.pixels[0])
        .count();
    assert!(lit > 96 * 96 / 20, "only {lit} lit pixels");
    let exr = trilux_io::image::read(d.join("marble.exr")).unwrap();
    assert_eq!((exr.width, exr.height), (96, 96));
    let vtu = std::fs::read_to_string(d.join("marble.vtu")).unwrap();
    for field in ["phi_r", "phi_g", "phi_b", "radiance"] {
        assert!(vtu.contains(&format!("Name=\"{field}\"")), "{field}");
    }
    // Paint a ball of skin into the marble, then break the blob in two.
    let report = json(
        d,
        &[
            "diffuse",
            "blob.node",
            "--paint",
            "0.5,0,0:0.4:skin1",
            "--fracture",
            "plane:1,0,0,0",
            "--view=0,0.3,1",
            "--size",
            "64",
            "-o",
            "broken.png",
        ],
    );
    assert_eq!(report["objects"], 2);
    // Each piece's solve says what ran and why; the timings add both
    // solves (a repeated step is summed, not overwritten) and the fracture.
    assert_eq!(report["solver_choice"].as_array().unwrap().len(), 2);
    let seconds = &report["seconds"];
    assert!(seconds["solving"].as_f64().unwrap() > 0.0, "{seconds}");
    assert!(seconds["fracturing"].as_f64().unwrap() > 0.0, "{seconds}");
    // The fracture splits the tetrahedra the plane crosses (both crack
    // faces flat), so the pieces hold more than were stuffed.
    let pieces = report["tetrahedra"].as_u64().unwrap();
    assert!(pieces > tets.tets.len() as u64, "{pieces}");
    fails(
        d,
        &[
            "diffuse",
            "blob.node",
            "--paint",
            "0,0,0:-1:skin1",
            "-o",
            "p.png",
        ],
        &["--paint", "radius"],
    );
    // A surface is tetrahedralized first; noise between two materials.
    let report = json(
        d,
        &[
            "diffuse",
            "blob.obj",
            "--material",
            "noise:marble,skin1",
            "--size",
            "64",
            "-o",
            "noise.png",
        ],
    );
    assert!(report["tetrahedra"].as_u64().unwrap() > 100);
    assert!(d.join("noise.png").exists());
}

#[test]
fn diffuse_names_a_bad_material_light_cut_or_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let blob = blob(d);
    let blob = blob.to_str().unwrap();
    fails(
        d,
        &["diffuse", blob, "--material", "jade", "-o", "a.png"],
        &["jade", "marble"],
    );
    fails(
        d,
        &["diffuse", blob, "--material", "noise:marble", "-o", "a.png"],
        &["noise:A,B"],
    );
    fails(
        d,
        &["diffuse", blob, "--light", "sun:0,1,0", "-o", "a.png"],
        &["--light", "sun"],
    );
    fails(
        d,
        &["diffuse", blob, "--light", "dir:0,1", "-o", "a.png"],
        &["--light", "3"],
    );
    fails(
        d,
        &["diffuse", blob, "--cut", "plane:0,0,0,1", "-o", "a.png"],
        &["--cut", "zero"],
    );
    fails(
        d,
        &["diffuse", blob, "--view", "0,0,0", "-o", "a.png"],
        &["--view", "zero"],
    );
    fails(
        d,
        &["diffuse", "missing.node", "-o", "a.png"],
        &["missing.node"],
    );
    assert!(!d.join("a.png").exists());
}

#[test]
fn tetra_stuffs_the_raw_bunny_and_diffuse_accepts_it() {
    if !have_data("tetra_stuffs_the_raw_bunny_and_diffuse_accepts_it") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bunny = data("meshes/stanford-bunny.obj");
    let report = json(d, &["tetra", bunny.to_str().unwrap(), "-o", "bunny.node"]);
    let min = report["dihedral_degrees"][0].as_f64().unwrap();
    let bound = report["dihedral_bound_degrees"][0].as_f64().unwrap();
    assert!(
        min >= bound && bound >= 8.9,
        "minimum dihedral {min}°, bound {bound}°"
    );
    let mesh = trilux_io::tet::read(d.join("bunny.node")).unwrap();
    assert_eq!(report["tetrahedra"], mesh.tets.len());
    trilux(d)
        .args([
            "diffuse",
            "bunny.node",
            "--material",
            "marble",
            "--unit-mm",
            "1000",
            "--cut",
            "plane:0,0,1,0",
            "--size",
            "128",
            "-o",
            "bunny.png",
        ])
        .assert()
        .success();
    assert_eq!(
        trilux_io::image::read(d.join("bunny.png")).unwrap().width,
        128
    );
}

/// Writes `faces` as a TetGen `.face` file (1-based, boundary markers).
fn write_face_file(path: &Path, faces: &[[u32; 3]]) {
    let mut text = format!("# boundary triangles\n{} 1\n", faces.len());
    for (k, f) in faces.iter().enumerate() {
        text.push_str(&format!(
            "{} {} {} {} 1\n",
            k + 1,
            f[0] + 1,
            f[1] + 1,
            f[2] + 1
        ));
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn info_reads_a_tetgen_face_file_beside_its_node_and_ele_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    stuffed_blob(d, "0.15");
    let mesh = trilux_io::tet::read(d.join("blob.node")).unwrap();
    let boundary = mesh.boundary();
    write_face_file(&d.join("blob.face"), &boundary);
    let report = json(d, &["info", "blob.face"]);
    assert_eq!(report["kind"], "TetGen faces", "{report}");
    assert_eq!(report["faces"], boundary.len(), "{report}");
    assert_eq!(report["tetrahedra"], mesh.tets.len(), "{report}");
    assert_eq!(report["matches_tetrahedra"], true, "{report}");
    assert_eq!(report["closed"], true, "{report}");
    assert_eq!(report["holes"], 0, "{report}");
    let out = run(d, &["info", "blob.face"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(&format!("faces: {}", boundary.len())),
        "{text}"
    );
    // A face list that is not the tetrahedra's boundary says so.
    write_face_file(&d.join("blob.face"), &boundary[1..]);
    let report = json(d, &["info", "blob.face"]);
    assert_eq!(report["matches_tetrahedra"], false, "{report}");
    assert_eq!(report["closed"], false, "{report}");
    // The .node and .ele files it refers to are needed, and named.
    std::fs::copy(d.join("blob.face"), d.join("lonely.face")).unwrap();
    fails(d, &["info", "lonely.face"], &["lonely.node"]);
}

#[test]
fn info_reads_the_face_files_of_the_data_folder() {
    if !have_data("info_reads_the_face_files_of_the_data_folder") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for name in ["bunny_50k", "sphere_20k"] {
        let file = data(&format!("tets/{name}.face"));
        let report = json(dir.path(), &["info", file.to_str().unwrap()]);
        assert_eq!(report["matches_tetrahedra"], true, "{name}: {report}");
        assert_eq!(report["closed"], true, "{name}: {report}");
    }
}

#[test]
fn diffuse_paints_the_side_of_a_plane_with_one_flag() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    stuffed_blob(d, "0.12");
    let help = run(d, &["diffuse", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(help.contains("--paint plane:"), "no example in\n{help}");
    // Ketchup (red) on the side x > 0 of a 4 cm marble blob seen from +z
    // (+x to the right of the picture).
    let report = json(
        d,
        &[
            "diffuse",
            "blob.node",
            "--paint",
            "plane:1,0,0,0:ketchup",
            "--unit-mm",
            "20",
            "--view=0,0,1",
            "--size",
            "64",
            "-o",
            "half.png",
        ],
    );
    let mesh = trilux_io::tet::read(d.join("blob.node")).unwrap();
    let right = mesh
        .tets
        .iter()
        .filter(|t| t.iter().map(|&v| mesh.positions[v as usize].x).sum::<f64>() > 0.0)
        .count();
    assert_eq!(report["paint"][0]["spec"], "plane:1,0,0,0:ketchup");
    assert_eq!(report["paint"][0]["tetrahedra"], right, "{report}");
    let image = trilux_io::image::read(d.join("half.png")).unwrap();
    let red = |columns: std::ops::Range<u32>| {
        let mut n = 0;
        for y in 0..image.height {
            for x in columns.clone() {
                let p = image.pixels[(y * image.width + x) as usize];
                n += usize::from(p[0] > 0.1 && p[0] > 2.0 * p[1]);
            }
        }
        n
    };
    let (left, right) = (red(0..28), red(36..64));
    assert!(
        right > 100 && left * 10 < right,
        "red pixels: left {left}, right {right}"
    );
    fails(
        d,
        &[
            "diffuse",
            "blob.node",
            "--paint",
            "plane:0,0,0,1:skin1",
            "-o",
            "p.png",
        ],
        &["'plane:0,0,0,1:skin1' for '--paint <SPEC>'", "zero"],
    );
    fails(
        d,
        &[
            "diffuse",
            "blob.node",
            "--paint",
            "plane:1,0,0,0:jade",
            "-o",
            "p.png",
        ],
        &["'plane:1,0,0,0:jade' for '--paint <SPEC>'", "marble"],
    );
    assert!(!d.join("p.png").exists());
}

#[test]
fn tetra_refuses_a_spacing_too_fine_before_computing_and_reports_the_one_it_used() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let blob = blob(d);
    let blob = blob.to_str().unwrap();
    // A user trial's tiny spacing ran for minutes and aborted on memory:
    // now it is a usage error naming the argument, in readable numbers.
    for size in ["0.0004", "1e-300"] {
        let err = common::fails_with(
            d,
            2,
            &["tetra", blob, "--spacing", size, "-o", "t.node"],
            &[
                "--spacing",
                "too fine for this surface",
                "use a larger --spacing",
            ],
        );
        assert!(err.len() < 300, "{err}");
    }
    assert!(!d.join("t.node").exists());
    // The old name still works, says it is deprecated, and errors name it
    // as typed.
    let out = run(d, &["tetra", blob, "--size", "0.3", "-o", "old.node"]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    assert!(
        common::stderr(&out)
            .contains("warning: `trilux tetra --size` is deprecated, use --spacing")
    );
    common::fails_with(
        d,
        2,
        &["tetra", blob, "--size", "1e-300", "-o", "t.node"],
        &["--size 1e-300: ", "use a larger --size"],
    );
    common::fails_with(
        d,
        2,
        &[
            "tetra",
            blob,
            "--size",
            "0.3",
            "--spacing",
            "0.3",
            "-o",
            "t.node",
        ],
        &["--spacing"],
    );
    // The spacing used (here the default) and every file written, in a
    // stable order, preview included.
    let report = json(d, &["tetra", blob, "-o", "b.node", "--preview", "b.png"]);
    let h = report["spacing"].as_f64().unwrap();
    assert!(h > 0.0 && h < 0.2, "{h}");
    let files: Vec<&str> = report["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    assert_eq!(files.len(), 3, "{files:?}");
    assert!(files.windows(2).all(|w| w[0] <= w[1]), "{files:?}");
    assert!(files.iter().any(|f| f.ends_with("b.png")));
}

#[test]
fn huge_and_far_away_coordinates_are_measured_where_the_file_puts_them() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let tet = |scale: f32, at: Vec3| TriMesh {
        positions: [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z]
            .map(|p| at + p * scale)
            .to_vec(),
        indices: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        ..TriMesh::default()
    };
    // Coordinates near 1e30: the default spacing used to overflow in f32
    // and blame a --size nobody gave.
    tet(1e30, Vec3::ZERO).write(d.join("huge.obj")).unwrap();
    let report = json(d, &["tetra", "huge.obj", "-o", "h.node"]);
    assert!(report["tetrahedra"].as_u64().unwrap() > 0);
    // A unit tetrahedron at 100000: `info` used to show the reader's
    // shifted bounds, around 0.
    tet(1.0, Vec3::splat(100_000.0))
        .write(d.join("far.obj"))
        .unwrap();
    let info = json(d, &["info", "far.obj"]);
    let lo = info["bounds"][0][0].as_f64().unwrap();
    let hi = info["bounds"][1][0].as_f64().unwrap();
    assert!(
        (lo - 100_000.0).abs() < 1e-3 && (hi - 100_001.0).abs() < 1e-3,
        "{info}"
    );
}

#[test]
fn diffuse_names_the_formats_it_reads() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("x.vtu"), "<VTKFile/>").unwrap();
    common::fails_with(
        d,
        1,
        &["diffuse", "x.vtu", "-o", "x.png"],
        &["x.vtu", ".node", ".obj"],
    );
}

/// A TetGen mesh with nodes no tetrahedron uses (one before all others,
/// one after: what TetGen's `-r` and meshio's point lists leave): diffuse
/// and view drop them with a warning naming the file and the first node,
/// and the VTU keeps the file's nodes and tetrahedra (NaN where dropped).
#[test]
fn diffuse_drops_nodes_no_tetrahedron_uses_and_writes_the_files_numbering() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    stuffed_blob(d, "0.3");
    let mut mesh = trilux_io::tet::read(d.join("blob.node")).unwrap();
    mesh.positions.insert(0, glam::DVec3::new(9.0, 9.0, 9.0));
    mesh.positions.push(glam::DVec3::new(-9.0, 9.0, 9.0));
    for t in &mut mesh.tets {
        *t = t.map(|v| v + 1);
    }
    trilux_io::tet::write(d.join("loose.node"), &mesh).unwrap();
    assert_eq!(mesh.unused_nodes(), [0, mesh.positions.len() as u32 - 1]);
    let out = run(
        d,
        &[
            "diffuse",
            "loose.node",
            "--size",
            "32",
            "-o",
            "loose.png",
            "--vtu",
            "loose.vtu",
        ],
    );
    let err = common::stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("warning: loose.node: 2 nodes are used by no tetrahedron (first: node 0"),
        "{err}"
    );
    let vtu = std::fs::read_to_string(d.join("loose.vtu")).unwrap();
    let piece = format!(
        "NumberOfPoints=\"{}\" NumberOfCells=\"{}\"",
        mesh.positions.len(),
        mesh.tets.len()
    );
    assert!(vtu.contains(&piece), "{piece}");
}

#[test]
fn diffuse_warns_when_a_cut_plane_misses_the_object() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    stuffed_blob(d, "0.2");
    let base = ["diffuse", "blob.node", "--unit-mm", "20", "--size", "32"];
    // z > 5 is far above the unit-size blob: nothing is cut.
    let miss = run(
        d,
        &[&base[..], &["--cut", "plane:0,0,1,5", "-o", "a.png"]].concat(),
    );
    assert!(miss.status.success());
    let err = common::stderr(&miss);
    assert!(
        err.contains("warning: --cut plane:0,0,1,5: the plane misses the object"),
        "{err}"
    );
    // A plane through the middle cuts and says nothing of the kind.
    let hit = run(
        d,
        &[&base[..], &["--cut", "plane:0,0,1,0", "-o", "b.png"]].concat(),
    );
    assert!(hit.status.success());
    assert!(!common::stderr(&hit).contains("misses"));
}

#[test]
fn diffuse_warns_that_an_open_surface_is_not_closed_and_a_closed_one_passes_quietly() {
    // `trilux view` reads its mesh through the same code as `diffuse`.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let closed = blob(d);
    let mut open = TriMesh::read(&closed).unwrap();
    open.indices.remove(0);
    open.objects.clear();
    open.write(d.join("open.obj")).unwrap();
    let out = run(
        d,
        &["diffuse", "open.obj", "--size", "32", "-o", "open.png"],
    );
    let err = common::stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("warning: open.obj: not a closed surface (1 hole, 3 boundary edges)"),
        "{err}"
    );
    assert!(err.contains("trilux tetra open.obj --spacing S"), "{err}");
    let out = run(
        d,
        &["diffuse", "blob.obj", "--size", "32", "-o", "closed.png"],
    );
    let err = common::stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("closed surface"), "{err}");
}

#[test]
fn diffuse_writes_the_surface_as_gltf_one_object_per_piece_and_keeps_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    stuffed_blob(d, "0.2");
    let broken = [
        "diffuse",
        "blob.node",
        "--fracture",
        "plane:1,0,0,0",
        "--size",
        "64",
    ];
    let report = json(
        d,
        &[&broken[..], &["-o", "broken.png", "--glb", "broken.glb"]].concat(),
    );
    assert_eq!(report["objects"], 2);
    assert_eq!(report["output"], "broken.png");
    assert_eq!(
        report["files"],
        serde_json::json!(["broken.png", "broken.glb"])
    );
    let glb = d.join("broken.glb");
    test_support::gltf::validate(&glb);
    let scene = trilux_io::mesh::gltf::read_scene(&glb).unwrap();
    let names: Vec<&str> = scene.mesh.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["piece 0", "piece 1"]);
    let n = scene.mesh.positions.len();
    assert_eq!(scene.mesh.normals.as_ref().map(Vec::len), Some(n));
    let colours = scene.vertex_data.colors.as_ref().unwrap();
    assert!(colours.iter().flatten().all(|c| (0.0..=1.0).contains(c)));
    // The PNG's exposure: its brightest percent at white, so some
    // vertices clamp, and most do not.
    let white = colours.iter().filter(|c| c[..3].contains(&1.0)).count();
    assert!(white > 0 && white < n / 2, "{white} of {n} at white");
    let radiance = match scene.vertex_data.attribute("RADIANCE") {
        Some(trilux_io::mesh::gltf::AttributeValues::Vec3(r)) => r,
        other => panic!("{other:?}"),
    };
    // Unclamped: the colours are the radiance over one white.
    let (k, brightest) = radiance
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.max_element().total_cmp(&b.1.max_element()))
        .unwrap();
    assert!(brightest.max_element() > 0.0 && colours[k][..3].contains(&1.0));
    let phi = scene.vertex_data.attribute("PHI").unwrap();
    assert_eq!((phi.len(), phi.components()), (n, 3));
    // The second piece is drawn moved apart along +x, as in the picture.
    let x = |o: usize| {
        let t = &scene.mesh.indices[scene.mesh.objects[o].triangles.clone()];
        let p = scene.mesh.absolute_positions();
        t.iter().flatten().map(|&v| p[v as usize].x).sum::<f64>() / (3 * t.len()) as f64
    };
    assert!(x(1) > x(0) + 0.3, "{} {}", x(0), x(1));

    // .gltf: a .bin beside it; a .bin in the way is refused before the
    // solve (no picture written), and so is an existing .glb.
    let gltf = [&broken[..], &["-o", "b2.png", "--glb", "broken.gltf"]].concat();
    let report = json(d, &gltf);
    assert_eq!(
        report["files"],
        serde_json::json!(["b2.png", "broken.bin", "broken.gltf"])
    );
    test_support::gltf::validate(&d.join("broken.gltf"));
    assert!(d.join("broken.bin").is_file());
    std::fs::remove_file(d.join("broken.gltf")).unwrap();
    let again = [&broken[..], &["-o", "b3.png", "--glb", "broken.gltf"]].concat();
    common::fails_with(d, 1, &again, &["broken.bin", "exists", "--force"]);
    let again = [&broken[..], &["-o", "b3.png", "--glb", "broken.glb"]].concat();
    common::fails_with(d, 1, &again, &["broken.glb", "exists", "--force"]);
    assert!(!d.join("b3.png").exists() && !d.join("broken.gltf").exists());
    let before = std::fs::read(&glb).unwrap();
    let forced = [&["--force"][..], &again].concat();
    json(d, &forced);
    assert!(d.join("b3.png").exists());
    assert!(
        std::fs::read(&glb).unwrap() == before,
        "not the same surface"
    );
    // Only .glb and .gltf.
    let obj = [&broken[..], &["-o", "b4.png", "--glb", "b4.obj"]].concat();
    common::fails_with(d, 2, &obj, &["error: --glb b4.obj: expected .glb or .gltf"]);
}

#[test]
fn diffuse_lists_every_file_it_writes_and_info_shows_the_gltf_attributes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    stuffed_blob(d, "0.25");
    let base = ["diffuse", "blob.node", "--size", "32"];
    let all = ["-o", "a.png", "--exr", "a.exr", "--vtu", "a.vtu"];
    let report = json(d, &[&base[..], &all, &["--glb", "a.gltf"]].concat());
    let written = ["a.png", "a.exr", "a.vtu", "a.bin", "a.gltf"];
    assert_eq!(report["files"], serde_json::json!(written), "{report}");
    assert_eq!(report["output"], "a.png");
    for f in written {
        assert!(d.join(f).is_file(), "{f}");
    }
    // The summary line names them all too.
    let out = run(
        d,
        &[&["--force"], &base[..], &all, &["--glb", "a.gltf"]].concat(),
    );
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.trim_end()
            .ends_with("; written to a.png, a.exr, a.vtu, a.bin, a.gltf"),
        "{text}"
    );
    let out = run(d, &[&base[..], &["-o", "b.png", "--glb", "b.glb"]].concat());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.trim_end().ends_with("; written to b.png, b.glb"),
        "{text}"
    );

    // `info` on the surface: the triangles with their vertex colours and
    // the radiance and φ as custom attributes.
    for file in ["a.gltf", "b.glb"] {
        let info = json(d, &["info", file]);
        assert_eq!(info["kind"], "triangle mesh", "{info}");
        assert_eq!(info["closed"], true);
        assert_eq!(info["colors"], "RGB");
        let mut custom = info["custom_attributes"].as_array().unwrap().clone();
        custom.sort_by_key(|a| a["name"].as_str().unwrap().to_string());
        assert_eq!(
            custom,
            [
                serde_json::json!({"name": "_PHI", "components": 3}),
                serde_json::json!({"name": "_RADIANCE", "components": 3}),
            ]
        );
        let out = run(d, &["info", file]);
        let text = String::from_utf8_lossy(&out.stdout);
        for line in [
            "  vertex colours (COLOR_0): RGB\n",
            "_PHI (3 components)",
            "_RADIANCE (3 components)",
        ] {
            assert!(text.contains(line), "{line:?} not in {text}");
        }
    }
}

#[test]
fn diffuse_and_view_fit_a_surface_to_an_envelope_and_refuse_it_for_tets() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let blob = blob(d);
    let blob = blob.to_str().unwrap();
    // The surface stuffed with its boundary fitted: the run says how near
    // it came, and the tetrahedra are those `tetra --envelope` writes.
    let args = [
        "diffuse",
        blob,
        "--envelope",
        "0.002",
        "--size",
        "32",
        "-o",
        "e.png",
    ];
    let out = trilux(d).args(args).arg("--json").output().unwrap();
    assert!(out.status.success(), "{}", common::stderr(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["envelope"], 0.002, "{report}");
    let stderr = common::stderr(&out);
    assert!(
        stderr.contains("the tetrahedra's boundary lies within") && stderr.contains("envelope"),
        "{stderr}"
    );
    let tetra = json(d, &["tetra", blob, "--envelope", "0.002", "-o", "t.node"]);
    assert_eq!(
        report["tetrahedra"], tetra["tetrahedra"],
        "{report} vs {tetra}"
    );
    let plain = json(d, &["diffuse", blob, "--size", "32", "-o", "p.png"]);
    assert!(plain["envelope"].is_null());
    // Already tetrahedral: nothing to fit, said rather than ignored.
    stuffed_blob(d, "0.12");
    for command in ["diffuse", "view"] {
        let mut args = vec![command, "blob.node", "--envelope", "0.002"];
        if command == "diffuse" {
            args.extend(["-o", "x.png"]);
        }
        fails_with(
            d,
            2,
            &args,
            &["--envelope 0.002", "blob.node", "already tetrahedral"],
        );
    }
    fails_with(
        d,
        2,
        &["diffuse", blob, "--envelope", "2", "-o", "x.png"],
        &["--envelope 2", "between 0 and 1"],
    );
    assert!(!d.join("x.png").exists());
}
