//! Charts of the study, as SVG text or PNG/RGB pixels, drawn with plotters and an embedded font
//! (DejaVu Sans, shipped in `assets/` with its licence), so no system font is needed.
//!
//! - [`speed_accuracy`]: speed on the x axis (ms per frame, log scale) against accuracy on the y
//!   axis (PSNR against the 1-spp reference), one labelled point per method per scene.
//! - [`sweep`]: one chart per sweep, one line per method, for a chosen [`SweepMetric`].
//! - [`scatter`]: points per series with a line through the mean at each x (the terrain study).
//!
//! Log axes are drawn as linear axes over `log10(x)` with tick labels written back as `x`: one
//! code path for both kinds of axis. Infinite PSNR (identical images) is drawn at
//! [`PSNR_CEILING_DB`].

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::error::StudyError;
use crate::harness::{Metrics, Record};
use crate::sweeps::{SweepKind, SweepSeries};

/// The embedded font (DejaVu Sans, Bitstream Vera licence: `assets/DejaVuSans-LICENSE.txt`).
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Infinite PSNR is plotted at this height.
pub const PSNR_CEILING_DB: f64 = 100.0;

/// Smallest silhouette displacement drawn on the log axis (a zero error sits here).
pub const SILHOUETTE_FLOOR_PX: f64 = 1e-3;

/// Smallest relative depth error drawn on the log axis (a zero error sits here).
pub const DEPTH_REL_FLOOR: f64 = 1e-8;

/// Register the embedded font once as plotters' "sans-serif".
fn ensure_font() -> Result<(), StudyError> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(StudyError::Chart {
            chart: "font".into(),
            message: "the embedded DejaVu Sans could not be parsed".into(),
        })
    }
}

/// What a sweep chart plots on its y axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SweepMetric {
    /// Mean silhouette displacement (px), log axis floored at [`SILHOUETTE_FLOOR_PX`] (a sweep
    /// spans 0 to thousands of pixels when a method stops drawing a sphere that fills the view).
    SilhouettePx,
    /// PSNR (dB), linear axis, infinite drawn at [`PSNR_CEILING_DB`].
    PsnrDb,
    /// Maximum depth error over the reference's depth range, log axis floored at
    /// [`DEPTH_REL_FLOOR`].
    DepthErrRel,
}

impl SweepMetric {
    pub const ALL: [SweepMetric; 3] = [
        SweepMetric::SilhouettePx,
        SweepMetric::PsnrDb,
        SweepMetric::DepthErrRel,
    ];

    pub fn name(self) -> &'static str {
        match self {
            SweepMetric::SilhouettePx => "silhouette",
            SweepMetric::PsnrDb => "psnr",
            SweepMetric::DepthErrRel => "depth",
        }
    }

    fn label(self) -> &'static str {
        match self {
            SweepMetric::SilhouettePx => "silhouette displacement (px, 0 drawn at 0.001)",
            SweepMetric::PsnrDb => "PSNR vs reference (dB)",
            SweepMetric::DepthErrRel => "max depth error / depth range",
        }
    }

    fn log(self) -> bool {
        self != SweepMetric::PsnrDb
    }

    fn value(self, m: &Metrics) -> f64 {
        match self {
            SweepMetric::SilhouettePx => m.silhouette_px.clamp(SILHOUETTE_FLOOR_PX, 1e6),
            SweepMetric::PsnrDb => m.psnr_db.min(PSNR_CEILING_DB),
            SweepMetric::DepthErrRel => m.depth_err_rel().clamp(DEPTH_REL_FLOOR, 1e3),
        }
    }
}

/// The colour of a method's points and lines (fixed, so charts agree with each other).
fn method_color(method: &str) -> RGBColor {
    match method {
        "polygon" => RGBColor(31, 119, 180),
        "lut" => RGBColor(255, 127, 14),
        "template" => RGBColor(44, 160, 44),
        "raycast" => RGBColor(214, 39, 40),
        _ => RGBColor(90, 90, 90),
    }
}

/// A linear or log10 axis mapping.
#[derive(Clone, Copy)]
struct Axis {
    log: bool,
}

impl Axis {
    fn map(self, v: f64) -> f64 {
        if self.log { v.max(1e-300).log10() } else { v }
    }

    /// Tick positions (mapped values) inside `r` at round values: 1, 2 and 5 times a power of
    /// ten on a log axis (only the powers when the axis spans many decades), and steps of 1, 2
    /// or 5 times a power of ten on a linear axis.
    fn ticks(self, r: &std::ops::Range<f64>) -> Vec<f64> {
        let (lo, hi) = (r.start, r.end);
        if !(lo.is_finite() && hi.is_finite() && hi > lo) {
            return vec![];
        }
        if self.log {
            let decades = hi - lo;
            let mults: &[f64] = if decades > 6.0 {
                &[1.0]
            } else if decades > 2.5 {
                &[1.0, 3.0]
            } else {
                &[1.0, 2.0, 5.0]
            };
            let step = if decades > 12.0 {
                (decades / 8.0).ceil() as i32
            } else {
                1
            };
            let mut out = Vec::new();
            let mut d = lo.floor() as i32;
            while (d as f64) <= hi.ceil() {
                for m in mults {
                    let t = m.log10() + d as f64;
                    if t >= lo && t <= hi {
                        out.push(t);
                    }
                }
                d += step;
            }
            out
        } else {
            let raw = (hi - lo) / 8.0;
            let mag = 10f64.powf(raw.log10().floor());
            let step = [1.0, 2.0, 5.0, 10.0]
                .iter()
                .map(|m| m * mag)
                .find(|s| *s >= raw)
                .unwrap_or(10.0 * mag);
            let mut out = Vec::new();
            let mut t = (lo / step).ceil() * step;
            while t <= hi && out.len() < 50 {
                out.push(t);
                t += step;
            }
            out
        }
    }

    fn label(self, t: f64) -> String {
        if self.log {
            // The tick is at a round value: print it without the rounding noise of 10^t.
            let v = 10f64.powf(t);
            let d = v.log10().floor();
            let m = (v / 10f64.powf(d)).round();
            let v = m * 10f64.powf(d);
            if (1e-3..1e5).contains(&v) {
                let s = format!("{v:.3}");
                s.trim_end_matches('0').trim_end_matches('.').to_string()
            } else {
                format!("{m}e{d}")
            }
        } else {
            let v = (t * 1000.0).round() / 1000.0;
            format!("{}", if v == 0.0 { 0.0 } else { v })
        }
    }
}

/// A linear coordinate (over mapped values) whose ticks are the given round values.
#[derive(Clone)]
struct Ticked {
    range: std::ops::Range<f64>,
    ticks: Vec<f64>,
}

impl Ticked {
    fn new(axis: Axis, range: std::ops::Range<f64>) -> Ticked {
        let ticks = axis.ticks(&range);
        Ticked { range, ticks }
    }
}

impl Ranged for Ticked {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let span = self.range.end - self.range.start;
        let f = if span > 0.0 {
            (v - self.range.start) / span
        } else {
            0.5
        };
        let f = f.clamp(-10.0, 10.0);
        limit.0 + ((limit.1 - limit.0) as f64 * f).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.max_num_points() == 0 {
            return vec![];
        }
        self.ticks.clone()
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.range.clone()
    }
}

