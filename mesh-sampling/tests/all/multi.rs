//! Several meshes at once: counts per mesh follow their areas, the
//! density is uniform over the union, replacing a mesh changes only what
//! it should, errors name the mesh.

use test_support::stats;

use glam::Vec3;
use mesh_sampling::{
    Density, DensitySampler, Error, MeshRef, MultiDensitySampler, MultiMeshSampler,
};
use rand::SeedableRng;
use rand::distr::Distribution;
use rand_pcg::Pcg64Mcg;

/// A square of side `s` at height `z` (area s²).
fn square(s: f32, z: f32) -> Vec<Vec3> {
    vec![
        Vec3::new(0.0, 0.0, z),
        Vec3::new(s, 0.0, z),
        Vec3::new(0.0, s, z),
        Vec3::new(s, s, z),
    ]
}

const QUAD: [[u32; 3]; 2] = [[0, 1, 2], [1, 3, 2]];

fn mesh_counts(sampler: &MultiMeshSampler<'_>, n: usize) -> Vec<u64> {
    let mut rng = Pcg64Mcg::seed_from_u64(17);
    let mut counts = vec![0u64; sampler.len()];
    for _ in 0..n {
        let p = sampler.sample(&mut rng);
        counts[p.mesh] += 1;
        // Each point lies on its own mesh (told apart by height).
        assert_eq!(p.point.position.z, p.mesh as f32);
        assert_eq!(p.point.pdf, sampler.pdf(p.mesh, p.point.face as usize));
    }
    counts
}

#[test]
fn counts_follow_areas_and_replacement_updates_them() {
    let (a, b, c) = (
        square(1.0, 0.0),
        square(3f32.sqrt(), 1.0),
        square(3f32.sqrt(), 0.0),
    );
    let mut sampler =
        MultiMeshSampler::new([MeshRef::new(&a, &QUAD), MeshRef::new(&b, &QUAD)]).unwrap();
    assert!((sampler.total_area() - 4.0).abs() < 1e-5);
    assert!((sampler.pdf(1, 0) - 0.25).abs() < 1e-6);
    let counts = mesh_counts(&sampler, 400_000);
    assert!(
        stats::chi_square(&counts, &[0.25, 0.75], 20.0).p_value > 1e-3,
        "{counts:?}"
    );

    // Mesh 0 grows to the size of mesh 1: the split becomes even.
    sampler.replace(0, MeshRef::new(&c, &QUAD)).unwrap();
    assert!((sampler.total_area() - 6.0).abs() < 1e-5);
    let counts = mesh_counts(&sampler, 400_000);
    assert!(
        stats::chi_square(&counts, &[0.5, 0.5], 20.0).p_value > 1e-3,
        "{counts:?}"
    );
    // The old split is rejected by the same test.
    assert!(stats::chi_square(&counts, &[0.25, 0.75], 20.0).p_value < 1e-9);
}

#[test]
fn batches_do_not_depend_on_the_thread_count() {
    let (a, b) = (square(1.0, 0.0), square(2.0, 1.0));
    let sampler =
        MultiMeshSampler::new([MeshRef::new(&a, &QUAD), MeshRef::new(&b, &QUAD)]).unwrap();
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| sampler.sample_n(5, 50_000).unwrap())
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn errors_name_the_mesh_and_leave_the_sampler_unchanged() {
    let a = square(1.0, 0.0);
    assert_eq!(MultiMeshSampler::new([]).unwrap_err(), Error::Empty);
    let err = MultiMeshSampler::new([MeshRef::new(&a, &QUAD), MeshRef::new(&a, &[[0, 1, 9]])])
        .unwrap_err();
    assert!(matches!(err, Error::InMesh { index: 1, .. }), "{err}");
    assert_eq!(
        err.to_string(),
        "mesh 1: triangle 0 references vertex 9, but there are only 4 vertices"
    );

    let mut sampler = MultiMeshSampler::new([MeshRef::new(&a, &QUAD)]).unwrap();
    assert_eq!(
        sampler.replace(3, MeshRef::new(&a, &QUAD)).unwrap_err(),
        Error::NoSuchMesh { index: 3, count: 1 }
    );
    assert!(sampler.replace(0, MeshRef::new(&a, &[[0, 0, 1]])).is_err());
    assert!(
        (sampler.total_area() - 1.0).abs() < 1e-6,
        "unchanged after a failed replace"
    );
}

#[test]
fn densities_over_several_meshes_follow_their_masses() {
    let (a, b) = (square(1.0, 0.0), square(3f32.sqrt(), 1.0));
    // Masses: 1 · 1 and 2 · 3.
    let (wa, wb, wc) = ([1.0f32; 2], [2.0f32; 2], [6.0f32; 2]);
    fn build<'a>(p: &'a [Vec3], w: &'a [f32]) -> DensitySampler<'a> {
        DensitySampler::new(MeshRef::new(p, &QUAD), Density::PerFace(w)).unwrap()
    }
    let mut sampler = MultiDensitySampler::new([build(&a, &wa), build(&b, &wb)]).unwrap();
    assert!((sampler.total_mass() - 7.0).abs() < 1e-5);
    let count = |s: &MultiDensitySampler<'_>| {
        let mut counts = vec![0u64; 2];
        for p in s.sample_n(3, 200_000).unwrap() {
            counts[p.mesh] += 1;
            assert_eq!(p.point.position.z, p.mesh as f32);
            let pdf = s.pdf(p.mesh, p.point.face as usize, p.point.barycentric);
            assert!((pdf - p.point.pdf).abs() < 1e-6 * pdf);
        }
        counts
    };
    let counts = count(&sampler);
    let test = stats::chi_square(&counts, &[1.0 / 7.0, 6.0 / 7.0], 20.0);
    assert!(test.p_value > 1e-3, "{counts:?}");
    // Density 1/7 per unit area on mesh 0, 2/7 on mesh 1: ∫ = 1/7 + 6/7.
    assert!((sampler.pdf(0, 0, [0.3, 0.3, 0.4]) - 1.0 / 7.0).abs() < 1e-6);
    assert!((sampler.pdf(1, 1, [0.3, 0.3, 0.4]) - 2.0 / 7.0).abs() < 1e-6);
    // Mesh 0's weight grows to 6: masses 6 and 6.
    sampler.replace(0, build(&a, &wc)).unwrap();
    let counts = count(&sampler);
    assert!(
        stats::chi_square(&counts, &[0.5, 0.5], 20.0).p_value > 1e-3,
        "{counts:?}"
    );
    assert!(stats::chi_square(&counts, &[1.0 / 7.0, 6.0 / 7.0], 20.0).p_value < 1e-9);
    assert!(matches!(
        sampler.replace(2, build(&a, &wa)),
        Err(Error::NoSuchMesh { index: 2, count: 2 })
    ));
    assert!(matches!(MultiDensitySampler::new([]), Err(Error::Empty)));
}
