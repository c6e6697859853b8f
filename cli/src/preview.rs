//! A small software renderer on glam for previews: a z-buffer rasteriser
//! with perspective-correct barycentrics (so textures and mesh colours can
//! be filtered per pixel, MIP levels included), point splats, a camera
//! fitted to a bounding box, 2×2 supersampling. Output is a linear RGBA
//! [`Image`] (write PNG for 8-bit sRGB, EXR for linear).

use glam::{Mat4, Vec2, Vec3, Vec4};
use trilux_io::image::Image;

/// A perspective camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Where it is.
    pub eye: Vec3,
    /// The point at the centre of the picture.
    pub target: Vec3,
    /// The up direction.
    pub up: Vec3,
    /// Vertical field of view, in radians.
    pub fov_y: f32,
}

impl Camera {
    /// A three-quarter view from the front, above and to the right
    /// (+z front, +y up), far enough for the box's bounding sphere to fill
    /// about 90 % of the picture.
    pub fn fit(lo: Vec3, hi: Vec3) -> Self {
        Self::fit_from(lo, hi, Vec3::new(0.55, 0.45, 1.0))
    }

    /// As [`fit`](Self::fit), looking from direction `from` (towards the
    /// box centre).
    pub fn fit_from(lo: Vec3, hi: Vec3, from: Vec3) -> Self {
        let centre = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-6);
        let fov_y = 35f32.to_radians();
        let distance = radius / (fov_y * 0.5).sin() / 0.9;
        let dir = from.normalize_or(Vec3::Z);
        Self {
            eye: centre + dir * distance,
            target: centre,
            up: Vec3::Y,
            fov_y,
        }
    }

    fn view_projection(&self, aspect: f32) -> Mat4 {
        let distance = (self.eye - self.target).length().max(1e-12);
        // Right-handed look-at (camera looks down −z) and an OpenGL-style
        // perspective whose NDC depth grows away from the camera.
        let f = (self.target - self.eye).normalize_or(Vec3::NEG_Z);
        let s = f.cross(self.up).normalize_or(Vec3::X);
        let u = s.cross(f);
        let view = Mat4::from_cols(
            Vec4::new(s.x, u.x, -f.x, 0.0),
            Vec4::new(s.y, u.y, -f.y, 0.0),
            Vec4::new(s.z, u.z, -f.z, 0.0),
            Vec4::new(-s.dot(self.eye), -u.dot(self.eye), f.dot(self.eye), 1.0),
        );
        let (near, far) = (distance * 1e-3, distance * 1e3);
        let t = 1.0 / (self.fov_y * 0.5).tan();
        let proj = Mat4::from_cols(
            Vec4::new(t / aspect, 0.0, 0.0, 0.0),
            Vec4::new(0.0, t, 0.0, 0.0),
            Vec4::new(0.0, 0.0, (far + near) / (near - far), -1.0),
            Vec4::new(0.0, 0.0, 2.0 * far * near / (near - far), 0.0),
        );
        proj * view
    }
}

/// What a shading function knows about a pixel of a triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fragment {
    /// The triangle.
    pub face: u32,
    /// Perspective-correct barycentrics at the pixel centre.
    pub barycentric: [f32; 3],
    /// Their change per output pixel to the right …
    pub db_dx: [f32; 3],
    /// … and downwards (for MIP and anisotropic filtering).
    pub db_dy: [f32; 3],
    /// The point on the surface.
    pub position: Vec3,
    /// The triangle's unit normal, turned towards the camera.
    pub normal: Vec3,
    /// Unit direction from the point to the camera.
    pub to_eye: Vec3,
}

/// A triangle projected to the supersampled screen: its corners, their
/// [`to_screen`] (position, depth, `1/w`), its doubled signed area on
/// screen and the samples' bounding box.
#[derive(Debug, Clone, Copy)]
struct Projected {
    p: [Vec3; 3],
    s: [(Vec2, f32, f32); 3],
    area: f32,
    lo: Vec2,
    hi: Vec2,
}

/// A picture being drawn: colour and depth at `supersample²` samples per
/// output pixel.
#[derive(Debug, Clone)]
pub struct Renderer {
    width: u32,
    height: u32,
    ss: u32,
    camera: Camera,
    view_projection: Mat4,
    color: Vec<[f32; 4]>,
    depth: Vec<f32>,
}

