//! Editing without resampling: subdivision leaves every lookup unchanged,
//! deleting, adding and re-resolving faces touch only their own samples.

use crate::support;

use mesh_colors::edit::child_of;
use mesh_colors::{Error, MeshColors, Topology};
use support::Rng;

fn colored(min_level: u64, seed: u64) -> MeshColors {
    let (positions, faces) = support::grid(5, 0.3);
    let mut rng = Rng(seed);
    let levels: Vec<u32> = (0..faces.len())
        .map(|_| 1 << (min_level + rng.below(5 - min_level)))
        .collect();
    let mut mc =
        MeshColors::new(Topology::new(positions.len(), &faces).unwrap(), &levels, 3).unwrap();
    for x in mc.samples_mut() {
        *x = rng.f32();
    }
    mc
}

fn max_diff(a: &[f32], b: &[f32]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

#[test]
fn subdivision_leaves_every_lookup_unchanged() {
    let mc = colored(1, 1);
    let sub = mc.subdivide().unwrap();
    assert_eq!(sub.faces.len(), 4 * mc.face_count());
    assert_eq!(
        sub.colors.topology().vertex_count(),
        mc.topology().vertex_count() + mc.topology().edges().len()
    );
    // Same samples, only reorganised: R²/2-ish per face is conserved
    // exactly (no sample is created or lost).
    assert_eq!(sub.colors.sample_count(), mc.sample_count());
    let mut rng = Rng(2);
    let (mut a, mut b) = ([0.0f32; 3], [0.0f32; 3]);
    for round in 0..200_000 {
        let f = rng.below(mc.face_count() as u64) as usize;
        let bary = if round % 2 == 0 {
            // Dyadic barycentrics: the arithmetic is exact, so must be the result.
            let (i, j) = (rng.below(4097) as u32, rng.below(4097) as u32);
            let (i, j) = if i + j > 4096 {
                (4096 - i, 4096 - j)
            } else {
                (i, j)
            };
            [
                i as f32 / 4096.0,
                j as f32 / 4096.0,
                (4096 - i - j) as f32 / 4096.0,
            ]
        } else {
            rng.barycentric()
        };
        let (child, cb) = child_of(bary);
        let g = 4 * f + child;
        mc.linear(f, bary, &mut a).unwrap();
        sub.colors.linear(g, cb, &mut b).unwrap();
        // Samples are carried bit for bit (checked below); a lookup may
        // differ in the last bits only, because a child can run along a
        // half-edge in the other canonical direction or (the centre child)
        // see the parent lattice turned half a turn, which reorders the
        // rounding of the same three-term sum.
        assert!(
            max_diff(&a, &b) < 2e-6,
            "face {f} at {bary:?}: {a:?} vs {b:?}"
        );
    }
    // Every sample value moves over exactly: the same multiset of bits.
    let bits = |m: &MeshColors| {
        let mut v: Vec<u32> = m.samples().iter().map(|x| x.to_bits()).collect();
        v.sort_unstable();
        v
    };
    assert_eq!(bits(&mc), bits(&sub.colors));
    // Positions: midpoints after the old vertices.
    let (positions, _) = support::grid(5, 0.3);
    let p = sub.positions(&positions).unwrap();
    assert!(sub.positions(&positions[..3]).is_err());
    let [x, y] = sub.midpoints[3];
    assert_eq!(
        p[positions.len() + 3],
        0.5 * (positions[x as usize] + positions[y as usize])
    );
    // A face at R = 1 cannot be split without inventing samples.
    let coarse = colored(0, 5);
    let f = (0..coarse.face_count())
        .find(|&f| coarse.face_resolution(f).unwrap() == 1)
        .unwrap();
    assert_eq!(coarse.subdivide(), Err(Error::CannotSubdivide { face: f }));
}

#[test]
fn deleting_and_adding_faces_keeps_the_other_colours() {
    let mc = colored(0, 3);
    let remove = [3usize, 10, 11, 27];
    let fewer = mc.delete_faces(&remove).unwrap();
    assert_eq!(fewer.face_count(), mc.face_count() - remove.len());
    let kept: Vec<usize> = (0..mc.face_count())
        .filter(|f| !remove.contains(f))
        .collect();
    let mut rng = Rng(4);
    let (mut a, mut b) = ([0.0f32; 3], [0.0f32; 3]);
    for _ in 0..50_000 {
        let k = rng.below(kept.len() as u64) as usize;
        let bary = rng.barycentric();
        mc.linear(kept[k], bary, &mut a).unwrap();
        fewer.linear(k, bary, &mut b).unwrap();
        // Edges left with a finer face are refined by interpolation.
        assert!(max_diff(&a, &b) < 1e-6, "{a:?} vs {b:?}");
    }
    // Face interiors of the kept faces are copied bit for bit.
    for (k, &f) in kept.iter().enumerate() {
        let n = mesh_colors::samples_per_face(mc.face_resolution(f).unwrap()) as usize;
        let (i, j) = (
            mc.face_index(f).unwrap() * 3,
            fewer.face_index(k).unwrap() * 3,
        );
        assert_eq!(&mc.samples()[i..i + 3 * n], &fewer.samples()[j..j + 3 * n]);
    }
    // Add them back at their resolutions: the old faces' lookups are
    // exactly the original ones again.
    let back_faces: Vec<[u32; 3]> = remove.iter().map(|&f| mc.topology().faces()[f]).collect();
    let back_res: Vec<u32> = remove
        .iter()
        .map(|&f| mc.face_resolution(f).unwrap())
        .collect();
    let again = fewer
        .add_faces(&back_faces, &back_res, mc.topology().vertex_count())
        .unwrap();
    for _ in 0..50_000 {
        let k = rng.below(kept.len() as u64) as usize;
        let bary = rng.barycentric();
        fewer.linear(k, bary, &mut a).unwrap();
        again.linear(k, bary, &mut b).unwrap();
        assert!(max_diff(&a, &b) < 1e-6);
    }
    // A new face on a new vertex (next to the boundary edge (0, 1)) starts
    // as the interpolation of its vertex colours, inside and on its new
    // edges; the existing edge (0, 1) keeps its samples.
    let v = mc.topology().vertex_count() as u32;
    let grown = mc
        .add_faces(&[[1, 0, v]], &[8], mc.topology().vertex_count() + 1)
        .unwrap();
    let g = grown.face_count() - 1;
    let face = grown.topology().faces()[g];
    for a in mesh_colors::lattice_points(8) {
        if a[2] == 0 && a[0] > 0 && a[1] > 0 {
            continue; // on the old edge (0, 1)
        }
        let i = grown.lattice_index(g, a).unwrap();
        let want: Vec<f32> = (0..3)
            .map(|c| {
                (0..3)
                    .map(|k| a[k] as f32 / 8.0 * grown.sample(face[k] as usize).unwrap()[c])
                    .sum()
            })
            .collect();
        assert!(max_diff(grown.sample(i).unwrap(), &want) < 1e-6, "{a:?}");
    }
    let e01 = mc.topology().edge_between(0, 1).unwrap() as usize;
    let n01 = mc.edge_resolution(e01).unwrap() as usize - 1;
    let e01g = grown.topology().edge_between(0, 1).unwrap() as usize;
    assert_eq!(
        &mc.samples()[mc.edge_index(e01).unwrap() * 3..(mc.edge_index(e01).unwrap() + n01) * 3],
        &grown.samples()
            [grown.edge_index(e01g).unwrap() * 3..(grown.edge_index(e01g).unwrap() + n01) * 3]
    );
    assert!(matches!(
        mc.delete_faces(&[999]),
        Err(Error::MissingFace { face: 999, .. })
    ));
    assert!(mc.add_faces(&[[0, 1, 99]], &[2], 40).is_err());
    assert!(mc.add_faces(&[[0, 1, 2]], &[3], 40).is_err());
}

#[test]
fn changing_one_resolution_resamples_only_that_face() {
    let mc = colored(1, 6);
    let f = 12;
    let r = mc.face_resolution(f).unwrap();
    let finer = mc.set_face_resolution(f, 2 * r).unwrap();
    assert_eq!(finer.face_resolution(f).unwrap(), 2 * r);
    let mut rng = Rng(7);
    let (mut a, mut b) = ([0.0f32; 3], [0.0f32; 3]);
    for _ in 0..50_000 {
        let g = rng.below(mc.face_count() as u64) as usize;
        let bary = rng.barycentric();
        mc.linear(g, bary, &mut a).unwrap();
        finer.linear(g, bary, &mut b).unwrap();
        // Refining samples the old piecewise-linear colour on a lattice
        // that contains the old one: the colour does not change anywhere.
        assert!(max_diff(&a, &b) < 2e-6, "face {g}: {a:?} vs {b:?}");
    }
    // Other faces' interiors are untouched bit for bit.
    for g in (0..mc.face_count()).filter(|&g| g != f) {
        let n = mesh_colors::samples_per_face(mc.face_resolution(g).unwrap()) as usize;
        let (i, j) = (
            mc.face_index(g).unwrap() * 3,
            finer.face_index(g).unwrap() * 3,
        );
        assert_eq!(&mc.samples()[i..i + 3 * n], &finer.samples()[j..j + 3 * n]);
    }
    // Coarsening changes that face (it loses detail) but not the others
    // away from it, and stays continuous (checked by the filtering tests'
    // rule: edges are read from the edge alone).
    let coarser = mc.set_face_resolution(f, 1).unwrap();
    let t = mc.topology();
    let touches = |g: usize| t.faces()[g].iter().any(|v| t.faces()[f].contains(v));
    for g in (0..mc.face_count()).filter(|&g| !touches(g)) {
        for _ in 0..100 {
            let bary = rng.barycentric();
            mc.linear(g, bary, &mut a).unwrap();
            coarser.linear(g, bary, &mut b).unwrap();
            assert_eq!(a, b);
        }
    }
    assert!(mc.set_face_resolution(f, 6).is_err());
    assert!(mc.set_face_resolution(999, 2).is_err());
}
