// An orbit camera: target, distance, yaw and pitch; orbit, pan and zoom
// happen here, at display rate, without the server.

export function normalize(v) {
  const l = Math.hypot(v[0], v[1], v[2]) || 1;
  return [v[0] / l, v[1] / l, v[2] / l];
}
export function cross(a, b) {
  return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
}
export function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
const add = (a, b, s = 1) => [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]];

export class Camera {
  constructor(lo, hi) {
    this.target = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2];
    this.radius = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2 || 1;
    this.distance = this.radius * 2.8;
    this.yaw = 0.6; this.pitch = 0.35; this.fov = 0.8;
  }
  eye() {
    const c = Math.cos(this.pitch);
    return add(this.target, [c * Math.sin(this.yaw), Math.sin(this.pitch), c * Math.cos(this.yaw)], this.distance);
  }
  forward() { return normalize(add(this.target, this.eye(), -1)); }
  basis() {
    const f = this.forward();
    const r = normalize(cross(f, [0, 1, 0]));
    return { f, r, u: cross(r, f) };
  }
  // Looks at the target from direction `d` (target → eye), as a session
  // file's saved view gives it.
  lookFrom(d) {
    const [x, y, z] = normalize(d);
    this.pitch = Math.max(-1.5, Math.min(1.5, Math.asin(Math.max(-1, Math.min(1, y)))));
    this.yaw = Math.atan2(x, z);
  }
  orbit(dx, dy) {
    this.yaw -= dx * 0.008;
    this.pitch = Math.max(-1.5, Math.min(1.5, this.pitch + dy * 0.008));
  }
  pan(dx, dy, height) {
    const { r, u } = this.basis();
    const s = 2 * this.distance * Math.tan(this.fov / 2) / height;
    this.target = add(add(this.target, r, -dx * s), u, dy * s);
  }
  zoom(factor) { this.distance = Math.max(this.radius * 0.05, Math.min(this.radius * 50, this.distance * factor)); }
  viewProj(aspect) {
    const e = this.eye(), { f, r, u } = this.basis();
    const near = this.distance * 0.01, far = this.distance + this.radius * 20;
    const t = 1 / Math.tan(this.fov / 2);
    const view = [r[0], u[0], -f[0], 0, r[1], u[1], -f[1], 0, r[2], u[2], -f[2], 0,
      -dot(r, e), -dot(u, e), dot(f, e), 1];
    const proj = [t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, (far + near) / (near - far), -1, 0, 0, 2 * far * near / (near - far), 0];
    const m = new Float32Array(16);
    for (let i = 0; i < 4; i++) for (let j = 0; j < 4; j++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += proj[k * 4 + j] * view[i * 4 + k];
      m[i * 4 + j] = s;
    }
    return m;
  }
  // The ray through pixel (x, y) of a w × h view: {o, d}.
  ray(x, y, w, h) {
    const { f, r, u } = this.basis();
    const t = Math.tan(this.fov / 2);
    const sx = (2 * x / w - 1) * t * (w / h), sy = (1 - 2 * y / h) * t;
    return { o: this.eye(), d: normalize(add(add(f, r, sx), u, sy)) };
  }
  // The point of pixel (x, y) on the plane through the target facing the camera.
  onPlane(x, y, w, h) {
    const { o, d } = this.ray(x, y, w, h);
    const f = this.forward();
    const s = dot(add(this.target, o, -1), f) / dot(d, f);
    return add(o, d, s);
  }
}
