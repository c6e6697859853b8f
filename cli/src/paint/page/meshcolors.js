// Mesh colours on the GPU (Yuksel, Keyser & House 2010, Sec. 5.3): every
// sample and MIP level of a mesh_colors::gpu::GpuLayout in an RGBA32F
// texture, its per-face table in an RGBA32UI texture, and a fragment shader
// that filters per face exactly as the CPU filters do. The formulas are the
// ones gpu.rs's module documentation states (steps 1-4 below), with the
// products and sums of GpuLayout::lookup associated as there, so the GPU's
// value equals the CPU's to an ulp or two (the parity test,
// cli/tests/all/paint_shader.rs, holds the 8-bit output within 1/255).
//
// Geometry: unindexed triangles, three vertices per face in face order, so
// the face id is gl_VertexID / 3 and corner k of a face gets the
// barycentric e_k. No attribute but the position is needed: the vertex
// shader fetches its face's table entry by that id and passes it decoded
// as flat varyings, so no fragment reads the table.
//
// Cost in SwiftShader (software WebGL: four fragments run at once through
// every path any of them takes, integer division lane by lane) shaped the
// code: one program per filter, display and output; no integer division;
// the rare corner and edge cases in loops that run once or not at all
// (a quad that needs neither skips them). The Table I bench is in
// cli/tests/all/paint_shader.rs.
//
// Usage:
//   const mc = new MeshColorsRenderer(gl);
//   mc.setMesh(positions, triangles);      // Float32Array xyz, Uint32Array abc
//   mc.setLayout(parts);                   // {width, channels, samples, faces}
//   mc.updateRects(changes, parts);        // after GpuLayout::update
//   mc.draw(viewProj, { filter: 'trilinear' });
//   const hit = mc.pick(viewProj, x, y, w, h);  // face and barycentrics under a pixel

// Face table words (gpu.rs, "Face table"): w0 = F, w1..w3 = V_k, w4..w6 =
// E_k, w7 = packed levels and edge directions.
const VS = `
precision highp float;
precision highp int;
precision highp usampler2D;
in vec3 position;
uniform mat4 viewProj;
uniform usampler2D faces;    // RGBA32UI, GpuLayout::face_texels
out vec3 vBary;
out vec3 vWorld;
// The face's table entry, decoded here (three times a face) instead of in
// every fragment: flat, so each fragment reads its face's words as they are.
flat out int vFace;
flat out float vTag;          // (face id mod 255 + 1) / 255 (tagAlpha)
flat out uvec4 vFV;          // w0..w3: F, V_0, V_1, V_2
flat out uvec3 vE;           // w4..w6: E_0, E_1, E_2
flat out ivec4 vLevels;      // n, vl_0, vl_1, vl_2 (at most MAX_LEVEL)
flat out ivec4 vEdges;       // el_0, el_1, el_2 (at most n), edge direction bits 0-2
const int MAX_LEVEL = 10;    // mesh_colors::MAX_LEVEL
void main() {
  vWorld = position;
  // drawArrays from 0: vertex 3f + k is corner k of face f.
  vFace = gl_VertexID / 3;
  int k = gl_VertexID - 3 * vFace;
  vTag = float(vFace % 255 + 1) / 255.0;
  vBary = vec3(k == 0, k == 1, k == 2);
  int w = textureSize(faces, 0).x;
  int t = 2 * vFace;
  uvec4 a = texelFetch(faces, ivec2(t % w, t / w), 0);
  uvec4 b = texelFetch(faces, ivec2((t + 1) % w, (t + 1) / w), 0);
  uint bits = b.w;
  vFV = a;
  vE = b.xyz;
  int n = min(int(bits & 15u), MAX_LEVEL);
  uvec3 shift = uvec3(0u, 4u, 8u);
  vLevels = ivec4(n, min(ivec3((uvec3(bits) >> (shift + 4u)) & 15u), ivec3(MAX_LEVEL)));
  // An edge is never finer than its face (as the CPU clamps it).
  ivec3 el = min(ivec3((uvec3(bits) >> (shift + 16u)) & 15u), ivec3(n));
#ifdef TWIN_EDGE_DIRECTION
  int fwd = 7;               // the wrong twin: every edge read from corner k
#else
  int fwd = int((bits >> 28u) & 7u);
#endif
  vEdges = ivec4(el, fwd);
  gl_Position = viewProj * vec4(position, 1.0);
}`;

