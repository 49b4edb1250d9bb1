//! `texmap terrain contour`: vector contour lines of any DEM `terrain build` reads, as GeoJSON
//! or an ESRI shapefile equal to `gdal_contour`'s. Glue only: the lines are
//! `texmap_terrain::contour_lines`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use texmap_terrain::contour_lines::{
    ContourOptions, Levels, WriteOptions, contour_lines, write_geojson, write_shapefile,
};

use crate::args::usage;

const CONTOUR_AFTER_HELP: &str = "\
Options and their gdal_contour flags:
  -i, --interval     -i     a line every INTERVAL height units (with --offset: -off)
  --levels a,b,c     -fl    lines at these heights only
  --exp-base B       -e     lines at 1, B, B², B³, … (and 0)
  --attr [NAME]      -a     write each line's height as attribute NAME (ELEV when no name)
  --3d               -3d    write the height as every vertex's Z too
  --nodata V         -snodata   heights equal to V are no-data too
Exactly one of --interval, --levels, --exp-base.

Examples:
  texmap terrain contour N44W072.hgt -i 50 --attr -o contours.geojson
      (as `gdal_contour -f GeoJSON -i 50 -a ELEV N44W072.hgt contours.geojson`, line for line)
  texmap terrain contour dem_utm.tif --levels 500,1000,1500 --attr HEIGHT --3d -o c.geojson
  texmap terrain contour N44W072.hgt N44W071.hgt -i 100 -o contours.geojson
  texmap terrain contour dem.tif -i 10 --attr -o contours.shp
      (gdal_contour's default format: contours.shp, .shx, .dbf and .prj)

The lines equal gdal_contour 3.6.2's, vertex for vertex, in the same order and direction
(crates/terrain/tests/contour_lines.rs compares them): they run through the lattice of sample
centres, reach half a cell past the outermost samples to the raster's edge, stop half a cell short
of a no-data sample, and are joined across cells into long lines (rings closed: the first vertex
repeated). A height exactly on a level counts as 1e-6 above it, as in GDAL, so the lowest
height's level gets no line and the highest's does. Several DEM tiles are joined into one grid
first, as `terrain build --dem` joins them. Coordinates are the DEM's (degrees for a geographic
grid, with GDAL's CRS84 `crs` member; an EPSG URN for a projected one). Departures from GDAL:
--levels is sorted first (GDAL drops a level below an earlier larger one), --nodata adds to the
file's no-data instead of replacing it, polygons (-p) are not made, and a shapefile's .prj is
written only for WGS 84 degrees and UTM zones (ESRI's WKT, as GDAL writes it).";

/// Contour lines of one or more DEM tiles, as gdal_contour draws them.
#[derive(Args, Debug)]
#[command(after_help = CONTOUR_AFTER_HELP)]
pub struct ContourArgs {
    /// Elevation files (any format `terrain build --dem` reads); several tiles are joined. Or
    /// one database directory from `terrain build`: its full-resolution grid.
    #[arg(required = true, value_name = "DEM")]
    pub input: Vec<PathBuf>,
    /// Output: GeoJSON (.geojson, .json) or an ESRI shapefile (.shp, with .shx, .dbf and .prj
    /// beside it), in the DEM's coordinates; chosen by the extension (gdal_contour -f).
    #[arg(short, long)]
    pub output: PathBuf,
    /// A line every INTERVAL height units (gdal_contour -i).
    #[arg(short, long, value_name = "INTERVAL", allow_hyphen_values = true)]
    pub interval: Option<f64>,
    /// Lines at OFFSET + k·INTERVAL (gdal_contour -off).
    #[arg(
        long,
        value_name = "OFFSET",
        default_value_t = 0.0,
        allow_hyphen_values = true,
        requires = "interval"
    )]
    pub offset: f64,
    /// Lines at these heights only, comma-separated (gdal_contour -fl).
    #[arg(
        long,
        value_name = "A,B,C",
        allow_hyphen_values = true,
        conflicts_with_all = ["interval", "exp_base"]
    )]
    pub levels: Option<String>,
    /// Lines at 1, B, B², … (and 0): for heights spanning orders of magnitude (gdal_contour -e).
    #[arg(long, value_name = "B", conflicts_with = "interval")]
    pub exp_base: Option<f64>,
    /// Write each line's height as attribute NAME (gdal_contour -a); ELEV when no name is given.
    /// Without it the lines carry only their ID, as gdal_contour's without -a.
    #[arg(long, value_name = "NAME", num_args = 0..=1, default_missing_value = "ELEV")]
    pub attr: Option<String>,
    /// Write the height as every vertex's Z (gdal_contour -3d).
    #[arg(long = "3d")]
    pub three_d: bool,
    /// Heights equal to V are no-data too, besides the file's own (gdal_contour -snodata).
    #[arg(long, value_name = "V", allow_hyphen_values = true)]
    pub nodata: Option<f64>,
    /// Polygons between levels (gdal_contour -p): not made yet.
    #[arg(long, hide = true)]
    pub polygons: bool,
}

