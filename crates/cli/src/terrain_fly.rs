//! `texmap terrain fly` (a flight path or an orbit to PNG frames or a movie, with a progress bar)
//! and `texmap terrain compare` (the sampler study against the ray-traced reference). Glue only:
//! paths are `texmap_terrain::flight`, the study is `texmap_study::terrain`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use indicatif::ProgressBar;
use serde_json::json;
use texmap_core::frame::Frame;
use texmap_study::terrain::{self as study, StudyOptions, TerrainReference};
use texmap_terrain::db::Database;
use texmap_terrain::flight::{self, PathView};
use texmap_terrain::view::{FlightCamera, FlightTerrain, FrameScratch, ViewOptions};

use crate::args::usage;
use crate::movie::Sink;

/// Fly a path over the terrain database and write every frame.
#[derive(Args, Debug)]
pub struct FlyArgs {
    /// Database directory (from `texmap terrain build`).
    pub dir: PathBuf,
    /// Path file: CSV (x,y,altitude,heading,pitch[,roll[,fov]] per line, optional header), a
    /// JSON array of {x, y, altitude, heading, pitch, roll?, fov?}, or a recorded flight: a GPX
    /// track (.gpx: GPS units, Strava, gpxpy, ogr2ogr) or an IGC flight log (.igc: gliding and
    /// paragliding loggers), flown looking along the track and banking in its turns.
    #[arg(long, conflicts_with = "orbit")]
    pub path: Option<PathBuf>,
    /// A GPX/IGC track replayed on its own clock: SPEEDUP track seconds per movie second (one
    /// frame every SPEEDUP/--fps seconds of the track); without it one frame per fix.
    #[arg(long, value_name = "SPEEDUP")]
    pub speedup: Option<f64>,
    /// Pitch of the views along a GPX/IGC track, degrees (negative looks down).
    #[arg(long, allow_hyphen_values = true, default_value_t = -10.0)]
    pub track_pitch: f64,
    /// Metres added to a GPX/IGC track's altitudes (a view from above the pilot's eye).
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.0)]
    pub above: f64,
    /// Orbit instead of a path: FRAMES[,RADIUS[,HEIGHT[,PITCH]]] — FRAMES views on a circle around
    /// the grid's centre looking at it; radius and height above the ground as fractions of the
    /// grid's smaller extent (defaults 0.3 and 0.1), pitch in degrees (default −25).
    #[arg(long, allow_hyphen_values = true)]
    pub orbit: Option<String>,
    /// Field of view, size, sampler and level of detail.
    #[command(flatten)]
    pub view: crate::terrain_view::FlightViewArgs,
    /// Frames per second of a movie output.
    #[arg(long, default_value_t = 25.0)]
    pub fps: f64,
    /// Write one JSON line per frame: the view, the frame's statistics (chunks per level,
    /// triangles) and the GST maps Seed 000 Eq. 5-7 made resident along the flight (needed,
    /// loaded, cache hits, evictions, resident bytes).
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// GST map cache budget along the flight, MiB; with --texture streamed, the budget of the
    /// maps and chunk textures the frames are drawn from.
    #[arg(long, default_value_t = 512)]
    pub cache_mb: u64,
    /// Output: PNG frames (frames/%04d.png) or a movie (.apng, .mp4, .webm, .gif).
    #[arg(short, long)]
    pub output: PathBuf,
}

/// Compare every sampler with the ray-traced reference along a flight path.
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// Database directory (from `texmap terrain build`).
    #[arg(required_unless_present = "builtin")]
    pub dir: Option<PathBuf>,
    /// Use the built-in deterministic terrain instead of a database: a SIDE² grid of hills with a
    /// synthetic 4·(SIDE−1)² photo (e.g. 257).
    #[arg(long, conflicts_with = "dir")]
    pub builtin: Option<u32>,
    /// Path file (as for `fly`); default: the built-in study path (look-down, low, grazing, turn,
    /// slow pass; 26 views).
    #[arg(long)]
    pub path: Option<PathBuf>,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "320x240")]
    pub size: String,
    /// Horizontal field of view, degrees.
    #[arg(long, default_value_t = 45.0)]
    pub fov: f64,
    /// Reference samples per pixel axis (n x n per pixel).
    #[arg(long, default_value_t = 4)]
    pub samples: u32,
    /// Samplers to compare, comma-separated: nearest, bilinear, trilinear, span3, span4, aniso,
    /// quadratic3 (quadratic interpolation on each level's 3x3 neighbourhood); default: all.
    #[arg(long)]
    pub samplers: Option<String>,
    /// Refine chunks while their screen-space error exceeds this many pixels.
    #[arg(long, default_value_t = 1.0)]
    pub pixel_error: f32,
    /// Largest side of the whole-terrain texture assembled from the GST pyramid.
    #[arg(long, default_value_t = 4096)]
    pub max_texture: u32,
    /// Output directory: results.csv, results.json, summary.md, and the charts
    /// error_vs_pitch and error_vs_altitude as .svg and .png.
    #[arg(long)]
    pub out: PathBuf,
}

