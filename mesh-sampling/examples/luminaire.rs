//! Šik & Křivánek 2013, Fig. 1b measured without a full renderer: a
//! luminaire whose emission is an HDR image, above a Lambertian receiver
//! rendered as an image of its irradiance by next-event estimation, with
//! every [`Strategy`] of [`Emitter`] at 1, 4, 16 and 64 samples per pixel
//! and at equal time, and a constant-radiance copy of the luminaire with
//! the same power, sampled by area, as the floor that geometry alone
//! leaves.
//!
//! ```text
//! cargo run --release -p mesh-sampling --example luminaire -- [--json] [--quick]
//!     [--texture FILE]… [--mesh FILE] [--triangles N,…] [--size WxH]
//!     [--reference-spp N] [--threads T] [--seed S] [--out DIR]
//!     [--pictures DIR] [--mitsuba PYTHON]
//! ```
//!
//! The luminaires (`support/luminaire.rs`): a one-sided rectangle, 2 × 1
//! at height 1, in 256 to 16,384 triangles (`--triangles`; 1,024 unless
//! named), carrying each image of `$TRILUX_DATA/hdr` (or `--texture`; a
//! generated sun and sky without data) as its emission (bilinear,
//! clamped); and the Stanford bunny (`$TRILUX_DATA/meshes/stanford-bunny.obj`
//! or `--mesh`; a generated blob without data), which has no UVs, with
//! overlapping UVs made here by a planar projection from above that folds
//! (top and bottom share their texels). The receiver `[−2, 2] × [−1, 1]`
//! is a 128 × 64 image (`--size`); each pixel is the irradiance averaged
//! over it.
//!
//! The reference is `texture-exact` at 4,096 samples per pixel, twice with
//! different seeds: their relative MSE must be within 1.5× of what their
//! own per-pixel variances predict, and the reference's own (a quarter of
//! theirs) at most 5% of `texture-exact`'s at 64 spp (else the example
//! stops); the mean of the two is the reference. For the rectangle it is
//! cross-checked against a quadrature (every quarter texel, 2 × 2 points
//! per pixel) on a lattice of 32 pixels. The floor's reference is
//! Lambert's closed form for the rectangle, and 2 × 4,096 area samples per
//! pixel for the bunny.
//!
//! Rows: RMSE, relative MSE (the mean over pixels of `(x − r)² / r²`),
//! the expected relative MSE (the strategy's per-sample relative variance,
//! from a render at 1,024 spp, over the spp: one image's relative MSE
//! misses a heavy tail such as the sun by area), relative MSE × seconds,
//! and the relative bias of the image with its standard error. Seconds are the render's (sampling and estimation, the
//! median of three runs, on `--threads` threads, 1 by default); the
//! emitter's build time is reported apart. Equal time gives every strategy
//! the seconds `texture` took at 64 spp. Light samples per second per
//! thread, each strategy against `area`, are the median of nine
//! back-to-back pairs of runs. With `--mitsuba PYTHON`, Mitsuba 3 renders
//! the same rectangle (the sun image, 1,024 triangles) and bunny through
//! `bench/mitsuba_luminaire.py` at the same spp: its next-event step on
//! both, and its `direct` integrator on the rectangle (`bench/run.sh` sets
//! up the venv). Markdown tables go to stdout; `--json` prints one object per
//! row instead. Pictures (a PNG per luminaire, EXR beside it) go to
//! `--out` (default `target/luminaire`); `--pictures DIR` also writes the
//! PNGs of the sun rectangle and the sun bunny there (the README's).
//! `--quick`: a 16 × 8 image, 256 triangles, textures shrunk to 128 × 64
//! (box averages, which keep the power), 2,048 reference samples per pixel,
//! 64 for the variance, one timed run, no equal time (a first look; the
//! test runs the same module on generated data).

#[path = "support/data.rs"]
mod data;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use mesh_sampling::{Emission, EmissionTexture, Emitter, EmitterOptions, Strategy, Wrap};

#[path = "support/luminaire.rs"]
mod luminaire;

use luminaire::{
    Config, FLOOR, Irradiance, Measured, QuadratureCheck, Receiver, Row, Shape, compare, folded,
    generated_textures, paired_rate, peak_over_mean, rectangle_with,
};

/// Samples per pixel of the pictures.
const PICTURE_SPP: usize = 16;

