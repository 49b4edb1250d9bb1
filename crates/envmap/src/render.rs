//! One face for every method: [`Renderer::render`]`(&scene, &camera, &options)` → [`Output`]
//! (the frame, and the time of the map update apart from the time of drawing).
//!
//! # A frame
//! 1. **Map update** ([`Output::update_ms`]): per [`Method`], a static map rebuilt only when its
//!    inputs change, or a dynamic map drawn from the objects ([`crate::maps`]). Maps are made at
//!    the target's centre. A cube map may be time-sliced ([`Options::cube_faces_per_frame`]):
//!    N of its six faces redrawn per frame, round robin, the others kept from earlier frames
//!    ([`Output::faces_updated`] says which were redrawn).
//! 2. **Drawing** ([`Output::draw_ms`]): the objects flat-lit by texmap-raster, then the target,
//!    then (optionally) the environment where nothing was drawn — last, so that early depth
//!    rejection skips every covered pixel (drawn first, the per-pixel sky cost about a third of a
//!    1024x768 frame of the tunnel). The target:
//!    - a sphere target is drawn exactly, per pixel: a sprite over its screen bounds whose quad
//!      shader intersects each pixel's ray with the sphere (depth, discard) and looks the map up;
//!    - a mesh target is drawn in two passes: its smooth normals are rasterised into a second
//!      framebuffer (Gouraud "colours" that are normals: the framebuffer stores linear `f32`, so
//!      the interpolated normal comes back unclamped), then a sprite over the mesh's screen bounds
//!      reads normal and depth per pixel and looks the map up, depth-tested against the objects;
//!    - `SphereStaticVertex` instead computes sphere-map coordinates at the vertices and lets the
//!      rasteriser interpolate them (the 1998 method, for its rim "sparkle").
//!
//! # Directions
//! The view ray `d` of a pixel and the surface normal `n` give the mirror direction
//! [`reflect`]`(d, n)` (Seed 003's `E' = 2(N·E)N − E` with `E = −d`). A refractive sphere is
//! followed exactly: refraction in ([`refract`], relative index `1/ior`), the chord through the
//! sphere, refraction out (total internal reflection reflects inside, up to
//! [`MAX_INTERNAL_BOUNCES`]), and the map is looked up in the leaving direction. A refractive mesh
//! is refracted once, at the surface seen (the 1998 "refraction mapping"). `CubeBox` replaces
//! the direction by the vector from the probe to where the ray (from the surface point, or from
//! the exit point) leaves the proxy box (Bjorke, GPU Gems ch. 19; engines' "box projection").
//!
//! # Camera roll
//! Sphere maps are made in the camera's eye frame ([`MapFrame::of_camera`]), cube and paraboloid
//! maps in the world frame; reflection directions are computed in the world frame and turned into
//! the map's frame at lookup. So nothing is folded into a model-view matrix, and a rolled camera
//! sees the reflection roll with the view (tested).

use std::time::Instant;

use glam::{Vec2, Vec3};
use texmap_core::camera::Camera;
use texmap_core::frame::Frame;
use texmap_core::optics::{reflect, refract};
use texmap_core::sample::Sampler;
use texmap_mesh::TriMesh;
use texmap_raster::{
    Cull, DrawState, Framebuffer, Mesh, MipSampler, QuadOut, Shading, Sprite, SpriteQuad,
};

use crate::address::{MapFrame, sphere_uv};
use crate::error::EnvMapError;
use crate::maps::{
    self, EnvMap, Filter, MAX_MAP_SIZE, MIN_MAP_SIZE, MapKind, MapScratch, RimPolicy, UpdateParams,
};
use crate::scene::{EnvScene, Surface, TargetShape};
use crate::shapes;

/// Internal reflections followed inside a refractive sphere before giving up (the last
/// direction is then looked up as is).
pub const MAX_INTERNAL_BOUNCES: u32 = 8;

