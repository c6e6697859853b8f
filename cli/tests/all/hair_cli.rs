//! `trilux sample … --hair LEN[:SEGMENTS]`: strands in every format, read
//! back; errors name their argument.

use std::path::Path;

use trilux_io::curves::hair;
use trilux_io::glam::Vec3;

use crate::common::{fails, json, run, torus_and_noise};

fn torus(dir: &Path) -> String {
    let (torus, _) = torus_and_noise(dir, [32, 16], 16);
    torus.display().to_string()
}

#[test]
fn hair_files_hold_one_strand_per_point_of_the_asked_length() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = torus(dir.path());
    let report = json(
        dir.path(),
        &[
            "sample", &mesh, "-n", "500", "--seed", "3", "--hair", "0.25:5", "-o", "h.hair",
        ],
    );
    assert_eq!(report["strands"], 500);
    assert_eq!(report["strand_points"], 3000);
    let curves = hair::read(dir.path().join("h.hair")).unwrap();
    assert_eq!(curves.counts, vec![6; 500]);
    // Straight strands: each 0.25 long, its root on the torus (the points
    // of the same seed without --hair).
    for strand in curves.points.chunks(6) {
        let length: f32 = strand.windows(2).map(|w| w[0].distance(w[1])).sum();
        assert!((length - 0.25).abs() < 1e-4, "{length}");
        let axis = (strand[5] - strand[0]).normalize();
        assert!(
            strand
                .windows(2)
                .all(|w| (w[1] - w[0]).normalize().dot(axis) > 0.9999)
        );
    }
    assert!(
        run(
            dir.path(),
            &["sample", &mesh, "-n", "500", "--seed", "3", "-o", "p.ply"]
        )
        .status
        .success()
    );
    let cloud = trilux_io::mesh::ply::read(dir.path().join("p.ply")).unwrap();
    let roots: Vec<Vec3> = curves.points.chunks(6).map(|s| s[0]).collect();
    assert_eq!(
        roots, cloud.positions,
        "the roots are the points of the same seed"
    );
}

#[test]
fn usda_glb_and_ply_outputs_carry_the_strands_and_roots() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = torus(dir.path());
    for out in ["h.usda", "h.glb", "h.gltf", "h.ply"] {
        let report = json(
            dir.path(),
            &[
                "sample",
                &mesh,
                "-n",
                "200",
                "--hair",
                "0.1",
                "--hair-curl",
                "0.01:2",
                "--hair-comb",
                "0,1,0:30",
                "--hair-clumps",
                "20:0.5",
                "-o",
                out,
            ],
        );
        assert_eq!(report["segments"], 8, "{out}");
        assert_eq!(report["strand_points"], 1800, "{out}");
    }
    let usda = std::fs::read_to_string(dir.path().join("h.usda")).unwrap();
    assert!(usda.contains("def BasisCurves \"strands\"") && usda.contains("def Points \"roots\""));
    let counts = usda
        .lines()
        .find(|l| l.contains("curveVertexCounts"))
        .unwrap();
    let inner = &counts[counts.find("= [").unwrap() + 3..counts.rfind(']').unwrap()];
    assert_eq!(inner.split(", ").collect::<Vec<_>>(), vec!["9"; 200]);
    let scene = trilux_io::mesh::gltf::read_scene(dir.path().join("h.glb")).unwrap();
    assert_eq!(scene.points.positions.len(), 200, "root points");
    assert!(scene.points.faces.is_some());
    let ply = trilux_io::mesh::ply::read(dir.path().join("h.ply")).unwrap();
    assert_eq!(ply.positions.len(), 200);
    assert!(ply.face_ids.is_some() && ply.normals.is_some());
    let names: Vec<&str> = ply.scalars.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["bary0", "bary1", "bary2"]);
    assert_eq!(ply.ids, Some((0..200).collect()));
    for (k, (b0, (b1, b2))) in ply.scalars[0]
        .1
        .iter()
        .zip(ply.scalars[1].1.iter().zip(&ply.scalars[2].1))
        .enumerate()
    {
        assert!((b0 + b1 + b2 - 1.0).abs() < 1e-5, "point {k}");
    }
}

#[test]
fn the_same_seed_gives_the_same_strands_on_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = torus(dir.path());
    let args = |threads: &str, out: &str| {
        let ok = run(
            dir.path(),
            &[
                "sample",
                &mesh,
                "-n",
                "40000",
                "--hair",
                "0.1:4",
                "--hair-curl",
                "0.02:1.5",
                "--hair-clumps",
                "300:0.6",
                "--threads",
                threads,
                "-o",
                out,
            ],
        );
        assert!(ok.status.success());
    };
    args("1", "one.hair");
    args("2", "two.hair");
    let one = std::fs::read(dir.path().join("one.hair")).unwrap();
    assert_eq!(one, std::fs::read(dir.path().join("two.hair")).unwrap());
}

