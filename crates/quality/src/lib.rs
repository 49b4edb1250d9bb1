//! # texmap-quality — publication-quality sphere images at interactive cost
//!
//! Molecular-dynamics papers show their atoms anti-aliased, with ambient occlusion, shadows
//! (often soft) and an outline. This crate adds those to the exact ray-cast impostor of
//! `texmap-impostor` ([`Method::Raycast`]) while keeping most pixels at one sample:
//!
//! 1. **Primary visibility** is the impostor frame: exact depth and coverage at every pixel
//!    centre, in about a millisecond for a thousand atoms.
//! 2. **Recovery.** The crate's own ray caster (a uniform grid over the drawable spheres and
//!    bond cylinders, module `grid`) finds the primitive behind each covered pixel by
//!    intersecting the pixel-centre ray with the primitives listed in the grid cell of the
//!    impostor's surface point — one cell, not a walk — and only walks the grid where that
//!    fails. This gives the point, the normal and the material (half-bond colours included).
//! 3. **Shading** with [`Lighting::shade_with`]: the ambient term times the **ambient
//!    occlusion** (the cosine-weighted fraction of `ao_samples` hemisphere rays that travel
//!    `ao_distance` without meeting a sphere or a bond), and the key light (the first light of
//!    the [`Lighting`]) removed where a **shadow** ray toward it meets anything. The AO
//!    directions are stratified in `cos²θ`, their azimuths a golden-ratio sequence (on a table
//!    of 4096 steps) offset by a hash of the pixel coordinates and the sample index, so the
//!    noise is the same bytes for any thread count. AO rays are tested only against the
//!    primitive's neighbour list (built once per frame for the primitives seen), cut per pixel
//!    to the spheres and bonds that reach the ball of radius `ao_distance` above the surface;
//!    a shadow ray only against the one cell holding its origin in a 2D grid perpendicular to
//!    the key light. With [`SoftShadows`] the key light is a disc of a given apparent size:
//!    `samples` shadow rays per point, uniform in solid angle over the disc (stratified in
//!    `sin²(θ/2)`, golden-ratio azimuths, offsets hashed from the pixel), the key term scaled by
//!    the fraction that meets nothing; the 2D grid's cells are widened by the sideways drift of
//!    the widest ray across the scene, so one cell still lists every possible occluder. A 0°
//!    disc traces exactly the hard shadow ray, and gives the hard-shadow image byte for byte.
//!    **Depth cueing** ([`Fog`]) then blends linearly toward a colour between two eye-space
//!    depths.
//! 4. **Anti-aliasing** on edges only: a pixel whose 8 neighbours do not all show the same
//!    primitive (a silhouette against the background or against another atom, an
//!    intersection curve) or a key-light visibility within 0.25 of its own (any hard-shadow
//!    edge; a penumbra narrower than about four pixels) is traced again with `aa` samples
//!    (an `n × n` grid of strata centres when `aa` is a square, else a Hammersley set) through
//!    the grid, each shaded as above with its own shadow ray, and averaged in linear light. A
//!    sample's AO is the one found at the centre of this pixel or of a neighbour when that
//!    centre lies on the same primitive (AO changes little within a pixel); only a primitive
//!    seen at no centre nearby gets its own `ao_samples` rays. With a
//!    [`Background::Transparent`] background the edge pixel's alpha is its covered fraction.
//! 5. **Outlines** ([`Outline`]): a covered point is outlined when a point `width_px` pixels or
//!    less away along rows and columns is background or lies deeper by more than the radius of
//!    the point's primitive (QuteMol's depth-discontinuity silhouettes). With `aa` 1 the rule
//!    is applied at pixel centres, on the impostor's depths, and marked pixels are painted. With
//!    anti-aliasing it is applied to each sample offset (the offset's sub-image: sample `k` of
//!    every pixel) within `width_px + 1` pixels of a primitive change, the depths traced through
//!    the grid there (on the pixel's own primitive where its 3x3 block shows one primitive):
//!    edge pixels composite outlined and shaded samples, other pixels blend toward the outline
//!    colour by their outlined fraction in linear light, and farther pixels keep the
//!    pixel-centre rule. The reference ray tracer applies the same rule to its samples, so the
//!    outline has an error figure.
//!
//! Depth in the output is the impostor's (pixel-centre) depth. Colours are clamped to [0, 1]
//! per sample and encoded as sRGB, as the reference ray tracer does, whose AO, shadow (hard and
//! disc), fog and outline options follow the same definitions so that each setting has an
//! error figure.
//!
//! # Presets
//! | preset | aa | AO samples | shadows | outline |
//! |---|---|---|---|---|
//! | [`QualityOptions::draft`] | 1 | 0 | no | no |
//! | [`QualityOptions::good`] | 4 | 8 | yes | no |
//! | [`QualityOptions::publication`] | 16 | 32 | yes | 1 px black |
//!
//! The AO distance defaults to four times the mean sphere radius ([`ao_distance_for`]).
//!
//! # Determinism
//! Every pixel is a pure function of its coordinates and the inputs (rows in parallel with
//! rayon, fixed work per pixel, no fused multiply-add), so the bytes do not depend on the
//! thread count.
//!
//! ```
//! use texmap_core::{camera::Camera, glam::Vec3, shade::{Lighting, Material}};
//! use texmap_impostor::SphereScene;
//! use texmap_quality::{render, QualityOptions};
//!
//! let mut scene = SphereScene::new(vec![Material::plastic(Vec3::new(0.8, 0.2, 0.2))]);
//! scene.push(Vec3::ZERO, 1.0, 0);
//! scene.push(Vec3::new(1.5, 0.0, 0.0), 1.0, 0);
//! let cam = Camera::perspective_look_at(Vec3::new(0.0, 0.0, 8.0), Vec3::ZERO, Vec3::Y, 40.0, 64, 48)
//!     .unwrap();
//! let out = render(&scene, &cam, &Lighting::default_for(&cam), &QualityOptions::good()).unwrap();
//! // Only the silhouette and the intersection curve were supersampled.
//! assert!(out.stats.edge_pixels > 0 && out.stats.edge_pixels < 64 * 48 / 4);
//! // Bad options are errors, not panics.
//! let mut bad = QualityOptions::good();
//! bad.aa = 0;
//! assert!(render(&scene, &cam, &Lighting::default_for(&cam), &bad).is_err());
//! ```
//!
//! **Architecture invariant:** this crate depends on `texmap-core` and `texmap-impostor` only;
//! the reference ray tracer appears in its tests alone.

mod grid;

use glam::Vec3;
use rayon::prelude::*;
use texmap_core::camera::Camera;
use texmap_core::color::{linear_to_srgb8, srgb8_to_linear_rgb};
use texmap_core::frame::Frame;
use texmap_core::shade::{Lighting, Material};
use texmap_impostor::{Method, Options, Renderer, SphereScene};

