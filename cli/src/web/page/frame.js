// The 16-byte header of binary frames (web/frame.rs): magic, version,
// kind, flags, tag, then two little-endian u32 (a, b). Each app owns its
// magic and version.

// The header of `buffer`: {kind, flags, tag, a, b}; an error when the
// magic or version is not the app's.
export function readHeader(buffer, magic, version) {
  const h = new DataView(buffer, 0, 16);
  const m = String.fromCharCode(h.getUint8(0), h.getUint8(1), h.getUint8(2), h.getUint8(3));
  if (m !== magic || h.getUint8(4) !== version) throw new Error('unknown frame (magic ' + m + ', version ' + h.getUint8(4) + ')');
  return { kind: h.getUint8(5), flags: h.getUint8(6), tag: h.getUint8(7), a: h.getUint32(8, true), b: h.getUint32(12, true) };
}

// The header of an upload (page → server): magic, version, kind, two
// zero bytes, then the seq as a little-endian u64.
export function uploadHeader({ magic, version, kind }, seq) {
  const h = new Uint8Array(16);
  for (let i = 0; i < 4; i++) h[i] = magic.charCodeAt(i);
  h[4] = version; h[5] = kind;
  new DataView(h.buffer).setBigUint64(8, BigInt(seq), true);
  return h;
}