/// Draws `pts` (x, y, open) as one method's markers, a shape of its own per method (as well as
/// its colour, so that overlapping series stay apart); open markers are hollow. With `legend`,
/// the series gets the method's legend entry.
fn draw_markers<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<Ticked, Ticked>>,
    method: &str,
    color: RGBColor,
    pts: &[(f64, f64, bool)],
    size: i32,
    legend: bool,
) -> Result<(), String> {
    let style = move |open: bool| {
        if open {
            color.stroke_width(2)
        } else {
            color.filled()
        }
    };
    let e = |err: DrawingAreaErrorKind<DB::ErrorType>| err.to_string();
    macro_rules! shape {
        ($make:expr) => {{
            let anno = chart
                .draw_series(
                    pts.iter()
                        .map(|&(x, y, open)| EmptyElement::at((x, y)) + $make((0, 0), style(open))),
                )
                .map_err(e)?;
            if legend {
                anno.label(method).legend(move |(x, y)| {
                    EmptyElement::at((x + 9, y)) + $make((0, 0), style(false))
                });
            }
        }};
    }
    match method {
        "polygon" => shape!(|c: (i32, i32), st: ShapeStyle| Rectangle::new(
            [(c.0 - size, c.1 - size), (c.0 + size, c.1 + size)],
            st
        )),
        "lut" => shape!(|c: (i32, i32), st: ShapeStyle| TriangleMarker::new(c, size + 1, st)),
        "template" => {
            shape!(|c: (i32, i32), st: ShapeStyle| Cross::new(c, size, st.stroke_width(2)))
        }
        _ => shape!(|c: (i32, i32), st: ShapeStyle| Circle::new(c, size, st)),
    }
    Ok(())
}

/// Chart text for a capped value.
const CAPPED_NOTE: &str =
    "open marker: infinite PSNR (identical to the reference), drawn at 100 dB";

/// Padded range of mapped values (never empty).
fn range(vals: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in vals.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return 0.0..1.0;
    }
    let pad = ((hi - lo) * 0.08).max(0.05 * hi.abs().max(1.0)).max(1e-9);
    (lo - pad)..(hi + pad)
}

/// The series' legend in a white box at `position`, as every chart here draws it.
fn legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(position)
        .draw()
        .map_err(|e| e.to_string())
}

fn chart_err(chart: &str) -> impl Fn(String) -> StudyError + '_ {
    move |message| StudyError::Chart {
        chart: chart.to_string(),
        message,
    }
}

/// Draw the speed-versus-accuracy chart: one point per record (the reference's own record
/// left out), against the 1-spp reference when the records hold it (a sphere comparison), else
/// against whatever reference each was measured with (e.g. the quality axis's converged ones).
fn draw_speed_accuracy<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    records: &[Record],
) -> Result<(), String> {
    let one_spp = records.iter().any(|r| r.reference == "reftrace-1spp");
    let pts: Vec<&Record> = records
        .iter()
        .filter(|r| (!one_spp || r.reference == "reftrace-1spp") && r.method != "reftrace")
        .filter(|r| r.ms_per_frame.is_finite() && r.ms_per_frame > 0.0)
        .collect();
    // Series in first-seen order; the sphere methods keep their fixed colours.
    let mut methods: Vec<&str> = Vec::new();
    for r in &pts {
        if !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
    }
    let xa = Axis { log: true };
    let ya = Axis { log: false };
    let xr = range(pts.iter().map(|r| xa.map(r.ms_per_frame)));
    let yr = range(pts.iter().map(|r| r.psnr_db.min(PSNR_CEILING_DB)));
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
        .caption("Speed versus accuracy", ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(56)
        .build_cartesian_2d(Ticked::new(xa, xr.clone()), Ticked::new(ya, yr.clone()))
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("milliseconds per frame (log scale)")
        .y_desc("PSNR vs reference ray tracer (dB)")
        .x_label_formatter(&|t| xa.label(*t))
        .y_label_formatter(&|t| ya.label(*t))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .draw()
        .map_err(|e| e.to_string())?;
    let mut capped = false;
    for (k, &method) in methods.iter().enumerate() {
        let color = match method {
            "polygon" | "lut" | "template" | "raycast" => method_color(method),
            _ => {
                let (r, g, b) = Palette99::pick(k).to_rgba().rgb();
                RGBColor(r, g, b)
            }
        };
        let mine: Vec<&&Record> = pts.iter().filter(|r| r.method == method).collect();
        if mine.is_empty() {
            continue;
        }
        let at: Vec<(f64, f64, bool)> = mine
            .iter()
            .map(|r| {
                (
                    xa.map(r.ms_per_frame),
                    r.psnr_db.min(PSNR_CEILING_DB),
                    r.psnr_db > PSNR_CEILING_DB,
                )
            })
            .collect();
        capped |= at.iter().any(|p| p.2);
        draw_markers(&mut chart, method, color, &at, 6, true)?;
        chart
            .draw_series(mine.iter().zip(&at).map(|(r, &(x, y, open))| {
                let text = if open {
                    format!("{} {} (∞ dB)", r.method, r.scene)
                } else {
                    format!("{} {}", r.method, r.scene)
                };
                // Labels stay inside the plot: left of points in the right third, below
                // points near the top.
                let fx = (x - xr.start) / (xr.end - xr.start);
                let fy = (y - yr.start) / (yr.end - yr.start);
                let dx = if fx > 0.62 {
                    -(text.chars().count() as i32 * 7 + 10)
                } else {
                    8
                };
                let dy = if fy > 0.9 { 6 } else { -14 };
                EmptyElement::at((x, y))
                    + Text::new(text, (dx, dy), ("sans-serif", 13).into_font().color(&BLACK))
            }))
            .map_err(|e| e.to_string())?;
    }
    legend(&mut chart, SeriesLabelPosition::LowerRight)?;
    if capped {
        root.draw(&Text::new(
            CAPPED_NOTE,
            (72, 40),
            ("sans-serif", 13).into_font().color(&BLACK),
        ))
        .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())
}

/// Draw one sweep chart (all series must be of one kind).
fn draw_sweep<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    series: &[SweepSeries],
    metric: SweepMetric,
) -> Result<(), String> {
    let kind = series.first().map(|s| s.kind).unwrap_or(SweepKind::Fov);
    let xa = Axis { log: kind.log_x() };
    let ya = Axis { log: metric.log() };
    let xr = range(
        series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| xa.map(p.x))),
    );
    let yr = range(
        series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| ya.map(metric.value(&p.metrics)))),
    );
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{} versus {}", metric.label(), kind.x_label()),
            ("sans-serif", 18),
        )
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(Ticked::new(xa, xr.clone()), Ticked::new(ya, yr.clone()))
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(kind.x_label())
        .y_desc(metric.label())
        .x_label_formatter(&|t| xa.label(*t))
        .y_label_formatter(&|t| ya.label(*t))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .draw()
        .map_err(|e| e.to_string())?;
    // Series drawn first get wider lines, so a series lying on top of another leaves it visible
    // as an outline; every method also has its own marker shape.
    let n = series.len();
    let mut capped = false;
    for (i, s) in series.iter().enumerate() {
        let method = s.method.name();
        let color = method_color(method);
        let width = 2 + 2 * (n - 1 - i) as u32;
        let pts: Vec<(f64, f64, bool)> = s
            .points
            .iter()
            .map(|p| {
                let open = metric == SweepMetric::PsnrDb && p.metrics.psnr_db > PSNR_CEILING_DB;
                (xa.map(p.x), ya.map(metric.value(&p.metrics)), open)
            })
            .collect();
        capped |= pts.iter().any(|p| p.2);
        chart
            .draw_series(LineSeries::new(
                pts.iter().map(|p| (p.0, p.1)),
                color.mix(0.85).stroke_width(width),
            ))
            .map_err(|e| e.to_string())?;
        draw_markers(&mut chart, method, color, &pts, 4, true)?;
    }
    legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    if capped {
        root.draw(&Text::new(
            CAPPED_NOTE,
            (CHART_SIZE.0 as i32 - 480, 38),
            ("sans-serif", 13).into_font().color(&BLACK),
        ))
        .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())
}