const FS = `
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp usampler2D;

uniform sampler2D samples;   // RGBA32F, GpuLayout::sample_texels
uniform int perValue;        // P = ceil(channels / 4) texels per value
uniform int group;           // which texel of a value is shown (channel / 4)
// The filter, display and output are compile-time constants: one program
// per combination (MeshColorsRenderer.program), so that a program holds only
// its own path (SwiftShader runs every path of a program it cannot rule out).
const int filterMode = FILTER_MODE;  // 0 nearest, 1 linear, 2 level, 3 trilinear, 4 anisotropic
uniform int level;           // the level of filterMode 2
uniform int maxSamples;      // anisotropic probes at most
const int display = DISPLAY;  // 0 RGB of the group, 1 grey of one component, 2 heat map of it
uniform int component;       // the component (channel % 4) displays 1 and 2 show
uniform vec2 heatRange;      // the values mapped to the ends of the heat map
const int outputMode = OUTPUT_MODE;  // 0 colour; 1 pick: face, barycentrics and their derivatives
uniform bool tagAlpha;       // alpha = (face id mod 255 + 1) / 255, never 0 (lets a
                             // reader of the canvas tell which face a pixel shows; tests)

flat in int vFace;
flat in float vTag;
flat in uvec4 vFV;
flat in uvec3 vE;
flat in ivec4 vLevels;
flat in ivec4 vEdges;
in vec3 vBary;
in vec3 vWorld;
uniform float shade;         // 0: the colours as stored; > 0: lit by a headlight,
uniform vec3 eye;            // darker by up to shade where the surface turns away
layout(location = 0) out vec4 out0;
layout(location = 1) out vec4 out1;
layout(location = 2) out vec4 out2;

const int FINEST = 255;      // query level: every primitive at its finest
const int MAX_LEVEL = 10;    // mesh_colors::MAX_LEVEL
const int MAX_PROBES = 64;   // mesh_colors::MAX_PROBES

// Component k of a vector, by selection: SwiftShader runs four fragments
// at once, and a vector or array indexed by a per-fragment value costs far
// more there than a choice between three values.
uint pick(uvec3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }
int pick(ivec3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }
bool pick(bvec3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }
float pick(vec3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

// One face's table entry (View::decode), as the vertex shader decoded it.
struct Face {
  uint F; uvec3 V; uvec3 E;
  int n; ivec3 vl; ivec3 el;
  bvec3 fwd;                 // edge k runs canonically from corner k to k + 1
};
Face face;

void decode() {
  face.F = vFV.x;
  face.V = vFV.yzw;
  face.E = vE;
  face.n = vLevels.x;
  face.vl = vLevels.yzw;
  face.el = vEdges.xyz;
  face.fwd = notEqual(ivec3(vEdges.w) & ivec3(1, 2, 4), ivec3(0));
}

// Pyramid value i's shown texel: linear texel index t = i * P + group at
// (t % W, t / W), W the texture's width (WebGL2 has no texture buffers).
// The row comes from a float product and one correction step instead of
// an integer division, which a SIMD CPU (SwiftShader) does lane by lane:
// t < 2^24 (rows <= W <= 4096) is exact as a float, and the product's
// error is far below a row, so the estimate is the row or a neighbour.
uniform int rowTexels;        // W
uniform float rowScale;       // 1 / W
vec4 value(uint i) {
  int t = int(i * uint(perValue) + uint(group));
  int y = int(float(t) * rowScale);
  int x = t - y * rowTexels;
  y += x < 0 ? -1 : (x >= rowTexels ? 1 : 0);
  x += x < 0 ? rowTexels : (x >= rowTexels ? -rowTexels : 0);
  return texelFetch(samples, ivec2(x, y), 0);
}

// k + 1 mod 3. No integer division or remainder anywhere: SwiftShader
// divides lane by lane, even by a constant.
int next(int k) { return k == 2 ? 0 : k + 1; }

// Offsets of a level within an edge's and a face's levels (mip.rs):
// sum over m < l of 2^m - 1, and of (2^m - 1)(2^m - 2) / 2 in closed form
// ((4^l - 1) / 3 - 3 (2^l - 1) + 2l) / 2 (0, 0, 0, 3, 24, 129, ...), where
// (4^l - 1) / 3 = 4^0 + ... + 4^(l-1) is the bits of 0x55555 below bit 2l.
uint edgeLevelOffset(int l) { return uint((1 << l) - 1 - l); }
uint faceLevelOffset(int l) {
  uint quads = 0x55555u & ((1u << uint(2 * l)) - 1u);
  return (quads + uint(2 * l) - 3u * (uint(1 << l) - 1u)) >> 1;
}
// Interior sample C_ij of a face of resolution r (structure.rs).
uint interiorIndex(uint r, uint i, uint j) { return (i - 1u) * (r - 1u) - (((i - 1u) * i) >> 1) + (j - 1u); }

// Corner k seen at query level q (its own level, at most).
uint cornerIndex(int k, int q) { return pick(face.V, k) + uint(min(q, pick(face.vl, k))); }

// Node i of edge k at edge level le: its canonical start vertex (i = 0),
// its end vertex (i = 2^le) or its sample i.
uint nodeIndex(int k, int q, int le, uint i) {
  bool fwd = pick(face.fwd, k), atStart = i == 0u, atEnd = i == uint(1 << le);
  // The start is corner k on a forward edge, the end is then corner k + 1.
  uint corner = cornerIndex(atStart == fwd ? k : next(k), q);
  return atStart || atEnd ? corner : pick(face.E, k) + edgeLevelOffset(le) + i - 1u;
}

// Where a point lies (step 1): kind 0 corner k, 1 edge k at canonical
// parameter t, 2 inside with clamped barycentrics c.
struct Place { int kind; int k; float t; vec3 c; };

Place place(vec3 b) {
  vec3 c = vec3(b.x > 0.0 ? b.x : 0.0, b.y > 0.0 ? b.y : 0.0, b.z > 0.0 ? b.z : 0.0);
  int zeros = int(c.x == 0.0) + int(c.y == 0.0) + int(c.z == 0.0);
  if (zeros == 0) return Place(2, 0, 0.0, c);
  if (zeros == 3) return Place(2, 0, 0.0, vec3(1.0));
  if (zeros == 2) return Place(0, c.x > 0.0 ? 0 : (c.y > 0.0 ? 1 : 2), 0.0, c);
  int m = c.x == 0.0 ? 0 : (c.y == 0.0 ? 1 : 2);
  int k = next(m), k1 = next(k);
  float cs = pick(face.fwd, k) ? pick(c, k) : pick(c, k1);
  float ce = pick(face.fwd, k) ? pick(c, k1) : pick(c, k);
  return Place(1, k, ce / (cs + ce), c);
}

// The lattice triangle of resolution r around c (step 2, Fig. 7): its
// three points and weights.
void lattice3(vec3 c, uint r, out uvec3 p0, out uvec3 p1, out uvec3 p2, out vec3 w) {
  float s = float(r) / (c.x + c.y + c.z);
  float x = c.x * s, y = c.y * s;
  uint i = min(uint(x), r - 1u);
  uint j = min(uint(y), r - 1u - i);
  float fx = x - float(i), fy = y - float(j);
  uint k = r - i - j;
  if (fx + fy <= 1.0 || k == 1u) {
    p0 = uvec3(i, j, k); p1 = uvec3(i + 1u, j, k - 1u); p2 = uvec3(i, j + 1u, k - 1u);
    w = vec3(1.0 - fx - fy, fx, fy);
  } else {
    p0 = uvec3(i + 1u, j + 1u, k - 2u); p1 = uvec3(i + 1u, j, k - 1u); p2 = uvec3(i, j + 1u, k - 1u);
    w = vec3(fx + fy - 1.0, 1.0 - fy, 1.0 - fx);
  }
}

// Steps 1-3 at query level q: the value at one point of the face.
//
// The point resolves, per lattice point, to one or two weighted pyramid
// values: a corner, an interior sample, or an edge's nodes i and i + 1 at
// fraction fr (a face finer than its edge interpolates the edge: the
// continuity rule; nearest takes the closer node, the upper on a tie).
// Every case is computed and the right one selected rather than branched
// to, and the fetch is in one place: SwiftShader runs four fragments in
// lock step through every path any of them takes, and GLSL inlines every
// call, so a shader shaped like the CPU's call graph (a fetch and an early
// return at each call site) compiled for seconds and drew 20x slower, for
// the same arithmetic.
//
// The products associate as the CPU's: for nearest, linear and most MIP
// lookups each value adds (w_t x node weight) x value; where the CPU's MIP
// map reads its per-face cache of lattice values (a MIP lookup inside, at
// q <= n or at least the corners' finest level), each lattice value is
// formed first, then weighted.
vec4 levelValue(Place at, int q, bool nearest, bool mipOrder) {
  int cornerLevel = max(face.vl.x, max(face.vl.y, face.vl.z));
  bool inside = at.kind == 2;
  bool cached = mipOrder && inside && !(q > face.n && q < cornerLevel);
  int lf = min(q, face.n);
  uint r = uint(1 << lf);
  uvec3 p0, p1, p2;
  vec3 w;
  lattice3(at.c, r, p0, p1, p2, w);
  // Nearest: the largest weight, the first on a tie.
  int best = (w.x >= w.y && w.x >= w.z) ? 0 : (w.y >= w.z ? 1 : 2);
  vec4 acc = vec4(0.0);
  uint faceBase = face.F + faceLevelOffset(lf);
  for (int t = 0; t < (inside ? 3 : 1); t++) {
    if (inside && nearest && t != best) continue;
    uvec3 a = t == 0 ? p0 : (t == 1 ? p1 : p2);
    float wt = !inside || cached || nearest ? 1.0 : pick(w, t);
    // An interior lattice point (the common case): one sample.
    uint i0 = faceBase + interiorIndex(r, a.x, a.y), i1 = i0;
    bool two = false;
    vec2 tw = vec2(wt, 0.0);
    // A corner or an edge's node(s) otherwise. The loops below run once or
    // not at all: SwiftShader runs four fragments at once through both
    // sides of every if, but skips a loop none of the four enters, so
    // quads of interior points pay for neither this nor a second fetch.
    bool interior = inside && all(notEqual(a, uvec3(0u)));
    for (int g = interior ? 1 : 0; g < 1; g++) {
      bvec3 atCorner = equal(a, uvec3(r)), zero = equal(a, uvec3(0u));
      bool isCorner = inside ? any(atCorner) : at.kind == 0;
      bool isEdge = inside ? !isCorner && any(zero) : at.kind == 1;
      int ck = inside ? (atCorner.x ? 0 : (atCorner.y ? 1 : 2)) : at.k;
      int ek = inside ? (zero.x ? 1 : (zero.y ? 2 : 0)) : at.k;  // opposite the zero
      int le = min(q, pick(face.el, ek));
      // On the edge: a lattice point at canonical position p / 2^lf, exact
      // in steps of the edge's 2^-le; a placed point at parameter at.t.
      uint s = pick(a, next(ek));
      uint p = pick(face.fwd, ek) ? s : r - s;
      int d = max(lf - le, 0);
      float x = at.t * float(1 << le);
      uint i = inside ? p >> uint(d) : min(uint(x), uint(1 << le) - 1u);
      float fr = inside ? float(p & uint((1 << d) - 1)) / float(1 << d) : x - float(i);
      two = isEdge && !nearest && (fr != 0.0 || !inside);
      i0 = isCorner ? cornerIndex(ck, q) : nodeIndex(ek, q, le, i + (nearest && fr >= 0.5 ? 1u : 0u));
      i1 = nodeIndex(ek, q, le, i + 1u);
      tw = two ? vec2(wt * (1.0 - fr), wt * fr) : vec2(wt, 0.0);
    }
    vec4 y0 = tw.x * value(i0), y1 = vec4(0.0);
    for (int g = two ? 0 : 1; g < 1; g++) y1 = tw.y * value(i1);
    vec4 v = two ? y0 + y1 : y0;
    acc = cached ? acc + pick(w, t) * v : (two ? acc + y0 + y1 : acc + y0);
  }
  return acc;
}

// The level of a footprint w in barycentric units: -log2 w in [0, MAX_LEVEL]
// (mip.rs's level_of_footprint; the finest for w <= 0 or NaN).
float levelOfFootprint(float w) {
  if (!(w > 0.0)) return float(MAX_LEVEL);
  return clamp(-log2(w), 0.0, float(MAX_LEVEL));
}

// One probe at level lambda (step 4): the two levels around it blended,
// only where they differ for the primitive the point lies on (so both
// faces agree on a shared edge). Nearest and linear are lambda = FINEST,
// a MIP level lambda = that level: one level each (frac = 0).
vec4 probe(vec3 b, float lambda, bool nearest, bool mipOrder) {
  Place at = place(b);
  int top = at.kind == 0 ? pick(face.vl, at.k) : (at.kind == 1 ? pick(face.el, at.k) : face.n);
  float l0 = floor(lambda);
  float frac = lambda - l0;
  int l = int(l0);
  int levels = (l >= top || frac == 0.0) ? 1 : 2;
  vec4 v = vec4(0.0);
  for (int j = 0; j < levels; j++) {
    vec4 x = levelValue(at, l + j, nearest, mipOrder);
    v = j == 0 ? x : (1.0 - frac) * v + frac * x;
  }
  return v;
}

// A barycentric displacement's length on the equilateral triangle of unit
// edge (where the sample lattice is regular).
float metric(vec3 d) {
  float x = d.x + 0.5 * d.y, y = d.y * 0.8660254;
  return sqrt(x * x + y * y);
}

// The filtered value at the fragment. The screen derivatives dx = db/dx,
// dy = db/dy are the change of the barycentrics from one pixel to the next.
// Trilinear: the CPU's footprint (MipMap::trilinear's argument, the
// fraction of the face's edge a pixel covers) is the longer of the pixel's
// two axes measured by metric, GL's isotropic rho. Anisotropic (Sec. 4.3)
// takes the derivatives themselves (MipMap::anisotropic's db_dx, db_dy):
// up to maxSamples probes along the longer axis, clamped into the face, at
// the level of the shorter axis. One probe call site for all filters
// keeps the program small (see levelValue).
vec4 filtered(vec3 b, vec3 dx, vec3 dy) {
  bool nearest = filterMode == 0, mipOrder = filterMode >= 2;
  float lambda = filterMode <= 1 ? float(FINEST)
    : filterMode == 2 ? float(level)
    : levelOfFootprint(max(metric(dx), metric(dy)));
  float n = 1.0;
  vec3 axis = vec3(0.0);
  if (filterMode == 4) {
    float lx = metric(dx), ly = metric(dy);
    float major = lx >= ly ? lx : ly;
    float minor = lx >= ly ? ly : lx;
    axis = lx >= ly ? dx : dy;
    float maxN = float(clamp(maxSamples, 1, MAX_PROBES));
    n = minor > 0.0 ? clamp(ceil(major / minor), 1.0, maxN) : maxN;
    lambda = levelOfFootprint(max(major / n, minor));
  }
  int count = int(n);
  vec4 sum = vec4(0.0);
  for (int k = 0; k < count; k++) {
    vec3 p = b;
    if (count > 1) {
      float t = (float(k) + 0.5) / n - 0.5;
      p = b + t * axis;
      p = vec3(p.x > 0.0 ? p.x : 0.0, p.y > 0.0 ? p.y : 0.0, p.z > 0.0 ? p.z : 0.0);
    }
    sum += probe(p, lambda, nearest, mipOrder);
  }
  return count > 1 ? sum / n : sum;
}

// The workspace's sRGB encoding (trilux_io::image::linear_to_srgb, and
// view's gl.js): clamped to [0, 1] first.
float srgb(float x) {
  x = clamp(x, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

// A heat map for a scalar channel: five sRGB stops (dark blue, purple, red,
// orange, pale yellow), linear between them; values clamped to the range.
vec3 heat(float v) {
  float s = clamp((v - heatRange.x) / (heatRange.y - heatRange.x), 0.0, 1.0) * 4.0;
  vec3 stops[5] = vec3[5](vec3(0.05, 0.03, 0.2), vec3(0.45, 0.1, 0.55), vec3(0.85, 0.2, 0.3),
                          vec3(0.98, 0.6, 0.1), vec3(0.99, 0.97, 0.65));
  int i = min(int(s), 3);
  return mix(stops[i], stops[i + 1], s - float(i));
}

void main() {
  // Derivatives first, in uniform control flow (they are undefined in a
  // branch some fragments of a quad skip).
  vec3 dx = dFdx(vBary), dy = dFdy(vBary);
  if (outputMode == 1) {
    out0 = vec4(float(vFace), vBary);
    out1 = vec4(dx, 0.0);
    out2 = vec4(dy, 0.0);
    return;
  }
  decode();
  vec4 v = filtered(vBary, dx, dy);
  // The painter's view lit from the eye, so the shape reads (the parity
  // test and exports see shade = 0: the colours alone). The face's own
  // normal from screen derivatives: flat per face, no attribute needed.
  float light = 1.0;
  if (shade > 0.0) {
    vec3 n = normalize(cross(dFdx(vWorld), dFdy(vWorld)));
    light = 1.0 - shade * (1.0 - abs(dot(n, normalize(eye - vWorld))));
  }
  vec3 rgb;
  if (display == 0) rgb = vec3(srgb(light * v.r), srgb(light * v.g), srgb(light * v.b));
  else if (display == 1) rgb = vec3(srgb(light * v[component]));
  else rgb = light * heat(v[component]);
  out0 = vec4(rgb, tagAlpha ? vTag : 1.0);
}`;

