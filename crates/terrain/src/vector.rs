//! Vector overlays: GeoJSON points, lines and polygons drawn into a terrain's geospecific
//! texture, as map layers (roads, rivers, boundaries, sites) are draped in GIS and terrain tools.
//!
//! **Reading.** [`read_geojson`] takes RFC 7946 GeoJSON (a `FeatureCollection`, one `Feature` or
//! one geometry), GeoJSON text sequences (RFC 8142, `ogr2ogr -f GeoJSONSeq`: one feature per
//! line, with or without the record separator) and the older 2008 form with a `crs` member
//! (`ogr2ogr -lco RFC7946=NO`, QGIS): `urn:ogc:def:crs:EPSG::32619`, `EPSG:3857`,
//! `urn:ogc:def:crs:OGC:1.3:CRS84`. Without a `crs` member coordinates are WGS 84 longitude and
//! latitude, as RFC 7946 says. The systems placed are those of [`crate::geodesy::Placement`]:
//! WGS 84 degrees (ETRS89 and NAD83 degrees taken as WGS 84), UTM of WGS 84, ETRS89 or NAD83, and
//! Web Mercator; others are refused by name (`ogr2ogr -t_srs EPSG:4326` converts them). Features
//! are read one at a time from the file's `features` array, so memory holds the features' own
//! coordinates, not a parsed copy of the whole document. Every error names the file, the feature
//! (`features[12].geometry.coordinates[0]`) and, for JSON syntax, the line and column.
//!
//! **Style.** Each feature's `properties` may carry the simplestyle-spec 1.1 keys that
//! geojson.io, GitHub and Mapbox draw with: `stroke`, `stroke-width`, `stroke-opacity`, `fill`,
//! `fill-opacity`, `marker-color`, `marker-size` (`small`, `medium`, `large`: discs 6, 9 and 13
//! texels across). Colours are `#rgb` or `#rrggbb`. A key a feature does not set comes from the
//! layer's [`Style`] (`texmap terrain build --overlay-style 'stroke=#ff0000,stroke-width=3'`),
//! whose own defaults are simplestyle's (grey `#555555` lines 2 wide, fills at 0.6 opacity).
//! Widths are texels of the finest texture level, so a line is as wide on the ground as that
//! many texels; coarser levels average it down with the photo, as a mipmap does.
//!
//! **Drawing.** Vertices are moved into the DEM's system ([`Placement::xy`]) and onto the finest
//! level's texel lattice (texel `i`'s centre at grid sample `i·(W − 1)/(S − 1)`, as the texture
//! spans the grid from its first to its last sample); edges are straight on that lattice, as
//! `gdal_rasterize` draws them after transforming the vertices. A polygon is filled by the
//! even–odd rule at texel centres (the pixel-centre rule of `gdal_rasterize`: a texel whose centre
//! lies inside is at least half covered), holes included, and anti-aliased across its edges by
//! the distance of the texel centre to the nearest edge (coverage `0.5 ± d`, one texel wide). A
//! line of width `w ≥ 1` covers `clamp(w/2 + 0.5 − d, 0, 1)` of a texel at distance `d` from its
//! nearest segment (each line string is one shape, so joints are not blended twice); a thinner
//! line is one texel wide at `w` times the opacity, so its total ink stays `w`. Points are discs.
//! Features are drawn in file order, layers in the order given, fill before outline, each
//! composited over the texture with its opacity. Each map tile draws only the features whose
//! bounds reach it ([`Overlay::draw`]), so the cost is proportional to the texels the features
//! cover.
//!
//! ```
//! use texmap_terrain::dem::{CrsKind, Georef, Grid};
//! use texmap_terrain::vector::{Overlay, Style, parse_geojson};
//!
//! // A 65 x 65 grid in WGS 84 degrees and a red square around its centre.
//! let georef = Georef { crs: CrsKind::Geographic, epsg: Some(4326), origin_x: 10.0,
//!     origin_y: 46.0, dx: 0.001, dy: -0.001 };
//! let grid = Grid::new("flat", 65, 65, vec![500.0; 65 * 65], georef)?;
//! let json = br##"{"type": "Feature", "properties": {"fill": "#ff0000", "fill-opacity": 1,
//!     "stroke-width": 0}, "geometry": {"type": "Polygon", "coordinates":
//!     [[[10.016, 45.984], [10.048, 45.984], [10.048, 45.952], [10.016, 45.952], [10.016, 45.984]]]}}"##;
//! let layer = parse_geojson(json, "square.geojson")?;
//! // The finest texture level: 256 texels a side, one map.
//! let overlay = Overlay::place(&[layer], &Style::default(), &grid, 256, 256)?;
//! let mut map = image::RgbaImage::from_pixel(256, 256, image::Rgba([0, 0, 0, 255]));
//! overlay.draw(0, 0, &mut map);
//! // The square spans grid samples 16..48, texels 64..192: its inside is red, outside black.
//! assert_eq!(map.get_pixel(128, 128).0, [255, 0, 0, 255]);
//! assert_eq!(map.get_pixel(20, 128).0, [0, 0, 0, 255]);
//! # Ok::<(), texmap_terrain::TerrainError>(())
//! ```

use crate::TerrainError;
use crate::dem::{CrsKind, Georef, Grid};
use crate::error::{format_err, io};
use crate::geodesy::Placement;
use serde::de::{self, DeserializeSeed, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde_json::Value;
use std::path::Path;

/// A position in the file's coordinates (x, y: longitude, latitude or easting, northing).
pub type Position = [f64; 2];

/// One feature: its points, line strings and polygon rings (a `GeometryCollection` or
/// `Multi*` geometry contributes all of its parts), with its own style keys.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Feature {
    pub points: Vec<Position>,
    pub lines: Vec<Vec<Position>>,
    /// Every ring of every polygon (outer boundaries and holes), filled by the even–odd rule.
    pub rings: Vec<Vec<Position>>,
    /// The simplestyle keys the feature sets.
    pub style: StyleKeys,
}

/// Simplestyle keys, each set or not (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StyleKeys {
    pub stroke: Option<Option<[u8; 3]>>,
    pub stroke_width: Option<f32>,
    pub stroke_opacity: Option<f32>,
    pub fill: Option<Option<[u8; 3]>>,
    pub fill_opacity: Option<f32>,
    pub marker_color: Option<Option<[u8; 3]>>,
    /// Disc diameter in texels.
    pub marker_size: Option<f32>,
}

