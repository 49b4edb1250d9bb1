//! `texmap terrain viewshed`: what an observer on the terrain sees, as a GeoTIFF on the grid's
//! lattice (and optionally a picture). Glue only: the viewshed is `texmap_terrain::viewshed`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{ArgGroup, Args};
use texmap_terrain::TerrainError;
use texmap_terrain::db::Database;
use texmap_terrain::dem::{self, ReadOptions};
use texmap_terrain::viewshed::{
    MaskValues, Method, Observer, Output, ViewshedOptions, viewshed_with_progress,
};

use crate::args::{UsageError, usage};
use crate::terrain_grid::{geotiff_options, require_geotiff};
use crate::terrain_view::{lonlat_point, parse_pair};

const VIEWSHED_AFTER_HELP: &str = "\
Examples:
  texmap terrain viewshed N44W072.hgt --observer-lonlat=-71.3033,44.2706 -o summit.tif --png summit.png
  texmap terrain viewshed area.db --observer 316135,4904505 --observer-height 30 --max-distance 20000 -o tower.tif
  texmap terrain viewshed dem.tif --observer 316135,4904505 --method gdal -o vs.tif
      (the last as `gdal_viewshed -ox 316135 -oy 4904505 dem.tif vs.tif` of GDAL 3.6, cell for cell)

The output has the input grid's size and georeference (gdal_viewshed cuts it to --max-distance's
square): 255 visible, 0 hidden, 0 beyond --max-distance or on no-data (--visible, --invisible,
--out-of-range change them); with --mode dem or ground, the float32 elevation or height above the
ground a target needs to be seen (nan beyond the range and on no-data). --cog lays the file out
as `gdal_translate -of COG -co COMPRESS=DEFLATE` does: a mask with -co PREDICTOR=YES
-co RESAMPLING=NEAREST, heights with -co PREDICTOR=FLOATING_POINT -co RESAMPLING=AVERAGE.";

/// Compute the viewshed of an observer standing on a grid or database.
#[derive(Args, Debug)]
#[command(
    after_help = VIEWSHED_AFTER_HELP,
    group(ArgGroup::new("where").required(true).args(["observer", "observer_lonlat", "observer_cell"]))
)]
pub struct ViewshedArgs {
    /// An elevation file (any format `terrain build` reads: GeoTIFF, .hgt, DTED, .asc, .flt, .bil,
    /// PNG) or a database directory from `terrain build`.
    pub input: PathBuf,
    /// The observer at X,Y in the grid's georeference; it stands at the centre of the sample whose
    /// cell holds the point.
    #[arg(long, allow_hyphen_values = true, value_name = "X,Y")]
    pub observer: Option<String>,
    /// The observer at WGS 84 longitude,latitude in degrees, whatever the grid's system
    /// (geographic, UTM or Web Mercator), e.g. --observer-lonlat=-71.3033,44.2706.
    #[arg(long, allow_hyphen_values = true, value_name = "LON,LAT")]
    pub observer_lonlat: Option<String>,
    /// The observer at sample COL,ROW (0-based, row 0 the northern edge).
    #[arg(long, value_name = "COL,ROW")]
    pub observer_cell: Option<String>,
    /// The eye's height above the observer's ground, metres (gdal_viewshed -oz).
    #[arg(
        long,
        value_name = "M",
        default_value_t = 2.0,
        allow_hyphen_values = true
    )]
    pub observer_height: f64,
    /// The target's height above each cell's ground, metres (-tz).
    #[arg(
        long,
        value_name = "M",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub target_height: f64,
    /// Cells farther than M ground metres (on a geographic grid too) are out of range (-md).
    #[arg(long, value_name = "M")]
    pub max_distance: Option<f64>,
    /// Curvature and refraction: heights drop by C·d²/(2·6378137 m) at distance d (-cc). 0.85714
    /// is the earth with standard refraction, 1 the bare earth, 0 a flat earth.
    #[arg(
        long,
        value_name = "C",
        default_value_t = 0.85714,
        allow_hyphen_values = true
    )]
    pub curvature: f64,
    /// wang: gdal_viewshed's reference-plane sweep (Wang, Robinson & White 2000), one pass;
    /// gdal: the same bit for bit as GDAL 3.6, whose cells next to the observer take the
    /// observer's ground as their horizon (hiding most slopes below a summit); exact: a sight
    /// line to every cell, heights interpolated at each grid-line crossing (slower).
    #[arg(long, default_value = "wang")]
    pub method: String,
    /// normal: a visibility mask; dem: the elevation a target must reach to be seen; ground: the
    /// height above the ground it must have (-om NORMAL, DEM, GROUND).
    #[arg(long, default_value = "normal")]
    pub mode: String,
    /// Mask value of visible cells (-vv).
    #[arg(long, default_value_t = 255)]
    pub visible: u8,
    /// Mask value of hidden cells (-iv).
    #[arg(long, default_value_t = 0)]
    pub invisible: u8,
    /// Mask value beyond --max-distance and on no-data (-ov).
    #[arg(long, default_value_t = 0)]
    pub out_of_range: u8,
    /// Output GeoTIFF (.tif or .tiff).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Write a Cloud-Optimized GeoTIFF (512x512 tiles, overviews: masks nearest, heights
    /// averaged), so QGIS, TiTiler or GDAL's /vsicurl/ read over HTTP only what they show.
    #[arg(long)]
    pub cog: bool,
    /// Also a PNG picture: the shaded relief, visible cells yellow, hidden ones dark, cells beyond
    /// the range grey, the observer red (at most 4096 pixels a side).
    #[arg(long)]
    pub png: Option<PathBuf>,
}

