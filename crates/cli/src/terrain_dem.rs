//! `texmap terrain dem MODE`: gdaldem's products (hillshade, slope, aspect, colour relief, TRI,
//! TPI, roughness) of any DEM `terrain build` reads, as a GeoTIFF (and optionally a picture).
//! Glue only: the products are `texmap_terrain::dem_products`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use texmap_terrain::dem::{self, CrsKind, Grid, ReadOptions};
use texmap_terrain::dem_products::{
    ColorMatch, ColorTable, DemOptions, DemProduct, Gradient, HillshadeOptions, Product, Shading,
    TriAlg, color_relief, compute,
};

use crate::args::usage;
use crate::terrain_grid::{geotiff_options, require_geotiff};

const DEM_AFTER_HELP: &str = "\
Modes (what each is for):
  hillshade     a grey relief for a map's background or a photo's overlay (byte, no-data 0)
  slope         steepness in degrees or percent: landing sites, avalanche terrain, erosion
  aspect        the direction a slope faces: sun exposure, vegetation, snow (degrees)
  color-relief  heights coloured by a colour file: hypsometric tint maps (RGB or RGBA)
  tri           terrain ruggedness index: how much a sample differs from its neighbours
  tpi           topographic position index: ridges (> 0) and valleys (< 0)
  roughness     largest minus smallest height around a sample: surface roughness

Examples:
  texmap terrain dem hillshade N44W072.hgt -o hs.tif --png hs.png
  texmap terrain dem slope dem_utm.tif -o slope.tif --compute-edges
  texmap terrain dem color-relief colors.txt N44W072.hgt N44W071.hgt -o tint.tif --alpha --cog
      (as `gdaldem color-relief -alpha in.tif colors.txt tint.tif` of GDAL 3.6, pixel for pixel)

Each mode equals `gdaldem MODE` of GDAL 3.6.2 with the same options (crates/terrain/tests/
dem_products.rs compares them: the same values, a hillshade at most one grey level apart on about
one sample in 4000; --exact departs from GDAL 3.6.2, which matches only the lowest entry). Several DEM tiles are joined into one grid first, as `terrain
build --dem` joins them; a database directory from `terrain build` gives its full-resolution grid. Spacing: --scale has gdaldem's -s meaning (vertical units per horizontal
unit); without it a projected grid takes 1 and a geographic (degree) grid takes the true metres
per degree at each row's latitude, so slopes are right without -s 111120 (give --scale 111120 for
gdaldem's own output on such a grid). --cog writes a Cloud-Optimized GeoTIFF as the other terrain
commands do.";

/// gdaldem's products of one or more DEM tiles.
#[derive(Args, Debug)]
#[command(after_help = DEM_AFTER_HELP)]
pub struct DemArgs {
    #[command(subcommand)]
    pub mode: DemMode,
}

/// The mode, with its own options.
#[derive(Subcommand, Debug)]
pub enum DemMode {
    /// Shaded relief lit from one (or four) directions: a map's grey background (gdaldem hillshade).
    Hillshade(HillshadeArgs),
    /// Steepness in degrees (or percent): landing sites, avalanche terrain (gdaldem slope).
    Slope(SlopeArgs),
    /// The direction a slope faces, degrees clockwise from north (gdaldem aspect).
    Aspect(AspectArgs),
    /// Heights coloured by a colour file: hypsometric tints (gdaldem color-relief).
    ColorRelief(ColorReliefArgs),
    /// Terrain ruggedness index: how much a sample differs from its neighbours (gdaldem TRI).
    Tri(TriArgs),
    /// Topographic position index: ridges above 0, valleys below (gdaldem TPI).
    Tpi(CommonArgs),
    /// Largest minus smallest height of a sample's 3x3 window (gdaldem roughness).
    Roughness(CommonArgs),
}

