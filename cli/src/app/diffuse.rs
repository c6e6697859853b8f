//! `trilux diffuse`: TransCut's diffusion on a tetrahedral mesh (lights,
//! materials, cuts, paint, fracture), shaded with Eq. 3's outgoing
//! radiance plus a specular term, and rendered.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use tet_diffusion::{Cut, CutMethod, Light, Object};

use super::args::{LightSpec, Material, Paint, PaintSpec, PictureArgs, Plane};
use super::ops::object::{check_volume, default_light, diagonal, read_volume, unit_mm};
use super::{Context, Result, arg_cause, file_cause};

#[derive(Debug, clap::Args)]
#[command(
    about = "Solve TransCut's diffusion on a tetrahedral mesh (or a surface, tetrahedralized first) and render it",
    after_help = "Example:\n  trilux diffuse ../shared/data/tets/bunny_500k.node --material marble --unit-mm 1000 \\\n      --light dir:0.3,1,0.6 --cut plane:0,0,1,0 -o bunny_marble.png --vtu bunny_marble.vtu\n\nPainting: the ears (the side y > 0.15) in skin, and a ball of ketchup:\n  trilux diffuse ../shared/data/tets/bunny_50k.node --material marble \\\n      --paint plane:0,1,0,0.15:skin1 --paint 0.03,0.08,0.03:0.01:ketchup -o bunny_painted.png\n\nMaterials: apple chicken1 chicken2 cream ketchup marble potato skimmilk skin1 skin2\nspectralon wholemilk, or noise:A,B (fractal noise between two of them).\n\nA session of `trilux view` (saved from its page), rendered as the page exports it:\n  trilux diffuse --session session.json --view 0.5,1,2 -o session.png"
)]
pub(crate) struct Args {
    /// A tetrahedral mesh (.node, .ele, .msh, .mesh) or a closed surface
    /// (.obj, .gltf, .glb, .ply), which is tetrahedralized first.
    #[arg(required_unless_present = "session")]
    pub(crate) input: Option<PathBuf>,
    /// Replay a session file of `trilux view` instead (its object and
    /// edits, exactly as `trilux view --replay` does, refined as the page
    /// refines when idle); the picture is the page's export of it, from
    /// the camera the page saved unless --view is given.
    #[cfg(feature = "view")]
    #[arg(long, value_name = "SESSION.json", conflicts_with_all = [
        "input", "material", "unit_mm", "envelope", "light", "envmap", "cut", "relax_cut", "paint", "fracture",
        "solver",
    ])]
    pub(crate) session: Option<PathBuf>,
    /// A measured material (Jensen et al. 2001) or noise:A,B.
    #[arg(long, default_value = "marble", value_parser = Material::parse)]
    pub(crate) material: Material,
    /// Millimetres per mesh unit (default: 1000 when the mesh's diagonal is
    /// under 5 units, as for scans in metres; 1 otherwise).
    #[arg(long, value_name = "X", allow_negative_numbers = true, value_parser = super::args::unit_mm)]
    pub(crate) unit_mm: Option<f64>,
    /// For a surface: fit the tetrahedra's boundary to it within EPS (a
    /// fraction of the bounding box's diagonal, e.g. 0.002), so thin parts
    /// and creases stay (as `trilux tetra --envelope`).
    #[arg(long, value_name = "EPS", allow_negative_numbers = true)]
    pub(crate) envelope: Option<f64>,
    /// dir:x,y,z[:r,g,b] (toward the light) or point:x,y,z[:r,g,b];
    /// repeatable. Default: one light from the upper front.
    #[arg(long, value_name = "SPEC", value_parser = LightSpec::parse)]
    pub(crate) light: Vec<LightSpec>,
    /// An equirectangular environment map as a light.
    #[arg(long, value_name = "IMAGE")]
    pub(crate) envmap: Option<PathBuf>,
    /// plane:nx,ny,nz,d removes the side n·x > d; repeatable. The cut
    /// splits the tetrahedra the plane crosses, so its face is flat.
    #[arg(long, value_name = "SPEC", value_parser = Plane::parse)]
    pub(crate) cut: Vec<Plane>,
    /// Cut as TransCut does instead: remove the tetrahedra entirely on the
    /// cut side and relax the cross-section toward the plane (a jagged
    /// face, one tetrahedron deep).
    #[arg(long)]
    pub(crate) relax_cut: bool,
    /// x,y,z:radius:material paints a material into a soft-edged ball
    /// (Gaussian, σ = radius); plane:nx,ny,nz,d:material paints the whole
    /// side n·x > d (the side --cut would remove); repeatable (planes are
    /// painted first, then balls, each in the order given).
    #[arg(long, value_name = "SPEC", value_parser = PaintSpec::parse)]
    pub(crate) paint: Vec<PaintSpec>,
    /// plane:nx,ny,nz,d breaks the object in two along the plane.
    #[arg(long, value_name = "SPEC", value_parser = Plane::parse)]
    pub(crate) fracture: Option<Plane>,
    /// The linear solver: auto chooses by the system (Jacobi-PCG, or the
    /// V-cycle where its hierarchy pays; the summary says which ran and
    /// --json why); jacobi or vcycle force one.
    #[arg(long, value_enum, default_value_t = SolverArg::Auto)]
    pub(crate) solver: SolverArg,
    #[command(flatten)]
    pub(crate) picture: PictureArgs,
    /// The picture (tone-mapped, 8-bit sRGB PNG).
    #[arg(short, long, value_name = "OUT.png")]
    pub(crate) output: PathBuf,
    /// Also the linear radiance as EXR.
    #[arg(long, value_name = "OUT.exr")]
    pub(crate) exr: Option<PathBuf>,
    /// Also φ and the radiance per node as VTU, for ParaView.
    #[arg(long, value_name = "OUT.vtu")]
    pub(crate) vtu: Option<PathBuf>,
    /// Also the surface as glTF (.glb, or .gltf + .bin) for 3D viewers:
    /// the radiance as vertex colours at the picture's exposure, and as
    /// attributes the radiance unclamped (_RADIANCE) and φ (_PHI); one
    /// object per piece.
    #[arg(long, value_name = "OUT.glb")]
    pub(crate) glb: Option<PathBuf>,
}