use grid::{Grid, Hit, LightGrid, Neighbours};

/// The largest accepted `aa` (samples per edge pixel).
pub const MAX_AA: u32 = 256;
/// The largest accepted `ao_samples`.
pub const MAX_AO_SAMPLES: u32 = 4096;
/// The widest accepted outline, in pixels.
pub const MAX_OUTLINE_PX: u32 = 16;
/// The most shadow rays per shaded point with [`SoftShadows`].
pub const MAX_SOFT_SHADOW_SAMPLES: u32 = 1024;
/// The largest accepted [`SoftShadows::light_size_deg`].
pub const MAX_LIGHT_SIZE_DEG: f32 = 30.0;
/// The default apparent diameter of the key light for soft shadows, in degrees.
pub const DEFAULT_LIGHT_SIZE_DEG: f32 = 4.0;

/// What is drawn where no surface is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Background {
    /// An opaque sRGB colour.
    Color([u8; 3]),
    /// Alpha 0 (colour black); anti-aliased edges carry their covered fraction as alpha.
    Transparent,
}

/// Depth cueing: the colour blends linearly toward `color` from weight 0 at eye-space depth
/// `start` to weight `strength` at depth `end` and beyond (in linear light, per sample).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fog {
    pub start: f32,
    pub end: f32,
    /// sRGB colour.
    pub color: [u8; 3],
    /// Weight of the fog colour at `end`, in [0, 1].
    pub strength: f32,
}

impl Fog {
    /// Fog across the scene's depth as `camera` sees it: from the front of the bounding sphere of
    /// the scene's spheres to its back, strength 0.7. `None` for a scene without valid spheres.
    pub fn for_scene(scene: &SphereScene, camera: &Camera, color: [u8; 3]) -> Option<Fog> {
        let (lo, hi) = scene.bounds()?;
        let c = (lo + hi) * 0.5;
        let r = (hi - lo).length() * 0.5;
        let d = -camera.world_to_eye(c).z;
        Some(Fog {
            start: (d - r).max(0.0),
            end: d + r,
            color,
            strength: 0.7,
        })
    }

    #[inline]
    fn apply(&self, c: Vec3, depth: f32, color: Vec3) -> Vec3 {
        let f = ((depth - self.start) / (self.end - self.start)).clamp(0.0, 1.0) * self.strength;
        c * (1.0 - f) + color * f
    }
}

/// A silhouette line at depth discontinuities.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Outline {
    /// Line width in pixels, 1..=[`MAX_OUTLINE_PX`].
    pub width_px: u32,
    /// sRGB colour.
    pub color: [u8; 3],
}

/// Soft shadows: the key light is a disc of apparent diameter `light_size_deg` centred on its
/// direction, and a surface point receives the key light times the fraction of `samples`
/// shadow rays toward the disc that meet nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftShadows {
    /// Shadow rays per shaded point, 1..=[`MAX_SOFT_SHADOW_SAMPLES`].
    pub samples: u32,
    /// Apparent (angular) diameter of the light in degrees, 0..=[`MAX_LIGHT_SIZE_DEG`]; 0 is
    /// the point light of hard shadows.
    pub light_size_deg: f32,
}

/// What the quality pass adds to the ray-cast impostor image (see the crate docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QualityOptions {
    /// Samples per edge pixel, 1..=[`MAX_AA`]; 1 turns anti-aliasing off.
    pub aa: u32,
    /// Ambient-occlusion rays per pixel, 0..=[`MAX_AO_SAMPLES`]; 0 turns AO off.
    pub ao_samples: u32,
    /// How far an occluder may be (world units, finite and positive); `None` is
    /// [`ao_distance_for`] the scene.
    pub ao_distance: Option<f32>,
    /// Hard shadows from the key light (the first light of the [`Lighting`]).
    pub shadows: bool,
    /// Soft shadows from the key light as a disc; `Some` turns shadows on whatever `shadows`
    /// says.
    pub soft_shadows: Option<SoftShadows>,
    pub fog: Option<Fog>,
    pub background: Background,
    pub outline: Option<Outline>,
    /// Draw [`SphereScene::bonds`] (as the impostor's `Options::draw_bonds`).
    pub draw_bonds: bool,
}

impl QualityOptions {
    /// Nothing added: the exact ray-cast impostor image (black background).
    pub fn draft() -> QualityOptions {
        QualityOptions {
            aa: 1,
            ao_samples: 0,
            ao_distance: None,
            shadows: false,
            soft_shadows: None,
            fog: None,
            background: Background::Color([0, 0, 0]),
            outline: None,
            draw_bonds: true,
        }
    }

    /// 4 samples on edges, 8 AO rays, shadows.
    pub fn good() -> QualityOptions {
        QualityOptions {
            aa: 4,
            ao_samples: 8,
            shadows: true,
            ..QualityOptions::draft()
        }
    }

    /// 16 samples on edges, 32 AO rays, shadows and a 1-pixel black outline.
    pub fn publication() -> QualityOptions {
        QualityOptions {
            aa: 16,
            ao_samples: 32,
            shadows: true,
            outline: Some(Outline {
                width_px: 1,
                color: [0, 0, 0],
            }),
            ..QualityOptions::draft()
        }
    }

    /// A preset by name: `draft`, `good` or `publication`.
    pub fn preset(name: &str) -> Option<QualityOptions> {
        match name {
            "draft" => Some(QualityOptions::draft()),
            "good" => Some(QualityOptions::good()),
            "publication" => Some(QualityOptions::publication()),
            _ => None,
        }
    }

    /// Check every option; the first problem found is the error.
    pub fn validate(&self) -> Result<(), QualityError> {
        if !(1..=MAX_AA).contains(&self.aa) {
            return Err(QualityError::BadAa { aa: self.aa });
        }
        if self.ao_samples > MAX_AO_SAMPLES {
            return Err(QualityError::BadAoSamples {
                samples: self.ao_samples,
            });
        }
        if let Some(d) = self.ao_distance
            && !(d.is_finite() && d > 0.0)
        {
            return Err(QualityError::BadAoDistance { distance: d });
        }
        if let Some(f) = self.fog
            && !(f.start.is_finite()
                && f.end.is_finite()
                && f.end > f.start
                && (0.0..=1.0).contains(&f.strength))
        {
            return Err(QualityError::BadFog {
                start: f.start,
                end: f.end,
                strength: f.strength,
            });
        }
        if let Some(o) = self.outline
            && !(1..=MAX_OUTLINE_PX).contains(&o.width_px)
        {
            return Err(QualityError::BadOutline {
                width_px: o.width_px,
            });
        }
        if let Some(ss) = self.soft_shadows {
            if !(1..=MAX_SOFT_SHADOW_SAMPLES).contains(&ss.samples) {
                return Err(QualityError::BadSoftShadowSamples {
                    samples: ss.samples,
                });
            }
            if !(0.0..=MAX_LIGHT_SIZE_DEG).contains(&ss.light_size_deg) {
                return Err(QualityError::BadLightSize {
                    degrees: ss.light_size_deg,
                });
            }
        }
        Ok(())
    }
}