/** The shaders' sources; `defines` (names) go after the version line. */
export function sources(defines = []) {
  const head = '#version 300 es\n' + defines.map((d) => `#define ${d}\n`).join('');
  return { vertex: head + VS, fragment: head + FS };
}

/** The filters and their shader codes. */
export const FILTERS = { nearest: 0, linear: 1, level: 2, trilinear: 3, anisotropic: 4 };
const DISPLAYS = { color: 0, grey: 1, heat: 2 };

function compile(gl, type, text) {
  const s = gl.createShader(type);
  gl.shaderSource(s, text);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}

function link(gl, defines) {
  const src = sources(defines);
  const p = gl.createProgram();
  gl.attachShader(p, compile(gl, gl.VERTEX_SHADER, src.vertex));
  gl.attachShader(p, compile(gl, gl.FRAGMENT_SHADER, src.fragment));
  // Every program reads the positions from one vertex array.
  gl.bindAttribLocation(p, POSITION, 'position');
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
  return p;
}

const POSITION = 0;
const UNIFORMS = ['viewProj', 'samples', 'faces', 'rowTexels', 'rowScale', 'perValue', 'group', 'level', 'maxSamples', 'component',
  'heatRange', 'tagAlpha', 'shade', 'eye'];

// Texture formats of the two layout textures (gpu.rs, "Textures").
const SAMPLES = (gl) => ({ internal: gl.RGBA32F, format: gl.RGBA, type: gl.FLOAT, unit: 0 });
const FACES = (gl) => ({ internal: gl.RGBA32UI, format: gl.RGBA_INTEGER, type: gl.UNSIGNED_INT, unit: 1 });