#[test]
fn bad_hair_arguments_are_errors_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = torus(dir.path());
    let cases: &[(&[&str], &[&str])] = &[
        (&["--hair", "-1"], &["--hair -1", "positive"]),
        (&["--hair", "nan"], &["--hair nan", "positive"]),
        (&["--hair", "0.1:0"], &["--hair 0.1:0", "SEGMENTS"]),
        (&["--hair", "0.1:99999"], &["--hair 0.1:99999", "4096"]),
        (
            &["--hair", "0.1", "--hair-curl", "x"],
            &["--hair-curl x", "RADIUS:TURNS"],
        ),
        (
            &["--hair", "0.1", "--hair-curl", "-1:2"],
            &["--hair-curl -1:2", ">= 0"],
        ),
        (
            &["--hair", "0.1", "--hair-comb", "0,0,0:10"],
            &["--hair-comb 0,0,0:10"],
        ),
        (
            &["--hair", "0.1", "--hair-comb", "0,1,0:200"],
            &["--hair-comb 0,1,0:200"],
        ),
        (
            &["--hair", "0.1", "--hair-clumps", "0:0.5"],
            &["--hair-clumps 0:0.5", "CENTRES"],
        ),
        (
            &["--hair", "0.1", "--hair-clumps", "10:1.5"],
            &["--hair-clumps 10:1.5", "AMOUNT"],
        ),
    ];
    for (extra, needles) in cases {
        let mut args = vec!["sample", mesh.as_str(), "-n", "10", "-o", "x.usda"];
        args.extend_from_slice(extra);
        fails(dir.path(), &args, needles);
    }
    fails(
        dir.path(),
        &["sample", &mesh, "-n", "10", "--hair", "0.1", "-o", "x.obj"],
        &["-o x.obj", ".usda"],
    );
    fails(
        dir.path(),
        &["sample", &mesh, "-n", "10", "-o", "x.usda"],
        &["-o x.usda", ".ply"],
    );
    fails(
        dir.path(),
        &[
            "sample",
            &mesh,
            "-n",
            "10",
            "--hair-curl",
            "1:1",
            "-o",
            "x.usda",
        ],
        &["--hair"],
    );
    assert!(!dir.path().join("x.usda").exists());
}

#[test]
fn a_mesh_colours_channel_scales_each_strands_length_at_its_root() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, noise) = torus_and_noise(d, [32, 16], 16);
    let (torus, noise) = (torus.to_str().unwrap(), noise.to_str().unwrap());
    assert!(
        run(
            d,
            &[
                "colors",
                "convert",
                torus,
                "--texture",
                noise,
                "-o",
                "t.meshcolors"
            ]
        )
        .status
        .success()
    );
    for out in ["roots.ply", "h.hair"] {
        let ok = run(
            d,
            &[
                "sample",
                torus,
                "-n",
                "300",
                "--seed",
                "9",
                "--hair",
                "0.5:2",
                "--hair-length-meshcolors",
                "t.meshcolors",
                "--hair-length-channel",
                "g",
                "-o",
                out,
            ],
        );
        assert!(ok.status.success(), "{}", crate::common::stderr(&ok));
    }
    let (colors, _) = mesh_colors::file::load(d.join("t.meshcolors")).unwrap();
    let roots = trilux_io::mesh::ply::read(d.join("roots.ply")).unwrap();
    let faces = roots.face_ids.as_ref().unwrap();
    let bary = |k: usize, i: usize| roots.scalars[k].1[i];
    let curves = hair::read(d.join("h.hair")).unwrap();
    let mut value = vec![0.0f32; colors.channels()];
    let mut varied = (f32::INFINITY, 0.0f32);
    for (i, strand) in curves.points.chunks(3).enumerate() {
        let b = [bary(0, i), bary(1, i), bary(2, i)];
        colors.linear(faces[i] as usize, b, &mut value).unwrap();
        let length: f32 = strand.windows(2).map(|w| w[0].distance(w[1])).sum();
        assert!(
            (length - 0.5 * value[1]).abs() < 1e-4,
            "strand {i}: {length} vs {}",
            0.5 * value[1]
        );
        varied = (varied.0.min(length), varied.1.max(length));
    }
    assert!(
        varied.1 > varied.0 + 0.05,
        "the noise varies the lengths: {varied:?}"
    );
}

#[test]
fn strands_of_a_far_mesh_are_written_in_the_files_frame() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut far = trilux::shapes::torus(32, 16);
    far.origin = trilux_io::glam::DVec3::new(4.0e5, -2.5e5, 1.0e5);
    far.write(d.join("far.obj")).unwrap();
    for out in ["roots.ply", "h.hair"] {
        let ok = run(
            d,
            &[
                "sample", "far.obj", "-n", "50", "--hair", "0.3:3", "-o", out,
            ],
        );
        assert!(ok.status.success(), "{}", crate::common::stderr(&ok));
    }
    let roots = trilux_io::mesh::ply::read(d.join("roots.ply")).unwrap();
    let curves = hair::read(d.join("h.hair")).unwrap();
    for (i, strand) in curves.points.chunks(4).enumerate() {
        let want = roots.origin + roots.positions[i].as_dvec3();
        // f32 holds coordinates near 4·10^5 to 1/32.
        assert!(
            (strand[0].as_dvec3() - want).abs().max_element() < 0.04,
            "root {i}"
        );
    }
}

