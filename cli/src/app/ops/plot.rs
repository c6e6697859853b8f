//! Line plots as PNG through plotters' bitmap backend (drawn in memory,
//! written by trilux-io, so no second image crate).

use std::path::Path;
use std::sync::OnceLock;

use plotters::prelude::*;

use crate::app::{Context, Result, invalid};

/// Fonts plotters can draw labels with (the DejaVu and Liberation fonts
/// most Linux systems have); `None` when none is installed.
fn font() -> Option<&'static str> {
    static FONT: OnceLock<Option<&'static str>> = OnceLock::new();
    *FONT.get_or_init(|| {
        let candidates = [
            "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
            "/usr/share/fonts/TTF/DejaVuSans.ttf",
            "/usr/share/fonts/dejavu/DejaVuSans.ttf",
            "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
            "/Library/Fonts/Arial.ttf",
            "C:\\Windows\\Fonts\\arial.ttf",
        ];
        candidates.iter().find_map(|p| {
            let bytes: &'static [u8] = Box::leak(std::fs::read(p).ok()?.into_boxed_slice());
            plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).ok()?;
            Some("sans-serif")
        })
    })
}

/// One curve: a name and its points.
pub(crate) struct Series {
    pub(crate) name: String,
    pub(crate) points: Vec<(f64, f64)>,
}

/// Draws `series` on log or linear axes and writes a PNG; returns `false`
/// (and writes nothing) when no font for the labels is installed.
pub(crate) fn line_plot(
    context: &Context,
    path: &Path,
    title: &str,
    labels: (&str, &str),
    log: (bool, bool),
    series: &[Series],
) -> Result<bool> {
    let Some(font) = font() else {
        return Ok(false);
    };
    let (w, h) = (800u32, 520u32);
    let mut buffer = vec![0u8; (w * h * 3) as usize];
    let chart = Chart {
        font,
        title,
        labels,
        log,
    };
    chart
        .draw(&mut buffer, (w, h), series)
        .map_err(|e| invalid(format!("{}: drawing the plot failed: {e}", path.display())))?;
    let srgb = trilux_io::image::srgb_to_linear;
    let image = trilux_io::image::Image {
        width: w,
        height: h,
        pixels: buffer
            .chunks_exact(3)
            .map(|p| {
                [
                    srgb(f32::from(p[0]) / 255.0),
                    srgb(f32::from(p[1]) / 255.0),
                    srgb(f32::from(p[2]) / 255.0),
                    1.0,
                ]
            })
            .collect(),
    };
    crate::app::write_image(context, path, &image)?;
    Ok(true)
}

/// The range of one axis over the finite (and, on a log axis, positive)
/// values, padded; `(1, 10)` when there is none.
fn axis_range(v: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let v: Vec<f64> = v.filter(|x| x.is_finite() && (!log || *x > 0.0)).collect();
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !(lo.is_finite() && hi.is_finite()) {
        (1.0, 10.0)
    } else if log {
        (lo / 1.5, hi * 1.5)
    } else {
        let pad = ((hi - lo) * 0.08).max(1e-9);
        (lo - pad, hi + pad)
    }
}

/// What a plot looks like: its font, title, axis labels and scales.
struct Chart<'a> {
    font: &'static str,
    title: &'a str,
    labels: (&'a str, &'a str),
    log: (bool, bool),
}

impl Chart<'_> {
    /// Draws `series` into `buffer` (RGB8, `w × h`).
    fn draw(
        &self,
        buffer: &mut [u8],
        (w, h): (u32, u32),
        series: &[Series],
    ) -> std::result::Result<(), Box<dyn std::error::Error>> {
        let Self {
            font,
            title,
            labels: (x_label, y_label),
            log: (log_x, log_y),
        } = *self;
        let xr = axis_range(
            series.iter().flat_map(|s| s.points.iter().map(|p| p.0)),
            log_x,
        );
        let yr = axis_range(
            series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
            log_y,
        );
        let root = BitMapBackend::with_buffer(buffer, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut builder = ChartBuilder::on(&root);
        let chart = builder
            .caption(title, (font, 22))
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(70);
        let colors = [RED, BLUE, GREEN, MAGENTA, CYAN, BLACK];
        macro_rules! body {
            ($chart:expr) => {{
                let mut c = $chart;
                c.configure_mesh()
                    .x_desc(x_label)
                    .y_desc(y_label)
                    .label_style((font, 14))
                    .draw()?;
                for (k, s) in series.iter().enumerate() {
                    let color = colors[k % colors.len()];
                    c.draw_series(LineSeries::new(
                        s.points.iter().copied(),
                        color.stroke_width(2),
                    ))?
                    .label(s.name.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
                    });
                    c.draw_series(s.points.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
                }
                c.configure_series_labels()
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .label_font((font, 14))
                    .draw()?;
            }};
        }
        match (log_x, log_y) {
            (true, true) => {
                body!(chart.build_cartesian_2d((xr.0..xr.1).log_scale(), (yr.0..yr.1).log_scale())?)
            }
            (true, false) => body!(chart.build_cartesian_2d((xr.0..xr.1).log_scale(), yr.0..yr.1)?),
            (false, true) => body!(chart.build_cartesian_2d(xr.0..xr.1, (yr.0..yr.1).log_scale())?),
            (false, false) => body!(chart.build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)?),
        }
        root.present()?;
        Ok(())
    }
}