/// The environment-mapping methods (a closed set).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Static sphere map of the environment, looked up per pixel.
    SphereStatic,
    /// Static sphere map, coordinates per vertex, interpolated (the 1998 way).
    SphereStaticVertex,
    /// Seed 003: the objects mapped into the sphere map every frame, per-pixel lookup.
    SphereDynamic,
    /// Dynamic cube map, six faces.
    Cube,
    /// The dynamic cube map looked up box-projected (parallax-corrected).
    CubeBox,
    /// Dynamic dual-paraboloid map.
    Paraboloid,
}

impl Method {
    /// Every method, in table order.
    pub const ALL: [Method; 6] = [
        Method::SphereStatic,
        Method::SphereStaticVertex,
        Method::SphereDynamic,
        Method::Cube,
        Method::CubeBox,
        Method::Paraboloid,
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Method::SphereStatic => "sphere-static",
            Method::SphereStaticVertex => "sphere-static-vertex",
            Method::SphereDynamic => "sphere-dynamic",
            Method::Cube => "cube",
            Method::CubeBox => "cube-box",
            Method::Paraboloid => "paraboloid",
        }
    }

    /// The method of a command-line name.
    pub fn from_name(name: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == name)
    }

    /// The map layout the method uses.
    pub fn map_kind(self) -> MapKind {
        match self {
            Method::SphereStatic | Method::SphereStaticVertex | Method::SphereDynamic => {
                MapKind::Sphere
            }
            Method::Cube | Method::CubeBox => MapKind::Cube,
            Method::Paraboloid => MapKind::Paraboloid,
        }
    }

    /// Whether the map holds the objects (re-rendered every frame).
    pub fn is_dynamic(self) -> bool {
        !matches!(self, Method::SphereStatic | Method::SphereStaticVertex)
    }
}

/// Everything a render needs besides the scene and the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    pub method: Method,
    /// Map side in texels ([`MIN_MAP_SIZE`]..=[`MAX_MAP_SIZE`]; cube faces without border).
    pub map_size: u32,
    pub filter: Filter,
    /// Dynamic sphere and paraboloid maps: what happens to triangles crossing the rim.
    pub rim: RimPolicy,
    /// Seed 003's option: draw into the map only triangles whose centroid is at least this far
    /// from the target's centre (0: all).
    pub min_object_distance: f32,
    /// Show the environment where nothing is drawn (else `background`).
    pub show_environment: bool,
    /// sRGB8 clear colour when the environment is not shown.
    pub background: [u8; 4],
    /// Segments of the tessellated sphere for `SphereStaticVertex` on a sphere target (rings are
    /// half as many).
    pub vertex_segments: u32,
    /// `Cube` and `CubeBox`: cube faces redrawn per frame, 1..=6 (6, the default: the whole map
    /// every frame). With fewer, the [`Renderer`] keeps its cube map and redraws N faces per
    /// frame, round robin in [`Face::ALL`](crate::address::Face::ALL) order, the others kept as
    /// they are (texels and pyramids): the update costs about N/6 of a full one, and a face may
    /// show the objects as they were up to ⌈6/N⌉ − 1 frames earlier (see [`Renderer::render`]).
    /// The other methods ignore it.
    pub cube_faces_per_frame: u32,
}

impl Options {
    /// 256² maps, trilinear, rim splitting, every object, environment shown.
    pub fn new(method: Method) -> Options {
        Options {
            method,
            map_size: 256,
            filter: Filter::Trilinear,
            rim: RimPolicy::Split,
            min_object_distance: 0.0,
            show_environment: true,
            background: [0, 0, 0, 255],
            vertex_segments: 32,
            cube_faces_per_frame: 6,
        }
    }

    fn validate(&self) -> Result<(), EnvMapError> {
        if !(MIN_MAP_SIZE..=MAX_MAP_SIZE).contains(&self.map_size) {
            return Err(EnvMapError::MapSize {
                size: self.map_size,
            });
        }
        if !(self.min_object_distance.is_finite() && self.min_object_distance >= 0.0) {
            return Err(EnvMapError::BadOption {
                what: "min_object_distance must be finite and ≥ 0",
            });
        }
        if !(1..=6).contains(&self.cube_faces_per_frame) {
            return Err(EnvMapError::FacesPerFrame {
                faces: self.cube_faces_per_frame,
            });
        }
        if !(3..=4096).contains(&self.vertex_segments) {
            return Err(EnvMapError::BadOption {
                what: "vertex_segments must be in 3..=4096",
            });
        }
        Ok(())
    }
}