/// The coordinate system of a layer's positions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LayerCrs {
    /// WGS 84 longitude and latitude (RFC 7946, or a `crs` member naming it).
    Lonlat,
    /// An EPSG code from a `crs` member, with its placement.
    Epsg(u16, Placement),
}

/// A GeoJSON file's features in its own coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct VectorLayer {
    /// The file name (or the name given to bytes in memory), for errors and notes.
    pub source: String,
    pub crs: LayerCrs,
    pub features: Vec<Feature>,
}

/// A layer's default style: what a feature's missing simplestyle keys take.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    /// Line colour (`None`: no lines, no polygon outlines).
    pub stroke: Option<[u8; 3]>,
    /// Line width, texels of the finest level.
    pub stroke_width: f32,
    pub stroke_opacity: f32,
    /// Polygon fill (`None`: outlines only).
    pub fill: Option<[u8; 3]>,
    pub fill_opacity: f32,
    /// Point colour (`None`: points not drawn).
    pub marker_color: Option<[u8; 3]>,
    /// Point disc diameter, texels.
    pub marker_size: f32,
}

impl Default for Style {
    /// simplestyle-spec 1.1's defaults.
    fn default() -> Self {
        Style {
            stroke: Some([0x55; 3]),
            stroke_width: 2.0,
            stroke_opacity: 1.0,
            fill: Some([0x55; 3]),
            fill_opacity: 0.6,
            marker_color: Some([0x7e; 3]),
            marker_size: 9.0,
        }
    }
}

/// Marker diameters in texels for simplestyle's `small`, `medium`, `large`.
const MARKER_SIZES: [(&str, f32); 3] = [("small", 6.0), ("medium", 9.0), ("large", 13.0)];

/// A colour `#rgb` / `#rrggbb`, or `none` (not drawn).
fn parse_colour(s: &str) -> Option<Option<[u8; 3]>> {
    let s = s.trim();
    if s.eq_ignore_ascii_case("none") {
        return Some(None);
    }
    let hex = s.strip_prefix('#')?;
    if !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    let v = |i: usize, n: usize| u8::from_str_radix(&hex[i..i + n], 16).ok();
    match hex.len() {
        3 => Some(Some([v(0, 1)? * 17, v(1, 1)? * 17, v(2, 1)? * 17])),
        6 => Some(Some([v(0, 2)?, v(2, 2)?, v(4, 2)?])),
        _ => None,
    }
}

/// One simplestyle key's value (a JSON value from a feature, or text from the command line)
/// into `keys`; `Err` says what was expected.
fn set_key(keys: &mut StyleKeys, key: &str, value: &Value) -> Result<bool, String> {
    let colour = |v: &Value| {
        v.as_str()
            .and_then(parse_colour)
            .ok_or_else(|| format!("\"{key}\" as a colour #rgb, #rrggbb or none, found {v}"))
    };
    // Numbers may come as JSON numbers or as numeric strings (some writers quote them).
    let number = |v: &Value, lo: f64, hi: f64| {
        let x = match v {
            Value::Number(n) => n.as_f64(),
            Value::String(s) => s.trim().parse::<f64>().ok(),
            _ => None,
        };
        x.filter(|x| x.is_finite() && (lo..=hi).contains(x))
            .map(|x| x as f32)
            .ok_or_else(|| format!("\"{key}\" as a number from {lo} to {hi}, found {v}"))
    };
    match key {
        "stroke" => keys.stroke = Some(colour(value)?),
        "stroke-width" => keys.stroke_width = Some(number(value, 0.0, 256.0)?),
        "stroke-opacity" => keys.stroke_opacity = Some(number(value, 0.0, 1.0)?),
        "fill" => keys.fill = Some(colour(value)?),
        "fill-opacity" => keys.fill_opacity = Some(number(value, 0.0, 1.0)?),
        "marker-color" => keys.marker_color = Some(colour(value)?),
        "marker-size" => {
            let named = value.as_str().and_then(|s| {
                MARKER_SIZES
                    .iter()
                    .find(|(n, _)| n.eq_ignore_ascii_case(s.trim()))
                    .map(|(_, d)| *d)
            });
            keys.marker_size = Some(match named {
                Some(d) => d,
                None => number(value, 0.0, 256.0).map_err(|_| {
                    format!("\"marker-size\" as small, medium, large or texels, found {value}")
                })?,
            });
        }
        _ => return Ok(false),
    }
    Ok(true)
}

impl Style {
    /// `self` with the keys of a `key=value,key=value` list set (simplestyle names, e.g.
    /// `stroke=#ff0000,stroke-width=3,fill=none`); an unknown key or a bad value is an error
    /// naming it.
    pub fn with_keys(mut self, list: &str) -> Result<Style, TerrainError> {
        let mut keys = StyleKeys::default();
        for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let bad = |expected: String| format_err("overlay style", item, expected);
            let (k, v) = item
                .split_once('=')
                .ok_or_else(|| bad("key=value (simplestyle keys)".into()))?;
            let (k, v) = (k.trim(), v.trim());
            let value = match v.parse::<f64>() {
                Ok(x) if k != "stroke" && k != "fill" && k != "marker-color" => {
                    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
                }
                _ => Value::String(v.to_string()),
            };
            if !set_key(&mut keys, k, &value).map_err(bad)? {
                return Err(bad(
                    "a simplestyle key: stroke, stroke-width, stroke-opacity, fill, \
                     fill-opacity, marker-color, marker-size"
                        .into(),
                ));
            }
        }
        self.apply(&keys);
        Ok(self)
    }

    fn apply(&mut self, k: &StyleKeys) {
        if let Some(c) = k.stroke {
            self.stroke = c;
        }
        if let Some(w) = k.stroke_width {
            self.stroke_width = w;
        }
        if let Some(o) = k.stroke_opacity {
            self.stroke_opacity = o;
        }
        if let Some(c) = k.fill {
            self.fill = c;
        }
        if let Some(o) = k.fill_opacity {
            self.fill_opacity = o;
        }
        if let Some(c) = k.marker_color {
            self.marker_color = c;
        }
        if let Some(s) = k.marker_size {
            self.marker_size = s;
        }
    }
}

/// Read a vector layer: an ESRI shapefile (`.shp`, [`crate::shapefile`]) or GeoJSON in any of
/// the forms of the module docs.
pub fn read_vector(path: impl AsRef<Path>) -> Result<VectorLayer, TerrainError> {
    let path = path.as_ref();
    let shp = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("shp"));
    if shp {
        crate::shapefile::read_shapefile(path)
    } else {
        read_geojson(path)
    }
}

