//! `trilux paint`: the command that loads a surface and its colours and
//! starts the painting server of `trilux::paint`.

use std::path::{Path, PathBuf};

use mesh_colors::MeshColors;
use serde_json::{Value, json};
use trilux::ColorMesh;
use trilux::paint::{Document, Options};
use trilux_io::mesh::TriMesh;

use super::ops::colors::load_for;
use super::{Context, Result, arg_error, file_error};

/// Samples a flat start aims at (the resolution is chosen from the face
/// count): detailed enough to paint at once, light enough to upload fast.
const START_SAMPLES: usize = 400_000;

#[derive(Debug, clap::Args)]
#[command(
    about = "Paint colours on a 3D model in the browser, no UVs needed (Mesh Colors)",
    after_help = "Examples:\n  trilux paint                                   # a built-in model\n  trilux paint ../shared/data/meshes/spot.obj --open\n  trilux paint cow.obj --colors cow.meshcolors --channels roughness\n  trilux paint cow.obj --replay session.json\n\nIt prints a URL with a secret token; open it in a browser on this machine.\nPress ? on the page for the tools and keys. Ctrl+C stops the server (the colours are autosaved)."
)]
pub(crate) struct Args {
    /// The surface: .obj, .gltf, .glb or .ply, UVs or none; none: a
    /// built-in model.
    pub(crate) mesh: Option<PathBuf>,
    /// Start from these mesh colours (made for this mesh).
    #[arg(long, value_name = "F.meshcolors", conflicts_with = "texture")]
    pub(crate) colors: Option<PathBuf>,
    /// Start from this texture, converted (the mesh needs UVs); by default
    /// the mesh's own texture when it has one.
    #[arg(long, value_name = "IMAGE")]
    pub(crate) texture: Option<PathBuf>,
    /// The face resolution of a flat start, a power of two (default: from
    /// the mesh's size, about 400,000 samples).
    #[arg(long, value_name = "R", value_parser = resolution)]
    pub(crate) resolution: Option<u32>,
    /// Scalar channels to paint besides colour, comma-separated, each
    /// shown as a heat map and starting at 0, or at the value after `=`
    /// (e.g. density,roughness=0.5: an unpainted roughness of 0 is a
    /// mirror in Blender).
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub(crate) channels: Vec<String>,
    /// Replay a session file the page exported (its edits, on this mesh).
    #[arg(long, value_name = "SESSION.json")]
    pub(crate) replay: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) serve: super::web::ServeArgs,
    /// Folder saves, exports and the autosave are written to.
    #[arg(long, value_name = "DIR", default_value = ".")]
    pub(crate) export_dir: PathBuf,
}

fn resolution(text: &str) -> std::result::Result<u32, String> {
    let r: u32 = text.parse().map_err(|e| format!("{e}"))?;
    let max = 1u32 << mesh_colors::MAX_LEVEL;
    if !r.is_power_of_two() || r > max {
        return Err(format!("expected a power of two from 1 to {max}"));
    }
    Ok(r)
}

pub(crate) fn run(context: &mut Context, args: Args) -> Result<()> {
    channel_starts(&args.channels)?;
    if !args.export_dir.is_dir() {
        return Err(file_error(
            &args.export_dir,
            "no such folder (for --export-dir)",
        ));
    }
    let doc = load(context, &args)?;
    let log = match &args.replay {
        Some(path) => Some(read_session(path, &doc)?),
        None => None,
    };
    // Absolute, so the page's messages say where files are, not "./".
    let export_dir = std::path::absolute(&args.export_dir).unwrap_or(args.export_dir.clone());
    let (autosave, earlier) =
        autosave_paths(&export_dir, &doc.model_name(), args.colors.as_deref());
    if let Some(newest) = earlier.last() {
        eprintln!(
            "note: an earlier trilux paint of this model left autosaved colours in {}; resume them with --colors {} (this session autosaves to {}, so they are kept)",
            newest.display(),
            newest.display(),
            autosave.display()
        );
    }
    super::web::warn_host(args.serve.host);
    let faces = doc.surface.faces.len();
    let options = Options {
        host: args.serve.host,
        port: args.serve.port,
        export_dir,
        autosave: Some(autosave),
        earlier_autosaves: earlier,
        ..Default::default()
    };
    let start = trilux::paint::start(doc, log, options);
    super::web::serve(context, "paint", (faces, "faces"), args.serve.open, start)
}