/// What every mode takes.
#[derive(Args, Debug)]
pub struct CommonArgs {
    /// Elevation files (any format `terrain build --dem` reads); several tiles are joined. Or
    /// one database directory from `terrain build`: its full-resolution grid.
    #[arg(required = true, value_name = "DEM")]
    pub input: Vec<PathBuf>,
    /// Output GeoTIFF (.tif or .tiff), on the DEM's lattice and georeference.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Values at the grid's edges and beside no-data too (gdaldem -compute_edges).
    #[arg(long)]
    pub compute_edges: bool,
    /// Vertical units per horizontal unit of the georeference (gdaldem -s; 111120 for degrees
    /// and metres as gdaldem does it). Default: 1, or true metres per degree on a geographic grid.
    #[arg(short, long, value_name = "RATIO")]
    pub scale: Option<f64>,
    /// Write a Cloud-Optimized GeoTIFF (512x512 tiles, overviews).
    #[arg(long)]
    pub cog: bool,
    /// Also a PNG picture (float products stretched to grey).
    #[arg(long, value_name = "OUT.png")]
    pub png: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct HillshadeArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Vertical exaggeration (gdaldem -z).
    #[arg(short, long = "z-factor", value_name = "Z", default_value_t = 1.0)]
    pub z: f64,
    /// Light azimuth, degrees clockwise from north (gdaldem -az).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 315.0,
        allow_hyphen_values = true
    )]
    pub az: f64,
    /// Light altitude above the horizon, degrees (gdaldem -alt).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 45.0,
        allow_hyphen_values = true
    )]
    pub alt: f64,
    /// Gradient: Horn (smooth, default) or ZevenbergenThorne (sharper, for smooth terrain).
    #[arg(long, default_value = "Horn")]
    pub alg: String,
    /// Shade times slope: flat ground white, steep ground dark (gdaldem -combined).
    #[arg(long, conflicts_with_all = ["multidirectional", "igor"])]
    pub combined: bool,
    /// Four lights (225°, 270°, 315°, 360°) weighted by aspect (gdaldem -multidirectional).
    #[arg(long, conflicts_with = "igor")]
    pub multidirectional: bool,
    /// Igor's shading: slopes facing away from the light darker, no light altitude (gdaldem -igor).
    #[arg(long)]
    pub igor: bool,
}

#[derive(Args, Debug)]
pub struct SlopeArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Percent (100 · rise / run) instead of degrees (gdaldem -p).
    #[arg(short, long)]
    pub percent: bool,
    /// Gradient: Horn or ZevenbergenThorne.
    #[arg(long, default_value = "Horn")]
    pub alg: String,
}

#[derive(Args, Debug)]
pub struct AspectArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Degrees counter-clockwise from east instead of clockwise from north (gdaldem -trigonometric).
    #[arg(long)]
    pub trigonometric: bool,
    /// Flat ground 0 instead of no-data −9999 (gdaldem -zero_for_flat).
    #[arg(long)]
    pub zero_for_flat: bool,
    /// Gradient: Horn or ZevenbergenThorne.
    #[arg(long, default_value = "Horn")]
    pub alg: String,
}

#[derive(Args, Debug)]
pub struct ColorReliefArgs {
    /// gdaldem's colour file: `height R G B [A]` or `height name` a line; heights may be
    /// percentages (`50%`) or `nv` (no-data); separators space, tab, comma or colon.
    #[arg(value_name = "COLOR_FILE")]
    pub colors: PathBuf,
    #[command(flatten)]
    pub common: CommonArgs,
    /// Write an alpha band (RGBA; gdaldem -alpha).
    #[arg(long)]
    pub alpha: bool,
    /// Only heights equal to an entry are coloured, others transparent black
    /// (gdaldem -exact_color_entry; GDAL 3.6.2 matches only the lowest entry, we match each).
    #[arg(long, conflicts_with = "nearest")]
    pub exact: bool,
    /// The nearest entry's colour instead of interpolating (gdaldem -nearest_color_entry).
    #[arg(long)]
    pub nearest: bool,
}

#[derive(Args, Debug)]
pub struct TriArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Riley (terrestrial, default: root of summed squared differences) or Wilson (bathymetry:
    /// mean absolute difference).
    #[arg(long, default_value = "Riley")]
    pub alg: String,
}

fn gradient(alg: &str) -> Result<Gradient> {
    match alg.to_ascii_lowercase().as_str() {
        "horn" => Ok(Gradient::Horn),
        "zevenbergenthorne" => Ok(Gradient::ZevenbergenThorne),
        _ => usage(format!("--alg {alg}: expected Horn or ZevenbergenThorne")),
    }
}

/// What to compute, once the options are checked.
enum Job {
    Grid(Product, Gradient),
    Colors(ColorTable, ColorMatch, bool),
}