/// Read a GeoJSON file (see the module docs for the forms read).
pub fn read_geojson(path: impl AsRef<Path>) -> Result<VectorLayer, TerrainError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(io(path))?;
    parse_geojson(&bytes, &path.display().to_string())
}

/// [`read_geojson`] of bytes in memory; `source` names them in errors.
pub fn parse_geojson(bytes: &[u8], source: &str) -> Result<VectorLayer, TerrainError> {
    let json_err = |e: serde_json::Error| {
        let pos = format!("line {} column {}", e.line(), e.column());
        let msg = e.to_string();
        // serde_json appends " at line L column C"; the position is already in `at`.
        let msg = msg.rfind(" at line ").map_or(&msg[..], |i| &msg[..i]);
        match msg.split_once('\u{1f}') {
            // A feature that parsed but is not GeoJSON: its path, then what was expected.
            Some((path, expected)) => format_err(source, format!("{pos}, {path}"), expected),
            None => format_err(source, pos, format!("JSON ({msg})")),
        }
    };
    // GeoJSON text sequences: RS-separated (RFC 8142), or newline-delimited features (a first
    // line that is a whole JSON value, with more after it; a pretty-printed document's first
    // line is not one).
    let is_seq = bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&0x1e);
    let line_end = bytes
        .iter()
        .position(|&b| b == b'\n')
        .unwrap_or(bytes.len());
    let multiple = !is_seq
        && serde_json::from_slice::<IgnoredAny>(&bytes[..line_end]).is_ok()
        && bytes[line_end..].iter().any(|b| !b.is_ascii_whitespace());
    if is_seq || multiple {
        let cleaned: Vec<u8> = bytes
            .iter()
            .map(|&b| if b == 0x1e { b' ' } else { b })
            .collect();
        let mut features = Vec::new();
        for (i, v) in serde_json::Deserializer::from_slice(&cleaned)
            .into_iter::<Value>()
            .enumerate()
        {
            let v = v.map_err(json_err)?;
            let at = format!("record {}", i + 1);
            if v.get("type").and_then(Value::as_str) != Some("Feature") {
                return Err(format_err(
                    source,
                    at,
                    "a Feature in a GeoJSON text sequence",
                ));
            }
            features.push(feature_of(&v).map_err(|e| {
                let at = match e.path.is_empty() {
                    true => at.clone(),
                    false => format!("{at}, {}", e.path),
                };
                format_err(source, at, e.expected)
            })?);
        }
        return Ok(VectorLayer {
            source: source.to_string(),
            crs: LayerCrs::Lonlat,
            features,
        });
    }
    let mut de = serde_json::Deserializer::from_slice(bytes);
    let top = Top::default();
    let top = de::Deserializer::deserialize_map(&mut de, TopVisitor(top)).map_err(json_err)?;
    de.end().map_err(json_err)?;
    let crs = match &top.crs {
        None | Some(Value::Null) => LayerCrs::Lonlat,
        Some(v) => layer_crs(v).map_err(|e| format_err(source, "crs", e))?,
    };
    let features = match top.kind.as_deref() {
        Some("FeatureCollection") => {
            if !top.has_features {
                return Err(format_err(
                    source,
                    "FeatureCollection",
                    "a \"features\" array",
                ));
            }
            top.features
        }
        Some("Feature") => {
            let mut obj = serde_json::Map::new();
            obj.insert("type".into(), "Feature".into());
            obj.insert("geometry".into(), top.geometry.unwrap_or(Value::Null));
            obj.insert("properties".into(), top.properties.unwrap_or(Value::Null));
            vec![
                feature_of(&Value::Object(obj))
                    .map_err(|e| format_err(source, e.path, e.expected))?,
            ]
        }
        Some(kind) if GEOMETRIES.contains(&kind) => {
            let mut g = serde_json::Map::new();
            g.insert("type".into(), kind.into());
            if let Some(c) = top.coordinates {
                g.insert("coordinates".into(), c);
            }
            if let Some(c) = top.geometries {
                g.insert("geometries".into(), c);
            }
            let mut f = Feature::default();
            add_geometry(&mut f, &Value::Object(g), kind).map_err(|e| {
                let at = match e.path.is_empty() {
                    true => kind.to_string(),
                    false => format!("{kind}, {}", e.path),
                };
                format_err(source, at, e.expected)
            })?;
            vec![f]
        }
        Some(kind) => {
            return Err(format_err(
                source,
                format!("\"type\": \"{kind}\""),
                "a GeoJSON object: FeatureCollection, Feature or a geometry",
            ));
        }
        None => {
            return Err(format_err(
                source,
                "the top-level object",
                "a \"type\" member (GeoJSON: FeatureCollection, Feature or a geometry)",
            ));
        }
    };
    Ok(VectorLayer {
        source: source.to_string(),
        crs,
        features,
    })
}

const GEOMETRIES: [&str; 7] = [
    "Point",
    "MultiPoint",
    "LineString",
    "MultiLineString",
    "Polygon",
    "MultiPolygon",
    "GeometryCollection",
];

/// The members of the top-level object that matter, `features` converted as they stream by.
#[derive(Default)]
struct Top {
    kind: Option<String>,
    crs: Option<Value>,
    has_features: bool,
    features: Vec<Feature>,
    geometry: Option<Value>,
    properties: Option<Value>,
    coordinates: Option<Value>,
    geometries: Option<Value>,
}

struct TopVisitor(Top);

impl<'de> Visitor<'de> for TopVisitor {
    type Value = Top;
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a GeoJSON object")
    }
    fn visit_map<A: MapAccess<'de>>(mut self, mut map: A) -> Result<Top, A::Error> {
        let top = &mut self.0;
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "type" => top.kind = Some(map.next_value()?),
                "crs" => top.crs = Some(map.next_value()?),
                "features" => {
                    top.has_features = true;
                    map.next_value_seed(FeaturesSeed(&mut top.features))?;
                }
                "geometry" => top.geometry = Some(map.next_value()?),
                "properties" => top.properties = Some(map.next_value()?),
                "coordinates" => top.coordinates = Some(map.next_value()?),
                "geometries" => top.geometries = Some(map.next_value()?),
                _ => {
                    map.next_value::<IgnoredAny>()?;
                }
            }
        }
        Ok(self.0)
    }
}

