//! `texmap terrain build | info | export | maps | render | viewshed | dem | grid | fly | compare`: glue between files, texmap-terrain and the terminal.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Subcommand;

use serde_json::json;
use texmap_terrain::db::{self, BuildOptions, Database};
use texmap_terrain::dem::{self, DemFormat, ReadOptions};
use texmap_terrain::gst;

use crate::args::usage;

#[derive(Subcommand, Debug)]
pub enum TerrainCmd {
    /// Build a terrain database (chunked LoD mesh + GST map pyramid) from an elevation grid.
    Build {
        /// Elevation grid: GeoTIFF, ESRI ASCII (.asc), SRTM (.hgt), DTED (.dt0, .dt1, .dt2), ESRI
        /// GridFloat (.flt) or BIL (.bil) with its .hdr and .prj, gridded XYZ text (.xyz: `x y z`
        /// lines as gdal_translate -of XYZ and many agencies' DGM tiles write them, any order,
        /// unlisted samples no-data, a .prj beside it), 16-bit PNG, or Mapbox Terrain-RGB
        /// or Terrarium PNG (--terrain-rgb, --terrarium); or a lidar point cloud, LAS or LAZ
        /// (`--dem survey.laz`, several tiles one cloud), gridded as --lidar-* says. Several grids
        /// that tile an area (e.g. `--dem N44W072.hgt N44W071.hgt`) are joined as gdalbuildvrt
        /// joins them: one system, cell size and lattice; the later file wins where they overlap,
        /// and samples no file covers are no-data. A GDAL VRT (`--dem dem.vrt`, as gdalbuildvrt
        /// or gdal_translate -of VRT write them) is read as GDAL composites it. Web-map elevation
        /// tiles stored as Z/X/Y.png
        /// (`--dem tiles/12/1205/1539.png tiles/12/1206/1539.png`, or a directory of them) are
        /// placed in Web Mercator (EPSG:3857) by their address, XYZ scheme, the tile's bounds the
        /// outer edges of its pixels; tiles of one zoom only.
        #[arg(long, num_args = 1.., required = true)]
        dem: Vec<PathBuf>,
        /// Orthophoto (PNG, JPEG, GeoTIFF or GDAL VRT), placed by its georeference or stretched.
        /// A photo in another system than the DEM's is reprojected (WGS 84 degrees, UTM of WGS
        /// 84, ETRS89 or NAD83, Web Mercator EPSG:3857). Several photo tiles (`--photo
        /// tiles/*.tif`, or a directory of GeoTIFFs) are mosaicked as gdalbuildvrt would: each
        /// placed by its own georeference, later wins where they overlap, and a tile's no-data
        /// (GDAL_NODATA in every band) and transparent pixels (an alpha band, as gdalwarp
        /// -dstalpha writes) show the tile below; a tile in another system than the first is
        /// reprojected into the mosaic. Where no photo covers the DEM, and without a photo at
        /// all, the texture is shaded relief (height colours lit like `gdaldem hillshade`).
        #[arg(long, num_args = 1..)]
        photo: Vec<PathBuf>,
        /// Photo bands for red, green, blue (1-based), e.g. 3,2,1 (each tile's, in a mosaic).
        #[arg(long)]
        bands: Option<String>,
        /// How the photo's samples become 8-bit colours: 'auto' (8-bit bands as they are, wider
        /// ones from each band's lowest to its highest sample), 'minmax', 'percent:2,98' (each
        /// band from its 2nd to its 98th percentile, QGIS's cumulative count cut: a 16-bit
        /// Sentinel-2 or Landsat scene whose clouds and glints would leave the land dark under
        /// minmax), or 'range:0,3000' (gdal_translate -scale; six numbers give one pair per
        /// band). The ranges used are printed and kept in the manifest: pass them as range: to a
        /// neighbouring database so that the colours match.
        #[arg(long, default_value = "auto", value_name = "RULE")]
        stretch: texmap_terrain::photo::Stretch,
        /// After the stretch, t^(1/GAMMA) (gdal_translate -exponent 1/GAMMA): above 1 brightens
        /// the shadows, as QGIS's gamma does.
        #[arg(long, default_value_t = 1.0, value_name = "GAMMA")]
        gamma: f64,
        /// Maximum vertical error of the finest level, metres.
        #[arg(long, default_value_t = 1.0)]
        max_error: f32,
        /// Samples per chunk side (2^k + 1).
        #[arg(long, default_value_t = 257)]
        chunk: u32,
        /// Most GST texture levels (level L is 256·2^L texels a side): the finest level has a
        /// texel per DEM sample and per photo pixel over the DEM, up to this many levels (8:
        /// 32768² texels). A GeoTIFF photo is read a band of rows at a time, so its size
        /// bounds only the build's time and the disk.
        #[arg(long, default_value_t = 8)]
        texture_levels: u32,
        /// Draw contour lines every M metres of height into the texture, as topographic maps
        /// (every fifth an index line twice as wide); without --photo the texture is then the
        /// shaded relief with the lines.
        #[arg(long, value_name = "M")]
        contours: Option<f64>,
        /// The contour lines' width in texels of the finest texture level.
        #[arg(long, value_name = "TEXELS", default_value_t = 1.5)]
        contour_width: f32,
        /// Draw a vector layer's points, lines and polygons into the texture (roads, rivers,
        /// boundaries, sites; repeat for several layers, drawn in order): an ESRI shapefile
        /// (x.shp, placed by the x.prj beside it: degrees, UTM or Web Mercator of WGS 84, ETRS89
        /// or NAD83), RFC 7946 GeoJSON in WGS 84 degrees, a GeoJSON text sequence, or GeoJSON
        /// with a "crs" member in UTM or Web Mercator (ogr2ogr -f GeoJSON -t_srs EPSG:4326
        /// converts a GeoPackage or another system). GeoJSON features are coloured by their
        /// simplestyle properties (stroke, stroke-width, fill, fill-opacity, marker-color,
        /// marker-size) where they have them, shapefile features by --overlay-style; without
        /// --photo the texture is the shaded relief.
        #[arg(long, value_name = "FILE")]
        overlay: Vec<PathBuf>,
        /// The overlays' style where a feature sets none: simplestyle keys, e.g.
        /// 'stroke=#ff0000,stroke-width=3,fill=none' (widths in texels of the finest level;
        /// defaults: stroke=#555555, stroke-width=2, fill=#555555, fill-opacity=0.6,
        /// marker-color=#7e7e7e, marker-size=medium).
        #[arg(long, value_name = "KEY=VALUE,...", requires = "overlay")]
        overlay_style: Option<String>,
        /// Colour the shaded relief's heights by a gdaldem color-relief colour file (lines
        /// 'height R G B [A]', 'P% R G B', 'nv R G B' or a named colour; linear between entries,
        /// as gdaldem's default) instead of the built-in green–brown–white ramp, still lit by the
        /// same hillshade. Percentages are of the DEM's height range; no-data takes the nv colour
        /// (grey without one); alpha is ignored. The resolved table is kept in the manifest, so
        /// views, streamed textures and exports of the database use it. Without --photo the
        /// texture is then the shaded relief; with one, the parts it does not cover.
        #[arg(long, value_name = "FILE")]
        relief_colors: Option<PathBuf>,
        /// Read a PNG as Mapbox Terrain-RGB: height = −10000 + 0.1·(R·65536 + G·256 + B) m.
        #[arg(long)]
        terrain_rgb: bool,
        /// Read a PNG as Terrarium (AWS Terrain Tiles, Mapzen): height = R·256 + G + B/256 −
        /// 32768 m.
        #[arg(long, conflicts_with = "terrain_rgb")]
        terrarium: bool,
        /// With --terrain-rgb or --terrarium and one --dem file: its tile address Z/X/Y (e.g.
        /// 12/1205/1539), for a file whose path does not end in Z/X/Y.png. A tile is n x n
        /// pixels, n a power of two, or n + 1 (backfilled: the extra row and column lie one pixel
        /// beyond the tile's east and south edges).
        #[arg(long, value_name = "Z/X/Y")]
        tile: Option<String>,
        /// With --terrain-rgb or --terrarium: tile rows count from the south (TMS), not from the
        /// north (XYZ, the web-map default).
        #[arg(long)]
        tms: bool,
        /// 16-bit PNG: metres per unit, offset, and metres between samples (also for a
        /// Terrain-RGB or Terrarium image without a tile address).
        #[arg(long, default_value_t = 1.0)]
        scale: f64,
        #[arg(long, default_value_t = 0.0)]
        offset: f64,
        #[arg(long, default_value_t = 1.0)]
        cell: f64,
        /// Fill no-data from neighbours instead of leaving holes.
        #[arg(long)]
        fill: bool,
        /// DTED: read records whose checksum does not match their bytes (a producer that wrote
        /// wrong checksums) instead of refusing the file.
        #[arg(long)]
        ignore_checksums: bool,
        /// Output directory (must not exist).
        #[arg(long)]
        out: PathBuf,
        #[command(flatten)]
        lidar: crate::terrain_grid::LidarArgs,
    },
    /// Print a grid's or a database's size, georeference, height range, no-data count, levels and
    /// triangles per level as one JSON object.
    Info {
        /// A database directory or an elevation file (a GDAL VRT also reports its bands and
        /// sources).
        path: PathBuf,
    },
    /// Export the whole terrain at an error as .glb (texture embedded) or .obj (+ .mtl, .png), or
    /// the whole level-of-detail tree as 3D Tiles for Cesium (--3d-tiles); the texture is the
    /// photo's or, without one, shaded relief.
    Export {
        /// Database directory.
        dir: PathBuf,
        /// Maximum vertical error of the exported mesh, metres (not with --3d-tiles: the tileset
        /// holds every level).
        #[arg(long, default_value_t = 1.0)]
        max_error: f32,
        /// Output: a .glb or .obj file, or with --3d-tiles a new directory.
        #[arg(short, long)]
        output: PathBuf,
        /// Greedy Delaunay refinement instead of the RTIN (fewer triangles; no no-data allowed).
        #[arg(long)]
        greedy: bool,
        /// Write an OGC 3D Tiles 1.1 tileset into the new directory -o: tileset.json and one .glb
        /// per chunk, each tile's geometricError the chunk's measured error, placed on the WGS 84
        /// ellipsoid (the grid must be geographic, UTM or Web Mercator; heights are taken as
        /// ellipsoidal unless --geoid is given).
        /// Open it in CesiumJS with `Cesium3DTileset.fromUrl(".../tileset.json")`.
        #[arg(long = "3d-tiles")]
        tiles3d: bool,
        /// With --3d-tiles: the geoid the DEM's heights are above (SRTM and most national DEMs:
        /// EGM96 or EGM2008), so that the tiles get ellipsoidal heights and sit on Cesium World
        /// Terrain instead of 20-100 m above or below it. A PROJ .gtx grid (proj-data's
        /// /usr/share/proj/egm96_15.gtx) or a GeoTIFF in degrees (us_nga_egm96_15.tif).
        #[arg(long, value_name = "GRID")]
        geoid: Option<PathBuf>,
        /// Write Cesium quantized-mesh-1.0 terrain into the new directory -o: layer.json and a
        /// TMS geographic pyramid of .terrain tiles, down to the level as fine as the grid, for
        /// `CesiumTerrainProvider.fromUrl(".../")` (the globe's terrain under any imagery).
        #[arg(long = "quantized-mesh", conflicts_with_all = ["tiles3d", "greedy"])]
        quantized_mesh: bool,
        /// With --quantized-mesh: the finest level (0-19; default: as fine as the grid).
        #[arg(long, value_name = "LEVEL", requires = "quantized_mesh")]
        max_level: Option<u32>,
        /// With --quantized-mesh: gzip every tile (names unchanged), as cesium-terrain-builder
        /// writes them; serve them with `Content-Encoding: gzip`.
        #[arg(long, requires = "quantized_mesh")]
        gzip: bool,
    },
    /// Seed 000 Eq. (5)-(7): GST maps the active area needs per level, and the total.
    Maps {
        #[arg(long, default_value_t = 45.0)]
        fov: f64,
        #[arg(long, default_value_t = 1024)]
        pixels: u32,
        #[arg(long, default_value_t = 256)]
        map_texels: u32,
        #[arg(long, default_value_t = 9)]
        levels: u32,
    },
    /// Draw the database from an aircraft (flight view) with a Seed 000 sampler.
    Render(crate::terrain_view::RenderArgs),
    /// What an observer on the terrain sees (viewshed, as gdal_viewshed): a GeoTIFF mask.
    Viewshed(crate::terrain_viewshed::ViewshedArgs),
    /// gdaldem's products of a DEM (hillshade, slope, aspect, color-relief, tri, tpi, roughness)
    /// as GeoTIFFs equal to GDAL's.
    Dem(crate::terrain_dem::DemArgs),
    /// Vector contour lines of a DEM as GeoJSON or a shapefile, line for line gdal_contour's.
    Contour(crate::terrain_contour::ContourArgs),
    /// Grid lidar point clouds (LAS, LAZ) into a DEM GeoTIFF, as PDAL's writers.gdal does.
    Grid(crate::terrain_grid::GridArgs),
    /// Fly a path file (or an orbit) over the database: PNG frames or a movie, with a progress bar.
    Fly(crate::terrain_fly::FlyArgs),
    /// Every sampler against the supersampled ray-traced reference along a flight path: CSV,
    /// JSON, Markdown summary and SVG charts, and Seed 000's bank claims counted.
    Compare(crate::terrain_fly::CompareArgs),
}

