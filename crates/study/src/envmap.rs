//! The environment-mapping study: every method of `texmap-envmap` against `texmap-reftrace` on
//! the same scene.
//!
//! - **methods**: the built-in tunnel (a mirror sphere among orbiting objects in a striped
//!   tunnel, after Seed 003's demo): PSNR over the target's pixels against the full reference,
//!   and against the reference *without* objects (what a static map of the environment can at
//!   best reach); time per frame with the map update apart.
//! - **angle**: the same frames, the error binned by the angle of incidence on the sphere
//!   (0° faces the viewer, 90° is the silhouette, where the reflected directions approach the
//!   sphere map's singular direction and its sampling collapses).
//! - **distance**: one object of constant angular size at `k` target radii (a smooth
//!   environment, so the error left is the parallax of the map's single centre): Seed 003's
//!   "exact only at the centre".
//! - **resolution**: the tunnel at map sides 32–512.
//! - **refraction**: a glass sphere (ior 1.5 and 1.05) in the tunnel.
//!
//! The reference traces the target analytically (mirror, or refraction without Fresnel: what the
//! maps compute), objects flat-shaded with the same materials and lighting, escaped rays and
//! primary misses looking up the same [`Environment`], `n × n` samples per pixel. Target pixels
//! are those where the traced depth with the target alone equals the depth with everything.
//! PSNR is over sRGB8 RGB of those pixels.
//!
//! Timings come from this harness (wall clock, median of a few frames, shared machine): the
//! criterion bench `benches/envmap.rs` is the figure to quote.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use glam::{Quat, Vec3};
use plotters::prelude::*;
use plotters::style::FontStyle;
use serde::Serialize;
use texmap_core::camera::Camera;
use texmap_core::frame::Frame;
use texmap_core::shade::Material;
use texmap_envmap::scene::{
    TunnelParams, smooth_environment, tunnel_camera, tunnel_lighting, tunnel_scene,
};
use texmap_envmap::shapes;
use texmap_envmap::{
    EnvMapError, EnvScene, Method, Object, Options, Renderer, Surface, Target, TargetShape,
};
use texmap_reftrace::{
    MeshShading, Optics, RenderError, RenderOptions, SceneBuilder, SceneError, SurfaceMaterial,
};

/// Why the envmap study failed.
#[derive(Debug)]
#[non_exhaustive]
pub enum EnvStudyError {
    EnvMap(EnvMapError),
    Reference(RenderError),
    ReferenceScene(SceneError),
    BadOption {
        what: &'static str,
    },
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    Json(serde_json::Error),
    Chart {
        chart: String,
        message: String,
    },
}

impl std::fmt::Display for EnvStudyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EnvStudyError::EnvMap(e) => write!(f, "envmap: {e}"),
            EnvStudyError::Reference(e) => write!(f, "reference ray tracer: {e}"),
            EnvStudyError::ReferenceScene(e) => write!(f, "reference scene: {e}"),
            EnvStudyError::BadOption { what } => write!(f, "bad study option: {what}"),
            EnvStudyError::Io { path, source } => write!(f, "{}: {source}", path.display()),
            EnvStudyError::Json(e) => write!(f, "results JSON: {e}"),
            EnvStudyError::Chart { chart, message } => write!(f, "chart {chart}: {message}"),
        }
    }
}

impl std::error::Error for EnvStudyError {}

impl From<EnvMapError> for EnvStudyError {
    fn from(e: EnvMapError) -> Self {
        EnvStudyError::EnvMap(e)
    }
}
impl From<RenderError> for EnvStudyError {
    fn from(e: RenderError) -> Self {
        EnvStudyError::Reference(e)
    }
}
impl From<SceneError> for EnvStudyError {
    fn from(e: SceneError) -> Self {
        EnvStudyError::ReferenceScene(e)
    }
}

