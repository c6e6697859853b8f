//! `trilux sample --rate`: the library's scatter by rate, written as the
//! command writes points; its argument errors.

use crate::common;
use common::{fails_with, json, stderr, trilux};
use mesh_sampling::{Density, ScatterDensity, ScatterOptions, scatter};
use trilux_io::mesh::TriMesh;

#[test]
fn sample_by_rate_writes_the_library_scatter_for_the_seed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, noise) = common::torus_and_noise(d, [48, 24], 64);
    let mesh = TriMesh::read(&torus).unwrap();
    let written = |args: &[&str], name: &str| -> Vec<glam::Vec3> {
        let out = trilux(d)
            .args(["-q", "sample", torus.to_str().unwrap(), "--seed", "5"])
            .args(args)
            .args(["-o", name])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        trilux_io::mesh::ply::read(d.join(name)).unwrap().positions
    };
    let options = ScatterOptions {
        seed: 5,
        ..ScatterOptions::new(300.0)
    };
    let positions = |density: ScatterDensity<'_>, options: &ScatterOptions| -> Vec<glam::Vec3> {
        scatter(trilux::mesh_ref(&mesh), density, options)
            .unwrap()
            .iter()
            .map(|p| p.position)
            .collect()
    };
    // Uniform: rate × area points on average, the library's exactly, on
    // any number of threads.
    let uniform = positions(ScatterDensity::Uniform, &options);
    assert!(uniform.len() > 1000, "{}", uniform.len());
    assert_eq!(written(&["--rate", "300"], "u.ply"), uniform);
    assert_eq!(
        written(&["--rate", "300", "--threads", "1"], "u1.ply"),
        uniform
    );
    // A density texture as the command reads it (values as stored), with
    // a stated ceiling.
    let raw = trilux_io::image::ReadOptions {
        raw: true,
        ..Default::default()
    };
    let image = trilux_io::image::read_with(&noise, raw).unwrap();
    let texture = trilux::density_texture(&image, mesh_sampling::Channel::Luminance).unwrap();
    let ceiling = ScatterOptions {
        max_density: Some(1.0),
        ..options
    };
    let library = positions(Density::Texture(&texture).into(), &ceiling);
    let args = ["--rate", "300", "--max-density", "1"];
    let cli = written(
        &[&args[..], &["--density", noise.to_str().unwrap()]].concat(),
        "t.ply",
    );
    assert_eq!(cli, library);
    // Fewer points than uniform, all of them among the uniform
    // candidates (same ceiling 1: the texture only thins them).
    assert!(cli.len() < uniform.len());
    assert!(cli.iter().all(|p| uniform.contains(p)));
    // The JSON report names the mode.
    let report = json(
        d,
        &[
            "sample",
            torus.to_str().unwrap(),
            "--rate",
            "300",
            "--seed",
            "5",
            "-o",
            "j.glb",
        ],
    );
    assert_eq!(report["method"], "rate");
    assert_eq!(report["rate"], 300.0);
    assert_eq!(report["points"], uniform.len());
}

#[test]
fn sample_by_rate_argument_errors_name_the_argument() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, noise) = common::torus_and_noise(d, [48, 24], 64);
    let torus = torus.to_str().unwrap();
    let noise = noise.to_str().unwrap();
    for rate in ["-1", "0", "nan", "inf"] {
        fails_with(
            d,
            2,
            &["sample", torus, "--rate", rate, "-o", "a.ply"],
            &["--rate", "positive"],
        );
    }
    fails_with(
        d,
        2,
        &["sample", torus, "--rate", "1e12", "-o", "a.ply"],
        &["--rate 1000000000000", "points"],
    );
    fails_with(
        d,
        2,
        &[
            "sample",
            torus,
            "--rate",
            "10",
            "--max-density",
            "-2",
            "-o",
            "a.ply",
        ],
        &["--max-density -2", "positive"],
    );
    // A ceiling below the texture's values names the face.
    fails_with(
        d,
        2,
        &[
            "sample",
            torus,
            "--rate",
            "100",
            "--max-density",
            "0.01",
            "--density",
            noise,
            "-o",
            "a.ply",
        ],
        &["--max-density 0.01", "on face", "above the ceiling"],
    );
    // Not with -n, --blue-noise or --method; --max-density needs --rate.
    for extra in [
        &["-n", "10"][..],
        &["--blue-noise"],
        &["--method", "exact", "--density", noise],
    ] {
        fails_with(
            d,
            2,
            &[&["sample", torus, "--rate", "10", "-o", "a.ply"][..], extra].concat(),
            &["--rate"],
        );
    }
    fails_with(
        d,
        2,
        &[
            "sample",
            torus,
            "-n",
            "10",
            "--max-density",
            "1",
            "-o",
            "a.ply",
        ],
        &["--max-density 1", "--rate"],
    );
    assert!(!d.join("a.ply").exists());
}

/// What a fresh user met (issue #47): `--max-density` alone asks for
/// `--rate` (not for -n, which --rate excludes); a rate too large says
/// what rate fits, in the CLI's terms (not the library's `sample_stream`);
/// `--ascii` with a non-PLY output names that output's real format.
#[test]
fn rate_and_ascii_errors_name_what_the_user_can_change() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (torus, _) = common::torus_and_noise(d, [16, 8], 4);
    let torus = torus.to_str().unwrap();
    let message = fails_with(
        d,
        2,
        &["sample", torus, "--max-density", "1", "-o", "a.ply"],
        &["--rate <R>"],
    );
    assert!(!message.contains("--count"), "{message}");
    let message = fails_with(
        d,
        2,
        &["sample", torus, "--rate", "1e12", "-o", "a.ply"],
        &["--rate 1000000000000", "--rate of at most", "134217728"],
    );
    assert!(!message.contains("sample_stream"), "{message}");
    for (out, format) in [
        ("a.glb", "glTF"),
        ("a.usda", "USD text"),
        ("a.usd", "USD text"),
        ("a.hair", ".hair"),
    ] {
        let message = fails_with(
            d,
            2,
            &[
                "sample", torus, "-n", "10", "--hair", "0.1", "--ascii", "-o", out,
            ],
            &["--ascii", out, format],
        );
        assert!(
            format == "glTF" || !message.contains("glTF"),
            "{out}: {message}"
        );
    }
    assert!(!d.join("a.ply").exists());
}