/// The `features` array, each element converted as soon as it is parsed.
struct FeaturesSeed<'a>(&'a mut Vec<Feature>);

impl<'de> DeserializeSeed<'de> for FeaturesSeed<'_> {
    type Value = ();
    fn deserialize<D: de::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for FeaturesSeed<'_> {
    type Value = ();
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("an array of Features")
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        while let Some(v) = seq.next_element::<Value>()? {
            let at = format!("features[{}]", self.0.len());
            let f = feature_of(&v).map_err(|e| {
                let e = e.under(&at);
                de::Error::custom(format!("{}\u{1f}{}", e.path, e.expected))
            })?;
            self.0.push(f);
        }
        Ok(())
    }
}

/// The EPSG code a `crs` member names.
fn layer_crs(v: &Value) -> Result<LayerCrs, String> {
    let props = v.get("properties");
    let name = props
        .and_then(|p| p.get("name"))
        .and_then(Value::as_str)
        .map(str::to_string);
    let code = match (&name, props.and_then(|p| p.get("code"))) {
        (Some(n), _) => {
            let n = n.trim();
            if n.ends_with("CRS84") || n.ends_with("CRS:84") {
                return Ok(LayerCrs::Lonlat);
            }
            n.rsplit(':')
                .next()
                .and_then(|c| c.trim().parse::<u32>().ok())
        }
        (None, Some(c)) => c.as_u64().map(|c| c as u32),
        (None, None) => None,
    };
    let code = code.ok_or_else(|| {
        format!(
            "a \"crs\" naming an EPSG code (\"urn:ogc:def:crs:EPSG::4326\" or \"EPSG:32633\"), found {v}"
        )
    })?;
    layer_crs_of_epsg(code)
}

/// The layer system of an EPSG code (900913, the old Web Mercator code, as 3857), or why it is
/// not one texmap places.
pub(crate) fn layer_crs_of_epsg(code: u32) -> Result<LayerCrs, String> {
    let code = if code == 900913 { 3857 } else { code };
    let epsg = u16::try_from(code).ok();
    let georef = |crs| Georef {
        crs,
        epsg,
        origin_x: 0.0,
        origin_y: 0.0,
        dx: 1.0,
        dy: -1.0,
    };
    let placement = match epsg {
        Some(4326 | 4258 | 4269 | 4979) => return Ok(LayerCrs::Lonlat),
        Some(_) => Placement::of(&georef(CrsKind::Projected)),
        None => None,
    };
    match (epsg, placement) {
        (Some(e), Some(p)) => Ok(LayerCrs::Epsg(e, p)),
        _ => Err(format!(
            "a system texmap places (WGS 84 degrees, UTM of WGS 84, ETRS89 or NAD83, Web Mercator), \
             found EPSG:{code} (convert with ogr2ogr -t_srs EPSG:4326)"
        )),
    }
}

/// What a part of a feature should have been: its JSON path below the feature (`geometry.
/// coordinates[0][3]`) and what was expected there.
#[derive(Debug)]
struct Bad {
    path: String,
    expected: String,
}

impl Bad {
    fn new(expected: impl Into<String>) -> Bad {
        Bad {
            path: String::new(),
            expected: expected.into(),
        }
    }

    /// The same error one level up: `key` (a member name) or `[i]` (an index) before the path.
    fn under(mut self, key: &str) -> Bad {
        self.path = match (self.path.is_empty(), self.path.starts_with('[')) {
            (true, _) => key.to_string(),
            (false, true) => format!("{key}{}", self.path),
            (false, false) => format!("{key}.{}", self.path),
        };
        self
    }

    fn index(self, i: usize) -> Bad {
        self.under(&format!("[{i}]"))
    }
}

/// One Feature object into a [`Feature`].
fn feature_of(v: &Value) -> Result<Feature, Bad> {
    let obj = v.as_object().ok_or_else(|| Bad::new("a Feature object"))?;
    match obj.get("type").and_then(Value::as_str) {
        Some("Feature") => {}
        other => {
            return Err(Bad::new(format!(
                "\"Feature\", found {}",
                other.map_or("none".to_string(), |t| format!("\"{t}\""))
            ))
            .under("type"));
        }
    }
    let mut f = Feature::default();
    if let Some(Value::Object(p)) = obj.get("properties") {
        // A null property is one the feature does not set (ogr2ogr writes empty fields so).
        for (k, value) in p.iter().filter(|(_, v)| !v.is_null()) {
            set_key(&mut f.style, k, value).map_err(|e| Bad::new(e).under("properties"))?;
        }
    }
    match obj.get("geometry") {
        // A feature without a geometry (allowed by RFC 7946) draws nothing.
        None | Some(Value::Null) => {}
        Some(g) => {
            let kind = g.get("type").and_then(Value::as_str).unwrap_or("");
            add_geometry(&mut f, g, kind).map_err(|e| e.under("geometry"))?;
        }
    }
    Ok(f)
}

fn add_geometry(f: &mut Feature, g: &Value, kind: &str) -> Result<(), Bad> {
    let unknown = || {
        Bad::new(format!(
            "a geometry type ({}), found {kind:?}",
            GEOMETRIES.join(", ")
        ))
        .under("type")
    };
    if kind == "GeometryCollection" {
        let parts = g
            .get("geometries")
            .and_then(Value::as_array)
            .ok_or_else(|| Bad::new("an array of geometries").under("geometries"))?;
        for (i, p) in parts.iter().enumerate() {
            let k = p.get("type").and_then(Value::as_str).unwrap_or("");
            add_geometry(f, p, k).map_err(|e| e.index(i).under("geometries"))?;
        }
        return Ok(());
    }
    if !GEOMETRIES.contains(&kind) {
        return Err(unknown());
    }
    let c = g
        .get("coordinates")
        .ok_or_else(|| Bad::new("a \"coordinates\" member"))?;
    let each = |c: &Value| -> Result<Vec<Value>, Bad> {
        c.as_array()
            .cloned()
            .ok_or_else(|| Bad::new(format!("an array, found {}", short(c))))
    };
    let r = match kind {
        "Point" => position(c).map(|p| f.points.push(p)),
        "MultiPoint" => each(c).and_then(|ps| {
            for (i, p) in ps.iter().enumerate() {
                f.points.push(position(p).map_err(|e| e.index(i))?);
            }
            Ok(())
        }),
        "LineString" => line(c).map(|l| f.lines.push(l)),
        "MultiLineString" => each(c).and_then(|ls| {
            for (i, l) in ls.iter().enumerate() {
                f.lines.push(line(l).map_err(|e| e.index(i))?);
            }
            Ok(())
        }),
        "Polygon" => polygon(f, c),
        "MultiPolygon" => each(c).and_then(|ps| {
            for (i, p) in ps.iter().enumerate() {
                polygon(f, p).map_err(|e| e.index(i))?;
            }
            Ok(())
        }),
        _ => return Err(unknown()),
    };
    r.map_err(|e| e.under("coordinates"))
}

