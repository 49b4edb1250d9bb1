//! The flight-view study (Seed 000): every sampler of the terrain flight view against a
//! supersampled, footprint-integrated ray-traced reference, and the paper's hardware claims
//! counted through the bank emulator.
//!
//! **The reference** ([`TerrainReference`]): the terrain's full-resolution mesh (the RTIN at
//! error 0, [`texmap_terrain::db::whole_mesh`], so every grid sample is a vertex or lies on the
//! surface) traced by `texmap-reftrace` with the level-0 texels of the very texture the flight
//! view samples, integrated over each sample's exact screen footprint (reftrace's
//! footprint-integrated texture), with `n × n` stratified samples per pixel (4 × 4 unless stated).
//! The flight view is unlit (a pixel is its texture value), so the reference shades with an
//! ambient light of 1 and no directional light on a white matte material: the shading model
//! returns the texture value unchanged, and a difference between the two frames is the method's
//! sampling (plus the level-of-detail mesh's geometric error, common to all samplers). Edges:
//! the flight view's texture clamps, reftrace's repeats; the two differ only where a pixel's
//! footprint reaches past the terrain's outer edge.
//!
//! **Per view and sampler** ([`run_study`]): PSNR and SSIM (texmap-core metrics, on the sRGB8
//! output) and a blur measure: the mean squared luma gradient (forward differences over pixels
//! that both frames cover, with their right and lower neighbours) of the method's frame divided
//! by the reference's — 1 is as sharp as the reference, below 1 blurrier, above 1 sharper than
//! the integral (aliasing) — also given in dB (`10 log10`). **Temporal flicker**: over the
//! path's slow pass (its `slow-pass` views; a user path: all views), the mean absolute luma
//! difference between consecutive frames, minus the reference's: shimmering that the motion
//! itself does not explain.
//!
//! **The paper's claims** ([`Claims`]), counted on the whole path: bank conflicts of the span
//! sampler through [`BankedTexture`] (3x3 and 4x4; a control run with the 3x3 window forced one
//! level finer shows the emulator does see conflicts), banks read per window (9 vs 16), texture
//! memory of the shared banked pyramid against one pyramid copy per pixel processor of the 2x2
//! span (the paper: 1/4), level computations per covered pixel (span: one per 2x2 span,
//! trilinear: one per pixel), and the blur that 3x3 banks cost against 4x4 (PSNR difference in
//! dB, blur measure).
//!
//! **Higher-order interpolation from the 3x3 neighbourhood** ([`Sampler::Quadratic3`], study
//! name `quadratic3`: per level, 3-point Lagrange interpolation on the 3x3 texels around the
//! pixel's nearest texel, on trilinear's levels), which the paper suggests but did not test,
//! is drawn like every other texmap-core sampler (its quad kernel, so its frame time compares
//! with trilinear's) and compared with trilinear in [`Claims`].
//!
//! [`write_study`] writes `results.csv`, `results.json`, `summary.md` and two charts, each as
//! SVG and PNG: `error_vs_pitch` and `error_vs_altitude` (PSNR of every sampler against the
//! view's pitch and height above the ground). [`demo_section`] builds a deterministic terrain
//! ([`builtin_terrain`]), flies it into an APNG and compares the samplers on a small study path.
//!
//! ```
//! use texmap_study::terrain::{StudyOptions, TerrainReference, builtin_terrain, run_study};
//! use texmap_terrain::flight::study_path;
//! use texmap_terrain::view::FlightCamera;
//!
//! let terrain = builtin_terrain(65, 128)?;
//! let template = FlightCamera { width: 48, height: 36, ..FlightCamera::over(terrain.grid()) };
//! let path: Vec<_> = study_path(terrain.grid(), &template).into_iter().take(2).collect();
//! let reference = TerrainReference::new(&terrain)?;
//! let opts = StudyOptions { samples_per_axis: 2, samplers: vec!["trilinear".into()], ..StudyOptions::default() };
//! let study = run_study(&terrain, &reference, &path, &opts, &mut |_, _| {})?;
//! assert_eq!(study.results.len(), 2);
//! assert!(study.results.iter().all(|r| r.psnr_db > 15.0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use glam::Vec3;
use serde::Serialize;
use texmap_core::camera::Camera;
use texmap_core::frame::Frame;
use texmap_core::metrics::{psnr, ssim};
use texmap_core::mip::MipTexture;
use texmap_core::sample::{BankStats, BankedTexture, Banks, Sampler};
use texmap_core::shade::{Lighting, Material};
use texmap_raster::{Framebuffer, MipSampler, QuadSampler, TexQuad};
use texmap_reftrace::{RenderOptions, Scene, SceneBuilder, SurfaceMaterial, Texture};
use texmap_terrain::dem::{Georef, Grid};
use texmap_terrain::flight::{PathView, study_path};
use texmap_terrain::models::Placed;
use texmap_terrain::view::{
    self, FlightCamera, FlightTerrain, FrameScratch, ViewError, ViewOptions, ground_height,
    sampler_by_name,
};

use crate::error::StudyError;

/// Why a terrain study step failed.
#[derive(Debug)]
#[non_exhaustive]
pub enum TerrainStudyError {
    /// A view could not be set up or drawn (names the view when it comes from a path).
    View {
        view: Option<usize>,
        source: ViewError,
    },
    Terrain(texmap_terrain::TerrainError),
    /// The reference scene or texture was refused.
    Reference(String),
    Study(StudyError),
    Movie(texmap_movie::MovieError),
    /// An option out of range.
    BadOption {
        what: &'static str,
        value: String,
    },
}

impl std::fmt::Display for TerrainStudyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TerrainStudyError::View {
                view: Some(i),
                source,
            } => write!(f, "view {i} of the path: {source}"),
            TerrainStudyError::View { view: None, source } => write!(f, "{source}"),
            TerrainStudyError::Terrain(e) => write!(f, "{e}"),
            TerrainStudyError::Reference(m) => write!(f, "terrain reference: {m}"),
            TerrainStudyError::Study(e) => write!(f, "{e}"),
            TerrainStudyError::Movie(e) => write!(f, "{e}"),
            TerrainStudyError::BadOption { what, value } => {
                write!(f, "option {what} = {value} is out of range")
            }
        }
    }
}

impl std::error::Error for TerrainStudyError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            TerrainStudyError::View { source, .. } => Some(source),
            TerrainStudyError::Terrain(e) => Some(e),
            TerrainStudyError::Study(e) => Some(e),
            TerrainStudyError::Movie(e) => Some(e),
            _ => None,
        }
    }
}

impl From<StudyError> for TerrainStudyError {
    fn from(e: StudyError) -> Self {
        TerrainStudyError::Study(e)
    }
}

impl From<ViewError> for TerrainStudyError {
    fn from(source: ViewError) -> Self {
        TerrainStudyError::View { view: None, source }
    }
}