/// Screen position (pixels), depth and `1/w` of a clip-space point.
fn to_screen(clip: Vec4, w: f32, h: f32) -> (Vec2, f32, f32) {
    let inv = 1.0 / clip.w;
    let ndc = clip.truncate() * inv;
    (
        Vec2::new((ndc.x + 1.0) * 0.5 * w, (1.0 - ndc.y) * 0.5 * h),
        ndc.z,
        inv,
    )
}

impl Renderer {
    /// A `width × height` picture from `camera`, background a soft grey
    /// gradient (opaque), drawn at 2×2 samples per pixel.
    pub fn new(width: u32, height: u32, camera: Camera) -> Self {
        let (width, height) = (width.clamp(1, 8192), height.clamp(1, 8192));
        let ss = 2;
        let (w, h) = (width * ss, height * ss);
        let aspect = width as f32 / height as f32;
        let color = (0..h)
            .flat_map(|y| std::iter::repeat_n(background(y, h), w as usize))
            .collect();
        Self {
            width,
            height,
            ss,
            camera,
            view_projection: camera.view_projection(aspect),
            color,
            depth: vec![f32::INFINITY; (w * h) as usize],
        }
    }

    /// The camera.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Draws triangles, colouring each covered sample with `shade`
    /// (linear RGB). Both sides are drawn; triangles behind the camera are
    /// skipped.
    pub fn draw_mesh(
        &mut self,
        positions: &[Vec3],
        faces: &[[u32; 3]],
        shade: impl Fn(&Fragment) -> [f32; 3],
    ) {
        for (f, tri) in faces.iter().enumerate() {
            if let Some(t) = self.project(positions, tri) {
                self.raster(f as u32, &t, &shade);
            }
        }
    }

    /// Triangle `tri` on the supersampled screen; `None` when a corner is
    /// missing or behind the camera, the triangle is flat on screen, or it
    /// covers no sample.
    fn project(&self, positions: &[Vec3], tri: &[u32; 3]) -> Option<Projected> {
        let (wf, hf) = (
            (self.width * self.ss) as f32,
            (self.height * self.ss) as f32,
        );
        let p = tri
            .iter()
            .map(|&v| positions.get(v as usize).copied())
            .collect::<Option<Vec<Vec3>>>()?;
        let p = [p[0], p[1], p[2]];
        let clip = [0, 1, 2].map(|k| self.view_projection * p[k].extend(1.0));
        if clip
            .iter()
            .any(|c| c.w.is_nan() || c.w <= 0.0 || !c.is_finite())
        {
            return None;
        }
        let s = clip.map(|c| to_screen(c, wf, hf));
        let (a, b, c) = (s[0].0, s[1].0, s[2].0);
        let area = (b - a).perp_dot(c - a);
        if area.abs() < 1e-12 || !area.is_finite() {
            return None;
        }
        let lo = a.min(b).min(c).max(Vec2::ZERO);
        let hi = a.max(b).max(c).min(Vec2::new(wf - 1.0, hf - 1.0));
        if lo.x > hi.x || lo.y > hi.y {
            return None;
        }
        Some(Projected { p, s, area, lo, hi })
    }

