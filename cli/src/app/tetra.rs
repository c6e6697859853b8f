//! `trilux tetra`: a closed surface to tetrahedra by isosurface stuffing
//! (the algorithm is `tet_stuffing`).

use std::path::PathBuf;

use super::Context;
use super::Result;
use super::ops::stuff::{Spacing, number, stuff};

#[derive(Debug, clap::Args)]
#[command(
    about = "Tetrahedralize a surface by isosurface stuffing (bounded dihedral angles); writes TetGen, MEDIT or VTU",
    after_help = "Examples:\n  trilux tetra ../shared/data/meshes/stanford-bunny.obj --spacing 0.003 -o bunny.node --preview bunny_tets.png\n  trilux tetra ../shared/data/meshes/stanford-bunny.obj -o bunny.node --glb bunny_boundary.glb"
)]
pub(crate) struct Args {
    /// The surface: .obj, .gltf, .glb or .ply (holes and overlaps are fine:
    /// inside is decided by the generalized winding number).
    pub(crate) surface: PathBuf,
    /// Lattice spacing in the mesh's unit (default: 1/40 of the bounding
    /// box's diagonal).
    #[arg(long, value_name = "H")]
    pub(crate) spacing: Option<f64>,
    /// The old name of --spacing (`--size` is a picture's pixels in the
    /// other subcommands); accepted with a deprecation note on stderr.
    #[arg(long, value_name = "H", hide = true, conflicts_with = "spacing")]
    pub(crate) size: Option<f64>,
    /// Coarser tetrahedra deep inside (octree grading).
    #[arg(long)]
    pub(crate) graded: bool,
    /// Fit the boundary to the surface: move boundary vertices onto tips,
    /// creases and thin parts farther than EPS (a fraction of the bounding
    /// box's diagonal, e.g. 0.002) from it, splitting boundary edges where
    /// moves are not enough (at most 3x the tetrahedra), keeping every
    /// dihedral angle at 10° or more. Not a guarantee: the summary prints
    /// the distance reached.
    #[arg(long, value_name = "EPS", allow_negative_numbers = true)]
    pub(crate) envelope: Option<f64>,
    /// The tetrahedral mesh: .node (with .ele), .mesh or .vtu.
    #[arg(short, long, value_name = "OUT.node")]
    pub(crate) output: PathBuf,
    /// Also render the boundary to a PNG.
    #[arg(long, value_name = "OUT.png")]
    pub(crate) preview: Option<PathBuf>,
    /// Also write the boundary of the tetrahedra (a closed surface,
    /// triangles facing out) as glTF: .glb, or .gltf with a .bin beside it.
    #[arg(long, value_name = "OUT.glb")]
    pub(crate) glb: Option<PathBuf>,
}