/// One measurement: a method at one point of one study.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnvRecord {
    /// `methods`, `angle`, `distance`, `resolution` or `refraction`.
    pub study: String,
    pub method: String,
    /// The swept value: incidence angle (degrees, bin centre), distance (target radii), map
    /// side (texels), ior; 0 for `methods`.
    pub x: f64,
    /// PSNR (dB) over the target's pixels (or the bin's) against the full reference.
    pub psnr_db: f64,
    /// `methods` only: PSNR against the reference without objects (NaN elsewhere).
    pub psnr_env_only_db: f64,
    /// Mean absolute error, sRGB8 codes averaged over RGB.
    pub mean_abs_err: f64,
    /// Median wall time of the map update and of drawing (ms; 0 outside `methods`).
    pub update_ms: f64,
    pub draw_ms: f64,
    /// Pixels measured.
    pub pixels: usize,
}

/// Study size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvStudyOptions {
    pub width: u32,
    pub height: u32,
    /// Reference samples per pixel axis.
    pub samples: u32,
    /// Frames timed per method (median).
    pub timed_frames: u32,
    /// Map side of the `methods`, `angle`, `distance` and `refraction` studies.
    pub map_size: u32,
}

impl Default for EnvStudyOptions {
    fn default() -> Self {
        EnvStudyOptions {
            width: 320,
            height: 240,
            samples: 3,
            timed_frames: 5,
            map_size: 256,
        }
    }
}

/// The reference frame (see the module docs); `with_objects = false` traces the target alone.
pub fn reference(
    scene: &EnvScene,
    cam: &Camera,
    with_objects: bool,
    samples: u32,
) -> Result<Frame, EnvStudyError> {
    let mut b = SceneBuilder::new();
    let mut materials = Vec::new();
    if with_objects {
        for o in scene.objects() {
            b.add_mesh(
                &o.mesh.positions,
                o.mesh.indices(),
                None,
                materials.len() as u32,
            )?;
            materials.push(SurfaceMaterial::opaque(o.material));
        }
    }
    add_target(&mut b, scene, materials.len() as u32)?;
    materials.push(match scene.target().surface {
        Surface::Mirror => SurfaceMaterial::mirror(Material::matte(Vec3::ZERO), 1.0),
        Surface::Refractive { ior } => SurfaceMaterial {
            shading: Material::matte(Vec3::ZERO),
            optics: Optics::Refractive {
                ior,
                fresnel: false,
            },
            texture: None,
        },
    });
    let traced = b.build();
    let mut opts = RenderOptions::new(*scene.lighting(), &materials);
    opts.environment_on_primary_miss = true;
    opts.max_depth = 4;
    opts.samples_per_axis = samples;
    let env = scene.environment();
    Ok(traced.render_with_environment(cam, &opts, &|d: Vec3| env.radiance(d))?)
}

fn add_target(b: &mut SceneBuilder, scene: &EnvScene, id: u32) -> Result<(), EnvStudyError> {
    match &scene.target().shape {
        TargetShape::Sphere { centre, radius } => {
            b.add_sphere(*centre, *radius, id);
        }
        TargetShape::Mesh(m) => {
            b.add_mesh_shaded(
                &m.positions,
                m.indices(),
                None,
                Some(scene.target_normals()),
                MeshShading::VertexNormals,
                id,
            )?;
        }
    }
    Ok(())
}

/// Pixels where the reference sees the target.
pub fn target_mask(scene: &EnvScene, cam: &Camera) -> Result<Vec<bool>, EnvStudyError> {
    let mut all = SceneBuilder::new();
    for o in scene.objects() {
        all.add_mesh(&o.mesh.positions, o.mesh.indices(), None, 0)?;
    }
    add_target(&mut all, scene, 0)?;
    let mut only = SceneBuilder::new();
    add_target(&mut only, scene, 0)?;
    let da = all.build().depth_image(cam);
    let dt = only.build().depth_image(cam);
    Ok(da
        .iter()
        .zip(&dt)
        .map(|(a, t)| t.is_finite() && (a - t).abs() <= 1e-5 * t.abs())
        .collect())
}