/// A rendered frame and its timings.
#[derive(Clone, Debug)]
pub struct Output {
    pub frame: Frame,
    /// Wall time of the map update (0 when a cached static map was reused).
    pub update_ms: f64,
    /// Wall time of drawing the frame with the map.
    pub draw_ms: f64,
    /// Pieces of mapped triangles dropped at the singular direction (projected maps).
    pub dropped_pieces: usize,
    /// The map's faces redrawn this frame: bit `i` is [`EnvMap::faces`]`()[i]` (on a cube map,
    /// [`Face::ALL`](crate::address::Face::ALL)`[i]`). Every face of a dynamic map, N of the six
    /// on a time-sliced cube frame, 0 when a cached static map was reused.
    pub faces_updated: u8,
}

/// Holds framebuffers, the map and cached static maps across frames (create once, render many).
#[derive(Debug, Default)]
pub struct Renderer {
    fb: Option<Framebuffer>,
    gbuf: Option<Framebuffer>,
    scratch: MapScratch,
    static_map: Option<(MapKind, u32, MapFrame, Vec3, EnvMap)>,
    map: Option<EnvMap>,
    /// The `min_object_distance` the kept map was drawn with.
    map_min_distance: f32,
    /// Time-sliced cube maps: the face the next partial update starts at.
    next_face: usize,
    /// A frame handed back by [`Renderer::recycle`], resolved into by the next render.
    spare: Option<Frame>,
}

fn framebuffer(
    slot: &mut Option<Framebuffer>,
    w: u32,
    h: u32,
) -> Result<&mut Framebuffer, EnvMapError> {
    if slot
        .as_ref()
        .is_none_or(|f| f.width() != w || f.height() != h)
    {
        *slot = Some(Framebuffer::new(w, h)?);
    }
    Ok(slot.as_mut().expect("just set"))
}

/// The exit point of the ray `o + t·r` from the box `[lo, hi]` (`o` inside), if any.
#[inline]
fn box_exit(o: Vec3, r: Vec3, lo: Vec3, hi: Vec3) -> Option<Vec3> {
    if !(o.cmpgt(lo).all() && o.cmplt(hi).all()) {
        return None;
    }
    let inv = r.recip();
    let t1 = (hi - o) * inv;
    let t0 = (lo - o) * inv;
    let t = t1.max(t0).min_element();
    (t.is_finite() && t > 0.0).then(|| o + r * t)
}

/// Per-frame constants of the target's shading.
struct TargetShader<'a> {
    map: &'a EnvMap,
    surface: Surface,
    sphere: Option<(Vec3, f32)>,
    proxy: Option<(Vec3, Vec3)>,
    filter: Filter,
}

