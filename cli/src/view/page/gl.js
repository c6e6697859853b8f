// WebGL2 drawing of the pieces' surfaces with the server's per-vertex
// radiance (Eq. 3 at normal exitance). Per fragment: the view-dependent
// Fresnel factor F_t(η, ω_o) / F_t(η, 0°) of Eq. 3 (so orbiting never
// shows stale radiance), an optional Cook–Torrance specular term for the
// directional light, exposure, and the sRGB encoding the CLI's PNGs use.
// The exposure's white is measured as the CLI measures it for a PNG: the
// 99th percentile of the luminance of the pixels the object covers (a
// small offscreen pass writes each covered pixel's log-luminance).

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

function shader(gl, type, text) {
  const s = gl.createShader(type);
  gl.shaderSource(s, text);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}

export class Renderer {
  constructor(canvas) {
    const gl = canvas.getContext('webgl2', { antialias: true, preserveDrawingBuffer: true });
    if (!gl) throw new Error('WebGL2 is not available in this browser');
    this.gl = gl;
    const p = gl.createProgram();
    gl.attachShader(p, shader(gl, gl.VERTEX_SHADER, VS));
    gl.attachShader(p, shader(gl, gl.FRAGMENT_SHADER, FS));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
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
    const w = Math.floor(c.clientWidth * devicePixelRatio), h = Math.floor(c.clientHeight * devicePixelRatio);
    if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
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
    if (!this.fbo || this.fbo.w !== w || this.fbo.h !== h) {
      if (this.fbo) { gl.deleteFramebuffer(this.fbo.fb); gl.deleteTexture(this.fbo.tex); gl.deleteRenderbuffer(this.fbo.depth); }
      const tex = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA8, w, h);
      const depth = gl.createRenderbuffer();
      gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
      gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, w, h);
      const fb = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
      gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
      this.fbo = { fb, tex, depth, w, h, pixels: new Uint8Array(w * h * 4) };
    }
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

  // The nearest surface hit of a ray (origin o, direction d): {piece, point, t}.
  pick(o, d) {
    let best = null;
    this.pieces.forEach((p, k) => {
      if (!p) return;
      const P = p.positions, I = p.indices, off = p.offset;
      for (let i = 0; i < I.length; i += 3) {
        const a = I[i] * 3, b = I[i + 1] * 3, c = I[i + 2] * 3;
        const ax = P[a] + off[0], ay = P[a + 1] + off[1], az = P[a + 2] + off[2];
        const e1x = P[b] + off[0] - ax, e1y = P[b + 1] + off[1] - ay, e1z = P[b + 2] + off[2] - az;
        const e2x = P[c] + off[0] - ax, e2y = P[c + 1] + off[1] - ay, e2z = P[c + 2] + off[2] - az;
        const px = d[1] * e2z - d[2] * e2y, py = d[2] * e2x - d[0] * e2z, pz = d[0] * e2y - d[1] * e2x;
        const det = e1x * px + e1y * py + e1z * pz;
        if (Math.abs(det) < 1e-20) continue;
        const inv = 1 / det;
        const tx = o[0] - ax, ty = o[1] - ay, tz = o[2] - az;
        const u = (tx * px + ty * py + tz * pz) * inv;
        if (u < 0 || u > 1) continue;
        const qx = ty * e1z - tz * e1y, qy = tz * e1x - tx * e1z, qz = tx * e1y - ty * e1x;
        const v = (d[0] * qx + d[1] * qy + d[2] * qz) * inv;
        if (v < 0 || u + v > 1) continue;
        const t = (e2x * qx + e2y * qy + e2z * qz) * inv;
        if (t > 0 && (!best || t < best.t)) best = { piece: k, t, point: [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]] };
      }
    });
    return best;
  }
}
