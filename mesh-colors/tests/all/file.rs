//! The `.meshcolors` format: bit-exact round trips, and corrupt, truncated
//! or random bytes rejected with an error (never a panic).

use crate::support;

use mesh_colors::{Error, Fingerprint, MeshColors, Topology, file};
use support::Rng;

fn sample_colors() -> MeshColors {
    let (positions, faces) = support::grid(4, 0.2);
    let mut rng = Rng(3);
    let levels: Vec<u32> = (0..faces.len()).map(|_| 1 << rng.below(5)).collect();
    let mut mc = MeshColors::new(
        Topology::new(positions.len() + 2, &faces).unwrap(),
        &levels,
        4,
    )
    .unwrap();
    for (i, x) in mc.samples_mut().iter_mut().enumerate() {
        // Include values that a text format would not keep: NaN payloads,
        // negative zero, subnormals.
        *x = match i % 97 {
            0 => f32::from_bits(0x7fc0_1234),
            1 => -0.0,
            2 => f32::from_bits(1),
            _ => rng.f32() * 3.0 - 1.0,
        };
    }
    mc
}

#[test]
fn round_trip_is_bit_exact_with_and_without_mip() {
    let mc = sample_colors();
    let bytes = file::to_bytes(&mc, None).unwrap();
    let (back, mip) = file::from_bytes(&bytes).unwrap();
    assert!(mip.is_none());
    assert_eq!(back.topology(), mc.topology());
    let bits = |s: &[f32]| s.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(back.samples()), bits(mc.samples()));
    assert_eq!(file::to_bytes(&back, None).unwrap(), bytes);

    let pyramid = mc.mip_map();
    let bytes = file::to_bytes(&mc, Some(&pyramid)).unwrap();
    let (back, mip) = file::from_bytes(&bytes).unwrap();
    assert_eq!(bits(mip.unwrap().data()), bits(pyramid.data()));
    assert_eq!(bits(back.samples()), bits(mc.samples()));

    let path = std::env::temp_dir().join(format!(
        "mesh-colors-test-{}.meshcolors",
        std::process::id()
    ));
    file::save(&path, &mc, Some(&pyramid)).unwrap();
    let (loaded, _) = file::load(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(bits(loaded.samples()), bits(mc.samples()));
}

fn rejected(bytes: &[u8]) -> Error {
    match file::from_bytes(bytes) {
        Ok(_) => panic!("accepted {} corrupt bytes", bytes.len()),
        Err(e) => e,
    }
}

#[test]
fn truncated_and_inconsistent_files_are_rejected_with_the_offset() {
    let mc = sample_colors();
    let bytes = file::to_bytes(&mc, Some(&mc.mip_map())).unwrap();
    // Every truncation.
    for len in 0..bytes.len() {
        assert!(
            matches!(rejected(&bytes[..len]), Error::File { .. }),
            "length {len}"
        );
    }
    // Trailing bytes.
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(rejected(&longer).to_string().contains("after the end"));
    let set = |at: usize, v: u32| {
        let mut b = bytes.clone();
        b[at..at + 4].copy_from_slice(&v.to_le_bytes());
        b
    };
    assert!(rejected(&set(0, 0)).to_string().contains("magic"));
    assert!(rejected(&set(8, 3)).to_string().contains("version 3"));
    assert!(rejected(&set(12, 0)).to_string().contains("0 channels"));
    assert!(rejected(&set(24, 6)).to_string().contains("flags"));
    // Counts the file cannot hold are refused before allocating.
    assert!(
        rejected(&set(16, u32::MAX))
            .to_string()
            .contains("truncated")
    );
    assert!(
        rejected(&set(20, u32::MAX))
            .to_string()
            .contains("truncated")
    );
    // A face naming a missing vertex: the error gives the face's offset.
    match rejected(&set(HEADER + 12 * 5, 10_000)) {
        Error::File { offset, reason, .. } => {
            assert_eq!(offset, (HEADER + 12 * 5) as u64);
            assert!(reason.contains("face 5"), "{reason}");
        }
        e => panic!("{e}"),
    }
    // A level above the cap, and one that changes the sample count.
    let faces = mc.face_count();
    let levels_at = HEADER + 12 * faces;
    let mut b = bytes.clone();
    b[levels_at + 3] = 11;
    assert!(rejected(&b).to_string().contains("level 11"));
    let mut b = bytes.clone();
    b[levels_at] = (b[levels_at] + 1) % 5;
    assert!(matches!(rejected(&b), Error::File { .. }));
    // A non-manifold edge: make face 1 repeat face 0's edge a third time.
    let mut b = bytes.clone();
    let f0: Vec<u8> = b[HEADER..HEADER + 12].to_vec();
    b[HEADER + 12..HEADER + 24].copy_from_slice(&f0);
    assert!(matches!(rejected(&b), Error::File { .. }));
    // Faces that no longer match the stored topology hash (two faces
    // swapped: still a valid mesh, but not the one the file was made for).
    let mut b = bytes.clone();
    let (f0, f1) = (
        b[HEADER..HEADER + 12].to_vec(),
        b[HEADER + 12..HEADER + 24].to_vec(),
    );
    b[HEADER..HEADER + 12].copy_from_slice(&f1);
    b[HEADER + 12..HEADER + 24].copy_from_slice(&f0);
    let e = rejected(&b);
    assert!(e.to_string().contains("topology hash"), "{e}");
}

