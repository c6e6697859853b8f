//! The Kuhn cube lattice: conforming, well-shaped tets built in code, shared
//! by the crate's unit tests and its integration tests (included by path).

use glam::DVec3;

/// An `n³`-cube lattice of `[0, size]³`, each cube split into six tets
/// around its main diagonal (Kuhn): conforming and well shaped.
pub(crate) fn cube(n: usize, size: f64) -> (Vec<DVec3>, Vec<[u32; 4]>) {
    let m = n + 1;
    let id = |x: usize, y: usize, z: usize| (x + m * (y + m * z)) as u32;
    let mut p = Vec::new();
    for z in 0..m {
        for y in 0..m {
            for x in 0..m {
                p.push(DVec3::new(x as f64, y as f64, z as f64) * (size / n as f64));
            }
        }
    }
    let mut tets = Vec::new();
    // The six monotone paths from corner 000 to corner 111.
    const PATHS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
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
    (p, tets)
}
