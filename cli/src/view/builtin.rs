//! The object `trilux view` opens without a mesh: a marble ball, 40 mm
//! across, with a ketchup core off its centre and a ring of skin inside —
//! invisible from outside, lit through, and revealed by the first cut.

use tet_diffusion::glam::DVec3;
use tet_diffusion::{Error, Light, Medium, Object, TetMesh, kuhn_ball};

/// The direction toward `trilux view`'s default light, in the world frame:
/// normalize(-0.6, 0.6, -0.5) in the frame of the page's starting camera
/// (right, up, away from the viewer) — from above, to the left and in
/// front, so most of what the camera sees is lit and the terminator,
/// where light diffuses into the shadow, crosses the ball. A light from
/// the camera lit the ball evenly (a flat white disc that did not read as
/// translucent); one from behind left most of it black. The page starts
/// with the same direction (`state.lightDir` in app.js).
pub const DEFAULT_LIGHT: [f64; 3] = [-0.351, 0.746, 0.565];

/// `trilux view`'s light when it is given none: directional, from
/// [`DEFAULT_LIGHT`], irradiance 1.
pub fn default_light() -> Light {
    Light::Directional {
        to_light: DVec3::from_array(DEFAULT_LIGHT),
        irradiance: [1.0; 3],
    }
}

/// Radius of the ball, mm (the mesh's unit).
pub const RADIUS: f64 = 20.0;

/// The ball's tets: an `n³` lattice of `[-1, 1]³`, each cube split into six
/// tets around its main diagonal (Kuhn), mapped radially
/// (`x ← R x ‖x‖∞ / ‖x‖₂`) so that the boundary vertices lie on the sphere
/// and every tet stays positively oriented.
pub fn ball(n: usize) -> Result<TetMesh, Error> {
    let (positions, tets) = kuhn_ball(n, RADIUS);
    TetMesh::new(&positions, &tets)
}

/// The built-in object (`n = 16`: 24 576 tets), unlit.
///
/// # Errors
/// None in practice (the mesh is made here); those of [`Object::new`].
pub fn object(n: usize) -> Result<Object, Error> {
    let mesh = ball(n)?;
    let marble = Medium::measured("marble")?;
    let ketchup = Medium::measured("ketchup")?;
    let skin = Medium::measured("skin1")?;
    let core = DVec3::new(0.25, 0.15, 0.1) * RADIUS;
    let media = (0..mesh.tets().len())
        .map(|t| {
            let c = mesh.tet_center(t);
            let ring =
                (c.y.abs() < 0.12 * RADIUS) && (0.55 * RADIUS..0.75 * RADIUS).contains(&c.length());
            if c.distance(core) < 0.38 * RADIUS {
                ketchup
            } else if ring {
                skin
            } else {
                marble
            }
        })
        .collect();
    Object::new(mesh, 1.0, media, 1.3)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ball_is_closed_round_and_heterogeneous() {
        let o = object(8).unwrap();
        let m = o.mesh();
        assert_eq!(m.tets().len(), 8 * 8 * 8 * 6);
        for &v in m.boundary_vertices() {
            let r = m.positions()[v as usize].length();
            assert!((r - RADIUS).abs() < 1e-9, "{r}");
        }
        let distinct: std::collections::HashSet<String> =
            o.media().iter().map(|m| format!("{m:?}")).collect();
        assert_eq!(distinct.len(), 3);
    }
}
