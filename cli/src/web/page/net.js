// The WebSocket to the server: JSON requests with a sequence number up
// (and binary uploads), JSON messages and binary frames down. It
// reconnects after a drop; the server kept the app's state.

import { uploadHeader } from './frame.js';

export class Connection {
  // `app` names the app in what the page shows ("trilux view is not
  // answering"); `decode(buffer)` turns a binary frame into what
  // `onFrame` takes; `protocol` is the frames' version this page reads,
  // which the server's hello must name (else the page asks for a reload
  // and reads nothing more).
  constructor(app, decode, onText, onFrame, onState, protocol = 1) {
    this.protocol = protocol;
    // Each page starts its numbers at random: the server's status lists
    // the seqs it answered to every page, and two tabs that both counted
    // from 1 would take each other's answers for their own.
    this.seq = Math.floor(Math.random() * 2 ** 30);
    this.app = app; this.decode = decode;
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
        ? 'trilux ' + this.app + ' is not answering (stopped?): start it again and open the URL it prints; retrying…'
        : 'disconnected; reconnecting…');
      setTimeout(() => this.open(), 1000);
    };
    ws.onmessage = (e) => {
      if (this.stale) return;
      if (typeof e.data !== 'string') { this.onFrame(this.decode(e.data)); return; }
      const m = JSON.parse(e.data);
      if (m.type === 'hello' && m.protocol !== undefined && (m.app !== this.app || m.protocol !== this.protocol)) {
        this.stale = true;
        this.onState(`this page reads trilux ${this.app} protocol ${this.protocol}, the server speaks ${m.app} ${m.protocol}: reload the page`);
        return;
      }
      this.onText(m);
    };
    this.ws = ws;
  }
  // The request's sequence number, or null when there is no connection
  // (the request is not sent, so no answer will come).
  send(op, fields = {}) {
    if (this.ws.readyState !== WebSocket.OPEN) return null;
    const seq = ++this.seq;
    this.ws.send(JSON.stringify({ seq, op, ...fields }));
    return seq;
  }
  // A binary upload of `bytes` behind the 16-byte header `head` names
  // ({magic, version, kind}, see frame.js), which carries the seq.
  upload(head, bytes) {
    if (this.ws.readyState !== WebSocket.OPEN) return null;
    const seq = ++this.seq;
    const m = new Uint8Array(16 + bytes.length);
    m.set(uploadHeader(head, seq));
    m.set(bytes, 16);
    this.ws.send(m);
    return seq;
  }
}
