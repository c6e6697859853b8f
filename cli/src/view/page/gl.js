// WebGL2 drawing of the pieces' surfaces with the server's per-vertex
// radiance (Eq. 3 at normal exitance). Per fragment: the view-dependent
// Fresnel factor F_t(η, ω_o) / F_t(η, 0°) of Eq. 3 (so orbiting never
// shows stale radiance), an optional Cook–Torrance specular term for the
// directional light, exposure, and the sRGB encoding the CLI's PNGs use.
// The exposure's white is measured as the CLI measures it for a PNG: the
// 99th percentile of the luminance of the pixels the object covers (a
// small offscreen pass writes each covered pixel's log-luminance).

import { program, fitCanvas, offscreen } from './glutil.js';
import { pick } from './pick.js';

const VS = `#version 300 es
in vec3 position; in vec3 normal; in vec3 radiance;
uniform mat4 viewProj; uniform vec3 offset;
out vec3 vNormal; out vec3 vRadiance; out vec3 vWorld;
void main() {
  vec3 p = position + offset;
  vWorld = p; vNormal = normal; vRadiance = radiance;
  gl_Position = viewProj * vec4(p, 1.0);
}`;

const FS = `#version 300 es
precision highp float;
in vec3 vNormal; in vec3 vRadiance; in vec3 vWorld;
uniform vec3 eye; uniform float eta; uniform float exposure;
uniform vec3 lightDir; uniform vec3 lightRgb; uniform float specular; uniform float unitScale;
uniform float measure;
out vec4 color;
float transmittance(float c) {
  c = clamp(c, 0.0, 1.0);
  float s2 = (1.0 - c * c) / (eta * eta);
  if (s2 >= 1.0) return 0.0;
  float ct = sqrt(1.0 - s2);
  float rp = (eta * c - ct) / (eta * c + ct);
  float rs = (c - eta * ct) / (c + eta * ct);
  return 1.0 - 0.5 * (rp * rp + rs * rs);
}
float srgb(float x) { return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055; }
void main() {
  vec3 n = normalize(vNormal);
  vec3 v = normalize(eye - vWorld);
  float ft0 = transmittance(1.0);
  vec3 L = vRadiance * (transmittance(dot(n, v)) / ft0);
  if (specular > 0.5) {
    // Cook–Torrance: GGX distribution, Smith shadowing, Schlick Fresnel.
    vec3 l = normalize(lightDir);
    float nl = dot(n, l), nv = max(dot(n, v), 1e-4);
    if (nl > 0.0) {
      vec3 h = normalize(l + v);
      float nh = max(dot(n, h), 0.0), a = 0.15, a2 = a * a;
      float d = a2 / (3.14159265 * pow(nh * nh * (a2 - 1.0) + 1.0, 2.0));
      float k = a / 2.0;
      float g = (nl / (nl * (1.0 - k) + k)) * (nv / (nv * (1.0 - k) + k));
      float f0 = pow((eta - 1.0) / (eta + 1.0), 2.0);
      float f = f0 + (1.0 - f0) * pow(1.0 - max(dot(h, v), 0.0), 5.0);
      L += lightRgb * (d * g * f / (4.0 * nv)) * unitScale;
    }
  }
  if (measure > 0.5) {
    // log2 of the luminance in [-64, 64), 16 bits over red and green; alpha
    // marks a covered pixel.
    float lum = dot(L, vec3(0.2126, 0.7152, 0.0722));
    if (lum <= 0.0) { color = vec4(0.0, 0.0, 1.0, 1.0); return; }
    float v = clamp((log2(lum) + 64.0) / 128.0, 0.0, 1.0) * 65535.0;
    float hi = floor(v / 256.0);
    color = vec4(hi / 255.0, (v - hi * 256.0) / 255.0, 0.0, 1.0);
    return;
  }
  vec3 c = L * exposure;
  color = vec4(srgb(clamp(c.r, 0.0, 1.0)), srgb(clamp(c.g, 0.0, 1.0)), srgb(clamp(c.b, 0.0, 1.0)), 1.0);
}`;

export class Renderer {
  constructor(canvas) {
    const gl = canvas.getContext('webgl2', { antialias: true, preserveDrawingBuffer: true });
    if (!gl) throw new Error('WebGL2 is not available in this browser');
    this.gl = gl;
    const p = program(gl, VS, FS);
    this.program = p;
    this.loc = {};
    for (const u of ['viewProj', 'offset', 'eye', 'eta', 'exposure', 'lightDir', 'lightRgb', 'specular', 'unitScale', 'measure'])
      this.loc[u] = gl.getUniformLocation(p, u);
    this.pieces = [];
    this.frames = 0;
  }