export class MeshColorsRenderer {
  /**
   * gl: a WebGL2 context. defines: the tests' wrong twins,
   * TWIN_EDGE_DIRECTION (a shader define: every edge read from corner k)
   * and TWIN_ROW_WIDTH (the shader told rows are one texel short).
   */
  constructor(gl, { defines = [] } = {}) {
    this.gl = gl;
    this.defines = defines;
    this.programs = new Map();
    this.vao = gl.createVertexArray();
    this.buffer = gl.createBuffer();
    this.textures = { samples: gl.createTexture(), faces: gl.createTexture() };
    this.count = 0;
    this.layout = null;
    this.pickTarget = null;
    // Linked now: a shader that does not compile fails here, not at the
    // first frame.
    this.program(FILTERS.linear, DISPLAYS.color, 0);
  }

  /**
   * The program of one filter, display and output (0 colour, 1 pick) with
   * its uniform locations, linked on first use and kept.
   */
  program(filter, display, output) {
    const key = `${filter} ${display} ${output}`;
    if (!this.programs.has(key)) {
      const gl = this.gl;
      const p = link(gl, [...this.defines, `FILTER_MODE ${filter}`, `DISPLAY ${display}`, `OUTPUT_MODE ${output}`]);
      const loc = {};
      for (const u of UNIFORMS) loc[u] = gl.getUniformLocation(p, u);
      this.programs.set(key, { program: p, loc });
    }
    return this.programs.get(key);
  }