struct Args {
    json: bool,
    quick: bool,
    textures: Vec<PathBuf>,
    mesh: Option<PathBuf>,
    triangles: Option<Vec<usize>>,
    size: Option<(usize, usize)>,
    reference_spp: Option<usize>,
    threads: usize,
    seed: u64,
    out: PathBuf,
    pictures: Option<PathBuf>,
    mitsuba: Option<PathBuf>,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        json: false,
        quick: false,
        textures: Vec::new(),
        mesh: None,
        triangles: None,
        size: None,
        reference_spp: None,
        threads: 1,
        seed: 1,
        out: PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../target/luminaire")),
        pictures: None,
        mitsuba: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        let number = |name: &str, v: String| {
            v.parse::<usize>()
                .ok()
                .filter(|&n| n > 0)
                .ok_or(format!("{name} {v}: expected a positive whole number"))
        };
        match a.as_str() {
            "--json" => args.json = true,
            "--quick" => args.quick = true,
            "--texture" => args.textures.push(value(&a)?.into()),
            "--mesh" => args.mesh = Some(value(&a)?.into()),
            "--triangles" => {
                let v = value(&a)?;
                let list = v
                    .split(',')
                    .map(|t| number("--triangles", t.to_string()))
                    .collect::<Result<Vec<_>, _>>()?;
                for &t in &list {
                    rectangle_with(t)?;
                }
                args.triangles = Some(list);
            }
            "--size" => {
                let v = value(&a)?;
                let (w, h) = v
                    .split_once('x')
                    .ok_or(format!("--size {v}: expected WxH, e.g. 128x64"))?;
                args.size = Some((
                    number("--size", w.to_string())?,
                    number("--size", h.to_string())?,
                ));
            }
            "--reference-spp" => {
                args.reference_spp = Some(number(&a, value(&a)?)?.max(2));
            }
            "--threads" => args.threads = number(&a, value(&a)?)?,
            "--seed" => {
                let v = value(&a)?;
                args.seed = v
                    .parse()
                    .map_err(|_| format!("--seed {v}: expected a whole number"))?;
            }
            "--out" => args.out = value(&a)?.into(),
            "--pictures" => args.pictures = Some(value(&a)?.into()),
            "--mitsuba" => args.mitsuba = Some(value(&a)?.into()),
            "-h" | "--help" => {
                return Err(
                    "usage: luminaire [--json] [--quick] [--texture FILE]… [--mesh FILE] \
                     [--triangles N,…] [--size WxH] [--reference-spp N] [--threads T] [--seed S] \
                     [--out DIR] [--pictures DIR] [--mitsuba PYTHON]"
                        .into(),
                );
            }
            other => return Err(format!("unknown argument {other} (see --help)")),
        }
    }
    Ok(args)
}

/// An image file as an emission texture (bilinear, clamped), shrunk by
/// box averaging (which keeps its power) until it is at most `max_width`
/// wide.
fn read_texture(path: &Path, max_width: Option<usize>) -> Result<EmissionTexture, String> {
    let image = trilux_io::image::read(path).map_err(|e| e.to_string())?;
    let (mut w, mut h) = (image.width as usize, image.height as usize);
    let mut rgb: Vec<[f32; 3]> = image.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
    while max_width.is_some_and(|m| w > m) && w % 2 == 0 && h % 2 == 0 {
        let (w2, h2) = (w / 2, h / 2);
        rgb = (0..w2 * h2)
            .map(|k| {
                let (x, y) = (2 * (k % w2), 2 * (k / w2));
                let mut c = [0.0f32; 3];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    for (a, b) in c.iter_mut().zip(rgb[(y + dy) * w + x + dx]) {
                        *a += 0.25 * b;
                    }
                }
                c
            })
            .collect();
        (w, h) = (w2, h2);
    }
    Ok(EmissionTexture::new(w, h, rgb)
        .map_err(|e| format!("{}: {e}", path.display()))?
        .with_wrap(Wrap::ClampToEdge))
}

/// A mesh file as the bunny luminaire (overlapping UVs made here).
fn read_bunny(path: &Path) -> Result<(Shape, bool), String> {
    let mesh = trilux_io::mesh::read(path).map_err(|e| e.to_string())?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().replace("stanford-", ""))
        .unwrap_or_else(|| "mesh".into());
    Ok(folded(&name, &mesh.positions, &mesh.indices))
}

/// A Mitsuba 3 image: rel MSE and bias.
struct PeerRow {
    /// `mitsuba-3-nee` (its next-event step called per sample) or
    /// `mitsuba-3-direct` (its `direct` integrator).
    strategy: String,
    scene: String,
    texture: String,
    triangles: usize,
    spp: usize,
    seconds: f64,
    errors: luminaire::Errors,
    image: Irradiance,
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: luminaire: {e}");
            ExitCode::FAILURE
        }
    }
}

