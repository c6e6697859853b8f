//! Image bytes (the first byte picks PNG, JPEG, Radiance HDR or OpenEXR),
//! decoded under a small memory budget: no panic, no allocation beyond
//! the budget; an image must be consistent.
#![no_main]

use libfuzzer_sys::fuzz_target;
use trilux_io::image::{ReadOptions, decode};

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else {
        return;
    };
    let name = ["fuzz.png", "fuzz.jpg", "fuzz.hdr", "fuzz.exr"][usize::from(pick % 4)];
    let options = ReadOptions {
        max_dimension: 4096,
        max_bytes: 64 << 20,
        ..ReadOptions::default()
    };
    if let Ok(image) = decode(bytes, name, options) {
        assert_eq!(
            image.pixels.len() as u64,
            u64::from(image.width) * u64::from(image.height)
        );
    }
});
