//! ESRI shapefiles as vector overlays: the `.shp` geometry of points, multipoints, polylines and
//! polygons (with or without Z and M values, which are ignored: overlays are draped), placed by
//! the `.prj` beside it, so the layers GIS users have (roads, rivers, boundaries from a national
//! mapping agency, QGIS exports) drape without a conversion step.
//!
//! **Geometry** ([`read_shapefile`]): every record of the main file in order, one
//! [`Feature`] each: a point or multipoint gives points, a polyline its parts as line strings, a
//! polygon its parts as rings (outer rings and holes alike: overlays fill by the even–odd rule).
//! Null shapes are kept as empty features (the feature count matches the attribute table's
//! records). Multipatch (3D surfaces) is refused. Lengths are never trusted: the header's file
//! length, each record's content length and its part and point counts are checked against the
//! bytes there are, and a violation names the byte offset and what was expected. Attributes
//! (`.dbf`) are not read: a feature's style comes from the layer's (`--overlay-style`).
//!
//! **System** (the `.prj`, WKT 1 as GDAL, QGIS and ArcGIS write it): an `AUTHORITY["EPSG", …]`
//! of the outermost system when there is one; otherwise ESRI's names: `GCS_WGS_1984` (and ETRS89,
//! NAD83) degrees, `WGS_1984_UTM_Zone_19N` (and `ETRS_1989_…`, `NAD_1983_…`), and
//! `WGS_1984_Web_Mercator_Auxiliary_Sphere`. Any other system is refused by name with the
//! `ogr2ogr -t_srs EPSG:4326` hint. Without a `.prj` the coordinates are taken as WGS 84 degrees
//! when every one of them lies within ±180°, ±90° (GDAL's and QGIS's reading of such a file), and
//! refused otherwise.
//!
//! ```no_run
//! let layer = texmap_terrain::shapefile::read_shapefile("roads.shp")?;
//! println!("{} features", layer.features.len());
//! # Ok::<(), texmap_terrain::TerrainError>(())
//! ```

use std::path::Path;

use crate::TerrainError;
use crate::error::{format_err, io};
use crate::vector::{Feature, LayerCrs, Position, VectorLayer, layer_crs_of_epsg};

/// Read a shapefile (`x.shp`, with `x.prj` beside it when there is one): see the module docs.
pub fn read_shapefile(path: impl AsRef<Path>) -> Result<VectorLayer, TerrainError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(io(path))?;
    let source = path.display().to_string();
    let prj = ["prj", "PRJ"]
        .iter()
        .map(|e| path.with_extension(e))
        .find(|p| p.exists());
    let wkt = match &prj {
        Some(p) => Some(std::fs::read_to_string(p).map_err(io(p))?),
        None => None,
    };
    let features = parse_shp(&bytes, &source)?;
    let crs = match (&wkt, &prj) {
        (Some(w), Some(p)) => crs_of_wkt(w, "ogr2ogr")
            .map_err(|e| format_err(&p.display().to_string(), "the system", e))?,
        _ => {
            let degrees = features.iter().all(|f| {
                f.points
                    .iter()
                    .chain(f.lines.iter().flatten())
                    .chain(f.rings.iter().flatten())
                    .all(|p| p[0].abs() <= 180.0 && p[1].abs() <= 90.0)
            });
            if !degrees {
                return Err(format_err(
                    &source,
                    "the system",
                    "a .prj beside the file naming its coordinate system (the coordinates are \
                     not longitudes and latitudes; write one with ogr2ogr -a_srs EPSG:NNNN)",
                ));
            }
            LayerCrs::Lonlat
        }
    };
    Ok(VectorLayer {
        source,
        crs,
        features,
    })
}