impl From<texmap_terrain::TerrainError> for TerrainStudyError {
    fn from(e: texmap_terrain::TerrainError) -> Self {
        TerrainStudyError::Terrain(e)
    }
}

impl From<texmap_movie::MovieError> for TerrainStudyError {
    fn from(e: texmap_movie::MovieError) -> Self {
        TerrainStudyError::Movie(e)
    }
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> TerrainStudyError + '_ {
    move |source| {
        TerrainStudyError::Study(StudyError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// Samples per axis of the reference unless stated (16 per pixel).
pub const DEFAULT_REFERENCE_SAMPLES: u32 = 4;

/// The supersampled, footprint-integrated ray-traced reference of a [`FlightTerrain`] (see the
/// module docs). Built once per terrain (BVH over the full-resolution mesh, linear texture).
pub struct TerrainReference {
    scene: Scene,
    textures: Vec<Texture>,
    materials: Vec<SurfaceMaterial>,
    triangles: usize,
}

impl std::fmt::Debug for TerrainReference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TerrainReference")
            .field("triangles", &self.triangles)
            .field(
                "texture",
                &(self.textures[0].width(), self.textures[0].height()),
            )
            .finish()
    }
}

impl TerrainReference {
    /// The reference of `terrain`: its grid's full-resolution mesh and level 0 of its texture.
    pub fn new(terrain: &FlightTerrain) -> Result<TerrainReference, TerrainStudyError> {
        TerrainReference::with_models(terrain, &[])
    }

    /// The reference of `terrain` with placed models ([`texmap_terrain::models`]): each model's
    /// mesh traced with level 0 of its texture (repeating, as the model's pyramid), or its flat
    /// colour when it is drawn untextured. Tree billboards are not part of the reference.
    pub fn with_models(
        terrain: &FlightTerrain,
        models: &[Placed],
    ) -> Result<TerrainReference, TerrainStudyError> {
        let reference = |e: &dyn std::fmt::Display| TerrainStudyError::Reference(e.to_string());
        let level0 = |tex: &MipTexture| {
            let n = tex.width() as usize * tex.height() as usize;
            let texels = tex.texels()[..n].iter().map(|t| t.to_array()).collect();
            Texture::new(tex.width(), tex.height(), texels).map_err(|e| reference(&e))
        };
        let mesh = texmap_terrain::db::whole_mesh(terrain.grid(), 0.0)?;
        let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let mut b = SceneBuilder::new();
        b.add_mesh(&mesh.positions, &indices, mesh.uvs.as_deref(), 0)
            .map_err(|e| reference(&e))?;
        let mut textures = vec![level0(terrain.texture())?];
        let mut materials =
            vec![SurfaceMaterial::opaque(Material::matte(Vec3::ONE)).with_texture(0)];
        let mut triangles = mesh.triangles.len();
        for m in models {
            let id = materials.len() as u32;
            let idx: Vec<u32> = m.triangles.iter().flatten().copied().collect();
            match (&m.uvs, &m.texture) {
                (Some(uvs), Some(tex)) => {
                    b.add_mesh(&m.positions, &idx, Some(uvs), id)
                        .map_err(|e| reference(&e))?;
                    materials.push(
                        SurfaceMaterial::opaque(Material::matte(Vec3::ONE))
                            .with_texture(textures.len() as u32),
                    );
                    textures.push(level0(tex)?);
                }
                _ => {
                    b.add_mesh(&m.positions, &idx, None, id)
                        .map_err(|e| reference(&e))?;
                    materials.push(SurfaceMaterial::opaque(Material::matte(m.color)));
                }
            }
            triangles += m.triangles.len();
        }
        Ok(TerrainReference {
            scene: b.build(),
            textures,
            materials,
            triangles,
        })
    }

    /// Triangles of the full-resolution mesh.
    pub fn triangles(&self) -> usize {
        self.triangles
    }

    /// Trace `camera` with `samples_per_axis²` samples per pixel; uncovered pixels are `sky`.
    pub fn render(
        &self,
        camera: &Camera,
        samples_per_axis: u32,
        sky: [u8; 3],
    ) -> Result<Frame, TerrainStudyError> {
        let lighting = Lighting::new(Vec3::ONE, &[])
            .map_err(|e| TerrainStudyError::Reference(e.to_string()))?;
        let mut opts = RenderOptions::new(lighting, &self.materials);
        opts.textures = &self.textures;
        opts.samples_per_axis = samples_per_axis;
        opts.max_depth = 0;
        opts.background = texmap_core::color::srgb8_to_linear_rgb([sky[0], sky[1], sky[2], 255]);
        self.scene
            .render(camera, &opts)
            .map_err(|e| StudyError::Reference(e).into())
    }

    /// The reference of one flight view (the camera of [`FlightCamera::camera`]).
    pub fn render_view(
        &self,
        terrain: &FlightTerrain,
        view: &FlightCamera,
        samples_per_axis: u32,
    ) -> Result<Frame, TerrainStudyError> {
        let cam = view.camera(terrain.grid())?;
        self.render(&cam, samples_per_axis, [0, 0, 0])
    }
}

/// One flight-view frame with a texmap-core sampler (the fast kernels), as a [`Frame`].
pub fn render_method(
    terrain: &FlightTerrain,
    view: &FlightCamera,
    sampler: Sampler,
    pixel_error: f32,
) -> Result<Frame, TerrainStudyError> {
    let mut fb = Framebuffer::new(view.width, view.height).map_err(ViewError::Raster)?;
    let opts = ViewOptions {
        pixel_error,
        sampler,
        ..ViewOptions::default()
    };
    terrain.render(view, &opts, &mut fb, &mut FrameScratch::default())?;
    Ok(fb.to_frame())
}

/// Draw one view with any [`QuadSampler`] (for the counting samplers of the claims).
fn render_with<S: QuadSampler>(
    terrain: &FlightTerrain,
    view: &FlightCamera,
    sampler: &S,
    pixel_error: f32,
) -> Result<Frame, TerrainStudyError> {
    let cam = view.camera(terrain.grid())?;
    let sel = terrain.select(&cam, pixel_error);
    let mut fb = Framebuffer::new(view.width, view.height).map_err(ViewError::Raster)?;
    fb.clear([0, 0, 0, 0]);
    terrain.draw(&cam, &sel, sampler, &mut fb, &mut FrameScratch::default())?;
    Ok(fb.to_frame())
}

/// The span sampler through the bank emulator, counting over a whole path (bit-identical colours
/// to [`Sampler::Span`]).
struct BankCounter<'a> {
    tex: &'a MipTexture,
    banked: BankedTexture,
    counts: [AtomicU64; 5],
}

