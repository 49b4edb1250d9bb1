//! The study's currency, for every family of methods: one [`Record`] per method, scene and
//! reference (the row of results.json / results.csv), the [`Metrics`] of a frame against its
//! reference, error images, timing, and the results files.
//!
//! Nothing here knows what a method draws: the sphere harness ([`crate::harness`]), the
//! environment-mapping study and the terrain samplers' study all produce [`texmap_core::frame::Frame`]s and
//! hand them to [`compare`] and [`record`].

use std::path::Path;
use std::time::Instant;

use glam::Vec3;
use serde::{Deserialize, Serialize};
use texmap_core::color::srgb8_to_linear_rgb;
use texmap_core::frame::Frame;
use texmap_core::metrics;

use crate::error::{StudyError, write_file};

/// One method on one scene against one reference: the machine-readable result row
/// (results.json / results.csv).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Record {
    pub scene: String,
    /// The method's name (`raycast`, `template`, … for the sphere methods; `trilinear`, `span3`,
    /// … for the samplers), or the reference's own (its error fields are then against itself,
    /// i.e. zero / infinite PSNR).
    pub method: String,
    /// What the errors are measured against, e.g. `reftrace-1spp` or `reftrace-4x4`.
    pub reference: String,
    pub width: u32,
    pub height: u32,
    /// Median wall-clock milliseconds per frame (tables reused across frames).
    pub ms_per_frame: f64,
    /// PSNR of the RGB colour in dB; infinite (JSON `null`) for identical images.
    #[serde(with = "inf_as_null")]
    pub psnr_db: f64,
    pub ssim: f64,
    /// Mean and maximum absolute depth difference (scene units) over pixels both frames cover.
    pub depth_err_mean: f64,
    pub depth_err_max: f64,
    /// Mean silhouette displacement in pixels (mismatched pixels over reference outline length).
    pub silhouette_px: f64,
    /// Pixels covered in exactly one of the frame and the reference.
    pub silhouette_mismatched: u64,
}

/// Serialise an infinite PSNR as JSON `null` and read it back as infinity (JSON has no infinity).
mod inf_as_null {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if v.is_finite() {
            s.serialize_f64(*v)
        } else {
            s.serialize_none()
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
    }
}

/// Every accuracy figure of one frame against a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    pub psnr_db: f64,
    pub ssim: f64,
    pub depth_err_mean: f64,
    pub depth_err_max: f64,
    /// Range of the reference's finite depths (max − min; 0 if it covers at most one depth).
    pub depth_range: f64,
    /// Mean silhouette displacement in pixels ([`metrics::silhouette_error`]).
    pub silhouette_px: f64,
    pub silhouette_mismatched: usize,
    /// Pixels the reference covers.
    pub reference_coverage: usize,
}

impl Metrics {
    /// `depth_err_max / depth_range` (0 when the range is 0 and the error is 0, infinite when only
    /// the range is 0).
    pub fn depth_err_rel(&self) -> f64 {
        if self.depth_range > 0.0 {
            self.depth_err_max / self.depth_range
        } else if self.depth_err_max == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    }
}

/// Compare a frame with the reference.
pub fn compare(frame: &Frame, reference: &Frame) -> Result<Metrics, StudyError> {
    let de = metrics::depth_error(frame, reference)?;
    let sil = metrics::silhouette_error(frame, reference)?;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &d in reference.depth.iter().filter(|d| d.is_finite()) {
        lo = lo.min(d as f64);
        hi = hi.max(d as f64);
    }
    Ok(Metrics {
        psnr_db: metrics::psnr(frame, reference)?,
        ssim: metrics::ssim(frame, reference)?,
        depth_err_mean: de.mean_abs,
        depth_err_max: de.max_abs,
        depth_range: if hi > lo { hi - lo } else { 0.0 },
        silhouette_px: sil.mean_displacement_px,
        silhouette_mismatched: sil.mismatched_pixels,
        reference_coverage: reference.coverage_count(),
    })
}

pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Median wall-clock milliseconds of `runs` calls of `f` after `warmup` calls.
pub fn time_ms<T>(warmup: usize, runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut last = None;
    for _ in 0..warmup {
        last = Some(f());
    }
    let mut times = Vec::with_capacity(runs);
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        let out = f();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        last = Some(out);
    }
    (median(times), last.expect("at least one run"))
}

/// The record of `method`'s `frame` on `scene`, measured against `reference`.
pub fn record(
    scene: &str,
    method: &str,
    reference: &str,
    frame: &Frame,
    ms: f64,
    m: &Metrics,
) -> Record {
    Record {
        scene: scene.to_string(),
        method: method.to_string(),
        reference: reference.to_string(),
        width: frame.width(),
        height: frame.height(),
        ms_per_frame: ms,
        psnr_db: m.psnr_db,
        ssim: m.ssim,
        depth_err_mean: m.depth_err_mean,
        depth_err_max: m.depth_err_max,
        silhouette_px: m.silhouette_px,
        silhouette_mismatched: m.silhouette_mismatched as u64,
    }
}

/// An error image: per-pixel absolute colour difference times `gain` (clamped to 255) where both
/// frames agree on coverage; magenta where only the frame covers the pixel, green where only the
/// reference does. Frames of different sizes give [`StudyError::Metric`].
pub fn error_image(frame: &Frame, reference: &Frame, gain: f32) -> Result<Frame, StudyError> {
    if frame.width() != reference.width() || frame.height() != reference.height() {
        return Err(StudyError::Metric(metrics::MetricError::SizeMismatch {
            a: (frame.width(), frame.height()),
            b: (reference.width(), reference.height()),
        }));
    }
    let mut out = Frame::new(frame.width(), frame.height(), [0, 0, 0, 255]);
    for i in 0..frame.len() {
        let (a, r) = (frame.covered(i), reference.covered(i));
        out.color[i] = match (a, r) {
            (true, false) => [255, 0, 255, 255],
            (false, true) => [0, 255, 0, 255],
            _ => {
                let (p, q) = (frame.color[i], reference.color[i]);
                let d =
                    |c: usize| ((p[c] as f32 - q[c] as f32).abs() * gain).clamp(0.0, 255.0) as u8;
                [d(0), d(1), d(2), 255]
            }
        };
        out.depth[i] = reference.depth[i];
    }
    Ok(out)
}

/// The records as CSV: a header line, then one line per record (`inf` for an infinite PSNR).
pub fn records_to_csv(records: &[Record]) -> String {
    let mut s = String::from(
        "scene,method,reference,width,height,ms_per_frame,psnr_db,ssim,depth_err_mean,depth_err_max,silhouette_px,silhouette_mismatched\n",
    );
    for r in records {
        s.push_str(&format!(
            "{},{},{},{},{},{:.4},{:.3},{:.5},{:.6e},{:.6e},{:.4},{}\n",
            r.scene,
            r.method,
            r.reference,
            r.width,
            r.height,
            r.ms_per_frame,
            r.psnr_db,
            r.ssim,
            r.depth_err_mean,
            r.depth_err_max,
            r.silhouette_px,
            r.silhouette_mismatched
        ));
    }
    s
}

/// The records as a pretty-printed JSON array.
pub fn records_to_json(records: &[Record]) -> Result<String, StudyError> {
    serde_json::to_string_pretty(records).map_err(StudyError::Json)
}

/// Write `results.json` and `results.csv` into `dir` (which must exist).
pub fn write_results(dir: &Path, records: &[Record]) -> Result<(), StudyError> {
    write_file(
        dir.join("results.json"),
        records_to_json(records)?.as_bytes(),
    )?;
    write_file(dir.join("results.csv"), records_to_csv(records).as_bytes())
}

/// Mean linear-light colour of the covered pixels (a quick sanity figure for reports).
pub fn mean_covered_color(frame: &Frame) -> Vec3 {
    let mut sum = Vec3::ZERO;
    let mut n = 0u32;
    for i in 0..frame.len() {
        if frame.covered(i) {
            sum += srgb8_to_linear_rgb(frame.color[i]);
            n += 1;
        }
    }
    if n == 0 { Vec3::ZERO } else { sum / n as f32 }
}