  /**
   * The mesh: positions (xyz per vertex) and triangles (three vertex ids
   * per face, face f = triangle f of the mesh colours' topology), expanded
   * to three vertices per face so that gl_VertexID / 3 is the face.
   */
  setMesh(positions, triangles) {
    const corners = new Float32Array(triangles.length * 3);
    for (let i = 0; i < triangles.length; i++) corners.set(positions.subarray(3 * triangles[i], 3 * triangles[i] + 3), 3 * i);
    this.setCorners(corners);
  }

  /** Corner positions already expanded: nine floats per face. */
  setCorners(corners) {
    const gl = this.gl;
    gl.bindVertexArray(this.vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.buffer);
    gl.bufferData(gl.ARRAY_BUFFER, corners, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(POSITION);
    gl.vertexAttribPointer(POSITION, 3, gl.FLOAT, false, 0, 0);
    gl.bindVertexArray(null);
    this.count = corners.length / 3;
  }

  /**
   * A GpuLayout's parts: {width, channels, samples: Float32Array,
   * faces: Uint32Array, rows} (GpuParts; both arrays RGBA per texel,
   * row-major, whole rows of `width` texels; `rows`, if given, the sample
   * texture's height when `samples` holds only its first rows, the rest
   * zeros). Allocates both textures (texImage2D): at the start and
   * whenever GpuLayout::update reports `resized`.
   */
  setLayout(parts) {
    const gl = this.gl;
    const w = parts.width;
    this.layout = { width: w, channels: parts.channels, perValue: Math.ceil(parts.channels / 4) };
    const upload = (tex, f, data, rows) => {
      gl.activeTexture(gl.TEXTURE0 + f.unit);
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.pixelStorei(gl.UNPACK_ROW_LENGTH, 0);
      gl.pixelStorei(gl.UNPACK_ALIGNMENT, 4);
      const given = data.length / (4 * w);
      if (rows > given) {
        // Zeros first (WebGL fills a texture made from null with them),
        // then the rows that hold values.
        gl.texImage2D(gl.TEXTURE_2D, 0, f.internal, w, rows, 0, f.format, f.type, null);
        gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, w, given, f.format, f.type, data);
      } else {
        gl.texImage2D(gl.TEXTURE_2D, 0, f.internal, w, given, 0, f.format, f.type, data);
      }
      // texelFetch reads exact texels; NEAREST keeps the texture complete
      // (float and integer textures are not filterable).
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    };
    upload(this.textures.samples, SAMPLES(gl), parts.samples, parts.rows || 0);
    upload(this.textures.faces, FACES(gl), parts.faces, 0);
  }