impl<'a> BankCounter<'a> {
    fn new(tex: &'a MipTexture, banks: Banks, bias: i32) -> BankCounter<'a> {
        BankCounter {
            tex,
            banked: BankedTexture::new(tex, banks).with_level_bias(bias),
            counts: Default::default(),
        }
    }
    fn stats(&self) -> BankStats {
        let c = |i: usize| self.counts[i].load(Ordering::Relaxed);
        BankStats {
            spans: c(0),
            window_reads: c(1),
            bank_reads: c(2),
            conflicts: c(3),
            edge_windows: c(4),
        }
    }
}

impl QuadSampler for BankCounter<'_> {
    fn sample_quad(&self, quad: &TexQuad) -> [Vec3; 4] {
        let mut s = BankStats::default();
        let c = self.banked.sample_quad(self.tex, quad.uv, &mut s);
        for (i, v) in [
            s.spans,
            s.window_reads,
            s.bank_reads,
            s.conflicts,
            s.edge_windows,
        ]
        .into_iter()
        .enumerate()
        {
            self.counts[i].fetch_add(v, Ordering::Relaxed);
        }
        c.map(|t| t.truncate())
    }
}

/// A texmap-core sampler that counts the quads it is asked for.
struct QuadCounter<'a> {
    inner: MipSampler<'a>,
    quads: AtomicU64,
}

impl QuadSampler for QuadCounter<'_> {
    fn sample_quad(&self, quad: &TexQuad) -> [Vec3; 4] {
        self.quads.fetch_add(1, Ordering::Relaxed);
        self.inner.sample_quad(quad)
    }
}

/// The study name of [`Sampler::Quadratic3`], the higher-order interpolation from the 3x3
/// neighbourhood that the paper suggests (compared with trilinear in [`Claims`]).
pub const QUADRATIC_NAME: &str = "quadratic3";

/// Rec. 601 luma of an sRGB8 pixel.
fn luma(c: [u8; 4]) -> f64 {
    0.299 * c[0] as f64 + 0.587 * c[1] as f64 + 0.114 * c[2] as f64
}

/// Mean squared luma gradients `(method, reference)` over pixels that both frames cover together
/// with their right and lower neighbours.
fn gradient_energy(a: &Frame, r: &Frame) -> (f64, f64) {
    let (w, h) = (a.width() as usize, a.height() as usize);
    let (mut ea, mut er, mut n) = (0.0, 0.0, 0usize);
    for y in 0..h.saturating_sub(1) {
        for x in 0..w.saturating_sub(1) {
            let i = y * w + x;
            let ids = [i, i + 1, i + w];
            if !ids.iter().all(|&k| a.covered(k) && r.covered(k)) {
                continue;
            }
            let g = |f: &Frame| {
                let c = luma(f.color[i]);
                let dx = luma(f.color[i + 1]) - c;
                let dy = luma(f.color[i + w]) - c;
                dx * dx + dy * dy
            };
            ea += g(a);
            er += g(r);
            n += 1;
        }
    }
    if n == 0 {
        return (0.0, 0.0);
    }
    (ea / n as f64, er / n as f64)
}

/// The blur measure of `a` against reference `r`: ratio of mean squared luma gradients (1 when
/// neither has any gradient).
pub fn blur_ratio(a: &Frame, r: &Frame) -> f64 {
    let (ea, er) = gradient_energy(a, r);
    if er == 0.0 {
        if ea == 0.0 { 1.0 } else { f64::INFINITY }
    } else {
        ea / er
    }
}

/// Mean absolute luma difference between two consecutive frames over the pixels both cover.
fn frame_difference(a: &Frame, b: &Frame) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for i in 0..a.len().min(b.len()) {
        if a.covered(i) && b.covered(i) {
            s += (luma(a.color[i]) - luma(b.color[i])).abs();
            n += 1;
        }
    }
    if n == 0 { 0.0 } else { s / n as f64 }
}

/// Every sampler name the study knows: [`view::SAMPLER_NAMES`] (with [`QUADRATIC_NAME`]).
pub fn study_sampler_names() -> Vec<String> {
    view::SAMPLER_NAMES.iter().map(|s| s.to_string()).collect()
}

/// What the study draws and how.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StudyOptions {
    /// Reference samples per pixel axis (1..=16).
    pub samples_per_axis: u32,
    /// The flight view's level-of-detail tolerance, pixels.
    pub pixel_error: f32,
    /// Sampler names ([`study_sampler_names`]; default: all).
    pub samplers: Vec<String>,
}

impl Default for StudyOptions {
    fn default() -> Self {
        StudyOptions {
            samples_per_axis: DEFAULT_REFERENCE_SAMPLES,
            pixel_error: 1.0,
            samplers: study_sampler_names(),
        }
    }
}

/// Where a view of the path is: its index, segment, eye and attitude.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ViewPlace {
    pub view: usize,
    pub segment: String,
    pub eye_x: f64,
    pub eye_y: f64,
    pub altitude_m: f64,
    /// Height of the eye above the ground under it.
    pub clearance_m: f64,
    pub heading_deg: f64,
    pub pitch_deg: f64,
}

/// One sampler on one view.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ViewResult {
    #[serde(flatten)]
    pub place: ViewPlace,
    pub sampler: String,
    pub psnr_db: f64,
    pub ssim: f64,
    pub blur_ratio: f64,
    pub blur_db: f64,
    /// Wall time of the frame (one run, indicative).
    pub ms: f64,
}

/// One sampler over the whole path.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SamplerSummary {
    pub sampler: String,
    pub psnr_mean_db: f64,
    pub psnr_min_db: f64,
    /// The view of the lowest PSNR (where the sampler breaks first).
    pub worst_view: usize,
    pub worst_segment: String,
    pub ssim_mean: f64,
    /// `10 log10` of the mean blur ratio over the views.
    pub blur_mean_db: f64,
    /// Mean frame-to-frame luma difference over the slow pass minus the reference's (8-bit
    /// levels).
    pub flicker_excess: f64,
    pub ms_mean: f64,
}

/// Seed 000's claims as counted on the path.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Claims {
    /// Bank conflicts of the span sampler over every view (the paper: none).
    pub conflicts_span3: u64,
    pub conflicts_span4: u64,
    /// Control: 3x3 banks with the finer level forced one level finer (the trilinear pair): the
    /// emulator must count conflicts here.
    pub conflicts_span3_forced_finer: u64,
    pub spans_span3: u64,
    /// Banks read per parallel window read (the paper: 9 instead of 16).
    pub banks_per_window_span3: f64,
    pub banks_per_window_span4: f64,
    /// The emulated 3x3 frames equal the fast span kernel's, byte for byte.
    pub emulator_matches_fast_path: bool,
    /// Texture memory, texels: the pyramid shared through K² banks (with its K − 1 apron), and
    /// one pyramid copy for each of the span's four pixel processors.
    pub texels_shared_3x3: u64,
    pub texels_per_pixel_copies: u64,
    /// shared / per-pixel copies (the paper: 1/4).
    pub memory_ratio: f64,
    /// Level-of-detail computations per covered pixel: span (one per 2x2 span) and trilinear
    /// (one per pixel, helper lanes of partly covered quads included).
    pub level_computations_per_pixel_span3: f64,
    pub level_computations_per_pixel_trilinear: f64,
    /// The price of 3x3 banks: mean PSNR of span4 minus span3 (dB) and their blur measures.
    pub psnr_span4_minus_span3_db: Option<f64>,
    pub blur_span3_db: Option<f64>,
    pub blur_span4_db: Option<f64>,
    /// Higher-order interpolation from the 3x3 neighbourhood against trilinear: mean PSNR of
    /// [`Sampler::Quadratic3`] minus trilinear's (dB), and the views where it is better.
    pub psnr_quadratic_minus_trilinear_db: Option<f64>,
    pub quadratic_better_views: Option<usize>,
}