pub(crate) fn run(context: &mut Context, args: Args) -> Result<()> {
    super::check_output(context, "-o", &args.output, &["node", "ele", "mesh", "vtu"])?;
    if let Some(p) = &args.preview {
        super::check_output(context, "--preview", p, &["png", "exr"])?;
    }
    if let Some(p) = &args.glb {
        super::check_output(context, "--glb", p, &["glb", "gltf"])?;
    }
    let spacing = match (args.spacing, args.size) {
        (None, Some(h)) => {
            eprintln!(
                "warning: `trilux tetra --size` is deprecated, use --spacing (--size is a picture's pixels in the other subcommands)"
            );
            Spacing::Given {
                h: Some(h),
                option: "--size",
            }
        }
        (h, _) => Spacing::Given {
            h,
            option: "--spacing",
        },
    };
    let mesh = super::read_mesh(context, &args.surface)?;
    let (tets, h) = context.step("stuffing", || {
        stuff(
            &mesh,
            &args.surface,
            spacing,
            args.graded,
            true,
            args.envelope,
        )
    })?;
    let out = trilux::tet::from_stuffing(&tets, mesh.origin);
    let force = context.force;
    let mut files = context.step("writing", || {
        trilux::output::write_atomic_files(&args.output, force, |tmp| {
            Ok(trilux_io::tet::write(tmp, &out)?)
        })
    })?;
    let surface = (args.preview.is_some() || args.glb.is_some())
        .then(|| context.step("finding the boundary", || trilux::tet::surface(&out)));
    if let (Some(p), Some(surface)) = (&args.glb, &surface) {
        files.extend(context.step("writing the boundary", || {
            trilux::output::write_gltf(p, force, |tmp| trilux_io::mesh::gltf::write(tmp, surface))
        })?);
    }
    if let (Some(p), Some(surface)) = (&args.preview, &surface) {
        let image = context.step("rendering the preview", || {
            trilux::preview::render_mesh(&surface.positions, &surface.indices, 768, 768)
        });
        super::write_image(context, p, &image)?;
        files.push(p.clone());
    }
    // The writer's list follows the folder's order; show a stable one.
    files.sort();
    let r = &tets.report;
    if let Some(d) = r.distance.as_ref().filter(|d| d.left_out_triangles > 0) {
        eprintln!(
            "warning: {}: {} triangles ({:.2}% of the area) enclose no volume (open sheets or fins by the winding number) and are left out of the tetrahedra",
            args.surface.display(),
            d.left_out_triangles,
            100.0 * d.left_out_area
        );
    }
    let diagonal = trilux::mesh::bounds(&mesh)
        .map(|(lo, hi)| (hi.as_dvec3() - lo.as_dvec3()).length())
        .unwrap_or(0.0);
    // What the options guarantee, beside what this surface got.
    let bound = r.dihedral_bounds_deg;
    let text = format!(
        "{} tetrahedra, {} vertices, {} boundary triangles at spacing {}{}{} in {:.2} s; dihedral angles {:.2}° .. {:.2}° (within {}°–{}° on any surface){}; written to {}\n",
        r.tets,
        r.vertices,
        r.boundary_triangles,
        spacing_text(h, diagonal),
        if args.graded { " (graded)" } else { "" },
        args.envelope
            .map(|eps| format!(
                ", fitted to an envelope of {}% of the diagonal ({} boundary vertices moved, {} edges split, {} creases)",
                significant(100.0 * eps),
                r.fitted_vertices,
                r.split_edges,
                r.sharp_edges
            ))
            .unwrap_or_default(),
        r.elapsed.as_secs_f64(),
        r.min_dihedral_deg,
        r.max_dihedral_deg,
        bound.0,
        bound.1,
        r.distance
            .as_ref()
            .map(|d| distance_text(d, args.envelope))
            .unwrap_or_default(),
        files
            .iter()
            .map(|f| f.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let json = serde_json::json!({
        "command": "tetra",
        "surface": super::shown(&args.surface),
        "tetrahedra": r.tets,
        "vertices": r.vertices,
        "boundary_triangles": r.boundary_triangles,
        "spacing": h,
        "diagonal": diagonal,
        "graded": args.graded,
        "envelope": args.envelope,
        "fitted_vertices": r.fitted_vertices,
        "sharp_edges": r.sharp_edges,
        "split_edges": r.split_edges,
        "dihedral_degrees": [r.min_dihedral_deg, r.max_dihedral_deg],
        // The bound any surface gets with these options.
        "dihedral_bound_degrees": [bound.0, bound.1],
        "distance": r.distance.as_ref().map(distance_json),
        // Whether the measured distance is within the envelope asked for.
        "envelope_reached": args.envelope.zip(r.distance.as_ref()).map(|(eps, d)| d.hausdorff_fraction() <= eps),
        "stuffing_seconds": r.elapsed.as_secs_f64(),
        "files": files.iter().map(|f| super::shown(f)).collect::<Vec<_>>(),
        "seconds": context.timings_json(),
    });
    context.report(&text, json);
    Ok(())
}

/// The spacing in the mesh's unit to 4 significant digits, and as a share
/// of the bounding box's diagonal (which the default spacing is 1/40 of).
fn spacing_text(h: f64, diagonal: f64) -> String {
    if diagonal > 0.0 && diagonal.is_finite() {
        format!(
            "{} (1/{} of the diagonal, {})",
            significant(h),
            significant(diagonal / h),
            significant(diagonal)
        )
    } else {
        significant(h)
    }
}

/// `x` to 4 significant digits, in plain notation between 10⁻⁴ and 10⁷.
fn significant(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return number(x);
    }
    if (1e-4..1e7).contains(&x.abs()) {
        let decimals = (3 - x.abs().log10().floor() as i32).max(0) as usize;
        let text = format!("{x:.decimals$}");
        // 0.002500 -> 0.0025, 40.00 -> 40.
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    } else {
        format!("{x:.3e}")
    }
}

/// The summary's clause on how far the boundary lies from the surface.
fn distance_text(d: &tet_stuffing::SurfaceDistance, envelope: Option<f64>) -> String {
    // Caps over the surface's holes are measured apart: their distance is
    // the hole's size, not the mesh's error.
    let caps = if d.hole_caps > 0.0 {
        format!(
            "; not counted: {:.1}% of the boundary closes holes of the surface, up to {:.3}% from it",
            100.0 * d.hole_caps,
            100.0 * d.hole_caps_to_input / d.diagonal.max(f64::MIN_POSITIVE)
        )
    } else {
        String::new()
    };
    // Say plainly whether the envelope asked for was reached.
    let verdict = match envelope {
        Some(eps) if d.hausdorff_fraction() <= eps => ", within the envelope".to_string(),
        Some(eps) => format!(
            ", NOT within the {}% envelope (parts about a spacing thick; a smaller --spacing helps)",
            significant(100.0 * eps)
        ),
        None => String::new(),
    };
    format!(
        "; boundary within {:.3}% of the diagonal of the surface{verdict} (Hausdorff; mean {:.3}%; {} + {} points measured{caps})",
        100.0 * d.hausdorff_fraction(),
        100.0 * d.mean_fraction(),
        d.input_samples,
        d.boundary_samples
    )
}

/// `--json`'s `distance`: lengths in the surface's unit, fractions of its
/// bounding box's diagonal.
fn distance_json(d: &tet_stuffing::SurfaceDistance) -> serde_json::Value {
    serde_json::json!({
        "hausdorff": d.hausdorff,
        "hausdorff_fraction": d.hausdorff_fraction(),
        "mean": d.mean,
        "mean_fraction": d.mean_fraction(),
        "input_to_tets": d.input_to_tets,
        "tets_to_input": d.tets_to_input,
        "diagonal": d.diagonal,
        "input_points": d.input_samples,
        "boundary_points": d.boundary_samples,
        "left_out_triangles": d.left_out_triangles,
        "left_out_area_fraction": d.left_out_area,
        "hole_caps_fraction": d.hole_caps,
        "hole_caps_to_input": d.hole_caps_to_input,
    })
}
