//! Rendering a [`Scene`] into a [`Frame`]: primary visibility, shading with the workspace's one
//! shading model, mirror and refraction rays, stratified supersampling and the footprint-integrated
//! texture reference.
//!
//! # What a pixel holds
//! - **Colour:** the average, in linear light, of `n × n` samples at the centres of the pixel's
//!   `n × n` strata (`x = i + (a + 0.5)/n`, `y = j + (b + 0.5)/n`; `n = samples_per_axis`, a regular
//!   grid, no jitter, so the result is deterministic). Each sample is clamped to [0, 1] before
//!   averaging (as a rasteriser's resolve of stored colours does); the mean is encoded with
//!   [`linear_to_srgb8`]. Alpha is 255.
//! - **Depth and coverage:** from the single ray through the pixel centre `(i + 0.5, j + 0.5)`,
//!   exactly the ray of a 1-sample render (for odd `n` it is one of the samples). So coverage and
//!   depth match a rasteriser's pixel-centre rule whatever `n` is, and a pixel partly covered may
//!   carry a blended colour with infinite depth. Depth is `t · (dir · forward)`, the eye-space
//!   distance along the view axis; only hits with depth in the camera's `[near, far]` count.
//! - **Misses:** primary rays that hit nothing give [`RenderOptions::background`] (or the
//!   environment, with [`RenderOptions::environment_on_primary_miss`]); secondary rays that escape
//!   look up the environment function in their direction.
//!
//! # Shading
//! `Lighting::shade(material, n, v)` with `n` the unit shading normal ([`crate::Hit::shading_normal`])
//! turned to the viewer's side of the surface (surfaces are two-sided; the side is decided by the
//! geometric normal) and `v = −dir`, the unit vector toward the viewer. Meshes are flat shaded
//! unless added with a smooth [`crate::MeshShading`], which interpolates vertex normals (Phong);
//! mirror and refraction directions use the same shading normal, secondary-ray origins are
//! offset along the geometric one. Optics:
//! - [`Optics::Mirror`]: `(1 − k)·local + k·L(reflected)` with the reflection
//!   `r = d − 2 (d·n) n` (Seed 003's `E' = 2(N·E)N − E` with `E = −d`);
//! - [`Optics::Refractive`]: Snell refraction with relative index `1/ior` entering and `ior`
//!   leaving, total internal reflection when it has no solution, and optionally the exact
//!   unpolarised Fresnel reflectance mixing the two; no local shading term.
//!
//! `max_depth` is the number of secondary bounces traced: a secondary ray that would exceed it is
//! not traced but takes the environment in its direction (so `max_depth = 0` with a mirror gives
//! exactly "environment in the reflected direction", the ideal an environment map approximates).
//! Secondary rays start at the hit point offset along the normal by `SECONDARY_EPS_REL` of the
//! coordinates' magnitude.
//!
//! # Ambient occlusion, shadows and depth cueing
//! Off by default (then nothing changes). With [`RenderOptions::ambient_occlusion`], every
//! locally shaded hit scales the ambient term of the shading model by the fraction of
//! `n × n` cosine-weighted hemisphere rays around the viewer-facing geometric normal that meet
//! nothing within [`AmbientOcclusion::distance`]: one ray per stratum of the unit square
//! (`u1` gives `cos²θ`, `u2` the azimuth), jittered inside its stratum by a hash of the sample's
//! screen position and bounce, so the result is deterministic. With [`RenderOptions::shadows`]
//! the key light (the first light of the lighting) is dropped where a ray toward it meets
//! anything. With [`RenderOptions::soft_shadows`] the key light is a disc of apparent diameter
//! [`DiscLight::size_deg`] around its direction: `n × n` shadow rays, one per stratum of the unit
//! square jittered by a hash, `u1` giving the angle `θ` to the light's direction by
//! `sin²(θ/2) = u1·sin²(ρ/2)` (uniform in solid angle over the cap of angular radius `ρ`, half
//! the size) and `u2` the azimuth; the key light's term is scaled by the fraction that meets
//! nothing (the shading is a sum over lights, so this is the blend of the shading with and
//! without it). A 0° disc is the hard shadow. All these rays start at the secondary-ray origin
//! (offset along the normal) and are traced only where the geometric normal faces the light's
//! centre. [`RenderOptions::fog`] blends each primary sample's colour linearly toward a colour
//! by its depth ([`DepthCue`]); misses are not fogged.
//!
//! # Outlines
//! [`RenderOptions::outline`] draws silhouette lines by the rule of `texmap-quality`, applied to
//! every sample rather than every pixel centre: the image is traced one sample offset at a time
//! (the `n × n` offsets above), and a covered sample becomes the outline colour when a sample at
//! the same offset in a pixel within `width_px` rows and columns misses or lies deeper by more
//! than the radius of the sample's own sphere or cylinder (only misses count on triangles).
//! The pixel is the mean of its outlined and shaded samples, so the line is anti-aliased as the
//! rest of the image; with one sample per pixel it is exactly the pixel-centre rule.
//!
//! # Textures
//! A material's texture multiplies its base colour on mesh triangles that have uvs (spheres and
//! cylinders ignore it). On primary hits the texture value is the **box integral of the level-0
//! texels over the sample's exact screen footprint** (the `1/n × 1/n` pixel stratum): the stratum is
//! cut into `m × m` cells, each cell-centre ray is intersected with the hit triangle's plane, and
//! the nearest texel at that uv is averaged; `m = ⌈2·e⌉` where `e` is the longest footprint edge in
//! texels, at most 64 — at least two points per texel along each axis of the footprint. Secondary
//! hits take the nearest texel at the hit's uv.