    /// Fills the samples of a projected triangle (face `f`) nearer than
    /// what is drawn, with `shade`.
    fn raster(&mut self, f: u32, t: &Projected, shade: &impl Fn(&Fragment) -> [f32; 3]) {
        let (w, h) = (self.width * self.ss, self.height * self.ss);
        let (wf, hf) = (w as f32, h as f32);
        let scale = self.ss as f32;
        let Projected { p, s, area, lo, hi } = *t;
        let (a, b, c) = (s[0].0, s[1].0, s[2].0);
        let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        // Screen-space (affine) barycentrics of a screen point.
        let affine = |q: Vec2| {
            [
                (c - b).perp_dot(q - b) / area,
                (a - c).perp_dot(q - c) / area,
                (b - a).perp_dot(q - a) / area,
            ]
        };
        // Perspective-correct barycentrics from the affine ones.
        let correct = |l: [f32; 3]| {
            let pw = [l[0] * s[0].2, l[1] * s[1].2, l[2] * s[2].2];
            let sum = pw[0] + pw[1] + pw[2];
            pw.map(|x| x / sum)
        };
        for y in lo.y.floor() as u32..=hi.y.ceil().min(hf - 1.0) as u32 {
            for x in lo.x.floor() as u32..=hi.x.ceil().min(wf - 1.0) as u32 {
                let q = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let l = affine(q);
                if l.iter().any(|&x| x < -1e-6) {
                    continue;
                }
                let z = l[0] * s[0].1 + l[1] * s[1].1 + l[2] * s[2].1;
                let i = (y * w + x) as usize;
                if z.is_nan() || z >= self.depth[i] || z < -1.0 {
                    continue;
                }
                self.depth[i] = z;
                let bc = correct(l);
                let position = p[0] * bc[0] + p[1] * bc[1] + p[2] * bc[2];
                let to_eye = (self.camera.eye - position).normalize_or(Vec3::Z);
                let bx = correct(affine(q + Vec2::X));
                let by = correct(affine(q + Vec2::Y));
                let fragment = Fragment {
                    face: f,
                    barycentric: bc,
                    db_dx: [0, 1, 2].map(|k| (bx[k] - bc[k]) * scale),
                    db_dy: [0, 1, 2].map(|k| (by[k] - bc[k]) * scale),
                    position,
                    normal: if normal.dot(to_eye) < 0.0 {
                        -normal
                    } else {
                        normal
                    },
                    to_eye,
                };
                let rgb = shade(&fragment);
                self.color[i] = [rgb[0], rgb[1], rgb[2], 1.0];
            }
        }
    }

    /// Draws points as round splats of `radius` output pixels, coloured
    /// by `color(index)`, depth-tested against what is drawn (pulled a
    /// little towards the camera so that points on a drawn surface show).
    pub fn draw_points(&mut self, points: &[Vec3], radius: f32, color: impl Fn(usize) -> [f32; 3]) {
        let (w, h) = (self.width * self.ss, self.height * self.ss);
        let r = (radius * self.ss as f32).max(0.5);
        let ri = r.ceil() as i64;
        for (k, p) in points.iter().enumerate() {
            let clip = self.view_projection * p.extend(1.0);
            if clip.w.is_nan() || clip.w <= 0.0 || !clip.is_finite() {
                continue;
            }
            let (s, z, _) = to_screen(clip, w as f32, h as f32);
            // Depth bias: a thousandth of the way to the camera in NDC.
            let z = z - (1.0 - z).abs() * 1e-3 - 1e-5;
            let rgb = color(k);
            let (cx, cy) = (s.x.floor() as i64, s.y.floor() as i64);
            for y in (cy - ri).max(0)..=(cy + ri).min(h as i64 - 1) {
                for x in (cx - ri).max(0)..=(cx + ri).min(w as i64 - 1) {
                    let d = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - s;
                    if d.length_squared() > r * r {
                        continue;
                    }
                    let i = (y as u32 * w + x as u32) as usize;
                    if z < self.depth[i] {
                        self.depth[i] = z;
                        self.color[i] = [rgb[0], rgb[1], rgb[2], 1.0];
                    }
                }
            }
        }
    }

    /// Draws line segments `(a, b)` one sample wide, coloured by
    /// `color(index)`, depth-tested against what is drawn with the bias
    /// [`draw_points`](Self::draw_points) uses; a segment with an end
    /// behind the camera is skipped.
    pub fn draw_lines(&mut self, segments: &[(Vec3, Vec3)], color: impl Fn(usize) -> [f32; 3]) {
        let (w, h) = (self.width * self.ss, self.height * self.ss);
        let (wf, hf) = (w as f32, h as f32);
        for (k, &(a, b)) in segments.iter().enumerate() {
            let clip = [a, b].map(|p| self.view_projection * p.extend(1.0));
            if clip.iter().any(|c| !c.is_finite() || c.w <= 0.0) {
                continue;
            }
            let [(sa, za, _), (sb, zb, _)] = clip.map(|c| to_screen(c, wf, hf));
            // NDC depth is affine in screen space, so it is interpolated
            // linearly along the segment; one step per sample, capped so
            // that a segment far off screen costs little.
            let steps = (sb - sa).length().ceil().clamp(1.0, 4.0 * (wf + hf)) as u32;
            let rgb = color(k);
            for i in 0..=steps {
                let t = i as f32 / steps as f32;
                let s = sa.lerp(sb, t);
                let z = za + (zb - za) * t;
                let z = z - (1.0 - z).abs() * 1e-3 - 1e-5;
                if !(s.x >= 0.0 && s.y >= 0.0 && s.x < wf && s.y < hf) {
                    continue;
                }
                let i = (s.y as u32 * w + s.x as u32) as usize;
                if z < self.depth[i] {
                    self.depth[i] = z;
                    self.color[i] = [rgb[0], rgb[1], rgb[2], 1.0];
                }
            }
        }
    }

