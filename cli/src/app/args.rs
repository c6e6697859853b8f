//! Typed values and shared option groups of the command line.
//!
//! Every spec (`--light`, `--cut`, `--paint`, `--fracture`, `--view`,
//! `--material`) is parsed by a clap `value_parser` into a typed value, so
//! that a bad one is a usage error that names the argument before any
//! work starts. Each value keeps the text it was parsed from, for the
//! messages and JSON reports that quote it.

use std::fmt;

use glam::DVec3;
use tet_diffusion::{Light, Medium, Noise, Stroke};

/// The largest picture `--size` allows (pixels per side).
pub(crate) const MAX_PICTURE: u32 = 8192;

/// The picture options of the subcommands that render one.
#[derive(Debug, Clone, clap::Args)]
pub(crate) struct PictureArgs {
    /// Look from this direction (x,y,z from the mesh's centre toward the
    /// camera; default a three-quarter view from +z, above and right).
    #[arg(long, value_name = "X,Y,Z", value_parser = View::parse)]
    pub(crate) view: Option<View>,
    /// Picture width and height in pixels.
    #[arg(long, default_value_t = 768, value_parser = picture_size)]
    pub(crate) size: u32,
}

impl PictureArgs {
    /// The view direction, if one was given.
    pub(crate) fn direction(&self) -> Option<glam::Vec3> {
        self.view.as_ref().map(|v| v.direction)
    }
}

/// `--size` of a picture: 1 to [`MAX_PICTURE`] pixels.
pub(crate) fn picture_size(text: &str) -> Result<u32, String> {
    pixels(text, MAX_PICTURE)
}

/// A number of pixels from 1 to `max`.
pub(crate) fn pixels(text: &str, max: u32) -> Result<u32, String> {
    let n: u32 = text.parse().map_err(|e| format!("{e}"))?;
    if n == 0 || n > max {
        return Err(format!("the picture must be 1 to {max} pixels wide"));
    }
    Ok(n)
}

/// `--unit-mm`: millimetres per mesh unit, a positive number.
pub(crate) fn unit_mm(text: &str) -> Result<f64, String> {
    let mm: f64 = text.parse().map_err(|e| format!("{e}"))?;
    if !(mm.is_finite() && mm > 0.0) {
        return Err("millimetres per mesh unit must be a positive number".into());
    }
    Ok(mm)
}

/// `x,y,z`: a non-zero direction to look from.
#[derive(Debug, Clone)]
pub(crate) struct View {
    /// The direction from the mesh's centre toward the camera.
    pub(crate) direction: glam::Vec3,
}

impl View {
    /// Parses `x,y,z` (three finite numbers, not all zero).
    pub(crate) fn parse(spec: &str) -> Result<View, String> {
        let v: Vec<f32> = spec
            .split(',')
            .map(|x| x.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .ok()
            .filter(|v: &Vec<f32>| v.len() == 3 && v.iter().all(|x| x.is_finite()))
            .ok_or("expected three numbers x,y,z")?;
        let direction = glam::Vec3::new(v[0], v[1], v[2]);
        if direction.length_squared() == 0.0 {
            return Err("the direction is zero".into());
        }
        Ok(View { direction })
    }
}

/// `text` (a part of `spec`) as `n` finite comma-separated numbers.
fn numbers(text: &str, spec: &str, n: usize) -> Result<Vec<f64>, String> {
    let v: Option<Vec<f64>> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect();
    match v {
        Some(v) if v.len() == n => Ok(v),
        _ if text == spec => Err(format!("expected {n} finite comma-separated numbers")),
        _ => Err(format!(
            "expected {n} finite comma-separated numbers, found {text:?}"
        )),
    }
}

fn vec3(v: &[f64]) -> DVec3 {
    DVec3::new(v[0], v[1], v[2])
}

/// A measured material by name; `spec` is the whole value, which names
/// the problem unless `name` is a part of it.
pub(crate) fn medium(name: &str, spec: &str) -> Result<Medium, String> {
    Medium::measured(name).map_err(|_| {
        let names = tet_diffusion::MEASURED
            .iter()
            .map(|m| m.0)
            .collect::<Vec<_>>()
            .join(", ");
        if name == spec {
            format!("unknown material (one of {names})")
        } else {
            format!("unknown material {name:?} (one of {names})")
        }
    })
}

/// `--material`: a measured material, or `noise:A,B` (fractal noise
/// between two of them).
#[derive(Debug, Clone)]
pub(crate) struct Material {
    /// The value as typed.
    pub(crate) spec: String,
    /// The material, or the noise's first one.
    pub(crate) a: Medium,
    /// The noise's second material.
    pub(crate) b: Option<Medium>,
}

impl Material {
    /// Parses a material's name or `noise:A,B`.
    pub(crate) fn parse(spec: &str) -> Result<Material, String> {
        let (a, b) = match spec.strip_prefix("noise:") {
            Some(pair) => {
                let names: Vec<&str> = pair.split(',').collect();
                let [a, b] = names.as_slice() else {
                    return Err("expected noise:A,B".into());
                };
                (medium(a, spec)?, Some(medium(b, spec)?))
            }
            None => (medium(spec, spec)?, None),
        };
        Ok(Material {
            spec: spec.to_string(),
            a,
            b,
        })
    }