use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;
use texmap_core::camera::{Camera, Ray};
use texmap_core::color::linear_to_srgb8;
use texmap_core::frame::Frame;
use texmap_core::optics;
use texmap_core::shade::{Lighting, Material};

use crate::error::RenderError;
use crate::geom::RayPre;
use crate::scene::{Hit, Scene, valid_ray};
use crate::texture::Texture;

/// The largest `samples_per_axis` accepted (256 samples per pixel).
pub const MAX_SAMPLES_PER_AXIS: u32 = 16;
/// The largest `max_depth` accepted.
pub const MAX_RECURSION_DEPTH: u32 = 16;
/// The largest [`AmbientOcclusion::samples_per_axis`] accepted (4096 rays per shaded point).
pub const MAX_AO_SAMPLES_PER_AXIS: u32 = 64;
/// The largest [`DiscLight::samples_per_axis`] accepted (4096 shadow rays per shaded point).
pub const MAX_SHADOW_SAMPLES_PER_AXIS: u32 = 64;
/// The largest [`DiscLight::size_deg`] accepted.
pub const MAX_LIGHT_SIZE_DEG: f32 = 30.0;
/// The widest accepted [`Outline::width_px`].
pub const MAX_OUTLINE_PX: u32 = 16;
/// Cap on the footprint-integration grid per axis.
const MAX_FOOTPRINT_GRID: u32 = 64;
/// Secondary-ray origin offset, relative to the magnitude of the coordinates involved.
const SECONDARY_EPS_REL: f32 = 8.0 * f32::EPSILON;

/// How light leaves a surface besides the local shading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Optics {
    /// Local shading only.
    Opaque,
    /// Mirror reflection mixed with local shading: `(1 − reflectance)·local + reflectance·L(r)`.
    Mirror { reflectance: f32 },
    /// A dielectric of index `ior` (outside index 1). With `fresnel`, reflection and refraction
    /// are mixed by the exact unpolarised Fresnel reflectance; without, light is only refracted
    /// (total internal reflection still reflects).
    Refractive { ior: f32, fresnel: bool },
}

/// A material as the ray tracer sees it: the shared shading model's [`Material`], optics and an
/// optional texture (index into [`RenderOptions::textures`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceMaterial {
    pub shading: Material,
    pub optics: Optics,
    pub texture: Option<u32>,
}

impl SurfaceMaterial {
    /// An opaque, untextured material.
    pub fn opaque(shading: Material) -> SurfaceMaterial {
        SurfaceMaterial {
            shading,
            optics: Optics::Opaque,
            texture: None,
        }
    }

    /// A mirror: `reflectance` 1 shows only what is reflected.
    pub fn mirror(shading: Material, reflectance: f32) -> SurfaceMaterial {
        SurfaceMaterial {
            shading,
            optics: Optics::Mirror { reflectance },
            texture: None,
        }
    }

    /// A clear dielectric of index `ior` (Fresnel-weighted reflection on).
    pub fn refractive(ior: f32) -> SurfaceMaterial {
        SurfaceMaterial {
            shading: Material::matte(Vec3::ZERO),
            optics: Optics::Refractive { ior, fresnel: true },
            texture: None,
        }
    }

    /// The same material modulated by texture `texture`.
    pub fn with_texture(mut self, texture: u32) -> SurfaceMaterial {
        self.texture = Some(texture);
        self
    }
}

/// Ambient occlusion of the reference: `samples_per_axis²` stratified rays per shaded point,
/// occluders counted within `distance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmbientOcclusion {
    pub samples_per_axis: u32,
    pub distance: f32,
}

/// The key light as a disc of apparent (angular) diameter `size_deg` around its direction, for
/// soft shadows: `samples_per_axis²` stratified shadow rays per shaded point, uniform in solid
/// angle over the disc (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscLight {
    pub samples_per_axis: u32,
    /// 0..=[`MAX_LIGHT_SIZE_DEG`]; 0 is the point light of hard shadows.
    pub size_deg: f32,
}

