//! Models on the terrain: textured OBJ/glTF meshes placed in the grid's georeference, and a
//! built-in tree billboard, both drawn into the flight view's [`Framebuffer`] after the terrain.
//!
//! **Models** ([`Model`], [`Placed`]). A model is one mesh (every mesh of the file merged) read
//! by texmap-mesh ([`texmap_mesh::read_obj`], [`texmap_mesh::read_gltf`]) in the model's own
//! units, `y` up, `−z` its front (north at heading 0). Its texture is the OBJ material's
//! base-colour map (`map_Kd` of the first material library named by `mtllib` that has one) or the
//! glTF material's base-colour texture (of the first primitive with a material, times its base
//! colour factor; [`texmap_mesh::read_gltf_base_color`]), read as sRGB into a gamma-correct,
//! repeating [`MipTexture`]. A model without a textured material and a mesh without texture
//! coordinates are drawn with one flat colour ([`Model::color`]: a glTF material's base colour
//! factor, otherwise grey). A [`Placement`] puts the model at a map position `(x, y)` of the grid's
//! georeference ([`crate::dem::Georef::sample_xy`]) with its lowest vertex
//! `height_above_ground` metres above the ground under `(x, y)` ([`crate::view::ground_height`]),
//! turned `heading` degrees clockwise seen from above (the model's `−z` then points along the
//! heading) and scaled uniformly. [`draw_models`] culls placed models whose bounding sphere lies
//! outside the view frustum and draws the others with [`Framebuffer::draw_textured`] and a
//! [`MipSampler`] — the terrain's sampler kind — depth-tested against what is already in the
//! framebuffer, both faces drawn (files do not promise a consistent winding).
//!
//! **Trees** ([`TreeBillboard`], [`PlacedTree`]). The billboard is a procedurally generated RGBA
//! image (a conifer: brown trunk, green crown with a hashed texture, alpha 0 around it) standing
//! on the ground as a vertical quad turned about the vertical toward the eye (a cylindrical
//! billboard: it stays upright whatever the camera's pitch). [`draw_trees`] sends one
//! [`Sprite`] per tree (the screen box of the quad's four projected corners) through
//! [`Framebuffer::draw_sprites`]; its [`QuadShader`] intersects each pixel's eye ray with the
//! quad's plane, samples the tree texture there with the same texmap-core [`Sampler`] (the
//! rasteriser's 2x2 quad supplies the derivatives), discards texels with alpha below ½ and
//! outside the quad, and writes the plane's eye-space depth, so terrain and models in front
//! hide it and it hides what lies behind. [`forest`] scatters trees deterministically by a hash
//! over the grid on cells whose four samples all hold data.
//!
//! Counts of models and trees drawn and culled and of model triangles submitted are returned in
//! [`ModelStats`]. Drawing is deterministic for any thread count (the rasteriser's guarantee;
//! every placement is computed sequentially).
//!
//! ```
//! use texmap_raster::Framebuffer;
//! use texmap_terrain::chunks;
//! use texmap_terrain::dem::{Georef, Grid};
//! use texmap_terrain::models::{self, Model, Placement, Tree, TreeBillboard};
//! use texmap_terrain::view::{self, FlightCamera, FlightTerrain, FrameScratch, ViewOptions};
//! use texmap_mesh::TriMesh;
//! use glam::Vec3;
//!
//! let n = 65u32;
//! let grid = Grid::new("flat", n, n, vec![100.0; (n * n) as usize], Georef::local(10.0))?;
//! let tree = chunks::build(&grid, 0.5, 33)?;
//! let photo = image::RgbaImage::from_pixel(64, 64, image::Rgba([80, 120, 60, 255]));
//! let terrain = FlightTerrain::new(grid, tree, view::texture_from_rgba(&photo)?);
//!
//! // A 20 m cube without texture (drawn flat), 260 m north of the centre, 45° heading.
//! let p: Vec<Vec3> = (0..8).map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32)).collect();
//! let t = vec![[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]];
//! let cube = Model::from_mesh("cube", TriMesh::new(p, t)?, None)?;
//! let at = Placement { x: 320.0, y: -60.0, heading_deg: 45.0, scale: 20.0, ..Placement::default() };
//! let placed = models::Placed::new(&cube, terrain.grid(), &at)?;
//! let trees = models::place_trees(terrain.grid(), &models::forest(terrain.grid(), 50, 7))?;
//!
//! let eye = FlightCamera { width: 160, height: 120, ..FlightCamera::over(terrain.grid()) };
//! let opts = ViewOptions::default();
//! let mut fb = Framebuffer::new(160, 120)?;
//! terrain.render(&eye, &opts, &mut fb, &mut FrameScratch::default())?;
//! let cam = eye.camera(terrain.grid())?;
//! let ms = models::draw_models(&cam, &[placed], opts.sampler, &mut fb)?;
//! let ts = models::draw_trees(&cam, &trees, &TreeBillboard::new(), opts.sampler, &mut fb)?;
//! assert_eq!(ms.models_drawn, 1);
//! assert_eq!(ms.model_triangles, 12);
//! assert!(ts.trees_drawn > 0);
//!
//! // Bad input is an error naming the value.
//! let bad = Placement { scale: 0.0, ..at };
//! assert!(models::Placed::new(&cube, terrain.grid(), &bad).unwrap_err().to_string().contains("scale"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Vec2, Vec3, Vec4};
use texmap_core::camera::Camera;
use texmap_core::mip::{MipError, MipTexture, Reduction, Wrap};
use texmap_core::sample::Sampler;
use texmap_mesh::{MeshError, TriMesh};
use texmap_raster::{
    Cull, DrawState, Framebuffer, Mesh, MipSampler, QuadOut, QuadShader, RasterError, Shading,
    Sprite, SpriteQuad,
};