fn short(v: &Value) -> String {
    let s = v.to_string();
    match s.char_indices().nth(40) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s,
    }
}

fn position(v: &Value) -> Result<Position, Bad> {
    let a = v.as_array();
    let x = a.and_then(|a| a.first()).and_then(Value::as_f64);
    let y = a.and_then(|a| a.get(1)).and_then(Value::as_f64);
    match (x, y) {
        (Some(x), Some(y)) => Ok([x, y]),
        _ => Err(Bad::new(format!("a position [x, y], found {}", short(v)))),
    }
}

/// A line string's positions.
fn line(v: &Value) -> Result<Vec<Position>, Bad> {
    let a = v
        .as_array()
        .ok_or_else(|| Bad::new(format!("an array of positions, found {}", short(v))))?;
    let pts = a
        .iter()
        .enumerate()
        .map(|(i, p)| position(p).map_err(|e| e.index(i)))
        .collect::<Result<Vec<_>, _>>()?;
    if pts.len() < 2 {
        return Err(Bad::new(format!(
            "at least 2 positions in a line string, found {}",
            pts.len()
        )));
    }
    Ok(pts)
}

/// A polygon's rings into `f.rings` (closed if the file left them open).
fn polygon(f: &mut Feature, v: &Value) -> Result<(), Bad> {
    let rings = v
        .as_array()
        .ok_or_else(|| Bad::new(format!("an array of rings, found {}", short(v))))?;
    for (i, r) in rings.iter().enumerate() {
        let mut pts = line(r).map_err(|e| e.index(i))?;
        if pts.first() != pts.last() {
            pts.push(pts[0]);
        }
        if pts.len() < 4 {
            return Err(Bad::new(format!(
                "a linear ring of at least 4 positions (3 corners and the first again), found {}",
                pts.len()
            ))
            .index(i));
        }
        f.rings.push(pts);
    }
    Ok(())
}

/// A paint: sRGB colour and opacity.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Paint {
    rgb: [u8; 3],
    alpha: f32,
}

/// One drawable piece of a feature, in finest-level texel coordinates (texel `(i, j)`'s centre
/// at `(i, j)`).
#[derive(Clone, Debug)]
struct Shape {
    /// Segments measured for distance: a polygon's ring edges, a line's segments, or a point
    /// as a segment of length zero.
    edges: Vec<[Position; 2]>,
    /// Polygons: filled by the even–odd rule over `edges`.
    fill: Option<Paint>,
    /// Lines, outlines and point discs: paint and full width in texels.
    stroke: Option<(Paint, f32)>,
    /// Bounds of the edges, widened by the reach of the anti-aliasing and the stroke.
    lo: Position,
    hi: Position,
}

impl Shape {
    /// How far from an edge the shape can cover a texel.
    fn reach(&self) -> f64 {
        let s = self.stroke.map_or(0.0, |(_, w)| stroke_reach(w));
        let f = if self.fill.is_some() { 0.5 } else { 0.0 };
        s.max(f)
    }
}

fn stroke_reach(w: f32) -> f64 {
    if w >= 1.0 { w as f64 / 2.0 + 0.5 } else { 1.0 }
}

/// Coverage of a texel at distance `d` from the nearest segment of a stroke `w` texels wide.
fn stroke_coverage(w: f32, d: f32) -> f32 {
    if w >= 1.0 {
        (w / 2.0 + 0.5 - d).clamp(0.0, 1.0)
    } else {
        w * (1.0 - d).clamp(0.0, 1.0)
    }
}

/// Layers placed on a texture's finest level, ready to draw map by map.
#[derive(Clone, Debug)]
pub struct Overlay {
    size: u32,
    map_texels: u32,
    shapes: Vec<Shape>,
    /// Per map (row-major, `size / map_texels` a side): the shapes reaching it, in draw order.
    bins: Vec<Vec<u32>>,
    /// Per layer: features that reach the texture, of all.
    counts: Vec<(String, usize, usize)>,
}