/// Silhouette outlines (module docs): a sample is painted `color` when a sample at the same
/// offset in a pixel at most `width_px` away (rows and columns) misses or lies deeper by more
/// than the radius of the sample's own sphere or cylinder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outline {
    /// 1..=[`MAX_OUTLINE_PX`].
    pub width_px: u32,
    /// Linear RGB.
    pub color: Vec3,
}

/// Depth cueing: a primary sample at eye-space depth `z` becomes
/// `(1 − f)·c + f·color` with `f = strength · clamp((z − start)/(end − start), 0, 1)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthCue {
    pub start: f32,
    pub end: f32,
    /// Linear RGB.
    pub color: Vec3,
    pub strength: f32,
}

/// Everything a render needs besides the scene and the camera.
#[derive(Clone, Debug)]
pub struct RenderOptions<'a> {
    pub lighting: Lighting,
    /// Indexed by the primitives' material ids.
    pub materials: &'a [SurfaceMaterial],
    /// Indexed by [`SurfaceMaterial::texture`].
    pub textures: &'a [Texture],
    /// `n` for `n × n` stratified samples per pixel, 1..=[`MAX_SAMPLES_PER_AXIS`].
    pub samples_per_axis: u32,
    /// Linear RGB colour of pixels (and samples) whose primary ray hits nothing.
    pub background: Vec3,
    /// Primary misses show the environment instead of the background.
    pub environment_on_primary_miss: bool,
    /// Secondary bounces traced, at most [`MAX_RECURSION_DEPTH`].
    pub max_depth: u32,
    /// Ambient occlusion (module docs); `None` = off.
    pub ambient_occlusion: Option<AmbientOcclusion>,
    /// Hard shadows from the key light (module docs).
    pub shadows: bool,
    /// Soft shadows from the key light as a disc (module docs); `Some` turns shadows on
    /// whatever `shadows` says.
    pub soft_shadows: Option<DiscLight>,
    /// Depth cueing of primary samples; `None` = off.
    pub fog: Option<DepthCue>,
    /// Silhouette outlines; `None` = off.
    pub outline: Option<Outline>,
}

impl<'a> RenderOptions<'a> {
    /// One sample per pixel, black background, 8 bounces, no textures.
    pub fn new(lighting: Lighting, materials: &'a [SurfaceMaterial]) -> RenderOptions<'a> {
        RenderOptions {
            lighting,
            materials,
            textures: &[],
            samples_per_axis: 1,
            background: Vec3::ZERO,
            environment_on_primary_miss: false,
            max_depth: 8,
            ambient_occlusion: None,
            shadows: false,
            soft_shadows: None,
            fog: None,
            outline: None,
        }
    }

    /// Check everything once, before tracing.
    fn validate(&self, scene: &Scene) -> Result<(), RenderError> {
        if !(1..=MAX_SAMPLES_PER_AXIS).contains(&self.samples_per_axis) {
            return Err(RenderError::BadSamples {
                samples_per_axis: self.samples_per_axis,
            });
        }
        if self.max_depth > MAX_RECURSION_DEPTH {
            return Err(RenderError::BadMaxDepth {
                max_depth: self.max_depth,
            });
        }
        if !self.background.is_finite() {
            return Err(RenderError::BadBackground);
        }
        if let Some(ao) = self.ambient_occlusion
            && !((1..=MAX_AO_SAMPLES_PER_AXIS).contains(&ao.samples_per_axis)
                && ao.distance.is_finite()
                && ao.distance > 0.0)
        {
            return Err(RenderError::BadAmbientOcclusion {
                samples_per_axis: ao.samples_per_axis,
                distance: ao.distance,
            });
        }
        if let Some(l) = self.soft_shadows
            && !((1..=MAX_SHADOW_SAMPLES_PER_AXIS).contains(&l.samples_per_axis)
                && (0.0..=MAX_LIGHT_SIZE_DEG).contains(&l.size_deg))
        {
            return Err(RenderError::BadSoftShadows {
                samples_per_axis: l.samples_per_axis,
                size_deg: l.size_deg,
            });
        }
        if let Some(o) = self.outline
            && !((1..=MAX_OUTLINE_PX).contains(&o.width_px) && o.color.is_finite())
        {
            return Err(RenderError::BadOutline {
                width_px: o.width_px,
            });
        }
        if let Some(f) = self.fog
            && !(f.start.is_finite()
                && f.end.is_finite()
                && f.end > f.start
                && (0.0..=1.0).contains(&f.strength)
                && f.color.is_finite())
        {
            return Err(RenderError::BadFog);
        }
        if let Some(m) = scene.max_material_id()
            && m as usize >= self.materials.len()
        {
            return Err(RenderError::MissingMaterial {
                material_id: m,
                materials: self.materials.len(),
            });
        }
        for (i, m) in self.materials.iter().enumerate() {
            let bad = |what| Err(RenderError::BadMaterial { material: i, what });
            let s = &m.shading;
            if !(s.base_color.is_finite() && s.specular.is_finite() && s.shininess.is_finite()) {
                return bad("shading parameters must be finite");
            }
            match m.optics {
                Optics::Opaque => {}
                Optics::Mirror { reflectance } => {
                    if !(0.0..=1.0).contains(&reflectance) {
                        return bad("mirror reflectance must be in [0, 1]");
                    }
                }
                Optics::Refractive { ior, .. } => {
                    if !(ior.is_finite() && ior > 0.0) {
                        return bad("index of refraction must be finite and positive");
                    }
                }
            }
            if let Some(t) = m.texture
                && t as usize >= self.textures.len()
            {
                return Err(RenderError::MissingTexture {
                    material: i,
                    texture: t,
                    textures: self.textures.len(),
                });
            }
        }
        Ok(())
    }
}

/// Per-render constants shared by every pixel.
struct Tracer<'a, E> {
    scene: &'a Scene,
    cam: &'a Camera,
    opts: &'a RenderOptions<'a>,
    env: &'a E,
    forward: Vec3,
}