/// The values of `--solver` (no doc comments on them: clap would switch
/// the whole help to its long layout): tet-diffusion's `Method::Auto`,
/// `JacobiPcg` and `VCyclePcg`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum SolverArg {
    Auto,
    Jacobi,
    Vcycle,
}

impl SolverArg {
    fn method(self) -> tet_diffusion::Method {
        match self {
            Self::Auto => tet_diffusion::Method::Auto,
            Self::Jacobi => tet_diffusion::Method::JacobiPcg,
            Self::Vcycle => tet_diffusion::Method::VCyclePcg,
        }
    }
}

/// Sweeps of TransCut's relaxation of the cross-section after a
/// `--relax-cut`: that cut removes whole tetrahedra, so the fresh face is
/// as jagged as the mesh until its vertices are pulled toward the plane.
pub(crate) const CUT_RELAX_SWEEPS: usize = 20;

/// What a run made: the solved objects and what the summary reports.
struct Solved {
    objects: Vec<Object>,
    lights: Vec<Light>,
    unit_mm: f64,
    levels: usize,
    /// The solver each object's solve chose, and why.
    choices: Vec<tet_diffusion::Choice>,
    painted: Vec<usize>,
    /// The nodes dropped from the file's mesh, to write the VTU back in
    /// its numbering.
    dropped: Option<trilux::tet::DroppedNodes>,
}

