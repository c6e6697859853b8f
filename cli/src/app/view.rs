//! `trilux view`: the command that loads the object and starts the
//! server of `trilux::view` (the server, the session and the page live
//! in the library; this file only reads arguments and files and supplies
//! the renderer for exports).

use std::path::{Path, PathBuf};

use glam::DVec3;
use serde_json::{Value, json};
use tet_diffusion::{Log, Object, Session};
use trilux::view::protocol::ExportKind;
use trilux::view::session_file::EnvFiles;

use super::args::Material;
use super::ops::object::{check_volume, diagonal, read_volume};
use super::{Context, Result, arg_error, file_error};

#[derive(Debug, clap::Args)]
#[command(
    about = "Cut, paint, fracture and relight a translucent object interactively in the browser (TransCut)",
    after_help = "Example:\n  trilux view                     # a built-in marble ball with a ketchup core\n  trilux view ../shared/data/tets/bunny_50k.node --material marble --open\n  trilux view --replay session.json\n\nIt prints a URL with a secret token; open it in a browser on this machine.\nPress ? on the page for the keys. Ctrl+C stops the server."
)]
pub(crate) struct Args {
    /// A tetrahedral mesh (.node, .ele, .msh, .mesh, .vtu) or a closed
    /// surface (.obj, .gltf, .glb, .ply), tetrahedralized first; none: a
    /// built-in object.
    pub(crate) input: Option<PathBuf>,
    /// A measured material (Jensen et al. 2001) or noise:A,B.
    #[arg(long, value_parser = Material::parse)]
    pub(crate) material: Option<Material>,
    /// Millimetres per mesh unit (default: 1000 when the mesh's diagonal is
    /// under 5 units, as for scans in metres; 1 otherwise).
    #[arg(long, value_name = "X", allow_negative_numbers = true, value_parser = super::args::unit_mm)]
    pub(crate) unit_mm: Option<f64>,
    /// For a surface: fit the tetrahedra's boundary to it within EPS (a
    /// fraction of the bounding box's diagonal, e.g. 0.002), so thin parts
    /// and creases stay (as `trilux tetra --envelope`).
    #[arg(long, value_name = "EPS", allow_negative_numbers = true)]
    pub(crate) envelope: Option<f64>,
    #[command(flatten)]
    pub(crate) serve: super::web::ServeArgs,
    /// Start from a session file the page exported (its source and edits).
    // The file names its own mesh, material and unit: given beside it they
    // would be ignored, so they are refused (as `diffuse --session` does).
    #[arg(long, value_name = "SESSION.json", conflicts_with_all = ["input", "material", "unit_mm", "envelope"])]
    pub(crate) replay: Option<PathBuf>,
    /// Folder the page's exports are written to.
    #[arg(long, value_name = "DIR", default_value = ".")]
    pub(crate) export_dir: PathBuf,
}

/// The object and edits of the session file at `path`.
fn replay(context: &mut Context, path: &Path) -> Result<(Object, Value, Log, EnvFiles)> {
    super::check_input(path)?;
    let text = std::fs::read_to_string(path).map_err(|e| file_error(path, e))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let (source, log, envs) = trilux::view::session_file::from_json_in(&text, Some(dir))
        .map_err(|e| file_error(path, e))?;
    let mesh = source
        .get("mesh")
        .and_then(Value::as_str)
        .map(PathBuf::from);
    let material = source
        .get("material")
        .and_then(Value::as_str)
        .map(|m| Material::parse(m).map_err(|e| file_error(path, format!("material {m:?}: {e}"))))
        .transpose()?;
    let unit = source.get("unit_mm").and_then(Value::as_f64);
    let envelope = source.get("envelope").and_then(Value::as_f64);
    if let Some(eps) = envelope
        && !(eps > 0.0 && eps <= 1.0)
    {
        return Err(file_error(
            path,
            format!("envelope {eps}: a fraction of the bounding box's diagonal, between 0 and 1"),
        ));
    }
    if let Some(mm) = unit
        && !(mm.is_finite() && mm > 0.0)
    {
        return Err(file_error(
            path,
            format!("unit_mm {mm}: millimetres per mesh unit must be a positive number"),
        ));
    }
    let view = trilux::view::session_file::saved_view(&source).map_err(|e| file_error(path, e))?;
    // The user named only the session file: a mesh it names that is gone
    // (moved, or a relative path from another folder) is an error in it.
    if let Some(m) = &mesh
        && !m.exists()
    {
        return Err(file_error(
            path,
            format!(
                "source.mesh {:?}: no such file (a relative path is taken from the current folder)",
                m.display().to_string()
            ),
        ));
    }
    let (object, mut loaded) = load(context, mesh.as_deref(), material.as_ref(), unit, envelope)?;
    // The camera it was saved with: the page starts there.
    if let (Some(v), Some(o)) = (view, loaded.as_object_mut()) {
        o.insert("view".into(), json!(v.to_array()));
    }
    Ok((object, loaded, log, envs))
}