/// A view of the path as studied.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StudiedView {
    #[serde(flatten)]
    pub place: ViewPlace,
    pub reference_ms: f64,
    pub pixels_covered: usize,
}

/// The whole study.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TerrainStudy {
    pub width: u32,
    pub height: u32,
    pub options: StudyOptions,
    pub reference_triangles: usize,
    pub texture_side: [u32; 2],
    pub views: Vec<StudiedView>,
    pub results: Vec<ViewResult>,
    pub summary: Vec<SamplerSummary>,
    pub claims: Claims,
    /// Frame-to-frame luma difference of the reference over the slow pass (8-bit levels).
    pub reference_flicker: f64,
}

/// Texels of a pyramid laid out in K x K banks: per level `K² · ⌈(w + K − 1)/K⌉ · ⌈(h + K − 1)/K⌉`
/// (the layout of [`BankedTexture`]).
fn banked_texels(tex: &MipTexture, k: u64) -> u64 {
    tex.levels()
        .iter()
        .map(|l| {
            k * k * (l.width as u64 + k - 1).div_ceil(k) * (l.height as u64 + k - 1).div_ceil(k)
        })
        .sum()
}

/// Indices of the views over which flicker is measured: the longest run of consecutive
/// `slow-pass` views, or every view when there is none.
fn flicker_views(path: &[PathView]) -> Vec<usize> {
    let (mut best, mut cur): (Vec<usize>, Vec<usize>) = (Vec::new(), Vec::new());
    for (i, p) in path.iter().enumerate() {
        if p.segment == "slow-pass" {
            cur.push(i);
            if cur.len() > best.len() {
                best = cur.clone();
            }
        } else {
            cur.clear();
        }
    }
    if best.len() >= 2 {
        best
    } else {
        (0..path.len()).collect()
    }
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 { f64::NAN } else { s / n as f64 }
}

