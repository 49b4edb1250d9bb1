//! `texmap envmap`: draw a reflective or refractive target with an environment map (Seed 003 and
//! its alternatives), one frame or an animation; `texmap envmap compare` writes the study.
//! Glue only: texmap-envmap renders, texmap-study compares, texmap-mesh reads meshes.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use glam::Vec3;
use texmap_core::camera::Camera;
use texmap_core::color::srgb8_to_linear;
use texmap_core::shade::Material;
use texmap_envmap::scene::{TunnelParams, tunnel_camera, tunnel_lighting, tunnel_scene};
use texmap_envmap::{
    EnvScene, Environment, Filter, Method, Object, Options, Renderer, RimPolicy, Surface, Target,
    TargetShape,
};

use crate::args::usage;
use crate::movie::Sink;
use crate::scene::parse_size;

#[derive(Args, Debug)]
#[command(args_conflicts_with_subcommands = true)]
pub struct EnvmapArgs {
    #[command(subcommand)]
    pub cmd: Option<EnvmapCmd>,
    #[command(flatten)]
    pub render: EnvRenderArgs,
}

#[derive(Subcommand, Debug)]
pub enum EnvmapCmd {
    /// Every method against the reference ray tracer, and time-sliced cube maps on the moving
    /// scene (error against update cost): envmap.csv, envmap.json and SVG/PNG charts.
    Compare {
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// Image size of the study's frames, WxH.
        #[arg(long, default_value = "320x240")]
        size: String,
        /// Reference samples per pixel axis (n x n per pixel).
        #[arg(long, default_value_t = 3)]
        samples: u32,
        /// Frames of the time-sliced cube study (0 leaves it out): the moving tunnel rendered
        /// with 1, 2, 3 and 6 cube faces redrawn per frame, each frame against the reference.
        #[arg(long, default_value_t = texmap_study::envmap::STALENESS_FRAMES)]
        staleness_frames: u32,
        /// Scene seconds between the time-sliced study's frames: the faster the objects move
        /// per frame, the larger the error of faces drawn a few frames earlier.
        #[arg(long, value_name = "SECONDS", default_value_t = texmap_study::envmap::STALENESS_DT)]
        staleness_dt: f32,
    },
    #[command(
        about = crate::envmap_bake::ABOUT,
        long_about = crate::envmap_bake::LONG_ABOUT
    )]
    Bake(crate::envmap_bake::BakeArgs),
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvMethodArg {
    SphereStatic,
    /// The static sphere map with coordinates per vertex (the 1998 way: rim sparkle).
    SphereStaticVertex,
    SphereDynamic,
    Cube,
    Paraboloid,
    CubeBox,
    /// The reference ray tracer (slow, exact).
    Reference,
}

