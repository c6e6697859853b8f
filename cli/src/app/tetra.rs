//! `trilux tetra`: a closed surface to tetrahedra by isosurface stuffing
//! (the algorithm is `tet_diffusion::stuffing`).

use std::path::{Path, PathBuf};

use tet_diffusion::stuffing;
use trilux_io::mesh::TriMesh;

use super::{Context, Result, arg_error, file_error};

#[derive(Debug, clap::Args)]
#[command(
    about = "Tetrahedralize a surface by isosurface stuffing (bounded dihedral angles); writes TetGen, MEDIT or VTU",
    after_help = "Example:\n  trilux tetra ../shared/data/meshes/stanford-bunny.obj --size 0.003 -o bunny.node --preview bunny_tets.png"
)]
pub(crate) struct Args {
    /// The surface: .obj, .gltf, .glb or .ply (holes and overlaps are fine:
    /// inside is decided by the generalized winding number).
    pub(crate) surface: PathBuf,
    /// Lattice spacing in the mesh's unit (default: 1/40 of the bounding
    /// box's diagonal).
    #[arg(long, value_name = "H")]
    pub(crate) size: Option<f64>,
    /// Coarser tetrahedra deep inside (octree grading).
    #[arg(long)]
    pub(crate) graded: bool,
    /// The tetrahedral mesh: .node (with .ele), .mesh or .vtu.
    #[arg(short, long, value_name = "OUT.node")]
    pub(crate) output: PathBuf,
    /// Also render the boundary to a PNG.
    #[arg(long, value_name = "OUT.png")]
    pub(crate) preview: Option<PathBuf>,
}

/// Stuffs `mesh` at spacing `h` (default diagonal / 40).
pub(crate) fn stuff(
    mesh: &TriMesh,
    path: &Path,
    h: Option<f64>,
    graded: bool,
) -> Result<stuffing::TetMesh> {
    let (lo, hi) = trilux::mesh::bounds(mesh).unwrap_or_default();
    let h = h.unwrap_or_else(|| f64::from((hi - lo).length()) / 40.0);
    if !(h.is_finite() && h > 0.0) {
        return Err(arg_error(
            format!("--size {h}"),
            "the lattice spacing must be a positive length",
        ));
    }
    let options = stuffing::Options {
        graded,
        ..stuffing::Options::new(h)
    };
    stuffing::tetrahedralize(&mesh.positions, &mesh.indices, &options).map_err(|e| match e {
        stuffing::Error::EmptyVolume { h } => file_error(
            path,
            format!(
                "the surface encloses nothing at spacing {h} (an open sheet, or thinner than the lattice: try a smaller --size)"
            ),
        ),
        other => file_error(path, other),
    })
}

pub(crate) fn run(context: &mut Context, args: Args) -> Result<()> {
    super::check_output(context, &args.output, &["node", "ele", "mesh", "vtu"])?;
    if let Some(p) = &args.preview {
        super::check_output(context, p, &["png", "exr"])?;
    }
    let mesh = super::read_mesh(context, &args.surface)?;
    let tets = context.step("stuffing", || {
        stuff(&mesh, &args.surface, args.size, args.graded)
    })?;
    let out = trilux::tet::from_stuffing(&tets, mesh.origin);
    let force = context.force;
    let files = context.step("writing", || {
        trilux::output::write_atomic_files(&args.output, force, |tmp| {
            Ok(trilux_io::tet::write(tmp, &out)?)
        })
    })?;
    if let Some(p) = &args.preview {
        let surface = trilux::tet::surface(&out);
        let image = context.step("rendering the preview", || {
            trilux::preview::render_mesh(&surface.positions, &surface.indices, 768, 768)
        });
        super::write_image(context, p, &image)?;
    }
    let r = &tets.report;
    let text = format!(
        "{} tetrahedra, {} vertices, {} boundary triangles in {:.2} s; dihedral angles {:.2}° .. {:.2}°; written to {}\n",
        r.tets,
        r.vertices,
        r.boundary_triangles,
        r.elapsed.as_secs_f64(),
        r.min_dihedral_deg,
        r.max_dihedral_deg,
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
        "dihedral_degrees": [r.min_dihedral_deg, r.max_dihedral_deg],
        "stuffing_seconds": r.elapsed.as_secs_f64(),
        "files": files.iter().map(|f| super::shown(f)).collect::<Vec<_>>(),
        "seconds": context.timings_json(),
    });
    context.report(&text, json);
    Ok(())
}