/// Run the study: every sampler of `opts` against the reference on every view of `path`,
/// then the claims through the bank emulator. `progress(done, total)` after each view.
pub fn run_study(
    terrain: &FlightTerrain,
    reference: &TerrainReference,
    path: &[PathView],
    opts: &StudyOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<TerrainStudy, TerrainStudyError> {
    if path.is_empty() {
        return Err(TerrainStudyError::BadOption {
            what: "path",
            value: "no views".into(),
        });
    }
    let mut samplers = Vec::new();
    for name in &opts.samplers {
        let s = match sampler_by_name(name) {
            Some(s) => s,
            None => {
                return Err(TerrainStudyError::BadOption {
                    what: "sampler",
                    value: name.clone(),
                });
            }
        };
        samplers.push((name.clone(), s));
    }
    let (width, height) = (path[0].view.width, path[0].view.height);
    if path
        .iter()
        .any(|p| (p.view.width, p.view.height) != (width, height))
    {
        return Err(TerrainStudyError::BadOption {
            what: "path image size",
            value: "views of different sizes".into(),
        });
    }
    let grid = terrain.grid();
    let flicker_set = flicker_views(path);
    let mut prev: Option<(Frame, Vec<Frame>)> = None;
    let mut flicker = vec![0.0f64; samplers.len()];
    let mut ref_flicker = 0.0f64;
    let mut flicker_pairs = 0usize;
    let mut views = Vec::with_capacity(path.len());
    let mut results = Vec::new();
    let tex = terrain.texture();
    let span3 = BankCounter::new(tex, Banks::K3, 0);
    let span4 = BankCounter::new(tex, Banks::K4, 0);
    let forced = BankCounter::new(tex, Banks::K3, -1);
    let tri = QuadCounter {
        inner: MipSampler {
            texture: tex,
            sampler: Sampler::Trilinear,
        },
        quads: AtomicU64::new(0),
    };
    let mut covered_total = 0u64;
    let mut emulator_matches = true;
    for (i, p) in path.iter().enumerate() {
        let at = |source| TerrainStudyError::View {
            view: Some(i),
            source,
        };
        let v = &p.view;
        let cam = v.camera(grid).map_err(at)?;
        let t0 = Instant::now();
        let rf = reference.render(&cam, opts.samples_per_axis, [0, 0, 0])?;
        let reference_ms = t0.elapsed().as_secs_f64() * 1e3;
        let (col, row) = grid.georef().xy_to_sample(v.eye_x, v.eye_y);
        // Over no-data, the clearance is taken above the highest ground (as the path places it).
        let ground = ground_height(grid, col, row).unwrap_or_else(|| grid.height_range().1 as f64);
        let clearance = v.altitude - ground;
        let place = ViewPlace {
            view: i,
            segment: p.segment.to_string(),
            eye_x: v.eye_x,
            eye_y: v.eye_y,
            altitude_m: v.altitude,
            clearance_m: clearance,
            heading_deg: v.heading_deg,
            pitch_deg: v.pitch_deg,
        };
        views.push(StudiedView {
            place: place.clone(),
            reference_ms,
            pixels_covered: rf.coverage_count(),
        });
        let mut frames = Vec::with_capacity(samplers.len());
        for (name, s) in &samplers {
            let t0 = Instant::now();
            let f = render_method(terrain, v, *s, opts.pixel_error).map_err(|e| match e {
                TerrainStudyError::View { source, .. } => at(source),
                e => e,
            })?;
            let ms = t0.elapsed().as_secs_f64() * 1e3;
            let br = blur_ratio(&f, &rf);
            results.push(ViewResult {
                place: place.clone(),
                sampler: name.clone(),
                psnr_db: psnr(&f, &rf).map_err(StudyError::from)?,
                ssim: ssim(&f, &rf).map_err(StudyError::from)?,
                blur_ratio: br,
                blur_db: 10.0 * br.log10(),
                ms,
            });
            frames.push(f);
        }
        // The claims: the span sampler through the bank emulator, trilinear counted.
        let e3 = render_with(terrain, v, &span3, opts.pixel_error).map_err(|e| match e {
            TerrainStudyError::View { source, .. } => at(source),
            e => e,
        })?;
        let fast3 = render_method(terrain, v, Sampler::Span(Banks::K3), opts.pixel_error)?;
        emulator_matches &= e3 == fast3;
        covered_total += fast3.coverage_count() as u64;
        render_with(terrain, v, &span4, opts.pixel_error)?;
        render_with(terrain, v, &forced, opts.pixel_error)?;
        render_with(terrain, v, &tri, opts.pixel_error)?;
        if flicker_set.contains(&i) {
            if let Some((pr, pf)) = &prev {
                ref_flicker += frame_difference(pr, &rf);
                for (k, f) in frames.iter().enumerate() {
                    flicker[k] += frame_difference(&pf[k], f);
                }
                flicker_pairs += 1;
            }
            prev = Some((rf, frames));
        }
        progress(i + 1, path.len());
    }
    let pairs = flicker_pairs.max(1) as f64;
    let reference_flicker = ref_flicker / pairs;
    let summary: Vec<SamplerSummary> = samplers
        .iter()
        .enumerate()
        .map(|(k, (name, _))| {
            let mine: Vec<&ViewResult> = results.iter().filter(|r| &r.sampler == name).collect();
            let worst = mine
                .iter()
                .min_by(|a, b| a.psnr_db.total_cmp(&b.psnr_db))
                .expect("one result per view");
            SamplerSummary {
                sampler: name.clone(),
                psnr_mean_db: mean(mine.iter().map(|r| r.psnr_db)),
                psnr_min_db: worst.psnr_db,
                worst_view: worst.place.view,
                worst_segment: worst.place.segment.clone(),
                ssim_mean: mean(mine.iter().map(|r| r.ssim)),
                blur_mean_db: 10.0
                    * mean(mine.iter().map(|r| r.blur_ratio).filter(|x| x.is_finite())).log10(),
                flicker_excess: flicker[k] / pairs - reference_flicker,
                ms_mean: mean(mine.iter().map(|r| r.ms)),
            }
        })
        .collect();
    let find = |n: &str| summary.iter().find(|s| s.sampler == n);
    let (s3, s4, sf) = (span3.stats(), span4.stats(), forced.stats());
    let covered = covered_total.max(1) as f64;
    let per_pixel_copies = 4 * tex.texels().len() as u64;
    let shared = banked_texels(tex, 3);
    let claims = Claims {
        conflicts_span3: s3.conflicts,
        conflicts_span4: s4.conflicts,
        conflicts_span3_forced_finer: sf.conflicts,
        spans_span3: s3.spans,
        banks_per_window_span3: s3.bank_reads as f64 / s3.window_reads.max(1) as f64,
        banks_per_window_span4: s4.bank_reads as f64 / s4.window_reads.max(1) as f64,
        emulator_matches_fast_path: emulator_matches,
        texels_shared_3x3: shared,
        texels_per_pixel_copies: per_pixel_copies,
        memory_ratio: shared as f64 / per_pixel_copies as f64,
        level_computations_per_pixel_span3: s3.spans as f64 / covered,
        level_computations_per_pixel_trilinear: 4.0 * tri.quads.load(Ordering::Relaxed) as f64
            / covered,
        psnr_span4_minus_span3_db: find("span4")
            .zip(find("span3"))
            .map(|(a, b)| a.psnr_mean_db - b.psnr_mean_db),
        blur_span3_db: find("span3").map(|s| s.blur_mean_db),
        blur_span4_db: find("span4").map(|s| s.blur_mean_db),
        psnr_quadratic_minus_trilinear_db: find(QUADRATIC_NAME)
            .zip(find("trilinear"))
            .map(|(a, b)| a.psnr_mean_db - b.psnr_mean_db),
        quadratic_better_views: find(QUADRATIC_NAME).and(find("trilinear")).map(|_| {
            let of = |n: &str| -> Vec<f64> {
                results
                    .iter()
                    .filter(|r| r.sampler == n)
                    .map(|r| r.psnr_db)
                    .collect()
            };
            of(QUADRATIC_NAME)
                .iter()
                .zip(of("trilinear"))
                .filter(|(q, t)| **q > *t)
                .count()
        }),
    };
    Ok(TerrainStudy {
        width,
        height,
        options: opts.clone(),
        reference_triangles: reference.triangles(),
        texture_side: [tex.width(), tex.height()],
        views,
        results,
        summary,
        claims,
        reference_flicker,
    })
}

/// `results.csv`: one row per view and sampler.
pub fn results_csv(study: &TerrainStudy) -> String {
    let mut s = String::from(
        "view,segment,eye_x,eye_y,altitude_m,clearance_m,heading_deg,pitch_deg,sampler,psnr_db,ssim,blur_ratio,blur_db,ms\n",
    );
    for r in &study.results {
        s.push_str(&format!(
            "{},{},{},{},{:.3},{:.3},{},{},{},{:.4},{:.5},{:.5},{:.4},{:.3}\n",
            r.place.view,
            r.place.segment,
            r.place.eye_x,
            r.place.eye_y,
            r.place.altitude_m,
            r.place.clearance_m,
            r.place.heading_deg,
            r.place.pitch_deg,
            r.sampler,
            r.psnr_db,
            r.ssim,
            r.blur_ratio,
            r.blur_db,
            r.ms
        ));
    }
    s
}

/// The summary as a Markdown table and the claims as a list (for docs/ACCURACY.md).
pub fn summary_markdown(study: &TerrainStudy) -> String {
    let mut s = format!(
        "{} views at {}x{}, reference {}x{} samples per pixel over {} triangles, texture {}x{}.\n\n\
         | sampler | PSNR mean (dB) | PSNR min (dB) @ view | SSIM mean | blur (dB) | flicker excess | ms/frame |\n\
         |---|---|---|---|---|---|---|\n",
        study.views.len(),
        study.width,
        study.height,
        study.options.samples_per_axis,
        study.options.samples_per_axis,
        study.reference_triangles,
        study.texture_side[0],
        study.texture_side[1],
    );
    for r in &study.summary {
        s.push_str(&format!(
            "| {} | {:.2} | {:.2} @ {} ({}) | {:.4} | {:+.2} | {:+.3} | {:.1} |\n",
            r.sampler,
            r.psnr_mean_db,
            r.psnr_min_db,
            r.worst_view,
            r.worst_segment,
            r.ssim_mean,
            r.blur_mean_db,
            r.flicker_excess,
            r.ms_mean
        ));
    }
    let c = &study.claims;
    let opt = |v: Option<f64>| v.map_or("n/a".to_string(), |x| format!("{x:+.2} dB"));
    s.push_str(&format!(
        "\nSeed 000's claims over the path (bank emulator):\n\n\
         - bank conflicts: span3 {}, span4 {} over {} spans (control, 3x3 forced one level finer: {})\n\
         - banks read per window: span3 {:.2}, span4 {:.2}\n\
         - emulated frames equal the fast span kernel's: {}\n\
         - texture memory, shared 3x3 banks / one pyramid per pixel processor: {} / {} texels = {:.4}\n\
         - level computations per covered pixel: span3 {:.3}, trilinear {:.3}\n\
         - blur of 3x3 against 4x4 banks: PSNR span4 − span3 {}; blur measure span3 {}, span4 {}\n\
         - quadratic interpolation on the 3x3 neighbourhood against trilinear: PSNR {}, better on {} of {} views\n",
        c.conflicts_span3,
        c.conflicts_span4,
        c.spans_span3,
        c.conflicts_span3_forced_finer,
        c.banks_per_window_span3,
        c.banks_per_window_span4,
        c.emulator_matches_fast_path,
        c.texels_shared_3x3,
        c.texels_per_pixel_copies,
        c.memory_ratio,
        c.level_computations_per_pixel_span3,
        c.level_computations_per_pixel_trilinear,
        opt(c.psnr_span4_minus_span3_db),
        opt(c.blur_span3_db),
        opt(c.blur_span4_db),
        opt(c.psnr_quadratic_minus_trilinear_db),
        c.quadratic_better_views
            .map_or("n/a".to_string(), |n| n.to_string()),
        study.views.len(),
    ));
    s
}

/// Series colours of the charts (one per sampler, in [`view::SAMPLER_NAMES`] order).
const COLOURS: [&str; 8] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
];

