// trilux view's binary frames (view/protocol.rs): TLXF version 1 down
// (surfaces and radiance), TLXU version 1 up (environment maps).

import { readHeader } from './frame.js';

export const SURFACE = 1, RADIANCE = 2, FINAL = 1, LAST = 2;
// The header of an environment-map upload.
export const ENVIRONMENT_UPLOAD = { magic: 'TLXU', version: 1, kind: 1 };

export function parseFrame(buffer) {
  const { kind, flags, tag: piece, a, b } = readHeader(buffer, 'TLXF', 1);
  if (kind === SURFACE) {
    return { kind, flags, piece, positions: new Float32Array(buffer, 16, a * 3),
      normals: new Float32Array(buffer, 16 + a * 12, a * 3),
      indices: new Uint32Array(buffer, 16 + a * 24, b * 3) };
  }
  return { kind, flags, piece, seq: b, radiance: new Float32Array(buffer, 16, a * 3) };
}