/// Observer and parameter errors are the caller's to fix: usage errors (exit code 2).
fn viewshed_error(e: TerrainError) -> anyhow::Error {
    match e {
        TerrainError::ObserverOutside { .. }
        | TerrainError::ObserverNoData { .. }
        | TerrainError::BadParameter { .. } => UsageError(e.to_string()).into(),
        other => anyhow::Error::new(other),
    }
}

pub fn run(a: ViewshedArgs) -> Result<()> {
    let Some(method) = Method::by_name(&a.method) else {
        return usage(format!(
            "--method {}: expected one of {}",
            a.method,
            Method::NAMES.join(", ")
        ));
    };
    let output = match a.mode.to_ascii_lowercase().as_str() {
        "normal" => Output::Visibility,
        "dem" => Output::Elevation,
        "ground" => Output::Height,
        m => return usage(format!("--mode {m}: expected normal, dem or ground")),
    };
    for (flag, v) in [
        ("--observer-height", a.observer_height),
        ("--target-height", a.target_height),
        ("--curvature", a.curvature),
    ] {
        if !v.is_finite() {
            return usage(format!("{flag} {v}: expected a finite number"));
        }
    }
    if let Some(d) = a.max_distance
        && !(d.is_finite() && d > 0.0)
    {
        return usage(format!("--max-distance {d}: expected metres > 0"));
    }
    require_geotiff(&a.output)?;
    // Parse the observer's syntax before reading anything.
    let cell = a
        .observer_cell
        .as_deref()
        .map(|s| parse_pair::<u32>(s, ',', "--observer-cell"))
        .transpose()?;
    let map = a
        .observer
        .as_deref()
        .map(|s| parse_pair::<f64>(s, ',', "--observer"))
        .transpose()?;
    let (grid, tint) = if a.input.is_dir() {
        let db = Database::open(&a.input)?;
        (db.grid_mapped()?, db.tint())
    } else {
        let grid = dem::read_dem(&a.input, &ReadOptions::default())?;
        (grid, texmap_terrain::relief::Tint::Ramp)
    };
    let observer = match (cell, map, &a.observer_lonlat) {
        (Some((col, row)), _, _) => Observer::Cell { col, row },
        (_, Some((x, y)), _) => Observer::Map { x, y },
        (_, _, Some(s)) => {
            let (x, y) = lonlat_point(grid.georef(), s, "--observer-lonlat", "--observer X,Y")?;
            Observer::Map { x, y }
        }
        _ => return usage("give --observer, --observer-lonlat or --observer-cell"),
    };
    let opts = ViewshedOptions {
        observer_height: a.observer_height,
        target_height: a.target_height,
        max_distance: a.max_distance,
        curvature: a.curvature,
        method,
        output,
    };
    let values = MaskValues {
        visible: a.visible,
        invisible: a.invisible,
        out_of_range: a.out_of_range,
    };
    let pb = crate::commands::progress(grid.height() as u64, "viewshed rows");
    let t0 = Instant::now();
    let vs = viewshed_with_progress(&grid, observer, &opts, |done, _| pb.set_position(done))
        .map_err(viewshed_error)?;
    pb.finish_and_clear();
    let secs = t0.elapsed().as_secs_f64();
    let layout = geotiff_options(a.cog);
    vs.write_geotiff_with(&a.output, &values, &layout)?;
    if let Some(p) = &a.png {
        let img = vs.image_tinted(&grid, &tint, 4096);
        crate::output::write_atomic(p, |tmp| {
            img.save_with_format(tmp, image::ImageFormat::Png)
                .with_context(|| format!("cannot write {}", p.display()))
        })?;
    }
    let n = vs.counts();
    let cells = vs.width as u64 * vs.height as u64;
    let pct = |k: u64| 100.0 * k as f64 / cells.max(1) as f64;
    let (oc, or) = vs.observer;
    crate::note!(
        "observer at sample ({oc}, {or}), eye {:.1} m above sea level: {:.2} % of the {cells} \
         cells visible ({}), {:.2} % hidden, {} beyond the range, {} no-data ({} method, {:.2} s)",
        vs.eye,
        pct(n.visible),
        n.visible,
        pct(n.invisible),
        n.out_of_range,
        n.nodata,
        method.name(),
        secs
    );
    crate::note!(
        "wrote {}{}",
        a.output.display(),
        a.png
            .as_ref()
            .map(|p| format!(" and {}", p.display()))
            .unwrap_or_default()
    );
    Ok(())
}
