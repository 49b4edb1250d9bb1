//! `texmap envmap bake`: the scene's dynamic cube map around a point written as image files, for
//! engines and tools to import as a reflection probe. Glue only: texmap-envmap bakes
//! (`texmap_envmap::bake`), this file parses, checks and writes (atomically, through
//! `output::write_atomic`).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use glam::Vec3;
use texmap_core::color::linear_to_srgb8;
use texmap_envmap::Surface;
use texmap_envmap::address::Face;
use texmap_envmap::bake::{BakeOptions, Image, Layout, bake, face_name};

use crate::args::usage;
use crate::envmap::{build_scene, load_environment};
use crate::output::write_atomic;

pub const ABOUT: &str =
    "Bake a reflection probe: the scene's dynamic cube map around a point, as EXR or PNG images";

pub const LONG_ABOUT: &str = "\
Bake a reflection probe: the scene's dynamic cube map (the `--method cube` map, drawn by six \
90° cameras) around a point at one moment of the animation, written as images for engines and \
tools to import. The target itself is not drawn into its probe, as in the dynamic map.

Faces follow the OpenGL cube-map specification (also KTX's and DDS's): order +X, −X, +Y, −Y, +Z, \
−Z, each face oriented by the specification's (sc, tc, ma) table in this scene's world (right-\
handed, y up). Layouts:
  cross     (default) the horizontal cross, 4N x 3N: +Y over +Z, the row −X +Z +X −Z, −Y under \
+Z. For tools that take a cross (cmft; Unity's cube texture import detects one, though Unity's \
left-handed world may show it mirrored).
  faces     six N x N images; the path must contain {face}, which becomes px nx py ny pz nz. For \
tools that assemble a DDS or KTX cube map from six files in this order (DirectXTex's texassemble \
cube, KTX-Software's ktx create --cubemap).
  c3x2      ffmpeg's v360 c3x2 layout, 3N x 2N, faces r l u / d f b as ffmpeg defines them: \
`ffmpeg -i probe.png -vf v360=c3x2:e probe_equirect.png` converts it to any v360 projection.
  equirect  latitude-longitude, 4N x 2N, the layout of `texmap envmap --env` (centre −z, top \
+y), so a baked equirect fed back as --env reproduces the surroundings. For Blender's world \
(Environment Texture node) and Unreal, which imports a lat-long .hdr as a cube texture (convert \
the EXR to .hdr first). Resampled from the cube bilinearly; the other layouts move texels only.

-o OUT: .exr writes linear float RGB radiance (what probes should be); .png writes 8-bit sRGB, \
where radiance over 1 (the sun) clips. Files appear only when complete.

Examples:
  texmap envmap bake -o probe.exr
  texmap envmap bake --layout faces --size 512 --frame 48 -o probe/{face}.exr
  texmap envmap bake --layout equirect --at 0,0,-6 -o hall.exr";

#[derive(Args, Debug)]
pub struct BakeArgs {
    /// `builtin` (the mirror sphere in a tunnel of moving objects) or an OBJ/glTF file whose first
    /// mesh is the target and the others the surrounding objects, as for `texmap envmap`.
    #[arg(long, default_value = "builtin")]
    pub scene: String,
    /// Latitude-longitude environment image (PNG, EXR or Radiance .hdr, width = 2 x height, centre
    /// −z, top +y), as for `texmap envmap`; default: the built-in sky.
    #[arg(long, value_name = "FILE")]
    pub env: Option<PathBuf>,
    /// Probe position X,Y,Z in scene units; default: the target's centre.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub at: Option<String>,
    /// Texels per face side (4-4096).
    #[arg(long, value_name = "N", default_value_t = 256)]
    pub size: u32,
    /// Moment of the animation in seconds (default 0).
    #[arg(
        long,
        value_name = "SECONDS",
        allow_negative_numbers = true,
        conflicts_with = "frame"
    )]
    pub time: Option<f32>,
    /// Moment of the animation as a frame of `texmap envmap --frames` (1/24 s apart).
    #[arg(long, value_name = "N")]
    pub frame: Option<u32>,
    /// Image layout (see above): cross, faces, c3x2 or equirect.
    #[arg(long, value_enum, default_value = "cross")]
    pub layout: LayoutArg,
    /// Output file: .exr (linear float RGB) or .png (8-bit sRGB, values over 1 clip); with
    /// `--layout faces` the path must contain {face}.
    #[arg(short = 'o', long = "out", value_name = "OUT")]
    pub out: PathBuf,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayoutArg {
    Cross,
    Faces,
    C3x2,
    Equirect,
}