/// Why a quality render was refused.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum QualityError {
    /// `aa` is 0 or above [`MAX_AA`].
    BadAa { aa: u32 },
    /// `ao_samples` is above [`MAX_AO_SAMPLES`].
    BadAoSamples { samples: u32 },
    /// `ao_distance` is not finite and positive.
    BadAoDistance { distance: f32 },
    /// Fog depths not finite or not `start < end`, or strength outside [0, 1].
    BadFog { start: f32, end: f32, strength: f32 },
    /// Outline width 0 or above [`MAX_OUTLINE_PX`].
    BadOutline { width_px: u32 },
    /// Soft-shadow rays 0 or above [`MAX_SOFT_SHADOW_SAMPLES`].
    BadSoftShadowSamples { samples: u32 },
    /// Light size negative, above [`MAX_LIGHT_SIZE_DEG`] or not a number.
    BadLightSize { degrees: f32 },
}

impl std::fmt::Display for QualityError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            QualityError::BadAa { aa } => write!(
                f,
                "anti-aliasing: {aa} samples per pixel is not allowed (1..={MAX_AA}; 1 = off)"
            ),
            QualityError::BadAoSamples { samples } => write!(
                f,
                "ambient occlusion: {samples} samples is not allowed (0..={MAX_AO_SAMPLES}; 0 = off)"
            ),
            QualityError::BadAoDistance { distance } => write!(
                f,
                "ambient occlusion distance {distance} must be finite and positive"
            ),
            QualityError::BadFog {
                start,
                end,
                strength,
            } => write!(
                f,
                "fog from depth {start} to {end} with strength {strength}: need finite start < end and strength in [0, 1]"
            ),
            QualityError::BadOutline { width_px } => write!(
                f,
                "outline width {width_px} px is not allowed (1..={MAX_OUTLINE_PX})"
            ),
            QualityError::BadSoftShadowSamples { samples } => write!(
                f,
                "soft shadows: {samples} rays per point is not allowed (1..={MAX_SOFT_SHADOW_SAMPLES})"
            ),
            QualityError::BadLightSize { degrees } => write!(
                f,
                "light size {degrees} degrees is not allowed (0..={MAX_LIGHT_SIZE_DEG}; 0 = hard shadows)"
            ),
        }
    }
}

impl std::error::Error for QualityError {}

/// Four times the mean radius of the scene's valid spheres (1 for a scene without any): the
/// default reach of ambient occlusion, about one neighbour shell of a dense packing.
pub fn ao_distance_for(scene: &SphereScene) -> f32 {
    let mut sum = 0f64;
    let mut n = 0usize;
    for i in 0..scene.len() {
        if scene.is_valid(i) {
            sum += scene.radii[i] as f64;
            n += 1;
        }
    }
    if n == 0 {
        1.0
    } else {
        (4.0 * sum / n as f64) as f32
    }
}

/// What a quality render did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QualityStats {
    /// The impostor pass's statistics.
    pub impostor: texmap_impostor::RenderStats,
    /// Pixels traced again with `aa` samples.
    pub edge_pixels: usize,
    /// Covered pixels whose primitive was not in the grid cell of the impostor's surface point
    /// (found by a full grid walk instead).
    pub recovery_walks: usize,
    /// Covered impostor pixels the grid ray found no primitive for (kept as the impostor drew
    /// them; nonzero only for rays grazing a silhouette).
    pub recovery_misses: usize,
    /// Pixels painted, wholly or in part, by the outline.
    pub outline_pixels: usize,
}

/// A quality frame and its statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct QualityRender {
    pub frame: Frame,
    pub stats: QualityStats,
}

/// Keeps the impostor renderer's buffers between frames.
#[derive(Debug, Default)]
pub struct QualityRenderer {
    impostor: Renderer,
}

/// The primitive id of a background pixel.
const NONE: u32 = u32::MAX;
/// The id of a covered pixel the grid could not recover.
const UNKNOWN: u32 = u32::MAX - 1;

/// Everything a sample needs.
struct Ctx<'a> {
    grid: &'a Grid,
    /// The key light's 2D grid (with shadows on).
    light: Option<LightGrid>,
    /// Soft shadows: rays per point, `sin(ρ/2)` of the disc's angular radius `ρ`, and the key
    /// light's direction completed to an orthonormal frame.
    soft: Option<SoftLight>,
    /// AO occluder lists of the primitives seen at pixel centres (with AO on).
    neighbours: Option<Neighbours>,
    /// `(cos, sin)` of `2π k / AZIMUTHS`.
    azimuths: Vec<(f32, f32)>,
    cam: &'a Camera,
    forward: Vec3,
    lighting: &'a Lighting,
    materials: &'a [Material],
    ao_samples: u32,
    ao_distance: f32,
    fog: Option<(Fog, Vec3)>,
}

/// The key light as a disc (see [`Ctx::key_visibility`]).
#[derive(Clone, Copy)]
struct SoftLight {
    samples: u32,
    sin_half: f32,
    dir: Vec3,
    t1: Vec3,
    t2: Vec3,
}

/// Two neighbouring pixels whose key-light visibilities differ by more than this are an edge
/// (hard shadows: visibility 0 or 1, so any change; soft shadows: a penumbra narrower than
/// about four pixels).
const LIGHT_EDGE: f32 = 0.25;

/// Azimuth steps of the AO directions.
const AZIMUTHS: usize = 4096;
/// The most AO occluder candidates kept per pixel before falling back to grid walks.
const MAX_CANDIDATES: usize = 96;

/// `(cos, sin)` of the centres of [`AZIMUTHS`] equal steps of the circle.
fn azimuth_table() -> Vec<(f32, f32)> {
    (0..AZIMUTHS)
        .map(|k| {
            let a = std::f32::consts::TAU * (k as f32 + 0.5) / AZIMUTHS as f32;
            (a.cos(), a.sin())
        })
        .collect()
}

/// splitmix64's finaliser.
#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A uniform number in [0, 1) from the top 24 bits.
#[inline]
fn unit(h: u64) -> f32 {
    (h >> 40) as f32 * (1.0 / 16_777_216.0)
}

/// The seed of sample `sub` of pixel (i, j) (`sub` 0 = the centre pass).
#[inline]
fn seed(i: u32, j: u32, sub: u32) -> u64 {
    mix(((i as u64) | ((j as u64) << 21) | ((sub as u64) << 42)) ^ 0x5eed_0a0c_c1a5_0000)
}

