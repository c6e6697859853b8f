// The nearest hit of a ray on triangle meshes (Möller–Trumbore), for
// picking under the cursor.

// `pieces`: meshes {positions (x, y, z per vertex), indices (3 per
// triangle), offset [x, y, z]}, holes allowed. The nearest hit in front
// of origin o along direction d: {piece, triangle, u, v, t, point}, with
// (u, v) the barycentrics of the triangle's second and third vertex; or
// null.
export function pick(pieces, o, d) {
  let best = null;
  pieces.forEach((p, k) => {
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
      if (t > 0 && (!best || t < best.t)) {
        best = { piece: k, triangle: i / 3, u, v, t, point: [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]] };
      }
    }
  });
  return best;
}
