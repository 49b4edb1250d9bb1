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
//! - **staleness**: time-sliced cube maps ([`Options::cube_faces_per_frame`] N of 1, 2, 3, 6) on
//!   the moving tunnel: [`EnvStudyOptions::staleness_frames`] frames
//!   [`EnvStudyOptions::staleness_dt`] apart in scene time, one [`Renderer`] across them, each
//!   frame against the reference at its own time. PSNR pooled over the frames after the first
//!   (which draws the whole map for every N), against the reference and against the same method
//!   redrawing every face (the stale faces' error alone), and the mean update time per frame:
//!   the update cost traded for the error. `staleness_frames` holds the per-frame figures.
//!
//! The reference traces the target analytically (mirror, or refraction without Fresnel: what the
//! maps compute), objects flat-shaded with the same materials and lighting, escaped rays and
//! primary misses looking up the same [`Environment`](texmap_envmap::Environment), `n × n`
//! samples per pixel. Target pixels are those where the traced depth with the target alone
//! equals the depth with everything. PSNR is over sRGB8 RGB of those pixels.
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
    /// `methods`, `angle`, `distance`, `resolution`, `refraction`, `staleness` or
    /// `staleness_frames`.
    pub study: String,
    pub method: String,
    /// The swept value: incidence angle (degrees, bin centre), distance (target radii), map
    /// side (texels), ior, cube faces redrawn per frame (`staleness`), frame index
    /// scene time of the frame (`staleness_frames`, seconds); 0 for `methods`.
    pub x: f64,
    /// PSNR (dB) over the target's pixels (or the bin's) against the full reference.
    pub psnr_db: f64,
    /// `methods` only: PSNR against the reference without objects (NaN elsewhere).
    pub psnr_env_only_db: f64,
    /// Mean absolute error, sRGB8 codes averaged over RGB.
    pub mean_abs_err: f64,
    /// Median wall time of the map update and of drawing (ms; 0 outside `methods`); for
    /// `staleness` the mean per frame, for `staleness_frames` the frame's.
    pub update_ms: f64,
    pub draw_ms: f64,
    /// Pixels measured.
    pub pixels: usize,
    /// Cube faces redrawn per frame ([`Options::cube_faces_per_frame`]): the default 6 outside
    /// the staleness studies.
    pub faces_per_frame: u32,
    /// Staleness studies only: PSNR against the same method redrawing every face every frame,
    /// the stale faces' own error (infinite for N = 6; NaN elsewhere).
    pub psnr_vs_full_update_db: f64,
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
    /// Map side of the `methods`, `angle`, `distance`, `refraction` and `staleness` studies.
    pub map_size: u32,
    /// Frames of the staleness study (0 leaves it out).
    pub staleness_frames: u32,
    /// Scene time between two frames of the staleness study (seconds).
    pub staleness_dt: f32,
}

impl Default for EnvStudyOptions {
    fn default() -> Self {
        EnvStudyOptions {
            width: 320,
            height: 240,
            samples: 3,
            timed_frames: 5,
            map_size: 256,
            staleness_frames: STALENESS_FRAMES,
            staleness_dt: STALENESS_DT,
        }
    }
}