struct Case {
    shape: Shape,
    texture: usize,
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let data = data::data_dir();
    let max_width = args.quick.then_some(128);
    // Textures, the sun (largest peak over mean) first.
    let mut textures: Vec<(String, EmissionTexture)> = Vec::new();
    let mut files = args.textures.clone();
    if files.is_empty()
        && let Some(d) = &data
    {
        let dir = d.join("hdr");
        let mut found: Vec<PathBuf> = std::fs::read_dir(&dir)
            .map_err(|e| format!("{}: {e}", dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "hdr" || x == "exr"))
            .collect();
        found.sort();
        files = found;
    }
    for f in &files {
        let name = f
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        textures.push((name, read_texture(f, max_width)?));
    }
    if textures.is_empty() {
        textures = generated_textures(if args.quick { 64 } else { 256 });
    }
    textures.sort_by(|a, b| peak_over_mean(&b.1).total_cmp(&peak_over_mean(&a.1)));
    let bunny_path = args.mesh.clone().or_else(|| {
        data.as_ref()
            .map(|d| d.join("meshes/stanford-bunny.obj"))
            .filter(|p| p.is_file())
    });
    let (bunny, flipped) = match &bunny_path {
        Some(p) => read_bunny(p).map_err(|e| format!("--mesh: {e}"))?,
        None => {
            let (p, t) = luminaire::blob(if args.quick { 12 } else { 64 });
            folded("blob", &p, &t)
        }
    };
    let triangles = args.triangles.clone().unwrap_or(if args.quick {
        vec![256]
    } else {
        vec![256, 1024, 4096, 16384]
    });
    let other_triangles = if args.quick { 256 } else { 1024 };
    let mut cases = Vec::new();
    for &t in &triangles {
        cases.push(Case {
            shape: rectangle_with(t)?,
            texture: 0,
        });
    }
    for k in 1..textures.len() {
        cases.push(Case {
            shape: rectangle_with(other_triangles)?,
            texture: k,
        });
    }
    for k in 0..textures.len() {
        cases.push(Case {
            shape: bunny.clone(),
            texture: k,
        });
    }
    let (w, h) = args
        .size
        .unwrap_or(if args.quick { (16, 8) } else { (128, 64) });
    let config = Config {
        receiver: Receiver {
            width: w,
            height: h,
        },
        spps: vec![1, 4, 16, 64],
        reference_spp: args
            .reference_spp
            .unwrap_or(if args.quick { 2048 } else { 4096 }),
        variance_spp: if args.quick { 64 } else { 1024 },
        seed: args.seed,
        repeats: if args.quick { 1 } else { 3 },
        equal_time: !args.quick,
        threads: args.threads,
    };
    std::fs::create_dir_all(&args.out).map_err(|e| format!("{}: {e}", args.out.display()))?;
    if let Some(p) = &args.pictures {
        std::fs::create_dir_all(p).map_err(|e| format!("{}: {e}", p.display()))?;
    }

    let mut out = String::new();
    let mut json = String::new();
    let _ = writeln!(
        out,
        "Receiver {w} × {h} pixels; reference texture-exact at 2 × {} spp; rows on {} thread(s).\n",
        config.reference_spp, config.threads
    );
    for (name, t) in &textures {
        let _ = writeln!(
            out,
            "- texture `{name}`: {} × {} texels, peak / mean luminance {:.0}",
            t.width(),
            t.height(),
            peak_over_mean(t)
        );
    }
    let _ = writeln!(
        out,
        "- {}: {} triangles, {}planar-projection UVs that overlap{}\n",
        bunny.name,
        bunny.triangles(),
        if bunny_path.is_none() {
            "generated (no data), "
        } else {
            ""
        },
        if flipped {
            " (triangles reoriented outward)"
        } else {
            ""
        }
    );
    let mut refs_table = String::from(
        "| luminaire | texture | triangles | reference s | two seeds: rel MSE (predicted) | quadrature: pixels, max rel diff, max \\|z\\|, rms z |\n|---|---|---:|---:|---:|---|\n",
    );
    let mut all_rows: Vec<Row> = Vec::new();
    let mut measured: Vec<(usize, Measured)> = Vec::new();
    // The rectangle's irradiance does not depend on its tessellation (its
    // UVs are linear on the plane): one reference per texture, made with
    // the first tessellation, serves the others.
    let mut shared: Vec<(usize, usize, luminaire::Reference, Option<QuadratureCheck>)> = Vec::new();
    for (c, case) in cases.iter().enumerate() {
        let (tname, texture) = &textures[case.texture];
        eprintln!(
            "luminaire: {} {} triangles, {tname}…",
            case.shape.name,
            case.shape.triangles()
        );
        let reuse = shared
            .iter()
            .find(|s| case.shape.planar && s.0 == case.texture);
        let m = luminaire::measure(
            &case.shape,
            texture,
            tname,
            &config,
            PICTURE_SPP,
            reuse.map(|s| (&s.2, s.3)),
        )?;
        let made_with = reuse.map(|s| s.1);
        if case.shape.planar && made_with.is_none() {
            shared.push((
                case.texture,
                case.shape.triangles(),
                m.reference.clone(),
                m.quadrature,
            ));
        }
        let r = &m.reference;
        // Converged: the two seeds agree within their noise, and the
        // reference's own rel MSE (a quarter of theirs) is at most 5% of
        // texture-exact's at 64 spp.
        let exact64 = m
            .rows
            .iter()
            .find(|r| r.strategy == "texture-exact" && r.budget == "equal-spp" && r.spp == 64)
            .map_or(f64::INFINITY, |r| r.errors.rel_mse);
        if !(r.agreement <= 1.5 * r.predicted_agreement && r.agreement / 4.0 <= 0.05 * exact64) {
            return Err(format!(
                "{} {tname}: the reference has not converged (two seeds: rel MSE {:.3e}, \
                 predicted {:.3e}; texture-exact at 64 spp: {exact64:.3e}): raise --reference-spp",
                case.shape.name, r.agreement, r.predicted_agreement
            ));
        }
        let quad = m.quadrature.map_or("-".to_string(), |q| {
            format!(
                "{}, {:.2e}, {:.2}, {:.2}",
                q.pixels, q.max_relative, q.max_z, q.rms_z
            )
        });
        let _ = writeln!(
            refs_table,
            "| {} | {tname} | {} | {} | {:.2e} ({:.2e}) | {quad} |",
            case.shape.name,
            case.shape.triangles(),
            made_with.map_or(format!("{:.1}", r.seconds), |t| format!(
                "the {t} triangles' reference"
            )),
            r.agreement,
            r.predicted_agreement
        );
        let quad_json = m.quadrature.map_or(String::new(), |q| {
            format!(
                ", \"quadrature_pixels\": {}, \"quadrature_max_relative\": {:.6e}, \"quadrature_max_z\": {:.4}, \"quadrature_rms_z\": {:.4}",
                q.pixels, q.max_relative, q.max_z, q.rms_z
            )
        });
        let _ = writeln!(
            json,
            "{{\"kind\": \"reference\", \"scene\": \"{}\", \"texture\": \"{tname}\", \"triangles\": {}, \"strategy\": \"texture-exact\", \"spp\": {}, \"seeds\": 2, \"seconds\": {:.3}, \"seeds_rel_mse\": {:.6e}, \"seeds_rel_mse_predicted\": {:.6e}{quad_json}{}}}",
            case.shape.name,
            case.shape.triangles(),
            config.reference_spp,
            r.seconds,
            r.agreement,
            r.predicted_agreement,
            made_with.map_or(String::new(), |t| format!(", \"made_with_triangles\": {t}"))
        );
        if let Some(q) = m.quadrature
            && q.max_z > 5.0
        {
            return Err(format!(
                "{} {tname}: the reference and the quadrature disagree ({} SE)",
                case.shape.name, q.max_z
            ));
        }
        all_rows.extend(m.rows.iter().cloned());
        measured.push((c, m));
    }