#[test]
fn a_texture_channel_scales_each_strands_length_at_its_roots_uv() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, noise) = torus_and_noise(d, [32, 16], 16);
    let (torus, noise) = (torus.to_str().unwrap(), noise.to_str().unwrap());
    for out in ["roots.ply", "h.hair"] {
        let ok = run(
            d,
            &[
                "sample",
                torus,
                "-n",
                "300",
                "--seed",
                "4",
                "--hair",
                "0.5:2",
                "--hair-length-texture",
                noise,
                "--hair-length-channel",
                "r",
                "-o",
                out,
            ],
        );
        assert!(ok.status.success(), "{}", crate::common::stderr(&ok));
    }
    let options = trilux_io::image::ReadOptions {
        raw: true,
        ..Default::default()
    };
    let image = trilux_io::image::read_with(noise, options).unwrap();
    let texture = trilux::density_texture(&image, mesh_sampling::Channel::Index(0)).unwrap();
    let roots = trilux_io::mesh::ply::read(d.join("roots.ply")).unwrap();
    let uvs = roots.uvs.as_ref().unwrap();
    let curves = hair::read(d.join("h.hair")).unwrap();
    for (i, strand) in curves.points.chunks(3).enumerate() {
        let length: f32 = strand.windows(2).map(|w| w[0].distance(w[1])).sum();
        let want = 0.5 * texture.eval(uvs[i].as_dvec2()) as f32;
        assert!(
            (length - want).abs() < 1e-3,
            "strand {i}: {length} vs {want}"
        );
    }
    fails(
        d,
        &[
            "sample",
            torus,
            "-n",
            "10",
            "--hair",
            "0.1",
            "--hair-length-channel",
            "r",
            "-o",
            "x.usda",
        ],
        &["--hair-length"],
    );
}

/// `--preview` with `--hair` draws the strands (it wrote nothing before):
/// a picture unlike the points' preview of the same seed, which has no
/// strands; `.usd` is written as USD text, the same bytes as `.usda`; a
/// PLY's summary counts the roots it holds, not curve points; `--json`
/// gives the length as typed and the sampling's fields.
#[test]
fn hair_preview_usd_ply_summary_and_json_say_what_was_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mesh = torus(d);
    let hair = |extra: &[&str]| {
        let mut args = vec!["sample", mesh.as_str(), "-n", "300", "--seed", "4"];
        args.extend_from_slice(extra);
        json(d, &args)
    };
    let report = hair(&["--hair", "0.3", "-o", "h.usda", "--preview", "h.png"]);
    assert_eq!(report["preview"], "h.png");
    let strands = trilux_io::image::read(d.join("h.png")).unwrap();
    json(
        d,
        &[
            "sample",
            &mesh,
            "-n",
            "300",
            "--seed",
            "4",
            "-o",
            "p.ply",
            "--preview",
            "p.png",
        ],
    );
    let points = trilux_io::image::read(d.join("p.png")).unwrap();
    assert_eq!(
        (strands.width, strands.height),
        (points.width, points.height)
    );
    assert_ne!(strands.pixels, points.pixels, "the strands are drawn");

    hair(&["--hair", "0.3", "-o", "h.usd"]);
    assert_eq!(
        std::fs::read(d.join("h.usd")).unwrap(),
        std::fs::read(d.join("h.usda")).unwrap()
    );

    let out = run(
        d,
        &[
            "sample", &mesh, "-n", "300", "--hair", "0.05", "-o", "h.ply",
        ],
    );
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("the 300 roots written to h.ply (PLY holds no curves)"),
        "{text}"
    );

    let report = hair(&["--hair", "0.05", "-o", "j.hair"]);
    assert_eq!(report["length"].to_string(), "0.05");
    assert_eq!(report["method"], "uniform");
    assert_eq!(report["seed"], 4);
    for key in ["rate", "max_density", "blue_noise", "packing", "preview"] {
        assert!(report.get(key).is_some(), "{key}: {report}");
    }
    let report = json(
        d,
        &[
            "sample",
            &mesh,
            "--rate",
            "50",
            "--max-density",
            "1",
            "--hair",
            "0.05",
            "-o",
            "r.hair",
        ],
    );
    assert_eq!(
        (report["method"].as_str(), report["rate"].as_f64()),
        (Some("rate"), Some(50.0))
    );
    assert_eq!(report["max_density"], 1.0);
}
