//! `texmap terrain render`: one flight view of a terrain database to a PNG (and optionally its
//! depth as OpenEXR), with the frame's statistics as JSON. Glue only: the view is
//! `texmap_terrain::view`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use serde_json::json;
use texmap_core::sample::Sampler;
use texmap_raster::Framebuffer;
use texmap_terrain::db::Database;
use texmap_terrain::view::{
    FlightCamera, FlightTerrain, FrameScratch, SAMPLER_NAMES, ViewError, ViewOptions,
    sampler_by_name,
};

use crate::args::{UsageError, usage};
use crate::output::{write_depth_exr, write_png};

/// The image options `terrain render` and `terrain fly` share.
#[derive(Args, Debug)]
pub struct FlightViewArgs {
    /// Horizontal field of view, degrees (in `fly`, a path file's fov column overrides it).
    #[arg(long, default_value_t = 45.0)]
    pub fov: f64,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768")]
    pub size: String,
    /// nearest, bilinear, trilinear, span3, span4, aniso, quadratic3 (quadratic interpolation
    /// on each level's 3x3 neighbourhood), or reference: the full-resolution mesh ray-traced
    /// with the texture integrated over each sample's footprint, --samples² per pixel.
    #[arg(long, default_value = "trilinear")]
    pub sampler: String,
    /// Reference samples per pixel axis (--sampler reference).
    #[arg(long, default_value_t = 4)]
    pub samples: u32,
    /// Refine chunks while their screen-space error exceeds this many pixels.
    #[arg(long, default_value_t = 1.0)]
    pub pixel_error: f32,
    /// Largest side of the whole-terrain texture assembled from the GST pyramid.
    #[arg(long, default_value_t = 4096)]
    pub max_texture: u32,
    /// Texture source: `whole` (one texture, the finest GST level whose side is at most
    /// --max-texture) or `streamed` (each chunk textured from the GST maps at the level it
    /// needs, maps and chunk textures held under --cache-mb).
    #[arg(long, default_value = "whole")]
    pub texture: String,
    /// Chunk-mesh cache budget, MiB: a database's chunk meshes are read from its files when a
    /// view selects them and the least recently used are dropped above this (the frame's own
    /// chunks always stay).
    #[arg(long, default_value_t = 128)]
    pub chunk_cache_mb: u64,
    /// Models and trees drawn on the terrain.
    #[command(flatten)]
    pub objects: crate::terrain_models::ModelArgs,
}

impl FlightViewArgs {
    /// The rasterising sampler (`None` for `reference`) and the image size, checked.
    pub fn checked(&self) -> Result<(Option<Sampler>, (u32, u32))> {
        let reference = self.sampler == "reference";
        let sampler = sampler_by_name(&self.sampler);
        if sampler.is_none() && !reference {
            return usage(format!(
                "--sampler {}: expected one of {}, reference",
                self.sampler,
                SAMPLER_NAMES.join(", ")
            ));
        }
        if reference && !(1..=texmap_reftrace::MAX_SAMPLES_PER_AXIS).contains(&self.samples) {
            return usage(format!(
                "--samples {}: expected 1..={}",
                self.samples,
                texmap_reftrace::MAX_SAMPLES_PER_AXIS
            ));
        }
        match self.texture.as_str() {
            "whole" => {}
            "streamed" if reference => {
                return usage("--texture streamed: the reference sampler reads the whole texture");
            }
            "streamed" => {}
            t => return usage(format!("--texture {t}: expected whole or streamed")),
        }
        if reference && self.objects.any_trees() {
            return usage("--tree/--trees: the reference sampler traces models, not billboards");
        }
        Ok((sampler, crate::scene::parse_size(&self.size)?))
    }

    /// Whether frames are textured from the streamed GST maps.
    pub fn streamed(&self) -> bool {
        self.texture == "streamed"
    }

    /// The chunk-mesh cache budget in bytes.
    pub fn chunk_budget(&self) -> u64 {
        self.chunk_cache_mb.saturating_mul(1 << 20)
    }

    /// The side limit of the whole texture to open the terrain with (the coarsest level when
    /// streamed: the stream holds the photo).
    pub fn whole_texture_side(&self) -> u32 {
        if self.streamed() { 1 } else { self.max_texture }
    }
}