    /// The medium of every tetrahedron of `mesh`; `scale` is the noise's
    /// feature size in mesh units.
    pub(crate) fn media(
        &self,
        mesh: &tet_diffusion::TetMesh,
        scale: f64,
    ) -> Result<Vec<Medium>, tet_diffusion::Error> {
        match self.b {
            Some(b) => Noise {
                a: self.a,
                b,
                scale,
                octaves: 4,
                seed: 1,
            }
            .media(mesh),
            None => Ok(vec![self.a; mesh.tets().len()]),
        }
    }
}

impl fmt::Display for Material {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.spec)
    }
}

/// `--light`: `dir:x,y,z[:r,g,b]` (toward the light) or
/// `point:x,y,z[:r,g,b]`.
#[derive(Debug, Clone)]
pub(crate) struct LightSpec {
    /// The value as typed.
    pub(crate) spec: String,
    /// The light.
    pub(crate) light: Light,
}

impl LightSpec {
    /// Parses `kind:x,y,z[:r,g,b]`.
    pub(crate) fn parse(spec: &str) -> Result<LightSpec, String> {
        let parts: Vec<&str> = spec.split(':').collect();
        let (kind, xyz, rgb) = match parts.as_slice() {
            [k, xyz] => (*k, *xyz, None),
            [k, xyz, rgb] => (*k, *xyz, Some(*rgb)),
            _ => return Err("expected dir:x,y,z[:r,g,b] or point:x,y,z[:r,g,b]".into()),
        };
        let p = vec3(&numbers(xyz, spec, 3)?);
        let c = match rgb {
            Some(rgb) => {
                let c = numbers(rgb, spec, 3)?;
                [c[0], c[1], c[2]]
            }
            None => [1.0; 3],
        };
        let light = match kind {
            "dir" if p.length_squared() == 0.0 => return Err("the direction is zero".into()),
            "dir" => Light::Directional {
                to_light: p,
                irradiance: c,
            },
            "point" => Light::Point {
                position: p,
                intensity: c,
            },
            other => return Err(format!("unknown kind of light {other:?} (dir or point)")),
        };
        Ok(LightSpec {
            spec: spec.to_string(),
            light,
        })
    }
}

/// `plane:nx,ny,nz,d`, the plane n·x = d (`--cut` removes, `--fracture`
/// breaks along, `--paint` fills the side n·x > d).
#[derive(Debug, Clone)]
pub(crate) struct Plane {
    /// The value as typed.
    pub(crate) spec: String,
    /// The plane's point nearest the origin.
    pub(crate) point: DVec3,
    /// The unit normal, toward the side n·x > d.
    pub(crate) normal: DVec3,
}

impl Plane {
    /// Parses `plane:nx,ny,nz,d`.
    pub(crate) fn parse(spec: &str) -> Result<Plane, String> {
        Plane::parse_in(spec, spec)
    }