  // A surface frame: positions, normals (f32 × 3 each) and triangles.
  setSurface(piece, positions, normals, indices) {
    const gl = this.gl;
    const old = this.pieces[piece];
    if (old) for (const b of [old.pos, old.nor, old.rad, old.idx]) gl.deleteBuffer(b);
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    const buffer = (data, attr, target = gl.ARRAY_BUFFER) => {
      const b = gl.createBuffer();
      gl.bindBuffer(target, b);
      gl.bufferData(target, data, gl.DYNAMIC_DRAW);
      if (attr !== null) {
        const l = gl.getAttribLocation(this.program, attr);
        gl.enableVertexAttribArray(l);
        gl.vertexAttribPointer(l, 3, gl.FLOAT, false, 0, 0);
      }
      return b;
    };
    const rad = new Float32Array(positions.length);
    this.pieces[piece] = {
      vao, count: indices.length, vertices: positions.length / 3,
      positions, normals, indices, radiance: rad,
      pos: buffer(positions, 'position'), nor: buffer(normals, 'normal'), rad: buffer(rad, 'radiance'),
      idx: buffer(indices, null, gl.ELEMENT_ARRAY_BUFFER), offset: [0, 0, 0],
    };
    gl.bindVertexArray(null);
  }

  dropPiecesFrom(n) {
    this.pieces.length = Math.min(this.pieces.length, n);
  }

  setRadiance(piece, values) {
    const p = this.pieces[piece];
    if (!p || values.length !== p.vertices * 3) return false;
    p.radiance = values;
    const gl = this.gl;
    gl.bindBuffer(gl.ARRAY_BUFFER, p.rad);
    gl.bufferData(gl.ARRAY_BUFFER, values, gl.DYNAMIC_DRAW);
    return true;
  }

  draw(camera, opts) {
    const gl = this.gl;
    const c = gl.canvas;
    fitCanvas(c);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.viewport(0, 0, c.width, c.height);
    gl.clearColor(0.106, 0.11, 0.122, 1);
    this.pass(camera, opts, c.width / c.height, 0);
    this.frames++;
  }

  // One drawing of the pieces into the bound framebuffer (cleared first).
  pass(camera, opts, aspect, measure) {
    const gl = this.gl;
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(this.program);
    gl.uniform1f(this.loc.measure, measure);
    gl.uniformMatrix4fv(this.loc.viewProj, false, camera.viewProj(aspect));
    gl.uniform3fv(this.loc.eye, camera.eye());
    gl.uniform1f(this.loc.eta, opts.eta);
    gl.uniform1f(this.loc.exposure, opts.exposure);
    gl.uniform3fv(this.loc.lightDir, opts.lightDir);
    gl.uniform3fv(this.loc.lightRgb, opts.lightRgb);
    gl.uniform1f(this.loc.specular, opts.specular ? 1 : 0);
    gl.uniform1f(this.loc.unitScale, 0.04 / (4 * Math.PI));
    for (const p of this.pieces) {
      if (!p) continue;
      gl.uniform3fv(this.loc.offset, p.offset);
      gl.bindVertexArray(p.vao);
      gl.drawElements(gl.TRIANGLES, p.count, gl.UNSIGNED_INT, 0);
    }
    gl.bindVertexArray(null);
  }

  // The exposure's white as the CLI's PNGs have it: the 99th percentile of
  // the luminance of the pixels the object covers (background excluded),
  // from a drawing at most 256 pixels wide with the canvas's aspect.
  // `opts` as for draw (exposure unused). Returns null when nothing is
  // covered.
  measureWhite(camera, opts) {
    const gl = this.gl;
    const c = gl.canvas;
    const aspect = c.width / Math.max(c.height, 1);
    const w = Math.max(16, Math.min(256, c.width)), h = Math.max(16, Math.round(w / aspect));
    this.fbo = offscreen(gl, this.fbo, w, h);
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.fbo.fb);
    gl.viewport(0, 0, w, h);
    gl.clearColor(0, 0, 0, 0);
    this.pass(camera, opts, aspect, 1);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, this.fbo.pixels);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    const px = this.fbo.pixels, lum = [];
    let covered = 0;
    for (let i = 0; i < px.length; i += 4) {
      if (px[i + 3] < 128) continue;
      covered++;
      if (px[i + 2] > 128) continue; // covered, luminance 0
      const v = (px[i] * 256 + px[i + 1]) / 65535;
      lum.push(Math.pow(2, v * 128 - 64));
    }
    if (!covered) return null;
    lum.sort((a, b) => a - b);
    return { white: lum.length ? Math.max(lum[Math.floor(lum.length * 0.99)], 1e-12) : 1, covered };
  }

  // The nearest surface hit of a ray (origin o, direction d): {piece,
  // point, t} (and the triangle and its barycentrics), or null.
  pick(o, d) {
    return pick(this.pieces, o, d);
  }
}