impl Scene {
    /// Render with escaped secondary rays taking the background colour.
    ///
    /// Deterministic: the same scene, camera and options give the same bytes for any rayon thread
    /// count (every pixel is computed independently of the schedule).
    pub fn render(&self, camera: &Camera, opts: &RenderOptions) -> Result<Frame, RenderError> {
        let bg = opts.background;
        self.render_with_environment(camera, opts, &move |_d: Vec3| bg)
    }

    /// Primary visibility only (trace, no shading): the depth of the closest hit through each
    /// pixel centre, row-major, INFINITY on a miss — bit for bit the depth buffer of
    /// [`Scene::render`] at any `samples_per_axis`. Parallel over rows, deterministic.
    pub fn depth_image(&self, camera: &Camera) -> Vec<f32> {
        let (w, h) = (camera.width() as usize, camera.height() as usize);
        let forward = camera.forward();
        let mut depth = vec![f32::INFINITY; w * h];
        depth.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
            let y = j as f32 + 0.5;
            for (i, d) in row.iter_mut().enumerate() {
                *d = primary_depth(self, camera, forward, i as f32 + 0.5, y);
            }
        });
        depth
    }

    /// Render with an environment: `env(d)` is the linear RGB radiance arriving along unit
    /// direction `d` from infinity, used for secondary rays that escape (and primary misses if
    /// [`RenderOptions::environment_on_primary_miss`]). Non-finite values are taken as black.
    pub fn render_with_environment<E>(
        &self,
        camera: &Camera,
        opts: &RenderOptions,
        env: &E,
    ) -> Result<Frame, RenderError>
    where
        E: Fn(Vec3) -> Vec3 + Sync,
    {
        opts.validate(self)?;
        let tracer = Tracer {
            scene: self,
            cam: camera,
            opts,
            env,
            forward: camera.forward(),
        };
        if let Some(outline) = opts.outline {
            return Ok(tracer.render_outlined(outline));
        }
        Ok(frame_of(camera, |i, j| tracer.pixel(i as u32, j as u32)))
    }
}

/// The frame whose pixel `(i, j)` has linear colour and depth `pixel(i, j)`, encoded to sRGB8;
/// parallel over rows (each pixel depends only on its coordinates).
fn frame_of(camera: &Camera, pixel: impl Fn(usize, usize) -> (Vec3, f32) + Sync) -> Frame {
    let (w, h) = (camera.width() as usize, camera.height() as usize);
    let mut color = vec![[0u8; 4]; w * h];
    let mut depth = vec![f32::INFINITY; w * h];
    color
        .par_chunks_mut(w)
        .zip(depth.par_chunks_mut(w))
        .enumerate()
        .for_each(|(j, (crow, drow))| {
            for i in 0..w {
                let (c, d) = pixel(i, j);
                crow[i] = linear_to_srgb8(c, 255);
                drow[i] = d;
            }
        });
    Frame::from_parts(camera.width(), camera.height(), color, depth)
        .expect("buffers sized width * height")
}