use crate::dem::Grid;
use crate::view::ground_height;

/// Why a model or a tree could not be loaded, placed or drawn.
#[derive(Debug)]
#[non_exhaustive]
pub enum ModelError {
    /// The mesh file could not be read (the error names the file).
    Mesh(MeshError),
    /// The file name has no extension the readers know (`.obj`, `.gltf`, `.glb`).
    UnknownFormat {
        path: PathBuf,
    },
    /// A material library or texture image named by the model could not be read or decoded.
    Texture {
        model: String,
        path: PathBuf,
        message: String,
    },
    /// A vertex of the model is NaN or infinite.
    NonFiniteVertex {
        model: String,
        vertex: usize,
    },
    /// A placement or tree value outside its range (`what` names the model or tree).
    BadValue {
        what: String,
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    /// A placement's map position lies outside the grid.
    Outside {
        what: String,
        x: f64,
        y: f64,
        col: f64,
        row: f64,
        width: u32,
        height: u32,
    },
    /// There is no ground (only no-data samples) under a placement.
    NoGround {
        what: String,
        x: f64,
        y: f64,
    },
    Raster(RasterError),
    Mip(MipError),
}

impl std::fmt::Display for ModelError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ModelError::Mesh(e) => write!(f, "model: {e}"),
            ModelError::UnknownFormat { path } => write!(
                f,
                "model {}: unknown format (expected a .obj, .gltf or .glb file)",
                path.display()
            ),
            ModelError::Texture {
                model,
                path,
                message,
            } => write!(f, "model {model}: texture {}: {message}", path.display()),
            ModelError::NonFiniteVertex { model, vertex } => {
                write!(f, "model {model}: vertex {vertex} is not finite")
            }
            ModelError::BadValue {
                what,
                name,
                value,
                expected,
            } => write!(f, "{what}: {name} = {value}, expected {expected}"),
            ModelError::Outside {
                what,
                x,
                y,
                col,
                row,
                width,
                height,
            } => write!(
                f,
                "{what}: position ({x}, {y}) is at sample ({col:.2}, {row:.2}), outside the \
                 {width} x {height} grid"
            ),
            ModelError::NoGround { what, x, y } => {
                write!(f, "{what}: no ground under ({x}, {y}) (no-data samples)")
            }
            ModelError::Raster(e) => write!(f, "models: {e}"),
            ModelError::Mip(e) => write!(f, "models: texture: {e}"),
        }
    }
}