/// Draw the terrain database from an aircraft.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Database directory (from `texmap terrain build`).
    pub dir: PathBuf,
    /// Eye position X,Y in the grid's georeference (default: the grid's centre).
    #[arg(long, allow_hyphen_values = true)]
    pub eye: Option<String>,
    /// Eye position as WGS 84 longitude,latitude in degrees, whatever the grid's system
    /// (geographic, UTM or Web Mercator), e.g. --eye-lonlat=-71.3033,44.2706.
    #[arg(long, allow_hyphen_values = true, conflicts_with = "eye")]
    pub eye_lonlat: Option<String>,
    /// Eye altitude, metres above sea level (default: the ground at the eye plus a quarter of
    /// the grid's smaller extent).
    #[arg(long, allow_hyphen_values = true)]
    pub altitude: Option<f64>,
    /// Degrees clockwise from north.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub heading: f64,
    /// Degrees above the horizon (negative looks down), −90..=90.
    #[arg(long, default_value_t = -30.0, allow_hyphen_values = true)]
    pub pitch: f64,
    /// Degrees, positive right wing down.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub roll: f64,
    /// Field of view, size, sampler and level of detail.
    #[command(flatten)]
    pub view: FlightViewArgs,
    /// Sky colour R,G,B (0-255) where no terrain is drawn (default: transparent).
    #[arg(long)]
    pub sky: Option<String>,
    /// Haze toward the horizon: the visibility in metres (contrast falls to 2 % there); the
    /// haze colour is --sky (default 190,205,220). Off by default.
    #[arg(long)]
    pub haze: Option<f32>,
    /// GST map cache budget, MiB (the maps Seed 000 Eq. 5-7 asks for are made resident and
    /// counted); with --texture streamed, the budget of the maps and chunk textures drawn.
    #[arg(long, default_value_t = 512)]
    pub cache_mb: u64,
    /// Output PNG.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write the eye-space depth as a one-channel OpenEXR.
    #[arg(long)]
    pub depth: Option<PathBuf>,
    /// Print the frame statistics as JSON on stdout (otherwise on stderr, unless --quiet).
    #[arg(long)]
    pub stats: bool,
}

pub(crate) fn parse_pair<T: std::str::FromStr>(s: &str, sep: char, what: &str) -> Result<(T, T)> {
    let mut it = s.split(sep).map(|t| t.trim().parse::<T>());
    match (it.next(), it.next(), it.next()) {
        (Some(Ok(a)), Some(Ok(b)), None) => Ok((a, b)),
        _ => usage(format!(
            "{what} {s}: expected two numbers separated by '{sep}'"
        )),
    }
}

/// The grid coordinates of `text`, a WGS 84 `LON,LAT` given as `flag` (`instead` names the option
/// that takes the grid's own coordinates, for the error on a grid with no place on the globe).
pub(crate) fn lonlat_point(
    g: &texmap_terrain::dem::Georef,
    text: &str,
    flag: &str,
    instead: &str,
) -> Result<(f64, f64)> {
    let (lon, lat) = parse_pair::<f64>(text, ',', flag)?;
    if !(lon.abs() <= 180.0 && lat.abs() <= 90.0) {
        return usage(format!(
            "{flag} {text}: expected longitude in −180..180 and latitude in −90..90"
        ));
    }
    match texmap_terrain::geodesy::Placement::of(g) {
        Some(p) => Ok(p.xy(lon, lat)),
        None => usage(format!(
            "{flag} {text}: the grid has no place on the globe ({:?}{}): give {instead} in its \
             own coordinates",
            g.crs,
            g.epsg.map(|c| format!(", EPSG:{c}")).unwrap_or_default()
        )),
    }
}

fn view_error(e: ViewError) -> anyhow::Error {
    match e {
        ViewError::NonFinite { .. }
        | ViewError::EyeOutside { .. }
        | ViewError::BelowGround { .. }
        | ViewError::BadParameter { .. }
        | ViewError::TextureBudget { .. }
        | ViewError::Camera(_) => UsageError(e.to_string()).into(),
        other => anyhow::Error::new(other),
    }
}