/// The features of a `.shp` file's bytes; `source` names it in errors.
pub fn parse_shp(bytes: &[u8], source: &str) -> Result<Vec<Feature>, TerrainError> {
    let bad = |at: usize, what: String| format_err(source, format!("byte {at}"), what);
    if bytes.len() < 100 {
        return Err(bad(
            0,
            format!("a 100-byte shapefile header, found {} bytes", bytes.len()),
        ));
    }
    let be = |at: usize| i32::from_be_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    let le = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    if be(0) != 9994 {
        return Err(bad(0, format!("the shapefile code 9994, found {}", be(0))));
    }
    let declared = be(24) as i64 * 2;
    if declared < 100 || declared > bytes.len() as i64 {
        return Err(bad(
            24,
            format!(
                "a file length (16-bit words) from the header to at most the {} bytes there are, \
                 found {} bytes",
                bytes.len(),
                declared
            ),
        ));
    }
    if le(28) != 1000 {
        return Err(bad(28, format!("shapefile version 1000, found {}", le(28))));
    }
    let end = declared as usize;
    let mut features = Vec::new();
    let mut at = 100;
    while at < end {
        if end - at < 8 {
            return Err(bad(at, "an 8-byte record header".into()));
        }
        let words = be(at + 4);
        let len = words as i64 * 2;
        if words < 2 || at as i64 + 8 + len > end as i64 {
            return Err(bad(
                at + 4,
                format!(
                    "a record content length (16-bit words) within the file, found {words} \
                     ({} bytes left)",
                    end - at - 8
                ),
            ));
        }
        let content = &bytes[at + 8..at + 8 + len as usize];
        features.push(record(content, at + 8).map_err(|(off, what)| bad(off, what))?);
        at += 8 + len as usize;
    }
    Ok(features)
}

/// One record's shape; errors give the absolute byte offset and what was expected.
fn record(c: &[u8], base: usize) -> Result<Feature, (usize, String)> {
    let need = |at: usize, n: usize, what: &str| {
        if at + n > c.len() {
            Err((
                base + at,
                format!("{what} ({n} bytes), past the record's {} bytes", c.len()),
            ))
        } else {
            Ok(())
        }
    };
    let i32_at = |at: usize| i32::from_le_bytes(c[at..at + 4].try_into().expect("4 bytes"));
    let f64_at = |at: usize| f64::from_le_bytes(c[at..at + 8].try_into().expect("8 bytes"));
    let point_at = |at: usize| -> Result<Position, (usize, String)> {
        let p = [f64_at(at), f64_at(at + 8)];
        if p.iter().all(|v| v.is_finite()) {
            Ok(p)
        } else {
            Err((base + at, format!("a finite x, y, found {p:?}")))
        }
    };
    let kind = i32_at(0);
    let mut feature = Feature::default();
    match kind {
        0 => {}
        1 | 11 | 21 => {
            need(4, 16, "a point")?;
            feature.points.push(point_at(4)?);
        }
        8 | 18 | 28 => {
            // Box (32 bytes), count, points.
            need(36, 4, "a point count")?;
            let n = i32_at(36);
            let n =
                usize::try_from(n).map_err(|_| (base + 36, format!("a point count, found {n}")))?;
            need(40, n.saturating_mul(16), "the points")?;
            for k in 0..n {
                feature.points.push(point_at(40 + 16 * k)?);
            }
        }
        3 | 13 | 23 | 5 | 15 | 25 => {
            need(36, 8, "part and point counts")?;
            let (parts, points) = (i32_at(36), i32_at(40));
            let (Ok(np), Ok(nv)) = (usize::try_from(parts), usize::try_from(points)) else {
                return Err((
                    base + 36,
                    format!("part and point counts, found {parts} and {points}"),
                ));
            };
            need(44, np.saturating_mul(4), "the part starts")?;
            let first = 44 + 4 * np;
            if nv.saturating_mul(16) > c.len().saturating_sub(first) {
                return Err((
                    base + 40,
                    format!(
                        "a point count the record holds, found {nv} points ({} bytes) after                          {first} bytes of a {}-byte record",
                        nv.saturating_mul(16),
                        c.len()
                    ),
                ));
            }
            let mut starts = Vec::with_capacity(np + 1);
            for k in 0..np {
                let s = i32_at(44 + 4 * k);
                let previous = starts.last().copied().unwrap_or(0);
                match usize::try_from(s) {
                    Ok(s) if s <= nv && s >= previous && (k > 0 || s == 0) => starts.push(s),
                    _ => {
                        return Err((
                            base + 44 + 4 * k,
                            format!(
                                "part {k}'s first point: 0 for the first part, then rising, at \
                                 most the {nv} points, found {s}"
                            ),
                        ));
                    }
                }
            }
            starts.push(nv);
            for w in starts.windows(2) {
                let mut part = Vec::with_capacity(w[1] - w[0]);
                for k in w[0]..w[1] {
                    part.push(point_at(first + 16 * k)?);
                }
                if matches!(kind, 5 | 15 | 25) {
                    feature.rings.push(part);
                } else {
                    feature.lines.push(part);
                }
            }
        }
        31 => {
            return Err((
                base,
                "a point, multipoint, polyline or polygon shape, found a multipatch (3D \
                 surfaces are not draped)"
                    .into(),
            ));
        }
        other => {
            return Err((
                base,
                format!("a shape type of the shapefile specification, found {other}"),
            ));
        }
    }
    Ok(feature)
}