impl<E: Fn(Vec3) -> Vec3 + Sync> Tracer<'_, E> {
    /// The frame with outlines: one sub-image per sample offset (colour, depth and outline gap of
    /// that sample in every pixel), the outline rule applied within each sub-image, and the
    /// outlined or shaded samples averaged per pixel; depth from the centre ray.
    fn render_outlined(&self, outline: Outline) -> Frame {
        let (w, h) = (self.cam.width() as usize, self.cam.height() as usize);
        let n = self.opts.samples_per_axis;
        let nf = n as f32;
        let half = 0.5 / nf;
        let r = outline.width_px as usize;
        let mut sum = vec![Vec3::ZERO; w * h];
        let mut sub = vec![(Vec3::ZERO, f32::INFINITY, 0f32); w * h];
        for b in 0..n {
            for a in 0..n {
                let (dx, dy) = ((a as f32 + 0.5) / nf, (b as f32 + 0.5) / nf);
                sub.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
                    for (i, out) in row.iter_mut().enumerate() {
                        *out = self.primary_sample(i as f32 + dx, j as f32 + dy, half);
                        out.0 = out.0.clamp(Vec3::ZERO, Vec3::ONE);
                    }
                });
                let sub = &sub;
                sum.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
                    for (i, acc) in row.iter_mut().enumerate() {
                        let (c, dp, gap) = sub[j * w + i];
                        let mut marked = false;
                        if dp.is_finite() {
                            'probe: for jj in j.saturating_sub(r)..=(j + r).min(h - 1) {
                                for ii in i.saturating_sub(r)..=(i + r).min(w - 1) {
                                    let dq = sub[jj * w + ii].1;
                                    if !dq.is_finite() || dq - dp > gap {
                                        marked = true;
                                        break 'probe;
                                    }
                                }
                            }
                        }
                        *acc += if marked { outline.color } else { c };
                    }
                });
            }
        }
        let inv = 1.0 / (n * n) as f32;
        frame_of(self.cam, |i, j| {
            (
                sum[j * w + i] * inv,
                self.primary_depth(i as f32 + 0.5, j as f32 + 0.5),
            )
        })
    }

    /// Linear colour (mean of the samples) and depth (centre ray) of pixel (i, j).
    fn pixel(&self, i: u32, j: u32) -> (Vec3, f32) {
        let n = self.opts.samples_per_axis;
        let nf = n as f32;
        let half = 0.5 / nf;
        let mut acc = Vec3::ZERO;
        let mut centre_depth = None;
        for b in 0..n {
            for a in 0..n {
                let x = i as f32 + (a as f32 + 0.5) / nf;
                let y = j as f32 + (b as f32 + 0.5) / nf;
                let (c, d, _) = self.primary_sample(x, y, half);
                acc += c.clamp(Vec3::ZERO, Vec3::ONE);
                if n % 2 == 1 && a == n / 2 && b == n / 2 {
                    centre_depth = Some(d);
                }
            }
        }
        let depth = match centre_depth {
            Some(d) => d,
            None => self.primary_depth(i as f32 + 0.5, j as f32 + 0.5),
        };
        (acc / (n * n) as f32, depth)
    }

    /// The primary ray through (x, y) and its parameter interval from the clip planes.
    #[inline]
    fn primary_ray(&self, x: f32, y: f32) -> (Ray, f32, f32, f32) {
        primary_ray(self.cam, self.forward, x, y)
    }

    /// Depth of the primary ray through (x, y), INFINITY on a miss.
    fn primary_depth(&self, x: f32, y: f32) -> f32 {
        primary_depth(self.scene, self.cam, self.forward, x, y)
    }

    /// One primary sample: linear colour, depth, and the depth gap beyond which a neighbour
    /// makes it an outline sample (the radius of its sphere or cylinder; infinite on a
    /// triangle, so that only misses outline meshes).
    fn primary_sample(&self, x: f32, y: f32, half: f32) -> (Vec3, f32, f32) {
        let (ray, cos, tmin, tmax) = self.primary_ray(x, y);
        let miss = || {
            let c = if self.opts.environment_on_primary_miss {
                self.env_lookup(ray.dir)
            } else {
                self.opts.background
            };
            (c, f32::INFINITY, 0.0)
        };
        if !(valid_ray(&ray) && cos > 0.0) {
            return miss();
        }
        let pre = RayPre::new(ray.origin, ray.dir);
        let Some(raw) = self.scene.closest(&pre, tmin, tmax) else {
            return miss();
        };
        let hit = self.scene.finish(&pre, &raw);
        let mat = &self.opts.materials[hit.material_id as usize];
        let tex = self.texture_value(&hit, mat, Some((x, y, half)));
        let seed = ((x.to_bits() as u64) << 32) | y.to_bits() as u64;
        let mut c = self.shade(&hit, ray.dir, mat, tex, 0, seed);
        let depth = finite_depth(raw.t * cos);
        if let Some(f) = &self.opts.fog {
            let w = ((depth - f.start) / (f.end - f.start)).clamp(0.0, 1.0) * f.strength;
            c = c * (1.0 - w) + f.color * w;
        }
        let gap = self.scene.hit_radius(&hit).unwrap_or(f32::INFINITY);
        (c, depth, gap)
    }

    /// The environment in direction `d`, never non-finite.
    #[inline]
    fn env_lookup(&self, d: Vec3) -> Vec3 {
        let c = (self.env)(d);
        if c.is_finite() { c } else { Vec3::ZERO }
    }

    /// Texture multiplier of a hit (ONE when untextured): footprint-integrated for primary
    /// samples (`footprint = (x, y, half-size)` in pixels), nearest texel otherwise.
    fn texture_value(
        &self,
        hit: &Hit,
        mat: &SurfaceMaterial,
        footprint: Option<(f32, f32, f32)>,
    ) -> Vec3 {
        let Some(ti) = mat.texture else {
            return Vec3::ONE;
        };
        let tex = &self.opts.textures[ti as usize];
        let Some((verts, uvs)) = self.scene.triangle_uv_data(hit) else {
            return Vec3::ONE;
        };
        let crate::scene::HitKind::Triangle { bary, .. } = hit.kind else {
            return Vec3::ONE;
        };
        let uv_hit = uvs[0] * (1.0 - bary.x - bary.y) + uvs[1] * bary.x + uvs[2] * bary.y;
        match footprint {
            Some((x, y, half)) => footprint_integral(self.cam, tex, &verts, &uvs, x, y, half)
                .unwrap_or_else(|| tex.nearest(uv_hit).truncate()),
            None => tex.nearest(uv_hit).truncate(),
        }
    }

    /// Outgoing radiance at a hit seen along `dir`, at bounce `depth`.
    fn shade(
        &self,
        hit: &Hit,
        dir: Vec3,
        mat: &SurfaceMaterial,
        tex: Vec3,
        depth: u32,
        seed: u64,
    ) -> Vec3 {
        let d = dir.normalize();
        // The geometric normal decides the side (and offsets secondary origins); the shading
        // normal (interpolated on smooth meshes, else the same) shades and bends rays.
        let front = hit.normal.dot(d) < 0.0;
        let ng = if front { hit.normal } else { -hit.normal };
        let ns = if front {
            hit.shading_normal
        } else {
            -hit.shading_normal
        };
        let v = -d;
        let eps = SECONDARY_EPS_REL * (1.0 + hit.point.abs().max_element() + hit.t.abs());
        let local = |m: &SurfaceMaterial| {
            let mut s = m.shading;
            s.base_color *= tex;
            let shadows = self.opts.shadows || self.opts.soft_shadows.is_some();
            if self.opts.ambient_occlusion.is_none() && !shadows {
                return self.opts.lighting.shade(&s, ns, v);
            }
            let origin = hit.point + ng * eps;
            let ao = match self.opts.ambient_occlusion {
                Some(ao) => self.ambient_visibility(origin, ng, ao, mix64(seed ^ depth as u64)),
                None => 1.0,
            };
            let mut mask = u32::MAX;
            let mut key_fraction = 1.0;
            if shadows
                && let Some(key) = self.opts.lighting.lights().first()
                && ng.dot(key.to_light) > 0.0
            {
                match self.opts.soft_shadows {
                    None => {
                        let pre = RayPre::new(origin, key.to_light);
                        if self.scene.closest(&pre, 0.0, f32::INFINITY).is_some() {
                            mask &= !1;
                        }
                    }
                    Some(disc) => {
                        key_fraction = self.disc_visibility(
                            origin,
                            key.to_light,
                            disc,
                            mix64(seed ^ depth as u64 ^ 0x5_0f75_4ad0),
                        );
                    }
                }
            }
            if key_fraction < 1.0 {
                // Lights add up: the key term scaled by the visible fraction of the disc.
                let without = self.opts.lighting.shade_with(&s, ns, v, ao, !1);
                let with = self.opts.lighting.shade_with(&s, ns, v, ao, u32::MAX);
                return without + (with - without) * key_fraction;
            }
            self.opts.lighting.shade_with(&s, ns, v, ao, mask)
        };
        let seed2 = mix64(seed.wrapping_add(0x9e37_79b9_7f4a_7c15));
        let reflect = || {
            self.secondary(
                hit.point + ng * eps,
                optics::reflect(d, ns),
                depth + 1,
                seed2,
            )
        };
        match mat.optics {
            Optics::Opaque => local(mat),
            Optics::Mirror { reflectance: k } => {
                let l = if k < 1.0 { local(mat) } else { Vec3::ZERO };
                let r = if k > 0.0 { reflect() } else { Vec3::ZERO };
                l * (1.0 - k) + r * k
            }
            Optics::Refractive { ior, fresnel } => {
                // Snell's law with relative index eta = n_from / n_to.
                let eta = if front { 1.0 / ior } else { ior };
                let Some(t) = optics::refract(d, ns, eta) else {
                    // Total internal reflection.
                    return reflect();
                };
                let refr = self.secondary(hit.point - ng * eps, t.dir, depth + 1, seed2 ^ 1);
                if !fresnel {
                    return refr;
                }
                let f = optics::fresnel_dielectric(t.cos_i, t.cos_t, eta);
                let refl = if f > 0.0 { reflect() } else { Vec3::ZERO };
                refl * f + refr * (1.0 - f)
            }
        }
    }

    /// Radiance arriving along a secondary ray (environment beyond the depth limit).
    fn secondary(&self, origin: Vec3, dir: Vec3, depth: u32, seed: u64) -> Vec3 {
        let dir = dir.normalize_or_zero();
        if depth > self.opts.max_depth || !origin.is_finite() || dir == Vec3::ZERO {
            return self.env_lookup(dir);
        }
        let pre = RayPre::new(origin, dir);
        let Some(raw) = self.scene.closest(&pre, 0.0, f32::INFINITY) else {
            return self.env_lookup(dir);
        };
        let hit = self.scene.finish(&pre, &raw);
        let mat = &self.opts.materials[hit.material_id as usize];
        let tex = self.texture_value(&hit, mat, None);
        self.shade(&hit, dir, mat, tex, depth, seed)
    }

    /// The unoccluded fraction of `ao.samples_per_axis²` stratified cosine-weighted rays
    /// around unit normal `n` from `origin` (module docs).
    fn ambient_visibility(&self, origin: Vec3, n: Vec3, ao: AmbientOcclusion, seed: u64) -> f32 {
        let (t1, t2) = tangents(n);
        let m = ao.samples_per_axis;
        let inv = 1.0 / m as f32;
        stratified_fraction(m, seed, |sa, sb| {
            let (u1, u2) = (sa * inv, sb * inv);
            let r = u1.sqrt();
            let phi = 2.0 * std::f32::consts::PI * u2;
            let dir =
                (t1 * (r * phi.cos()) + t2 * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt())
                    .normalize_or(n);
            let pre = RayPre::new(origin, dir);
            self.scene.closest(&pre, 0.0, ao.distance).is_none()
        })
    }
}

