// The WebSocket to the server: JSON edits with a sequence number up (and
// environment maps as binary uploads),
// JSON status and binary frames (16-byte header, little-endian arrays)
// down. It reconnects after a drop; the server kept the session.

export const SURFACE = 1, RADIANCE = 2, FINAL = 1, LAST = 2;

export function parseFrame(buffer) {
  const h = new DataView(buffer, 0, 16);
  const magic = String.fromCharCode(h.getUint8(0), h.getUint8(1), h.getUint8(2), h.getUint8(3));
  if (magic !== 'TLXF' || h.getUint8(4) !== 1) throw new Error('unknown frame (magic ' + magic + ', version ' + h.getUint8(4) + ')');
  const kind = h.getUint8(5), flags = h.getUint8(6), piece = h.getUint8(7);
  const a = h.getUint32(8, true), b = h.getUint32(12, true);
  if (kind === SURFACE) {
    return { kind, flags, piece, positions: new Float32Array(buffer, 16, a * 3),
      normals: new Float32Array(buffer, 16 + a * 12, a * 3),
      indices: new Uint32Array(buffer, 16 + a * 24, b * 3) };
  }
  return { kind, flags, piece, seq: b, radiance: new Float32Array(buffer, 16, a * 3) };
}

export class Connection {
  constructor(onText, onFrame, onState) {
    this.seq = 0;
    this.onText = onText; this.onFrame = onFrame; this.onState = onState;
    this.open();
  }
  open() {
    const url = location.href.replace(/^http/, 'ws').replace(/[^/]*$/, '') + 'ws';
    const ws = new WebSocket(url);
    ws.binaryType = 'arraybuffer';
    ws.onopen = () => { this.failures = 0; this.onState('connected'); };
    // A server stopped with Ctrl+C never comes back under this token:
    // after a few failed tries, say so rather than "reconnecting" forever.
    ws.onclose = () => {
      this.failures = (this.failures || 0) + 1;
      this.onState(this.failures > 3
        ? 'trilux view is not answering (stopped?): start it again and open the URL it prints; retrying…'
        : 'disconnected; reconnecting…');
      setTimeout(() => this.open(), 1000);
    };
    ws.onmessage = (e) => {
      if (typeof e.data === 'string') this.onText(JSON.parse(e.data));
      else this.onFrame(parseFrame(e.data));
    };
    this.ws = ws;
  }
  // The edit's sequence number, or null when there is no connection (the
  // edit is not sent, so no answer will come).
  send(op, fields = {}) {
    if (this.ws.readyState !== WebSocket.OPEN) return null;
    const seq = ++this.seq;
    this.ws.send(JSON.stringify({ seq, op, ...fields }));
    return seq;
  }
  // An environment-map upload: the 16-byte header (TLXU, version 1, kind
  // 1, the seq as u64) and the .hdr file's bytes (none: remove the map).
  upload(bytes) {
    if (this.ws.readyState !== WebSocket.OPEN) return null;
    const seq = ++this.seq;
    const m = new Uint8Array(16 + bytes.length);
    m.set([0x54, 0x4c, 0x58, 0x55, 1, 1, 0, 0]);
    new DataView(m.buffer).setBigUint64(8, BigInt(seq), true);
    m.set(bytes, 16);
    this.ws.send(m);
    return seq;
  }
}