/// One note per grid that overlaps the ones before it in a mosaic (whose heights win there).
pub(crate) fn note_overlaps(overlaps: &[dem::mosaic::Overlap]) {
    for o in overlaps {
        crate::note!(
            "{} overlaps the grids before it on {} samples (largest difference {} m): its \
             heights are kept there",
            o.later,
            o.samples,
            o.max_difference
        );
    }
}

pub fn run(cmd: TerrainCmd) -> Result<()> {
    match cmd {
        TerrainCmd::Build {
            dem,
            photo,
            bands,
            stretch,
            gamma,
            max_error,
            chunk,
            terrain_rgb,
            terrarium,
            tile,
            tms,
            texture_levels,
            contours,
            contour_width,
            overlay,
            overlay_style,
            relief_colors,
            scale,
            offset,
            cell,
            fill,
            ignore_checksums,
            out,
            lidar,
        } => {
            let bands = match bands {
                None => None,
                Some(s) => {
                    let v: Vec<u16> = s
                        .split(',')
                        .map(|t| t.trim().parse::<u16>())
                        .collect::<Result<_, _>>()
                        .or_else(|_| {
                            usage(format!(
                                "--bands {s}: expected three band numbers like 3,2,1"
                            ))
                        })?;
                    match v[..] {
                        [r, g, b] if r > 0 && g > 0 && b > 0 => Some([r, g, b]),
                        _ => {
                            return usage(format!(
                                "--bands {s}: expected three 1-based band numbers like 3,2,1"
                            ));
                        }
                    }
                }
            };
            if !(gamma.is_finite() && gamma > 0.0) {
                return usage(format!("--gamma {gamma}: expected a number above 0"));
            }
            if photo.is_empty() && (stretch != texmap_terrain::photo::Stretch::Auto || gamma != 1.0)
            {
                return usage("--stretch and --gamma make a --photo's colours: give the photo");
            }
            if !(max_error.is_finite() && max_error >= 0.0) {
                return usage(format!("--max-error {max_error}: expected metres ≥ 0"));
            }
            let format = if terrarium {
                Some(DemFormat::Terrarium)
            } else {
                terrain_rgb.then_some(DemFormat::TerrainRgb)
            };
            if (tile.is_some() || tms) && format.is_none() {
                return usage("--tile and --tms apply to --terrain-rgb and --terrarium");
            }
            let tile = match tile {
                None => None,
                Some(t) if dem.len() == 1 => Some(
                    dem::png::TileAddress::parse(&t).or_else(|e| usage(format!("--tile: {e}")))?,
                ),
                Some(_) => {
                    return usage(
                        "--tile places one --dem file; several tiles are placed by their \
                         Z/X/Y.png paths",
                    );
                }
            };
            let opts = ReadOptions {
                format,
                scale,
                offset,
                cell,
                tile,
                tms,
                verify_checksums: !ignore_checksums,
                ..ReadOptions::default()
            };
            let parts = crate::terrain_grid::read_dems(&dem, opts, &lidar)?;
            let names: Vec<String> = parts.iter().map(|p| p.0.clone()).collect();
            let (mut grid, overlaps) = dem::mosaic::mosaic(parts)?;
            note_overlaps(&overlaps);
            if fill {
                grid.fill_nodata();
            }
            if !(1..=12).contains(&texture_levels) {
                return usage(format!(
                    "--texture-levels {texture_levels}: expected 1..=12"
                ));
            }
            let contours = match contours {
                None => None,
                Some(m) if m.is_finite() && m > 0.0 => {
                    if !(contour_width.is_finite() && (0.25..=16.0).contains(&contour_width)) {
                        return usage(format!(
                            "--contour-width {contour_width}: expected 0.25 to 16 texels"
                        ));
                    }
                    Some(texmap_terrain::relief::Contours {
                        width: contour_width,
                        ..texmap_terrain::relief::Contours::every(m)
                    })
                }
                Some(m) => return usage(format!("--contours {m}: expected metres > 0")),
            };
            // Read before the build, so that a bad file leaves nothing behind.
            let tint = match &relief_colors {
                None => texmap_terrain::relief::Tint::Ramp,
                Some(path) => {
                    let table = texmap_terrain::dem_products::ColorTable::read(path)?;
                    texmap_terrain::relief::Tint::Table(texmap_terrain::relief::TintTable::resolve(
                        &table, &grid,
                    ))
                }
            };
            let overlay_style = match overlay_style {
                None => texmap_terrain::vector::Style::default(),
                Some(s) => match texmap_terrain::vector::Style::default().with_keys(&s) {
                    Ok(s) => s,
                    Err(e) => return usage(format!("--overlay-style: {e}")),
                },
            };
            let overlays = overlay
                .iter()
                .map(texmap_terrain::vector::read_vector)
                .collect::<Result<Vec<_>, _>>()?;
            let photo = match photo.is_empty() {
                true => None,
                false => {
                    let opts = texmap_terrain::photo::PhotoOptions {
                        bands,
                        stretch,
                        gamma,
                    };
                    let p = texmap_terrain::photo::open_photos(&photo, &opts)?;
                    if let Some(a) = p.stretch() {
                        let [r, g, b] = a.ranges;
                        let all: Vec<String> =
                            a.ranges.as_flattened().iter().map(f64::to_string).collect();
                        let all = all.join(",");
                        crate::note!(
                            "photo colours: {} (red {}–{}, green {}–{}, blue {}–{}; --stretch range:{all}), gamma {}",
                            a.rule,
                            r[0],
                            r[1],
                            g[0],
                            g[1],
                            b[0],
                            b[1],
                            a.gamma
                        );
                    }
                    Some(p)
                }
            };
            let pb = crate::commands::progress(1, "building");
            let bo = BuildOptions {
                max_error,
                chunk,
                max_texture_levels: texture_levels,
                contours,
                overlays,
                overlay_style,
                tint,
                ..BuildOptions::default()
            };
            let m = db::build_with(
                &grid,
                &names.join(" + "),
                photo.as_deref(),
                &bo,
                &out,
                |d, t| {
                    pb.set_length(t);
                    pb.set_position(d);
                },
            )?;
            pb.finish_and_clear();
            for o in m.texture.iter().flat_map(|t| &t.overlays) {
                crate::note!(
                    "{}: {} of {} features drawn over the terrain",
                    o.source,
                    o.drawn,
                    o.features
                );
            }
            let tris: u64 = m
                .levels
                .last()
                .map_or(0, |l| l.chunks.iter().map(|c| c.triangles as u64).sum());
            crate::note!(
                "wrote {} ({} levels, {} triangles at the finest)",
                out.display(),
                m.levels.len(),
                tris
            );
            Ok(())
        }
        TerrainCmd::Info { path } => {
            let v = if path.is_dir() {
                let d = Database::open(&path)?;
                let m = &d.manifest;
                let mut v = json!({
                    "database": path.display().to_string(), "width": m.width, "height": m.height, "georef": m.georef,
                    "height_min": m.height_min, "height_max": m.height_max, "nodata": m.nodata, "max_error": m.max_error,
                    "chunk": m.chunk,
                    "levels": m.levels.iter().map(|l| json!({
                        "depth": l.depth, "target_error": l.target_error, "chunks": l.chunks.len(),
                        "triangles": l.chunks.iter().map(|c| c.triangles as u64).sum::<u64>(),
                        "max_geometric_error": l.chunks.iter().map(|c| c.geometric_error).fold(0.0f32, f32::max),
                    })).collect::<Vec<_>>(),
                    "texture": m.texture,
                });
                if let Some(t) = &m.relief_tint {
                    v["relief_tint"] = json!(t);
                }
                v
            } else {
                let grid = dem::read_dem(&path, &ReadOptions::default())?;
                let mut info = db::grid_info(&grid, &path.display().to_string());
                if dem::vrt::is_vrt(&path) {
                    let v = dem::vrt::Vrt::open(&path, dem::vrt::Use::Elevation)?;
                    info["vrt"] = v.summary();
                }
                info
            };
            println!("{}", serde_json::to_string(&v)?);
            Ok(())
        }
        TerrainCmd::Export {
            dir,
            max_error,
            output,
            greedy,
            tiles3d,
            geoid,
            quantized_mesh,
            max_level,
            gzip,
        } => {
            if geoid.is_some() && !(tiles3d || quantized_mesh) {
                return usage("--geoid applies to --3d-tiles and --quantized-mesh");
            }
            if quantized_mesh {
                let d = Database::open(&dir)?;
                let geoid = geoid.map(texmap_terrain::geoid::Geoid::open).transpose()?;
                let sp = crate::commands::spinner("writing quantized-mesh terrain");
                let options = texmap_terrain::qmesh::QuantizedMeshOptions {
                    geoid: geoid.as_ref(),
                    max_level,
                    gzip,
                };
                let s = texmap_terrain::qmesh::write_quantized_mesh(&d, &output, &options)?;
                sp.finish_and_clear();
                crate::note!(
                    "wrote {} (levels 0-{}, {} tiles, {} triangles, {:.1} MB)",
                    output.join("layer.json").display(),
                    s.levels - 1,
                    s.tiles,
                    s.triangles,
                    s.bytes as f64 / 1e6
                );
                return Ok(());
            }
            if tiles3d {
                if greedy {
                    return usage("--greedy applies to a single mesh, not to --3d-tiles");
                }
                let d = Database::open(&dir)?;
                let geoid = geoid.map(texmap_terrain::geoid::Geoid::open).transpose()?;
                let sp = crate::commands::spinner("writing 3D Tiles");
                let options = texmap_terrain::tiles3d::TilesetOptions {
                    geoid: geoid.as_ref(),
                    ..Default::default()
                };
                let s = texmap_terrain::tiles3d::write_tileset_with(&d, &output, &options)?;
                sp.finish_and_clear();
                crate::note!(
                    "wrote {} ({} tiles, {} with content, {} triangles, {:.1} MB)",
                    output.join("tileset.json").display(),
                    s.tiles,
                    s.with_content,
                    s.triangles,
                    s.bytes as f64 / 1e6
                );
                return Ok(());
            }
            if !(max_error.is_finite() && max_error >= 0.0) {
                return usage(format!("--max-error {max_error}: expected metres ≥ 0"));
            }
            let ext = output
                .extension()
                .and_then(|e| e.to_str())
                .map(|e| e.to_ascii_lowercase());
            let glb = match ext.as_deref() {
                Some("glb") => true,
                Some("obj") => false,
                _ => {
                    return usage(format!(
                        "{}: the output must end in .glb or .obj",
                        output.display()
                    ));
                }
            };
            let d = Database::open(&dir)?;
            let grid = d.grid()?;
            let mesh = if greedy {
                db::whole_mesh_greedy(&grid, max_error)?
            } else {
                db::whole_mesh(&grid, max_error)?
            };
            // The photo's finest level up to 4096² or, without a photo, the shaded relief the
            // views draw.
            let tex = match d.texture(4096)? {
                Some(t) => t,
                None => d.tint().image(&grid, 4096),
            };
            let tex = Some(tex);
            if glb {
                texmap_mesh::write_glb(&output, &mesh, tex.as_ref())
            } else {
                texmap_mesh::write_obj(&output, &mesh, tex.as_ref())
            }
            .with_context(|| format!("exporting {}", output.display()))?;
            crate::note!(
                "wrote {} ({} vertices, {} triangles)",
                output.display(),
                mesh.positions.len(),
                mesh.triangles.len()
            );
            Ok(())
        }
        TerrainCmd::Render(a) => crate::terrain_view::run(a),
        TerrainCmd::Viewshed(a) => crate::terrain_viewshed::run(a),
        TerrainCmd::Dem(a) => crate::terrain_dem::run(a),
        TerrainCmd::Contour(a) => crate::terrain_contour::run(a),
        TerrainCmd::Grid(a) => crate::terrain_grid::run(a),
        TerrainCmd::Fly(a) => crate::terrain_fly::run_fly(a),
        TerrainCmd::Compare(a) => crate::terrain_fly::run_compare(a),
        TerrainCmd::Maps {
            fov,
            pixels,
            map_texels,
            levels,
        } => {
            let b = gst::map_budget(fov, pixels, map_texels, levels)
                .or_else(|e| usage(e.to_string()))?;
            let total: u64 = b.iter().map(|x| x.1).sum();
            let v = json!({
                "fov_deg": fov, "pixels": pixels, "map_texels": map_texels,
                "levels": b.iter().map(|&(l, n)| json!({"level": l, "maps": n})).collect::<Vec<_>>(),
                "total": total,
                "resident_bytes": total * map_texels as u64 * map_texels as u64 * 4,
            });
            println!("{}", serde_json::to_string(&v)?);
            Ok(())
        }
    }
}