/// The EPSG code of a WKT's outermost system, when it names one: WKT 1's `AUTHORITY["EPSG","32619"]`
/// or WKT 2's `ID["EPSG",32619]` as a direct child of the outermost system (a unit's, datum's or
/// ellipsoid's code does not count). Also the LAS reader's, for a point cloud's WKT record
/// ([`crate::dem::las`]).
pub(crate) fn wkt_epsg(wkt: &str) -> Option<u32> {
    let wkt = wkt.trim().trim_end_matches('\0').trim_end();
    // The keyword `AUTHORITY[` or `ID[` that starts a word (`ELLIPSOID[` ends in `ID[`) one
    // bracket deep: a child of the outermost system, not of its datum, unit or ellipsoid.
    let bytes = wkt.as_bytes();
    let (mut depth, mut quoted, mut at) = (0i32, false, None);
    for (i, &b) in bytes.iter().enumerate() {
        match b {
            b'"' => quoted = !quoted,
            b'[' | b'(' if !quoted => depth += 1,
            b']' | b')' if !quoted => depth -= 1,
            _ if !quoted && depth == 1 => {
                let word =
                    i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
                let rest = &bytes[i..];
                if word && (rest.starts_with(b"AUTHORITY[") || rest.starts_with(b"ID[")) {
                    at = Some(i);
                }
            }
            _ => {}
        }
    }
    let rest = &wkt[at?..];
    let open = rest.find('[')?;
    let close = rest.find(']')?;
    let mut fields = rest[open + 1..close].split(',');
    let authority = fields.next()?.trim().trim_matches('"');
    let code = fields.next()?.trim().trim_matches('"').trim();
    authority
        .eq_ignore_ascii_case("EPSG")
        .then(|| code.parse().ok())
        .flatten()
}