/// Squared error sum and channel count over the masked pixels.
fn sq_err(a: &Frame, b: &Frame, mask: impl Fn(usize) -> bool) -> (f64, f64, usize) {
    let (mut se, mut ae, mut n) = (0.0f64, 0.0f64, 0usize);
    for (i, (ca, cb)) in a.color.iter().zip(&b.color).enumerate() {
        if mask(i) {
            for k in 0..3 {
                let d = ca[k] as f64 - cb[k] as f64;
                se += d * d;
                ae += d.abs();
            }
            n += 1;
        }
    }
    (se, ae, n)
}

fn psnr_of(se: f64, n: usize) -> f64 {
    if n == 0 {
        return f64::NAN;
    }
    let mse = se / (3 * n) as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    }
}

/// PSNR (dB) and mean absolute error (codes) over the masked pixels.
pub fn masked_error(a: &Frame, b: &Frame, mask: &[bool]) -> (f64, f64, usize) {
    let (se, ae, n) = sq_err(a, b, |i| mask[i]);
    (psnr_of(se, n), ae / (3 * n.max(1)) as f64, n)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// The distance study's scene: a unit mirror sphere and one box of half-size `0.18 k` at
/// distance `k` (constant angular size).
pub fn distance_scene(k: f32) -> Result<EnvScene, EnvStudyError> {
    let c = Vec3::new(0.45, 0.35, 0.82).normalize() * k;
    let h = 0.18 * k;
    let obj = Object {
        mesh: shapes::cuboid(
            c - Vec3::splat(h),
            c + Vec3::splat(h),
            Quat::from_rotation_y(0.5),
        ),
        material: Material::matte(Vec3::new(0.9, 0.3, 0.1)),
    };
    Ok(EnvScene::new(
        vec![obj],
        Target {
            shape: TargetShape::Sphere {
                centre: Vec3::ZERO,
                radius: 1.0,
            },
            surface: Surface::Mirror,
        },
        smooth_environment(),
        tunnel_lighting(),
    )?)
}

/// Incidence angle (degrees) on the unit sphere at the origin through each pixel (NaN: miss).
fn incidence(cam: &Camera) -> Vec<f32> {
    let (w, h) = (cam.width(), cam.height());
    let mut out = Vec::with_capacity((w * h) as usize);
    for j in 0..h {
        for i in 0..w {
            let r = cam.ray(i as f32 + 0.5, j as f32 + 0.5);
            let b = r.origin.dot(r.dir);
            let disc = b * b - (r.origin.length_squared() - 1.0);
            if disc < 0.0 {
                out.push(f32::NAN);
                continue;
            }
            let t = -b - disc.sqrt();
            let n = (r.origin + r.dir * t).normalize();
            out.push((-r.dir).dot(n).clamp(-1.0, 1.0).acos().to_degrees());
        }
    }
    out
}

/// Run the whole study.
pub fn run(opts: &EnvStudyOptions) -> Result<Vec<EnvRecord>, EnvStudyError> {
    if !(16..=4096).contains(&opts.width) || !(16..=4096).contains(&opts.height) {
        return Err(EnvStudyError::BadOption {
            what: "image sides must be in 16..=4096",
        });
    }
    if !(1..=8).contains(&opts.samples) || !(1..=100).contains(&opts.timed_frames) {
        return Err(EnvStudyError::BadOption {
            what: "samples must be in 1..=8 and timed_frames in 1..=100",
        });
    }
    let mut out = Vec::new();
    let rec = |study: &str, method: Method, x: f64| EnvRecord {
        study: study.into(),
        method: method.name().into(),
        x,
        psnr_db: f64::NAN,
        psnr_env_only_db: f64::NAN,
        mean_abs_err: f64::NAN,
        update_ms: 0.0,
        draw_ms: 0.0,
        pixels: 0,
    };
    let scene = tunnel_scene(TunnelParams::default())?;
    let cam = tunnel_camera(opts.width, opts.height)?;
    let full = reference(&scene, &cam, true, opts.samples)?;
    let env_only = reference(&scene, &cam, false, opts.samples)?;
    let mask = target_mask(&scene, &cam)?;
    let angles = incidence(&cam);
    for method in Method::ALL {
        let mut o = Options::new(method);
        o.map_size = opts.map_size;
        let mut r = Renderer::new();
        let (mut up, mut dr) = (Vec::new(), Vec::new());
        let mut frame = None;
        for k in 0..opts.timed_frames + 1 {
            let res = r.render(&scene, &cam, &o)?;
            // The first frame builds caches (static maps): not timed unless it is the only one.
            if k > 0 || opts.timed_frames == 0 {
                up.push(res.update_ms);
                dr.push(res.draw_ms);
            }
            frame = Some(res.frame);
        }
        let frame = frame.expect("at least one frame");
        // A static map's update is made once and reused: state the cost of making it.
        let first_update = if method.is_dynamic() {
            median(up.clone())
        } else {
            Renderer::new().render(&scene, &cam, &o)?.update_ms
        };
        let (p, mae, n) = masked_error(&frame, &full, &mask);
        let (pe, _, _) = masked_error(&frame, &env_only, &mask);
        out.push(EnvRecord {
            psnr_db: p,
            psnr_env_only_db: pe,
            mean_abs_err: mae,
            update_ms: first_update,
            draw_ms: median(dr),
            pixels: n,
            ..rec("methods", method, 0.0)
        });
        // Error against the incidence angle, 10° bins (static maps against the environment
        // alone: their error is their sampling, not the missing objects).
        let against = if method.is_dynamic() {
            &full
        } else {
            &env_only
        };
        for bin in 0..9 {
            let lo = bin as f32 * 10.0;
            let in_bin = |i: usize| mask[i] && angles[i] >= lo && angles[i] < lo + 10.0;
            let (se, ae, n) = sq_err(&frame, against, in_bin);
            if n > 0 {
                out.push(EnvRecord {
                    psnr_db: psnr_of(se, n),
                    mean_abs_err: ae / (3 * n) as f64,
                    pixels: n,
                    ..rec("angle", method, lo as f64 + 5.0)
                });
            }
        }
    }
    // Parallax against distance.
    let dcam = Camera::perspective_look_at(
        Vec3::new(0.0, 0.0, 4.0),
        Vec3::ZERO,
        Vec3::Y,
        40.0,
        opts.height,
        opts.height,
    )
    .map_err(EnvMapError::from)?;
    for k in [1.5f32, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 20.0, 30.0] {
        let s = distance_scene(k)?;
        let reference = reference(&s, &dcam, true, opts.samples)?;
        let mask = target_mask(&s, &dcam)?;
        for method in [
            Method::SphereDynamic,
            Method::Cube,
            Method::CubeBox,
            Method::Paraboloid,
        ] {
            let mut o = Options::new(method);
            o.map_size = opts.map_size;
            let f = Renderer::new().render(&s, &dcam, &o)?.frame;
            let (p, mae, n) = masked_error(&f, &reference, &mask);
            out.push(EnvRecord {
                psnr_db: p,
                mean_abs_err: mae,
                pixels: n,
                ..rec("distance", method, k as f64)
            });
        }
    }
    // Map resolution.
    for size in [32u32, 64, 128, 256, 512] {
        for method in Method::ALL {
            let mut o = Options::new(method);
            o.map_size = size;
            let f = Renderer::new().render(&scene, &cam, &o)?.frame;
            let against = if method.is_dynamic() {
                &full
            } else {
                &env_only
            };
            let (p, mae, n) = masked_error(&f, against, &mask);
            out.push(EnvRecord {
                psnr_db: p,
                mean_abs_err: mae,
                pixels: n,
                ..rec("resolution", method, size as f64)
            });
        }
    }
    // Refraction.
    for ior in [1.05f32, 1.5] {
        let s = tunnel_scene(TunnelParams {
            surface: Surface::Refractive { ior },
            ..Default::default()
        })?;
        let reference = reference(&s, &cam, true, opts.samples)?;
        let mask = target_mask(&s, &cam)?;
        for method in Method::ALL {
            let mut o = Options::new(method);
            o.map_size = opts.map_size;
            let f = Renderer::new().render(&s, &cam, &o)?.frame;
            let (p, mae, n) = masked_error(&f, &reference, &mask);
            out.push(EnvRecord {
                psnr_db: p,
                mean_abs_err: mae,
                pixels: n,
                ..rec("refraction", method, (ior as f64 * 1000.0).round() / 1000.0)
            });
        }
    }
    Ok(out)
}

/// CSV of the records (one header line).
pub fn to_csv(records: &[EnvRecord]) -> String {
    let mut s = String::from(
        "study,method,x,psnr_db,psnr_env_only_db,mean_abs_err,update_ms,draw_ms,pixels\n",
    );
    for r in records {
        s.push_str(&format!(
            "{},{},{},{:.3},{:.3},{:.3},{:.3},{:.3},{}\n",
            r.study,
            r.method,
            r.x,
            r.psnr_db,
            r.psnr_env_only_db,
            r.mean_abs_err,
            r.update_ms,
            r.draw_ms,
            r.pixels
        ));
    }
    s
}

/// Write `bytes` to `path` through a temporary name in the same directory, then rename: no
/// partial file is ever left under the final name.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), EnvStudyError> {
    let io = |source| EnvStudyError::Io {
        path: path.to_path_buf(),
        source,
    };
    let tmp = path.with_extension(format!(
        "{}.tmp",
        path.extension().and_then(|e| e.to_str()).unwrap_or("")
    ));
    std::fs::write(&tmp, bytes).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(io)
}

