// The scatter panel's drawing: the points the server scattered (GL_POINTS)
// and the strands grown from them (GL_LINES), depth-tested against the
// painted mesh drawn before them. Both arrive whole from the server (frame
// kinds 5 and 6) and are uploaded as they are: the server is the truth,
// the page only shows it.
//
// Usage:
//   const layer = new PointsLayer(gl);
//   layer.setPoints(Float32Array xyz);             // frame kind 5
//   layer.setStrands(Float32Array xyz, perStrand); // frame kind 6: polylines of perStrand points
//   layer.draw(viewProj, { size: 2 });

import { program } from './glutil.js';

const VS = `#version 300 es
in vec3 position;
uniform mat4 viewProj;
uniform float size;
void main() {
  gl_Position = viewProj * vec4(position, 1.0);
  // Pulled a hair toward the camera: a point on the surface is not hidden
  // by the triangle it lies on.
  gl_Position.z -= 2e-4 * gl_Position.w;
  gl_PointSize = size;
}`;

const FS = `#version 300 es
precision mediump float;
uniform vec4 color;
out vec4 outColor;
void main() { outColor = color; }`;

export class PointsLayer {
  constructor(gl) {
    this.gl = gl;
    this.program = program(gl, VS, FS);
    this.loc = {
      viewProj: gl.getUniformLocation(this.program, 'viewProj'),
      size: gl.getUniformLocation(this.program, 'size'),
      color: gl.getUniformLocation(this.program, 'color'),
    };
    this.points = this.buffer();
    this.strands = this.buffer();
    this.pointCount = 0;
    this.lineVertices = 0;
  }

  // A vertex array over one position buffer.
  buffer() {
    const gl = this.gl;
    const vao = gl.createVertexArray();
    const vbo = gl.createBuffer();
    gl.bindVertexArray(vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, vbo);
    const at = gl.getAttribLocation(this.program, 'position');
    gl.enableVertexAttribArray(at);
    gl.vertexAttribPointer(at, 3, gl.FLOAT, false, 0, 0);
    gl.bindVertexArray(null);
    return { vao, vbo };
  }

  setPoints(xyz) {
    const gl = this.gl;
    gl.bindBuffer(gl.ARRAY_BUFFER, this.points.vbo);
    gl.bufferData(gl.ARRAY_BUFFER, xyz, gl.STATIC_DRAW);
    this.pointCount = xyz.length / 3;
  }

  // Polylines of `perStrand` points each, drawn as the segments between
  // consecutive points (one LINES draw for every strand).
  setStrands(xyz, perStrand) {
    const gl = this.gl;
    const strands = perStrand > 1 ? xyz.length / (3 * perStrand) : 0;
    const segments = strands * (perStrand - 1);
    const lines = new Float32Array(segments * 6);
    let at = 0;
    for (let s = 0; s < strands; s++) {
      const base = 3 * s * perStrand;
      for (let k = 0; k + 1 < perStrand; k++) {
        lines.set(xyz.subarray(base + 3 * k, base + 3 * k + 6), at);
        at += 6;
      }
    }
    gl.bindBuffer(gl.ARRAY_BUFFER, this.strands.vbo);
    gl.bufferData(gl.ARRAY_BUFFER, lines, gl.STATIC_DRAW);
    this.lineVertices = 2 * segments;
  }

  draw(viewProj, opts = {}) {
    const gl = this.gl;
    if (!this.pointCount && !this.lineVertices) return;
    gl.useProgram(this.program);
    gl.enable(gl.DEPTH_TEST);
    gl.uniformMatrix4fv(this.loc.viewProj, false, viewProj);
    gl.uniform1f(this.loc.size, opts.size || 2);
    if (this.lineVertices) {
      gl.uniform4fv(this.loc.color, [0.55, 0.9, 1.0, 1]);
      gl.bindVertexArray(this.strands.vao);
      gl.drawArrays(gl.LINES, 0, this.lineVertices);
    }
    if (this.pointCount) {
      gl.uniform4fv(this.loc.color, [1.0, 0.45, 0.08, 1]);
      gl.bindVertexArray(this.points.vao);
      gl.drawArrays(gl.POINTS, 0, this.pointCount);
    }
    gl.bindVertexArray(null);
  }
}