/// Where a chart goes.
#[derive(Debug)]
pub enum Target<'a> {
    /// SVG text appended to the string.
    Svg(&'a mut String),
    /// RGB8 pixels written into the buffer (`3 · w · h` bytes).
    Rgb(&'a mut [u8]),
    /// A PNG file.
    Png(&'a Path),
}

/// Chart size in pixels (SVG user units).
pub const CHART_SIZE: (u32, u32) = (960, 640);

fn draw_on(
    name: &str,
    target: Target,
    size: (u32, u32),
    svg: impl FnOnce(DrawingArea<SVGBackend, Shift>) -> Result<(), String>,
    bmp: impl FnOnce(DrawingArea<BitMapBackend, Shift>) -> Result<(), String>,
) -> Result<(), StudyError> {
    ensure_font()?;
    let err = chart_err(name);
    match target {
        Target::Svg(s) => svg(SVGBackend::with_string(s, size).into_drawing_area()).map_err(err),
        Target::Rgb(buf) => {
            let need = 3 * size.0 as usize * size.1 as usize;
            if buf.len() != need {
                return Err(StudyError::BadOption {
                    what: "rgb buffer length",
                    value: format!("{} (need {need})", buf.len()),
                });
            }
            bmp(BitMapBackend::with_buffer(buf, size).into_drawing_area()).map_err(err)
        }
        Target::Png(path) => bmp(BitMapBackend::new(path, size).into_drawing_area()).map_err(err),
    }
}

/// Draw the speed-versus-accuracy chart at [`CHART_SIZE`].
pub fn speed_accuracy(records: &[Record], target: Target) -> Result<(), StudyError> {
    draw_on(
        "speed_accuracy",
        target,
        CHART_SIZE,
        |a| draw_speed_accuracy(a, records),
        |a| draw_speed_accuracy(a, records),
    )
}

/// Draw one sweep chart at [`CHART_SIZE`]; `series` should all be of one [`SweepKind`].
pub fn sweep(
    series: &[SweepSeries],
    metric: SweepMetric,
    target: Target,
) -> Result<(), StudyError> {
    draw_on(
        "sweep",
        target,
        CHART_SIZE,
        |a| draw_sweep(a, series, metric),
        |a| draw_sweep(a, series, metric),
    )
}

/// Write `speed_accuracy.{svg,png}` and, per sweep kind and metric,
/// `sweep_<kind>_<metric>.{svg,png}` into `dir`; returns the paths written.
pub fn write_charts(
    dir: &Path,
    records: &[Record],
    series: &[SweepSeries],
) -> Result<Vec<PathBuf>, StudyError> {
    let mut written = Vec::new();
    let mut emit =
        |stem: String, draw: &dyn Fn(Target) -> Result<(), StudyError>| -> Result<(), StudyError> {
            let mut svg = String::new();
            draw(Target::Svg(&mut svg))?;
            let svg_path = dir.join(format!("{stem}.svg"));
            crate::error::write_file(svg_path.clone(), svg.as_bytes())?;
            let png_path = dir.join(format!("{stem}.png"));
            draw(Target::Png(&png_path))?;
            written.push(svg_path);
            written.push(png_path);
            Ok(())
        };
    if !records.is_empty() {
        emit("speed_accuracy".into(), &|t| speed_accuracy(records, t))?;
    }
    for kind in SweepKind::ALL {
        let mine: Vec<SweepSeries> = series.iter().filter(|s| s.kind == kind).cloned().collect();
        if mine.is_empty() {
            continue;
        }
        for metric in SweepMetric::ALL {
            emit(format!("sweep_{}_{}", kind.name(), metric.name()), &|t| {
                sweep(&mine, metric, t)
            })?;
        }
    }
    Ok(written)
}

/// Colours of [`scatter`]'s series, in order (the terrain study's sampler palette).
const SCATTER_COLOURS: [RGBColor; 8] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0x7f, 0x7f, 0x7f),
];

/// A scatter chart at [`CHART_SIZE`]: one colour per series, a marker at every finite point and a
/// line through the mean `y` at each distinct `x` (the terrain study's PSNR against pitch and
/// height). Non-finite points are left out.
pub fn scatter(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[(String, Vec<(f64, f64)>)],
    target: Target,
) -> Result<(), StudyError> {
    let finite: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|(_, pts)| {
            let mut v: Vec<(f64, f64)> = pts
                .iter()
                .copied()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .collect();
            v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
            v
        })
        .collect();
    // Room on the right for the legend, so that it covers no point.
    let xr = range(finite.iter().flatten().map(|p| p.0));
    let xr = xr.start..xr.end + 0.3 * (xr.end - xr.start);
    let yr = range(finite.iter().flatten().map(|p| p.1));
    fn draw<DB: DrawingBackend>(
        root: DrawingArea<DB, Shift>,
        [title, x_label, y_label]: [&str; 3],
        names: &[&str],
        finite: &[Vec<(f64, f64)>],
        xr: std::ops::Range<f64>,
        yr: std::ops::Range<f64>,
    ) -> Result<(), String> {
        let e = |err: DrawingAreaErrorKind<DB::ErrorType>| err.to_string();
        root.fill(&WHITE).map_err(e)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(60)
            .build_cartesian_2d(xr, yr)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style(("sans-serif", 14))
            .light_line_style(RGBColor(238, 238, 238))
            .draw()
            .map_err(e)?;
        for (k, (name, pts)) in names.iter().zip(finite).enumerate() {
            let c = SCATTER_COLOURS[k % SCATTER_COLOURS.len()];
            let mut means: Vec<(f64, f64)> = Vec::new();
            let mut i = 0;
            while i < pts.len() {
                let j = pts[i..].iter().take_while(|p| p.0 == pts[i].0).count();
                let m = pts[i..i + j].iter().map(|p| p.1).sum::<f64>() / j as f64;
                means.push((pts[i].0, m));
                i += j;
            }
            chart
                .draw_series(LineSeries::new(means, c.stroke_width(2)))
                .map_err(e)?
                .label(*name)
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], c.stroke_width(3)));
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
                .map_err(e)?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present().map_err(e)
    }
    let names: Vec<&str> = series.iter().map(|s| s.0.as_str()).collect();
    let labels = [title, x_label, y_label];
    draw_on(
        "scatter",
        target,
        CHART_SIZE,
        |r| draw(r, labels, &names, &finite, xr.clone(), yr.clone()),
        |r| draw(r, labels, &names, &finite, xr.clone(), yr.clone()),
    )
}