impl<E: Fn(Vec3) -> Vec3 + Sync> Tracer<'_, E> {
    /// The unoccluded fraction of `disc.samples_per_axis²` shadow rays from `origin` toward a
    /// disc light of apparent diameter `disc.size_deg` centred on unit direction `to_light`: one
    /// ray per stratum of the unit square, jittered inside it by a hash, `u1` giving
    /// `sin²(θ/2) = u1·sin²(ρ/2)` (uniform in solid angle over the cap of angular radius `ρ`),
    /// `u2` the azimuth.
    fn disc_visibility(&self, origin: Vec3, to_light: Vec3, disc: DiscLight, seed: u64) -> f32 {
        let (t1, t2) = tangents(to_light);
        let sin_half = (0.25 * disc.size_deg.to_radians()).sin();
        let m = disc.samples_per_axis;
        let inv = 1.0 / m as f32;
        stratified_fraction(m, seed, |sa, sb| {
            let sh = (sa * inv).sqrt() * sin_half;
            let phi = 2.0 * std::f32::consts::PI * sb * inv;
            let sin_t = 2.0 * sh * (1.0 - sh * sh).max(0.0).sqrt();
            // Unit to rounding; not renormalised, so a 0° disc traces `to_light` itself.
            let dir = to_light * (1.0 - 2.0 * sh * sh) + (t1 * phi.cos() + t2 * phi.sin()) * sin_t;
            let pre = RayPre::new(origin, dir);
            self.scene.closest(&pre, 0.0, f32::INFINITY).is_none()
        })
    }
}

