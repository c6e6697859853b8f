//! Undirected graphs in compressed adjacency form: the vertices and edges
//! of a level of the hierarchy.

use rayon::prelude::*;
use sprs::CsMat;

/// Sorted neighbour lists, without self-loops.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Graph {
    offsets: Vec<usize>,
    neighbors: Vec<u32>,
}

impl Graph {
    /// The graph of a square matrix's off-diagonal non-zeros, made
    /// symmetric (an edge where `a_ij ≠ 0` or `a_ji ≠ 0`).
    pub fn from_matrix(a: &CsMat<f64>) -> Self {
        let indptr = a.indptr();
        let indptr = indptr.to_proper();
        let row = |i: usize| {
            let range = indptr[i]..indptr[i + 1];
            a.indices()[range.clone()]
                .iter()
                .zip(&a.data()[range])
                .filter(move |&(&j, &v)| j != i && v != 0.0)
                .map(|(&j, _)| j as u32)
        };
        // Most matrices (diffusion, Laplacians) have a symmetric pattern:
        // then the rows are the neighbour lists (CSR keeps them sorted).
        let direct = {
            let counts: Vec<usize> = (0..a.rows())
                .into_par_iter()
                .map(|i| row(i).count())
                .collect();
            let mut offsets = Vec::with_capacity(a.rows() + 1);
            offsets.push(0);
            for c in counts {
                offsets.push(offsets[offsets.len() - 1] + c);
            }
            let mut neighbors = vec![0u32; offsets[a.rows()]];
            let mut rest = neighbors.as_mut_slice();
            let mut slices = Vec::with_capacity(a.rows());
            for i in 0..a.rows() {
                let (head, tail) = rest.split_at_mut(offsets[i + 1] - offsets[i]);
                slices.push(head);
                rest = tail;
            }
            slices.into_par_iter().enumerate().for_each(|(i, out)| {
                for (o, j) in out.iter_mut().zip(row(i)) {
                    *o = j;
                }
            });
            Self { offsets, neighbors }
        };
        let sorted_symmetric = (0..direct.len()).into_par_iter().all(|i| {
            let nb = direct.neighbors(i);
            nb.windows(2).all(|w| w[0] < w[1])
                && nb.iter().all(|&j| {
                    direct
                        .neighbors(j as usize)
                        .binary_search(&(i as u32))
                        .is_ok()
                })
        });
        if sorted_symmetric {
            return direct;
        }
        let mut edges: Vec<(u32, u32)> = (0..a.rows())
            .into_par_iter()
            .flat_map_iter(|i| {
                row(i).map(move |j| (i.min(j as usize) as u32, i.max(j as usize) as u32))
            })
            .collect();
        edges.par_sort_unstable();
        edges.dedup();
        Self::from_sorted_edges(a.rows(), &edges)
    }

    /// The graph on `n` vertices with the given `(i, j)`, `i < j` edges,
    /// sorted and without duplicates.
    pub(crate) fn from_sorted_edges(n: usize, edges: &[(u32, u32)]) -> Self {
        let mut degree = vec![0usize; n + 1];
        for &(i, j) in edges {
            degree[i as usize + 1] += 1;
            degree[j as usize + 1] += 1;
        }
        for k in 1..=n {
            degree[k] += degree[k - 1];
        }
        let offsets = degree;
        let mut fill = offsets.clone();
        let mut neighbors = vec![0u32; 2 * edges.len()];
        // Sorted edges visited in order give each list sorted: the
        // smaller neighbours of j (as (i, j)) come before its larger ones.
        for &(i, j) in edges {
            neighbors[fill[j as usize]] = i;
            fill[j as usize] += 1;
        }
        for &(i, j) in edges {
            neighbors[fill[i as usize]] = j;
            fill[i as usize] += 1;
        }
        Self { offsets, neighbors }
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Whether the graph has no vertex.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of (undirected) edges.
    pub fn edges(&self) -> usize {
        self.neighbors.len() / 2
    }

    /// The sorted neighbours of `i`.
    #[inline]
    pub fn neighbors(&self, i: usize) -> &[u32] {
        &self.neighbors[self.offsets[i]..self.offsets[i + 1]]
    }

    /// Whether `i` and `j` are adjacent.
    pub fn adjacent(&self, i: usize, j: usize) -> bool {
        self.neighbors(i).binary_search(&(j as u32)).is_ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbour_lists_are_sorted_and_symmetric() {
        let g = Graph::from_sorted_edges(4, &[(0, 1), (0, 3), (1, 2), (2, 3)]);
        assert_eq!(g.neighbors(0), &[1, 3]);
        assert_eq!(g.neighbors(3), &[0, 2]);
        assert_eq!(g.edges(), 4);
        assert!(g.adjacent(2, 1) && !g.adjacent(0, 2));
    }

    #[test]
    fn a_matrix_pattern_is_made_symmetric() {
        let mut t = sprs::TriMat::new((3, 3));
        for (i, j, v) in [
            (0, 0, 2.0),
            (0, 1, -1.0),
            (1, 1, 2.0),
            (2, 1, -1.0),
            (2, 2, 2.0),
            (1, 2, 0.0),
        ] {
            t.add_triplet(i, j, v);
        }
        let g = Graph::from_matrix(&t.to_csr());
        assert_eq!(g.neighbors(1), &[0, 2]);
        assert_eq!(g.neighbors(2), &[1]);
        let mut t = sprs::TriMat::new((3, 3));
        for (i, j, v) in [(0, 1, -1.0), (1, 0, -1.0), (1, 2, -3.0), (2, 1, -3.0)] {
            t.add_triplet(i, j, v);
        }
        let g = Graph::from_matrix(&t.to_csr());
        assert_eq!(g.neighbors(1), &[0, 2]);
    }
}