/// A line chart of `size` pixels (`texmap plot`: a table's columns against one of them): one
/// colour per series (the first eight of [`SCATTER_COLOURS`], then again), each a polyline
/// broken where a `y` is not finite (an empty cell), a legend when there are two or more.
/// `title` may be empty.
pub fn lines(
    [title, x_label, y_label]: [&str; 3],
    series: &[(String, Vec<(f64, f64)>)],
    size: (u32, u32),
    target: Target,
) -> Result<(), StudyError> {
    let xr = range(series.iter().flat_map(|s| s.1.iter().map(|p| p.0)));
    let yr = range(
        series
            .iter()
            .flat_map(|s| s.1.iter().filter(|p| p.0.is_finite()).map(|p| p.1)),
    );
    fn draw<DB: DrawingBackend>(
        root: DrawingArea<DB, Shift>,
        labels: [&str; 3],
        series: &[(String, Vec<(f64, f64)>)],
        xr: std::ops::Range<f64>,
        yr: std::ops::Range<f64>,
    ) -> Result<(), String> {
        let e = |err: DrawingAreaErrorKind<DB::ErrorType>| err.to_string();
        root.fill(&WHITE).map_err(e)?;
        let mut builder = ChartBuilder::on(&root);
        if !labels[0].is_empty() {
            builder.caption(labels[0], ("sans-serif", 22));
        }
        let mut chart = builder
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(xr, yr)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc(labels[1])
            .y_desc(labels[2])
            .label_style(("sans-serif", 14))
            .light_line_style(RGBColor(238, 238, 238))
            .draw()
            .map_err(e)?;
        for (k, (name, points)) in series.iter().enumerate() {
            let c = SCATTER_COLOURS[k % SCATTER_COLOURS.len()];
            let mut first = true;
            for run in points
                .split(|p| !(p.0.is_finite() && p.1.is_finite()))
                .filter(|r| !r.is_empty())
            {
                let drawn = chart
                    .draw_series(LineSeries::new(run.iter().copied(), c.stroke_width(2)))
                    .map_err(e)?;
                if std::mem::take(&mut first) {
                    drawn.label(name.as_str()).legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 20, y)], c.stroke_width(3))
                    });
                }
            }
        }
        if series.len() > 1 {
            legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        }
        root.present().map_err(e)
    }
    draw_on(
        "lines",
        target,
        size,
        |a| draw(a, [title, x_label, y_label], series, xr.clone(), yr.clone()),
        |a| draw(a, [title, x_label, y_label], series, xr.clone(), yr.clone()),
    )
}

/// Size of [`structure_timeline`] in pixels.
pub const TIMELINE_SIZE: (u32, u32) = (1200, 640);