#[derive(Args, Debug)]
pub struct EnvRenderArgs {
    /// `builtin` (a mirror sphere in a tunnel of moving objects) or an OBJ/glTF file whose first
    /// mesh is the target and the others the surrounding objects.
    #[arg(long, default_value = "builtin")]
    pub scene: String,
    /// Latitude-longitude environment image (PNG, EXR or Radiance .hdr as HDRI libraries serve
    /// them, width = 2 x height; its centre is the −z direction, its top +y); default: a built-in
    /// sky. A cube map or skybox converts with ffmpeg, whose equirectangular layout is this one:
    /// `ffmpeg -i cube3x2.png -vf v360=c3x2:e env.png` (faces in ffmpeg's order r l u d f b, f
    /// becoming −z).
    #[arg(long, value_name = "FILE")]
    pub env: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "sphere-dynamic")]
    pub method: EnvMethodArg,
    /// Make the target refractive with this index of refraction (> 0); default: a mirror.
    #[arg(long, allow_negative_numbers = true)]
    pub ior: Option<f32>,
    /// Image size, WxH.
    #[arg(long, default_value = "800x600")]
    pub size: String,
    /// Map side in texels.
    #[arg(long, default_value_t = 256)]
    pub map_size: u32,
    /// Map filtering: trilinear over the map's pyramid, or bilinear on its finest level (aliases
    /// where the reflection shrinks the map, e.g. near the target's rim).
    #[arg(long, value_enum, default_value = "trilinear")]
    pub filter: EnvFilterArg,
    /// Dynamic sphere and paraboloid maps: triangles whose directions straddle the map's rim are
    /// split (`split`), or drawn with straight edges as in 1998 (`naive`: they smear across the
    /// map, the artefact Seed 003 shows).
    #[arg(long, value_enum, default_value = "split")]
    pub rim: EnvRimArg,
    /// Seed 003's option: draw into the dynamic maps only objects whose triangles lie at least
    /// this far from the target's centre (scene units; 0 draws every object). Nearby objects
    /// carry the largest parallax error, so leaving them out trades missing reflections for
    /// wrong ones.
    #[arg(
        long,
        value_name = "D",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub min_distance: f32,
    /// Cube and cube-box: cube faces redrawn per frame, 1-6. A dynamic cube map is six renders
    /// of the scene every frame; with N < 6 the map is kept between frames and only N faces are
    /// redrawn, round robin (all six on the first frame), so the map update costs about N/6 of
    /// a full one. The price: a face shows moving objects where they were up to ⌈6/N⌉ − 1
    /// frames ago (reflections lag and tear at face edges). Engines spread a probe over 6-16
    /// frames. 6 redraws every face every frame; only animations (--frames > 1) see a
    /// difference, and the other methods ignore it.
    #[arg(long, value_name = "N", default_value_t = 6)]
    pub faces_per_frame: u32,
    /// Background where nothing is drawn: `environment` (the environment image or sky), or
    /// R,G,B (0-255). The target still reflects the environment.
    #[arg(long, default_value = "environment")]
    pub background: String,
    /// Samples per pixel axis of `--method reference` (n x n per pixel).
    #[arg(long, default_value_t = 2)]
    pub reference_samples: u32,
    /// Frames to render (1/24 s apart); use a %04d pattern in -o for more than one PNG, or a
    /// movie extension.
    #[arg(long, default_value_t = 1)]
    pub frames: usize,
    /// Frames per second of a movie output.
    #[arg(long, default_value_t = 24.0)]
    pub fps: f64,
    /// Output: a PNG (or a pattern such as frames/%04d.png), or a movie: .mp4, .webm, .gif
    /// (through ffmpeg) or .apng.
    #[arg(short = 'o', long = "out", default_value = "envmap.png")]
    pub out: PathBuf,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EnvFilterArg {
    Bilinear,
    Trilinear,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EnvRimArg {
    Split,
    Naive,
}

pub fn run(a: EnvmapArgs) -> Result<()> {
    match a.cmd {
        Some(EnvmapCmd::Compare {
            out,
            size,
            samples,
            staleness_frames,
            staleness_dt,
        }) => compare(&out, &size, samples, staleness_frames, staleness_dt),
        Some(EnvmapCmd::Bake(b)) => crate::envmap_bake::run(&b),
        None => render(&a.render),
    }
}

fn compare(
    out: &Path,
    size: &str,
    samples: u32,
    staleness_frames: u32,
    staleness_dt: f32,
) -> Result<()> {
    let (width, height) = parse_size(size)?;
    let opts = texmap_study::envmap::EnvStudyOptions {
        width,
        height,
        samples,
        staleness_frames,
        staleness_dt,
        ..Default::default()
    };
    let pb = crate::commands::spinner("envmap study: rendering every method and the reference");
    let records = texmap_study::envmap::run(&opts)?;
    pb.finish_and_clear();
    let files = texmap_study::envmap::write(out, &records)?;
    for r in records.iter().filter(|r| r.study == "methods") {
        println!(
            "{:22} PSNR {:6.2} dB (env only {:6.2})  update {:8.2} ms  draw {:8.2} ms",
            r.method, r.psnr_db, r.psnr_env_only_db, r.update_ms, r.draw_ms
        );
    }
    for r in records.iter().filter(|r| r.study == "staleness") {
        println!(
            "{:10} {} face(s)/frame  PSNR {:6.2} dB (vs every face redrawn {:6.2})  update {:6.2} ms/frame",
            r.method, r.faces_per_frame, r.psnr_db, r.psnr_vs_full_update_db, r.update_ms
        );
    }
    for f in files {
        crate::note!("wrote {}", f.display());
    }
    Ok(())
}

/// A lat-long environment from a PNG (sRGB), EXR or Radiance HDR (linear) file.
pub(crate) fn load_environment(path: &Path) -> Result<Environment> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let (w, h, texels) = if ext == "exr" {
        let img = exr::prelude::read_first_rgba_layer_from_file(
            path,
            |res, _| (res.width(), vec![Vec3::ZERO; res.width() * res.height()]),
            |(w, px), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * *w + pos.x()] = Vec3::new(r, g, b);
            },
        )
        .with_context(|| format!("{}: cannot read EXR", path.display()))?;
        let size = img.layer_data.size;
        (
            size.width() as u32,
            size.height() as u32,
            img.layer_data.channel_data.pixels.1,
        )
    } else if ext == "hdr" {
        // Radiance RGBE (.hdr, as Poly Haven and most HDRI libraries serve them): linear.
        let img = image::open(path)
            .with_context(|| format!("{}: cannot read Radiance HDR", path.display()))?
            .to_rgb32f();
        let (w, h) = img.dimensions();
        let texels = img.pixels().map(|p| Vec3::new(p[0], p[1], p[2])).collect();
        (w, h, texels)
    } else {
        let img = image::open(path)
            .with_context(|| format!("{}: cannot read image", path.display()))?
            .to_rgb8();
        let (w, h) = img.dimensions();
        let texels = img
            .pixels()
            .map(|p| {
                Vec3::new(
                    srgb8_to_linear(p[0]),
                    srgb8_to_linear(p[1]),
                    srgb8_to_linear(p[2]),
                )
            })
            .collect();
        (w, h, texels)
    };
    Environment::lat_long(w, h, texels).with_context(|| format!("{}", path.display()))
}

