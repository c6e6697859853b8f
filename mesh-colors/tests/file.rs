//! The `.meshcolors` format: bit-exact round trips, and corrupt, truncated
//! or random bytes rejected with an error (never a panic).

mod support;

use mesh_colors::{Error, MeshColors, Topology, file};
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
    assert!(rejected(&set(8, 2)).to_string().contains("version 2"));
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
    match rejected(&set(28 + 12 * 5, 10_000)) {
        Error::File { offset, reason } => {
            assert_eq!(offset, 28 + 12 * 5);
            assert!(reason.contains("face 5"), "{reason}");
        }
        e => panic!("{e}"),
    }
    // A level above the cap, and one that changes the sample count.
    let faces = mc.face_count();
    let levels_at = 28 + 12 * faces;
    let mut b = bytes.clone();
    b[levels_at + 3] = 11;
    assert!(rejected(&b).to_string().contains("level 11"));
    let mut b = bytes.clone();
    b[levels_at] = (b[levels_at] + 1) % 5;
    assert!(matches!(rejected(&b), Error::File { .. }));
    // A non-manifold edge: make face 1 repeat face 0's edge a third time.
    let mut b = bytes.clone();
    let f0: Vec<u8> = b[28..40].to_vec();
    b[40..52].copy_from_slice(&f0);
    assert!(matches!(rejected(&b), Error::File { .. }));
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