/// A scatter chart as SVG text: one colour per series, markers at every point and a line
/// through the mean at each distinct x. Infinite y values are left out.
pub fn scatter_svg(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[(String, Vec<(f64, f64)>)],
) -> String {
    let (w, h) = (720.0, 440.0);
    let (l, r, t, b) = (70.0, 150.0, 40.0, 50.0);
    let pts = series
        .iter()
        .flat_map(|s| s.1.iter())
        .filter(|p| p.0.is_finite() && p.1.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    if x1 - x0 < 1e-9 {
        (x0, x1) = (x0 - 1.0, x1 + 1.0);
    }
    if y1 - y0 < 1e-9 {
        (y0, y1) = (y0 - 1.0, y1 + 1.0);
    }
    let (y0, y1) = (y0.floor(), y1.ceil());
    let px = |x: f64| l + (x - x0) / (x1 - x0) * (w - l - r);
    let py = |y: f64| h - b - (y - y0) / (y1 - y0) * (h - t - b);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" \
         font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n\
         <text x=\"{}\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">{title}</text>\n",
        (l + w - r) / 2.0
    );
    // Axes and ticks (5 intervals each).
    s.push_str(&format!(
        "<rect x=\"{l}\" y=\"{t}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"black\"/>\n",
        w - l - r,
        h - t - b
    ));
    for k in 0..=5 {
        let f = k as f64 / 5.0;
        let (xv, yv) = (x0 + f * (x1 - x0), y0 + f * (y1 - y0));
        s.push_str(&format!(
            "<line x1=\"{0:.1}\" y1=\"{1}\" x2=\"{0:.1}\" y2=\"{2}\" stroke=\"#ddd\"/>\
             <text x=\"{0:.1}\" y=\"{3}\" text-anchor=\"middle\">{4:.1}</text>\n",
            px(xv),
            t,
            h - b,
            h - b + 16.0,
            xv
        ));
        s.push_str(&format!(
            "<line x1=\"{l}\" y1=\"{0:.1}\" x2=\"{1}\" y2=\"{0:.1}\" stroke=\"#ddd\"/>\
             <text x=\"{2}\" y=\"{3:.1}\" text-anchor=\"end\">{4:.1}</text>\n",
            py(yv),
            w - r,
            l - 6.0,
            py(yv) + 4.0,
            yv
        ));
    }
    s.push_str(&format!(
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{x_label}</text>\n\
         <text x=\"16\" y=\"{}\" text-anchor=\"middle\" transform=\"rotate(-90 16 {})\">{y_label}</text>\n",
        (l + w - r) / 2.0,
        h - 12.0,
        (t + h - b) / 2.0,
        (t + h - b) / 2.0
    ));
    for (k, (name, points)) in series.iter().enumerate() {
        let c = COLOURS[k % COLOURS.len()];
        let mut finite: Vec<(f64, f64)> = points
            .iter()
            .copied()
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        finite.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        let mut means: Vec<(f64, f64)> = Vec::new();
        let mut i = 0;
        while i < finite.len() {
            let j = finite[i..]
                .iter()
                .take_while(|p| p.0 == finite[i].0)
                .count();
            means.push((finite[i].0, mean(finite[i..i + j].iter().map(|p| p.1))));
            i += j;
        }
        let line: Vec<String> = means
            .iter()
            .map(|&(x, y)| format!("{:.1},{:.1}", px(x), py(y)))
            .collect();
        s.push_str(&format!(
            "<polyline fill=\"none\" stroke=\"{c}\" stroke-width=\"1.5\" points=\"{}\"/>\n",
            line.join(" ")
        ));
        for &(x, y) in &finite {
            s.push_str(&format!(
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"2.5\" fill=\"{c}\"/>\n",
                px(x),
                py(y)
            ));
        }
        let ly = t + 14.0 + 18.0 * k as f64;
        s.push_str(&format!(
            "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"{c}\" stroke-width=\"3\"/>\
             <text x=\"{3}\" y=\"{4}\">{name}</text>\n",
            w - r + 10.0,
            ly,
            w - r + 34.0,
            w - r + 40.0,
            ly + 4.0
        ));
    }
    s.push_str("</svg>\n");
    s
}

fn chart_series(
    study: &TerrainStudy,
    x: impl Fn(&ViewResult) -> f64,
) -> Vec<(String, Vec<(f64, f64)>)> {
    study
        .summary
        .iter()
        .map(|s| {
            (
                s.sampler.clone(),
                study
                    .results
                    .iter()
                    .filter(|r| r.sampler == s.sampler)
                    .map(|r| (x(r), r.psnr_db))
                    .collect(),
            )
        })
        .collect()
}

/// The two charts: PSNR against pitch and against the eye's height above the ground
/// (`log10` metres).
pub fn charts(study: &TerrainStudy) -> [(String, String); 2] {
    chart_data(study).map(|(stem, title, x_label, series)| {
        (
            format!("{stem}.svg"),
            scatter_svg(title, x_label, "PSNR (dB)", &series),
        )
    })
}

/// Write `results.csv`, `results.json`, `summary.md` and the two charts (SVG and PNG) into `dir`
/// (created if missing); returns the paths written.
pub fn write_study(dir: &Path, study: &TerrainStudy) -> Result<Vec<PathBuf>, TerrainStudyError> {
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let json = serde_json::to_string_pretty(study).map_err(StudyError::Json)?;
    let mut files = vec![
        ("results.csv".to_string(), results_csv(study)),
        ("results.json".to_string(), json),
        ("summary.md".to_string(), summary_markdown(study)),
    ];
    files.extend(charts(study));
    let mut written = Vec::new();
    for (name, text) in files {
        let p = dir.join(name);
        std::fs::write(&p, text).map_err(io(&p))?;
        written.push(p);
    }
    // The same two charts as PNG, drawn with plotters.
    for (stem, title, x_label, series) in chart_data(study) {
        let p = dir.join(format!("{stem}.png"));
        crate::chart::scatter(
            title,
            x_label,
            "PSNR (dB)",
            &series,
            crate::chart::Target::Png(&p),
        )?;
        written.push(p);
    }
    Ok(written)
}