impl TargetShader<'_> {
    /// The lookup direction (world) of a surface point `p` with unit normal `n` seen along `d`.
    #[inline]
    fn direction(&self, p: Vec3, n: Vec3, d: Vec3) -> Vec3 {
        let (o, r) = match self.surface {
            Surface::Mirror => {
                let n = if n.dot(d) > 0.0 { -n } else { n };
                (p, reflect(d, n))
            }
            Surface::Refractive { ior } => self.refracted(p, n, d, ior),
        };
        match self.proxy {
            Some((lo, hi)) => match box_exit(o, r, lo, hi) {
                Some(q) => (q - self.map.centre()).normalize_or(r),
                None => r,
            },
            None => r,
        }
    }

    /// Origin and direction of the light path leaving a refractive target.
    #[inline]
    fn refracted(&self, p: Vec3, n: Vec3, d: Vec3, ior: f32) -> (Vec3, Vec3) {
        let front = n.dot(d) < 0.0;
        let (nn, eta) = if front { (n, 1.0 / ior) } else { (-n, ior) };
        let mut t = match refract(d, nn, eta) {
            Some(r) => r.dir.normalize_or(d),
            None => return (p, reflect(d, nn)),
        };
        let Some((c, radius)) = self.sphere else {
            return (p, t);
        };
        if !front {
            return (p, t);
        }
        // Follow the chord: from a point on the sphere, the far intersection along t is at
        // s = −2 t·(o − c).
        let mut o = p;
        for _ in 0..MAX_INTERNAL_BOUNCES {
            let s = -2.0 * t.dot(o - c);
            if s.is_nan() || s <= 0.0 {
                return (o, t);
            }
            let q = o + t * s;
            let n_in = -((q - c) / radius).normalize_or(t);
            match refract(t, n_in, ior) {
                Some(r) => return (q, r.dir.normalize_or(t)),
                None => {
                    t = reflect(t, n_in);
                    o = q;
                }
            }
        }
        (o, t)
    }

    /// Colours of a quad whose lanes carry (point, normal, view dir) in `geo` (lanes outside
    /// `mask` borrow a covered lane's direction for the derivatives).
    #[inline]
    fn shade(&self, geo: &[(Vec3, Vec3, Vec3); 4], mask: u8) -> [Vec3; 4] {
        let mut dirs = [Vec3::ZERO; 4];
        let first = mask.trailing_zeros() as usize;
        for l in 0..4 {
            if mask & (1 << l) != 0 {
                let (p, n, d) = geo[l];
                dirs[l] = self.direction(p, n, d);
            }
        }
        for l in 0..4 {
            if mask & (1 << l) == 0 {
                // Borrow along the quad's axis when possible (x pairs 0-1, 2-3; y pairs 0-2, 1-3).
                let cand = [l ^ 1, l ^ 2, l ^ 3, first];
                let k = cand
                    .into_iter()
                    .find(|&k| mask & (1 << k) != 0)
                    .unwrap_or(first);
                dirs[l] = dirs[k];
            }
        }
        self.map.lookup_quad(&dirs, mask, self.filter)
    }
}

/// Screen bounds of a set of world points (`None`: some point is behind the near plane, so the
/// whole screen must be covered).
fn screen_bounds(cam: &Camera, pts: impl Iterator<Item = Vec3>) -> Option<(Vec2, Vec2)> {
    let mut lo = Vec2::splat(f32::INFINITY);
    let mut hi = Vec2::splat(f32::NEG_INFINITY);
    for p in pts {
        let (s, depth) = cam.project(p)?;
        if depth.is_nan() || depth < cam.near() {
            return None;
        }
        lo = lo.min(s);
        hi = hi.max(s);
    }
    Some((lo, hi))
}

fn sprite_over(cam: &Camera, bounds: Option<(Vec2, Vec2)>, depth_min: f32) -> Sprite {
    let full = (
        Vec2::ZERO,
        Vec2::new(cam.width() as f32, cam.height() as f32),
    );
    let (lo, hi) = bounds.unwrap_or(full);
    let lo = (lo - Vec2::ONE).max(full.0);
    let hi = (hi + Vec2::ONE).min(full.1);
    Sprite {
        min: lo,
        max: hi.max(lo + Vec2::splat(1e-3)),
        depth_min: depth_min.max(0.0),
        id: 0,
    }
}

impl Renderer {
    pub fn new() -> Renderer {
        Renderer::default()
    }

    /// Hand back a frame of an earlier [`Output`] once it has been used: the next render resolves
    /// into its buffers instead of allocating new ones (a loop of frames then allocates none).
    pub fn recycle(&mut self, frame: Frame) {
        self.spare = Some(frame);
    }

    /// The map of the last frame (for display and tests).
    pub fn map(&self) -> Option<&EnvMap> {
        self.map.as_ref()
    }