/// `--channels` as typed (`NAME` or `NAME=START`): the names and the
/// values they start at (0 unless given).
fn channel_starts(specs: &[String]) -> Result<(Vec<String>, Vec<f32>)> {
    let mut names = Vec::with_capacity(specs.len());
    let mut starts = Vec::with_capacity(specs.len());
    for spec in specs {
        let (name, start) = match spec.split_once('=') {
            Some((name, value)) => {
                let start = value.trim().parse::<f32>().ok().filter(|v| v.is_finite());
                let start = start.ok_or_else(|| {
                    arg_error(
                        format!("--channels {}", specs.join(",")),
                        format!("{spec:?}: the value after = is the channel's start, a number"),
                    )
                })?;
                (name, start)
            }
            None => (spec.as_str(), 0.0),
        };
        names.push(name.to_string());
        starts.push(start);
    }
    check_channels(&names)?;
    Ok((names, starts))
}

/// Channel names: plain words, none repeated, not "color".
fn check_channels(names: &[String]) -> Result<()> {
    for (k, n) in names.iter().enumerate() {
        let problem = if n.is_empty() {
            Some("an empty name (two commas, or one at an end)".to_string())
        } else if n.len() > 32 {
            Some(format!("{n:?} is longer than 32 characters"))
        } else if let Some(c) = n
            .chars()
            .find(|&c| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'))
        {
            Some(format!(
                "{n:?} has {c:?}: a channel name is letters, digits, - and _"
            ))
        } else if n == "color" {
            Some("\"color\" is the RGB channel every model has; name the scalar channels".into())
        } else if names[..k].contains(n) {
            Some(format!("{n:?} is named twice"))
        } else {
            None
        };
        if let Some(problem) = problem {
            return Err(arg_error(
                format!("--channels {}", names.join(",")),
                problem,
            ));
        }
    }
    if 3 + names.len() > mesh_colors::MAX_CHANNELS {
        return Err(arg_error(
            format!("--channels {}", names.join(",")),
            format!("at most {} scalar channels", mesh_colors::MAX_CHANNELS - 3),
        ));
    }
    Ok(())
}

/// The file name's stem, `model` for the built-in one.
/// Where this session autosaves, in `dir`: `STEM.autosave.meshcolors`,
/// or `STEM.autosave-N.meshcolors` with the first `N` free, so that an
/// earlier session's autosave (after a crash, or one never resumed) is
/// never overwritten; the colours being resumed (`--colors` naming one of
/// them) are saved back where they came from. Also returns the earlier
/// autosaves found, oldest first, without the one resumed.
fn autosave_paths(dir: &Path, stem: &str, resumed: Option<&Path>) -> (PathBuf, Vec<PathBuf>) {
    let name = |k: usize| match k {
        1 => dir.join(format!("{stem}.autosave.meshcolors")),
        k => dir.join(format!("{stem}.autosave-{k}.meshcolors")),
    };
    let resumed = resumed.and_then(|p| p.canonicalize().ok());
    let mut earlier = Vec::new();
    let mut own = None;
    let mut k = 1;
    // Ends at the first free name: the folder holds finitely many files.
    let free = loop {
        let path = name(k);
        if !path.exists() {
            break path;
        }
        if own.is_none() && path.canonicalize().ok() == resumed {
            own = Some(path);
        } else {
            earlier.push(path);
        }
        k += 1;
    };
    let modified = |p: &PathBuf| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    earlier.sort_by_key(modified);
    (own.unwrap_or(free), earlier)
}

/// The surface and its starting colours, as the arguments say.
fn load(context: &mut Context, args: &Args) -> Result<Document> {
    let mesh = match &args.mesh {
        Some(path) => super::read_mesh(context, path)?,
        None => trilux::shapes::blob(4),
    };
    let shown = args.mesh.as_ref().map_or_else(
        || "the built-in model".to_string(),
        |p| p.display().to_string(),
    );
    let (surface, colors, start) = start_colors(context, args, &mesh)?;
    if surface.detached > 0 {
        eprintln!(
            "warning: {shown}: {} triangles are not joined to their neighbours (a third face on an edge, or degenerate): they are painted on their own",
            surface.detached
        );
    }
    let (names, starts) = channel_starts(&args.channels)?;
    let colors = with_scalars(colors, &starts)?;
    // Erasing goes back to the base: grey, and each channel's start.
    let mut base = vec![0.8f32; 3];
    base.extend(&starts);
    let source = json!({
        "mesh": args.mesh.as_ref().map(|p| p.display().to_string()),
        "colors": args.colors.as_ref().map(|p| p.display().to_string()),
        "texture": args.texture.as_ref().map(|p| p.display().to_string()),
        "start": start,
        "channels": args.channels,
    });
    Ok(Document {
        surface,
        colors,
        base,
        scalars: names,
        source,
    })
}

/// The welded surface and its colours from `--colors`, a texture, or a
/// flat base colour; and how they started (for the session file).
fn start_colors(
    context: &mut Context,
    args: &Args,
    mesh: &TriMesh,
) -> Result<(ColorMesh, MeshColors, Value)> {
    let mesh_path = args.mesh.as_deref().unwrap_or(Path::new("model"));
    if let Some(path) = &args.colors {
        let (surface, colors) = context.step("reading the mesh colours", || {
            load_for(mesh, mesh_path, path)
        })?;
        return Ok((surface, colors, json!("colors")));
    }
    let texture = match &args.texture {
        Some(path) => Some(super::read_image(context, path, false)?),
        None => None,
    };
    let has_texture = texture.is_some()
        || mesh
            .materials
            .iter()
            .any(|m| m.diffuse_image.is_some() || m.diffuse_texture.is_some());
    if has_texture && mesh.uvs.is_some() {
        let (surface, colors) = context
            .step("converting the texture to mesh colours", || {
                trilux::to_mesh_colors(mesh, texture.as_ref(), &Default::default())
            })
            .map_err(|e| super::at(mesh_path.display(), e))?;
        return Ok((surface, colors, json!("texture")));
    }
    if texture.is_some() {
        return Err(file_error(
            mesh_path,
            "the mesh has no UVs, so --texture cannot be converted; leave it out to paint on a flat colour",
        ));
    }
    let surface = ColorMesh::new(mesh).map_err(|e| super::at(mesh_path.display(), e))?;
    let r = args
        .resolution
        .unwrap_or_else(|| flat_resolution(surface.faces.len()));
    let topology = surface
        .topology()
        .map_err(|e| super::at(mesh_path.display(), e))?;
    check_fits(&topology, r, 3 + channel_starts(&args.channels)?.1.len())?;
    let mut colors = MeshColors::uniform(topology, r, 3)
        .map_err(|e| arg_error(format!("--resolution {r}"), e))?;
    colors.samples_mut().fill(0.8);
    Ok((
        surface,
        colors,
        json!({"flat": [0.8, 0.8, 0.8], "resolution": r}),
    ))
}

/// That colours at resolution `r` on every face, with `channels`
/// channels, fit the page's textures, before they are built (a
/// resolution too fine for the mesh would otherwise take seconds and
/// gigabytes to fail); else the error names `--resolution` and the
/// finest that fits.
fn check_fits(topology: &mesh_colors::Topology, r: u32, channels: usize) -> Result<()> {
    let budget = u64::from(trilux::paint::TEXTURE_WIDTH).pow(2);
    let texels = |r: u32| mesh_colors::gpu::uniform_sample_texels(topology, r, channels);
    if texels(r) <= budget {
        return Ok(());
    }
    let finest = (0..=mesh_colors::MAX_LEVEL)
        .rev()
        .map(|l| 1u32 << l)
        .find(|&r| texels(r) <= budget);
    let w = trilux::paint::TEXTURE_WIDTH;
    let problem = format!(
        "the page's textures would need {} rows of {w} texels, more than WebGL2's {w}; {}",
        texels(r).div_ceil(u64::from(w)),
        match finest {
            Some(f) => format!("--resolution {f} is the finest that fits this mesh"),
            None => "the mesh has too many faces for any resolution".into(),
        }
    );
    Err(arg_error(format!("--resolution {r}"), problem))
}

/// The power of two that gives about [`START_SAMPLES`] samples on `faces`
/// faces (a face of resolution R holds about R²/2), 1 to 64.
fn flat_resolution(faces: usize) -> u32 {
    let per_face = START_SAMPLES as f64 / faces.max(1) as f64;
    let r = (2.0 * per_face).sqrt();
    let level = r.log2().round().clamp(0.0, 6.0) as u32;
    1 << level
}

/// `colors` with one more channel per value of `starts`, which it starts at.
fn with_scalars(colors: MeshColors, starts: &[f32]) -> Result<MeshColors> {
    let scalars = starts.len();
    if scalars == 0 {
        return Ok(colors);
    }
    let c = colors.channels();
    let resolutions: Vec<u32> = (0..colors.face_count())
        .map(|f| colors.face_resolution(f).unwrap_or(1))
        .collect();
    let mut wide = MeshColors::new(colors.topology().clone(), &resolutions, c + scalars)?;
    for (to, from) in wide
        .samples_mut()
        .chunks_mut(c + scalars)
        .zip(colors.samples().chunks(c))
    {
        to[..c].copy_from_slice(from);
        to[c..].copy_from_slice(starts);
    }
    Ok(wide)
}

/// The edits of a paint session file, for `doc`.
fn read_session(path: &Path, doc: &Document) -> Result<Vec<mesh_colors::session::Edit>> {
    super::check_input(path)?;
    let text = std::fs::read_to_string(path).map_err(|e| file_error(path, e))?;
    let (source, edits) =
        trilux::paint::session_file::from_json(&text, &doc.scalars, doc.mirror_x())
            .map_err(|e| file_error(path, e))?;
    trilux::paint::session_file::check_replays_on(&source, doc).map_err(|e| file_error(path, e))?;
    Ok(edits)
}

#[cfg(test)]
mod tests {
    #[test]
    fn an_earlier_autosave_is_kept_and_named_unless_it_is_resumed() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let name = |s: &str| d.join(s);
        let first = name("cow.autosave.meshcolors");
        assert_eq!(autosave_paths(d, "cow", None), (first.clone(), vec![]));
        std::fs::write(&first, "earlier").unwrap();
        let second = name("cow.autosave-2.meshcolors");
        assert_eq!(
            autosave_paths(d, "cow", None),
            (second.clone(), vec![first.clone()])
        );
        // Resuming the first saves back to it.
        assert_eq!(
            autosave_paths(d, "cow", Some(&first)),
            (first.clone(), vec![])
        );
        std::fs::write(&second, "later").unwrap();
        let (own, earlier) = autosave_paths(d, "cow", Some(&second));
        assert_eq!((own, earlier), (second.clone(), vec![first.clone()]));
        let (own, earlier) = autosave_paths(d, "cow", None);
        assert_eq!(own, name("cow.autosave-3.meshcolors"));
        assert_eq!(earlier.len(), 2);
        // Another model's autosaves are not this one's.
        assert_eq!(
            autosave_paths(d, "pig", None).1,
            Vec::<std::path::PathBuf>::new()
        );
    }

    use super::*;

    #[test]
    fn a_flat_start_aims_at_a_few_hundred_thousand_samples() {
        assert_eq!(flat_resolution(5856), 16);
        assert_eq!(flat_resolution(1), 64);
        assert_eq!(flat_resolution(10_000_000), 1);
        assert_eq!(resolution("8"), Ok(8));
        assert!(resolution("6").is_err() && resolution("x").is_err());
    }

    #[test]
    fn scalar_channels_start_at_their_values_beside_the_colours() {
        let blob = trilux::shapes::blob(1);
        let surface = ColorMesh::new(&blob).unwrap();
        let mut colors = MeshColors::uniform(surface.topology().unwrap(), 2, 3).unwrap();
        colors.samples_mut().fill(0.25);
        let wide = with_scalars(colors, &[0.5, 0.0]).unwrap();
        assert_eq!(wide.channels(), 5);
        assert!(
            wide.samples()
                .chunks(5)
                .all(|s| s == [0.25, 0.25, 0.25, 0.5, 0.0])
        );
    }

    #[test]
    fn a_bad_channel_list_is_told_its_own_problem() {
        let check = |names: &[&str]| {
            let names: Vec<String> = names.iter().map(|n| n.to_string()).collect();
            check_channels(&names).map_err(|e| {
                // The placement, then the problem below it.
                let mut text = e.to_string();
                let mut source = std::error::Error::source(&e);
                while let Some(s) = source {
                    text += &format!(": {s}");
                    source = s.source();
                }
                text
            })
        };
        assert_eq!(check(&["roughness", "density"]), Ok(()));
        let specs = ["roughness=0.5".to_string(), "density".to_string()];
        let (names, starts) = channel_starts(&specs).unwrap();
        assert_eq!(
            (names, starts),
            (vec!["roughness".into(), "density".into()], vec![0.5, 0.0])
        );
        let bad = channel_starts(&["roughness=rough".to_string()]).unwrap_err();
        assert!(format!("{bad:?}").contains("start, a number"), "{bad:?}");
        let long = "x".repeat(33);
        let cases: [(&[&str], &str); 5] = [
            (&["roughness", "roughness"], "\"roughness\" is named twice"),
            (&["density", ""], "an empty name"),
            (&["a b"], "\"a b\" has ' '"),
            (&["color"], "\"color\" is the RGB channel"),
            (&[long.as_str()], "longer than 32 characters"),
        ];
        for (names, want) in cases {
            let e = check(names).unwrap_err();
            assert!(
                e.contains("--channels") && e.contains(want),
                "{names:?}: {e}"
            );
        }
    }
}
