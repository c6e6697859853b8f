//! The scatter panel: points that grow where a channel is painted, and
//! strands grown from them — Šik & Křivánek's interactive hair-root
//! placement (2013, Fig. 1a, Sec. 6) on a density painted as mesh colours.
//!
//! Three ways to scatter, as the page's `scatter` op asks:
//!
//! - **rate**: a Poisson process of `rate × density` points per unit area
//!   ([`mesh_sampling::Scatter`]), the density being the channel clamped
//!   to `[0, 1]`. A stroke re-thins only the faces whose samples it
//!   changed (an index of which faces each sample reaches); raising the
//!   density only adds points and lowering it only removes them, so the
//!   points do not flicker while they are painted.
//! - **count**: `n` independent points by the density (the paper's
//!   sampler over the colours baked to a texture), drawn again when a
//!   stroke ends.
//! - **blue noise**: `n` Poisson-disk points following the density
//!   (weighted sample elimination), drawn again when a stroke ends.
//!
//! Strands (a preview of at most [`MAX_PREVIEW_STRANDS`], from evenly
//! spaced roots) grow along the shading normal ([`mesh_sampling::grow_strands`]);
//! their length may be scaled by a second channel.

use std::time::Instant;

use glam::Vec3;
use mesh_colors::MeshColors;
use mesh_sampling::{
    BlueNoiseTarget, DensitySampler, HairOptions, MeshRef, Packing, Scatter, ScatterDensity,
    ScatterOptions, StrandParams, Strands, SurfacePoint, SurfaceSampler, blue_noise,
};
use serde_json::{Map, Value};

use super::reach::SampleFaces;
use crate::colors::ColorMesh;
use crate::web::BadField;
use crate::web::json::{Parsed, get, number};

/// The most points the page is sent (12 bytes each: 48 MB).
pub const MAX_SHOWN_POINTS: usize = 4_000_000;
/// The most strands the page previews (every k-th point's).
pub const MAX_PREVIEW_STRANDS: usize = 20_000;
/// The most segments of a previewed strand.
pub const MAX_PREVIEW_SEGMENTS: u32 = 32;

/// How the panel scatters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScatterMode {
    /// No points.
    Off,
    /// A Poisson process of this many points per unit area (model units)
    /// where the density is 1.
    Rate(f64),
    /// This many independent points by the density.
    Count(usize),
    /// This many blue-noise points following the density.
    BlueNoise(usize),
}

/// Strands grown from the points, for the preview.
#[derive(Debug, Clone, PartialEq)]
pub struct HairSpec {
    /// The length in model units (times the length channel's value, when
    /// one is named).
    pub length: f32,
    /// Segments per strand.
    pub segments: u32,
    /// A channel that scales the length where it is painted.
    pub length_channel: Option<String>,
}

/// The page's `scatter` request: `{"mode": "off" | "rate" | "count" |
/// "blue_noise", "channel": "color" (its luminance) or a scalar channel,
/// "rate" (for rate), "count" (for count and blue_noise), "seed",
/// "hair": null or {"length", "segments", "length_channel": null or a
/// channel}}`.
#[derive(Debug, Clone, PartialEq)]
pub struct ScatterSpec {
    /// How.
    pub mode: ScatterMode,
    /// The density's channel by name.
    pub channel: String,
    /// The seed of the points and the strands.
    pub seed: u64,
    /// Strands to preview.
    pub hair: Option<HairSpec>,
}

/// Parses a `scatter` request's fields.
///
/// # Errors
/// The first bad field, named as the page sends it (`rate`, `count`,
/// `hair.length`, …).
pub fn parse(o: &Map<String, Value>) -> Parsed<ScatterSpec> {
    let mode = match get(o, "mode")?.as_str() {
        Some("off") => ScatterMode::Off,
        Some("rate") => {
            let rate = number(get(o, "rate")?, "rate")?;
            if !(rate > 0.0 && rate.is_finite()) {
                return Err(BadField::new("rate", "expected points per unit area > 0"));
            }
            ScatterMode::Rate(rate)
        }
        Some("count") => ScatterMode::Count(count(o)?),
        Some("blue_noise") => ScatterMode::BlueNoise(count(o)?),
        _ => {
            return Err(BadField::new(
                "mode",
                "expected off, rate, count or blue_noise",
            ));
        }
    };
    let channel = get(o, "channel")?
        .as_str()
        .ok_or_else(|| BadField::new("channel", "expected a channel name"))?
        .to_string();
    let seed = match o.get("seed") {
        None => 0,
        Some(v) => v
            .as_u64()
            .ok_or_else(|| BadField::new("seed", "expected a whole number ≥ 0"))?,
    };
    let hair = match o.get("hair") {
        None | Some(Value::Null) => None,
        Some(h) => Some(hair(h)?),
    };
    Ok(ScatterSpec {
        mode,
        channel,
        seed,
        hair,
    })
}