    // Light samples per second per thread against area.
    let mut rate_table = String::from(
        "| luminaire | texture | triangles | strategy | M light samples/s (1 thread) | / area (median of pairs) |\n|---|---|---:|---|---:|---:|\n",
    );
    let mut rates = Vec::new();
    let (pairs, secs) = if args.quick { (3, 0.02) } else { (9, 0.25) };
    // Rates, Mitsuba and the README's pictures: the sun rectangle of
    // 1,024 triangles (or the first rectangle) and the sun bunny.
    let main_rectangle = if triangles.contains(&1024) {
        1024
    } else {
        triangles[0]
    };
    for case in cases
        .iter()
        .filter(|c| c.texture == 0 && (!c.shape.planar || c.shape.triangles() == main_rectangle))
    {
        let (tname, texture) = &textures[0];
        let emission = Emission::Texture {
            texture,
            scale: 1.0,
        };
        let make = |strategy| {
            Emitter::new(
                case.shape.mesh(),
                emission,
                &EmitterOptions {
                    strategy,
                    ..Default::default()
                },
            )
            .map_err(|e| e.to_string())
        };
        let area = make(Strategy::Area)?;
        for s in [
            Strategy::TrianglePower,
            Strategy::Texture,
            Strategy::TextureExact,
        ] {
            let e = make(s)?;
            let (ratio, rate, area_rate) = paired_rate(&e, &area, pairs, secs);
            let _ = writeln!(
                rate_table,
                "| {} | {tname} | {} | {} | {:.2} (area {:.2}) | {:.2}× |",
                case.shape.name,
                case.shape.triangles(),
                s.name(),
                rate / 1e6,
                area_rate / 1e6,
                ratio
            );
            let _ = writeln!(
                json,
                "{{\"kind\": \"throughput\", \"scene\": \"{}\", \"texture\": \"{tname}\", \"triangles\": {}, \"strategy\": \"{}\", \"samples_per_second\": {rate:.0}, \"area_samples_per_second\": {area_rate:.0}, \"ratio_to_area\": {ratio:.4}}}",
                case.shape.name,
                case.shape.triangles(),
                s.name()
            );
            rates.push((case.shape.name.clone(), s, ratio));
        }
    }

    // Mitsuba 3.
    let mut peers: Vec<PeerRow> = Vec::new();
    let mut peer_note = String::new();
    if let Some(python) = &args.mitsuba {
        for (c, m) in &measured {
            let case = &cases[*c];
            if case.texture != 0 || (case.shape.planar && case.shape.triangles() != main_rectangle)
            {
                continue;
            }
            match mitsuba(python, &args.out, case, &textures[0], &config, m) {
                Ok(rows) => peers.extend(rows),
                Err(e) => {
                    let _ = writeln!(peer_note, "- Mitsuba 3 on the {}: {e}", case.shape.name);
                    eprintln!("luminaire: mitsuba on the {}: {e}", case.shape.name);
                }
            }
        }
    }