    /// Parses `text`, a part of the value `spec`.
    fn parse_in(text: &str, spec: &str) -> Result<Plane, String> {
        let rest = text
            .strip_prefix("plane:")
            .ok_or("expected plane:nx,ny,nz,d")?;
        let v = numbers(rest, spec, 4)?;
        let n = vec3(&v);
        if n.length_squared() == 0.0 {
            return Err("the plane's normal is zero".into());
        }
        let normal = n.normalize();
        Ok(Plane {
            spec: text.to_string(),
            point: normal * (v[3] / n.length()),
            normal,
        })
    }
}

/// What one `--paint` paints.
#[derive(Debug, Clone)]
pub(crate) enum Paint {
    /// A soft-edged ball: a stroke of one point.
    Ball(Stroke),
    /// Every tetrahedron whose centre is on the side `(x − point) · normal
    /// > 0`, all of it.
    Side {
        /// The plane's point.
        point: DVec3,
        /// Its unit normal, toward the painted side.
        normal: DVec3,
        /// The material painted.
        medium: Medium,
    },
}

/// `--paint`: `x,y,z:radius:material` (a ball) or
/// `plane:nx,ny,nz,d:material` (a side of a plane).
#[derive(Debug, Clone)]
pub(crate) struct PaintSpec {
    /// The value as typed.
    pub(crate) spec: String,
    /// What it paints.
    pub(crate) paint: Paint,
}

impl PaintSpec {
    /// Parses a ball or a side of a plane.
    pub(crate) fn parse(spec: &str) -> Result<PaintSpec, String> {
        let paint = if spec.starts_with("plane:") {
            let Some((plane, m)) = spec.rsplit_once(':').filter(|(p, _)| *p != "plane") else {
                return Err("expected plane:nx,ny,nz,d:material".into());
            };
            let plane = Plane::parse_in(plane, spec)?;
            Paint::Side {
                point: plane.point,
                normal: plane.normal,
                medium: medium(m, spec)?,
            }
        } else {
            Paint::Ball(ball(spec)?)
        };
        Ok(PaintSpec {
            spec: spec.to_string(),
            paint,
        })
    }
}

/// `x,y,z:radius:material` as a stroke of one point.
fn ball(spec: &str) -> Result<Stroke, String> {
    let parts: Vec<&str> = spec.split(':').collect();
    let [xyz, r, m] = parts.as_slice() else {
        return Err("expected x,y,z:radius:material or plane:nx,ny,nz,d:material".into());
    };
    let radius: f64 = r
        .parse()
        .ok()
        .filter(|r: &f64| r.is_finite() && *r > 0.0)
        .ok_or("the radius must be a positive number")?;
    Ok(Stroke {
        points: vec![vec3(&numbers(xyz, spec, 3)?)],
        radius,
        medium: medium(m, spec)?,
        strength: 1.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_is_its_point_nearest_the_origin_and_unit_normal() {
        let p = Plane::parse("plane:0,0,2,1").unwrap();
        assert_eq!(p.normal, DVec3::Z);
        assert_eq!(p.point, DVec3::new(0.0, 0.0, 0.5));
        assert_eq!(p.spec, "plane:0,0,2,1");
    }

    #[test]
    fn a_part_of_a_spec_is_quoted_and_the_whole_is_not() {
        assert_eq!(
            LightSpec::parse("dir:0,1").unwrap_err(),
            "expected 3 finite comma-separated numbers, found \"0,1\""
        );
        assert_eq!(
            View::parse("1,2").unwrap_err(),
            "expected three numbers x,y,z"
        );
        assert!(
            Material::parse("jade")
                .unwrap_err()
                .starts_with("unknown material (one of")
        );
        assert!(
            Material::parse("noise:marble,jade")
                .unwrap_err()
                .starts_with("unknown material \"jade\"")
        );
    }

    #[test]
    fn paints_are_balls_or_sides() {
        let ball = PaintSpec::parse("0.03,0.08,0.03:0.01:ketchup").unwrap();
        assert!(matches!(ball.paint, Paint::Ball(ref s) if s.radius == 0.01));
        let side = PaintSpec::parse("plane:0,1,0,0.15:skin1").unwrap();
        assert!(matches!(side.paint, Paint::Side { normal, .. } if normal == DVec3::Y));
        assert!(PaintSpec::parse("plane:0,1,0,0.15").is_err());
    }
}