fn count(o: &Map<String, Value>) -> Parsed<usize> {
    get(o, "count")?
        .as_u64()
        .filter(|&n| n >= 1 && n <= MAX_SHOWN_POINTS as u64)
        .map(|n| n as usize)
        .ok_or_else(|| {
            BadField::new(
                "count",
                format!(
                    "expected a whole number of points, 1 to {}",
                    thousands(MAX_SHOWN_POINTS as f64)
                ),
            )
        })
}

fn hair(v: &Value) -> Parsed<HairSpec> {
    let o = v
        .as_object()
        .ok_or_else(|| BadField::new("hair", "expected an object or null"))?;
    let length = number(get(o, "length")?, "hair.length")? as f32;
    if !(length > 0.0 && length.is_finite()) {
        return Err(BadField::new("hair.length", "expected a length > 0"));
    }
    let segments = get(o, "segments")?
        .as_u64()
        .filter(|&k| k >= 1 && k <= u64::from(MAX_PREVIEW_SEGMENTS))
        .ok_or_else(|| {
            BadField::new(
                "hair.segments",
                format!("expected 1 to {MAX_PREVIEW_SEGMENTS}"),
            )
        })? as u32;
    let length_channel = match o.get("length_channel") {
        None | Some(Value::Null) => None,
        Some(c) => Some(
            c.as_str()
                .ok_or_else(|| BadField::new("hair.length_channel", "expected a channel name"))?
                .to_string(),
        ),
    };
    Ok(HairSpec {
        length,
        segments,
        length_channel,
    })
}

/// A channel of the colours: an index, or the luminance of RGB.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Channel {
    Luminance,
    Index(usize),
}

impl Channel {
    /// The channel `name` names among `scalars` (channels 3, 4, …).
    fn named(name: &str, scalars: &[String], field: &str) -> Parsed<Self> {
        if name == "color" {
            return Ok(Self::Luminance);
        }
        scalars
            .iter()
            .position(|s| s == name)
            .map(|k| Self::Index(3 + k))
            .ok_or_else(|| {
                BadField::new(
                    field,
                    format!("no channel named {name:?} (color or {scalars:?})"),
                )
            })
    }

    /// Its value at a point of a face, clamped to `[0, 1]` (NaN is 0).
    fn at(self, colors: &MeshColors, face: usize, barycentric: [f32; 3]) -> f32 {
        let mut values = [0.0f32; mesh_colors::MAX_CHANNELS];
        let c = colors.channels();
        if colors.linear(face, barycentric, &mut values[..c]).is_err() {
            return 0.0;
        }
        let v = match self {
            Self::Luminance => mesh_sampling::luminance([values[0], values[1], values[2]]),
            Self::Index(i) => values[i],
        };
        if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) }
    }

    fn sampling(self) -> mesh_sampling::Channel {
        match self {
            Self::Luminance => mesh_sampling::Channel::Luminance,
            Self::Index(i) => mesh_sampling::Channel::Index(i),
        }
    }
}

/// A copy of the surface a rate scatter borrows (its points are stored
/// per face and re-thinned in place, so it lives as long as the panel).
struct Surface {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
}

impl Surface {
    fn mesh_ref(&self) -> MeshRef<'_> {
        MeshRef::new(&self.positions, &self.indices)
    }
}

type ScatterOf<'a> = Scatter<'a>;

self_cell::self_cell!(
    /// A rate scatter over its own copy of the surface.
    struct RateScatter {
        owner: Surface,
        #[covariant]
        dependent: ScatterOf,
    }
);

impl std::fmt::Debug for RateScatter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "RateScatter({} points)",
            self.borrow_dependent().points().len()
        )
    }
}

/// What the panel last made, and what it needs to follow the strokes.
#[derive(Debug)]
pub(crate) struct ScatterState {
    spec: ScatterSpec,
    channel: Channel,
    length_channel: Option<Channel>,
    /// Which faces a changed sample reaches (rate mode).
    reach: SampleFaces,
    rate: Option<RateScatter>,
    /// The points of count and blue-noise modes.
    points: Vec<SurfacePoint>,
    /// Count and blue-noise points wait for the stroke's end.
    stale: bool,
    /// The preview strands.
    strands: Option<Strands>,
    /// How long the last update took, ms.
    pub(crate) last_ms: f64,
}

/// What an update did: nothing, or new points for the page.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Updated {
    Nothing,
    Points,
}