/// Two unit vectors completing unit `n` to an orthonormal frame (any vector not parallel to `n`
/// gives one).
#[inline]
fn tangents(n: Vec3) -> (Vec3, Vec3) {
    let helper = if n.x.abs() < 0.6 { Vec3::X } else { Vec3::Y };
    let t1 = n.cross(helper).normalize();
    (t1, n.cross(t1))
}

/// The fraction of `m x m` stratified samples for which `open(a + j1, b + j2)` holds: stratum
/// `(a, b)` of the `[0, m)²` square, jittered inside it by `j1, j2 ∈ [0, 1)` from a splitmix64
/// stream seeded with `seed` (so the same bytes for any thread count).
#[inline]
fn stratified_fraction(m: u32, seed: u64, mut open: impl FnMut(f32, f32) -> bool) -> f32 {
    let mut state = seed;
    let mut count = 0u32;
    for b in 0..m {
        for a in 0..m {
            state = mix64(state.wrapping_add(0x9e37_79b9_7f4a_7c15));
            let j1 = (state >> 40) as f32 / 16_777_216.0;
            let j2 = ((state >> 16) & 0xff_ffff) as f32 / 16_777_216.0;
            if open(a as f32 + j1, b as f32 + j2) {
                count += 1;
            }
        }
    }
    count as f32 / (m * m) as f32
}