impl std::error::Error for ModelError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ModelError::Mesh(e) => Some(e),
            ModelError::Raster(e) => Some(e),
            ModelError::Mip(e) => Some(e),
            _ => None,
        }
    }
}

impl From<RasterError> for ModelError {
    fn from(e: RasterError) -> Self {
        ModelError::Raster(e)
    }
}

/// A model ready to be placed: its merged mesh in model units and its texture, if any.
#[derive(Clone, Debug)]
pub struct Model {
    /// The file name (or the name given to [`Model::from_mesh`]), used in errors.
    pub name: String,
    pub mesh: TriMesh,
    /// The base-colour texture (gamma-correct, repeating), when the file names one.
    pub texture: Option<Arc<MipTexture>>,
    /// Linear RGB used when the model has no texture or no texture coordinates.
    pub color: Vec3,
}

/// The flat colour of untextured models: a light grey (linear 0.5).
pub const DEFAULT_MODEL_COLOR: Vec3 = Vec3::splat(0.5);

impl Model {
    /// Read a model file: `.obj` (with its `map_Kd` texture, see the module docs), `.gltf` or
    /// `.glb` (drawn with the flat colour). Errors name the file.
    pub fn load(path: impl AsRef<Path>) -> Result<Model, ModelError> {
        let path = path.as_ref();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let name = path.display().to_string();
        let mut color = DEFAULT_MODEL_COLOR;
        let (meshes, texture) = match ext.as_deref() {
            Some("obj") => {
                let meshes = texmap_mesh::read_obj(path).map_err(ModelError::Mesh)?;
                (meshes, obj_texture(path)?)
            }
            Some("gltf") | Some("glb") => {
                let meshes = texmap_mesh::read_gltf(path).map_err(ModelError::Mesh)?;
                let bc = texmap_mesh::read_gltf_base_color(path).map_err(ModelError::Mesh)?;
                let texture = match bc {
                    // The meshes carry TEXCOORD_0 only: a texture on another set is not drawn.
                    Some(b) if b.tex_coord == 0 && b.texture.is_some() => {
                        let img = b.texture.expect("checked above");
                        Some(gltf_texture(&img, b.factor).map_err(ModelError::Mip)?)
                    }
                    Some(b) => {
                        color = Vec3::new(b.factor[0], b.factor[1], b.factor[2]);
                        None
                    }
                    None => None,
                };
                (meshes, texture)
            }
            _ => {
                return Err(ModelError::UnknownFormat {
                    path: path.to_path_buf(),
                });
            }
        };
        let mut merged = TriMesh::default();
        let all_uvs = meshes.iter().all(|m| m.uvs.is_some());
        let mut uvs = Vec::new();
        for m in meshes {
            let base = merged.positions.len() as u32;
            merged.positions.extend_from_slice(&m.positions);
            merged
                .triangles
                .extend(m.triangles.iter().map(|t| t.map(|i| i + base)));
            if let Some(u) = &m.uvs {
                uvs.extend_from_slice(u);
            }
        }
        if all_uvs {
            merged.uvs = Some(uvs);
        }
        let mut model = Model::from_mesh(&name, merged, texture)?;
        model.color = color;
        Ok(model)
    }

    /// A model from a mesh in memory and an optional texture. Errors: a non-finite vertex, or a
    /// mesh that breaks [`TriMesh`]'s guarantees (an index past the vertices).
    pub fn from_mesh(
        name: &str,
        mesh: TriMesh,
        texture: Option<MipTexture>,
    ) -> Result<Model, ModelError> {
        mesh.validate(name, 0).map_err(ModelError::Mesh)?;
        if let Some(vertex) = mesh.positions.iter().position(|p| !p.is_finite()) {
            return Err(ModelError::NonFiniteVertex {
                model: name.to_string(),
                vertex,
            });
        }
        Ok(Model {
            name: name.to_string(),
            mesh,
            texture: texture.map(Arc::new),
            color: DEFAULT_MODEL_COLOR,
        })
    }

    /// Whether the model is drawn textured (it has a texture and texture coordinates).
    pub fn is_textured(&self) -> bool {
        self.texture.is_some() && self.mesh.uvs.is_some()
    }
}