pub fn run(a: DemArgs) -> Result<()> {
    let (common, job) = match a.mode {
        DemMode::Hillshade(h) => {
            for (flag, v) in [("-z", h.z), ("--az", h.az), ("--alt", h.alt)] {
                if !v.is_finite() {
                    return usage(format!("{flag} {v}: expected a finite number"));
                }
            }
            if h.z <= 0.0 {
                return usage(format!("-z {}: expected a factor > 0", h.z));
            }
            let shading = if h.combined {
                Shading::Combined
            } else if h.multidirectional {
                Shading::Multidirectional
            } else if h.igor {
                Shading::Igor
            } else {
                Shading::Standard
            };
            let p = Product::Hillshade(HillshadeOptions {
                z: h.z,
                azimuth: h.az,
                altitude: h.alt,
                shading,
            });
            (h.common, Job::Grid(p, gradient(&h.alg)?))
        }
        DemMode::Slope(s) => {
            let g = gradient(&s.alg)?;
            let p = Product::Slope { percent: s.percent };
            (s.common, Job::Grid(p, g))
        }
        DemMode::Aspect(s) => {
            let g = gradient(&s.alg)?;
            let p = Product::Aspect {
                trigonometric: s.trigonometric,
                zero_for_flat: s.zero_for_flat,
            };
            (s.common, Job::Grid(p, g))
        }
        DemMode::Tri(t) => {
            let alg = match t.alg.to_ascii_lowercase().as_str() {
                "riley" => TriAlg::Riley,
                "wilson" => TriAlg::Wilson,
                _ => return usage(format!("--alg {}: expected Riley or Wilson", t.alg)),
            };
            (t.common, Job::Grid(Product::Tri(alg), Gradient::Horn))
        }
        DemMode::Tpi(c) => (c, Job::Grid(Product::Tpi, Gradient::Horn)),
        DemMode::Roughness(c) => (c, Job::Grid(Product::Roughness, Gradient::Horn)),
        DemMode::ColorRelief(c) => {
            let m = if c.exact {
                ColorMatch::Exact
            } else if c.nearest {
                ColorMatch::Nearest
            } else {
                ColorMatch::Linear
            };
            require_geotiff(&c.common.output)?;
            // The colour file is read before the DEM: a bad line fails fast (exit 1, the file
            // and line named).
            let table = ColorTable::read(&c.colors)?;
            (c.common, Job::Colors(table, m, c.alpha))
        }
    };
    if let Some(s) = common.scale
        && !(s.is_finite() && s > 0.0)
    {
        return usage(format!("--scale {s}: expected a ratio > 0"));
    }
    require_geotiff(&common.output)?;
    let grid = read_joined(&common.input)?;
    let t0 = Instant::now();
    let product = match &job {
        Job::Grid(p, g) => {
            if common.scale.is_none() && grid.georef().crs == CrsKind::Geographic {
                crate::note!(
                    "geographic grid: spacing in true metres per degree at each row's latitude \
                     (gdaldem would need -s 111120; --scale 111120 gives its output)"
                );
            }
            let o = DemOptions {
                gradient: *g,
                compute_edges: common.compute_edges,
                scale: common.scale,
            };
            compute(&grid, p, &o)?
        }
        Job::Colors(t, m, alpha) => color_relief(&grid, t, *m, *alpha),
    };
    let secs = t0.elapsed().as_secs_f64();
    write(&product, &grid, &common)?;
    crate::note!(
        "{} x {} samples in {secs:.2} s; wrote {}{}",
        product.width,
        product.height,
        common.output.display(),
        common
            .png
            .as_ref()
            .map(|p| format!(" and {}", p.display()))
            .unwrap_or_default()
    );
    Ok(())
}

/// The DEM files read and joined into one grid, as `terrain build --dem` joins them, or the
/// grid of a database directory from `terrain build` (mapped, as `terrain viewshed` reads it).
pub(crate) fn read_joined(paths: &[PathBuf]) -> Result<Grid> {
    if let Some(dir) = paths.iter().find(|p| p.is_dir()) {
        if paths.len() > 1 {
            return usage(format!(
                "{}: a database directory is read alone; give it without other DEMs",
                dir.display()
            ));
        }
        return Ok(texmap_terrain::db::Database::open(dir)?.grid_mapped()?);
    }
    let parts = dem::read_dems(paths, &ReadOptions::default())?;
    let (grid, overlaps) = dem::mosaic::mosaic(parts)?;
    crate::terrain::note_overlaps(&overlaps);
    Ok(grid)
}

/// The GeoTIFF (written under a temporary name and renamed), then the picture; when the picture
/// cannot be written the GeoTIFF is removed, so a failure leaves no output.
fn write(product: &DemProduct, grid: &Grid, common: &CommonArgs) -> Result<()> {
    product.write_geotiff(&common.output, grid, &geotiff_options(common.cog))?;
    if let Some(p) = &common.png {
        let img = product.image();
        let written = crate::output::write_atomic(p, |tmp| {
            img.save_with_format(tmp, image::ImageFormat::Png)
                .with_context(|| format!("cannot write {}", p.display()))
        });
        if written.is_err() {
            let _ = std::fs::remove_file(&common.output);
        }
        written?;
    }
    Ok(())
}
