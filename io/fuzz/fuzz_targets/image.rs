//! Image bytes (the first byte picks PNG, JPEG, Radiance HDR or OpenEXR),
//! decoded under a small memory budget: no panic escapes, no allocation
//! beyond the budget; an image must be consistent.
#![no_main]

use libfuzzer_sys::fuzz_target;
use trilux_io::image::{ReadOptions, decode};

fuzz_target!(|data: &[u8]| {
    // libfuzzer-sys's panic hook aborts before `image::decode` can contain
    // a panic inside a codec; the default hook lets it unwind there, and a
    // panic anywhere else still aborts at the fuzzer's boundary.
    static DEFAULT_HOOK: std::sync::Once = std::sync::Once::new();
    DEFAULT_HOOK.call_once(|| drop(std::panic::take_hook()));
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
