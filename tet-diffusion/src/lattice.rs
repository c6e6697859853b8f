//! Tet meshes built in code: the Kuhn-subdivided box lattice, conforming
//! and well shaped, and the ball mapped from it, for tests, examples and
//! built-in objects.

use glam::DVec3;

/// The six monotone paths from corner 000 to corner 111 of a cube: Kuhn's
/// six tets around its main diagonal.
const PATHS: [[usize; 3]; 6] = [
    [0, 1, 2],
    [0, 2, 1],
    [1, 0, 2],
    [1, 2, 0],
    [2, 0, 1],
    [2, 1, 0],
];

/// An `n × n × n` lattice of cubes filling the box from `min` to `max`,
/// each cube split into six tets around its main diagonal (Kuhn): a
/// conforming mesh whose dihedral angles are 45°–90° on a cube, as plain
/// arrays for [`TetMesh::new`](crate::TetMesh::new) (or for mapping the
/// positions first, say onto a ball).
///
/// Vertex `(x, y, z)` of the lattice is `min + (x, y, z) · (max − min) / n`
/// at index `x + (n + 1) (y + (n + 1) z)`. Half of the tets are listed
/// negatively oriented; [`TetMesh::new`](crate::TetMesh::new) re-orients
/// them. `n = 0` gives the one vertex `min` and no tets.
///
/// # Example
/// ```
/// use tet_diffusion::{glam::DVec3, kuhn_lattice, TetMesh};
/// let (p, t) = kuhn_lattice(3, DVec3::ZERO, DVec3::ONE);
/// assert_eq!((p.len(), t.len()), (64, 27 * 6));
/// let mesh = TetMesh::new(&p, &t)?;
/// assert!((mesh.volume() - 1.0).abs() < 1e-12);
/// # Ok::<(), tet_diffusion::Error>(())
/// ```
pub fn kuhn_lattice(n: usize, min: DVec3, max: DVec3) -> (Vec<DVec3>, Vec<[u32; 4]>) {
    let m = n + 1;
    let id = |x: usize, y: usize, z: usize| (x + m * (y + m * z)) as u32;
    let step = if n == 0 {
        DVec3::ZERO
    } else {
        (max - min) / n as f64
    };
    let mut positions = Vec::with_capacity(m * m * m);
    for z in 0..m {
        for y in 0..m {
            for x in 0..m {
                positions.push(DVec3::new(x as f64, y as f64, z as f64) * step + min);
            }
        }
    }
    let mut tets = Vec::with_capacity(n * n * n * 6);
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                for path in PATHS {
                    let mut c = [x, y, z];
                    let mut tet = [id(x, y, z); 4];
                    for (k, &axis) in path.iter().enumerate() {
                        c[axis] += 1;
                        tet[k + 1] = id(c[0], c[1], c[2]);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    (positions, tets)
}

/// A ball of `radius` around the origin: the [`kuhn_lattice`] of
/// `[-1, 1]³` mapped radially, `x ← radius · x ‖x‖∞ / ‖x‖₂`, so that its
/// boundary vertices lie on the sphere and every tet stays positively
/// oriented (after [`TetMesh::new`](crate::TetMesh::new)'s re-orientation).
///
/// # Example
/// ```
/// use tet_diffusion::{kuhn_ball, TetMesh};
/// let (p, t) = kuhn_ball(6, 2.0);
/// let ball = TetMesh::new(&p, &t)?;
/// for &v in ball.boundary_vertices() {
///     assert!((ball.positions()[v as usize].length() - 2.0).abs() < 1e-12);
/// }
/// # Ok::<(), tet_diffusion::Error>(())
/// ```
pub fn kuhn_ball(n: usize, radius: f64) -> (Vec<DVec3>, Vec<[u32; 4]>) {
    let (lattice, tets) = kuhn_lattice(n, -DVec3::ONE, DVec3::ONE);
    let positions = lattice
        .into_iter()
        .map(|x| {
            let l = x.length();
            if l == 0.0 {
                x
            } else {
                x * (radius * x.abs().max_element() / l)
            }
        })
        .collect();
    (positions, tets)
}