pub fn run(a: RenderArgs) -> Result<()> {
    let (sampler, (width, height)) = a.view.checked()?;
    let reference = sampler.is_none();
    // The reference draws no rasterised frame; the trilinear entry only fills the options.
    let sampler = sampler.unwrap_or(Sampler::Trilinear);
    let background = match &a.sky {
        None => [0, 0, 0, 0],
        Some(s) => {
            let v: Vec<u8> = s
                .split(',')
                .map(|t| t.trim().parse::<u8>())
                .collect::<Result<_, _>>()
                .or_else(|_| usage(format!("--sky {s}: expected R,G,B in 0..=255")))?;
            match v[..] {
                [r, g, b] => [r, g, b, 255],
                _ => return usage(format!("--sky {s}: expected R,G,B in 0..=255")),
            }
        }
    };
    let db = Database::open(&a.dir)?;
    let t0 = Instant::now();
    let terrain = FlightTerrain::open(&db, a.view.whole_texture_side(), a.view.chunk_budget())
        .map_err(view_error)?;
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;

    let mut view = FlightCamera::over(terrain.grid());
    let eye = match (&a.eye, &a.eye_lonlat) {
        (Some(e), _) => Some(parse_pair::<f64>(e, ',', "--eye")?),
        (None, Some(e)) => Some(lonlat_point(
            terrain.grid().georef(),
            e,
            "--eye-lonlat",
            "--eye X,Y",
        )?),
        (None, None) => None,
    };
    if let Some((x, y)) = eye {
        view.eye_x = x;
        view.eye_y = y;
        if a.altitude.is_none() {
            // Keep the default height above the ground, now at the new eye.
            let d = FlightCamera::over(terrain.grid());
            let g = terrain.grid().georef();
            let (c, r) = g.xy_to_sample(x, y);
            let (c0, r0) = g.xy_to_sample(d.eye_x, d.eye_y);
            let above = d.altitude
                - texmap_terrain::view::ground_height(terrain.grid(), c0, r0).unwrap_or(0.0);
            if let Some(h) = texmap_terrain::view::ground_height(
                terrain.grid(),
                c.clamp(0.0, (terrain.grid().width() - 1) as f64),
                r.clamp(0.0, (terrain.grid().height() - 1) as f64),
            ) {
                view.altitude = h + above;
            }
        }
    }
    if let Some(h) = a.altitude {
        view.altitude = h;
    }
    view.heading_deg = a.heading;
    view.pitch_deg = a.pitch;
    view.roll_deg = a.roll;
    view.hfov_deg = a.view.fov;
    view.width = width;
    view.height = height;
    // Validate the view before allocating the image.
    let camera = view.camera(terrain.grid()).map_err(view_error)?;
    let objects = a.view.objects.load(terrain.grid())?;

    let mut fb = Framebuffer::new(width, height)
        .map_err(|e| anyhow::anyhow!("--size {}: {e}", a.view.size))?;
    let opts = ViewOptions {
        pixel_error: a.view.pixel_error,
        sampler,
        background,
    };
    let t1 = Instant::now();
    let stats = if a.view.streamed() {
        let mut stream =
            texmap_terrain::stream::TextureStream::new(&db, a.cache_mb.saturating_mul(1 << 20))
                .map_err(view_error)?;
        terrain
            .render_streamed(
                &view,
                &opts,
                &mut stream,
                &mut fb,
                &mut FrameScratch::default(),
            )
            .map_err(view_error)?
    } else {
        terrain
            .render(&view, &opts, &mut fb, &mut FrameScratch::default())
            .map_err(view_error)?
    };
    let model_stats = objects.draw(&camera, sampler, &mut fb)?;
    let mut frame = if reference {
        // The chunk statistics above are the flight view's; the image is the reference's.
        let r = texmap_study::terrain::TerrainReference::with_models(&terrain, objects.placed())?;
        let cam = view.camera(terrain.grid()).map_err(view_error)?;
        let mut f = r.render(
            &cam,
            a.view.samples,
            [background[0], background[1], background[2]],
        )?;
        if background[3] == 0 {
            // Transparent where no terrain is, as the flight view draws it.
            for i in 0..f.len() {
                if !f.covered(i) {
                    f.color[i] = background;
                }
            }
        }
        f
    } else {
        fb.to_frame()
    };
    let render_ms = t1.elapsed().as_secs_f64() * 1e3;
    let mut cache = texmap_terrain::gst::GstCache::new(a.cache_mb.saturating_mul(1 << 20));
    let residency = terrain
        .make_resident(&view, &db, &mut cache)
        .map_err(view_error)?;
    let pixels_covered = frame.coverage_count();
    if let Some(v) = a.haze {
        let sky = if a.sky.is_some() {
            [background[0], background[1], background[2]]
        } else {
            [190, 205, 220]
        };
        let cam = view.camera(terrain.grid()).map_err(view_error)?;
        texmap_terrain::view::apply_haze(&mut frame, &cam, sky, v).map_err(view_error)?;
    }
    write_png(&frame, &a.output)?;
    if let Some(d) = &a.depth {
        write_depth_exr(&frame, d)?;
    }
    let v = json!({
        "eye": [view.eye_x, view.eye_y], "altitude": view.altitude,
        "heading": view.heading_deg, "pitch": view.pitch_deg, "roll": view.roll_deg,
        "fov": view.hfov_deg, "size": [width, height], "sampler": a.view.sampler, "reference_samples": reference.then_some(a.view.samples),
        "pixel_error": a.view.pixel_error,
        "frame": stats, "models": model_stats, "pixels_covered": pixels_covered, "haze_m": a.haze, "residency": residency,
        "load_ms": load_ms, "render_ms": render_ms,
    });
    let text = serde_json::to_string(&v).context("frame statistics")?;
    if a.stats {
        println!("{text}");
    } else if !crate::commands::quiet() {
        eprintln!("{text}");
    }
    Ok(())
}