    // Pictures.
    for (c, m) in &measured {
        let case = &cases[*c];
        let peer = peers.iter().find(|p| {
            p.scene == case.shape.name
                && p.triangles == case.shape.triangles()
                && p.spp == PICTURE_SPP
                && p.strategy == "mitsuba-3-nee"
        });
        let name = format!(
            "luminaire-{}-{}-{}",
            case.shape.name,
            case.shape.triangles(),
            textures[case.texture].0
        );
        let wanted =
            case.texture == 0 && (!case.shape.planar || case.shape.triangles() == main_rectangle);
        let dirs: Vec<&Path> = std::iter::once(args.out.as_path())
            .chain(args.pictures.as_deref().filter(|_| wanted))
            .collect();
        picture(&dirs, &name, &config.receiver, m, peer.map(|p| &p.image))?;
    }

    // Tables.
    let mut rows_table = String::from(
        "| luminaire | texture | triangles | strategy | budget | spp | seconds | RMSE | rel MSE | expected rel MSE | rel MSE × s | bias ± SE | build s |\n|---|---|---:|---|---|---:|---:|---:|---:|---:|---:|---|---:|\n",
    );
    for r in &all_rows {
        let e = &r.errors;
        let _ = writeln!(
            rows_table,
            "| {} | {} | {} | {} | {} | {} | {:.4} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:+.2}% ± {:.2}% | {:.2} |",
            r.scene,
            r.texture,
            r.triangles,
            r.strategy,
            r.budget,
            r.spp,
            r.seconds,
            e.rmse,
            e.rel_mse,
            r.expected(),
            e.rel_mse * r.seconds,
            100.0 * e.bias,
            100.0 * e.bias_se,
            r.build_seconds
        );
        let _ = writeln!(
            json,
            "{{\"kind\": \"render\", \"scene\": \"{}\", \"texture\": \"{}\", \"triangles\": {}, \"strategy\": \"{}\", \"budget\": \"{}\", \"spp\": {}, \"seconds\": {:.6}, \"build_seconds\": {:.6}, \"rmse\": {:.6e}, \"rel_mse\": {:.6e}, \"rel_mse_expected\": {:.6e}, \"rel_var\": {:.6e}, \"rel_mse_time\": {:.6e}, \"bias\": {:.6e}, \"bias_se\": {:.6e}}}",
            r.scene,
            r.texture,
            r.triangles,
            r.strategy,
            r.budget,
            r.spp,
            r.seconds,
            r.build_seconds,
            e.rmse,
            e.rel_mse,
            r.expected(),
            r.rel_var,
            e.rel_mse * r.seconds,
            e.bias,
            e.bias_se
        );
    }
    for p in &peers {
        let e = &p.errors;
        let _ = writeln!(
            rows_table,
            "| {} | {} | {} | {} | equal-spp | {} | {:.4} | {:.3e} | {:.3e} | - | {:.3e} | {:+.2}% ± {:.2}% | - |",
            p.scene,
            p.texture,
            p.triangles,
            p.strategy,
            p.spp,
            p.seconds,
            e.rmse,
            e.rel_mse,
            e.rel_mse * p.seconds,
            100.0 * e.bias,
            100.0 * e.bias_se
        );
        let _ = writeln!(
            json,
            "{{\"kind\": \"render\", \"scene\": \"{}\", \"texture\": \"{}\", \"triangles\": {}, \"strategy\": \"{}\", \"budget\": \"equal-spp\", \"spp\": {}, \"seconds\": {:.6}, \"rmse\": {:.6e}, \"rel_mse\": {:.6e}, \"rel_mse_time\": {:.6e}, \"bias\": {:.6e}, \"bias_se\": {:.6e}}}",
            p.scene,
            p.texture,
            p.triangles,
            p.strategy,
            p.spp,
            p.seconds,
            e.rmse,
            e.rel_mse,
            e.rel_mse * p.seconds,
            e.bias,
            e.bias_se
        );
    }
    let targets = targets(&all_rows, &peers, &rates, &textures[0].0, &bunny.name);
    if args.json {
        print!("{json}");
    } else {
        println!("{out}");
        println!("References:\n\n{refs_table}");
        println!("Targets (the `{}` texture):\n\n{targets}", textures[0].0);
        println!("Light samples per second per thread:\n\n{rate_table}");
        println!("All rows:\n\n{rows_table}");
        if !peer_note.is_empty() {
            println!("{peer_note}");
        }
    }
    Ok(())
}