  /**
   * Uploads the texel rectangles GpuLayout::update reported (Changes:
   * {resized, samples: [rect], faces: [rect]}, rect = {x, y, width,
   * height}) with texSubImage2D. A rectangle's texels come from its own
   * `data` (width x height texels, row by row) when it has one, else from
   * the whole new arrays in `parts` (the layout's linear index y * W + x).
   */
  updateRects(changes, parts) {
    if (changes.resized) return this.setLayout(parts);
    const gl = this.gl;
    const send = (tex, f, rects, whole) => {
      if (!rects || !rects.length) return;
      gl.activeTexture(gl.TEXTURE0 + f.unit);
      gl.bindTexture(gl.TEXTURE_2D, tex);
      for (const r of rects) {
        const own = r.data !== undefined;
        gl.pixelStorei(gl.UNPACK_ROW_LENGTH, own ? r.width : this.layout.width);
        const src = own ? r.data : whole;
        const offset = own ? 0 : 4 * (r.y * this.layout.width + r.x);
        gl.texSubImage2D(gl.TEXTURE_2D, 0, r.x, r.y, r.width, r.height, f.format, f.type, src, offset);
      }
      gl.pixelStorei(gl.UNPACK_ROW_LENGTH, 0);
    };
    send(this.textures.samples, SAMPLES(gl), changes.samples, parts && parts.samples);
    send(this.textures.faces, FACES(gl), changes.faces, parts && parts.faces);
  }