/// A gamma-correct, repeating mip pyramid of an sRGB RGBA image (the model textures' form).
pub fn model_texture(img: &image::RgbaImage) -> Result<MipTexture, MipError> {
    MipTexture::from_srgb8(
        img.width(),
        img.height(),
        img.as_raw(),
        Reduction::GammaCorrect,
        Wrap::Repeat,
    )
}

/// A glTF base-colour texture times its (linear) factor, as a model texture.
fn gltf_texture(img: &image::RgbaImage, factor: [f32; 4]) -> Result<MipTexture, MipError> {
    if factor == [1.0; 4] {
        return model_texture(img);
    }
    let mut scaled = img.clone();
    for p in scaled.pixels_mut() {
        let c = texmap_core::color::srgb8_to_linear_rgb(p.0)
            * Vec3::new(factor[0], factor[1], factor[2]);
        let a = (p.0[3] as f32 * factor[3]).round().clamp(0.0, 255.0) as u8;
        p.0 = texmap_core::color::linear_to_srgb8(c, a);
    }
    model_texture(&scaled)
}

/// The `map_Kd` texture of an OBJ's material libraries, `None` when no library names one.
fn obj_texture(obj: &Path) -> Result<Option<MipTexture>, ModelError> {
    let model = obj.display().to_string();
    let text = std::fs::read(obj).map_err(|e| ModelError::Texture {
        model: model.clone(),
        path: obj.to_path_buf(),
        message: e.to_string(),
    })?;
    let text = String::from_utf8_lossy(&text);
    let dir = obj.parent().unwrap_or(Path::new(""));
    for line in text.lines() {
        let Some(rest) = line.trim().strip_prefix("mtllib") else {
            continue;
        };
        if !rest.starts_with(char::is_whitespace) {
            continue;
        }
        for lib in rest.split_whitespace() {
            let mtl = dir.join(lib);
            let bytes = std::fs::read(&mtl).map_err(|e| ModelError::Texture {
                model: model.clone(),
                path: mtl.clone(),
                message: format!("material library: {e}"),
            })?;
            let mtl_text = String::from_utf8_lossy(&bytes);
            for l in mtl_text.lines() {
                let Some(args) = l.trim().strip_prefix("map_Kd") else {
                    continue;
                };
                // The file name is the last word (options such as `-s 1 1 1` precede it).
                let Some(file) = args.split_whitespace().last() else {
                    continue;
                };
                let img_path = mtl.parent().unwrap_or(Path::new("")).join(file);
                let img = image::open(&img_path).map_err(|e| ModelError::Texture {
                    model: model.clone(),
                    path: img_path.clone(),
                    message: e.to_string(),
                })?;
                return model_texture(&img.to_rgba8())
                    .map(Some)
                    .map_err(ModelError::Mip);
            }
        }
    }
    Ok(None)
}

/// Where and how a model stands on the terrain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Map position in the grid's georeference.
    pub x: f64,
    pub y: f64,
    /// Metres from the ground under `(x, y)` to the model's lowest vertex (default 0).
    pub height_above_ground: f64,
    /// Degrees clockwise from north seen from above (default 0: the model's `−z` points north).
    pub heading_deg: f64,
    /// Uniform scale from model units to metres (default 1), finite and positive.
    pub scale: f64,
}

impl Default for Placement {
    fn default() -> Self {
        Placement {
            x: 0.0,
            y: 0.0,
            height_above_ground: 0.0,
            heading_deg: 0.0,
            scale: 1.0,
        }
    }
}

/// The ground height under map position `(x, y)` and its local metres `(east, south)`;
/// `what` names the placed thing in errors.
fn ground_at(grid: &Grid, what: &str, x: f64, y: f64) -> Result<(f64, f64, f64), ModelError> {
    for (name, value) in [("x", x), ("y", y)] {
        if !value.is_finite() {
            return Err(ModelError::BadValue {
                what: what.to_string(),
                name,
                value,
                expected: "a finite map coordinate",
            });
        }
    }
    let g = grid.georef();
    let (col, row) = g.xy_to_sample(x, y);
    let (w, h) = (grid.width(), grid.height());
    if !(col >= 0.0 && row >= 0.0 && col <= (w - 1) as f64 && row <= (h - 1) as f64) {
        return Err(ModelError::Outside {
            what: what.to_string(),
            x,
            y,
            col,
            row,
            width: w,
            height: h,
        });
    }
    let ground = ground_height(grid, col, row).ok_or_else(|| ModelError::NoGround {
        what: what.to_string(),
        x,
        y,
    })?;
    let (e, s) = g.local_metres(col, row);
    Ok((ground, e, s))
}