/// Loads the object a session file's `source` or the arguments describe.
pub(crate) fn load(
    context: &mut Context,
    input: Option<&Path>,
    material: Option<&Material>,
    unit_mm: Option<f64>,
    envelope: Option<f64>,
) -> Result<(Object, Value)> {
    let source = json!({
        "mesh": input.map(|p| p.display().to_string()),
        "material": material.map(|m| m.spec.as_str()),
        "unit_mm": unit_mm,
        "envelope": envelope,
    });
    let Some(input) = input else {
        if envelope.is_some() {
            return Err(super::usage(
                "--envelope fits the tetrahedra of a surface: give one (the built-in object is made in code)",
            ));
        }
        let mut object =
            trilux::view::builtin::object(16).map_err(|e| super::invalid(e.to_string()))?;
        if let Some(m) = material {
            let media = vec![m.a; object.media().len()];
            object = Object::new(object.mesh().clone(), 1.0, media, 1.3)
                .map_err(|e| super::invalid(e.to_string()))?;
        }
        add_default_light(&mut object)?;
        return Ok((object, source));
    };
    check_volume(input, "view", true)?;
    let (positions, tets, _) = read_volume(context, input, true, envelope)?;
    let mesh = tet_diffusion::TetMesh::new(&positions, &tets).map_err(|e| file_error(input, e))?;
    let diagonal = diagonal(&positions);
    let unit = super::ops::object::unit_mm(unit_mm, diagonal);
    let marble;
    let material = match material {
        Some(m) => m,
        None => {
            marble = Material::parse("marble").map_err(super::invalid)?;
            &marble
        }
    };
    let media = material
        .media(&mesh, diagonal / 6.0)
        .map_err(|e| arg_error(format!("--material {material}"), e))?;
    let mut object = context
        .step("assembling", || Object::new(mesh, unit, media, 1.3))
        .map_err(|e| file_error(input, e))?;
    add_default_light(&mut object)?;
    Ok((object, source))
}

fn add_default_light(object: &mut Object) -> Result<()> {
    object
        .add_light(trilux::view::builtin::default_light())
        .map_err(|e| super::invalid(e.to_string()))?;
    Ok(())
}

/// Exports through the CLI's renderer and writers.
struct Cli;

/// The pieces as one tet mesh in the display frame.
fn merged(session: &Session) -> trilux_io::tet::TetMesh {
    let mut out = trilux_io::tet::TetMesh::default();
    for o in session.pieces() {
        let base = out.positions.len() as u32;
        out.positions.extend(o.display_positions());
        out.tets
            .extend(o.mesh().tets().iter().map(|t| t.map(|v| v + base)));
    }
    out
}

impl trilux::view::Exporter for Cli {
    fn export(
        &self,
        session: &Session,
        kind: ExportKind,
        path: &Path,
        size: u32,
        view: Option<DVec3>,
        overwrite: bool,
    ) -> std::result::Result<(), String> {
        let view = view.map(|v| v.as_vec3());
        let written = match kind {
            ExportKind::Png | ExportKind::Exr => {
                // A file in the way is refused before the picture is drawn.
                trilux::output::check_new(path, overwrite).map_err(|e| e.to_string())?;
                let picture = trilux::tet::render_session(session, size, view);
                write_picture(&picture, kind == ExportKind::Png, path, overwrite)
            }
            ExportKind::Vtu => write_vtu(session, path, overwrite),
            ExportKind::Tet => return write_tet(session, path, overwrite),
            ExportKind::Session | ExportKind::Glb => {
                return Err(format!(
                    "{} files are written by the server",
                    kind.extension()
                ));
            }
        };
        written.map_err(|e| e.to_string())
    }
}

/// Writes a session's picture ([`trilux::tet::render_session`]):
/// tone-mapped 8-bit PNG (`png`) or linear EXR, atomically (an existing
/// file only with `overwrite`).
pub(crate) fn write_picture(
    picture: &trilux::tet::Picture,
    png: bool,
    path: &Path,
    overwrite: bool,
) -> trilux::Result<()> {
    trilux::output::write_atomic(path, overwrite, |tmp| {
        if png {
            Ok(trilux_io::image::write_png(
                tmp,
                &trilux::tet::tone_map(picture),
                trilux_io::image::PngDepth::Eight,
            )?)
        } else {
            Ok(trilux_io::image::write_exr(
                tmp,
                &picture.image,
                trilux_io::image::ExrPrecision::F32,
            )?)
        }
    })
}