  /**
   * Draws the mesh into the bound framebuffer (viewport and clearing are
   * the caller's). viewProj: column-major 4x4. opts: filter (a FILTERS
   * name), level (for 'level'), maxSamples (anisotropic, default 8),
   * display ('color' the RGB of channels 0-2, 'grey' or 'heat' of
   * `channel`), channel, range ([lo, hi] of the heat map), tagAlpha,
   * shade (0 to 1: how much darker a face turned away from `eye` is; 0,
   * the default, draws the colours alone) and eye (the camera's position).
   */
  draw(viewProj, opts = {}) {
    const gl = this.gl;
    const channel = opts.channel || 0;
    const display = DISPLAYS[opts.display || 'color'];
    const loc = this.bind(viewProj, this.program(FILTERS[opts.filter || 'linear'], display, 0));
    gl.uniform1i(loc.level, opts.level || 0);
    gl.uniform1i(loc.maxSamples, opts.maxSamples || 8);
    // RGB shows the first texel's .rgb; one channel is its texel's component.
    gl.uniform1i(loc.group, display === DISPLAYS.color ? 0 : Math.floor(channel / 4));
    gl.uniform1i(loc.component, channel % 4);
    gl.uniform2fv(loc.heatRange, opts.range || [0, 1]);
    gl.uniform1i(loc.tagAlpha, opts.tagAlpha ? 1 : 0);
    gl.uniform1f(loc.shade, opts.shade || 0);
    gl.uniform3fv(loc.eye, opts.eye || [0, 0, 0]);
    this.drawArrays();
  }