/// A model placed on the terrain: world-space vertices (local metres) and what it is drawn with.
#[derive(Clone, Debug)]
pub struct Placed {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    /// Texture coordinates, when the model is drawn textured.
    pub uvs: Option<Vec<Vec2>>,
    pub texture: Option<Arc<MipTexture>>,
    pub color: Vec3,
    /// Bounding sphere (for frustum culling).
    pub center: Vec3,
    pub radius: f32,
    /// The ground height under the placement point (metres).
    pub ground: f64,
}

impl Placed {
    /// Place `model` on `grid` (see the module docs). Errors: a non-finite value, a scale that
    /// is not positive, a position outside the grid or over no-data.
    pub fn new(model: &Model, grid: &Grid, at: &Placement) -> Result<Placed, ModelError> {
        let what = format!("model {}", model.name);
        for (name, value, expected) in [
            ("scale", at.scale, "a finite scale > 0"),
            (
                "height above ground",
                at.height_above_ground,
                "a finite height in metres",
            ),
            ("heading", at.heading_deg, "a finite angle in degrees"),
        ] {
            let ok = value.is_finite() && (name != "scale" || value > 0.0);
            if !ok {
                return Err(ModelError::BadValue {
                    what,
                    name,
                    value,
                    expected,
                });
            }
        }
        let (ground, e, s) = ground_at(grid, &what, at.x, at.y)?;
        let min_y = model
            .mesh
            .positions
            .iter()
            .map(|p| p.y as f64)
            .fold(f64::INFINITY, f64::min);
        let min_y = if min_y.is_finite() { min_y } else { 0.0 };
        let (sin, cos) = at.heading_deg.to_radians().sin_cos();
        let base_y = ground + at.height_above_ground;
        let positions: Vec<Vec3> = model
            .mesh
            .positions
            .iter()
            .map(|p| {
                let (qx, qy, qz) = (
                    p.x as f64 * at.scale,
                    (p.y as f64 - min_y) * at.scale,
                    p.z as f64 * at.scale,
                );
                // Clockwise from above: the model's −z (north) turns to (sin h, 0, −cos h).
                Vec3::new(
                    (e + qx * cos - qz * sin) as f32,
                    (base_y + qy) as f32,
                    (s + qx * sin + qz * cos) as f32,
                )
            })
            .collect();
        let (lo, hi) = positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let (center, radius) = if positions.is_empty() {
            (Vec3::ZERO, 0.0)
        } else {
            let c = 0.5 * (lo + hi);
            let r = positions.iter().map(|p| p.distance(c)).fold(0.0, f32::max);
            (c, r)
        };
        let textured = model.is_textured();
        Ok(Placed {
            name: model.name.clone(),
            positions,
            triangles: model.mesh.triangles.clone(),
            uvs: if textured {
                model.mesh.uvs.clone()
            } else {
                None
            },
            texture: if textured {
                model.texture.clone()
            } else {
                None
            },
            color: model.color,
            center,
            radius,
            ground,
        })
    }
}

/// What [`draw_models`] and [`draw_trees`] drew (integer counts, identical for any thread
/// count).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct ModelStats {
    pub models_drawn: u32,
    pub models_culled: u32,
    /// Triangles of the drawn models submitted to the rasteriser.
    pub model_triangles: u64,
    pub trees_drawn: u32,
    /// Trees outside the frustum, or with a corner of their quad not in front of the eye.
    pub trees_culled: u32,
}