/// A secondary-structure timeline (VMD's Timeline, the map of `gmx dssp`): the residues up the
/// y axis (labelled by `resids`), the frames along x (labelled by `x`, one value per frame: the
/// frame numbers or their times), each cell in VMD's Structure colours (helix purple, strand
/// yellow, coil white; md-scene's `STRUCTURE_COLORS`). `classes[f][r]` is residue `r`'s class
/// in frame `f`; a residue's run of frames in one class is one rectangle.
pub fn structure_timeline(
    x: &[f64],
    x_label: &str,
    resids: &[i64],
    classes: &[Vec<texmap_md_io::secondary::Structure>],
    target: Target,
) -> Result<(), StudyError> {
    use texmap_md_io::secondary::Structure;
    let colour = |c: Structure| match c {
        Structure::Coil => RGBColor(255, 255, 255),
        Structure::Helix => RGBColor(166, 0, 166),
        Structure::Strand => RGBColor(255, 255, 0),
    };
    // Per residue, the runs (first frame, end frame, class) of one class.
    let mut runs: Vec<(usize, usize, usize, Structure)> = Vec::new();
    for r in 0..resids.len() {
        let mut f = 0;
        while f < classes.len() {
            let c = classes[f][r];
            let end = f + classes[f..].iter().take_while(|row| row[r] == c).count();
            if c != Structure::Coil {
                runs.push((r, f, end, c));
            }
            f = end;
        }
    }
    let (nf, nr) = (classes.len().max(1) as f64, resids.len().max(1) as f64);
    // Tick labels: the x value or residue number of the cell starting at an axis position
    // (cells span [i, i + 1)); none between cells' starts.
    let cell = |v: f64| (v >= 0.0 && (v - v.round()).abs() < 1e-9).then_some(v.round() as usize);
    let x_at = |v: &f64| {
        let t = cell(*v).and_then(|i| x.get(i));
        t.map(|t| format!("{}", (t * 1000.0).round() / 1000.0))
            .unwrap_or_default()
    };
    let resid_at = |v: &f64| {
        let r = cell(*v).and_then(|i| resids.get(i));
        r.map(|r| r.to_string()).unwrap_or_default()
    };
    fn draw<DB: DrawingBackend>(
        root: DrawingArea<DB, Shift>,
        (nf, nr): (f64, f64),
        runs: &[(usize, usize, usize, texmap_md_io::secondary::Structure)],
        colour: &dyn Fn(texmap_md_io::secondary::Structure) -> RGBColor,
        x_label: &str,
        [x_at, resid_at]: [&dyn Fn(&f64) -> String; 2],
    ) -> Result<(), String> {
        use texmap_md_io::secondary::Structure;
        let e = |err: DrawingAreaErrorKind<DB::ErrorType>| err.to_string();
        root.fill(&WHITE).map_err(e)?;
        let mut chart = ChartBuilder::on(&root)
            .caption("secondary structure (DSSP)", ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(60)
            // Room on the right for the legend, so that it covers no cell.
            .build_cartesian_2d(0.0..nf * 1.15, 0.0..nr)
            .map_err(e)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(x_label)
            .y_desc("residue")
            .x_label_formatter(x_at)
            .y_label_formatter(resid_at)
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(e)?;
        chart
            .draw_series(runs.iter().map(|&(r, f0, f1, c)| {
                Rectangle::new(
                    [(f0 as f64, r as f64), (f1 as f64, r as f64 + 1.0)],
                    colour(c).filled(),
                )
            }))
            .map_err(e)?;
        for c in [Structure::Helix, Structure::Strand, Structure::Coil] {
            let fill = colour(c);
            chart
                .draw_series(std::iter::empty::<Rectangle<(f64, f64)>>())
                .map_err(e)?
                .label(c.name())
                .legend(move |(x, y)| {
                    // Outlined, so that coil's white box shows.
                    EmptyElement::at((x, y))
                        + Rectangle::new([(0, -6), (14, 6)], ShapeStyle::from(fill).filled())
                        + Rectangle::new([(0, -6), (14, 6)], BLACK.stroke_width(1))
                });
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        root.present().map_err(e)
    }
    draw_on(
        "structure_timeline",
        target,
        TIMELINE_SIZE,
        |a| draw(a, (nf, nr), &runs, &colour, x_label, [&x_at, &resid_at]),
        |a| draw(a, (nf, nr), &runs, &colour, x_label, [&x_at, &resid_at]),
    )
}

/// Size of [`matrix_heatmap`] in pixels.
pub const HEATMAP_SIZE: (u32, u32) = (900, 760);

/// Most cells a side [`matrix_heatmap`] draws: a larger matrix is drawn as the means of
/// blocks of its cells.
pub const HEATMAP_CELLS: usize = 300;

/// A square matrix over the frames (the pairwise RMSD of `texmap convert --rmsd-matrix`) as a
/// heatmap in viridis from 0 to its largest value, with a colour bar titled `value_label`:
/// frames along both axes, labelled by `x` (one value per frame: frame numbers or times),
/// frame 0 at the bottom left. `matrix` is row-major `x.len()²`.
pub fn matrix_heatmap(
    x: &[f64],
    x_label: &str,
    matrix: &[f64],
    value_label: &str,
    target: Target,
) -> Result<(), StudyError> {
    let n = x.len();
    if matrix.len() != n * n {
        return Err(StudyError::BadOption {
            what: "heatmap matrix length",
            value: format!("{} (need {})", matrix.len(), n * n),
        });
    }
    // Blocks of `b` frames a side, each drawn as its cells' mean.
    let b = n.div_ceil(HEATMAP_CELLS).max(1);
    let cells = n.div_ceil(b);
    let mut blocks = vec![None; cells * cells];
    for (bi, row) in blocks.chunks_mut(cells.max(1)).enumerate() {
        for (bj, out) in row.iter_mut().enumerate() {
            let (mut sum, mut count) = (0.0, 0usize);
            for i in bi * b..((bi + 1) * b).min(n) {
                for j in bj * b..((bj + 1) * b).min(n) {
                    sum += matrix[i * n + j];
                    count += 1;
                }
            }
            *out = Some(sum / count.max(1) as f64);
        }
    }
    let top = matrix.iter().fold(0.0f64, |m, v| m.max(*v));
    let cell = |v: f64| (v >= 0.0 && (v - v.round()).abs() < 1e-9).then_some(v.round() as usize);
    let x_at = |v: &f64| {
        let t = cell(*v).and_then(|i| x.get(i));
        t.map(|t| format!("{}", (t * 1000.0).round() / 1000.0))
            .unwrap_or_default()
    };
    let grid = Grid {
        x: 0.0..n as f64,
        y: 0.0..n as f64,
        step: (b as f64, b as f64),
        side: cells,
        cells: &blocks,
        top,
        labels: [x_label, x_label, value_label],
    };
    grid_heatmap("matrix_heatmap", &grid, Some(&x_at), target)
}

/// A free-energy landscape (gmx sham's Gibbs landscape; `texmap convert --pca-landscape`) as a
/// heatmap at [`HEATMAP_SIZE`]: its two projections along the axes (`x_label`, `y_label`),
/// each visited bin in viridis from 0 (the most visited, dark) to the largest ΔG, empty bins
/// white, a colour bar titled `value_label`.
pub fn landscape(
    l: &texmap_md_io::pca::Landscape,
    x_label: &str,
    y_label: &str,
    value_label: &str,
    target: Target,
) -> Result<(), StudyError> {
    let top = l
        .free_energy
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(*v));
    let bins = l.bins as f64;
    let grid = Grid {
        x: l.x.0..l.x.1,
        y: l.y.0..l.y.1,
        step: ((l.x.1 - l.x.0) / bins, (l.y.1 - l.y.0) / bins),
        side: l.bins,
        cells: &l.free_energy,
        top,
        labels: [x_label, y_label, value_label],
    };
    grid_heatmap("landscape", &grid, None, target)
}

/// Most (φ, ψ) pairs [`Ramachandran`] draws as dots; past them it draws their density.
pub const RAMACHANDRAN_DOTS: usize = 20_000;

/// Bins a side of [`Ramachandran`]'s density (2° each).
pub const RAMACHANDRAN_BINS: usize = 180;

/// A Ramachandran plot's data (MDAnalysis's `Ramachandran.plot`, gmx rama): the backbone
/// dihedral pairs (φ, ψ) in degrees of every residue in every frame, kept as points up to
/// [`RAMACHANDRAN_DOTS`] and always counted on a 2° grid, so that a long run takes bounded
/// memory.
#[derive(Clone, Debug)]
pub struct Ramachandran {
    points: Vec<(f64, f64)>,
    counts: Vec<u32>,
    total: usize,
}

impl Default for Ramachandran {
    fn default() -> Self {
        Ramachandran {
            points: Vec::new(),
            counts: vec![0; RAMACHANDRAN_BINS * RAMACHANDRAN_BINS],
            total: 0,
        }
    }
}

impl Ramachandran {
    /// Adds one residue's (φ, ψ) in degrees (−180 to 180; a pair not finite is left out).
    pub fn add(&mut self, phi: f64, psi: f64) {
        if !(phi.is_finite() && psi.is_finite()) {
            return;
        }
        let bin = |a: f64| {
            let k = ((a + 180.0) / 360.0 * RAMACHANDRAN_BINS as f64).floor() as isize;
            k.clamp(0, RAMACHANDRAN_BINS as isize - 1) as usize
        };
        self.counts[bin(psi) * RAMACHANDRAN_BINS + bin(phi)] += 1;
        if self.points.len() < RAMACHANDRAN_DOTS {
            self.points.push((phi, psi));
        }
        self.total += 1;
    }

    /// The pairs added.
    pub fn len(&self) -> usize {
        self.total
    }

    /// Whether no pair was added.
    pub fn is_empty(&self) -> bool {
        self.total == 0
    }

    /// The plot at [`HEATMAP_SIZE`]: φ along x and ψ up, −180° to 180°, each pair a dark dot
    /// while there are at most [`RAMACHANDRAN_DOTS`], else their density on 2° bins as
    /// `−ln(p / p_max)` in viridis (0, dark, at the most visited; empty bins white).
    pub fn draw(&self, target: Target) -> Result<(), StudyError> {
        if self.total > RAMACHANDRAN_DOTS {
            let most = f64::from(self.counts.iter().copied().max().unwrap_or(1));
            let cells: Vec<Option<f64>> = self
                .counts
                .iter()
                .map(|&n| (n > 0).then(|| -(f64::from(n) / most).ln()))
                .collect();
            let top = cells.iter().flatten().fold(0.0f64, |m, v| m.max(*v));
            let step = 360.0 / RAMACHANDRAN_BINS as f64;
            let grid = Grid {
                x: -180.0..180.0,
                y: -180.0..180.0,
                step: (step, step),
                side: RAMACHANDRAN_BINS,
                cells: &cells,
                top,
                labels: ["φ (°)", "ψ (°)", "−ln(p / p_max)"],
            };
            return grid_heatmap("ramachandran", &grid, None, target);
        }
        fn draw<DB: DrawingBackend>(
            root: DrawingArea<DB, Shift>,
            points: &[(f64, f64)],
        ) -> Result<(), String> {
            let e = |err: DrawingAreaErrorKind<DB::ErrorType>| err.to_string();
            root.fill(&WHITE).map_err(e)?;
            let mut chart = ChartBuilder::on(&root)
                .margin(16)
                .x_label_area_size(44)
                .y_label_area_size(60)
                .build_cartesian_2d(-180.0..180.0, -180.0..180.0)
                .map_err(e)?;
            chart
                .configure_mesh()
                .x_desc("φ (°)")
                .y_desc("ψ (°)")
                .x_labels(7)
                .y_labels(7)
                .x_label_formatter(&|v| format!("{v:.0}"))
                .y_label_formatter(&|v| format!("{v:.0}"))
                .label_style(("sans-serif", 14))
                .light_line_style(RGBColor(238, 238, 238))
                .draw()
                .map_err(e)?;
            let ink = RGBColor(0x1f, 0x3a, 0x93);
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 3, ink.filled())))
                .map_err(e)?;
            root.present().map_err(e)
        }
        draw_on(
            "ramachandran",
            target,
            HEATMAP_SIZE,
            |a| draw(a, &self.points),
            |a| draw(a, &self.points),
        )
    }
}