/// Writes the pieces (display frame) with φ per channel and the surface's
/// luminance per node as VTU, atomically.
pub(crate) fn write_vtu(session: &Session, path: &Path, overwrite: bool) -> trilux::Result<()> {
    use trilux_io::tet::vtu::{Encoding, Field};
    let mesh = merged(session);
    let mut phi: [Vec<f64>; 3] = Default::default();
    let mut lum = Vec::new();
    for o in session.pieces() {
        for (c, p) in phi.iter_mut().enumerate() {
            p.extend_from_slice(o.phi(c));
        }
        let mut l = vec![0.0; o.mesh().vertex_count()];
        for (&v, r) in o.mesh().boundary_vertices().iter().zip(o.radiance(None)) {
            l[v as usize] = 0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2];
        }
        lum.extend(l);
    }
    let field = |name, values| Field { name, values };
    let fields = [
        field("phi_r", &phi[0]),
        field("phi_g", &phi[1]),
        field("phi_b", &phi[2]),
        field("radiance", &lum),
    ];
    trilux::output::write_atomic(path, overwrite, |tmp| {
        Ok(trilux_io::tet::vtu::write(
            tmp,
            &mesh,
            &fields,
            &[],
            Encoding::Base64,
        )?)
    })
}

/// Writes the pieces as TetGen `path` (.node) and its .ele, each atomic.
fn write_tet(session: &Session, path: &Path, overwrite: bool) -> std::result::Result<(), String> {
    let ele = path.with_extension("ele");
    for p in ExportKind::Tet.files(path) {
        trilux::output::check_new(&p, overwrite).map_err(|e| e.to_string())?;
    }
    let mesh = merged(session);
    let tmp = trilux::output::temporary_name(path);
    let tmp_ele = tmp.with_extension("ele");
    let written = trilux_io::tet::tetgen::write(&tmp, &mesh)
        .map_err(|e| e.to_string())
        .and_then(|()| std::fs::rename(&tmp_ele, &ele).map_err(|e| e.to_string()))
        .and_then(|()| std::fs::rename(&tmp, path).map_err(|e| e.to_string()));
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
        let _ = std::fs::remove_file(&tmp_ele);
    }
    written
}

/// The session a session file describes, replayed as `trilux view
/// --replay` replays it and refined as the view refines it when idle
/// (so that its pictures are those the page exports).
///
/// # Errors
/// The file (unreadable, not a session file: the field named), its
/// object, or the first edit that fails (named by its index and op).
pub(crate) fn replayed(context: &mut Context, path: &Path) -> Result<(Session, Option<DVec3>)> {
    let (object, source, log, _) = replay(context, path)?;
    let view = trilux::view::session_file::saved_view(&source).map_err(|e| file_error(path, e))?;
    let options = trilux::view::Options::default().session;
    let mut session = context
        .step("replaying", || Session::replay(object, options, &log))
        .map_err(|(k, e)| {
            let op = log.edits.get(k).map_or("edit", |l| l.edit.name());
            file_error(path, format!("edits[{k}] ({op}): {e}"))
        })?;
    if session.needs_refinement() {
        context
            .step("solving", || session.refine_now())
            .map_err(|e| file_error(path, format!("the last edit's solve: {e}")))?;
    }
    Ok((session, view))
}

pub(crate) fn run(context: &mut Context, args: Args) -> Result<()> {
    let mut environments = EnvFiles::new();
    let (object, source, log) = match &args.replay {
        Some(path) => {
            let (o, s, log, envs) = replay(context, path)?;
            copy_environments(path, &envs, &args.export_dir)?;
            environments = envs;
            (o, s, Some(log))
        }
        None => {
            let (o, s) = load(
                context,
                args.input.as_deref(),
                args.material.as_ref(),
                args.unit_mm,
                args.envelope,
            )?;
            (o, s, None)
        }
    };
    if !args.export_dir.is_dir() {
        return Err(file_error(
            &args.export_dir,
            "no such folder (for --export-dir)",
        ));
    }
    super::web::warn_host(args.serve.host);
    let options = trilux::view::Options {
        host: args.serve.host,
        port: args.serve.port,
        export_dir: args.export_dir.clone(),
        environments,
        ..Default::default()
    };
    let tets = object.mesh().tets().len();
    let start = trilux::view::start(object, source, log, options, Box::new(Cli));
    super::web::serve(
        context,
        "view",
        (tets, "tetrahedra"),
        args.serve.open,
        start,
    )
}

/// Copies the environment maps a replayed session file names into the
/// export folder (where the session files it writes will name them).
fn copy_environments(session: &Path, envs: &EnvFiles, export_dir: &Path) -> Result<()> {
    let from = session.parent().unwrap_or(Path::new("."));
    for (_, file) in envs {
        let (a, b) = (from.join(file), export_dir.join(file));
        if !b.exists() {
            std::fs::copy(&a, &b).map_err(|e| file_error(&b, e))?;
        }
    }
    Ok(())
}