    /// Render one frame (see the module docs). Errors: options out of range, or the rasteriser
    /// refusing a draw (never for scene data, which [`EnvScene::new`] validated).
    ///
    /// With [`Options::cube_faces_per_frame`] N < 6, the cube map of the last frame is kept and
    /// N of its faces are redrawn, continuing round robin from the last frame's. It is redrawn
    /// whole (and the round robin starts again at face 0) on the first frame, and whenever the
    /// kept map is not a cube map of this frame's map size, probe centre and
    /// `min_object_distance` (another method in between, a resized map, a moved target). Other
    /// changes of the scene — moving objects, another environment — reach a face when it is next
    /// redrawn: that is the trade.
    pub fn render(
        &mut self,
        scene: &EnvScene,
        cam: &Camera,
        opts: &Options,
    ) -> Result<Output, EnvMapError> {
        opts.validate()?;
        let t0 = Instant::now();
        let (map, faces_updated) = self.update_map(scene, cam, opts)?;
        let update_ms = t0.elapsed().as_secs_f64() * 1e3;
        let t1 = Instant::now();
        let frame = self.draw(scene, cam, opts, &map)?;
        let draw_ms = t1.elapsed().as_secs_f64() * 1e3;
        self.map = Some(map);
        Ok(Output {
            frame,
            update_ms,
            draw_ms,
            dropped_pieces: self.scratch.dropped_pieces,
            faces_updated,
        })
    }

    /// The frame's map and the mask of its faces redrawn.
    fn update_map(
        &mut self,
        scene: &EnvScene,
        cam: &Camera,
        opts: &Options,
    ) -> Result<(EnvMap, u8), EnvMapError> {
        let kind = opts.method.map_kind();
        let frame = match kind {
            MapKind::Sphere => MapFrame::of_camera(cam),
            MapKind::Cube | MapKind::Paraboloid => MapFrame::WORLD,
        };
        let centre = scene.centre();
        self.scratch.dropped_pieces = 0;
        if !opts.method.is_dynamic() {
            if let Some((k, s, f, c, m)) = &self.static_map
                && *k == kind
                && *s == opts.map_size
                && *f == frame
                && *c == centre
            {
                return Ok((m.clone(), 0));
            }
            let m =
                EnvMap::from_environment(kind, scene.environment(), frame, centre, opts.map_size)?;
            self.static_map = Some((kind, opts.map_size, frame, centre, m.clone()));
            return Ok((m, maps::all_faces(kind)));
        }
        let p = UpdateParams {
            objects: scene.objects(),
            lighting: scene.lighting(),
            environment: scene.environment(),
            centre,
            frame,
            size: opts.map_size,
            min_distance: opts.min_object_distance,
            rim: opts.rim,
        };
        let all = maps::all_faces(kind);
        // The last frame's map: kept by a time-sliced cube update, else its pyramids' buffers
        // are rebuilt into.
        let n = opts.cube_faces_per_frame as usize;
        let last = self.map.take();
        let keep = last.as_ref().is_some_and(|m| {
            n < 6
                && m.kind() == MapKind::Cube
                && kind == MapKind::Cube
                && m.size() == opts.map_size
                && m.frame() == frame
                && m.centre() == centre
                && self.map_min_distance == opts.min_object_distance
        });
        let kept = match last {
            Some(m) if !keep => {
                self.scratch.recycle(m);
                None
            }
            last => last,
        };
        let map = match kind {
            MapKind::Sphere => (maps::update_sphere(&p, &mut self.scratch)?, all),
            MapKind::Paraboloid => (maps::update_paraboloid(&p, &mut self.scratch)?, all),
            MapKind::Cube => {
                let faces = match kept {
                    Some(_) => (0..n).fold(0u8, |m, k| m | 1 << ((self.next_face + k) % 6)),
                    None => all,
                };
                let map = maps::update_cube_faces(&p, &mut self.scratch, faces, kept)?;
                self.next_face = if faces == all {
                    0
                } else {
                    (self.next_face + n) % 6
                };
                (map, faces)
            }
        };
        self.map_min_distance = opts.min_object_distance;
        Ok(map)
    }