pub(crate) fn run(context: &mut Context, args: Args) -> Result<()> {
    #[cfg(feature = "view")]
    if let Some(path) = &args.session {
        return run_session(context, &args, path);
    }
    let input = args
        .input
        .as_deref()
        .ok_or_else(|| super::usage("a MESH (or --session) is required"))?;
    check_outputs(context, &args)?;
    if let Some(path) = &args.envmap {
        super::check_input(path)?;
    }
    check_volume(input, "diffuse", false)?;
    let (positions, tets, dropped) = read_volume(context, input, false, args.envelope)?;
    let mesh = tet_diffusion::TetMesh::new(&positions, &tets).map_err(|e| file_cause(input, e))?;
    let diagonal = diagonal(&positions);
    let unit_mm = unit_mm(args.unit_mm, diagonal);
    let media = args
        .material
        .media(&mesh, diagonal / 6.0)
        .map_err(|e| arg_cause(format!("--material {}", args.material), e))?;
    let mut object = context
        .step("assembling", || Object::new(mesh, unit_mm, media, 1.3))
        .map_err(|e| file_cause(input, e))?;
    let lights = light(context, &args, input, &mut object)?;
    let painted = paint(&args, &mut object)?;
    cut(context, &args, &mut object)?;
    let mut objects = context.step("fracturing", || fracture(&args, object, diagonal))?;
    let mut levels = None;
    let mut choices = Vec::with_capacity(objects.len());
    for o in &mut objects {
        o.settings.method = args.solver.method();
        let report = context
            .step("solving", || o.solve())
            .map_err(|e| file_cause(input, super::placed("the solve failed", false, e)))?;
        levels.get_or_insert(report.levels);
        choices.push(report.choice);
    }
    let solved = Solved {
        objects,
        lights,
        unit_mm,
        levels: levels.unwrap_or(0),
        choices,
        painted,
        dropped,
    };
    let files = write(context, &args, &solved)?;
    report(context, &args, input, &solved, &files);
    Ok(())
}

/// `--paint`: the sides of planes first, then the balls, each in the
/// order given; returns the tetrahedra each painted.
fn paint(args: &Args, object: &mut Object) -> Result<Vec<usize>> {
    let mut painted = vec![0; args.paint.len()];
    for balls in [false, true] {
        for (spec, count) in args.paint.iter().zip(&mut painted) {
            let report = match (&spec.paint, balls) {
                (
                    Paint::Side {
                        point,
                        normal,
                        medium,
                    },
                    false,
                ) => object.paint_half_space(*point, *normal, *medium),
                (Paint::Ball(stroke), true) => object.paint(stroke),
                _ => continue,
            }
            .map_err(|e| arg_cause(format!("--paint {}", spec.spec), e))?;
            *count = report.tets;
        }
    }
    Ok(painted)
}

/// `--session`: the view's session replayed, and its picture (and EXR,
/// VTU, glTF) written as the page's exports write them — byte for byte.
#[cfg(feature = "view")]
fn run_session(context: &mut Context, args: &Args, path: &Path) -> Result<()> {
    check_outputs(context, args)?;
    super::check_input(path)?;
    let (session, saved) = super::view::replayed(context, path)?;
    // --view, else the camera the page saved the session with.
    let view = args.picture.direction().or(saved.map(|v| v.as_vec3()));
    let size = args.picture.size;
    let force = context.force;
    let picture = context.step("rendering", || {
        trilux::tet::render_session(&session, size, view)
    });
    super::view::write_picture(&picture, true, &args.output, force)?;
    let mut files = vec![args.output.clone()];
    if let Some(p) = &args.exr {
        super::view::write_picture(&picture, false, p, force)?;
        files.push(p.clone());
    }
    if let Some(p) = &args.vtu {
        super::view::write_vtu(&session, p, force)?;
        files.push(p.clone());
    }
    if let Some(p) = &args.glb {
        files.extend(write_glb(p, session.pieces(), &picture, force)?);
    }
    let pieces = session.pieces();
    let tets: usize = pieces.iter().map(|o| o.mesh().tets().len()).sum();
    let edits = session.log().edits.len();
    let text = format!(
        "{tets} tetrahedra ({} object{}), session {} replayed ({edits} edits); written to {}\n",
        pieces.len(),
        if pieces.len() > 1 { "s" } else { "" },
        path.display(),
        listed(&files)
    );
    let json = serde_json::json!({
        "command": "diffuse",
        "session": super::shown(path),
        "edits": edits,
        "tetrahedra": tets,
        "objects": pieces.len(),
        "output": super::shown(&args.output),
        "files": shown_all(&files),
        "seconds": context.timings_json(),
    });
    context.report(&text, json);
    Ok(())
}