impl Overlay {
    /// Place `layers` on the finest texture level (`size` texels a side, the texture spanning
    /// `grid` from its first sample to its last) cut into maps of `map_texels`; a feature's
    /// missing style keys come from `style`. A layer none of whose features reaches the texture
    /// is an error (a wrong coordinate system, most often), as is a grid without a
    /// georeference, a layer in lon/lat whose positions are not longitudes and latitudes, or a
    /// position that does not project.
    pub fn place(
        layers: &[VectorLayer],
        style: &Style,
        grid: &Grid,
        size: u32,
        map_texels: u32,
    ) -> Result<Overlay, TerrainError> {
        if map_texels == 0 || size < 2 || !size.is_multiple_of(map_texels) {
            return Err(TerrainError::BadParameter {
                name: "overlay texture size",
                value: format!("{size} texels in maps of {map_texels}"),
                expected: "a whole number of maps, at least 2 texels",
            });
        }
        let g = grid.georef();
        let dem = Placement::of(g);
        let per_texel = [
            (grid.width() - 1) as f64 / (size - 1) as f64,
            (grid.height() - 1) as f64 / (size - 1) as f64,
        ];
        let n = size / map_texels;
        let mut overlay = Overlay {
            size,
            map_texels,
            shapes: Vec::new(),
            bins: vec![Vec::new(); (n * n) as usize],
            counts: Vec::new(),
        };
        for layer in layers {
            let src = &layer.source;
            // The file's coordinates -> the DEM's, by way of longitude and latitude unless both
            // name the same EPSG code.
            let same = match layer.crs {
                LayerCrs::Epsg(e, _) => g.epsg == Some(e),
                LayerCrs::Lonlat => g.crs == CrsKind::Geographic,
            };
            let Some(dem) = dem.or(same.then_some(Placement::Geographic)) else {
                return Err(TerrainError::Unsupported {
                    source: src.clone(),
                    what: format!(
                        "a vector overlay on {} (a grid without a georeference texmap places)",
                        grid_name(grid)
                    ),
                });
            };
            let to_texel = |p: Position| -> Result<Position, String> {
                let lonlat = layer.crs == LayerCrs::Lonlat;
                if lonlat && (!(-180.0..=180.0).contains(&p[0]) || !(-90.0..=90.0).contains(&p[1]))
                {
                    return Err(format!(
                        "longitude and latitude in degrees (a GeoJSON file without a \
                         \"crs\" member is WGS 84, RFC 7946), found ({}, {})",
                        p[0], p[1]
                    ));
                }
                let (x, y) = match layer.crs {
                    _ if same => (p[0], p[1]),
                    LayerCrs::Lonlat => dem.xy(p[0], p[1]),
                    LayerCrs::Epsg(_, pl) => {
                        let (lon, lat) = pl.lonlat(p[0], p[1]);
                        dem.xy(lon, lat)
                    }
                };
                let (col, row) = g.xy_to_sample(x, y);
                let t = [col / per_texel[0], row / per_texel[1]];
                if t.iter().all(|v| v.is_finite()) {
                    Ok(t)
                } else {
                    Err(format!(
                        "a position that projects onto the grid's system, found ({}, {})",
                        p[0], p[1]
                    ))
                }
            };
            let mut reached = 0;
            for (fi, f) in layer.features.iter().enumerate() {
                let mut st = *style;
                st.apply(&f.style);
                let project = |pts: &[Position]| -> Result<Vec<Position>, TerrainError> {
                    pts.iter()
                        .map(|&p| to_texel(p))
                        .collect::<Result<_, _>>()
                        .map_err(|e| format_err(src, format!("features[{fi}]"), e))
                };
                let paint = |c: Option<[u8; 3]>, a: f32| {
                    c.filter(|_| a > 0.0).map(|rgb| Paint { rgb, alpha: a })
                };
                let stroke = paint(st.stroke, st.stroke_opacity)
                    .filter(|_| st.stroke_width > 0.0)
                    .map(|p| (p, st.stroke_width));
                let mut pieces = Vec::new();
                if !f.rings.is_empty() {
                    let mut edges = Vec::new();
                    for r in &f.rings {
                        let t = project(r)?;
                        edges.extend(t.windows(2).map(|w| [w[0], w[1]]));
                    }
                    pieces.push((edges, paint(st.fill, st.fill_opacity), stroke));
                }
                if !f.lines.is_empty() && stroke.is_some() {
                    let mut edges = Vec::new();
                    for l in &f.lines {
                        let t = project(l)?;
                        edges.extend(t.windows(2).map(|w| [w[0], w[1]]));
                    }
                    pieces.push((edges, None, stroke));
                }
                let marker = paint(st.marker_color, 1.0)
                    .filter(|_| st.marker_size > 0.0)
                    .map(|p| (p, st.marker_size));
                if !f.points.is_empty() && marker.is_some() {
                    let t = project(&f.points)?;
                    pieces.push((t.iter().map(|&p| [p, p]).collect(), None, marker));
                }
                let mut any = false;
                for (edges, fill, stroke) in pieces {
                    if fill.is_none() && stroke.is_none() {
                        continue;
                    }
                    any |= overlay.add(Shape {
                        edges,
                        fill,
                        stroke,
                        lo: [0.0; 2],
                        hi: [0.0; 2],
                    });
                }
                reached += any as usize;
            }
            if reached == 0 && !layer.features.is_empty() {
                return Err(TerrainError::NoOverlap {
                    photo: src.clone(),
                    dem: grid_name(grid),
                });
            }
            overlay
                .counts
                .push((src.clone(), reached, layer.features.len()));
        }
        Ok(overlay)
    }

    /// Bin a shape by the maps its bounds reach; false if it reaches none.
    fn add(&mut self, mut s: Shape) -> bool {
        let r = s.reach();
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for e in &s.edges {
            for p in e {
                for k in 0..2 {
                    lo[k] = lo[k].min(p[k] - r);
                    hi[k] = hi[k].max(p[k] + r);
                }
            }
        }
        let last = (self.size - 1) as f64;
        if s.edges.is_empty()
            || hi[0] < -0.5
            || hi[1] < -0.5
            || lo[0] > last + 0.5
            || lo[1] > last + 0.5
        {
            return false;
        }
        s.lo = lo;
        s.hi = hi;
        let t = self.map_texels as f64;
        let n = self.size / self.map_texels;
        let map_of = |v: f64| ((v + 0.5) / t).floor().clamp(0.0, (n - 1) as f64) as u32;
        let id = self.shapes.len() as u32;
        for my in map_of(lo[1])..=map_of(hi[1]) {
            for mx in map_of(lo[0])..=map_of(hi[0]) {
                self.bins[(my * n + mx) as usize].push(id);
            }
        }
        self.shapes.push(s);
        true
    }

    /// The finest level's size in texels a side.
    pub fn size(&self) -> u32 {
        self.size
    }

    /// Per layer: its source, the features that reach the texture, and all its features.
    pub fn counts(&self) -> &[(String, usize, usize)] {
        &self.counts
    }