/// The row of `strategy` matching the rest.
fn find(
    rows: &[Row],
    scene: &str,
    triangles: Option<usize>,
    strategy: &str,
    budget: &str,
    spp: Option<usize>,
) -> Option<Row> {
    rows.iter()
        .find(|r| {
            r.scene == scene
                && triangles.is_none_or(|t| r.triangles == t)
                && r.strategy == strategy
                && r.budget == budget
                && spp.is_none_or(|s| r.spp == s)
        })
        .cloned()
}

/// The per-sample relative variance pooled from one-image errors: the
/// mean over the rows of `rel MSE × spp`.
fn pooled<'a>(rows: impl Iterator<Item = (&'a luminaire::Errors, usize)>) -> f64 {
    let v: Vec<f64> = rows.map(|(e, spp)| e.rel_mse * spp as f64).collect();
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// The issue's benchmark rows (the sun texture): relative MSE ratios from
/// the expected relative MSE (`rel_var / spp`) at 64 spp or at equal time,
/// with one image's measured ratio beside; the Mitsuba rows from the
/// images at 1, 4, 16 and 64 spp (pooled `rel MSE × spp`).
fn targets(
    rows: &[Row],
    peers: &[PeerRow],
    rates: &[(String, Strategy, f64)],
    sun: &str,
    bunny: &str,
) -> String {
    let rows: Vec<Row> = rows.iter().filter(|r| r.texture == sun).cloned().collect();
    let mut t = String::from(
        "| row | target | expected rel MSE ratio (one image's) | met |\n|---|---|---|---|\n",
    );
    let mut line = |row: String, target: String, measured: String, met: Option<bool>| {
        let met = match met {
            Some(true) => "yes",
            Some(false) => "**no**",
            None => "-",
        };
        let _ = writeln!(t, "| {row} | {target} | {measured} | {met} |");
    };
    // (expected ratio, one image's ratio) of a over b.
    let ratio = |a: &Option<Row>, b: &Option<Row>| match (a, b) {
        (Some(a), Some(b)) => Some((
            a.expected() / b.expected(),
            a.errors.rel_mse / b.errors.rel_mse,
        )),
        _ => None,
    };
    let shown = |x: Option<(f64, f64)>| {
        x.map_or("not measured".to_string(), |(e, m)| {
            format!("{} ({})", fmt_ratio(e), fmt_ratio(m))
        })
    };
    for budget in ["equal-spp", "equal-time"] {
        let half = budget == "equal-time";
        let spp = (!half).then_some(64);
        let at = if half { "equal time" } else { "64 spp" };
        let tex = |t| find(&rows, "rectangle", Some(t), "texture", budget, spp);
        let goal = if half { 500.0 } else { 1000.0 };
        let r = ratio(
            &find(&rows, "rectangle", Some(1024), "area", budget, spp),
            &tex(1024),
        );
        line(
            format!("area / texture, 1,024 triangles, {at}"),
            format!("≥ {goal:.0}×"),
            shown(r),
            r.map(|r| r.0 >= goal),
        );
        for (tris, goal) in [(1024, 20.0), (16384, 5.0)] {
            let goal = if half { goal / 2.0 } else { goal };
            let r = ratio(
                &find(
                    &rows,
                    "rectangle",
                    Some(tris),
                    "triangle-power",
                    budget,
                    spp,
                ),
                &tex(tris),
            );
            line(
                format!("triangle-power / texture, {tris} triangles, {at}"),
                format!("≥ {goal}×"),
                shown(r),
                r.map(|r| r.0 >= goal),
            );
        }
    }
    for (strategy, goal) in [("texture-exact", 1.5), ("texture", 2.0)] {
        for scene in ["rectangle", bunny] {
            let tris = (scene == "rectangle").then_some(1024);
            let r = ratio(
                &find(&rows, scene, tris, strategy, "equal-spp", Some(64)),
                &find(&rows, scene, tris, FLOOR, "equal-spp", Some(64)),
            );
            line(
                format!("{strategy} / constant floor, {scene}, 64 spp"),
                format!("≤ {goal}×"),
                shown(r),
                r.map(|r| r.0 <= goal),
            );
        }
    }
    let mut kinds: Vec<(&str, usize, &str)> = peers
        .iter()
        .map(|p| (p.scene.as_str(), p.triangles, p.strategy.as_str()))
        .collect();
    kinds.dedup();
    for (scene, tris, how) in kinds {
        let theirs: Vec<&PeerRow> = peers
            .iter()
            .filter(|p| p.scene == scene && p.strategy == how)
            .collect();
        let v_mitsuba = pooled(theirs.iter().map(|p| (&p.errors, p.spp)));
        let m64 = theirs.iter().find(|p| p.spp == 64);
        let rect = scene == "rectangle";
        let what = if how.ends_with("direct") {
            "its direct integrator"
        } else {
            "its NEE step"
        };
        for strategy in ["texture", "texture-exact"] {
            let ours: Vec<&Row> = rows
                .iter()
                .filter(|r| {
                    r.scene == scene
                        && (!rect || r.triangles == tris)
                        && r.strategy == strategy
                        && r.budget == "equal-spp"
                })
                .collect();
            if ours.is_empty() {
                continue;
            }
            let v_ours = pooled(ours.iter().map(|r| (&r.errors, r.spp)));
            let o64 = ours.iter().find(|r| r.spp == 64);
            if rect {
                let r = v_ours / v_mitsuba;
                line(
                    format!(
                        "{strategy} / Mitsuba 3 ({what}), rectangle, {tris} triangles, equal spp"
                    ),
                    "≤ 1.2×".into(),
                    format!(
                        "{} (rel MSE × spp, mean over 1–64 spp: {v_ours:.3e} / {v_mitsuba:.3e})",
                        fmt_ratio(r)
                    ),
                    Some(r <= 1.2),
                );
            } else if let (Some(o), Some(m)) = (o64, m64) {
                line(
                    format!(
                        "bias of the image, {strategy} and Mitsuba 3 ({what}), {scene}, 64 spp"
                    ),
                    "unbiased where Mitsuba is not".into(),
                    format!(
                        "ours {:+.2}% ± {:.2}%, Mitsuba {:+.2}% ± {:.2}%; rel MSE {:.3e} / {:.3e}",
                        100.0 * o.errors.bias,
                        100.0 * o.errors.bias_se,
                        100.0 * m.errors.bias,
                        100.0 * m.errors.bias_se,
                        o.errors.rel_mse,
                        m.errors.rel_mse
                    ),
                    Some(o.errors.z().abs() < 4.0 && m.errors.z().abs() >= 4.0),
                );
            }
        }
    }
    for (scene, s, r) in rates {
        // The target is the paper's (Sec. 5.2) for its subdivision; the
        // exact strategy's rejection step is shown beside it.
        let (target, met) = match s {
            Strategy::Texture => ("≥ 0.65×", Some(*r >= 0.65)),
            Strategy::TextureExact => ("(none: rejection on top)", None),
            _ => continue,
        };
        line(
            format!("light samples/s per thread, {} / area, {scene}", s.name()),
            target.into(),
            format!("{r:.2}×"),
            met,
        );
    }
    t
}

/// A ratio with three significant digits.
fn fmt_ratio(x: f64) -> String {
    if x >= 100.0 {
        format!("{x:.0}×")
    } else if x >= 10.0 {
        format!("{x:.1}×")
    } else {
        format!("{x:.2}×")
    }
}

/// Exports `case` for the Mitsuba script, runs it, and compares its
/// images with the reference.
fn mitsuba(
    python: &Path,
    out: &Path,
    case: &Case,
    texture: &(String, EmissionTexture),
    config: &Config,
    m: &Measured,
) -> Result<Vec<PeerRow>, String> {
    let dir = out.join(format!(
        "mitsuba-{}-{}",
        case.shape.name,
        case.shape.triangles()
    ));
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    write_ply(&dir.join("mesh.ply"), &case.shape)?;
    let t = &texture.1;
    let image = trilux_io::image::Image {
        width: t.width() as u32,
        height: t.height() as u32,
        pixels: t.texels().iter().map(|c| [c[0], c[1], c[2], 1.0]).collect(),
    };
    trilux_io::image::write_exr(
        dir.join("texture.exr"),
        &image,
        trilux_io::image::ExrPrecision::F32,
    )
    .map_err(|e| e.to_string())?;
    let r = &config.receiver;
    let spps: Vec<String> = config.spps.iter().map(|s| s.to_string()).collect();
    std::fs::write(
        dir.join("scene.json"),
        format!(
            "{{\"width\": {}, \"height\": {}, \"receiver_x\": [{}, {}], \"receiver_y\": [{}, {}], \"spp\": [{}], \"seed\": {}, \"direct\": {}}}\n",
            r.width,
            r.height,
            luminaire::RECEIVER_X[0],
            luminaire::RECEIVER_X[1],
            luminaire::RECEIVER_Y[0],
            luminaire::RECEIVER_Y[1],
            spps.join(", "),
            config.seed,
            case.shape.planar
        ),
    )
    .map_err(|e| e.to_string())?;
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("bench/mitsuba_luminaire.py");
    eprintln!("luminaire: mitsuba on the {}…", case.shape.name);
    let output = Command::new(python)
        .arg(&script)
        .arg(&dir)
        .output()
        .map_err(|e| format!("cannot run {}: {e}", python.display()))?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    if let Some(why) = stdout.lines().find_map(|l| l.strip_prefix("error=")) {
        return Err(why.to_string());
    }
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        return Err(format!(
            "{} exited with {}: {}",
            script.display(),
            output.status,
            stderr.lines().last().unwrap_or("")
        ));
    }
    let mut rows = Vec::new();
    for l in stdout.lines() {
        let field = |k: &str| {
            l.split_whitespace()
                .find_map(|f| f.strip_prefix(k))
                .ok_or(format!("the Mitsuba script printed {l:?}"))
        };
        let how = field("how=")?;
        let spp: usize = field("spp=")?
            .parse()
            .map_err(|_| format!("spp in {l:?}"))?;
        let seconds: f64 = field("seconds=")?
            .parse()
            .map_err(|_| format!("seconds in {l:?}"))?;
        let file = field("file=")?;
        let bytes = std::fs::read(file).map_err(|e| format!("{file}: {e}"))?;
        if bytes.len() != 12 * r.pixels() {
            return Err(format!(
                "{file}: {} bytes, expected {}",
                bytes.len(),
                12 * r.pixels()
            ));
        }
        let rgb: Vec<[f64; 3]> = bytes
            .chunks_exact(12)
            .map(|p| {
                [0, 4, 8]
                    .map(|o| f64::from(f32::from_le_bytes([p[o], p[o + 1], p[o + 2], p[o + 3]])))
            })
            .collect();
        let y: Vec<f64> = rgb
            .iter()
            .map(|c| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2])
            .collect();
        rows.push(PeerRow {
            strategy: format!("mitsuba-3-{how}"),
            scene: case.shape.name.clone(),
            texture: texture.0.clone(),
            triangles: case.shape.triangles(),
            spp,
            seconds,
            errors: compare(&y, &m.reference.image.y),
            image: Irradiance {
                y_var: vec![0.0; y.len()],
                rgb,
                y,
            },
        });
    }
    if rows.is_empty() {
        return Err("the Mitsuba script printed no result".into());
    }
    Ok(rows)
}