/// Radical inverse in base 2 (the Hammersley set's second coordinate).
#[inline]
fn radical_inverse(k: u32) -> f32 {
    (k.reverse_bits() >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Offset in the pixel of anti-aliasing sample `k` of `n`.
#[inline]
fn aa_offset(k: u32, n: u32) -> (f32, f32) {
    let side = (n as f32).sqrt() as u32;
    if side * side == n {
        let (a, b) = (k % side, k / side);
        (
            (a as f32 + 0.5) / side as f32,
            (b as f32 + 0.5) / side as f32,
        )
    } else {
        ((k as f32 + 0.5) / n as f32, radical_inverse(k))
    }
}

/// Sphere candidates of one AO point: centres relative to the point, squared radii.
/// Kept per row of pixels and reused, so that no pixel clears it.
struct Candidates {
    x: [f32; MAX_CANDIDATES],
    y: [f32; MAX_CANDIDATES],
    z: [f32; MAX_CANDIDATES],
    r2: [f32; MAX_CANDIDATES],
    bonds: [u32; MAX_CANDIDATES],
}

impl Candidates {
    fn new() -> Box<Candidates> {
        Box::new(Candidates {
            x: [0.0; MAX_CANDIDATES],
            y: [0.0; MAX_CANDIDATES],
            z: [0.0; MAX_CANDIDATES],
            r2: [0.0; MAX_CANDIDATES],
            bonds: [0; MAX_CANDIDATES],
        })
    }

    /// Whether the segment `t·d`, `t ∈ [0, reach]` (unit `d`, from a point outside every
    /// sphere) meets any of the first `n` spheres: the near root `b − √disc` (with `b = v·d`
    /// and the cancellation-free `disc = r² − |v − b d|²`) lies in `[0, reach]`, decided
    /// without the square root. Branch-free over all `n`, so the loop runs on SIMD lanes (the
    /// same IEEE operations, so the same answer, either way).
    #[inline]
    fn any_blocks(&self, n: usize, d: Vec3, reach: f32) -> bool {
        let mut any = false;
        for k in 0..n {
            let (vx, vy, vz) = (self.x[k], self.y[k], self.z[k]);
            let b = vx * d.x + vy * d.y + vz * d.z;
            let (qx, qy, qz) = (vx - d.x * b, vy - d.y * b, vz - d.z * b);
            let disc = self.r2[k] - (qx * qx + qy * qy + qz * qz);
            let br = b - reach;
            any |= (b > 0.0) & (disc >= 0.0) & ((b <= reach) | (br * br <= disc));
        }
        any
    }
}

/// Two unit vectors completing unit `n` to an orthonormal basis (branch-free up to the sign).
#[inline]
fn basis(n: Vec3) -> (Vec3, Vec3) {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
        Vec3::new(b, s + n.y * n.y * a, -n.y),
    )
}

impl Ctx<'_> {
    /// The fraction of `count` cosine-weighted hemisphere rays from `p` (normal `n`, on
    /// primitive `prim`) that travel `ao_distance` freely. The rays are tested against the
    /// primitive's neighbour list filtered to the ball of radius `ao_distance` around `p` and
    /// the half-space above it (the only primitives they can meet), or by grid walks where
    /// there is no list; both give the same answer.
    fn ambient_visibility(
        &self,
        p: Vec3,
        n: Vec3,
        prim: u32,
        count: u32,
        seed: u64,
        cand: &mut Candidates,
    ) -> f32 {
        let (t1, t2) = basis(n);
        let h = mix(seed);
        let (r1, r2) = (unit(h), unit(h << 24));
        let reach = self.ao_distance;
        // Sphere candidates as `c − p` and `r²` (structure of arrays, so that the test below
        // runs over lanes); bond candidates by id.
        let (mut ns, mut nb) = (0usize, 0usize);
        let mut inside = false;
        let mut listed = false;
        if let Some(nbh) = &self.neighbours
            && let Some(list) = nbh.of(prim)
        {
            listed = true;
            for &j in list {
                let (c, r) = nbh.spheres[j as usize];
                let v = c - p;
                let lim = reach + r;
                let d2 = v.length_squared();
                if !(d2 < lim * lim && v.dot(n) > -r) {
                    continue;
                }
                if ns == MAX_CANDIDATES || nb == MAX_CANDIDATES {
                    listed = false;
                    break;
                }
                match self.grid.prims[j as usize] {
                    grid::Prim::Sphere { r, .. } => {
                        // A point inside another sphere is occluded in every direction.
                        inside |= d2 <= r * r;
                        cand.x[ns] = v.x;
                        cand.y[ns] = v.y;
                        cand.z[ns] = v.z;
                        cand.r2[ns] = r * r;
                        ns += 1;
                    }
                    grid::Prim::Bond { .. } => {
                        cand.bonds[nb] = j;
                        nb += 1;
                    }
                }
            }
        }
        if listed && inside {
            return 0.0;
        }
        let mut open = 0u32;
        let inv = 1.0 / count as f32;
        for k in 0..count {
            let u1 = (k as f32 + r1) * inv;
            let u2 = r2 + k as f32 * 0.618_034;
            // The fractional part (u2 ≥ 0, so truncation is floor).
            let u2 = u2 - (u2 as u32) as f32;
            let (cos, sin) = self.azimuths[((u2 * AZIMUTHS as f32) as usize).min(AZIMUTHS - 1)];
            let s = u1.sqrt();
            let dir = t1 * (s * cos) + t2 * (s * sin) + n * (1.0 - u1).max(0.0).sqrt();
            let blocked = if listed {
                cand.any_blocks(ns, dir, reach)
                    || cand.bonds[..nb].iter().any(|&j| {
                        self.grid.prims[j as usize]
                            .intersect(p, dir, 0.0, reach)
                            .is_some()
                    })
            } else {
                self.grid.occluded(p, dir, 0.0, reach)
            };
            if !blocked {
                open += 1;
            }
        }
        open as f32 * inv
    }

    /// The fraction of the key light reaching `origin` (normal `n`): 0 or 1 with hard shadows,
    /// the open fraction of the soft light's rays with soft ones, 1 where the surface faces away
    /// from the light's centre (the key term is zero there anyway) or without shadows.
    ///
    /// Soft-shadow rays sample the disc uniformly in solid angle: ray `k` of `m` makes the angle
    /// `θ` with the light's direction where `sin²(θ/2) = u·sin²(ρ/2)` (`ρ` the disc's angular
    /// radius), `u = (k + r₁)/m` stratified, and its azimuth is the golden-ratio sequence offset
    /// by `r₂`, both offsets from a hash of the pixel and sample.
    fn key_visibility(&self, origin: Vec3, n: Vec3, seed: u64) -> f32 {
        let (Some(light), Some(key)) = (&self.light, self.lighting.lights().first()) else {
            return 1.0;
        };
        let faces_light = n.dot(key.to_light) > 0.0;
        if !faces_light {
            return 1.0;
        }
        let Some(soft) = &self.soft else {
            return if light.occluded(self.grid, origin) {
                0.0
            } else {
                1.0
            };
        };
        let h = mix(seed ^ 0x50f7_5ad0_0000_0001);
        let (r1, r2) = (unit(h), unit(h << 24));
        let inv = 1.0 / soft.samples as f32;
        let open = light.open_count(self.grid, origin, soft.samples, |k| {
            let u1 = (k as f32 + r1) * inv;
            let u2 = r2 + k as f32 * 0.618_034;
            let u2 = u2 - (u2 as u32) as f32;
            let (cos, sin) = self.azimuths[((u2 * AZIMUTHS as f32) as usize).min(AZIMUTHS - 1)];
            // Half-angle form: exact for small discs, and θ = 0 (a 0° light) gives `dir` itself.
            let sh = u1.sqrt() * soft.sin_half;
            let cos_t = 1.0 - 2.0 * sh * sh;
            let sin_t = 2.0 * sh * (1.0 - sh * sh).max(0.0).sqrt();
            soft.dir * cos_t + (soft.t1 * cos + soft.t2 * sin) * sin_t
        });
        if open == soft.samples {
            1.0
        } else {
            open as f32 * inv
        }
    }

    /// Linear colour (clamped to [0, 1]) of a hit seen along unit `d`, and the fraction of the
    /// key light that reaches it ([`Ctx::key_visibility`]).
    fn shade(
        &self,
        hit: &Hit,
        d: Vec3,
        ao: Ao,
        seed: u64,
        cand: &mut Candidates,
    ) -> (Vec3, f32, f32) {
        let n = if hit.normal.dot(d) > 0.0 {
            -hit.normal
        } else {
            hit.normal
        };
        let p = hit.point;
        let eps = 32.0 * f32::EPSILON * (1.0 + p.abs().max_element() + hit.t.abs());
        let origin = p + n * eps;
        let ao = match ao {
            Ao::Trace(0) => 1.0,
            Ao::Trace(count) => self.ambient_visibility(origin, n, hit.prim, count, seed, cand),
            Ao::Known(v) => v,
        };
        let vis = self.key_visibility(origin, n, seed);
        let m = &self.materials[hit.material as usize];
        // The key term scaled by its visibility: the shading is a sum over lights, so a
        // partly visible key light is a blend of the images with and without it.
        let mut c = if vis == 1.0 {
            self.lighting.shade_with(m, n, -d, ao, u32::MAX)
        } else {
            let dark = self.lighting.shade_with(m, n, -d, ao, !1);
            if vis == 0.0 {
                dark
            } else {
                let lit = self.lighting.shade_with(m, n, -d, ao, u32::MAX);
                dark + (lit - dark) * vis
            }
        };
        if let Some((fog, color)) = &self.fog {
            let depth = hit.t * d.dot(self.forward);
            c = fog.apply(c, depth, *color);
        }
        (c.clamp(Vec3::ZERO, Vec3::ONE), vis, ao)
    }

    /// The camera ray through (x, y) and its parameter range from the clip planes; `None` when
    /// it cannot see anything.
    #[inline]
    fn ray(&self, x: f32, y: f32) -> Option<(Vec3, Vec3, f32, f32, f32)> {
        let r = self.cam.ray(x, y);
        let cos = r.dir.dot(self.forward);
        (cos > 0.0 && r.dir.is_finite()).then(|| {
            (
                r.origin,
                r.dir,
                cos,
                self.cam.near() / cos,
                self.cam.far() / cos,
            )
        })
    }

    /// A full sample at (x, y): colour and whether it hit anything.
    /// An anti-aliasing sample at (x, y): its colour, or `None` on a miss. The AO is taken
    /// from `known(primitive)` when a nearby pixel centre lies on the same primitive (AO varies
    /// little within a pixel), else traced with `ao_count` rays.
    fn sample(
        &self,
        x: f32,
        y: f32,
        ao_count: u32,
        known: impl Fn(u32) -> Option<f32>,
        seed: u64,
        cand: &mut Candidates,
    ) -> Option<Vec3> {
        let (o, d, _, tmin, tmax) = self.ray(x, y)?;
        let hit = self.grid.closest(o, d, tmin, tmax)?;
        let ao = match (ao_count, known(hit.prim)) {
            (0, _) => Ao::Trace(0),
            (_, Some(v)) => Ao::Known(v),
            (n, None) => Ao::Trace(n),
        };
        Some(self.shade(&hit, d, ao, seed, cand).0)
    }
}