impl ModelStats {
    /// The sum of two counts (models of one call, trees of another).
    pub fn add(&self, o: &ModelStats) -> ModelStats {
        ModelStats {
            models_drawn: self.models_drawn + o.models_drawn,
            models_culled: self.models_culled + o.models_culled,
            model_triangles: self.model_triangles + o.model_triangles,
            trees_drawn: self.trees_drawn + o.trees_drawn,
            trees_culled: self.trees_culled + o.trees_culled,
        }
    }
}

/// Draw placed models into `fb` (not cleared: draw the terrain first) with `sampler`, culling
/// those outside the frustum. The camera's size must be the framebuffer's.
pub fn draw_models(
    camera: &Camera,
    models: &[Placed],
    sampler: Sampler,
    fb: &mut Framebuffer,
) -> Result<ModelStats, ModelError> {
    let state = DrawState {
        cull: Cull::None,
        ..DrawState::default()
    };
    let mut stats = ModelStats::default();
    for m in models {
        if m.triangles.is_empty() || camera.sphere_outside_view(m.center, m.radius) {
            stats.models_culled += 1;
            continue;
        }
        let mesh = Mesh::new(&m.positions, &m.triangles)?;
        let ds = match (&m.uvs, &m.texture) {
            (Some(uvs), Some(tex)) => {
                let mesh = mesh.with_uvs(uvs)?;
                let s = MipSampler {
                    texture: tex,
                    sampler,
                };
                fb.draw_textured(camera, &mesh, &s, &state)?
            }
            _ => fb.draw_mesh(camera, &mesh, &Shading::Flat(m.color), &state)?,
        };
        stats.models_drawn += 1;
        stats.model_triangles += ds.submitted as u64;
    }
    Ok(stats)
}

/// A tree to stand on the terrain: map position and height in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tree {
    pub x: f64,
    pub y: f64,
    pub height: f64,
}

/// A tree on the ground: the world position of its foot and its height and width (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedTree {
    pub base: Vec3,
    pub height: f32,
    pub width: f32,
}

/// Place trees on `grid` (their width follows [`TreeBillboard::ASPECT`]). Errors name the tree
/// by its index: a non-finite or non-positive height, a position outside the grid or over
/// no-data.
pub fn place_trees(grid: &Grid, trees: &[Tree]) -> Result<Vec<PlacedTree>, ModelError> {
    trees
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let what = format!("tree {i}");
            if !(t.height.is_finite() && t.height > 0.0) {
                return Err(ModelError::BadValue {
                    what,
                    name: "height",
                    value: t.height,
                    expected: "a finite height > 0 metres",
                });
            }
            let (ground, e, s) = ground_at(grid, &what, t.x, t.y)?;
            Ok(PlacedTree {
                base: Vec3::new(e as f32, ground as f32, s as f32),
                height: t.height as f32,
                width: (t.height * TreeBillboard::ASPECT as f64) as f32,
            })
        })
        .collect()
}