/// The levels from the options, checked (bad usage: exit 2).
fn levels(a: &ContourArgs) -> Result<Levels> {
    let l = match (a.interval, &a.levels, a.exp_base) {
        (Some(interval), None, None) => Levels::Interval {
            interval,
            offset: a.offset,
        },
        (None, Some(list), None) => {
            let mut v = Vec::new();
            for part in list.split(',') {
                match part.trim().parse::<f64>() {
                    Ok(x) => v.push(x),
                    Err(_) => {
                        return usage(format!(
                            "--levels {list}: {:?} is not a number (expected heights like \
                             100,200,250.5)",
                            part.trim()
                        ));
                    }
                }
            }
            Levels::Fixed(v)
        }
        (None, None, Some(base)) => Levels::Exponential { base },
        (None, None, None) => {
            return usage("no levels: give --interval (-i), --levels or --exp-base");
        }
        _ => return usage("give only one of --interval, --levels and --exp-base"),
    };
    l.check().or_else(|e| usage(e.to_string()))
}

pub fn run(a: ContourArgs) -> Result<()> {
    if a.polygons {
        return usage(
            "--polygons: contour polygons (gdal_contour -p) are not made yet; the lines are \
             (omit --polygons)",
        );
    }
    let levels = levels(&a)?;
    if let Some(v) = a.nodata
        && !v.is_finite()
    {
        return usage(format!("--nodata {v}: expected a finite height"));
    }
    let ext = a
        .output
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let shapefile = match ext.as_str() {
        "geojson" | "json" => false,
        "shp" => true,
        _ => {
            return usage(format!(
                "{}: expected a .geojson, .json or .shp output",
                a.output.display()
            ));
        }
    };
    let grid = crate::terrain_dem::read_joined(&a.input)?;
    let t0 = Instant::now();
    let options = ContourOptions { nodata: a.nodata };
    let lines = contour_lines(&grid, &levels, &options)?;
    let secs = t0.elapsed().as_secs_f64();
    let write = WriteOptions {
        attr: a.attr.clone(),
        three_d: a.three_d,
    };
    if shapefile {
        if !write_shapefile(&a.output, &lines, grid.georef(), &write)? {
            crate::note!(
                "no .prj written: only WGS 84 degrees and UTM zones are described (the DEM's \
                 EPSG code: {})",
                grid.georef()
                    .epsg
                    .map(|c| c.to_string())
                    .unwrap_or_else(|| "none".into())
            );
        }
    } else {
        write_geojson(&a.output, &lines, grid.georef(), &write)?;
    }
    let rings = lines.iter().filter(|l| l.is_closed()).count();
    let mut distinct: Vec<f64> = lines.iter().map(|l| l.level).collect();
    distinct.dedup();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup();
    crate::note!(
        "{} x {} samples: {} lines ({rings} rings) at {} levels in {secs:.2} s; wrote {}",
        grid.width(),
        grid.height(),
        lines.len(),
        distinct.len(),
        a.output.display()
    );
    if a.attr.is_none() {
        crate::note!("no height attribute (as gdal_contour without -a): give --attr to write ELEV");
    }
    Ok(())
}