/// A square grid of cells to draw as a heatmap.
struct Grid<'a> {
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    /// A cell's width and height.
    step: (f64, f64),
    /// Cells a side.
    side: usize,
    /// Row-major, x along a row, y up; `None` is left white.
    cells: &'a [Option<f64>],
    /// The value of the colour bar's top (its bottom is 0).
    top: f64,
    /// The x axis's, the y axis's and the colour bar's titles.
    labels: [&'a str; 3],
}

/// [`Grid`] in viridis at [`HEATMAP_SIZE`], with a colour bar; both axes labelled by
/// `format` when given.
fn grid_heatmap(
    name: &'static str,
    grid: &Grid,
    format: Option<&dyn Fn(&f64) -> String>,
    target: Target,
) -> Result<(), StudyError> {
    use texmap_md_scene::Colormap;
    let top = grid.top.max(f64::MIN_POSITIVE);
    let colour = |v: f64| {
        let c = Colormap::Viridis.srgb((v / top) as f32);
        RGBColor(
            (c[0] * 255.0).round() as u8,
            (c[1] * 255.0).round() as u8,
            (c[2] * 255.0).round() as u8,
        )
    };
    fn draw<DB: DrawingBackend>(
        root: DrawingArea<DB, Shift>,
        grid: &Grid,
        top: f64,
        colour: &dyn Fn(f64) -> RGBColor,
        format: Option<&dyn Fn(&f64) -> String>,
    ) -> Result<(), String> {
        let e = |err: DrawingAreaErrorKind<DB::ErrorType>| err.to_string();
        root.fill(&WHITE).map_err(e)?;
        let (main, bar) = root.split_horizontally(HEATMAP_SIZE.0 - 130);
        let mut chart = ChartBuilder::on(&main)
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(60)
            .build_cartesian_2d(grid.x.clone(), grid.y.clone())
            .map_err(e)?;
        let mut mesh = chart.configure_mesh();
        mesh.disable_mesh()
            .x_desc(grid.labels[0])
            .y_desc(grid.labels[1])
            .label_style(("sans-serif", 14));
        if let Some(f) = format {
            mesh.x_label_formatter(f).y_label_formatter(f);
        }
        mesh.draw().map_err(e)?;
        let (w, h) = grid.step;
        let side = grid.side;
        chart
            .draw_series((0..side * side).filter_map(|k| {
                let v = grid.cells[k]?;
                let (i, j) = (k % side, k / side);
                let (x0, y0) = (grid.x.start + i as f64 * w, grid.y.start + j as f64 * h);
                Some(Rectangle::new(
                    [
                        (x0, y0),
                        ((x0 + w).min(grid.x.end), (y0 + h).min(grid.y.end)),
                    ],
                    colour(v).filled(),
                ))
            }))
            .map_err(e)?;
        // The colour bar: 100 steps from 0 to the largest value.
        let mut scale = ChartBuilder::on(&bar)
            .margin_top(16)
            .margin_bottom(60)
            .margin_right(16)
            .y_label_area_size(56)
            .caption(grid.labels[2], ("sans-serif", 14))
            .build_cartesian_2d(0.0..1.0, 0.0..top)
            .map_err(e)?;
        scale
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .label_style(("sans-serif", 13))
            .draw()
            .map_err(e)?;
        scale
            .draw_series((0..100).map(|k| {
                let (v0, v1) = (top * k as f64 / 100.0, top * (k + 1) as f64 / 100.0);
                Rectangle::new([(0.0, v0), (1.0, v1)], colour(0.5 * (v0 + v1)).filled())
            }))
            .map_err(e)?;
        root.present().map_err(e)
    }
    draw_on(
        name,
        target,
        HEATMAP_SIZE,
        |a| draw(a, grid, top, &colour, format),
        |a| draw(a, grid, top, &colour, format),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweeps::SweepPoint;
    use texmap_impostor::Method;

    #[test]
    fn ticks_sit_at_round_values_on_both_kinds_of_axis() {
        let log = Axis { log: true };
        let r = 0.8f64.log10()..30f64.log10();
        let labels: Vec<String> = log.ticks(&r).iter().map(|t| log.label(*t)).collect();
        assert_eq!(labels, ["1", "2", "5", "10", "20"]);
        // Many decades: powers of ten only, written as such.
        let r = -9.0..2.5;
        let labels: Vec<String> = log.ticks(&r).iter().map(|t| log.label(*t)).collect();
        assert_eq!(labels[0], "1e-9");
        assert!(labels.contains(&"0.001".to_string()) && labels.contains(&"100".to_string()));
        assert!(
            labels
                .iter()
                .all(|l| !l.contains("1.585") && !l.contains("2.512"))
        );
        let lin = Axis { log: false };
        let ticks = lin.ticks(&(23.7..61.2));
        assert_eq!(ticks, [25.0, 30.0, 35.0, 40.0, 45.0, 50.0, 55.0, 60.0]);
        assert_eq!(lin.label(0.1 + 0.2), "0.3");
    }

    #[test]
    fn structure_timeline_colours_the_runs() {
        use texmap_md_io::secondary::Structure::{Coil, Helix, Strand};
        // 40 frames of 10 residues: 0-4 helix throughout, 5-7 strand in the second half.
        let classes: Vec<Vec<_>> = (0..40)
            .map(|f| {
                (0..10)
                    .map(|r| match r {
                        0..5 => Helix,
                        5..8 if f >= 20 => Strand,
                        _ => Coil,
                    })
                    .collect()
            })
            .collect();
        let x: Vec<f64> = (0..40).map(|f| f as f64 * 2.5).collect();
        let resids: Vec<i64> = (11..21).collect();
        let (w, h) = TIMELINE_SIZE;
        let mut rgb = vec![0u8; 3 * (w * h) as usize];
        structure_timeline(&x, "time (ps)", &resids, &classes, Target::Rgb(&mut rgb)).unwrap();
        let count = |c: [u8; 3]| rgb.chunks_exact(3).filter(|p| *p == c).count();
        let (purple, yellow) = (count([166, 0, 166]), count([255, 255, 0]));
        // Helix cells: 5 residues x 40 frames; strand: 3 x 20, so 10/3 as many pixels (the
        // legend's two boxes aside).
        assert!(purple > 20_000, "{purple}");
        let ratio = purple as f64 / yellow as f64;
        assert!((ratio - 10.0 / 3.0).abs() < 0.2, "{ratio}");
        let mut svg = String::new();
        structure_timeline(&x, "time (ps)", &resids, &classes, Target::Svg(&mut svg)).unwrap();
        assert!(svg.contains("helix") && svg.contains("strand") && svg.contains("time (ps)"));
    }

    #[test]
    fn matrix_heatmap_colours_by_value_and_blocks_large_matrices() {
        // Two states: frames 0-29 and 30-59, 0.5 Å apart within a state and 2 Å across.
        let n = 60;
        let m: Vec<f64> = (0..n * n)
            .map(|k| {
                let (i, j) = (k / n, k % n);
                if i == j {
                    0.0
                } else if (i < 30) == (j < 30) {
                    0.5
                } else {
                    2.0
                }
            })
            .collect();
        let x: Vec<f64> = (0..n).map(|f| f as f64).collect();
        let (w, h) = HEATMAP_SIZE;
        let mut rgb = vec![0u8; 3 * (w * h) as usize];
        matrix_heatmap(&x, "frame", &m, "RMSD (Å)", Target::Rgb(&mut rgb)).unwrap();
        let c = |v: f64| {
            let c = texmap_md_scene::Colormap::Viridis.srgb((v / 2.0) as f32);
            c.map(|x| (x * 255.0).round() as u8)
        };
        let count = |want: [u8; 3]| rgb.chunks_exact(3).filter(|p| *p == want).count();
        // The across-state blocks are half the matrix, the within-state ones the other half
        // (their diagonals aside); the colour bar adds a few pixels of each.
        let (across, within) = (count(c(2.0)), count(c(0.5)));
        assert!(across > 50_000, "{across}");
        assert!(
            (across as f64 / within as f64 - 1.0).abs() < 0.1,
            "{across} vs {within}"
        );
        // 700 frames are drawn as 234 blocks of 3 a side (HEATMAP_CELLS at most).
        let n = 700;
        let big: Vec<f64> = (0..n * n)
            .map(|k| ((k / n) as f64 - (k % n) as f64).abs())
            .collect();
        let x: Vec<f64> = (0..n).map(|f| f as f64 * 10.0).collect();
        let mut svg = String::new();
        matrix_heatmap(&x, "time (ps)", &big, "RMSD (Å)", Target::Svg(&mut svg)).unwrap();
        let rects = svg.matches("<rect").count();
        assert!(rects < 300 * 300 + 200 && rects > 200 * 200, "{rects}");
        assert!(matrix_heatmap(&x, "t", &big[1..], "v", Target::Svg(&mut String::new())).is_err());
    }

    #[test]
    fn landscape_colours_visited_bins_and_leaves_empty_ones_white() {
        use texmap_md_io::pca::Landscape;
        // 300 frames in one bin, 30 in another, 3 in a third; the other 97 bins empty.
        let mut points = vec![(0.05, 0.05); 300];
        points.extend(vec![(0.95, 0.95); 30]);
        points.extend(vec![(0.55, 0.05); 3]);
        let l = Landscape::new(&points, 10, 1.0).unwrap();
        let (w, h) = HEATMAP_SIZE;
        let mut rgb = vec![0u8; 3 * (w * h) as usize];
        landscape(
            &l,
            "PC1 (Å)",
            "PC2 (Å)",
            "ΔG (kJ/mol)",
            Target::Rgb(&mut rgb),
        )
        .unwrap();
        let top = 100f64.ln();
        let c = |v: f64| {
            let c = texmap_md_scene::Colormap::Viridis.srgb((v / top) as f32);
            c.map(|x| (x * 255.0).round() as u8)
        };
        let count = |want: [u8; 3]| rgb.chunks_exact(3).filter(|p| *p == want).count();
        // Each visited bin is a cell of about 75 x 68 pixels; the bar adds a few rows.
        let (most, tenth, hundredth) = (count(c(0.0)), count(c(10f64.ln())), count(c(top)));
        for n in [most, tenth, hundredth] {
            assert!(n > 4000 && n < 7000, "{most} {tenth} {hundredth}");
        }
        // The plot area is mostly white: the empty bins.
        assert!(count([255, 255, 255]) > 400_000);
        let mut svg = String::new();
        landscape(&l, "x", "y", "g", Target::Svg(&mut svg)).unwrap();
        assert!(svg.matches("<rect").count() < 3 + 100 + 20);
    }

    #[test]
    fn ramachandran_draws_dots_where_the_angles_are_then_their_density() {
        // A helix's residues (φ −60°, ψ −45°, within ±5°) and a strand's (−120°, 130°).
        let mut r = Ramachandran::default();
        for k in 0..40 {
            let d = (k % 5) as f64 * 2.0 - 4.0;
            r.add(-60.0 + d, -45.0 - d);
            r.add(-120.0 - d, 130.0 + d);
        }
        r.add(f64::NAN, 0.0);
        assert_eq!(r.len(), 80);
        let (w, h) = HEATMAP_SIZE;
        let mut rgb = vec![255u8; 3 * (w * h) as usize];
        r.draw(Target::Rgb(&mut rgb)).unwrap();
        // The plot area: 16 px margin, 60 px of y labels, 44 px of x labels.
        let (x0, x1, y0, y1) = (76.0, (w - 16) as f64, 16.0, (h - 60) as f64);
        let pixel = |phi: f64, psi: f64| {
            let x = x0 + (phi + 180.0) / 360.0 * (x1 - x0);
            let y = y0 + (180.0 - psi) / 360.0 * (y1 - y0);
            (x.round() as u32, y.round() as u32)
        };
        let ink = |x: u32, y: u32| {
            let i = 3 * (y * w + x) as usize;
            rgb[i..i + 3] == [0x1f, 0x3a, 0x93]
        };
        let (hx, hy) = pixel(-60.0, -45.0);
        let (sx, sy) = pixel(-120.0, 130.0);
        assert!(
            ink(hx, hy) && ink(sx, sy),
            "dots at the helix and the strand"
        );
        // Every dot lies within 14° of one of the two (5° of spread, the dot's radius).
        let near = |x: u32, y: u32, (cx, cy): (u32, u32)| {
            let per_degree = (x1 - x0) / 360.0;
            (x as f64 - cx as f64).hypot(y as f64 - cy as f64) < 14.0 * per_degree
        };
        let mut inked = 0;
        for y in 0..h {
            for x in 0..w {
                if ink(x, y) {
                    inked += 1;
                    assert!(near(x, y, (hx, hy)) || near(x, y, (sx, sy)), "({x}, {y})");
                }
            }
        }
        assert!(inked > 100);
        // Past RAMACHANDRAN_DOTS pairs: the density, one rectangle per visited 2° bin.
        let mut many = Ramachandran::default();
        for k in 0..RAMACHANDRAN_DOTS + 1 {
            let d = (k % 7) as f64;
            many.add(-60.0 + d, -45.0 + d);
        }
        let mut svg = String::new();
        many.draw(Target::Svg(&mut svg)).unwrap();
        let rects = svg.matches("<rect").count();
        assert!(rects > 4 && rects < 4 + 10 + 110, "{rects}");
    }

    #[test]
    fn lines_run_through_their_points_and_break_at_gaps() {
        // y = x from 0 to 10, a gap at x = 5; a second series y = 10 − x.
        let up: Vec<(f64, f64)> = (0..=10)
            .map(|x| (x as f64, if x == 5 { f64::NAN } else { x as f64 }))
            .collect();
        let down: Vec<(f64, f64)> = (0..=10).map(|x| (x as f64, 10.0 - x as f64)).collect();
        let series = vec![("up".to_string(), up), ("down".to_string(), down)];
        let mut svg = String::new();
        lines(["", "x", "y"], &series, (640, 480), Target::Svg(&mut svg)).unwrap();
        // Two polylines for "up" (the gap), one for "down", and the legend's two lines.
        let polylines = svg.matches("<polyline").count();
        assert!(polylines >= 3, "{polylines}");
        assert!(svg.contains("down"), "a legend");
        let (w, h) = (640u32, 480u32);
        let mut rgb = vec![0u8; 3 * (w * h) as usize];
        lines(["t", "x", "y"], &series[..1], (w, h), Target::Rgb(&mut rgb)).unwrap();
        let blue = |x: u32, y: u32| {
            let i = 3 * (y * w + x) as usize;
            rgb[i..i + 3] == [0x1f, 0x77, 0xb4]
        };
        // The line rises left to right: the blue pixels' mean height falls (image y grows
        // down) from the left quarter to the right quarter.
        let mean_y = |x0: u32, x1: u32| {
            let ys: Vec<u32> = (x0..x1)
                .flat_map(|x| (0..h).filter(move |&y| blue(x, y)))
                .collect();
            ys.iter().sum::<u32>() as f64 / ys.len().max(1) as f64
        };
        assert!(mean_y(100, 240) > mean_y(440, 600) + 100.0);
    }

    fn rec(method: &str, scene: &str, ms: f64, psnr: f64) -> Record {
        Record {
            scene: scene.into(),
            method: method.into(),
            reference: "reftrace-1spp".into(),
            width: 500,
            height: 500,
            ms_per_frame: ms,
            psnr_db: psnr,
            ssim: 0.9,
            depth_err_mean: 0.0,
            depth_err_max: 0.0,
            silhouette_px: 0.1,
            silhouette_mismatched: 3,
        }
    }

    fn distinct_colors(rgb: &[u8]) -> usize {
        let mut set = std::collections::HashSet::new();
        for p in rgb.chunks_exact(3) {
            set.insert([p[0], p[1], p[2]]);
        }
        set.len()
    }

    fn records() -> Vec<Record> {
        vec![
            rec("polygon", "s1", 12.0, 38.0),
            rec("lut", "s1", 1.5, 31.0),
            rec("template", "s1", 1.1, 24.0),
            rec("raycast", "s1", 2.0, f64::INFINITY),
            rec("raycast", "molecule", 0.9, 52.0),
        ]
    }

    #[test]
    fn speed_accuracy_chart_renders_text_points_and_colours() {
        let mut buf = vec![0u8; 3 * 960 * 640];
        speed_accuracy(&records(), Target::Rgb(&mut buf)).unwrap();
        // White background, four method colours, anti-aliased text: many distinct colours.
        let n = distinct_colors(&buf);
        assert!(n > 50, "only {n} distinct colours");
        // The raycast colour appears (its points were drawn).
        assert!(buf.chunks_exact(3).any(|p| p == [214, 39, 40]));
        let mut svg = String::new();
        speed_accuracy(&records(), Target::Svg(&mut svg)).unwrap();
        assert!(
            svg.starts_with("<svg")
                && svg.contains("template s1")
                && svg.contains("raycast molecule")
        );
        // One shape per method (circles for raycast, squares for polygon), the infinite
        // PSNR marked as capped on the point and in a note.
        assert!(svg.matches("<circle").count() >= 2);
        assert!(svg.contains("<rect") && svg.contains("raycast s1 (∞ dB)"));
        assert!(svg.contains("infinite PSNR"));
    }

    #[test]
    fn png_files_decode_to_the_chart_size() {
        let dir = tempfile::tempdir().unwrap();
        let m = |s: f64| Metrics {
            psnr_db: 40.0 + s,
            ssim: 0.99,
            depth_err_mean: 1e-6 * s,
            depth_err_max: 1e-5 * s,
            depth_range: 1.0,
            silhouette_px: 0.1 * s,
            silhouette_mismatched: s as usize,
            reference_coverage: 1000,
        };
        let series: Vec<SweepSeries> = [Method::Lut, Method::Raycast]
            .into_iter()
            .map(|method| SweepSeries {
                kind: SweepKind::ScreenRadius,
                method,
                points: [0.3, 1.0, 10.0, 100.0]
                    .iter()
                    .enumerate()
                    .map(|(i, &x)| SweepPoint {
                        x,
                        metrics: m(i as f64),
                    })
                    .collect(),
            })
            .collect();
        let paths = write_charts(dir.path(), &records(), &series).unwrap();
        // speed_accuracy + 3 metrics of one sweep, SVG and PNG each.
        assert_eq!(paths.len(), 2 * (1 + 3));
        for p in paths
            .iter()
            .filter(|p| p.extension().is_some_and(|e| e == "png"))
        {
            let img = image::open(p).unwrap().to_rgb8();
            assert_eq!(img.dimensions(), CHART_SIZE, "{}", p.display());
            let n = distinct_colors(img.as_raw());
            assert!(n > 50, "{}: only {n} distinct colours", p.display());
        }
    }

    #[test]
    fn wrong_buffer_size_is_an_error() {
        let mut buf = vec![0u8; 10];
        assert!(matches!(
            speed_accuracy(&records(), Target::Rgb(&mut buf)),
            Err(StudyError::BadOption { .. })
        ));
    }

    #[test]
    fn scatter_draws_every_series_in_its_colour() {
        let series = vec![
            (
                "trilinear".to_string(),
                vec![(-10.0, 30.0), (-10.0, 32.0), (-50.0, 35.0)],
            ),
            (
                "span3".to_string(),
                vec![(-10.0, 28.0), (-50.0, f64::INFINITY)],
            ),
        ];
        let mut svg = String::new();
        scatter("t", "pitch", "PSNR", &series, Target::Svg(&mut svg)).unwrap();
        assert!(svg.contains("trilinear") && svg.contains("span3"));
        let (w, h) = CHART_SIZE;
        let mut rgb = vec![0u8; 3 * (w * h) as usize];
        scatter("t", "pitch", "PSNR", &series, Target::Rgb(&mut rgb)).unwrap();
        let count = |c: RGBColor| rgb.chunks(3).filter(|p| *p == [c.0, c.1, c.2]).count();
        // Markers, mean lines and legend swatches of both series are drawn.
        assert!(
            count(SCATTER_COLOURS[0]) > 100,
            "{}",
            count(SCATTER_COLOURS[0])
        );
        assert!(
            count(SCATTER_COLOURS[1]) > 50,
            "{}",
            count(SCATTER_COLOURS[1])
        );
        assert_eq!(count(SCATTER_COLOURS[2]), 0);
    }
}