    /// Draw the overlay into map `(mx, my)` of the finest level (`map`: `map_texels` a side).
    pub fn draw(&self, mx: u32, my: u32, map: &mut image::RgbaImage) {
        let n = self.size / self.map_texels;
        let t = self.map_texels;
        if mx >= n || my >= n || map.width() != t || map.height() != t {
            return;
        }
        let ids = &self.bins[(my * n + mx) as usize];
        if ids.is_empty() {
            return;
        }
        let (x0, y0) = ((mx * t) as i64, (my * t) as i64);
        let mut dist = vec![f32::INFINITY; (t * t) as usize];
        let mut xs: Vec<f64> = Vec::new();
        let mut band: Vec<(f64, f64, usize)> = Vec::new();
        let mut active: Vec<(f64, usize)> = Vec::new();
        for &id in ids {
            let s = &self.shapes[id as usize];
            // The texels the shape's bounds reach, within this map.
            let clip = |lo: f64, hi: f64, o: i64| {
                let a = (lo.ceil().max(o as f64)) as i64;
                let b = (hi.floor().min((o + t as i64 - 1) as f64)) as i64;
                (a, b)
            };
            let (ia, ib) = clip(s.lo[0], s.hi[0], x0);
            let (ja, jb) = clip(s.lo[1], s.hi[1], y0);
            if ia > ib || ja > jb {
                continue;
            }
            let reach = s.reach();
            // Distance to the nearest edge for texels within `reach` of one.
            for j in ja..=jb {
                let row = ((j - y0) * t as i64) as usize;
                dist[row + (ia - x0) as usize..=row + (ib - x0) as usize].fill(f32::INFINITY);
            }
            for e in &s.edges {
                near_texels(e, reach, (ia, ib), (ja, jb), |i, j, d| {
                    let k = ((j - y0) * t as i64 + (i - x0)) as usize;
                    if d < dist[k] {
                        dist[k] = d;
                    }
                });
            }
            // Fills: the edges spanning this map's rows, by their lowest y, swept down the rows
            // (an edge crosses row y when lo ≤ y < hi).
            band.clear();
            active.clear();
            if s.fill.is_some() {
                for (k, e) in s.edges.iter().enumerate() {
                    let (lo, hi) = (e[0][1].min(e[1][1]), e[0][1].max(e[1][1]));
                    if lo < hi && hi > ja as f64 && lo <= jb as f64 {
                        band.push((lo, hi, k));
                    }
                }
                band.sort_by(|a, b| a.0.total_cmp(&b.0));
            }
            let mut entered = 0;
            for j in ja..=jb {
                let yc = j as f64;
                if s.fill.is_some() {
                    while entered < band.len() && band[entered].0 <= yc {
                        active.push((band[entered].1, band[entered].2));
                        entered += 1;
                    }
                    active.retain(|&(hi, _)| hi > yc);
                    xs.clear();
                    for &(_, k) in &active {
                        let [a, b] = s.edges[k];
                        xs.push(a[0] + (yc - a[1]) * (b[0] - a[0]) / (b[1] - a[1]));
                    }
                    xs.sort_by(f64::total_cmp);
                }
                let mut next = 0;
                for i in ia..=ib {
                    let k = ((j - y0) * t as i64 + (i - x0)) as usize;
                    let d = dist[k];
                    let px = map.get_pixel_mut((i - x0) as u32, (j - y0) as u32);
                    if let Some(f) = s.fill {
                        while next < xs.len() && xs[next] < i as f64 {
                            next += 1;
                        }
                        let inside = next % 2 == 1;
                        let c = if inside {
                            (0.5 + d).min(1.0)
                        } else {
                            (0.5 - d).max(0.0)
                        };
                        px.0 = over(px.0, f, c);
                    }
                    if let Some((p, w)) = s.stroke {
                        px.0 = over(px.0, p, stroke_coverage(w, d));
                    }
                }
            }
        }
    }
}

fn grid_name(grid: &Grid) -> String {
    format!("the {} x {} grid", grid.width(), grid.height())
}

/// `paint` at `coverage` composited over an 8-bit sRGB texel (Porter–Duff over).
fn over(px: [u8; 4], paint: Paint, coverage: f32) -> [u8; 4] {
    let a = paint.alpha * coverage;
    if a <= 0.0 {
        return px;
    }
    let pa = px[3] as f32 / 255.0;
    let out_a = a + pa * (1.0 - a);
    let mix = |c: u8, p: u8| {
        ((p as f32 * a + c as f32 * pa * (1.0 - a)) / out_a)
            .round()
            .clamp(0.0, 255.0) as u8
    };
    [
        mix(px[0], paint.rgb[0]),
        mix(px[1], paint.rgb[1]),
        mix(px[2], paint.rgb[2]),
        (out_a * 255.0).round() as u8,
    ]
}

