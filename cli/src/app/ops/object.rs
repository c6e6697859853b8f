//! A translucent object from a file: tetrahedra as read, or a closed
//! surface stuffed first (`diffuse`, `view`).

use std::path::Path;

use glam::DVec3;

use super::stuff::{Spacing, stuff};
use crate::app::{Context, Result, file_error};

/// The extensions read as tetrahedra; `vtu` only where `with_vtu`.
fn tet_extensions(with_vtu: bool) -> &'static [&'static str] {
    if with_vtu {
        &["node", "ele", "msh", "mesh", "vtu"]
    } else {
        &["node", "ele", "msh", "mesh"]
    }
}

/// The surfaces that are stuffed first.
const SURFACES: [&str; 4] = ["obj", "gltf", "glb", "ply"];

/// Checks that `subcommand` reads `input` (by its extension) before any
/// long step.
pub(crate) fn check_volume(input: &Path, subcommand: &str, with_vtu: bool) -> Result<()> {
    let ext = crate::app::extension(input);
    let tets = tet_extensions(with_vtu);
    if tets.contains(&ext.as_str()) || SURFACES.contains(&ext.as_str()) {
        return Ok(());
    }
    let dotted = |list: &[&str]| {
        list.iter()
            .map(|e| format!(".{e}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    Err(file_error(
        input,
        if with_vtu {
            format!(
                "{ext:?} is not read here: {subcommand} takes tetrahedra ({}) or a surface ({})",
                dotted(tets),
                dotted(&SURFACES)
            )
        } else {
            format!(
                "{ext:?} is not read here: {subcommand} takes tetrahedra ({}) or \
                 a surface to fill ({})",
                dotted(tets),
                dotted(&SURFACES)
            )
        },
    ))
}

/// What [`read_volume`] returns: positions, tetrahedra, and the nodes
/// dropped from the file's mesh (`None` when none were, or for a surface).
pub(crate) type Volume = (Vec<DVec3>, Vec<[u32; 4]>, Option<trilux::tet::DroppedNodes>);

/// The positions and tetrahedra of `input`: read (without the nodes no
/// tetrahedron uses, which are returned for writing results back), or
/// stuffed from a surface at the default spacing, its boundary fitted to
/// the surface when `envelope` is given (`trilux tetra --envelope`; then
/// the distance reached is said on stderr). [`check_volume`] said it is
/// read here.
pub(crate) fn read_volume(
    context: &mut Context,
    input: &Path,
    with_vtu: bool,
    envelope: Option<f64>,
) -> Result<Volume> {
    let ext = crate::app::extension(input);
    if tet_extensions(with_vtu).contains(&ext.as_str()) {
        if let Some(eps) = envelope {
            return Err(crate::app::arg_error(
                format!("--envelope {}", super::stuff::number(eps)),
                format!(
                    "{} is already tetrahedral; the envelope fits the tetrahedra of a surface \
                     (.obj, .gltf, .glb, .ply) to it",
                    input.display()
                ),
            ));
        }
        // Nodes no tetrahedron uses (TetGen and meshio files keep them)
        // would be empty rows of the solver's system: dropped, said.
        let (tet, dropped) = trilux::tet::drop_unused_nodes(crate::app::read_tets(context, input)?);
        if let Some(d) = &dropped {
            eprintln!("warning: {}", d.warning(input));
        }
        return Ok((tet.positions, tet.tets, dropped));
    }
    let surface = crate::app::read_mesh(context, input)?;
    // The help asks for a closed surface; an open one is stuffed all the
    // same (inside by the winding number), which may or may not be what
    // the user meant: said, not silent.
    let shape = trilux::mesh::shape(&surface);
    if shape.boundary_edges > 0 {
        eprintln!("warning: {}", open_surface(input, &shape));
    }
    let (stuffed, _) = context.step("tetrahedralizing", || {
        stuff(
            &surface,
            input,
            Spacing::Default,
            false,
            envelope.is_some(),
            envelope,
        )
    })?;
    if let (Some(eps), Some(d)) = (envelope, &stuffed.report.distance) {
        let reached = if d.hausdorff_fraction() <= eps {
            "within"
        } else {
            "NOT within"
        };
        eprintln!(
            "note: {}: the tetrahedra's boundary lies within {:.3}% of the diagonal of the surface \
             (Hausdorff), {reached} the {}% envelope; dihedral angles {:.2}°..{:.2}°",
            input.display(),
            100.0 * d.hausdorff_fraction(),
            super::stuff::number(100.0 * eps),
            stuffed.report.min_dihedral_deg,
            stuffed.report.max_dihedral_deg
        );
    }
    let out = trilux::tet::from_stuffing(&stuffed, surface.origin);
    Ok((out.positions, out.tets, None))
}

/// The warning for a surface with holes that is tetrahedralized anyway.
fn open_surface(input: &Path, shape: &trilux::mesh::Shape) -> String {
    let plural =
        |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
    format!(
        "{}: not a closed surface ({}, {}); its inside is guessed from the \
         winding number: check the result, or tetrahedralize it yourself with \
         `trilux tetra {} --spacing S -o OUT.node` and pass OUT.node",
        input.display(),
        plural(shape.holes, "hole", "holes"),
        plural(shape.boundary_edges, "boundary edge", "boundary edges"),
        input.display(),
    )
}

/// The length of the bounding box's diagonal.
pub(crate) fn diagonal(positions: &[DVec3]) -> f64 {
    let (lo, hi) = positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &p| {
            (a.min(p), b.max(p))
        });
    (hi - lo).length()
}

/// Millimetres per mesh unit: `given`, else 1000 when the diagonal is
/// under 5 units (scans in metres), 1 otherwise.
pub(crate) fn unit_mm(given: Option<f64>, diagonal: f64) -> f64 {
    given.unwrap_or(if diagonal < 5.0 { 1000.0 } else { 1.0 })
}

/// The light of a scene given none: from the upper front.
pub(crate) fn default_light() -> tet_diffusion::Light {
    tet_diffusion::Light::Directional {
        to_light: DVec3::new(0.4, 1.0, 0.7),
        irradiance: [1.0; 3],
    }
}