  /**
   * The pick pass into the bound framebuffer, whose colour attachments 0-2
   * are RGBA32F (EXT_color_buffer_float): (face, b0, b1, b2), (db/dx, 0),
   * (db/dy, 0); where nothing is drawn they keep the clear value.
   */
  drawPick(viewProj) {
    this.bind(viewProj, this.program(FILTERS.linear, DISPLAYS.color, 1));
    this.drawArrays();
  }

  /**
   * Face and barycentrics under pixel (x, y) (from the bottom left, in
   * drawing-buffer pixels) of a drawing of `width` x `height`, or null
   * over the background: the eyedropper's and the brush's query.
   */
  pick(viewProj, x, y, width, height) {
    const gl = this.gl;
    const t = this.pickFramebuffer(width, height);
    gl.bindFramebuffer(gl.FRAMEBUFFER, t.fb);
    gl.viewport(0, 0, width, height);
    gl.clearBufferfv(gl.COLOR, 0, [-1, 0, 0, 0]);
    gl.clear(gl.DEPTH_BUFFER_BIT);
    this.drawPick(viewProj);
    const px = new Float32Array(4);
    gl.readBuffer(gl.COLOR_ATTACHMENT0);
    gl.readPixels(x, y, 1, 1, gl.RGBA, gl.FLOAT, px);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return px[0] < 0 ? null : { face: px[0], b: [px[1], px[2], px[3]] };
  }

  /** The pick pass's framebuffer of this size (made once, kept). */
  pickFramebuffer(width, height) {
    const gl = this.gl;
    if (this.pickTarget && this.pickTarget.width === width && this.pickTarget.height === height) return this.pickTarget;
    if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('picking needs EXT_color_buffer_float');
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    const attachments = [0, 1, 2].map((i) => {
      const tex = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, width, height);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + i, gl.TEXTURE_2D, tex, 0);
      return gl.COLOR_ATTACHMENT0 + i;
    });
    const depth = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, width, height);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
    gl.drawBuffers(attachments);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    this.pickTarget = { fb, width, height };
    return this.pickTarget;
  }

  /** Uses program `p` with the layout's textures bound; its uniform locations. */
  bind(viewProj, p) {
    const gl = this.gl, loc = p.loc;
    gl.useProgram(p.program);
    gl.enable(gl.DEPTH_TEST);
    gl.uniformMatrix4fv(loc.viewProj, false, viewProj);
    gl.uniform1i(loc.samples, SAMPLES(gl).unit);
    gl.uniform1i(loc.faces, FACES(gl).unit);
    gl.uniform1i(loc.perValue, this.layout ? this.layout.perValue : 1);
    const w = this.layout ? this.layout.width : 1;
    // The wrong twin TWIN_ROW_WIDTH: rows one texel short.
    const rowTexels = this.defines.includes('TWIN_ROW_WIDTH') ? w - 1 : w;
    gl.uniform1i(loc.rowTexels, rowTexels);
    gl.uniform1f(loc.rowScale, 1 / rowTexels);
    gl.activeTexture(gl.TEXTURE0 + SAMPLES(gl).unit);
    gl.bindTexture(gl.TEXTURE_2D, this.textures.samples);
    gl.activeTexture(gl.TEXTURE0 + FACES(gl).unit);
    gl.bindTexture(gl.TEXTURE_2D, this.textures.faces);
    return loc;
  }

  drawArrays() {
    const gl = this.gl;
    gl.bindVertexArray(this.vao);
    gl.drawArrays(gl.TRIANGLES, 0, this.count);
    gl.bindVertexArray(null);
  }
}