    fn draw(
        &mut self,
        scene: &EnvScene,
        cam: &Camera,
        opts: &Options,
        map: &EnvMap,
    ) -> Result<Frame, EnvMapError> {
        let (w, h) = (cam.width(), cam.height());
        let fb = framebuffer(&mut self.fb, w, h)?;
        fb.clear(opts.background);
        let state = DrawState {
            cull: Cull::None,
            ..DrawState::default()
        };
        for o in scene.objects() {
            let mesh = Mesh::new(&o.mesh.positions, &o.mesh.triangles)?;
            let shading = Shading::LitFlat {
                lighting: *scene.lighting(),
                material: o.material,
            };
            fb.draw_mesh(cam, &mesh, &shading, &state)?;
        }
        let target = scene.target();
        let sphere = match target.shape {
            TargetShape::Sphere { centre, radius } => Some((centre, radius)),
            TargetShape::Mesh(_) => None,
        };
        let shader = TargetShader {
            map,
            surface: target.surface,
            sphere,
            proxy: match opts.method {
                Method::CubeBox => scene.proxy_box(),
                _ => None,
            },
            filter: opts.filter,
        };
        if opts.method == Method::SphereStaticVertex {
            let tess;
            let (mesh, normals): (&TriMesh, &[Vec3]) = match &target.shape {
                TargetShape::Sphere { centre, radius } => {
                    let s = opts.vertex_segments;
                    tess = shapes::uv_sphere(*centre, *radius, s, (s / 2).max(2));
                    (&tess, tess.normals.as_deref().unwrap_or(&[]))
                }
                TargetShape::Mesh(m) => (m, scene.target_normals()),
            };
            let frame = map.frame();
            let uvs: Vec<Vec2> = mesh
                .positions
                .iter()
                .zip(normals)
                .map(|(&p, &n)| {
                    let d = (p - cam.eye()).normalize_or(cam.forward());
                    sphere_uv(frame.to_map(shader.direction(p, n, d)))
                })
                .collect();
            let m = Mesh::new(&mesh.positions, &mesh.triangles)?.with_uvs(&uvs)?;
            let sampler = MipSampler {
                texture: &map.faces()[0],
                sampler: match opts.filter {
                    Filter::Bilinear => Sampler::Bilinear,
                    Filter::Trilinear => Sampler::Trilinear,
                },
            };
            fb.draw_textured(cam, &m, &sampler, &state)?;
            self.draw_background(scene, cam, opts)?;
            return Ok(self.resolve());
        }
        match &target.shape {
            TargetShape::Sphere { centre, radius } => {
                let (c, r) = (*centre, *radius);
                let corners = (0..8).map(|i| {
                    c + Vec3::new(
                        if i & 1 == 0 { -r } else { r },
                        if i & 2 == 0 { -r } else { r },
                        if i & 4 == 0 { -r } else { r },
                    )
                });
                let fwd = cam.forward();
                let sprite = sprite_over(
                    cam,
                    screen_bounds(cam, corners),
                    (c - cam.eye()).dot(fwd) - r,
                );
                let near = cam.near();
                let quad = |_: u32, q: &SpriteQuad| {
                    let mut geo = [(Vec3::ZERO, Vec3::Z, Vec3::NEG_Z); 4];
                    let mut depth = [f32::NAN; 4];
                    let mut mask = 0u8;
                    for l in 0..4 {
                        if q.mask & (1 << l) == 0 {
                            continue;
                        }
                        let ray = cam.ray(q.x[l], q.y[l]);
                        let d = ray.dir;
                        // Ray-sphere, pbrt's cancellation-free discriminant:
                        // disc = r² − |oc − (oc·d) d|² for unit d.
                        let oc = ray.origin - c;
                        let b = oc.dot(d);
                        let v = oc - d * b;
                        let disc = (r - v.length()) * (r + v.length());
                        if disc.is_nan() || disc < 0.0 {
                            continue;
                        }
                        let sq = disc.sqrt();
                        let t = if -b - sq > 0.0 { -b - sq } else { -b + sq };
                        let z = t * d.dot(fwd);
                        if !(t > 0.0 && z >= near) {
                            continue;
                        }
                        let p = ray.origin + d * t;
                        let n = ((p - c) / r).normalize_or(-d);
                        geo[l] = (p, n, d);
                        depth[l] = z;
                        mask |= 1 << l;
                    }
                    let color = if mask != 0 {
                        shader.shade(&geo, mask)
                    } else {
                        [Vec3::ZERO; 4]
                    };
                    QuadOut { color, depth, mask }
                };
                fb.draw_sprites(&[sprite], &quad, &DrawState::default())?;
            }
            TargetShape::Mesh(mesh) => {
                let gb = framebuffer(&mut self.gbuf, w, h)?;
                gb.clear([0, 0, 0, 255]);
                let normals = scene.target_normals();
                let m = Mesh::new(&mesh.positions, &mesh.triangles)?.with_colors(normals)?;
                gb.draw_mesh(cam, &m, &Shading::VertexColor, &state)?;
                let fwd = cam.forward();
                let bounds = screen_bounds(
                    cam,
                    mesh.positions.iter().copied().filter(|p| p.is_finite()),
                );
                let dmin = mesh
                    .positions
                    .iter()
                    .filter(|p| p.is_finite())
                    .map(|p| (*p - cam.eye()).dot(fwd))
                    .fold(f32::INFINITY, f32::min);
                let sprite = sprite_over(cam, bounds, dmin);
                let gb = &*gb;
                let quad = |_: u32, q: &SpriteQuad| {
                    let mut geo = [(Vec3::ZERO, Vec3::Z, Vec3::NEG_Z); 4];
                    let mut depth = [f32::NAN; 4];
                    let mut mask = 0u8;
                    for l in 0..4 {
                        if q.mask & (1 << l) == 0 {
                            continue;
                        }
                        let (x, y) = (q.x[l] as u32, q.y[l] as u32);
                        let Some(z) = gb.depth_at(x, y).filter(|z| z.is_finite()) else {
                            continue;
                        };
                        let ray = cam.ray(q.x[l], q.y[l]);
                        let t = z / ray.dir.dot(fwd);
                        let p = ray.origin + ray.dir * t;
                        let n = gb.color_at(x, y).unwrap_or(Vec3::Z).normalize_or(-ray.dir);
                        geo[l] = (p, n, ray.dir);
                        depth[l] = z;
                        mask |= 1 << l;
                    }
                    let color = if mask != 0 {
                        shader.shade(&geo, mask)
                    } else {
                        [Vec3::ZERO; 4]
                    };
                    QuadOut { color, depth, mask }
                };
                fb.draw_sprites(&[sprite], &quad, &DrawState::default())?;
            }
        }
        self.draw_background(scene, cam, opts)?;
        Ok(self.resolve())
    }

