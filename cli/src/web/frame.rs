//! Binary frames: a fixed 16-byte header, then raw little-endian arrays.
//! Each app owns its magic and version (bump the version when a payload
//! changes); the page's `frame.js` reads the same header.
//!
//! | bytes | field |
//! |---|---|
//! | 0..4 | magic |
//! | 4 | version |
//! | 5 | kind |
//! | 6 | flags |
//! | 7 | tag (view: the piece index) |
//! | 8..12 | `a`, u32 |
//! | 12..16 | `b`, u32 |

/// Header size.
pub const HEADER: usize = 16;

/// A frame's header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Header {
    /// The app's magic.
    pub magic: [u8; 4],
    /// The app's frame version.
    pub version: u8,
    /// What the payload holds.
    pub kind: u8,
    /// Flags of the kind.
    pub flags: u8,
    /// A small tag of the kind.
    pub tag: u8,
    /// A count of the kind.
    pub a: u32,
    /// Another count or id of the kind.
    pub b: u32,
}

impl Header {
    /// The 16 header bytes.
    pub fn bytes(&self) -> [u8; HEADER] {
        let mut h = [0u8; HEADER];
        h[..4].copy_from_slice(&self.magic);
        h[4..8].copy_from_slice(&[self.version, self.kind, self.flags, self.tag]);
        h[8..12].copy_from_slice(&self.a.to_le_bytes());
        h[12..16].copy_from_slice(&self.b.to_le_bytes());
        h
    }

    /// The header, then `payload`.
    pub fn frame(&self, payload: &[u8]) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER + payload.len());
        out.extend_from_slice(&self.bytes());
        out.extend_from_slice(payload);
        out
    }

    /// The header at the start of `bytes`; `None` when shorter.
    pub fn read(bytes: &[u8]) -> Option<Self> {
        let h: &[u8; HEADER] = bytes.get(..HEADER)?.try_into().ok()?;
        let word = |i: usize| u32::from_le_bytes([h[i], h[i + 1], h[i + 2], h[i + 3]]);
        Some(Self {
            magic: [h[0], h[1], h[2], h[3]],
            version: h[4],
            kind: h[5],
            flags: h[6],
            tag: h[7],
            a: word(8),
            b: word(12),
        })
    }
}

/// Appends `values` as little-endian f32.
pub fn put_f32(out: &mut Vec<u8>, values: impl IntoIterator<Item = f32>) {
    put_words(out, values.into_iter().map(f32::to_bits));
}

/// Appends `values` as little-endian u32.
pub fn put_u32(out: &mut Vec<u8>, values: impl IntoIterator<Item = u32>) {
    put_words(out, values.into_iter());
}

/// Appends a slice of `f32` or `u32` (a texture's texels, tens of
/// megabytes) little-endian: one copy on a little-endian machine, word by
/// word on another.
pub fn put_slice<T: bytemuck::NoUninit + LeWord>(out: &mut Vec<u8>, words: &[T]) {
    if cfg!(target_endian = "little") {
        out.extend_from_slice(bytemuck::cast_slice(words));
    } else {
        put_words(out, words.iter().map(|w| w.word()));
    }
}

/// A 4-byte word of a frame.
pub trait LeWord: Copy {
    /// Its bits as a `u32`.
    fn word(self) -> u32;
}

impl LeWord for f32 {
    fn word(self) -> u32 {
        self.to_bits()
    }
}

impl LeWord for u32 {
    fn word(self) -> u32 {
        self
    }
}

/// Appends `words` little-endian, reserving their size once: a paint
/// page's sample texture is tens of megabytes, which growing by doubling
/// would copy again and again.
fn put_words(out: &mut Vec<u8>, mut words: impl Iterator<Item = u32>) {
    // The words the iterator promises go into bytes allocated at once (a
    // loop without a capacity check per word); any beyond, one by one.
    let start = out.len();
    out.resize(start + words.size_hint().0 * 4, 0);
    let mut written = start;
    for (bytes, w) in out[start..].chunks_exact_mut(4).zip(&mut words) {
        bytes.copy_from_slice(&w.to_le_bytes());
        written += 4;
    }
    out.truncate(written);
    for w in words {
        out.extend_from_slice(&w.to_le_bytes());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slice_is_written_as_its_words_one_by_one() {
        let floats = [1.5f32, -0.0, f32::MAX, f32::from_bits(0x7fc0_0001), 3.0e-39];
        let (mut fast, mut slow) = (vec![7u8], vec![7u8]);
        put_slice(&mut fast, &floats);
        put_f32(&mut slow, floats);
        assert_eq!(fast, slow);
        let words = [0u32, 1, 0xdead_beef, u32::MAX];
        let (mut fast, mut slow) = (Vec::new(), Vec::new());
        put_slice(&mut fast, &words);
        put_u32(&mut slow, words);
        assert_eq!(fast, slow);
        assert_eq!(&fast[8..12], &[0xef, 0xbe, 0xad, 0xde]);
    }

    #[test]
    fn a_header_reads_back_and_short_input_is_none() {
        let h = Header {
            magic: *b"TEST",
            version: 3,
            kind: 2,
            flags: 1,
            tag: 9,
            a: 0x0102_0304,
            b: u32::MAX,
        };
        let f = h.frame(&[7, 8]);
        assert_eq!(&f[..4], b"TEST");
        assert_eq!(&f[8..12], &[4, 3, 2, 1]);
        assert_eq!(&f[HEADER..], &[7, 8]);
        assert_eq!(Header::read(&f), Some(h));
        assert_eq!(Header::read(&f[..HEADER - 1]), None);
        let mut v = Vec::new();
        put_f32(&mut v, [1.0]);
        put_u32(&mut v, [2]);
        assert_eq!(v, [0, 0, 128, 63, 2, 0, 0, 0]);
    }

    #[test]
    fn words_are_the_same_bytes_whatever_the_iterator_promises() {
        let words: Vec<u32> = (0..1000u32).map(|i| i.wrapping_mul(0x9E37_79B9)).collect();
        let want: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        // Exact size, no size known (filter), and after earlier bytes.
        let mut exact = Vec::new();
        put_u32(&mut exact, words.iter().copied());
        let mut unknown = Vec::new();
        put_u32(&mut unknown, words.iter().copied().filter(|_| true));
        let mut after = vec![9u8];
        put_f32(&mut after, words.iter().map(|&w| f32::from_bits(w)));
        assert_eq!(exact, want);
        assert_eq!(unknown, want);
        assert_eq!(after[0], 9);
        assert_eq!(&after[1..], &want[..]);
    }
}