/// Where a sample's ambient occlusion comes from.
#[derive(Clone, Copy)]
enum Ao {
    /// Trace this many rays (0 = AO off).
    Trace(u32),
    /// The value found at a nearby pixel centre on the same primitive.
    Known(f32),
}

/// Per-pixel result of the centre pass.
#[derive(Clone, Copy)]
struct Centre {
    color: Vec3,
    /// Ambient visibility at the centre (1 without AO).
    ao: f32,
    id: u32,
    /// Fraction of the key light reaching the centre (1 without shadows).
    lit: f32,
    /// Recovery needed a full grid walk.
    walked: bool,
}

impl QualityRenderer {
    pub fn new() -> QualityRenderer {
        QualityRenderer::default()
    }

    /// Draw `scene` as `camera` sees it under `lighting` (world space) with `options`.
    pub fn render(
        &mut self,
        scene: &SphereScene,
        camera: &Camera,
        lighting: &Lighting,
        options: &QualityOptions,
    ) -> Result<QualityRender, QualityError> {
        options.validate()?;
        let (bg_srgb, bg_alpha) = match options.background {
            Background::Color(c) => (c, 255u8),
            Background::Transparent => ([0, 0, 0], 0u8),
        };
        let bg4 = [bg_srgb[0], bg_srgb[1], bg_srgb[2], bg_alpha];
        let mut iopts = Options::new(Method::Raycast, *lighting);
        iopts.background = bg4;
        iopts.draw_bonds = options.draw_bonds;
        let base = self.impostor.render(scene, camera, &iopts);
        let mut stats = QualityStats {
            impostor: base.stats,
            ..QualityStats::default()
        };
        let mut frame = base.frame;
        let shadows = options.shadows || options.soft_shadows.is_some();
        let effects = options.ao_samples > 0 || shadows || options.fog.is_some();
        if !effects && options.aa == 1 && options.outline.is_none() {
            return Ok(QualityRender { frame, stats });
        }

        let grid = Grid::build(scene, options.draw_bonds);
        let key = lighting.lights().first().filter(|_| shadows);
        // The disc's angular radius ρ is half its apparent size.
        let rho = options
            .soft_shadows
            .map_or(0.0, |ss| (0.5 * ss.light_size_deg).to_radians());
        let light = key.map(|key| {
            let spread = if rho > 0.0 { rho.tan() } else { 0.0 };
            LightGrid::build(&grid, key.to_light, basis(key.to_light), spread)
        });
        let soft = match (key, options.soft_shadows) {
            (Some(key), Some(ss)) => {
                let (t1, t2) = basis(key.to_light);
                Some(SoftLight {
                    samples: ss.samples,
                    sin_half: (0.5 * rho).sin(),
                    dir: key.to_light,
                    t1,
                    t2,
                })
            }
            _ => None,
        };
        let mut ctx = Ctx {
            grid: &grid,
            light,
            soft,
            neighbours: None,
            azimuths: if options.ao_samples > 0 || soft.is_some() {
                azimuth_table()
            } else {
                Vec::new()
            },
            cam: camera,
            forward: camera.forward(),
            lighting,
            materials: &scene.materials,
            ao_samples: options.ao_samples,
            ao_distance: options
                .ao_distance
                .unwrap_or_else(|| ao_distance_for(scene)),
            fog: options.fog.map(|f| {
                (
                    f,
                    srgb8_to_linear_rgb([f.color[0], f.color[1], f.color[2], 255]),
                )
            }),
        };
        let (w, h) = (camera.width() as usize, camera.height() as usize);

        // 1. Centre pass: recover the primitive of every covered pixel and shade it.
        let mut centre = vec![
            Centre {
                color: Vec3::ZERO,
                ao: 1.0,
                id: NONE,
                lit: 1.0,
                walked: false,
            };
            w * h
        ];
        centre.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
            for (i, out) in row.iter_mut().enumerate() {
                let depth = frame.depth[j * w + i];
                if depth.is_finite() {
                    *out = recover(&ctx, i as u32, j as u32, depth);
                }
            }
        });
        if options.ao_samples > 0 {
            let mut seen = vec![false; grid.prims.len()];
            for c in &centre {
                if (c.id as usize) < seen.len() {
                    seen[c.id as usize] = true;
                }
            }
            ctx.neighbours = Some(Neighbours::build(&grid, &seen, ctx.ao_distance));
        }
        if effects {
            centre.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
                let mut cand = Candidates::new();
                for (i, out) in row.iter_mut().enumerate() {
                    if out.id < UNKNOWN {
                        shade_centre(&ctx, i as u32, j as u32, out, &mut cand);
                    }
                }
            });
        }
        stats.recovery_walks = centre.iter().filter(|c| c.walked).count();
        stats.recovery_misses = centre.iter().filter(|c| c.id == UNKNOWN).count();

        // 2. Edge pixels: a neighbour shows another primitive or another shadow state.
        let edge = |i: usize, j: usize| -> bool {
            let c = &centre[j * w + i];
            let (i0, i1) = (i.saturating_sub(1), (i + 1).min(w - 1));
            let (j0, j1) = (j.saturating_sub(1), (j + 1).min(h - 1));
            for jj in j0..=j1 {
                for ii in i0..=i1 {
                    let q = &centre[jj * w + ii];
                    if q.id != c.id || (q.lit - c.lit).abs() > LIGHT_EDGE {
                        return true;
                    }
                }
            }
            false
        };
        let aa = options.aa;
        let edges: Vec<bool> = (0..w * h)
            .into_par_iter()
            .with_min_len(w)
            .map(|k| aa > 1 && edge(k % w, k / w))
            .collect();

        // Outline: the pixel-centre marks, and with anti-aliasing the per-sample marks near
        // silhouettes.
        let hard_marks = options
            .outline
            .map(|o| outline_centre_marks(&grid, &centre, &frame.depth, w, h, o.width_px));
        let sample_marks = match options.outline {
            Some(o) if aa > 1 => Some(outline_sample_marks(
                &ctx, &centre, &edges, w, h, aa, o.width_px,
            )),
            _ => None,
        };
        let oc_lin = options
            .outline
            .map(|o| srgb8_to_linear_rgb([o.color[0], o.color[1], o.color[2], 255]));

        // 3. Colour: the centre sample, or `aa` samples on edges.
        let bg_lin = srgb8_to_linear_rgb(bg4);
        let ao_sub = options.ao_samples;
        let edge_counts: Vec<usize> = frame
            .color
            .par_chunks_mut(w)
            .enumerate()
            .map(|(j, row)| {
                let mut edges_here = 0;
                let mut cand = Candidates::new();
                for (i, px) in row.iter_mut().enumerate() {
                    let c = &centre[j * w + i];
                    if edges[j * w + i] {
                        edges_here += 1;
                        let mut sum = Vec3::ZERO;
                        let mut covered = 0u32;
                        // AO of the primitive at this pixel's centre, else at a neighbour's
                        // (the 3x3 block in row order).
                        let known = |prim: u32| {
                            if c.id == prim {
                                return Some(c.ao);
                            }
                            for jj in j.saturating_sub(1)..=(j + 1).min(h - 1) {
                                for ii in i.saturating_sub(1)..=(i + 1).min(w - 1) {
                                    let q = &centre[jj * w + ii];
                                    if q.id == prim {
                                        return Some(q.ao);
                                    }
                                }
                            }
                            None
                        };
                        let marked = sample_marks.as_ref().and_then(|m| m.bits_of(j * w + i));
                        for k in 0..aa {
                            if let (Some(bits), Some(oc)) = (marked, oc_lin)
                                && bits[(k / 64) as usize] & (1 << (k % 64)) != 0
                            {
                                sum += oc;
                                covered += 1;
                                continue;
                            }
                            let (dx, dy) = aa_offset(k, aa);
                            let x = i as f32 + dx;
                            let y = j as f32 + dy;
                            if let Some(col) = ctx.sample(
                                x,
                                y,
                                ao_sub,
                                known,
                                seed(i as u32, j as u32, k + 1),
                                &mut cand,
                            ) {
                                sum += col;
                                covered += 1;
                            }
                        }
                        *px = match options.background {
                            Background::Color(_) => linear_to_srgb8(
                                (sum + bg_lin * (aa - covered) as f32) / aa as f32,
                                255,
                            ),
                            Background::Transparent => {
                                if covered == 0 {
                                    [0, 0, 0, 0]
                                } else {
                                    let alpha = (255.0 * covered as f32 / aa as f32 + 0.5) as u8;
                                    linear_to_srgb8(sum / covered as f32, alpha)
                                }
                            }
                        };
                    } else if c.id == NONE {
                        *px = bg4;
                    } else if c.id != UNKNOWN && effects {
                        *px = linear_to_srgb8(c.color, 255);
                    } else {
                        px[3] = 255;
                    }
                }
                edges_here
            })
            .collect();
        stats.edge_pixels = edge_counts.iter().sum();

        // 4. Outline on the pixels not composited sample by sample above: the outline colour
        // where the centre rule marks them, or, near silhouettes with anti-aliasing, blended by
        // the fraction of their samples the rule marks (in linear light).
        if let (Some(o), Some(hard), Some(oc)) = (options.outline, &hard_marks, oc_lin) {
            let o4 = [o.color[0], o.color[1], o.color[2], 255];
            let mut painted = 0usize;
            for (k, px) in frame.color.iter_mut().enumerate() {
                match &sample_marks {
                    Some(m) if m.zone[k] => {
                        let n = m.count[k] as u32;
                        painted += (n > 0) as usize;
                        if edges[k] || n == 0 {
                            continue;
                        }
                        *px = if n == aa {
                            o4
                        } else {
                            let f = n as f32 / aa as f32;
                            let c = srgb8_to_linear_rgb(*px);
                            linear_to_srgb8(c * (1.0 - f) + oc * f, px[3])
                        };
                    }
                    _ => {
                        if hard[k] {
                            *px = o4;
                            painted += 1;
                        }
                    }
                }
            }
            stats.outline_pixels = painted;
        }
        Ok(QualityRender { frame, stats })
    }
}