/// Stem, title, x label and series of the two charts.
#[allow(clippy::type_complexity)] // one row per chart, read once by its two writers
fn chart_data(
    study: &TerrainStudy,
) -> [(
    &'static str,
    &'static str,
    &'static str,
    Vec<(String, Vec<(f64, f64)>)>,
); 2] {
    [
        (
            "error_vs_pitch",
            "PSNR against the reference by pitch",
            "pitch (degrees)",
            chart_series(study, |r| r.place.pitch_deg),
        ),
        (
            "error_vs_altitude",
            "PSNR against the reference by height above ground",
            "log10 height above ground (m)",
            chart_series(study, |r| r.place.clearance_m.max(1e-3).log10()),
        ),
    ]
}

/// A deterministic integer hash (for the built-in photo).
fn hash(x: u32, y: u32, seed: u32) -> u32 {
    let mut h =
        x.wrapping_mul(0x9E37_79B1) ^ y.wrapping_mul(0x85EB_CA77) ^ seed.wrapping_mul(0xC2B2_AE3D);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297A_2D39);
    h ^ (h >> 15)
}

/// The built-in terrain of the demo and the tests: a `side²` grid (10 m spacing) of rolling hills
/// with a ridge, and a `photo_side²` synthetic orthophoto — fields of hashed colours, with roads
/// and field edges one texel wide and per-texel grain, so minification aliases unless filtered.
/// Chunks of at most 65 samples at 0.5 m. Deterministic; no file is read.
pub fn builtin_terrain(side: u32, photo_side: u32) -> Result<FlightTerrain, TerrainStudyError> {
    if !(17..=2049).contains(&side) || !(16..=4096).contains(&photo_side) {
        return Err(TerrainStudyError::BadOption {
            what: "built-in terrain size",
            value: format!("{side} samples, {photo_side} texels"),
        });
    }
    let n = side;
    let scale = 256.0 / (n - 1) as f32;
    let h = (0..n * n)
        .map(|i| {
            let (x, z) = ((i % n) as f32 * scale, (i / n) as f32 * scale);
            let ridge = 90.0 * (-((x - 160.0) * (x - 160.0)) / 2000.0).exp();
            120.0
                + ridge
                + 35.0 * (x / 19.0).sin() * (z / 27.0).cos()
                + 12.0 * (x / 7.0 + z / 11.0).sin()
        })
        .collect();
    let grid = Grid::new(
        "built-in hills",
        n,
        n,
        h,
        Georef::local(10.0 * scale as f64),
    )?;
    let cell = (photo_side / 16).max(4);
    let photo = image::RgbaImage::from_fn(photo_side, photo_side, |x, y| {
        let (cx, cy) = (x / cell, y / cell);
        let f = hash(cx, cy, 1);
        let base: [f32; 3] = match f % 5 {
            0 => [95.0, 140.0, 60.0],
            1 => [170.0, 160.0, 90.0],
            2 => [60.0, 100.0, 50.0],
            3 => [140.0, 110.0, 80.0],
            _ => [120.0, 150.0, 70.0],
        };
        // Furrows: stripes two texels apart in alternate fields' directions.
        let furrow = if (f >> 3).is_multiple_of(2) {
            x % 2
        } else {
            y % 2
        } as f32;
        let grain = (hash(x, y, 7) % 25) as f32 - 12.0;
        let road = x % (4 * cell) == 0 || y % (4 * cell) == 0;
        let edge = x % cell == 0 || y % cell == 0;
        let c = |i: usize| {
            if road {
                225
            } else if edge {
                40
            } else {
                (base[i] + grain + 14.0 * furrow).clamp(0.0, 255.0) as u8
            }
        };
        image::Rgba([c(0), c(1), c(2), 255])
    });
    let tree = texmap_terrain::chunks::build(&grid, 0.5, 65.min(n))?;
    Ok(FlightTerrain::new(
        grid,
        tree,
        view::texture_from_rgba(&photo)?,
    ))
}