fn progress_bar(len: usize, msg: &'static str) -> ProgressBar {
    crate::commands::progress(len as u64, msg)
}

/// The orbit of `--orbit FRAMES[,RADIUS[,HEIGHT[,PITCH]]]`.
fn parse_orbit(
    s: &str,
    terrain: &FlightTerrain,
    template: &FlightCamera,
) -> Result<Vec<FlightCamera>> {
    let bad = || {
        usage(format!(
            "--orbit {s}: expected FRAMES[,RADIUS[,HEIGHT[,PITCH]]]"
        ))
    };
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.is_empty() || parts.len() > 4 {
        return bad();
    }
    let Ok(frames) = parts[0].parse::<u32>() else {
        return bad();
    };
    if frames == 0 || frames > 100_000 {
        return usage(format!("--orbit {s}: frames must be 1..=100000"));
    }
    let mut v = [0.3, 0.1, -25.0];
    for (k, p) in parts[1..].iter().enumerate() {
        match p.parse::<f64>() {
            Ok(x) if x.is_finite() => v[k] = x,
            _ => return bad(),
        }
    }
    if !(v[0] >= 0.0 && v[1] > 0.0 && v[2].abs() <= 90.0) {
        return usage(format!(
            "--orbit {s}: expected radius ≥ 0, height > 0 and |pitch| ≤ 90"
        ));
    }
    Ok(flight::orbit(
        terrain.grid(),
        template,
        frames,
        v[0],
        v[1],
        v[2],
    ))
}

/// Open a database as a flight terrain.
fn open(
    dir: &std::path::Path,
    max_texture: u32,
    chunk_budget: u64,
) -> Result<(Database, FlightTerrain)> {
    let db = Database::open(dir)?;
    let terrain = FlightTerrain::open(&db, max_texture, chunk_budget)
        .with_context(|| format!("{}: cannot open the terrain", dir.display()))?;
    Ok((db, terrain))
}

pub fn run_fly(a: FlyArgs) -> Result<()> {
    let (sampler, (width, height)) = a.view.checked()?;
    if a.path.is_none() && a.orbit.is_none() {
        return usage("terrain fly: give --path FILE or --orbit FRAMES[,RADIUS[,HEIGHT[,PITCH]]]");
    }
    let (db, terrain) = open(&a.dir, a.view.whole_texture_side(), a.view.chunk_budget())?;
    let template = FlightCamera {
        hfov_deg: a.view.fov,
        width,
        height,
        ..FlightCamera::over(terrain.grid())
    };
    let is_track = a
        .path
        .as_deref()
        .is_some_and(texmap_terrain::track::is_track);
    if !is_track && (a.speedup.is_some() || a.above != 0.0 || a.track_pitch != -10.0) {
        return usage("--speedup, --track-pitch and --above apply to a GPX or IGC --path");
    }
    let views = match (&a.path, &a.orbit) {
        (Some(p), _) if is_track => {
            use texmap_terrain::track;
            if !(a.above.is_finite() && a.track_pitch.abs() < 90.0) {
                return usage("--track-pitch: expected within ±90 degrees; --above: metres");
            }
            let t = track::read_track(p)?;
            let opts = track::TrackOptions {
                speedup: a.speedup,
                fps: a.fps,
                pitch_deg: a.track_pitch,
                above: a.above,
            };
            let v = track::track_views(&t, terrain.grid(), &template, &opts)?;
            if v.outside > 0 {
                crate::note!(
                    "{}: {} of {} frames left out: their eye lies outside the grid",
                    p.display(),
                    v.outside,
                    v.outside + v.views.len()
                );
            }
            if v.lifted > 0 {
                crate::note!(
                    "{}: {} eyes lifted to 2 m above the ground",
                    p.display(),
                    v.lifted
                );
            }
            v.views
        }
        (Some(p), _) => flight::read_path_for(p, &template, terrain.grid())?,
        (None, Some(o)) => parse_orbit(o, &terrain, &template)?,
        (None, None) => unreachable!("checked above"),
    };
    for (i, v) in views.iter().enumerate() {
        v.camera(terrain.grid())
            .with_context(|| format!("view {i} of the orbit"))?;
    }
    let objects = a.view.objects.load(terrain.grid())?;
    let mut sink = Sink::new(&a.output, views.len(), a.fps, false, None)?;
    let refr = if sampler.is_none() {
        Some(TerrainReference::with_models(&terrain, objects.placed())?)
    } else {
        None
    };
    let pb = progress_bar(views.len(), "frames");
    let t0 = Instant::now();
    let mut scratch = FrameScratch::default();
    let mut triangles = 0u64;
    let mut cache = texmap_terrain::gst::GstCache::new(a.cache_mb.saturating_mul(1 << 20));
    let mut stream = if a.view.streamed() {
        Some(
            texmap_terrain::stream::TextureStream::new(&db, a.cache_mb.saturating_mul(1 << 20))
                .context("--texture streamed")?,
        )
    } else {
        None
    };
    let mut lines = String::new();
    for (i, v) in views.iter().enumerate() {
        let mut frame_stats = None;
        let mut model_stats = None;
        let frame: Frame = match (&refr, sampler) {
            (Some(r), _) => r.render_view(&terrain, v, a.view.samples)?,
            (None, Some(s)) => {
                let mut fb = texmap_raster::Framebuffer::new(width, height)?;
                let opts = ViewOptions {
                    pixel_error: a.view.pixel_error,
                    sampler: s,
                    ..ViewOptions::default()
                };
                let st = match &mut stream {
                    Some(s) => terrain.render_streamed(v, &opts, s, &mut fb, &mut scratch),
                    None => terrain.render(v, &opts, &mut fb, &mut scratch),
                }
                .with_context(|| format!("view {i}"))?;
                triangles += st.triangles;
                frame_stats = Some(st);
                let cam = v.camera(terrain.grid())?;
                model_stats = Some(objects.draw(&cam, s, &mut fb)?);
                fb.to_frame()
            }
            (None, None) => unreachable!("sampler checked above"),
        };
        sink.write(i, &frame, false)?;
        if a.stats.is_some() {
            let residency = terrain
                .make_resident(v, &db, &mut cache)
                .with_context(|| format!("view {i}: GST maps"))?;
            let line = json!({
                "frame": i, "eye": [v.eye_x, v.eye_y], "altitude": v.altitude,
                "heading": v.heading_deg, "pitch": v.pitch_deg, "roll": v.roll_deg,
                "stats": frame_stats, "models": model_stats, "residency": residency,
                "pixels_covered": frame.coverage_count(),
            });
            lines.push_str(&line.to_string());
            lines.push('\n');
        }
        pb.inc(1);
    }
    if let Some(p) = &a.stats {
        std::fs::write(p, lines).with_context(|| format!("cannot write {}", p.display()))?;
    }
    let movie = sink.finish()?;
    pb.finish_and_clear();
    let secs = t0.elapsed().as_secs_f64();
    let v = json!({
        "frames": views.len(), "size": [width, height], "sampler": a.view.sampler,
        "seconds": secs, "ms_per_frame": 1e3 * secs / views.len() as f64,
        "triangles": triangles, "movie": movie.map(|p| p.display().to_string()),
    });
    if !crate::commands::quiet() {
        eprintln!("{v}");
    }
    Ok(())
}