/// The outline rule at pixel centres: a covered pixel is marked when a pixel within `r` rows
/// and columns is background or deeper (impostor depth) by more than the pixel's primitive
/// radius.
fn outline_centre_marks(
    grid: &Grid,
    centre: &[Centre],
    depth: &[f32],
    w: usize,
    h: usize,
    r: u32,
) -> Vec<bool> {
    let r = r as usize;
    let radius = |c: &Centre| match c.id {
        NONE | UNKNOWN => 0.0,
        id => grid.prims[id as usize].radius(),
    };
    (0..w * h)
        .into_par_iter()
        .with_min_len(w)
        .map(|k| {
            let (i, j) = (k % w, k / w);
            let dp = depth[k];
            if !dp.is_finite() {
                return false;
            }
            let gap = radius(&centre[k]);
            for jj in j.saturating_sub(r)..=(j + r).min(h - 1) {
                for ii in i.saturating_sub(r)..=(i + r).min(w - 1) {
                    let dq = depth[jj * w + ii];
                    if !dq.is_finite() || dq - dp > gap {
                        return true;
                    }
                }
            }
            false
        })
        .collect()
}

/// The outline rule applied to every anti-aliasing sample near a silhouette (see
/// [`outline_sample_marks`]).
struct SampleMarks {
    /// Pixels within `r + 1` of a primitive change, whose marks are counted per sample.
    zone: Vec<bool>,
    /// Marked samples per pixel of the zone.
    count: Vec<u16>,
    /// Per pixel, `u32::MAX` or its row in `bits` (edge pixels of the zone).
    slot: Vec<u32>,
    /// Bit `k` set: sample `k` of the pixel is marked.
    bits: Vec<[u64; 4]>,
}