impl ScatterState {
    /// The panel as `spec` asks, over `surface` painted with
    /// `colors` whose scalar channels are `scalars`.
    ///
    /// # Errors
    /// The field that cannot be met, as the page named it.
    pub(crate) fn new(
        spec: ScatterSpec,
        surface: &ColorMesh,
        colors: &MeshColors,
        scalars: &[String],
    ) -> Parsed<Self> {
        let start = Instant::now();
        let channel = Channel::named(&spec.channel, scalars, "channel")?;
        let length_channel = match spec.hair.as_ref().and_then(|h| h.length_channel.as_ref()) {
            Some(name) => Some(Channel::named(name, scalars, "hair.length_channel")?),
            None => None,
        };
        let mut state = Self {
            spec,
            channel,
            length_channel,
            reach: SampleFaces::default(),
            rate: None,
            points: Vec::new(),
            stale: false,
            strands: None,
            last_ms: 0.0,
        };
        match state.spec.mode {
            ScatterMode::Off => {}
            ScatterMode::Rate(rate) => {
                state.reach = SampleFaces::new(colors);
                state.rate = Some(rate_scatter(
                    surface,
                    colors,
                    channel,
                    rate,
                    state.spec.seed,
                )?);
            }
            ScatterMode::Count(_) | ScatterMode::BlueNoise(_) => {
                state.points = state.draw(surface, colors)?;
            }
        }
        state.grow(colors)?;
        state.last_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(state)
    }

    /// The points the page shows.
    pub(crate) fn points(&self) -> &[SurfacePoint] {
        match &self.rate {
            Some(r) => r.borrow_dependent().points(),
            None => &self.points,
        }
    }

    /// The request it follows, as the page sends it (a page that
    /// connects later shows it in its panel).
    pub(crate) fn request(&self) -> Value {
        let spec = &self.spec;
        let mut v = serde_json::json!({"channel": spec.channel, "seed": spec.seed});
        let (mode, key, amount) = match spec.mode {
            ScatterMode::Off => ("off", None, Value::Null),
            ScatterMode::Rate(r) => ("rate", Some("rate"), r.into()),
            ScatterMode::Count(n) => ("count", Some("count"), n.into()),
            ScatterMode::BlueNoise(n) => ("blue_noise", Some("count"), n.into()),
        };
        v["mode"] = mode.into();
        if let Some(key) = key {
            v[key] = amount;
        }
        v["hair"] = match &spec.hair {
            None => Value::Null,
            Some(h) => serde_json::json!({"length": h.length, "segments": h.segments,
                "length_channel": h.length_channel}),
        };
        v
    }

    /// The preview strands.
    pub(crate) fn strands(&self) -> Option<&Strands> {
        self.strands.as_ref()
    }

    /// Follows a change of the colours' values at `samples` (sorted).
    ///
    /// # Errors
    /// The scatter's, named `scatter`.
    pub(crate) fn samples_changed(
        &mut self,
        samples: &[u32],
        colors: &MeshColors,
    ) -> Result<Updated, (String, String)> {
        let start = Instant::now();
        let channel = self.channel;
        let Some(rate) = &mut self.rate else {
            // Count and blue-noise points are drawn again when the stroke
            // ends (a whole new set: nothing local to follow).
            self.stale = self.spec.mode != ScatterMode::Off;
            return Ok(Updated::Nothing);
        };
        let faces = self.reach.faces_of(samples);
        if faces.is_empty() {
            return Ok(Updated::Nothing);
        }
        let density = move |f: usize, b: [f32; 3]| channel.at(colors, f, b);
        rate.with_dependent_mut(|_, s| s.update_faces(&faces, ScatterDensity::Function(&density)))
            .map_err(scatter_error)?;
        self.grow(colors).map_err(|b| (b.field, b.problem))?;
        self.last_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(Updated::Points)
    }

    /// Follows new face resolutions (the sample numbering is new): the
    /// whole panel is made again.
    ///
    /// # Errors
    /// The scatter's, named `scatter`.
    pub(crate) fn layout_changed(
        &mut self,
        surface: &ColorMesh,
        colors: &MeshColors,
        scalars: &[String],
    ) -> Result<Updated, (String, String)> {
        if self.spec.mode == ScatterMode::Off {
            return Ok(Updated::Nothing);
        }
        *self = Self::new(self.spec.clone(), surface, colors, scalars)
            .map_err(|b| (b.field, b.problem))?;
        Ok(Updated::Points)
    }

    /// Draws count and blue-noise points again once a stroke has ended.
    ///
    /// # Errors
    /// The sampler's, named `scatter`.
    pub(crate) fn stroke_ended(
        &mut self,
        surface: &ColorMesh,
        colors: &MeshColors,
    ) -> Result<Updated, (String, String)> {
        if !self.stale {
            return Ok(Updated::Nothing);
        }
        let start = Instant::now();
        self.points = self
            .draw(surface, colors)
            .map_err(|b| (b.field, b.problem))?;
        self.stale = false;
        self.grow(colors).map_err(|b| (b.field, b.problem))?;
        self.last_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(Updated::Points)
    }