/// SplitMix64: a well-mixed 64-bit hash of `x`.
fn mix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// A uniform number in `[0, 1)` from a hash.
fn unit(h: u64) -> f64 {
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// `n` trees scattered over `grid` by a hash of `(seed, index)`: positions uniform over the grid,
/// kept only on cells whose four samples hold data, heights 8–20 m. Deterministic; fewer than
/// `n` when most of the grid is no-data (at most `8 n` candidates are tried).
pub fn forest(grid: &Grid, n: usize, seed: u64) -> Vec<Tree> {
    let (w, h) = (grid.width(), grid.height());
    let g = grid.georef();
    let mut out = Vec::with_capacity(n);
    let mut i = 0u64;
    while out.len() < n && i < 8 * n as u64 {
        let k = mix(seed ^ mix(i));
        i += 1;
        let col = unit(mix(k ^ 1)) * (w - 1) as f64;
        let row = unit(mix(k ^ 2)) * (h - 1) as f64;
        let (c0, r0) = (
            (col as u32).min(w.saturating_sub(2)),
            (row as u32).min(h.saturating_sub(2)),
        );
        let data = [(0, 0), (1, 0), (0, 1), (1, 1)].iter().all(|&(dc, dr)| {
            grid.at((c0 + dc).min(w - 1), (r0 + dr).min(h - 1))
                .is_finite()
        });
        if !data {
            continue;
        }
        let (x, y) = g.sample_xy(col, row);
        out.push(Tree {
            x,
            y,
            height: 8.0 + 12.0 * unit(mix(k ^ 3)),
        });
    }
    out
}

/// The built-in tree: a procedurally generated RGBA conifer and its mip pyramid.
#[derive(Clone, Debug)]
pub struct TreeBillboard {
    image: image::RgbaImage,
    texture: MipTexture,
}

impl Default for TreeBillboard {
    fn default() -> Self {
        TreeBillboard::new()
    }
}

impl TreeBillboard {
    /// Image width and height in texels.
    pub const SIZE: (u32, u32) = (64, 128);
    /// Width over height of the billboard (the image's aspect).
    pub const ASPECT: f32 = 0.5;

    /// The conifer: a trunk over the bottom eighth, a crown from the top to seven eighths whose
    /// half-width grows linearly downward, hashed shades of green; transparent texels carry the
    /// crown's mean colour so that filtering does not darken the edge.
    pub fn new() -> TreeBillboard {
        let (w, h) = Self::SIZE;
        let (wf, hf) = (w as f32, h as f32);
        let crown_mean = [40u8, 95, 40];
        let image = image::RgbaImage::from_fn(w, h, |x, y| {
            let (u, v) = ((x as f32 + 0.5) / wf, (y as f32 + 0.5) / hf);
            let du = (u - 0.5).abs();
            let trunk = v >= 0.8 && du < 0.07;
            let crown = (0.02..0.875).contains(&v) && du < 0.47 * (v - 0.02) / 0.855;
            if crown {
                let n = mix(((y as u64) << 32) | x as u64);
                let shade = (n % 40) as u8;
                image::Rgba([25 + shade / 2, 75 + shade, 30 + shade / 3, 255])
            } else if trunk {
                image::Rgba([95, 65, 35, 255])
            } else {
                image::Rgba([crown_mean[0], crown_mean[1], crown_mean[2], 0])
            }
        });
        let texture =
            MipTexture::from_srgb8(w, h, image.as_raw(), Reduction::GammaCorrect, Wrap::Clamp)
                .expect("the built-in tree image has a valid size and length");
        TreeBillboard { image, texture }
    }

    /// The sRGB RGBA image.
    pub fn image(&self) -> &image::RgbaImage {
        &self.image
    }
    pub fn texture(&self) -> &MipTexture {
        &self.texture
    }
    /// The fraction of texels with alpha ≥ ½ (the share of the quad a tree covers).
    pub fn coverage(&self) -> f64 {
        let n = self.image.pixels().filter(|p| p[3] >= 128).count();
        n as f64 / (self.image.width() * self.image.height()) as f64
    }
}

/// A tree's quad in eye space: its foot, its unit right and up axes and its plane's normal.
#[derive(Clone, Copy, Debug)]
struct EyeQuad {
    base: Vec3,
    right: Vec3,
    up: Vec3,
    normal: Vec3,
    width: f32,
    height: f32,
}

struct TreeShader<'a> {
    quads: &'a [EyeQuad],
    texture: &'a MipTexture,
    sampler: Sampler,
    /// Screen centre and focal length (the eye ray through pixel (x, y) is
    /// `((x − cx)/k, (cy − y)/k, −1)`).
    cx: f32,
    cy: f32,
    k: f32,
}

impl QuadShader for TreeShader<'_> {
    fn shade_quad(&self, id: u32, quad: &SpriteQuad) -> QuadOut {
        let q = &self.quads[id as usize];
        let mut uv = [Vec2::ZERO; 4];
        let mut depth = [f32::NAN; 4];
        let mut inside = 0u8;
        let pn = q.normal.dot(q.base);
        for l in 0..4 {
            let d = Vec3::new(
                (quad.x[l] - self.cx) / self.k,
                (self.cy - quad.y[l]) / self.k,
                -1.0,
            );
            let den = q.normal.dot(d);
            let t = pn / den;
            let p = d * t - q.base;
            let s = p.dot(q.right) / q.width + 0.5;
            let v = 1.0 - p.dot(q.up) / q.height;
            uv[l] = Vec2::new(s, v);
            depth[l] = t;
            if t > 0.0 && (0.0..1.0).contains(&s) && (0.0..1.0).contains(&v) {
                inside |= 1 << l;
            }
        }
        // Helper lanes of a ray parallel to the plane: give them a finite lane's coordinates.
        let fallback = uv
            .iter()
            .copied()
            .find(|u| u.is_finite())
            .unwrap_or(Vec2::ZERO);
        for u in &mut uv {
            if !u.is_finite() {
                *u = fallback;
            }
        }
        let texels: [Vec4; 4] = self.sampler.sample_quad(self.texture, uv);
        let mut mask = quad.mask & inside;
        for (l, t) in texels.iter().enumerate() {
            if t.w < 0.5 {
                mask &= !(1 << l);
            }
        }
        QuadOut {
            color: texels.map(|t| t.truncate()),
            depth,
            mask,
        }
    }
}