impl SampleMarks {
    #[inline]
    fn bits_of(&self, k: usize) -> Option<&[u64; 4]> {
        let s = self.slot[k];
        (s != u32::MAX).then(|| &self.bits[s as usize])
    }
}

/// `flags` dilated by `r` pixels (Chebyshev distance), as two separable passes.
fn dilate(flags: &[bool], w: usize, h: usize, r: usize) -> Vec<bool> {
    let mut rows = vec![false; w * h];
    rows.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
        let src = &flags[j * w..(j + 1) * w];
        let mut last: Option<usize> = None;
        for (i, &f) in src.iter().enumerate() {
            if f {
                last = Some(i);
            }
            row[i] = last.is_some_and(|l| i - l <= r);
        }
        let mut next: Option<usize> = None;
        for i in (0..w).rev() {
            if src[i] {
                next = Some(i);
            }
            row[i] |= next.is_some_and(|n| n - i <= r);
        }
    });
    let mut out = vec![false; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
        for jj in j.saturating_sub(r)..=(j + r).min(h - 1) {
            for (o, &f) in row.iter_mut().zip(&rows[jj * w..(jj + 1) * w]) {
                *o |= f;
            }
        }
    });
    out
}

/// The outline rule of the reference applied to each anti-aliasing offset: sample `k` of a
/// pixel (at `aa_offset(k)`) is marked when it is covered and the sample at the same offset
/// of a pixel within `r` rows and columns misses or lies deeper by more than the radius of the
/// sample's primitive. Evaluated only in the zone within `r + 1` pixels of a primitive change
/// (farther away every probe shows the pixel's own primitive and the centre rule stands); a
/// sample's depth is traced through the grid in pixels next to a primitive change and taken on
/// the pixel's own primitive elsewhere.
#[allow(clippy::too_many_arguments)]
fn outline_sample_marks(
    ctx: &Ctx,
    centre: &[Centre],
    edges: &[bool],
    w: usize,
    h: usize,
    aa: u32,
    r: u32,
) -> SampleMarks {
    let r = r as usize;
    let changes: Vec<bool> = (0..w * h)
        .into_par_iter()
        .with_min_len(w)
        .map(|k| {
            let (i, j) = (k % w, k / w);
            let id = centre[k].id;
            (j.saturating_sub(1)..=(j + 1).min(h - 1)).any(|jj| {
                (i.saturating_sub(1)..=(i + 1).min(w - 1)).any(|ii| centre[jj * w + ii].id != id)
            })
        })
        .collect();
    let zone = dilate(&changes, w, h, r + 1);
    let region = dilate(&zone, w, h, r);
    let mut slot = vec![u32::MAX; w * h];
    let mut rows = 0u32;
    for k in 0..w * h {
        if zone[k] && edges[k] {
            slot[k] = rows;
            rows += 1;
        }
    }
    let mut bits = vec![[0u64; 4]; rows as usize];
    let mut count = vec![0u16; w * h];
    // (depth, gap) of the current offset's sample in every pixel of the region.
    let mut sub = vec![(f32::INFINITY, 0f32); w * h];
    for k in 0..aa {
        let (dx, dy) = aa_offset(k, aa);
        sub.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
            for (i, out) in row.iter_mut().enumerate() {
                let p = j * w + i;
                if !region[p] {
                    continue;
                }
                *out = (f32::INFINITY, 0.0);
                let id = centre[p].id;
                if id == NONE && !changes[p] {
                    continue;
                }
                let Some((o, d, cos, tmin, tmax)) = ctx.ray(i as f32 + dx, j as f32 + dy) else {
                    continue;
                };
                let own = if changes[p] || id == UNKNOWN {
                    None
                } else {
                    ctx.grid
                        .hit_on(id, &ctx.grid.prims[id as usize], o, d, tmin, tmax)
                };
                if let Some(hit) = own.or_else(|| ctx.grid.closest(o, d, tmin, tmax)) {
                    *out = (hit.t * cos, ctx.grid.prims[hit.prim as usize].radius());
                }
            }
        });
        let sub = &sub;
        let marks: Vec<bool> = (0..w * h)
            .into_par_iter()
            .with_min_len(w)
            .map(|p| {
                if !zone[p] {
                    return false;
                }
                let (i, j) = (p % w, p / w);
                let (dp, gap) = sub[p];
                if !dp.is_finite() {
                    return false;
                }
                for jj in j.saturating_sub(r)..=(j + r).min(h - 1) {
                    for ii in i.saturating_sub(r)..=(i + r).min(w - 1) {
                        let dq = sub[jj * w + ii].0;
                        if !dq.is_finite() || dq - dp > gap {
                            return true;
                        }
                    }
                }
                false
            })
            .collect();
        for (p, &m) in marks.iter().enumerate() {
            if m {
                count[p] += 1;
                if slot[p] != u32::MAX {
                    bits[slot[p] as usize][(k / 64) as usize] |= 1 << (k % 64);
                }
            }
        }
    }
    SampleMarks {
        zone,
        count,
        slot,
        bits,
    }
}