/// Call `f(i, j, d)` for the texel centres `(i, j)` within the texel ranges that may lie within
/// `reach` of segment `e`, with `d` their distance to it (rows first, then the segment's x range
/// over the rows within reach, so a long diagonal visits a band, not its bounding box).
fn near_texels(
    e: &[Position; 2],
    reach: f64,
    (ia, ib): (i64, i64),
    (ja, jb): (i64, i64),
    mut f: impl FnMut(i64, i64, f32),
) {
    let (a, b) = (e[0], e[1]);
    let (ylo, yhi) = (a[1].min(b[1]), a[1].max(b[1]));
    let j0 = ((ylo - reach).ceil() as i64).max(ja);
    let j1 = ((yhi + reach).floor() as i64).min(jb);
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    for j in j0..=j1 {
        let yc = j as f64;
        // The segment's x range over the rows within reach of this one.
        let (xlo, xhi) = if dy.abs() < 1e-12 {
            (a[0].min(b[0]), a[0].max(b[0]))
        } else {
            let ya = (yc - reach).max(ylo);
            let yb = (yc + reach).min(yhi);
            let x_at = |y: f64| a[0] + (y - a[1]) * dx / dy;
            let (p, q) = (x_at(ya), x_at(yb));
            (p.min(q), p.max(q))
        };
        let i0 = ((xlo - reach).ceil() as i64).max(ia);
        let i1 = ((xhi + reach).floor() as i64).min(ib);
        for i in i0..=i1 {
            let (px, py) = (i as f64 - a[0], yc - a[1]);
            let s = if len2 > 0.0 {
                ((px * dx + py * dy) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let (qx, qy) = (px - s * dx, py - s * dy);
            let d = (qx * qx + qy * qy).sqrt();
            if d <= reach {
                f(i, j, d as f32);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn local_geo(n: u32) -> Grid {
        let g = Georef {
            crs: CrsKind::Geographic,
            epsg: Some(4326),
            origin_x: 0.0,
            origin_y: 0.0,
            dx: 0.01,
            dy: -0.01,
        };
        Grid::new("g", n, n, vec![0.0; (n * n) as usize], g).unwrap()
    }

    fn draw_all(o: &Overlay) -> image::RgbaImage {
        let s = o.size;
        let t = o.map_texels;
        let mut img = image::RgbaImage::from_pixel(s, s, image::Rgba([0, 0, 0, 255]));
        for my in 0..s / t {
            for mx in 0..s / t {
                let mut m = image::RgbaImage::from_pixel(t, t, image::Rgba([0, 0, 0, 255]));
                o.draw(mx, my, &mut m);
                image::imageops::replace(&mut img, &m, (mx * t) as i64, (my * t) as i64);
            }
        }
        img
    }

    /// A polygon's anti-aliased coverage sums to its area in texels, across map borders, with
    /// a hole; a diagonal edge included.
    #[test]
    fn fill_coverage_sums_to_the_area() {
        // 129 samples, 0.01° apart; texture 256 texels over 128 sample steps: 2 texels a step.
        let grid = local_geo(129);
        // A square 0.2° .. 0.9° (texels 40..180) minus a triangular hole.
        let json = br#"{"type":"Polygon","coordinates":[
            [[0.2,-0.2],[0.9,-0.2],[0.9,-0.9],[0.2,-0.9],[0.2,-0.2]],
            [[0.4,-0.4],[0.7,-0.4],[0.4,-0.7],[0.4,-0.4]]]}"#;
        let layer = parse_geojson(json, "sq").unwrap();
        let style = Style::default()
            .with_keys("fill=#ffffff,fill-opacity=1,stroke=none")
            .unwrap();
        let o = Overlay::place(&[layer], &style, &grid, 256, 64).unwrap();
        let img = draw_all(&o);
        let sum: f64 = img.pixels().map(|p| p.0[0] as f64 / 255.0).sum();
        let texels: f64 = 255.0 / 1.28; // texels per degree
        let area = (0.7 * texels).powi(2) - 0.5 * (0.3 * texels).powi(2);
        assert!((sum - area).abs() < 0.02 * area, "{sum} vs {area}");
        // Inside the hole (0.45°, -0.45°) and inside the ring.
        let t = |d: f64| (d * texels).round() as u32;
        assert_eq!(img.get_pixel(t(0.45), t(0.45)).0[0], 0);
        assert_eq!(img.get_pixel(t(0.8), t(0.3)).0[0], 255);
    }

    #[test]
    fn lines_have_their_width_and_points_their_discs() {
        let grid = local_geo(129);
        // A horizontal line across the texture at 0.5° south and a point.
        let json = br##"{"type":"FeatureCollection","features":[
            {"type":"Feature","properties":{"stroke":"#fff","stroke-width":4},
             "geometry":{"type":"LineString","coordinates":[[-1,-0.5],[2,-0.5]]}},
            {"type":"Feature","properties":{"marker-color":"#ffffff","marker-size":"large"},
             "geometry":{"type":"Point","coordinates":[0.3,-0.3]}}]}"##;
        let layer = parse_geojson(json, "l").unwrap();
        let o = Overlay::place(&[layer], &Style::default(), &grid, 256, 64).unwrap();
        let img = draw_all(&o);
        // Ink per column: the stroke's width.
        let col: f64 = (0..256)
            .map(|y| img.get_pixel(200, y).0[0] as f64 / 255.0)
            .sum();
        assert!((col - 4.0).abs() < 0.02, "{col}");
        // The disc: about π·6.5² texels of ink.
        let texels: f64 = 255.0 / 1.28;
        let (cx, cy) = ((0.3 * texels) as i64, (0.3 * texels) as i64);
        let ink: f64 = (cx - 10..=cx + 10)
            .flat_map(|x| (cy - 10..=cy + 10).map(move |y| (x, y)))
            .map(|(x, y)| img.get_pixel(x as u32, y as u32).0[0] as f64 / 255.0)
            .sum();
        let disc = std::f64::consts::PI * 6.5 * 6.5;
        assert!((ink - disc).abs() < 0.05 * disc, "{ink} vs {disc}");
    }

    #[test]
    fn errors_name_the_feature_and_what_was_expected() {
        let grid = local_geo(65);
        let err = |json: &[u8]| {
            parse_geojson(json, "f.geojson")
                .and_then(|l| Overlay::place(&[l], &Style::default(), &grid, 128, 64))
                .unwrap_err()
                .to_string()
        };
        let e = err(br#"{"type":"FeatureCollection","features":[
            {"type":"Feature","properties":{},"geometry":{"type":"Point","coordinates":[0.1,-0.1]}},
            {"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,0]]}}]}"#);
        assert!(
            e.contains("features[1]") && e.contains("at least 2 positions"),
            "{e}"
        );
        assert!(e.contains("line 3"), "{e}");
        let e = err(br#"{"type":"Feature","properties":{"stroke":"blue"},"geometry":null}"#);
        assert!(e.contains("\"stroke\" as a colour"), "{e}");
        let e = err(br#"{"type":"Point","coordinates":[313300, 4907360]}"#);
        assert!(e.contains("RFC 7946"), "{e}");
        let e = err(br#"{"type":"Point","coordinates":[40.0, 10.0]}"#);
        assert!(e.contains("does not overlap"), "{e}");
        let e = err(br#"{"type":"FeatureCollection","crs":{"type":"name","properties":{"name":"urn:ogc:def:crs:EPSG::2154"}},"features":[]}"#);
        assert!(e.contains("EPSG:2154") && e.contains("ogr2ogr"), "{e}");
        let e = err(br#"{"type":"FeatureCollection","features":[ {"type":"Feature""#);
        assert!(e.contains("line 1"), "{e}");
        let e = err(b"[1, 2]");
        assert!(e.contains("GeoJSON object"), "{e}");
    }

    #[test]
    fn style_lists_parse_and_refuse_unknown_keys() {
        let s = Style::default()
            .with_keys("stroke=#f00, stroke-width=3, fill=none, marker-size=small")
            .unwrap();
        assert_eq!(s.stroke, Some([255, 0, 0]));
        assert_eq!(s.stroke_width, 3.0);
        assert_eq!(s.fill, None);
        assert_eq!(s.marker_size, 6.0);
        assert!(Style::default().with_keys("colour=#fff").is_err());
        assert!(Style::default().with_keys("stroke-opacity=2").is_err());
    }

    #[test]
    fn text_sequences_read_every_record() {
        let seq = b"\x1e{\"type\":\"Feature\",\"properties\":null,\"geometry\":{\"type\":\"Point\",\"coordinates\":[1,2]}}\n\
                    \x1e{\"type\":\"Feature\",\"properties\":null,\"geometry\":{\"type\":\"Point\",\"coordinates\":[3,4]}}\n";
        let l = parse_geojson(seq, "s").unwrap();
        assert_eq!(l.features.len(), 2);
        assert_eq!(l.features[1].points, vec![[3.0, 4.0]]);
        let nd = b"{\"type\":\"Feature\",\"properties\":null,\"geometry\":{\"type\":\"Point\",\"coordinates\":[1,2]}}\n\
                   {\"type\":\"Feature\",\"properties\":null,\"geometry\":{\"type\":\"Point\",\"coordinates\":[3,4]}}\n";
        assert_eq!(parse_geojson(nd, "s").unwrap().features.len(), 2);
    }
}
