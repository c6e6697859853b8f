//! A closed surface to tetrahedra by isosurface stuffing (the algorithm
//! is `tet_stuffing`), with the messages of every subcommand that
//! stuffs: `tetra`, and `diffuse`, `view` and `demo` on a surface.

use std::path::Path;

use tet_stuffing as stuffing;
use trilux_io::mesh::TriMesh;

use crate::app::{Error, Result, arg_error, file_cause, file_error};

/// How the spacing of [`stuff`] is chosen: `--spacing` of `trilux tetra`,
/// or the default of a command without that option (`trilux diffuse`).
#[derive(Clone, Copy)]
pub(crate) enum Spacing {
    /// The option as given (`h`, and `option`, its name as typed, for
    /// errors), or its default when absent.
    Given {
        h: Option<f64>,
        option: &'static str,
    },
    /// Always the default; errors suggest `trilux tetra --spacing`.
    Default,
}

impl Spacing {
    /// The option's name as the messages use it.
    fn option(self) -> &'static str {
        match self {
            Spacing::Given { option, .. } => option,
            Spacing::Default => "--spacing",
        }
    }

    /// What to do about a spacing too fine (`larger`) or too coarse
    /// (`smaller`) for the surface.
    fn fixes(self) -> (String, String) {
        match self {
            Spacing::Default => (
                "tetrahedralize it with `trilux tetra --spacing H` first".to_string(),
                "tetrahedralize it with `trilux tetra --spacing H` and a smaller H first"
                    .to_string(),
            ),
            Spacing::Given { option, .. } => (
                format!("use a larger {option}"),
                format!("try a smaller {option}"),
            ),
        }
    }
}

/// Stuffs `mesh` (read from `path`) at the spacing `spacing` says, by
/// default 1/40 of the bounding box's diagonal; returns the mesh and the
/// spacing used. With `distance`, the report says how far the boundary
/// lies from the surface (`tetra` prints it; a command that goes on to
/// solve skips the cost). `envelope` is `tet_stuffing::Options::envelope`
/// (`trilux tetra --envelope`).
pub(crate) fn stuff(
    mesh: &TriMesh,
    path: &Path,
    spacing: Spacing,
    graded: bool,
    distance: bool,
    envelope: Option<f64>,
) -> Result<(stuffing::TetMesh, f64)> {
    let (h, given) = match spacing {
        Spacing::Given { h: Some(h), .. } => (h, true),
        Spacing::Given { h: None, .. } | Spacing::Default => {
            (trilux::tet::default_spacing(mesh), false)
        }
    };
    let option = spacing.option();
    if !(h.is_finite() && h > 0.0) {
        return Err(if given {
            arg_error(
                format!("{option} {}", number(h)),
                "the lattice spacing must be a positive length",
            )
        } else {
            let (lo, hi) = trilux::mesh::bounds(mesh).unwrap_or_default();
            let fix = match spacing {
                Spacing::Default => spacing.fixes().0,
                Spacing::Given { .. } => format!("give {option}"),
            };
            file_error(
                path,
                format!("no default lattice spacing from bounds {lo} .. {hi}; {fix}"),
            )
        });
    }
    let defaults = stuffing::Options::new(h);
    let options = stuffing::Options {
        graded,
        distance_samples: if distance {
            defaults.distance_samples
        } else {
            0
        },
        envelope,
        ..defaults
    };
    let stuffed = stuffing::tetrahedralize(&mesh.positions, &mesh.indices, &options)
        .map_err(|e| failure(e, path, spacing, h, given))?;
    Ok((stuffed, h))
}

/// The stuffing's error `e` at spacing `h` as a message that says what to
/// change: the argument's when the spacing was `given`, else the file's.
fn failure(e: stuffing::Error, path: &Path, spacing: Spacing, h: f64, given: bool) -> Error {
    let (larger, smaller) = spacing.fixes();
    let too_fine = |problem: String| {
        let problem = format!("too fine for this surface: {problem}; {larger}");
        if given {
            arg_error(format!("{} {}", spacing.option(), number(h)), problem)
        } else {
            file_error(path, problem)
        }
    };
    match e {
        stuffing::Error::EmptyVolume { h } => file_error(
            path,
            format!(
                "the surface encloses nothing at spacing {}: it is thinner than the lattice; \
                 {smaller}",
                number(h)
            ),
        ),
        stuffing::Error::OpenSurface { triangles } => file_error(
            path,
            format!(
                "the surface encloses nothing: none of its {triangles} triangles bounds a volume \
                 (an open sheet or a doubled wall, by the winding number), so no spacing gives \
                 tetrahedra; close the surface or give it thickness"
            ),
        ),
        stuffing::Error::InvalidEnvelope { eps } => arg_error(
            format!("--envelope {}", number(eps)),
            "the envelope is a fraction of the bounding box's diagonal, between 0 and 1 \
             (e.g. 0.002)",
        ),
        stuffing::Error::LatticeTooLarge {
            vertices, limit, ..
        } => too_fine(format!(
            "the lattice would need {} vertices, more than the limit of {limit}",
            if vertices == u128::MAX {
                "more than 10^36".to_string()
            } else {
                vertices.to_string()
            }
        )),
        stuffing::Error::TooManyTetrahedra {
            estimated, limit, ..
        } => too_fine(format!(
            "about {estimated} tetrahedra, more than the limit of {limit}"
        )),
        other => file_cause(path, other),
    }
}

/// A length as a person reads it: plain for everyday values, in
/// scientific notation when tiny or huge (not 300 zeros).
pub(crate) fn number(x: f64) -> String {
    if x == 0.0 || (1e-4..1e7).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}