/// A binary little-endian PLY of the shape: `x y z u v` per vertex.
fn write_ply(path: &Path, shape: &Shape) -> Result<(), String> {
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        shape.positions.len(),
        shape.indices.len()
    )
    .into_bytes();
    for (p, uv) in shape.positions.iter().zip(&shape.uvs) {
        for x in [p.x, p.y, p.z, uv.x, uv.y] {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
    }
    for t in &shape.indices {
        bytes.push(3);
        for i in t {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
    }
    std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// The pictures of a luminaire: a grid of panels at [`PICTURE_SPP`]
/// (top: reference, area, triangle-power[, Mitsuba 3]; bottom: texture,
/// texture-exact, constant floor), tone-mapped alike (Reinhard on the
/// reference's mean), as PNG and EXR (linear irradiance).
fn picture(
    dirs: &[&Path],
    name: &str,
    receiver: &Receiver,
    m: &Measured,
    peer: Option<&Irradiance>,
) -> Result<(), String> {
    let get = |s: &str| m.pictures.iter().find(|(n, _)| n == s).map(|(_, i)| i);
    let floor_scale =
        m.reference.image.y.iter().sum::<f64>() / m.floor_reference.iter().sum::<f64>();
    let mut top: Vec<Option<&Irradiance>> =
        vec![Some(&m.reference.image), get("area"), get("triangle-power")];
    let bottom: Vec<Option<&Irradiance>> = vec![get("texture"), get("texture-exact"), get(FLOOR)];
    if let Some(p) = peer {
        top.push(Some(p));
    }
    let cols = top.len();
    let (w, h) = (receiver.width, receiver.height);
    let (pw, ph) = (cols * (w + 1) - 1, 2 * h + 1);
    let mean = m.reference.image.y.iter().sum::<f64>() / m.reference.image.y.len() as f64;
    let k = 1.0 / mean;
    let mut png = vec![[0.0f32, 0.0, 0.0, 1.0]; pw * ph];
    let mut exr = png.clone();
    for (row, panels) in [top, bottom].iter().enumerate() {
        for (col, panel) in panels.iter().enumerate() {
            let Some(img) = panel else { continue };
            // The floor has its own (smoother) distribution: shown with
            // the same mean as the reference.
            let s = if row == 1 && col == 2 {
                floor_scale
            } else {
                1.0
            };
            for j in 0..h {
                for i in 0..w {
                    let c = img.rgb[j * w + i].map(|v| v * s);
                    let y = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                    let t = k / (1.0 + k * y.max(0.0));
                    // Image row 0 at the top is the receiver's y = 1.
                    let at = (row * (h + 1) + (h - 1 - j)) * pw + col * (w + 1) + i;
                    png[at] = [(c[0] * t) as f32, (c[1] * t) as f32, (c[2] * t) as f32, 1.0];
                    exr[at] = [c[0] as f32, c[1] as f32, c[2] as f32, 1.0];
                }
            }
        }
    }
    for (d, dir) in dirs.iter().enumerate() {
        // EXR in the first folder only (the README's folder keeps PNGs).
        for (ext, pixels) in
            [("png", &png), ("exr", &exr)]
                .into_iter()
                .take(if d == 0 { 2 } else { 1 })
        {
            let path = dir.join(format!("{name}.{ext}"));
            let image = trilux_io::image::Image {
                width: pw as u32,
                height: ph as u32,
                pixels: pixels.clone(),
            };
            trilux_io::image::write(&path, &image).map_err(|e| e.to_string())?;
        }
    }
    Ok(())
}