/// Chart size in pixels.
const CHART_SIZE: (u32, u32) = (900, 560);

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

fn ensure_font() -> Result<(), EnvStudyError> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_ok()
    });
    ok.then_some(()).ok_or(EnvStudyError::Chart {
        chart: "font".into(),
        message: "the embedded font could not be parsed".into(),
    })
}

/// One line per method of the records of `study`, y = PSNR (or mean abs error), on `root`.
/// Returns `false` (nothing drawn) when the study has no finite point.
fn line_chart<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    records: &[EnvRecord],
    study: &str,
    x_label: &str,
    log_x: bool,
    y_err: bool,
) -> Result<bool, EnvStudyError> {
    ensure_font()?;
    let err = |e: String| EnvStudyError::Chart {
        chart: study.into(),
        message: e,
    };
    let mine: Vec<&EnvRecord> = records.iter().filter(|r| r.study == study).collect();
    let y_of = |r: &EnvRecord| {
        if y_err {
            r.mean_abs_err
        } else {
            r.psnr_db.min(100.0)
        }
    };
    let x_of = |r: &EnvRecord| if log_x { r.x.log2() } else { r.x };
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for r in &mine {
        let (x, y) = (x_of(r), y_of(r));
        if x.is_finite() && y.is_finite() {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if x0 > x1 {
        return Ok(false);
    }
    let pad = ((y1 - y0) * 0.08).max(0.5);
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let title = match study {
        "angle" => "Error against angle of incidence (tunnel scene)",
        "distance" => "PSNR against object distance (target radii)",
        "resolution" => "PSNR against map resolution (tunnel scene)",
        "refraction" => "Refraction: PSNR against index of refraction",
        _ => study,
    };
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1 + 1e-9, (y0 - pad)..(y1 + pad))
        .map_err(|e| err(e.to_string()))?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(if y_err {
            "mean |error| (sRGB codes)"
        } else {
            "PSNR over target pixels (dB)"
        })
        .x_label_formatter(&|v| {
            if log_x {
                format!("{:.0}", 2f64.powf(*v))
            } else {
                format!("{v:.1}")
            }
        })
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| err(e.to_string()))?;
    for (mi, method) in Method::ALL.iter().enumerate() {
        let pts: Vec<(f64, f64)> = mine
            .iter()
            .filter(|r| r.method == method.name())
            .map(|r| (x_of(r), y_of(r)))
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect();
        if pts.is_empty() {
            continue;
        }
        let colour = Palette99::pick(mi).to_rgba();
        chart
            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
            .map_err(|e| err(e.to_string()))?
            .label(method.name())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(2)));
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled())))
            .map_err(|e| err(e.to_string()))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(|e| err(e.to_string()))?;
    root.present().map_err(|e| err(e.to_string()))?;
    Ok(true)
}