/// The layer system a `.prj`'s WKT names (see the module docs; also the `.prj` of an ESRI
/// `.hdr` raster, [`crate::dem::ehdr`]). A system texmap does not place is refused by name, with
/// the hint to convert it with `tool` (`ogr2ogr` for vectors, `gdalwarp` for rasters).
pub(crate) fn crs_of_wkt(wkt: &str, tool: &str) -> Result<LayerCrs, String> {
    let wkt = wkt.trim();
    let head = wkt
        .split('[')
        .next()
        .unwrap_or("")
        .trim()
        .to_ascii_uppercase();
    let name = wkt.split('"').nth(1).unwrap_or("").to_string();
    let refuse = || {
        format!(
            "a system texmap places (WGS 84, ETRS89 or NAD83 degrees, their UTM zones, Web \
             Mercator), found \"{name}\" (convert with {tool} -t_srs EPSG:4326)"
        )
    };
    if let Some(code) = wkt_epsg(wkt) {
        return layer_crs_of_epsg(code).map_err(|_| refuse());
    }
    let upper = name.to_ascii_uppercase().replace([' ', '-'], "_");
    let datum = if upper.contains("WGS_1984") || upper.contains("WGS_84") || upper.contains("WGS84")
    {
        Some(0)
    } else if upper.contains("ETRS_1989") || upper.contains("ETRS89") {
        Some(1)
    } else if upper.contains("NAD_1983") || upper.contains("NAD83") {
        Some(2)
    } else {
        None
    };
    match head.as_str() {
        "GEOGCS" | "GEOGCRS" if datum.is_some() => Ok(LayerCrs::Lonlat),
        "PROJCS" | "PROJCRS" => {
            if upper.contains("WEB_MERCATOR") || upper.contains("PSEUDO_MERCATOR") {
                return layer_crs_of_epsg(3857).map_err(|_| refuse());
            }
            let zone = upper.find("UTM_ZONE_").and_then(|i| {
                let z = &upper[i + 9..];
                let digits: String = z.chars().take_while(|c| c.is_ascii_digit()).collect();
                let hemisphere = z[digits.len()..].chars().next();
                Some((digits.parse::<u32>().ok()?, hemisphere?))
            });
            let code = match (datum, zone) {
                (Some(0), Some((z @ 1..=60, 'N'))) => 32600 + z,
                (Some(0), Some((z @ 1..=60, 'S'))) => 32700 + z,
                (Some(1), Some((z @ 28..=38, 'N'))) => 25800 + z,
                (Some(2), Some((z @ 1..=23, 'N'))) => 26900 + z,
                _ => return Err(refuse()),
            };
            layer_crs_of_epsg(code).map_err(|_| refuse())
        }
        _ => Err(refuse()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn esri_and_ogc_names_give_the_epsg_codes() {
        let esri_utm = r#"PROJCS["WGS_1984_UTM_Zone_19N",GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984",SPHEROID["WGS_1984",6378137.0,298.257223563]],PRIMEM["Greenwich",0.0],UNIT["Degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],UNIT["Meter",1.0]]"#;
        assert!(matches!(
            crs_of_wkt(esri_utm, "ogr2ogr"),
            Ok(LayerCrs::Epsg(32619, _))
        ));
        let etrs = r#"PROJCS["ETRS_1989_UTM_Zone_33N",GEOGCS["GCS_ETRS_1989"]]"#;
        assert!(matches!(
            crs_of_wkt(etrs, "ogr2ogr"),
            Ok(LayerCrs::Epsg(25833, _))
        ));
        let south = r#"PROJCS["WGS 84 / UTM zone 33S",GEOGCS["WGS 84"]]"#;
        assert!(matches!(
            crs_of_wkt(south, "ogr2ogr"),
            Ok(LayerCrs::Epsg(32733, _))
        ));
        let ogc = r#"PROJCS["WGS 84 / UTM zone 19N",GEOGCS["WGS 84",DATUM["WGS_1984",AUTHORITY["EPSG","6326"]],AUTHORITY["EPSG","4326"]],UNIT["metre",1,AUTHORITY["EPSG","9001"]],AUTHORITY["EPSG","32619"]]"#;
        assert!(matches!(
            crs_of_wkt(ogc, "ogr2ogr"),
            Ok(LayerCrs::Epsg(32619, _))
        ));
        let wm = r#"PROJCS["WGS_1984_Web_Mercator_Auxiliary_Sphere",GEOGCS["GCS_WGS_1984"]]"#;
        assert!(matches!(
            crs_of_wkt(wm, "ogr2ogr"),
            Ok(LayerCrs::Epsg(3857, _))
        ));
        // WKT 2 (PROJ's and pyproj's default): the outermost ID, not the ellipsoid's.
        let wkt2 = r#"PROJCRS["WGS 84 / UTM zone 19N",BASEGEOGCRS["WGS 84",DATUM["World Geodetic System 1984",ELLIPSOID["WGS 84",6378137,298.257223563,LENGTHUNIT["metre",1]]],ID["EPSG",4326]],CONVERSION["UTM zone 19N",METHOD["Transverse Mercator",ID["EPSG",9807]]],ID["EPSG",32619]]"#;
        assert_eq!(wkt_epsg(wkt2), Some(32619));
        assert_eq!(wkt_epsg(ogc), Some(32619));
        assert_eq!(wkt_epsg(esri_utm), None);
        let ellipsoid_only =
            r#"GEOGCRS["x",ELLIPSOID["WGS 84",6378137,298.257223563,ID["EPSG",7030]]]"#;
        assert_eq!(wkt_epsg(ellipsoid_only), None);
        let deg = r#"GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984"]]"#;
        assert_eq!(crs_of_wkt(deg, "ogr2ogr"), Ok(LayerCrs::Lonlat));
        let lambert = r#"PROJCS["RGF93_Lambert_93",GEOGCS["GCS_RGF_1993"]]"#;
        let e = crs_of_wkt(lambert, "ogr2ogr").unwrap_err();
        assert!(
            e.contains("\"RGF93_Lambert_93\"") && e.contains("ogr2ogr"),
            "{e}"
        );
    }
}