pub fn run_compare(a: CompareArgs) -> Result<()> {
    let (width, height) = crate::scene::parse_size(&a.size)?;
    if !(1..=texmap_reftrace::MAX_SAMPLES_PER_AXIS).contains(&a.samples) {
        return usage(format!(
            "--samples {}: expected 1..={}",
            a.samples,
            texmap_reftrace::MAX_SAMPLES_PER_AXIS
        ));
    }
    let known = study::study_sampler_names();
    let samplers: Vec<String> = match &a.samplers {
        None => known.clone(),
        Some(s) => s.split(',').map(|t| t.trim().to_string()).collect(),
    };
    if let Some(bad) = samplers.iter().find(|s| !known.contains(s)) {
        return usage(format!(
            "--samplers: {bad} is not one of {}",
            known.join(", ")
        ));
    }
    if !(a.pixel_error.is_finite() && a.pixel_error > 0.0) {
        return usage(format!("--pixel-error {}: expected > 0", a.pixel_error));
    }
    let terrain = match (&a.dir, a.builtin) {
        (_, Some(side)) => study::builtin_terrain(side, 4 * side.saturating_sub(1))?,
        (Some(dir), None) => {
            open(
                dir,
                a.max_texture,
                texmap_terrain::view::DEFAULT_CHUNK_BUDGET,
            )?
            .1
        }
        (None, None) => return usage("terrain compare: give a database DIR or --builtin SIDE"),
    };
    let template = FlightCamera {
        hfov_deg: a.fov,
        width,
        height,
        ..FlightCamera::over(terrain.grid())
    };
    let path: Vec<PathView> = match &a.path {
        Some(p) => flight::read_path_for(p, &template, terrain.grid())?
            .into_iter()
            .map(|view| PathView {
                segment: "path",
                view,
            })
            .collect(),
        None => flight::study_path(terrain.grid(), &template),
    };
    let reference = TerrainReference::new(&terrain)?;
    let opts = StudyOptions {
        samples_per_axis: a.samples,
        pixel_error: a.pixel_error,
        samplers,
    };
    let pb = progress_bar(path.len(), "views");
    let result = study::run_study(&terrain, &reference, &path, &opts, &mut |done, _| {
        pb.set_position(done as u64)
    });
    pb.finish_and_clear();
    let s = result?;
    let written = study::write_study(&a.out, &s)?;
    print!("{}", study::summary_markdown(&s));
    for p in written {
        crate::note!("wrote {}", p.display());
    }
    Ok(())
}