/// The scene and a camera for it at time `t`.
fn build(
    a: &EnvRenderArgs,
    env: &Option<Environment>,
    t: f32,
    w: u32,
    h: u32,
) -> Result<(EnvScene, Camera)> {
    let surface = match a.ior {
        Some(ior) => Surface::Refractive { ior },
        None => Surface::Mirror,
    };
    let s = build_scene(&a.scene, surface, env, t)?;
    if a.scene == "builtin" {
        return Ok((s, tunnel_camera(w, h)?));
    }
    // Orbit the target at three bounding radii.
    let r = s.radius().max(1e-3);
    let ang = 0.4 + t * 0.5;
    let eye = s.centre() + Vec3::new(ang.sin() * 3.0 * r, 0.8 * r, ang.cos() * 3.0 * r);
    let cam = Camera::perspective_look_at(eye, s.centre(), Vec3::Y, 50.0, w, h)?;
    Ok((s, cam))
}

/// The scene of `--scene` (`builtin` or a mesh file) at time `t`, with the `--env` environment.
pub(crate) fn build_scene(
    scene: &str,
    surface: Surface,
    env: &Option<Environment>,
    t: f32,
) -> Result<EnvScene> {
    if scene == "builtin" {
        let s = tunnel_scene(TunnelParams {
            time: t,
            detail: 1,
            surface,
        })?;
        let s = match env {
            Some(e) => EnvScene::new(
                s.objects().to_vec(),
                s.target().clone(),
                e.clone(),
                *s.lighting(),
            )?,
            None => s,
        };
        return Ok(s);
    }
    let path = Path::new(scene);
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let meshes = match ext.as_str() {
        "obj" => texmap_mesh::read_obj(path)?,
        "gltf" | "glb" => texmap_mesh::read_gltf(path)?,
        _ => {
            return usage(format!(
                "--scene {scene:?}: expected builtin, or a .obj, .gltf or .glb file"
            ));
        }
    };
    let mut it = meshes.into_iter();
    let Some(first) = it.next() else {
        anyhow::bail!("{}: no mesh to use as the target", path.display());
    };
    let palette = [
        Vec3::new(0.8, 0.8, 0.75),
        Vec3::new(0.2, 0.4, 0.8),
        Vec3::new(0.85, 0.3, 0.2),
        Vec3::new(0.3, 0.75, 0.3),
    ];
    let objects = it
        .enumerate()
        .map(|(i, m)| Object {
            mesh: m,
            material: Material::matte(palette[i % palette.len()]),
        })
        .collect();
    EnvScene::new(
        objects,
        Target {
            shape: TargetShape::Mesh(first),
            surface,
        },
        env.clone().unwrap_or(Environment::Sky),
        tunnel_lighting(),
    )
    .with_context(|| format!("{}", path.display()))
}

