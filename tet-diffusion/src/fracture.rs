//! Fracture and recombination (the paper's Fig. 1d–e): split an object
//! along a plane into two objects that solve independently (the tets the
//! plane crosses split along it exactly, by the machinery of the exact
//! cut, and the vertices of the faces between the sides duplicated, one
//! copy per piece), move them apart for display with rigid transforms, and
//! merge two pieces back into exactly the split object they came from.

#![expect(
    clippy::needless_range_loop,
    reason = "RGB loops index several per-channel arrays by one channel index"
)]

use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;

use crate::cut::split::{self, Keep};
use crate::error::finite_vec;
use crate::object::Lineage;
use crate::{Error, Light, Object, TetMesh};

/// Identifies one fracture, so that only its two pieces recombine.
static FRACTURES: AtomicU64 = AtomicU64::new(1);

impl Object {
    /// Splits the object by the plane through `point` with `normal`: the
    /// tets the plane crosses are first split along it exactly (as
    /// [`CutMethod::Exact`](crate::CutMethod::Exact) splits them, vertices
    /// within 0.2 of an edge's length of it snapped onto it, `φ`
    /// interpolated at the new vertices); then the tets on the side
    /// `(x − point) · normal ≥ 0` go to the second piece, the others to the
    /// first, so both crack faces lie on the plane. Each piece keeps the
    /// material, the lights (re-traced against its own surface), `φ` as
    /// its warm start, and what it needs to be
    /// [`recombine`](Object::recombine)d.
    ///
    /// # Errors
    /// [`Error::BadArgument`] for a non-finite point or a zero normal,
    /// [`Error::EmptyPiece`] when the plane does not split the object,
    /// [`Error::CutAngleBound`] as for the exact cut.
    pub fn fracture(&self, point: DVec3, normal: DVec3) -> Result<[Object; 2], Error> {
        finite_vec("the fracture plane's point", point)?;
        finite_vec("the fracture plane's normal", normal)?;
        if normal.length_squared() == 0.0 {
            return Err(Error::BadArgument {
                what: "the length of the fracture plane's normal".into(),
                value: 0.0,
                need: "it must be non-zero",
            });
        }
        let unit = normal.normalize();
        let level = move |x: DVec3| (x - point).dot(unit);
        let split = split::split(&self.mesh, &level, Keep::Both)?;
        let upper: Vec<bool> = split.side.iter().map(|&s| s > 0).collect();
        let count = upper.iter().filter(|&&u| u).count();
        if count == 0 {
            return Err(Error::EmptyPiece {
                side: "the positive",
            });
        }
        if count == upper.len() {
            return Err(Error::EmptyPiece {
                side: "the negative",
            });
        }
        // A split changed the mesh: the pieces recombine into the split
        // object, which is no longer a piece of an earlier fracture.
        let changed = split.split_tets > 0 || split.snapped > 0;
        let parts = self.split_parts(&split, false)?;
        let mesh = &parts.mesh;
        let token = FRACTURES.fetch_add(1, Ordering::Relaxed);
        let piece = |want: bool| -> Result<Object, Error> {
            let tet_ids: Vec<u32> = (0..upper.len() as u32)
                .filter(|&t| upper[t as usize] == want)
                .collect();
            let mut index = vec![u32::MAX; mesh.vertex_count()];
            for &t in &tet_ids {
                for &v in &mesh.tets()[t as usize] {
                    index[v as usize] = 0;
                }
            }
            let mut vertex = Vec::new();
            for (v, slot) in index.iter_mut().enumerate() {
                if *slot == 0 {
                    *slot = vertex.len() as u32;
                    vertex.push(v as u32);
                }
            }
            let positions = vertex
                .iter()
                .map(|&v| mesh.positions()[v as usize])
                .collect();
            let tets = tet_ids
                .iter()
                .map(|&t| mesh.tets()[t as usize].map(|v| index[v as usize]))
                .collect();
            let original = tet_ids
                .iter()
                .map(|&t| mesh.original_ids()[t as usize])
                .collect();
            let sub = TetMesh::with_original(positions, tets, original)?;
            let lineage = Lineage {
                token,
                parent_vertices: mesh.vertex_count(),
                parent_tets: mesh.tets().len(),
                vertex,
                tet: tet_ids,
                parent: if changed {
                    None
                } else {
                    self.lineage.clone().map(Box::new)
                },
                parent_original: mesh.original_ids().to_vec(),
            };
            self.derive(sub, lineage, &parts.media, &parts.phi)
        };
        Ok([piece(false)?, piece(true)?])
    }

    /// A new object on `mesh` with `media`, this one's settings and
    /// lights, and `phi` (of the parent mesh) carried through
    /// `lineage.vertex`.
    fn derive(
        &self,
        mesh: TetMesh,
        lineage: Lineage,
        media: &[crate::Medium],
        phi: &[Vec<f64>; 3],
    ) -> Result<Object, Error> {
        let mut object = Object::new(mesh, self.length_unit_mm, media.to_vec(), self.eta)?;
        object.settings = self.settings;
        object.shadows_enabled = self.shadows_enabled;
        object.phi =
            std::array::from_fn(|c| lineage.vertex.iter().map(|&v| phi[c][v as usize]).collect());
        for l in &self.lights {
            object.add_light(l.light.clone())?;
        }
        object.lineage = Some(lineage);
        Ok(object)
    }

    /// Merges the two pieces of one [`fracture`](Object::fracture) back
    /// into the object they came from, split along the fracture plane: the
    /// same vertices, tets, material
    /// (with what was painted on either piece) and therefore exactly the
    /// same matrices. Display transforms are dropped; lights and settings
    /// come from `a`.
    ///
    /// # Errors
    /// [`Error::NotMatchingPieces`] unless `a` and `b` are the two pieces
    /// of one fracture (and neither was cut since).
    pub fn recombine(a: &Object, b: &Object) -> Result<Object, Error> {
        let (la, lb) = match (&a.lineage, &b.lineage) {
            (Some(la), Some(lb)) if la.token == lb.token => (la, lb),
            _ => return Err(Error::NotMatchingPieces),
        };
        if la.tet.len() + lb.tet.len() != la.parent_tets {
            return Err(Error::NotMatchingPieces);
        }
        let mut positions = vec![DVec3::ZERO; la.parent_vertices];
        let mut phi: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; la.parent_vertices]);
        let mut tets = vec![[u32::MAX; 4]; la.parent_tets];
        let mut media = a.media.clone();
        for (piece, l) in [(b, lb), (a, la)] {
            for (k, &v) in l.vertex.iter().enumerate() {
                positions[v as usize] = piece.mesh.positions()[k];
                for c in 0..3 {
                    phi[c][v as usize] = piece.phi[c][k];
                }
            }
            for (k, &t) in l.tet.iter().enumerate() {
                tets[t as usize] = piece.mesh.tets()[k].map(|v| l.vertex[v as usize]);
            }
        }
        for &id in b.mesh.original_ids() {
            media[id as usize] = b.media[id as usize];
        }
        if tets.iter().any(|t| t[0] == u32::MAX) {
            return Err(Error::NotMatchingPieces);
        }
        let mesh = TetMesh::with_original(positions, tets, la.parent_original.clone())?;
        let mut object = Object::new(mesh, a.length_unit_mm, media, a.eta)?;
        object.settings = a.settings;
        object.shadows_enabled = a.shadows_enabled;
        object.phi = phi;
        let lights: Vec<Light> = a.lights.iter().map(|l| l.light.clone()).collect();
        for l in lights {
            object.add_light(l)?;
        }
        object.lineage = la.parent.as_deref().cloned();
        Ok(object)
    }
}