/// Output encodings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Exr,
    Png,
}

/// `X,Y,Z` as a finite point.
fn parse_point(s: &str) -> Result<Vec3> {
    let v: Vec<f32> = s
        .split(',')
        .map(|x| x.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .or_else(|_| usage(format!("--at {s:?}: expected three numbers X,Y,Z")))?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Vec3::new(x, y, z)),
        _ => usage(format!("--at {s:?}: expected three finite numbers X,Y,Z")),
    }
}

pub fn run(a: &BakeArgs) -> Result<()> {
    // Every usage check before any work.
    if !(texmap_envmap::MIN_MAP_SIZE..=texmap_envmap::MAX_MAP_SIZE).contains(&a.size) {
        return usage(format!(
            "--size {}: expected {}..={} texels per face side",
            a.size,
            texmap_envmap::MIN_MAP_SIZE,
            texmap_envmap::MAX_MAP_SIZE
        ));
    }
    let at = a.at.as_deref().map(parse_point).transpose()?;
    let time = match (a.time, a.frame) {
        (Some(t), _) if !t.is_finite() => {
            return usage(format!("--time {t}: expected a finite number of seconds"));
        }
        (Some(t), _) => t,
        // As `texmap envmap --frames` times its frames.
        (None, Some(f)) => f as f32 / 24.0,
        (None, None) => 0.0,
    };
    let out = a.out.to_string_lossy();
    let encoding = match a
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .as_deref()
    {
        Some("exr") => Encoding::Exr,
        Some("png") => Encoding::Png,
        _ => {
            return usage(format!(
                "-o {out}: expected a .exr (linear float) or .png (8-bit sRGB) file"
            ));
        }
    };
    let layout = match a.layout {
        LayoutArg::Cross => Layout::Cross,
        LayoutArg::Faces => Layout::Faces,
        LayoutArg::C3x2 => Layout::C3x2,
        LayoutArg::Equirect => Layout::Equirect,
    };
    let has_face = out.contains("{face}");
    if layout == Layout::Faces && !has_face {
        return usage(format!(
            "-o {out}: --layout faces writes six files; put {{face}} in the path (it becomes px nx py ny pz nz)"
        ));
    }
    if layout != Layout::Faces && has_face {
        return usage(format!(
            "-o {out}: {{face}} is for --layout faces; this layout writes one file"
        ));
    }

    let env = a.env.as_deref().map(load_environment).transpose()?;
    let scene = build_scene(&a.scene, Surface::Mirror, &env, time)?;
    let probe = bake(&scene, &BakeOptions { at, size: a.size })?;
    let images = probe.layout(layout);
    let paths: Vec<PathBuf> = if layout == Layout::Faces {
        Face::ALL
            .iter()
            .map(|&f| PathBuf::from(out.replace("{face}", face_name(f))))
            .collect()
    } else {
        vec![a.out.clone()]
    };
    for (img, path) in images.iter().zip(&paths) {
        write_image(img, path, encoding)?;
        crate::note!("wrote {}", path.display());
    }
    Ok(())
}

/// One image to `path`, atomically.
fn write_image(img: &Image, path: &Path, encoding: Encoding) -> Result<()> {
    let (w, h) = (img.width as usize, img.height as usize);
    match encoding {
        Encoding::Exr => write_atomic(path, |tmp| {
            exr::prelude::write_rgb_file(tmp, w, h, |x, y| {
                let c = img.texels[y * w + x];
                (c.x, c.y, c.z)
            })
            .with_context(|| format!("cannot write EXR {}", path.display()))
        }),
        Encoding::Png => {
            let bytes: Vec<u8> = img
                .texels
                .iter()
                .flat_map(|&c| {
                    let [r, g, b, _] = linear_to_srgb8(c, 255);
                    [r, g, b]
                })
                .collect();
            write_atomic(path, |tmp| {
                image::save_buffer_with_format(
                    tmp,
                    &bytes,
                    img.width,
                    img.height,
                    image::ExtendedColorType::Rgb8,
                    image::ImageFormat::Png,
                )
                .with_context(|| format!("cannot write PNG {}", path.display()))
            })
        }
    }
}