/// Default frames of the staleness study: two rounds of one face per frame after the first.
pub const STALENESS_FRAMES: u32 = 13;
/// Default scene time between the staleness study's frames (s): a 30 Hz animation.
pub const STALENESS_DT: f32 = 1.0 / 30.0;
/// Faces per frame of the staleness study.
pub const STALENESS_FACES: [u32; 4] = [1, 2, 3, 6];

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
    if opts.staleness_frames > 1000 || !(opts.staleness_dt.is_finite() && opts.staleness_dt >= 0.0)
    {
        return Err(EnvStudyError::BadOption {
            what: "staleness_frames must be in 0..=1000 and staleness_dt finite and ≥ 0",
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
        faces_per_frame: 6,
        psnr_vs_full_update_db: f64::NAN,
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
    out.extend(staleness(opts, &cam)?);
    Ok(out)
}

/// The staleness study (see the module docs): records `staleness` (x = faces per frame) and
/// `staleness_frames` (x = frame index), for the cube and box-projected cube methods.
fn staleness(opts: &EnvStudyOptions, cam: &Camera) -> Result<Vec<EnvRecord>, EnvStudyError> {
    let frames = opts.staleness_frames as usize;
    if frames == 0 {
        return Ok(Vec::new());
    }
    // The scene, its reference and its target's pixels at each frame's time, shared by every N.
    let shots = (0..frames)
        .map(|k| {
            let time = k as f32 * opts.staleness_dt;
            let scene = tunnel_scene(TunnelParams {
                time,
                ..Default::default()
            })?;
            let full = reference(&scene, cam, true, opts.samples)?;
            let mask = target_mask(&scene, cam)?;
            Ok((time, scene, full, mask))
        })
        .collect::<Result<Vec<_>, EnvStudyError>>()?;
    let mut out = Vec::new();
    for method in [Method::Cube, Method::CubeBox] {
        // N = 6 first: its frames are the full-update frames the others are compared with.
        let mut every_face: Vec<Frame> = Vec::new();
        let mut summary = Vec::new();
        for &n in STALENESS_FACES.iter().rev() {
            let mut o = Options::new(method);
            o.map_size = opts.map_size;
            o.cube_faces_per_frame = n;
            let mut r = Renderer::new();
            let (mut se, mut ae, mut px, mut se_full) = (0.0, 0.0, 0, 0.0);
            let (mut up, mut dr) = (0.0, 0.0);
            for (k, (time, scene, full, mask)) in shots.iter().enumerate() {
                let res = r.render(scene, cam, &o)?;
                let (fse, fae, fpx) = sq_err(&res.frame, full, |i| mask[i]);
                if n == 6 {
                    every_face.push(res.frame.clone());
                }
                let (fse_full, _, _) = sq_err(&res.frame, &every_face[k], |i| mask[i]);
                out.push(EnvRecord {
                    study: "staleness_frames".into(),
                    method: method.name().into(),
                    // The scene time, rounded to µs for the CSV.
                    x: (*time as f64 * 1e6).round() / 1e6,
                    psnr_db: psnr_of(fse, fpx),
                    psnr_env_only_db: f64::NAN,
                    mean_abs_err: fae / (3 * fpx.max(1)) as f64,
                    update_ms: res.update_ms,
                    draw_ms: res.draw_ms,
                    pixels: fpx,
                    faces_per_frame: n,
                    psnr_vs_full_update_db: psnr_of(fse_full, fpx),
                });
                // The first frame draws the whole map for every N (and fills the caches).
                if k > 0 {
                    se += fse;
                    ae += fae;
                    px += fpx;
                    se_full += fse_full;
                    up += res.update_ms;
                    dr += res.draw_ms;
                }
                r.recycle(res.frame);
            }
            let timed = (frames - 1).max(1) as f64;
            summary.push(EnvRecord {
                study: "staleness".into(),
                method: method.name().into(),
                x: n as f64,
                psnr_db: psnr_of(se, px),
                psnr_env_only_db: f64::NAN,
                mean_abs_err: ae / (3 * px.max(1)) as f64,
                update_ms: up / timed,
                draw_ms: dr / timed,
                pixels: px,
                faces_per_frame: n,
                psnr_vs_full_update_db: psnr_of(se_full, px),
            });
        }
        summary.reverse();
        out.extend(summary);
    }
    Ok(out)
}

/// CSV of the records (one header line).
pub fn to_csv(records: &[EnvRecord]) -> String {
    let mut s = String::from(
        "study,method,x,psnr_db,psnr_env_only_db,mean_abs_err,update_ms,draw_ms,pixels,\
         faces_per_frame,psnr_vs_full_update_db\n",
    );
    for r in records {
        s.push_str(&format!(
            "{},{},{},{:.3},{:.3},{:.3},{:.3},{:.3},{},{},{:.3}\n",
            r.study,
            r.method,
            r.x,
            r.psnr_db,
            r.psnr_env_only_db,
            r.mean_abs_err,
            r.update_ms,
            r.draw_ms,
            r.pixels,
            r.faces_per_frame,
            r.psnr_vs_full_update_db
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
/// The staleness chart's size (two panels side by side).
const STALENESS_CHART_SIZE: (u32, u32) = (1300, 560);

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

/// One line of a chart: its legend, colour and points.
struct Line {
    name: String,
    colour: RGBAColor,
    pts: Vec<(f64, f64)>,
}

/// The colour of a method's lines.
fn method_colour(method: Method) -> RGBAColor {
    let i = Method::ALL.iter().position(|&m| m == method).unwrap_or(0);
    Palette99::pick(i).to_rgba()
}

/// Axis labels and title of a panel.
struct Panel<'a> {
    chart: &'a str,
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    /// Points' x are log2 of the values (tick labels show the values).
    log_x: bool,
}

/// Draw `lines` (non-finite points left out) on `area`, filled white first; the caller presents
/// the drawing. Returns `false` (nothing drawn) when no point is finite.
fn draw_lines<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    panel: &Panel,
    lines: &[Line],
) -> Result<bool, EnvStudyError> {
    ensure_font()?;
    let err = |e: String| EnvStudyError::Chart {
        chart: panel.chart.into(),
        message: e,
    };
    let lines: Vec<(&Line, Vec<(f64, f64)>)> = lines
        .iter()
        .map(|l| {
            let pts = l.pts.iter().copied();
            (
                l,
                pts.filter(|(x, y)| x.is_finite() && y.is_finite())
                    .collect(),
            )
        })
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in lines.iter().flat_map(|(_, p)| p) {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        return Ok(false);
    }
    let pad = ((y1 - y0) * 0.08).max(0.5);
    area.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let mut chart = ChartBuilder::on(area)
        .caption(panel.title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1 + 1e-9, (y0 - pad)..(y1 + pad))
        .map_err(|e| err(e.to_string()))?;
    let log_x = panel.log_x;
    chart
        .configure_mesh()
        .x_desc(panel.x_label)
        .y_desc(panel.y_label)
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
    for (line, pts) in &lines {
        if pts.is_empty() {
            continue;
        }
        let colour = line.colour;
        chart
            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
            .map_err(|e| err(e.to_string()))?
            .label(line.name.as_str())
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
    Ok(true)
}

/// One line per method of the records of `study`, y = PSNR (or mean abs error), on `area`.
/// Returns `false` (nothing drawn) when the study has no finite point.
fn line_chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    records: &[EnvRecord],
    study: &str,
    x_label: &str,
    log_x: bool,
    y_err: bool,
) -> Result<bool, EnvStudyError> {
    let y_of = |r: &EnvRecord| {
        if y_err {
            r.mean_abs_err
        } else {
            r.psnr_db.min(100.0)
        }
    };
    let x_of = |r: &EnvRecord| if log_x { r.x.log2() } else { r.x };
    let lines: Vec<Line> = Method::ALL
        .iter()
        .map(|&method| Line {
            name: method.name().into(),
            colour: method_colour(method),
            pts: records
                .iter()
                .filter(|r| r.study == study && r.method == method.name())
                .map(|r| (x_of(r), y_of(r)))
                .collect(),
        })
        .collect();
    let title = match study {
        "angle" => "Error against angle of incidence (tunnel scene)",
        "distance" => "PSNR against object distance (target radii)",
        "resolution" => "PSNR against map resolution (tunnel scene)",
        "refraction" => "Refraction: PSNR against index of refraction",
        _ => study,
    };
    let panel = Panel {
        chart: study,
        title,
        x_label,
        y_label: if y_err {
            "mean |error| (sRGB codes)"
        } else {
            "PSNR over target pixels (dB)"
        },
        log_x,
    };
    draw_lines(area, &panel, &lines)
}

/// The staleness study on two panels: PSNR against faces redrawn per frame (against the
/// reference, and against the full update), and the mean update time per frame.
fn staleness_chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    records: &[EnvRecord],
) -> Result<bool, EnvStudyError> {
    let mine: Vec<&EnvRecord> = records.iter().filter(|r| r.study == "staleness").collect();
    let (left, right) = area.split_horizontally(STALENESS_CHART_SIZE.0 / 2);
    let (mut psnr, mut time) = (Vec::new(), Vec::new());
    for method in [Method::Cube, Method::CubeBox] {
        let of = |y: &dyn Fn(&EnvRecord) -> f64| -> Vec<(f64, f64)> {
            mine.iter()
                .filter(|r| r.method == method.name())
                .map(|r| (r.x, y(r)))
                .collect()
        };
        let colour = method_colour(method);
        psnr.push(Line {
            name: format!("{} vs reference", method.name()),
            colour,
            pts: of(&|r| r.psnr_db),
        });
        psnr.push(Line {
            name: format!("{} vs every face redrawn", method.name()),
            colour: colour.mix(0.45),
            pts: of(&|r| r.psnr_vs_full_update_db),
        });
        time.push(Line {
            name: method.name().into(),
            colour,
            pts: of(&|r| r.update_ms),
        });
    }
    // The frame interval and count, from the per-frame records' times.
    let times: Vec<f64> = records
        .iter()
        .filter(|r| r.study == "staleness_frames" && r.method == Method::Cube.name())
        .map(|r| r.x)
        .collect();
    let runs = times.iter().filter(|&&t| t == 0.0).count().max(1);
    let dt = times
        .iter()
        .copied()
        .filter(|&t| t > 0.0)
        .fold(f64::NAN, f64::min);
    let title = format!(
        "Time-sliced cube map: PSNR ({} frames {:.3} s apart)",
        times.len() / runs,
        dt
    );
    let x_label = "cube faces redrawn per frame";
    let drawn = draw_lines(
        &left,
        &Panel {
            chart: "staleness",
            title: &title,
            x_label,
            y_label: "PSNR over target pixels, frames 2+ (dB)",
            log_x: false,
        },
        &psnr,
    )?;
    Ok(drawn
        && draw_lines(
            &right,
            &Panel {
                chart: "staleness",
                title: "Map update per frame (mean, harness clock)",
                x_label,
                y_label: "update (ms)",
                log_x: false,
            },
            &time,
        )?)
}

/// Draw one chart as `<name>.svg` and `<name>.png` in `dir` (both through temporary names, then
/// renamed) and add their paths to `written`; nothing is written when `draw` draws nothing.
fn write_chart(
    dir: &Path,
    name: &str,
    size: (u32, u32),
    draw_svg: impl Fn(&DrawingArea<SVGBackend, plotters::coord::Shift>) -> Result<bool, EnvStudyError>,
    draw_png: impl Fn(
        &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    ) -> Result<bool, EnvStudyError>,
    written: &mut Vec<PathBuf>,
) -> Result<(), EnvStudyError> {
    let err = |e: String| EnvStudyError::Chart {
        chart: name.into(),
        message: e,
    };
    let mut svg = String::new();
    {
        let area = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        if !draw_svg(&area)? {
            return Ok(());
        }
        area.present().map_err(|e| err(e.to_string()))?;
    }
    let path = dir.join(format!("{name}.svg"));
    write_atomic(&path, svg.as_bytes())?;
    written.push(path);
    // PNG: drawn to a temporary name (plotters picks the encoder by extension), renamed.
    let png = dir.join(format!("{name}.png"));
    let tmp = dir.join(format!("{name}.partial.png"));
    {
        let area = BitMapBackend::new(&tmp, size).into_drawing_area();
        draw_png(&area)?;
        area.present().map_err(|e| err(e.to_string()))?;
    }
    std::fs::rename(&tmp, &png).map_err(|source| EnvStudyError::Io {
        path: png.clone(),
        source,
    })?;
    written.push(png);
    Ok(())
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
        write_chart(
            dir,
            &format!("envmap_{study}"),
            CHART_SIZE,
            |a| line_chart(a, records, study, x_label, log_x, y_err),
            |a| line_chart(a, records, study, x_label, log_x, y_err),
            &mut written,
        )?;
    }
    write_chart(
        dir,
        "envmap_staleness",
        STALENESS_CHART_SIZE,
        |a| staleness_chart(a, records),
        |a| staleness_chart(a, records),
        &mut written,
    )?;
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
            staleness_frames: 7,
            staleness_dt: STALENESS_DT,
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
        // Time slicing: the first frame is the full update's for every N; after it, fewer faces
        // per frame leave stale faces (an error against the full update), six leave none.
        for m in [Method::Cube, Method::CubeBox] {
            let stale = |n: u32| {
                recs.iter()
                    .find(|r| r.study == "staleness" && r.method == m.name() && r.x == n as f64)
                    .unwrap()
            };
            assert_eq!(stale(6).psnr_vs_full_update_db, f64::INFINITY);
            for n in [1, 2, 3] {
                let p = stale(n).psnr_vs_full_update_db;
                assert!(p.is_finite() && p > 10.0, "{m:?} N {n}: {p}");
                assert_eq!(stale(n).pixels, stale(6).pixels);
            }
            let frames: Vec<&EnvRecord> = recs
                .iter()
                .filter(|r| r.study == "staleness_frames" && r.method == m.name())
                .collect();
            assert_eq!(frames.len(), 7 * STALENESS_FACES.len());
            assert!(
                frames
                    .iter()
                    .filter(|r| r.x == 0.0)
                    .all(|r| r.psnr_vs_full_update_db == f64::INFINITY)
            );
        }
        let dir = tempfile::tempdir().unwrap();
        let files = write(dir.path(), &recs).unwrap();
        assert!(files.iter().any(|p| p.ends_with("envmap_staleness.svg")));
        assert!(files.iter().any(|p| p.ends_with("envmap_staleness.png")));
        assert!(files.iter().any(|p| p.ends_with("envmap_distance.svg")));
        assert!(files.iter().any(|p| p.ends_with("envmap_angle.png")));
        let csv = std::fs::read_to_string(dir.path().join("envmap.csv")).unwrap();
        assert_eq!(csv.lines().count(), recs.len() + 1);
    }
}