/// Draw trees as cylindrical billboards (see the module docs) into `fb` (not cleared) with
/// `sampler`. The camera must be a perspective camera of the framebuffer's size.
pub fn draw_trees(
    camera: &Camera,
    trees: &[PlacedTree],
    billboard: &TreeBillboard,
    sampler: Sampler,
    fb: &mut Framebuffer,
) -> Result<ModelStats, ModelError> {
    if (camera.width(), camera.height()) != (fb.width(), fb.height()) {
        return Err(ModelError::Raster(RasterError::SizeMismatch {
            camera: (camera.width(), camera.height()),
            target: (fb.width(), fb.height()),
        }));
    }
    let eye = camera.eye();
    let near = camera.near();
    let mut stats = ModelStats::default();
    let mut quads = Vec::with_capacity(trees.len());
    let mut sprites = Vec::with_capacity(trees.len());
    // Facing when the eye is straight above a tree: the camera's backward direction, flattened.
    let back = -camera.forward();
    let fallback = Vec3::new(back.x, 0.0, back.z)
        .try_normalize()
        .unwrap_or(Vec3::Z);
    for t in trees {
        let valid = t.base.is_finite()
            && t.height.is_finite()
            && t.height > 0.0
            && t.width.is_finite()
            && t.width > 0.0;
        let center = t.base + Vec3::Y * (0.5 * t.height);
        let radius = 0.5 * Vec2::new(t.width, t.height).length();
        if !valid || camera.sphere_outside_view(center, radius) {
            stats.trees_culled += 1;
            continue;
        }
        let to_eye = eye - t.base;
        let n = Vec3::new(to_eye.x, 0.0, to_eye.z)
            .try_normalize()
            .unwrap_or(fallback);
        let right = Vec3::Y.cross(n);
        let half = right * (0.5 * t.width);
        let top = Vec3::Y * t.height;
        let corners = [
            t.base - half,
            t.base + half,
            t.base - half + top,
            t.base + half + top,
        ];
        let mut lo = Vec2::splat(f32::INFINITY);
        let mut hi = Vec2::splat(f32::NEG_INFINITY);
        let mut dmin = f32::INFINITY;
        let mut ok = true;
        for c in corners {
            match camera.project(c) {
                Some((s, d)) if d > near => {
                    lo = lo.min(s);
                    hi = hi.max(s);
                    dmin = dmin.min(d);
                }
                _ => ok = false,
            }
        }
        if !ok {
            stats.trees_culled += 1;
            continue;
        }
        sprites.push(Sprite {
            min: lo.floor(),
            max: hi.ceil(),
            depth_min: dmin,
            id: quads.len() as u32,
        });
        quads.push(EyeQuad {
            base: camera.world_to_eye(t.base),
            right: camera.dir_to_eye(right),
            up: camera.dir_to_eye(Vec3::Y),
            normal: camera.dir_to_eye(n),
            width: t.width,
            height: t.height,
        });
        stats.trees_drawn += 1;
    }
    let shader = TreeShader {
        quads: &quads,
        texture: billboard.texture(),
        sampler,
        cx: 0.5 * camera.width() as f32,
        cy: 0.5 * camera.height() as f32,
        k: camera.scale(),
    };
    fb.draw_sprites(&sprites, &shader, &DrawState::default())?;
    Ok(stats)
}