/// Write `envmap.csv`, `envmap.json` and the charts (SVG and PNG) into `dir` (created if missing); returns
/// the paths written.
pub fn write(dir: &Path, records: &[EnvRecord]) -> Result<Vec<PathBuf>, EnvStudyError> {
    std::fs::create_dir_all(dir).map_err(|source| EnvStudyError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut written = Vec::new();
    let csv = dir.join("envmap.csv");
    write_atomic(&csv, to_csv(records).as_bytes())?;
    written.push(csv);
    let json = dir.join("envmap.json");
    let text = serde_json::to_string_pretty(records).map_err(EnvStudyError::Json)?;
    write_atomic(&json, text.as_bytes())?;
    written.push(json);
    for (study, x_label, log_x, y_err) in [
        (
            "angle",
            "angle of incidence (degrees, 10° bins)",
            false,
            true,
        ),
        (
            "distance",
            "object distance (target radii, log2 axis)",
            true,
            false,
        ),
        ("resolution", "map side (texels, log2 axis)", true, false),
        ("refraction", "index of refraction", false, false),
    ] {
        let mut svg = String::new();
        let drawn = line_chart(
            SVGBackend::with_string(&mut svg, CHART_SIZE).into_drawing_area(),
            records,
            study,
            x_label,
            log_x,
            y_err,
        )?;
        if !drawn {
            continue;
        }
        let path = dir.join(format!("envmap_{study}.svg"));
        write_atomic(&path, svg.as_bytes())?;
        written.push(path);
        // PNG: drawn to a temporary name (plotters picks the encoder by extension), renamed.
        let png = dir.join(format!("envmap_{study}.png"));
        let tmp = dir.join(format!("envmap_{study}.partial.png"));
        line_chart(
            BitMapBackend::new(&tmp, CHART_SIZE).into_drawing_area(),
            records,
            study,
            x_label,
            log_x,
            y_err,
        )?;
        std::fs::rename(&tmp, &png).map_err(|source| EnvStudyError::Io {
            path: png.clone(),
            source,
        })?;
        written.push(png);
    }
    Ok(written)
}

/// The images of the demo's environment-mapping section: the tunnel at time `t` drawn by every
/// method (maps of `map_size`) and by the reference (`samples`² per pixel), named as the
/// methods are.
pub fn demo_frames(
    width: u32,
    height: u32,
    map_size: u32,
    samples: u32,
) -> Result<Vec<(String, Frame)>, EnvStudyError> {
    let scene = tunnel_scene(TunnelParams {
        time: 0.0,
        detail: 1,
        surface: Surface::Mirror,
    })?;
    let cam = tunnel_camera(width, height)?;
    let mut out = vec![(
        "reference".to_string(),
        reference(&scene, &cam, true, samples)?,
    )];
    let mut renderer = Renderer::new();
    for m in Method::ALL {
        let mut o = Options::new(m);
        o.map_size = map_size;
        out.push((
            m.name().to_string(),
            renderer.render(&scene, &cam, &o)?.frame,
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_study_runs_and_ranks_the_methods() {
        let opts = EnvStudyOptions {
            width: 96,
            height: 72,
            samples: 2,
            timed_frames: 1,
            map_size: 64,
        };
        let recs = run(&opts).unwrap();
        let get = |study: &str, m: Method, x: f64| {
            recs.iter()
                .find(|r| r.study == study && r.method == m.name() && r.x == x)
                .unwrap()
                .psnr_db
        };
        // Parallax falls with distance for every dynamic map.
        for m in [Method::SphereDynamic, Method::Cube, Method::Paraboloid] {
            assert!(
                get("distance", m, 30.0) > get("distance", m, 1.5) + 3.0,
                "{m:?}"
            );
        }
        let dir = tempfile::tempdir().unwrap();
        let files = write(dir.path(), &recs).unwrap();
        assert!(files.iter().any(|p| p.ends_with("envmap_distance.svg")));
        assert!(files.iter().any(|p| p.ends_with("envmap_angle.png")));
        let csv = std::fs::read_to_string(dir.path().join("envmap.csv")).unwrap();
        assert_eq!(csv.lines().count(), recs.len() + 1);
    }
}