/// splitmix64's output function: a 64-bit mix of `z`.
#[inline]
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 33)).wrapping_mul(0xff51_afd7_ed55_8ccd);
    z = (z ^ (z >> 33)).wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    z ^ (z >> 33)
}

/// The primary ray through (x, y), the cosine of its angle to the view axis and its parameter
/// interval from the clip planes.
#[inline]
fn primary_ray(cam: &Camera, forward: Vec3, x: f32, y: f32) -> (Ray, f32, f32, f32) {
    let ray = cam.ray(x, y);
    let cos = ray.dir.dot(forward);
    (ray, cos, cam.near() / cos, cam.far() / cos)
}

/// Depth of the primary ray through (x, y), INFINITY on a miss.
#[inline]
fn primary_depth(scene: &Scene, cam: &Camera, forward: Vec3, x: f32, y: f32) -> f32 {
    let (ray, cos, tmin, tmax) = primary_ray(cam, forward, x, y);
    if !(valid_ray(&ray) && cos > 0.0) {
        return f32::INFINITY;
    }
    let pre = RayPre::new(ray.origin, ray.dir);
    match scene.closest(&pre, tmin, tmax) {
        Some(r) => finite_depth(r.t * cos),
        None => f32::INFINITY,
    }
}

/// A depth that is finite or INFINITY, never NaN.
#[inline]
fn finite_depth(d: f32) -> f32 {
    if d.is_finite() { d } else { f32::INFINITY }
}

/// Box integral of the level-0 texels over the screen square of half-size `half` pixels centred
/// at (x, y), mapped through the triangle's plane (see module docs). `None` when the plane is seen
/// edge-on at a corner (the caller falls back to the nearest texel).
fn footprint_integral(
    cam: &Camera,
    tex: &Texture,
    v: &[Vec3; 3],
    uv: &[Vec2; 3],
    x: f32,
    y: f32,
    half: f32,
) -> Option<Vec3> {
    // Set up the plane and the barycentric solve in f64.
    let v0 = v[0].as_dvec3();
    let e1 = v[1].as_dvec3() - v0;
    let e2 = v[2].as_dvec3() - v0;
    let n = e1.cross(e2);
    let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let den = d00 * d11 - d01 * d01;
    // Reject a degenerate triangle (den ≤ 0 or NaN).
    if den.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let (uv0, du1, du2) = (
        uv[0].as_dvec2(),
        (uv[1] - uv[0]).as_dvec2(),
        (uv[2] - uv[0]).as_dvec2(),
    );
    let uv_at = |sx: f32, sy: f32| -> Option<glam::DVec2> {
        // Intersect the ray through (sx, sy) with the triangle's plane.
        let r = cam.ray(sx, sy);
        let (o, d) = (r.origin.as_dvec3(), r.dir.as_dvec3());
        let denom = n.dot(d);
        if denom == 0.0 {
            return None;
        }
        let t = n.dot(v0 - o) / denom;
        let p: DVec3 = o + d * t - v0;
        let (p1, p2) = (p.dot(e1), p.dot(e2));
        let b1 = (d11 * p1 - d01 * p2) / den;
        let b2 = (d00 * p2 - d01 * p1) / den;
        let uv = uv0 + du1 * b1 + du2 * b2;
        uv.is_finite().then_some(uv)
    };
    // Footprint corners in texels decide the integration grid.
    let scale = glam::DVec2::new(tex.width() as f64, tex.height() as f64);
    let c00 = uv_at(x - half, y - half)? * scale;
    let c10 = uv_at(x + half, y - half)? * scale;
    let c01 = uv_at(x - half, y + half)? * scale;
    let c11 = uv_at(x + half, y + half)? * scale;
    let edge = |a: glam::DVec2, b: glam::DVec2| (a - b).abs().max_element();
    let e = edge(c00, c10)
        .max(edge(c01, c11))
        .max(edge(c00, c01))
        .max(edge(c10, c11));
    let m = ((2.0 * e).ceil() as u32).clamp(1, MAX_FOOTPRINT_GRID);
    // Midpoint rule over the m x m cells of the screen square.
    let step = 2.0 * half / m as f32;
    let mut sum = Vec3::ZERO;
    let mut count = 0u32;
    for b in 0..m {
        for a in 0..m {
            let sx = x - half + (a as f32 + 0.5) * step;
            let sy = y - half + (b as f32 + 0.5) * step;
            if let Some(u) = uv_at(sx, sy) {
                sum += tex.nearest(u.as_vec2()).truncate();
                count += 1;
            }
        }
    }
    (count > 0).then(|| sum / count as f32)
}