/// The primitive behind covered pixel (i, j) whose impostor depth is `depth`.
fn recover(ctx: &Ctx, i: u32, j: u32, depth: f32) -> Centre {
    let mut out = Centre {
        color: Vec3::ZERO,
        ao: 1.0,
        id: UNKNOWN,
        lit: 1.0,
        walked: false,
    };
    let Some((o, d, cos, tmin, tmax)) = ctx.ray(i as f32 + 0.5, j as f32 + 0.5) else {
        return out;
    };
    let t_est = depth / cos;
    let tol = 1e-3 * t_est.abs() + 1e-5;
    let near = ctx
        .grid
        .closest_near(o + d * t_est, o, d, tmin, tmax)
        .filter(|h| (h.t - t_est).abs() <= tol);
    let hit = match near {
        Some(h) => h,
        None => {
            out.walked = true;
            match ctx.grid.closest(o, d, tmin, tmax) {
                Some(h) => h,
                None => return out,
            }
        }
    };
    out.id = hit.prim;
    out
}

/// Shade the centre sample of pixel (i, j), whose primitive is known.
fn shade_centre(ctx: &Ctx, i: u32, j: u32, out: &mut Centre, cand: &mut Candidates) {
    let Some((o, d, _, tmin, tmax)) = ctx.ray(i as f32 + 0.5, j as f32 + 0.5) else {
        return;
    };
    let prim = &ctx.grid.prims[out.id as usize];
    if let Some(hit) = ctx.grid.hit_on(out.id, prim, o, d, tmin, tmax) {
        let (c, s, ao) = ctx.shade(&hit, d, Ao::Trace(ctx.ao_samples), seed(i, j, 0), cand);
        out.color = c;
        out.lit = s;
        out.ao = ao;
    }
}

/// One-shot [`QualityRenderer::render`].
pub fn render(
    scene: &SphereScene,
    camera: &Camera,
    lighting: &Lighting,
    options: &QualityOptions,
) -> Result<QualityRender, QualityError> {
    QualityRenderer::new().render(scene, camera, lighting, options)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aa_offsets_are_inside_the_pixel_and_distinct() {
        for n in [2u32, 4, 5, 9, 16, 17, 256] {
            let mut seen = Vec::new();
            for k in 0..n {
                let (x, y) = aa_offset(k, n);
                assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                assert!(!seen.contains(&(x, y)));
                seen.push((x, y));
            }
            // Stratified in x: the mean is the pixel centre.
            let mx: f32 = seen.iter().map(|p| p.0).sum::<f32>() / n as f32;
            assert!((mx - 0.5).abs() < 1e-5, "{n}: {mx}");
        }
    }

    #[test]
    fn neighbour_lists_give_the_grid_walks_answer() {
        use texmap_core::shade::Material;
        // A dense random cluster with bonds: AO from the candidate lists against AO from full
        // grid walks over the same directions, at points on every primitive's surface.
        let mut s = SphereScene::new(vec![Material::matte(Vec3::ONE)]);
        let mut x = 7u32;
        let mut rnd = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x as f32 / u32::MAX as f32
        };
        for _ in 0..300 {
            let c = Vec3::new(rnd(), rnd(), rnd()) * 16.0;
            s.push(c, 0.5 + 0.6 * rnd(), 0);
        }
        for k in 0..100u32 {
            s.bonds.push([k, k + 2]);
        }
        s.bond_radius = 0.2;
        let grid = Grid::build(&s, true);
        let cam = Camera::perspective_look_at(Vec3::splat(30.0), Vec3::ZERO, Vec3::Y, 40.0, 8, 8)
            .unwrap();
        let lighting = Lighting::default_for(&cam);
        let reach = 2.5;
        let mut ctx = Ctx {
            grid: &grid,
            light: None,
            soft: None,
            neighbours: None,
            azimuths: azimuth_table(),
            cam: &cam,
            forward: cam.forward(),
            lighting: &lighting,
            materials: &s.materials,
            ao_samples: 16,
            ao_distance: reach,
            fog: None,
        };
        let mut cand = Candidates::new();
        // Surface points: a ray from outside toward each primitive's centre.
        let mut points = Vec::new();
        for dir in [
            Vec3::new(0.3, 1.0, 0.2),
            Vec3::new(-1.0, 0.2, 0.4),
            Vec3::new(0.1, -0.3, -1.0),
        ] {
            for (id, p) in grid.prims.iter().enumerate() {
                let (c, _) = p.bounding_sphere();
                let o = c + dir.normalize() * 50.0;
                let d = (c - o).normalize();
                if let Some(h) = grid.closest(o, d, 0.0, f32::INFINITY)
                    && h.prim == id as u32
                {
                    let n = if h.normal.dot(d) > 0.0 {
                        -h.normal
                    } else {
                        h.normal
                    };
                    points.push((h.point + n * 1e-4, n, h.prim));
                }
            }
        }
        assert!(points.len() > 200, "{}", points.len());
        let walk: Vec<f32> = points
            .iter()
            .enumerate()
            .map(|(k, &(p, n, id))| ctx.ambient_visibility(p, n, id, 16, k as u64, &mut cand))
            .collect();
        ctx.neighbours = Some(Neighbours::build(
            &grid,
            &vec![true; grid.prims.len()],
            reach,
        ));
        let mut differ = 0;
        let mut occluded = 0;
        for (k, &(p, n, id)) in points.iter().enumerate() {
            let fast = ctx.ambient_visibility(p, n, id, 16, k as u64, &mut cand);
            differ += (fast != walk[k]) as u32;
            occluded += (walk[k] < 1.0) as u32;
        }
        eprintln!(
            "{differ} of {} points differ, {occluded} occluded",
            points.len()
        );
        // Only rays grazing a sphere may differ (two formulas for the same root).
        assert!(occluded > 100, "too little occlusion to test: {occluded}");
        assert!(
            differ * 50 <= points.len() as u32,
            "{differ} of {} differ",
            points.len()
        );
    }

    #[test]
    fn basis_is_orthonormal() {
        for n in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.5, 0.81).normalize(),
            Vec3::new(0.0, 0.0, -1.0 + 1e-7).normalize(),
        ] {
            let (a, b) = basis(n);
            assert!((a.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5);
            assert!(a.dot(b).abs() < 1e-5 && a.dot(n).abs() < 1e-5 && b.dot(n).abs() < 1e-5);
        }
    }
}