    /// Count or blue-noise points by the channel baked to a texture.
    fn draw(&self, surface: &ColorMesh, colors: &MeshColors) -> Parsed<Vec<SurfacePoint>> {
        let density = crate::colors::color_density(surface, colors, self.channel.sampling())
            .map_err(|e| BadField::new("channel", e.to_string()))?;
        let sampler = DensitySampler::new(
            density.mesh_ref(),
            mesh_sampling::Density::Texture(&density.texture),
        )
        .map_err(|e| BadField::new("channel", format!("{e} (paint some of it first)")))?;
        let points = match self.spec.mode {
            ScatterMode::Count(n) => sampler.sample_n(self.spec.seed, n),
            ScatterMode::BlueNoise(n) => blue_noise(
                &sampler,
                BlueNoiseTarget::Count(n),
                self.spec.seed,
                &mesh_sampling::BlueNoiseOptions {
                    packing: Packing::Elimination,
                    ..Default::default()
                },
            ),
            ScatterMode::Off | ScatterMode::Rate(_) => Ok(Vec::new()),
        }
        .map_err(|e| BadField::new("count", e.to_string()))?;
        Ok(points)
    }

    /// Grows the preview strands from evenly spaced points.
    fn grow(&mut self, colors: &MeshColors) -> Parsed<()> {
        self.strands = self.strands_from(colors, MAX_PREVIEW_STRANDS, false)?;
        Ok(())
    }

    /// Strands from at most `roots` evenly spaced points (all of them
    /// when there are fewer), as the request's hair asks, with per-point
    /// widths when `widths` (a renderer needs them; the preview's lines
    /// do not); `None` without hair.
    pub(crate) fn strands_from(
        &self,
        colors: &MeshColors,
        roots: usize,
        widths: bool,
    ) -> Parsed<Option<Strands>> {
        let Some(hair) = &self.spec.hair else {
            return Ok(None);
        };
        let points = self.points();
        let step = points.len().div_ceil(roots.max(1)).max(1);
        let chosen: Vec<SurfacePoint> = points.iter().step_by(step).copied().collect();
        let (length, scale) = (hair.length, self.length_channel);
        let options = HairOptions {
            segments: hair.segments,
            seed: self.spec.seed,
            widths,
            ..HairOptions::default()
        };
        mesh_sampling::grow_strands(&chosen, &options, |p| {
            let s = scale.map_or(1.0, |c| c.at(colors, p.face as usize, p.barycentric));
            StrandParams::straight(length * s)
        })
        .map(Some)
        .map_err(|e| BadField::new("hair", e.to_string()))
    }
}

/// A rate scatter of the channel over a copy of the surface.
fn rate_scatter(
    surface: &ColorMesh,
    colors: &MeshColors,
    channel: Channel,
    rate: f64,
    seed: u64,
) -> Parsed<RateScatter> {
    let copy = Surface {
        positions: surface.positions.clone(),
        indices: surface.faces.clone(),
    };
    let mesh = copy.mesh_ref();
    let area: f64 = (0..copy.indices.len()).map(|f| mesh.area(f)).sum();
    if rate * area > MAX_SHOWN_POINTS as f64 {
        return Err(BadField::new(
            "rate",
            format!(
                "{rate} points per unit area on an area of {area:.4} could give {} points, more than the {} the page shows",
                thousands(rate * area),
                thousands(MAX_SHOWN_POINTS as f64)
            ),
        ));
    }
    let density = move |f: usize, b: [f32; 3]| channel.at(colors, f, b);
    let options = ScatterOptions {
        max_density: Some(1.0),
        seed,
        clamp: true,
        ..ScatterOptions::new(rate)
    };
    RateScatter::try_new(copy, |s| {
        Scatter::new(s.mesh_ref(), ScatterDensity::Function(&density), &options)
    })
    .map_err(|e| BadField::new("rate", e.to_string()))
}

/// `x` rounded, its digits grouped by three: 5,709,518,805.
fn thousands(x: f64) -> String {
    let digits = format!("{:.0}", x.max(0.0));
    let mut out = String::new();
    for (k, c) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

fn scatter_error(e: mesh_sampling::Error) -> (String, String) {
    ("scatter".to_string(), e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_grouped_by_thousands() {
        assert_eq!(thousands(5_709_518_805.4), "5,709,518,805");
        assert_eq!(thousands(4e6), "4,000,000");
        assert_eq!(thousands(999.0), "999");
        assert_eq!(thousands(0.0), "0");
    }
}
