//! `texmap terrain grid`: lidar point clouds (LAS 1.0–1.4, LAZ) gridded into a DEM written as a
//! float32 GeoTIFF, and the `--lidar-*` options `terrain build` shares. Glue only: the reader and
//! the gridding are `texmap_terrain::dem::{las, lidar}`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use texmap_terrain::TerrainError;
use texmap_terrain::dem::lidar::{
    ClassSet, CloudReport, GridReport, LidarMethod, LidarOptions, grid_cloud, read_cloud,
};
use texmap_terrain::dem::{self, CrsKind, DemFormat, Grid, ReadOptions};

use crate::args::{UsageError, usage};

const GRID_AFTER_HELP: &str = "\
Examples:
  texmap terrain grid survey.laz -o dem.tif
  texmap terrain grid survey.laz -o dem.tif --cog   # for QGIS, TiTiler, GDAL /vsicurl/ over HTTP
  texmap terrain grid tiles/*.laz -o dem.tif --lidar-cell 1 --lidar-method idw --lidar-fill 3
  texmap terrain grid survey.las -o dsm.tif --lidar-classes 1,2,3,4,5,6 --lidar-method max
  texmap terrain grid survey.laz -o density.tif --lidar-classes 2 --lidar-method count   # gaps in the ground
  texmap terrain build --dem survey.laz --lidar-cell 2 --out area.db

The cells are squares of --lidar-cell metres aligned to multiples of it (so tiles gridded apart
share a lattice). A point counts in every cell whose centre lies strictly within --lidar-radius
(default cell x 1.414) of it: PDAL writers.gdal's rule, with its origin_x, origin_y, width and
height set to this lattice. gdal_grid -a average:radius1=R:radius2=R (minimum, maximum,
invdist:power=1) on the same points and nodes gives the same heights but where a point lies
exactly R from a centre, which GDAL counts. Several files are one cloud: the cells along a
tile's edge see the points across it. Without a GeoKey directory or WKT record in the files the
grid is in a local frame. --cog writes what `gdal_translate -of COG -co COMPRESS=DEFLATE
-co PREDICTOR=FLOATING_POINT -co RESAMPLING=AVERAGE` writes: overviews halving until one tile
holds the grid, each the average of the level before, empty cells left out.";

/// How lidar point clouds are gridded (`terrain grid`, and `terrain build --dem x.laz`).
#[derive(Args, Debug, Clone)]
#[command(next_help_heading = "Lidar point clouds (.las, .laz)")]
pub struct LidarArgs {
    /// Cell side in metres (the cloud's units), e.g. --lidar-cell 1. Default: the side holding
    /// about two of the chosen points per cell, rounded to 1, 2 or 5 times a power of ten.
    #[arg(long, value_name = "M")]
    pub lidar_cell: Option<f64>,
    /// A cell's height from the points within the radius of its centre (PDAL writers.gdal's
    /// output_type): mean, min (the ground under low vegetation), max (a surface model: canopy
    /// and roofs) or idw (inverse-distance weighted), e.g. --lidar-method idw. For quality
    /// control, `terrain grid` also writes count (points per cell: the survey's density and its
    /// gaps) and stdev (the population standard deviation of their heights: roughness, or
    /// objects left among the ground points); these are not heights, so not for a database.
    #[arg(long, value_name = "METHOD", default_value = "mean")]
    pub lidar_method: String,
    /// The ASPRS classes to grid, e.g. --lidar-classes 2,9 (ground and water). Default: ground
    /// (2) when the cloud has any, otherwise every class but noise (7, 18). Withheld points are
    /// never gridded.
    #[arg(long, value_name = "LIST")]
    pub lidar_classes: Option<String>,
    /// Only the last return of each pulse, the one that reached furthest down, e.g.
    /// --lidar-last-returns --lidar-classes 1 for an unclassified cloud under trees.
    #[arg(long)]
    pub lidar_last_returns: bool,
    /// Fill empty cells from the non-empty ones within N cells, weighted by one over their
    /// distance in cells (PDAL's window_size), e.g. --lidar-fill 3; 0 leaves them no-data.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub lidar_fill: u32,
    /// Search radius around a cell's centre in metres (PDAL's radius), e.g. --lidar-radius 2.
    /// Default: the cell side x 1.414.
    #[arg(long, value_name = "M")]
    pub lidar_radius: Option<f64>,
    /// Inverse-distance power of --lidar-method idw, e.g. --lidar-power 2 (PDAL's default 1;
    /// gdal_grid's invdist uses 2).
    #[arg(long, value_name = "P", default_value_t = 1.0)]
    pub lidar_power: f64,
}

impl LidarArgs {
    /// The options, bad values being usage errors.
    pub fn options(&self) -> Result<LidarOptions> {
        let Some(method) = LidarMethod::by_name(&self.lidar_method) else {
            return usage(format!(
                "--lidar-method {}: expected one of {}",
                self.lidar_method,
                LidarMethod::NAMES.join(", ")
            ));
        };
        if let Some(c) = self.lidar_cell
            && !(c.is_finite() && c > 0.0)
        {
            return usage(format!("--lidar-cell {c}: expected metres > 0, e.g. 1"));
        }
        if let Some(r) = self.lidar_radius
            && !(r.is_finite() && r > 0.0)
        {
            return usage(format!("--lidar-radius {r}: expected metres > 0"));
        }
        if !(self.lidar_power.is_finite() && self.lidar_power > 0.0) {
            return usage(format!(
                "--lidar-power {}: expected a power > 0, e.g. 1 or 2",
                self.lidar_power
            ));
        }
        if self.lidar_fill > texmap_terrain::dem::lidar::MAX_REACH {
            return usage(format!(
                "--lidar-fill {}: expected 0 to {} cells",
                self.lidar_fill,
                texmap_terrain::dem::lidar::MAX_REACH
            ));
        }
        let classes = match &self.lidar_classes {
            None => None,
            Some(s) => match ClassSet::parse(s) {
                Ok(c) if !c.is_empty() => Some(c),
                Ok(_) => return usage("--lidar-classes: expected at least one class"),
                Err(e) => return usage(format!("--lidar-classes {s}: {e}")),
            },
        };
        Ok(LidarOptions {
            cell: self.lidar_cell,
            method,
            radius: self.lidar_radius,
            power: self.lidar_power,
            classes,
            last_returns: self.lidar_last_returns,
            fill: self.lidar_fill,
        })
    }

    /// Whether any option differs from its default.
    fn given(&self) -> bool {
        self.lidar_cell.is_some()
            || !self.lidar_method.eq_ignore_ascii_case("mean")
            || self.lidar_classes.is_some()
            || self.lidar_last_returns
            || self.lidar_fill != 0
            || self.lidar_radius.is_some()
            || self.lidar_power != 1.0
    }
}

/// Grid lidar point clouds (LAS 1.0-1.4, LAZ) into an elevation grid, written as a GeoTIFF.
#[derive(Args, Debug)]
#[command(after_help = GRID_AFTER_HELP)]
pub struct GridArgs {
    /// LAS or LAZ files (.las, .laz), gridded together as one cloud (a survey's tiles).
    #[arg(required = true, num_args = 1..)]
    pub input: Vec<PathBuf>,
    /// Output GeoTIFF (.tif or .tiff): float32 heights (or counts, standard deviations), empty
    /// cells nan (GDAL's no-data tag; a count is 0 there), in the cloud's coordinate system.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Write a Cloud-Optimized GeoTIFF (512x512 tiles, overviews averaging the heights), so QGIS,
    /// TiTiler or GDAL's /vsicurl/ read over HTTP only the tiles and zoom level they show.
    #[arg(long)]
    pub cog: bool,
    #[command(flatten)]
    pub lidar: LidarArgs,
}

fn is_lidar(path: &Path) -> bool {
    DemFormat::from_path(path).or_else(|| DemFormat::sniff(path)) == Some(DemFormat::Las)
}

/// Parameter errors are the caller's to fix: usage errors (exit code 2).
fn lidar_error(e: TerrainError) -> anyhow::Error {
    match e {
        TerrainError::BadParameter { .. } => UsageError(e.to_string()).into(),
        other => anyhow::Error::new(other),
    }
}

/// Read and grid `paths` as one cloud, noting what was read and gridded and how long each took.
fn grid_noting(paths: &[PathBuf], opts: &LidarOptions) -> Result<(Grid, CloudReport)> {
    let sp = crate::commands::spinner("reading the point cloud");
    let t0 = Instant::now();
    let (cloud, report) = read_cloud(paths, opts).map_err(lidar_error)?;
    let read = t0.elapsed().as_secs_f64();
    sp.set_message("gridding the point cloud");
    let t1 = Instant::now();
    let (grid, g) =
        grid_cloud(&cloud, &report.source, report.crs, report.epsg, opts).map_err(lidar_error)?;
    let gridded = t1.elapsed().as_secs_f64();
    sp.finish_and_clear();
    drop(cloud);
    notes(&report, &g, opts.method, (read, gridded));
    Ok((grid, report))
}

/// What was read and gridded, for the terminal.
fn notes(cloud: &CloudReport, g: &GridReport, method: LidarMethod, (read, gridded): (f64, f64)) {
    let rate = |n: u64, s: f64| n as f64 / s.max(1e-9) / 1e6;
    crate::note!(
        "{}: {} points ({} withheld) read in {:.2} s ({:.1} M points/s); {} gridded: {}",
        cloud.source,
        cloud.points_read,
        cloud.withheld,
        read,
        rate(cloud.points_read, read),
        cloud.points_used,
        cloud.selection
    );
    crate::note!(
        "{} x {} cells of {} m{}, the {} of the points within {:.3} m of each centre, {} empty{} \
         ({:.2} s, {:.1} M points/s)",
        g.width,
        g.height,
        g.cell,
        if g.cell_auto {
            " (chosen from the density)"
        } else {
            ""
        },
        method.name(),
        g.radius,
        g.empty_cells,
        if g.filled_cells > 0 {
            format!(", {} of them filled", g.filled_cells)
        } else {
            String::new()
        },
        gridded,
        rate(cloud.points_used, gridded)
    );
    if cloud.crs == CrsKind::Local {
        crate::note!(
            "{}: no coordinate system in the file (no GeoKey directory or WKT record): the grid \
             is in a local frame",
            cloud.source
        );
    }
}

/// `terrain build`'s reading of `--dem`: lidar files gridded with `lidar` (and noted), other
/// grids as they are. Lidar options without a lidar file are a usage error.
pub fn read_dems(
    paths: &[PathBuf],
    opts: ReadOptions,
    lidar: &LidarArgs,
) -> Result<Vec<(String, Grid)>> {
    let clouds = paths.iter().filter(|p| is_lidar(p)).count();
    if clouds == 0 {
        if lidar.given() {
            return usage("the --lidar-* options apply to LAS and LAZ files (.las, .laz)");
        }
        return Ok(dem::read_dems(paths, &opts)?);
    }
    let opts = ReadOptions {
        lidar: lidar.options()?,
        ..opts
    };
    if !opts.lidar.method.is_height() {
        return usage(format!(
            "--lidar-method {}: a grid of the points' {}, not of heights, is no terrain; write it \
             with texmap terrain grid CLOUD -o {}.tif --lidar-method {0}",
            opts.lidar.method.name(),
            if opts.lidar.method == LidarMethod::Count {
                "counts"
            } else {
                "standard deviations"
            },
            opts.lidar.method.name()
        ));
    }
    if clouds < paths.len() {
        // Clouds and grids together: the clouds are one grid joined to the others.
        return dem::read_dems(paths, &opts).map_err(lidar_error);
    }
    let (grid, cloud) = grid_noting(paths, &opts.lidar)?;
    Ok(vec![(cloud.source, grid)])
}

/// A usage error unless `output` ends in `.tif` or `.tiff` (the commands that write a GeoTIFF).
pub(crate) fn require_geotiff(output: &Path) -> Result<()> {
    let tif = output
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| matches!(e.to_ascii_lowercase().as_str(), "tif" | "tiff"));
    if !tif {
        return usage(format!(
            "{}: the output must end in .tif or .tiff (a GeoTIFF)",
            output.display()
        ));
    }
    Ok(())
}

/// The layout `--cog` asks for (the commands that write a GeoTIFF).
pub(crate) fn geotiff_options(cog: bool) -> dem::geotiff_writer::GeoTiffOptions {
    dem::geotiff_writer::GeoTiffOptions {
        cog,
        ..Default::default()
    }
}

pub fn run(a: GridArgs) -> Result<()> {
    let opts = a.lidar.options()?;
    require_geotiff(&a.output)?;
    if let Some(p) = a.input.iter().find(|p| p.is_file() && !is_lidar(p)) {
        return usage(format!(
            "{}: not a LAS or LAZ file (.las, .laz); `terrain build --dem` takes raster grids",
            p.display()
        ));
    }
    let (grid, _) = grid_noting(&a.input, &opts)?;
    dem::geotiff_writer::write_grid_with(&a.output, &grid, &geotiff_options(a.cog))?;
    crate::note!("wrote {}", a.output.display());
    Ok(())
}