    /// Per output pixel, the fraction of its samples a triangle or point
    /// covers (0 = background only, 1 = fully covered), row-major like
    /// [`image`](Self::image).
    pub fn coverage(&self) -> Vec<f32> {
        let w = self.width * self.ss;
        let n = (self.ss * self.ss) as f32;
        let mut out = Vec::with_capacity((self.width * self.height) as usize);
        for y in 0..self.height {
            for x in 0..self.width {
                let mut covered = 0u32;
                for dy in 0..self.ss {
                    for dx in 0..self.ss {
                        let i = ((y * self.ss + dy) * w + x * self.ss + dx) as usize;
                        covered += u32::from(self.depth[i].is_finite());
                    }
                }
                out.push(covered as f32 / n);
            }
        }
        out
    }

    /// The background alone (the soft grey gradient every picture starts
    /// from), averaged per output pixel as [`image`](Self::image) averages.
    pub fn background(&self) -> Image {
        let h = self.height * self.ss;
        let n = (self.ss * self.ss) as f32;
        let mut pixels = Vec::with_capacity((self.width * self.height) as usize);
        for y in 0..self.height {
            // Summed in the order `image` sums, so that an uncovered
            // pixel of the picture equals this bit for bit.
            let mut sum = [0.0f32; 4];
            for dy in 0..self.ss {
                for _ in 0..self.ss {
                    for (s, c) in sum.iter_mut().zip(background(y * self.ss + dy, h)) {
                        *s += c;
                    }
                }
            }
            pixels.extend(std::iter::repeat_n(sum.map(|s| s / n), self.width as usize));
        }
        Image {
            width: self.width,
            height: self.height,
            pixels,
        }
    }

    /// The picture: each output pixel the mean of its samples.
    pub fn image(&self) -> Image {
        let w = self.width * self.ss;
        let n = (self.ss * self.ss) as f32;
        let mut pixels = Vec::with_capacity((self.width * self.height) as usize);
        for y in 0..self.height {
            for x in 0..self.width {
                let mut sum = [0.0f32; 4];
                for dy in 0..self.ss {
                    for dx in 0..self.ss {
                        let i = ((y * self.ss + dy) * w + x * self.ss + dx) as usize;
                        for (s, c) in sum.iter_mut().zip(self.color[i]) {
                            *s += c;
                        }
                    }
                }
                pixels.push(sum.map(|s| s / n));
            }
        }
        Image {
            width: self.width,
            height: self.height,
            pixels,
        }
    }
}

/// The background colour of sample row `y` of `h` (linear RGBA): a soft
/// grey gradient, lighter at the top.
fn background(y: u32, h: u32) -> [f32; 4] {
    let t = y as f32 / h as f32;
    let g = 0.32 - 0.17 * t;
    [g, g, g * 1.05, 1.0]
}

/// Diffuse shading of `albedo` under a key light from the upper left of
/// the camera and a little ambient light.
pub fn lambert(albedo: [f32; 3], fragment: &Fragment) -> [f32; 3] {
    let light = (fragment.to_eye + Vec3::new(-0.3, 0.6, 0.0)).normalize_or(fragment.to_eye);
    let k = 0.2 + 0.8 * fragment.normal.dot(light).max(0.0);
    albedo.map(|a| a * k)
}

/// A preview of a mesh in flat grey.
pub fn render_mesh(positions: &[Vec3], faces: &[[u32; 3]], width: u32, height: u32) -> Image {
    let Some((lo, hi)) = bounds(positions) else {
        return Renderer::new(width, height, Camera::fit(Vec3::splat(-1.0), Vec3::ONE)).image();
    };
    let mut r = Renderer::new(width, height, Camera::fit(lo, hi));
    r.draw_mesh(positions, faces, |f| lambert([0.7; 3], f));
    r.image()
}

/// The bounding box of points (`None` when empty or not finite).
pub fn bounds(points: &[Vec3]) -> Option<(Vec3, Vec3)> {
    let first = *points.first()?;
    let b = points
        .iter()
        .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    (b.0.is_finite() && b.1.is_finite()).then_some(b)
}