/// Version 2's header: version 1's 28 bytes and the 8-byte topology hash.
const HEADER: usize = 36;

#[test]
fn colours_load_only_for_the_mesh_they_belong_to() {
    let mc = sample_colors();
    let mine = mc.topology().fingerprint();
    assert_eq!(
        mine,
        Fingerprint::of(mc.topology().vertex_count(), mc.topology().faces())
    );
    let bytes = file::to_bytes(&mc, None).unwrap();
    assert!(file::from_bytes_for(&bytes, &mine).is_ok());

    // The same counts, another connectivity (one face turned): refused.
    let mut faces = mc.topology().faces().to_vec();
    faces[3] = [faces[3][1], faces[3][2], faces[3][0]];
    let other = Fingerprint::of(mc.topology().vertex_count(), &faces);
    assert_eq!((other.vertices, other.faces), (mine.vertices, mine.faces));
    assert_ne!(other.topology_hash, mine.topology_hash);
    match file::from_bytes_for(&bytes, &other) {
        Err(Error::WrongMesh { stored, expected }) => {
            assert_eq!((stored, expected), (mine, other));
        }
        r => panic!("expected WrongMesh, got {:?}", r.map(|_| ())),
    }
    // Another vertex count, through a file on disk: the message names both.
    let path = std::env::temp_dir().join(format!(
        "mesh-colors-wrong-mesh-{}.meshcolors",
        std::process::id()
    ));
    file::save(&path, &mc, None).unwrap();
    let bigger = Fingerprint::of(mc.topology().vertex_count() + 1, mc.topology().faces());
    let e = file::load_for(&path, &bigger).unwrap_err();
    assert!(file::load_for(&path, &mine).is_ok());
    std::fs::remove_file(&path).unwrap();
    let message = e.to_string();
    assert!(
        message.contains(&format!("{} vertices", mine.vertices))
            && message.contains(&format!("{} vertices", bigger.vertices)),
        "{message}"
    );

    // Version 1 files (no stored hash) are read, and checked by their faces.
    let mut v1 = bytes[..28].to_vec();
    v1[8..12].copy_from_slice(&1u32.to_le_bytes());
    v1.extend_from_slice(&bytes[HEADER..]);
    let (back, _) = file::from_bytes_for(&v1, &mine).unwrap();
    assert_eq!(back.samples().len(), mc.samples().len());
    assert!(file::from_bytes_for(&v1, &other).is_err());
}

#[test]
fn random_bytes_never_panic() {
    let mut rng = Rng(42);
    let good = file::to_bytes(&sample_colors(), None).unwrap();
    for round in 0..3000 {
        let mut b: Vec<u8> = if round % 2 == 0 {
            // Random bytes after a valid magic, version and small counts.
            let len = rng.below(400) as usize;
            let mut b: Vec<u8> = (0..len).map(|_| rng.next_u64() as u8).collect();
            if b.len() >= 12 {
                b[..8].copy_from_slice(&file::MAGIC);
                b[8..12].copy_from_slice(&1u32.to_le_bytes());
            }
            b
        } else {
            good.clone()
        };
        // Flip a few bytes anywhere.
        for _ in 0..1 + rng.below(4) {
            if !b.is_empty() {
                let i = rng.below(b.len() as u64) as usize;
                b[i] ^= 1 << rng.below(8);
            }
        }
        let _ = file::from_bytes(&b);
    }
}