    /// The drawn framebuffer as a frame (into the recycled one when there is one).
    fn resolve(&mut self) -> Frame {
        let fb = self.fb.as_ref().expect("drawn");
        match self.spare.take() {
            Some(mut f) => {
                fb.resolve_into(&mut f);
                f
            }
            None => fb.to_frame(),
        }
    }

    /// The environment where nothing was drawn: a full-screen sprite drawn last, depth-tested
    /// (without writing depth) so that covered pixels are rejected before any shading.
    fn draw_background(
        &mut self,
        scene: &EnvScene,
        cam: &Camera,
        opts: &Options,
    ) -> Result<(), EnvMapError> {
        let fb = self.fb.as_mut().expect("drawn");
        let (w, h) = (cam.width(), cam.height());
        if opts.show_environment {
            let env = scene.environment();
            let bg = Sprite {
                min: Vec2::ZERO,
                max: Vec2::new(w as f32, h as f32),
                // Everything drawn is nearer: early depth rejection skips covered pixels.
                depth_min: f32::MAX,
                id: 0,
            };
            let shader = |_: u32, q: &SpriteQuad| QuadOut {
                color: std::array::from_fn(|l| env.radiance(cam.ray(q.x[l], q.y[l]).dir)),
                depth: [f32::MAX; 4],
                mask: q.mask,
            };
            let state = DrawState {
                depth_write: false,
                ..DrawState::default()
            };
            fb.draw_sprites(&[bg], &shader, &state)?;
        }
        Ok(())
    }
}