/// The terrain section of `texmap demo`: builds [`builtin_terrain`] (129² samples, 512² photo),
/// writes a 24-frame orbit with the span 3x3 sampler (`terrain/flight.apng`, 192x144) and the
/// sampler study on the first views of each segment of the study path (160x120, 3x3 reference
/// samples) into `out_dir/terrain/`, and returns the HTML fragment that shows them (paths
/// relative to `out_dir`).
pub fn demo_section(out_dir: &Path) -> Result<String, TerrainStudyError> {
    let dir = out_dir.join("terrain");
    std::fs::create_dir_all(&dir).map_err(io(&dir))?;
    let terrain = builtin_terrain(129, 512)?;
    let grid = terrain.grid();
    let fly = FlightCamera {
        width: 192,
        height: 144,
        ..FlightCamera::over(grid)
    };
    let frames = texmap_terrain::flight::orbit(grid, &fly, 24, 0.3, 0.12, -25.0);
    let movie_path = dir.join("flight.apng");
    let mut mo = texmap_movie::MovieOptions::new(fly.width, fly.height, frames.len() as u32);
    mo.fps = 12.0;
    let mut movie = texmap_movie::MovieWriter::create(&movie_path, &mo)?;
    for v in &frames {
        let f = render_method(&terrain, v, Sampler::Span(Banks::K3), 1.0)?;
        movie.push(&f.color)?;
    }
    movie.finish()?;
    let template = FlightCamera {
        width: 160,
        height: 120,
        ..fly
    };
    let full = study_path(grid, &template);
    let mut path: Vec<PathView> = Vec::new();
    for seg in ["look-down", "low", "grazing", "turn"] {
        path.extend(full.iter().filter(|p| p.segment == seg).take(2).cloned());
    }
    path.extend(
        full.iter()
            .filter(|p| p.segment == "slow-pass")
            .take(3)
            .cloned(),
    );
    let reference = TerrainReference::new(&terrain)?;
    let opts = StudyOptions {
        samples_per_axis: 3,
        ..StudyOptions::default()
    };
    let study = run_study(&terrain, &reference, &path, &opts, &mut |_, _| {})?;
    write_study(&dir, &study)?;
    let mut html = String::from(
        "<h2>Terrain flight view (Seed 000)</h2>\n\
         <p>A built-in 129&sup2; terrain with a synthetic 512&sup2; photo, flown in an orbit with the \
         span 3x3 sampler:</p>\n<img src=\"terrain/flight.apng\" alt=\"terrain fly-through\">\n",
    );
    html.push_str(&format!(
        "<p>Every sampler against the ray-traced reference ({0}x{0} samples per pixel, texture \
         integrated over each sample's footprint) on {1} views:</p>\n<table>\n\
         <tr><th>sampler</th><th>PSNR mean (dB)</th><th>PSNR min (dB)</th><th>SSIM</th>\
         <th>blur (dB)</th><th>flicker excess</th></tr>\n",
        opts.samples_per_axis,
        path.len()
    ));
    for s in &study.summary {
        html.push_str(&format!(
            "<tr><td>{}</td><td>{:.2}</td><td>{:.2}</td><td>{:.4}</td><td>{:+.2}</td><td>{:+.3}</td></tr>\n",
            s.sampler, s.psnr_mean_db, s.psnr_min_db, s.ssim_mean, s.blur_mean_db, s.flicker_excess
        ));
    }
    let c = &study.claims;
    html.push_str(&format!(
        "</table>\n<p>Bank conflicts of the 3x3 span sampler: {} over {} spans; banks per window \
         {:.0} (4x4: {:.0}); texture memory against per-pixel copies {:.3}.</p>\n\
         <img src=\"terrain/error_vs_pitch.svg\" alt=\"PSNR by pitch\">\n\
         <img src=\"terrain/error_vs_altitude.svg\" alt=\"PSNR by height\">\n",
        c.conflicts_span3,
        c.spans_span3,
        c.banks_per_window_span3,
        c.banks_per_window_span4,
        c.memory_ratio
    ));
    Ok(html)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat plane of one colour: the reference and trilinear agree exactly (analytic: every
    /// covered pixel is the constant colour in both).
    #[test]
    fn reference_agrees_with_trilinear_on_a_constant_plane() {
        let n = 65u32;
        let grid = Grid::new(
            "flat",
            n,
            n,
            vec![50.0; (n * n) as usize],
            Georef::local(10.0),
        )
        .unwrap();
        let tree = texmap_terrain::chunks::build(&grid, 0.5, 33).unwrap();
        let photo = image::RgbaImage::from_pixel(64, 64, image::Rgba([180, 90, 40, 255]));
        let terrain = FlightTerrain::new(grid, tree, view::texture_from_rgba(&photo).unwrap());
        let v = FlightCamera {
            width: 64,
            height: 48,
            pitch_deg: -35.0,
            ..FlightCamera::over(terrain.grid())
        };
        let r = TerrainReference::new(&terrain).unwrap();
        let rf = r.render_view(&terrain, &v, 2).unwrap();
        let tf = render_method(&terrain, &v, Sampler::Trilinear, 1.0).unwrap();
        let mut compared = 0;
        for i in 0..rf.len() {
            if rf.covered(i) && tf.covered(i) {
                assert_eq!(&rf.color[i][..3], &[180, 90, 40], "reference pixel {i}");
                assert_eq!(&tf.color[i][..3], &[180, 90, 40], "trilinear pixel {i}");
                // The same plane from the same camera: the depths agree too.
                let (dr, dt) = (rf.depth[i], tf.depth[i]);
                assert!(
                    (dr - dt).abs() <= 1e-3 * dr,
                    "pixel {i}: depth {dr} vs {dt}"
                );
                compared += 1;
            }
        }
        assert!(compared > 1000, "{compared}");
    }

    /// Over a path, the 3x3 span sampler never reads outside its bank window, while the control
    /// (the window forced one level finer) does: the counter can fail.
    #[test]
    fn span3_has_no_bank_conflicts_over_a_path() {
        let terrain = builtin_terrain(65, 256).unwrap();
        let template = FlightCamera {
            width: 64,
            height: 48,
            ..FlightCamera::over(terrain.grid())
        };
        let path: Vec<PathView> = study_path(terrain.grid(), &template)
            .into_iter()
            .step_by(3)
            .collect();
        let reference = TerrainReference::new(&terrain).unwrap();
        let opts = StudyOptions {
            samples_per_axis: 1,
            samplers: vec!["trilinear".into(), "span3".into(), "span4".into()],
            ..StudyOptions::default()
        };
        let s = run_study(&terrain, &reference, &path, &opts, &mut |_, _| {}).unwrap();
        let c = &s.claims;
        assert!(c.spans_span3 > 1000, "{c:?}");
        assert_eq!(c.conflicts_span3, 0, "{c:?}");
        assert_eq!(c.conflicts_span4, 0, "{c:?}");
        assert!(c.conflicts_span3_forced_finer > 0, "{c:?}");
        assert_eq!(c.banks_per_window_span3, 9.0);
        assert_eq!(c.banks_per_window_span4, 16.0);
        assert!(c.emulator_matches_fast_path);
        assert!((c.memory_ratio - 0.25).abs() < 0.02, "{c:?}");
        assert!(
            c.level_computations_per_pixel_span3 < 0.5 * c.level_computations_per_pixel_trilinear
        );
        // The one-level-coarser window blurs: span3 is less sharp than span4.
        assert!(c.blur_span3_db.unwrap() < c.blur_span4_db.unwrap(), "{c:?}");
        let csv = results_csv(&s);
        assert_eq!(csv.lines().count(), 1 + 3 * path.len());
        for (_, svg) in charts(&s) {
            assert!(svg.starts_with("<svg") && svg.contains("span3"));
        }
    }

    #[test]
    fn demo_section_writes_its_files_and_fragment() {
        let dir = tempfile::tempdir().unwrap();
        let t0 = Instant::now();
        let html = demo_section(dir.path()).unwrap();
        eprintln!("demo_section: {:.2} s", t0.elapsed().as_secs_f64());
        for f in [
            "flight.apng",
            "error_vs_pitch.svg",
            "results.csv",
            "summary.md",
        ] {
            let p = dir.path().join("terrain").join(f);
            assert!(p.exists(), "{}", p.display());
            assert!(html.contains(f) || f.ends_with(".csv") || f.ends_with(".md"));
        }
        assert!(html.contains("<td>span3</td>") && html.contains("Bank conflicts"));
    }

    #[test]
    fn blur_ratio_sees_a_box_blur() {
        let (w, h) = (32u32, 32u32);
        let sharp: Vec<[u8; 4]> = (0..w * h)
            .map(|i| {
                if (i % w + i / w) % 2 == 0 {
                    [200; 4]
                } else {
                    [50; 4]
                }
            })
            .collect();
        let flat = vec![[125u8; 4]; (w * h) as usize];
        let depth = vec![1.0f32; (w * h) as usize];
        let a = Frame::from_parts(w, h, sharp, depth.clone()).unwrap();
        let b = Frame::from_parts(w, h, flat, depth).unwrap();
        assert_eq!(blur_ratio(&a, &a), 1.0);
        assert_eq!(blur_ratio(&b, &a), 0.0);
        assert_eq!(blur_ratio(&b, &b), 1.0);
    }
}