fn render(a: &EnvRenderArgs) -> Result<()> {
    if let Some(ior) = a.ior
        && !(ior.is_finite() && ior > 0.0)
    {
        return usage(format!(
            "--ior {ior}: the index of refraction must be a finite number > 0"
        ));
    }
    if !(texmap_envmap::MIN_MAP_SIZE..=texmap_envmap::MAX_MAP_SIZE).contains(&a.map_size) {
        return usage(format!(
            "--map-size {}: expected {}..={}",
            a.map_size,
            texmap_envmap::MIN_MAP_SIZE,
            texmap_envmap::MAX_MAP_SIZE
        ));
    }
    if !(1..=6).contains(&a.faces_per_frame) {
        return usage(format!(
            "--faces-per-frame {}: expected 1..=6 cube faces redrawn per frame",
            a.faces_per_frame
        ));
    }
    if !(1..=100_000).contains(&a.frames) {
        return usage(format!("--frames {}: expected 1..=100000", a.frames));
    }
    if !(a.min_distance.is_finite() && a.min_distance >= 0.0) {
        return usage(format!(
            "--min-distance {}: expected a finite distance ≥ 0",
            a.min_distance
        ));
    }
    if !(1..=16).contains(&a.reference_samples) {
        return usage(format!(
            "--reference-samples {}: expected 1..=16",
            a.reference_samples
        ));
    }
    let background = match a.background.trim() {
        "environment" => None,
        other => match crate::scene::parse_background(other)? {
            [_, _, _, 0] => {
                return usage(format!(
                    "--background {other}: expected environment or R,G,B (a transparent background is not supported here)"
                ));
            }
            c => Some(c),
        },
    };
    let (w, h) = parse_size(&a.size)?;
    let env = a.env.as_deref().map(load_environment).transpose()?;
    let mut sink = Sink::new(&a.out, a.frames, a.fps, false, None)?;
    let pb = crate::commands::progress(a.frames as u64, "envmap");
    // One renderer for every frame: it keeps the maps (a time-sliced cube map redraws only
    // --faces-per-frame faces of the kept one) and recycles the frame buffers.
    let mut renderer = Renderer::new();
    for f in 0..a.frames {
        let t = f as f32 / 24.0;
        let (scene, cam) = build(a, &env, t, w, h)?;
        let frame = match a.method {
            EnvMethodArg::Reference => {
                if background.is_some() {
                    return usage(
                        "--background R,G,B applies to the mapping methods; the reference shows the environment",
                    );
                }
                texmap_study::envmap::reference(&scene, &cam, true, a.reference_samples)?
            }
            m => {
                let method = match m {
                    EnvMethodArg::SphereStatic => Method::SphereStatic,
                    EnvMethodArg::SphereStaticVertex => Method::SphereStaticVertex,
                    EnvMethodArg::SphereDynamic => Method::SphereDynamic,
                    EnvMethodArg::Cube => Method::Cube,
                    EnvMethodArg::Paraboloid => Method::Paraboloid,
                    EnvMethodArg::CubeBox => Method::CubeBox,
                    EnvMethodArg::Reference => unreachable!("handled above"),
                };
                let mut o = Options::new(method);
                o.map_size = a.map_size;
                o.filter = match a.filter {
                    EnvFilterArg::Bilinear => Filter::Bilinear,
                    EnvFilterArg::Trilinear => Filter::Trilinear,
                };
                o.rim = match a.rim {
                    EnvRimArg::Split => RimPolicy::Split,
                    EnvRimArg::Naive => RimPolicy::Naive,
                };
                o.min_object_distance = a.min_distance;
                o.cube_faces_per_frame = a.faces_per_frame;
                if let Some(c) = background {
                    o.show_environment = false;
                    o.background = c;
                }
                renderer.render(&scene, &cam, &o)?.frame
            }
        };
        for path in sink.write(f, &frame, false)? {
            if a.frames == 1 {
                crate::note!("wrote {}", path.display());
            }
        }
        renderer.recycle(frame);
        pb.inc(1);
    }
    pb.finish_and_clear();
    if let Some(movie) = sink.finish()? {
        crate::note!("wrote {}", movie.display());
    }
    Ok(())
}