/// The outputs' names, before any long step.
fn check_outputs(context: &Context, args: &Args) -> Result<()> {
    super::check_output(context, "-o", &args.output, &["png"])?;
    if let Some(p) = &args.exr {
        super::check_output(context, "--exr", p, &["exr"])?;
    }
    if let Some(p) = &args.vtu {
        super::check_output(context, "--vtu", p, &["vtu"])?;
    }
    if let Some(p) = &args.glb {
        // A .gltf's .bin beside it too.
        super::check_output(context, "--glb", p, &["glb", "gltf"])?;
    }
    Ok(())
}

/// `--glb`: the pieces' surfaces with their radiance, the vertex colours
/// at the exposure of `picture` (the PNG written beside it), as the
/// view's export writes them; returns the files written (a `.gltf` and
/// its `.bin`, or the `.glb`).
fn write_glb(
    path: &Path,
    objects: &[Object],
    picture: &trilux::tet::Picture,
    force: bool,
) -> Result<Vec<PathBuf>> {
    let white = trilux::tet::exposure_white(picture);
    trilux::tet::write_radiance_gltf(path, objects, white, force)
}

/// The files as the summary line lists them.
fn listed(files: &[PathBuf]) -> String {
    files
        .iter()
        .map(|f| f.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The files as the JSON lists them.
fn shown_all(files: &[PathBuf]) -> Vec<String> {
    files.iter().map(|f| super::shown(f)).collect()
}

/// Adds the lights (the default one when none is given) and the
/// environment map to `object`; returns the lights the renderer shades
/// with.
fn light(
    context: &mut Context,
    args: &Args,
    input: &Path,
    object: &mut Object,
) -> Result<Vec<Light>> {
    let mut lights: Vec<Light> = args.light.iter().map(|l| l.light.clone()).collect();
    if lights.is_empty() && args.envmap.is_none() {
        lights.push(default_light());
    }
    for (k, light) in lights.iter().enumerate() {
        object
            .add_light(light.clone())
            .map_err(|e| match args.light.get(k) {
                Some(spec) => arg_cause(format!("--light {}", spec.spec), e),
                None => file_cause(input, e),
            })?;
    }
    if let Some(path) = &args.envmap {
        let image = super::read_image(context, path, false)?;
        let rgb: Vec<[f32; 3]> = image.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
        let env =
            tet_diffusion::Environment::new(&rgb, image.width as usize, image.height as usize, 256)
                .map_err(|e| file_cause(path, e))?;
        object
            .add_light(Light::Environment(Arc::new(env)))
            .map_err(|e| file_cause(path, e))?;
    }
    Ok(lights)
}

/// The `--cut`s, in order.
fn cut(context: &mut Context, args: &Args, object: &mut Object) -> Result<()> {
    let method = if args.relax_cut {
        CutMethod::Relax {
            sweeps: CUT_RELAX_SWEEPS,
        }
    } else {
        CutMethod::Exact
    };
    for plane in &args.cut {
        let cut = Cut::Plane {
            point: plane.point,
            normal: plane.normal,
        };
        let before = object.mesh().tets().len();
        let report = context
            .step("cutting", || object.cut(&cut, method))
            .map_err(|e| arg_cause(format!("--cut {}", plane.spec), e))?;
        // A plane outside the object is legal but almost always a slip
        // (metres vs millimetres, the sign of d): say so instead of
        // rendering the whole object as if the cut had worked.
        if report.removed_tets == 0 && report.split_tets == 0 && report.moved_vertices == 0 {
            eprintln!(
                "warning: --cut {}: the plane misses the object (all {before} tetrahedra are on \
                 the kept side n·x ≤ d); nothing was cut",
                plane.spec
            );
        }
    }
    Ok(())
}

/// The object, or its two pieces after `--fracture` (the second moved
/// apart along the plane's normal).
fn fracture(args: &Args, object: Object, diagonal: f64) -> Result<Vec<Object>> {
    let Some(plane) = &args.fracture else {
        return Ok(vec![object]);
    };
    let [a, mut b] = object
        .fracture(plane.point, plane.normal)
        .map_err(|e| arg_cause(format!("--fracture {}", plane.spec), e))?;
    b.set_transform(glam::DAffine3::from_translation(
        plane.normal * diagonal * 0.15,
    ));
    Ok(vec![a, b])
}

/// The picture, and the EXR, VTU and glTF when asked for; returns the
/// files written, in that order.
fn write(context: &mut Context, args: &Args, solved: &Solved) -> Result<Vec<PathBuf>> {
    let image = context.step("rendering", || {
        render(
            &solved.objects,
            &solved.lights,
            args.picture.size,
            args.picture.direction(),
        )
    });
    super::write_image(context, &args.output, &tone_map(&image))?;
    let mut files = vec![args.output.clone()];
    if let Some(p) = &args.exr {
        super::write_image(context, p, &image.image)?;
        files.push(p.clone());
    }
    if let Some(p) = &args.vtu {
        write_vtu(context, p, &solved.objects[0], solved.dropped.as_ref())?;
        files.push(p.clone());
    }
    if let Some(p) = &args.glb {
        files.extend(write_glb(p, &solved.objects, &image, context.force)?);
    }
    Ok(files)
}

/// φ per colour channel and the boundary's luminance per node of `o`.
fn write_vtu(
    context: &Context,
    path: &Path,
    o: &Object,
    dropped: Option<&trilux::tet::DroppedNodes>,
) -> Result<()> {
    use trilux_io::tet::vtu::{Encoding, Field};
    let m = o.mesh();
    let radiance = o.radiance(None);
    let mut lum = vec![0.0; m.vertex_count()];
    for (k, &v) in m.boundary_vertices().iter().enumerate() {
        let l = radiance[k];
        lum[v as usize] = 0.2126 * l[0] + 0.7152 * l[1] + 0.0722 * l[2];
    }
    let mut values = [o.phi(0).to_vec(), o.phi(1).to_vec(), o.phi(2).to_vec(), lum];
    // The file's own nodes and numbering when nodes were dropped and the
    // object is still the file's mesh (no cut or fracture moved them).
    let io_mesh = match dropped {
        Some(d) if d.is_solved(m.positions()) => {
            values = values.map(|v| d.scatter(&v));
            d.original.clone()
        }
        _ => trilux_io::tet::TetMesh {
            positions: m.positions().to_vec(),
            tets: m.tets().to_vec(),
            ..Default::default()
        },
    };
    let [phi_r, phi_g, phi_b, lum] = &values;
    let field = |name, values| Field { name, values };
    let fields = [
        field("phi_r", phi_r),
        field("phi_g", phi_g),
        field("phi_b", phi_b),
        field("radiance", lum),
    ];
    trilux::output::write_atomic(path, context.force, |tmp| {
        Ok(trilux_io::tet::vtu::write(
            tmp,
            &io_mesh,
            &fields,
            &[],
            Encoding::Base64,
        )?)
    })
}

/// The solvers that ran, once each in order ("Jacobi-PCG", or
/// "Jacobi-PCG, V-cycle-PCG" when the pieces of a fracture differ).
fn solvers(choices: &[tet_diffusion::Choice]) -> String {
    let mut names: Vec<String> = Vec::new();
    for c in choices {
        let name = c.solver.to_string();
        if !names.contains(&name) {
            names.push(name);
        }
    }
    names.join(", ")
}

/// The summary line, or the JSON object; `files` are every file written.
fn report(context: &Context, args: &Args, input: &Path, solved: &Solved, files: &[PathBuf]) {
    let objects = &solved.objects;
    let tets: usize = objects.iter().map(|o| o.mesh().tets().len()).sum();
    let painted = &solved.painted;
    let text = format!(
        "{} tetrahedra ({} object{}), {} mm per unit{}, solved by {}{}; written to {}\n",
        tets,
        objects.len(),
        if objects.len() > 1 { "s" } else { "" },
        solved.unit_mm,
        if painted.is_empty() {
            String::new()
        } else {
            format!(
                ", painted {} tetrahedra",
                painted
                    .iter()
                    .map(usize::to_string)
                    .collect::<Vec<_>>()
                    .join(" + ")
            )
        },
        solvers(&solved.choices),
        if solved.levels > 1 {
            format!(" ({} levels)", solved.levels)
        } else {
            String::new()
        },
        listed(files)
    );
    let json = serde_json::json!({
        "command": "diffuse",
        "input": super::shown(input),
        "tetrahedra": tets,
        "objects": objects.len(),
        "unit_mm": solved.unit_mm,
        "envelope": args.envelope,
        "material": args.material.spec,
        "paint": args
            .paint
            .iter()
            .zip(painted)
            .map(|(spec, n)| serde_json::json!({"spec": spec.spec, "tetrahedra": n}))
            .collect::<Vec<_>>(),
        "output": super::shown(&args.output),
        "files": shown_all(files),
        "solver": solvers(&solved.choices),
        "solver_choice": solved.choices.iter().map(ToString::to_string).collect::<Vec<_>>(),
        "seconds": context.timings_json(),
    });
    context.report(&text, json);
}

// The picture is drawn by the library (the Python package renders with
// it too); the names stay here for the demo and the tests below.
#[cfg(test)]
use glam::Vec3;
#[cfg(test)]
use trilux::tet::{Picture, exposure_white};
pub(crate) use trilux::tet::{render, tone_map};

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use tet_diffusion::Medium;
    use tet_diffusion::TetMesh;
    use tet_diffusion::fresnel::exit_radiance_factor;

    /// A ball of radius 1 of `6 n³` tets: the cube lattice of `[-1, 1]³`
    /// mapped radially, so that the boundary vertices lie on the sphere.
    fn ball(n: usize) -> TetMesh {
        let m = n + 1;
        let id = |i: usize, j: usize, k: usize| (i + m * (j + m * k)) as u32;
        let mut p = Vec::new();
        for k in 0..m {
            for j in 0..m {
                for i in 0..m {
                    let x = DVec3::new(i as f64, j as f64, k as f64) * (2.0 / n as f64) - 1.0;
                    let l = x.length();
                    p.push(if l == 0.0 {
                        x
                    } else {
                        x * (x.abs().max_element() / l)
                    });
                }
            }
        }
        let mut tets = Vec::new();
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let c = |d: usize| id(i + (d & 1), j + (d >> 1 & 1), k + (d >> 2));
                    for [a, b] in [[1, 3], [3, 2], [2, 6], [6, 4], [4, 5], [5, 1]] {
                        tets.push([c(0), c(a), c(b), c(7)]);
                    }
                }
            }
        }
        TetMesh::new(&p, &tets).unwrap()
    }

    fn marble(eta: f64) -> Object {
        Object::homogeneous(ball(16), 10.0, Medium::measured("marble").unwrap(), eta).unwrap()
    }

    /// The direction through the centre of pixel `(x, y)` of a square
    /// picture from `camera` (the renderer's projection, inverted).
    fn ray(camera: &trilux::preview::Camera, x: u32, y: u32, size: u32) -> Vec3 {
        let f = (camera.target - camera.eye).normalize();
        let s = f.cross(camera.up).normalize();
        let u = s.cross(f);
        let t = (camera.fov_y * 0.5).tan();
        let ndc_x = 2.0 * (x as f32 + 0.5) / size as f32 - 1.0;
        let ndc_y = 1.0 - 2.0 * (y as f32 + 0.5) / size as f32;
        (f + s * (ndc_x * t) + u * (ndc_y * t)).normalize()
    }

    #[test]
    fn fresnel_follows_each_pixels_direction_to_the_eye() {
        // A uniform J⁺ on a sphere seen in perspective: every pixel must
        // be J⁺ F_t(n·v)/(π η²) with v from that point to the eye, which
        // differs from F_t at the camera's central direction by far more
        // than the tolerance toward the limb.
        let eta = 1.3;
        let mut o = marble(eta);
        let n = o.mesh().vertex_count();
        o.set_phi([vec![1.0; n], vec![1.0; n], vec![1.0; n]])
            .unwrap();
        let j = o.boundary_flux()[0][0];
        assert!(o.boundary_flux().iter().all(|f| (f[0] - j).abs() < 1e-12));
        let size = 160;
        let from = Vec3::new(0.2, 0.3, 1.0);
        let picture = render(std::slice::from_ref(&o), &[], size, Some(from));
        let all: Vec<Vec3> = o.mesh().positions().iter().map(|p| p.as_vec3()).collect();
        let (lo, hi) = trilux::preview::bounds(&all).unwrap();
        let camera = trilux::preview::Camera::fit_from(lo, hi, from);
        let central = (camera.eye - camera.target).normalize();
        let (mut worst, mut worst_central, mut checked) = (0.0f64, 0.0f64, 0);
        for y in 0..size {
            for x in 0..size {
                let i = (y * size + x) as usize;
                if picture.coverage[i] < 1.0 {
                    continue;
                }
                // The ray's first hit on the unit sphere.
                let d = ray(&camera, x, y, size);
                let e = camera.eye;
                let b = e.dot(d);
                let disc = b * b - (e.length_squared() - 1.0);
                if disc <= 0.0 {
                    continue;
                }
                let p = e + d * (-b - disc.sqrt());
                let normal = p.normalize();
                let cos = normal.dot(-d);
                if cos < 0.3 {
                    continue; // the faceted limb
                }
                let expected = j * exit_radiance_factor(f64::from(cos), eta);
                let at_centre = j * exit_radiance_factor(f64::from(normal.dot(central)), eta);
                let got = f64::from(picture.image.pixels[i][0]);
                worst = worst.max((got / expected - 1.0).abs());
                worst_central = worst_central.max((at_centre / expected - 1.0).abs());
                checked += 1;
            }
        }
        eprintln!(
            "{checked} pixels: largest error {worst:.4}; F_t at the central direction would be off by {worst_central:.4}"
        );
        // The residue is the faceted sphere (its normals and hit points
        // are not the analytic ones); the central direction is 3× off that.
        assert!(checked > 4_000, "{checked}");
        assert!(worst < 0.025, "{worst}");
        assert!(worst_central > 0.08, "{worst_central}");
    }

    /// `o` lit by one directional light from `to_light`, solved.
    fn lit(mut o: Object, to_light: DVec3, irradiance: f64) -> (Object, Light) {
        let light = Light::Directional {
            to_light,
            irradiance: [irradiance; 3],
        };
        o.add_light(light.clone()).unwrap();
        o.settings.tolerance = 1e-8;
        o.solve().unwrap();
        (o, light)
    }

    /// The 99th-percentile luminance of the tone-mapped picture's fully
    /// covered pixels.
    fn shown_white(picture: &Picture) -> f32 {
        let shown = tone_map(picture);
        let mut lum: Vec<f32> = shown
            .pixels
            .iter()
            .zip(&picture.coverage)
            .filter(|&(_, &c)| c >= 1.0)
            .map(|(p, _)| discrete_sampling::luminance([p[0], p[1], p[2]]))
            .collect();
        lum.sort_by(f32::total_cmp);
        lum[lum.len() * 99 / 100]
    }

    #[test]
    fn a_dim_back_lit_object_is_exposed_like_a_bright_one_over_the_same_background() {
        let view = Vec3::Z;
        let (front, l0) = lit(marble(1.3), DVec3::new(0.2, 0.3, 1.0), 1.0);
        let (back, l1) = lit(marble(1.3), DVec3::new(0.1, 0.2, -1.0), 1e-3);
        let size = 96;
        let bright = render(std::slice::from_ref(&front), &[l0], size, Some(view));
        let dim = render(std::slice::from_ref(&back), &[l1], size, Some(view));
        // The back-lit ball is far dimmer in radiance ...
        assert!(exposure_white(&dim) < 1e-3 * exposure_white(&bright));
        // ... yet its brightest percent is shown as white, as the lit one's.
        for p in [&bright, &dim] {
            let w = shown_white(p);
            assert!((w - 1.0).abs() < 0.02, "{w}");
        }
        // The background is left alone, bit for bit, whatever the exposure.
        let empty = render(&[], &[], size, Some(view)).image;
        let (a, b) = (tone_map(&bright), tone_map(&dim));
        let mut background = 0;
        for i in 0..a.pixels.len() {
            if bright.coverage[i] == 0.0 && dim.coverage[i] == 0.0 {
                assert_eq!(a.pixels[i], b.pixels[i]);
                assert_eq!(a.pixels[i], empty.pixels[i]);
                background += 1;
            }
        }
        assert!(background > a.pixels.len() / 3, "{background}");
    }
}
