//! Flight paths: a sequence of [`FlightCamera`] views, read from a CSV or JSON file, generated as
//! an orbit, or the built-in study path over any grid.
//!
//! **Path files.** One view per CSV line or JSON array element, with the eye's `x, y` in the
//! grid's georeference, `altitude` in metres above sea level, `heading` and `pitch` in degrees,
//! and optionally `roll` and `fov` (horizontal, degrees). Missing optional values and the image
//! size come from a template camera.
//!
//! - CSV: columns `x,y,altitude,heading,pitch[,roll[,fov]]` in that order, or any order under a
//!   header line naming them (a first line that does not start with a number is a header).
//!   Blank lines and lines starting with `#` are skipped. Fields are separated by commas
//!   (surrounding spaces allowed).
//! - JSON (the file's first non-blank character is `[`): an array of objects with those keys.
//!
//! A bad line is an error naming the file and the 1-based line (CSV) or the array element and,
//! for a syntax error, the line and column (JSON): a missing or extra field, a value that is not a
//! finite number, an unknown header name. Whether each view is *valid* (eye inside the grid and
//! above the ground, pitch within ±90°) is the camera's check ([`FlightCamera::camera`]), made
//! when the view is drawn.
//!
//! **Orbits** ([`orbit`]) circle a centre at a radius, looking at it; **the study path**
//! ([`study_path`]) covers the cases Seed 000's sampler is judged on: a steep look-down from
//! high up, a low pass, a grazing view toward the horizon, a turn, and a slow pass of closely
//! spaced frames for temporal flicker.
//!
//! ```
//! use texmap_terrain::dem::{Georef, Grid};
//! use texmap_terrain::flight::{parse_path, study_path};
//! use texmap_terrain::view::FlightCamera;
//!
//! let grid = Grid::new("flat", 65, 65, vec![10.0; 65 * 65], Georef::local(10.0))?;
//! let template = FlightCamera { width: 64, height: 48, ..FlightCamera::over(&grid) };
//! let text = "x,y,altitude,heading,pitch\n320,-320,200,0,-30\n320,-300,200,10,-30\n";
//! let views = parse_path(text, "path.csv", &template)?;
//! assert_eq!(views.len(), 2);
//! assert_eq!(views[1].heading_deg, 10.0);
//! // A bad line names the file and the line.
//! let err = parse_path("320,-320,200,0\n", "path.csv", &template).unwrap_err();
//! assert_eq!(err.to_string(), "path.csv:1: expected 5 to 7 fields (x,y,altitude,heading,pitch[,roll[,fov]]), found 4");
//! // The built-in study path: at least 20 views, every one a valid camera over the grid.
//! let path = study_path(&grid, &template);
//! assert!(path.len() >= 20);
//! assert!(path.iter().all(|s| s.view.camera(&grid).is_ok()));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::Path;

use crate::dem::Grid;
use crate::view::{FlightCamera, ground_height};

/// Why a path file was refused.
#[derive(Debug)]
#[non_exhaustive]
pub enum PathError {
    Io {
        file: String,
        source: std::io::Error,
    },
    /// A CSV line (1-based) that does not hold a view.
    Line {
        file: String,
        line: usize,
        message: String,
    },
    /// A JSON file that does not parse (1-based line and column).
    Json {
        file: String,
        line: usize,
        column: usize,
        message: String,
    },
    /// A JSON array element (0-based) that does not hold a view.
    Element {
        file: String,
        index: usize,
        message: String,
    },
    /// A file with no views.
    Empty { file: String },
    /// A track that cannot be flown as a whole (no fix over the grid, a grid without a
    /// georeference, too many frames).
    Track { file: String, message: String },
}

impl std::fmt::Display for PathError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PathError::Io { file, source } => write!(f, "{file}: {source}"),
            PathError::Line {
                file,
                line,
                message,
            } => write!(f, "{file}:{line}: {message}"),
            PathError::Json {
                file,
                line,
                column,
                message,
            } => write!(f, "{file}:{line}:{column}: {message}"),
            PathError::Element {
                file,
                index,
                message,
            } => write!(f, "{file}: element {index}: {message}"),
            PathError::Empty { file } => write!(f, "{file}: no views in the path file"),
            PathError::Track { file, message } => write!(f, "{file}: {message}"),
        }
    }
}

impl std::error::Error for PathError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            PathError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// The path file's fields, in the order of a header-less CSV line.
const FIELDS: [&str; 7] = ["x", "y", "altitude", "heading", "pitch", "roll", "fov"];

/// Read a path file (CSV or JSON, see the module docs); `template` gives the image size and the
/// values of optional fields.
pub fn read_path(path: &Path, template: &FlightCamera) -> Result<Vec<FlightCamera>, PathError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| PathError::Io {
        file: file.clone(),
        source,
    })?;
    parse_path(&text, &file, template)
}

/// Parse a path file's text; `file` names it in errors.
pub fn parse_path(
    text: &str,
    file: &str,
    template: &FlightCamera,
) -> Result<Vec<FlightCamera>, PathError> {
    Ok(parse_located(text, file, template)?
        .into_iter()
        .map(|(_, v)| v)
        .collect())
}

/// Where a view was read: a CSV line (1-based) or a JSON array element (0-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Place {
    Line(usize),
    Element(usize),
}

fn parse_located(
    text: &str,
    file: &str,
    template: &FlightCamera,
) -> Result<Vec<(Place, FlightCamera)>, PathError> {
    let views = if text.trim_start().starts_with('[') {
        parse_json(text, file, template)?
    } else {
        parse_csv(text, file, template)?
    };
    if views.is_empty() {
        return Err(PathError::Empty { file: file.into() });
    }
    Ok(views)
}

/// [`parse_path`], then every view's camera checked over `grid` ([`FlightCamera::camera`]: eye
/// inside the grid and above the ground, pitch within ±90°, a valid field of view and size); a
/// view that fails is an error naming its line (CSV) or element (JSON).
pub fn parse_path_for(
    text: &str,
    file: &str,
    template: &FlightCamera,
    grid: &Grid,
) -> Result<Vec<FlightCamera>, PathError> {
    let views = parse_located(text, file, template)?;
    for (place, v) in &views {
        if let Err(e) = v.camera(grid) {
            return Err(match *place {
                Place::Line(line) => PathError::Line {
                    file: file.into(),
                    line,
                    message: e.to_string(),
                },
                Place::Element(index) => PathError::Element {
                    file: file.into(),
                    index,
                    message: e.to_string(),
                },
            });
        }
    }
    Ok(views.into_iter().map(|(_, v)| v).collect())
}

/// [`read_path`] with every view checked over `grid` ([`parse_path_for`]).
pub fn read_path_for(
    path: &Path,
    template: &FlightCamera,
    grid: &Grid,
) -> Result<Vec<FlightCamera>, PathError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| PathError::Io {
        file: file.clone(),
        source,
    })?;
    parse_path_for(&text, &file, template, grid)
}

fn view_from(values: &[Option<f64>; 7], template: &FlightCamera) -> FlightCamera {
    FlightCamera {
        eye_x: values[0].unwrap_or(template.eye_x),
        eye_y: values[1].unwrap_or(template.eye_y),
        altitude: values[2].unwrap_or(template.altitude),
        heading_deg: values[3].unwrap_or(template.heading_deg),
        pitch_deg: values[4].unwrap_or(template.pitch_deg),
        roll_deg: values[5].unwrap_or(template.roll_deg),
        hfov_deg: values[6].unwrap_or(template.hfov_deg),
        ..template.clone()
    }
}

fn parse_csv(
    text: &str,
    file: &str,
    template: &FlightCamera,
) -> Result<Vec<(Place, FlightCamera)>, PathError> {
    let mut columns: Option<Vec<usize>> = None;
    let mut views = Vec::new();
    let mut first = true;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        let bad = |message: String| PathError::Line {
            file: file.into(),
            line: i + 1,
            message,
        };
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if std::mem::take(&mut first)
            && !fields[0].starts_with(|c: char| c.is_ascii_digit() || "+-.".contains(c))
        {
            let mut cols = Vec::with_capacity(fields.len());
            for name in &fields {
                let Some(k) = FIELDS.iter().position(|f| f.eq_ignore_ascii_case(name)) else {
                    return Err(bad(format!(
                        "unknown column '{name}' in the header (expected {})",
                        FIELDS.join(", ")
                    )));
                };
                if cols.contains(&k) {
                    return Err(bad(format!("column '{name}' appears twice in the header")));
                }
                cols.push(k);
            }
            if let Some(missing) = (0..5).find(|k| !cols.contains(k)) {
                return Err(bad(format!(
                    "the header lacks the required column '{}'",
                    FIELDS[missing]
                )));
            }
            columns = Some(cols);
            continue;
        }
        let cols: Vec<usize> = match &columns {
            Some(c) => {
                if fields.len() != c.len() {
                    return Err(bad(format!(
                        "expected {} fields as in the header, found {}",
                        c.len(),
                        fields.len()
                    )));
                }
                c.clone()
            }
            None => {
                if !(5..=7).contains(&fields.len()) {
                    return Err(bad(format!(
                        "expected 5 to 7 fields (x,y,altitude,heading,pitch[,roll[,fov]]), found {}",
                        fields.len()
                    )));
                }
                (0..fields.len()).collect()
            }
        };
        let mut values = [None; 7];
        for (&k, text) in cols.iter().zip(&fields) {
            match text.parse::<f64>() {
                Ok(v) if v.is_finite() => values[k] = Some(v),
                _ => {
                    return Err(bad(format!(
                        "{} = '{text}' is not a finite number",
                        FIELDS[k]
                    )));
                }
            }
        }
        views.push((Place::Line(i + 1), view_from(&values, template)));
    }
    Ok(views)
}

fn parse_json(
    text: &str,
    file: &str,
    template: &FlightCamera,
) -> Result<Vec<(Place, FlightCamera)>, PathError> {
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| PathError::Json {
        file: file.into(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    let Some(items) = value.as_array() else {
        return Err(PathError::Json {
            file: file.into(),
            line: 1,
            column: 1,
            message: "expected an array of views".into(),
        });
    };
    let mut views = Vec::with_capacity(items.len());
    for (index, item) in items.iter().enumerate() {
        let bad = |message: String| PathError::Element {
            file: file.into(),
            index,
            message,
        };
        let Some(obj) = item.as_object() else {
            return Err(bad(
                "expected an object {x, y, altitude, heading, pitch}".into()
            ));
        };
        let mut values = [None; 7];
        for (key, v) in obj {
            let Some(k) = FIELDS.iter().position(|f| f == key) else {
                return Err(bad(format!(
                    "unknown key '{key}' (expected {})",
                    FIELDS.join(", ")
                )));
            };
            match v.as_f64() {
                Some(x) if x.is_finite() => values[k] = Some(x),
                _ => return Err(bad(format!("{key} = {v} is not a finite number"))),
            }
        }
        if let Some(missing) = (0..5).find(|&k| values[k].is_none()) {
            return Err(bad(format!("missing '{}'", FIELDS[missing])));
        }
        views.push((Place::Element(index), view_from(&values, template)));
    }
    Ok(views)
}

/// Write views as a CSV path file's text (with a header; `read_path` reads it back exactly, as
/// Rust prints the shortest decimal that round-trips).
pub fn to_csv(views: &[FlightCamera]) -> String {
    let mut s = String::from("x,y,altitude,heading,pitch,roll,fov\n");
    for v in views {
        s.push_str(&format!(
            "{},{},{},{},{},{},{}\n",
            v.eye_x, v.eye_y, v.altitude, v.heading_deg, v.pitch_deg, v.roll_deg, v.hfov_deg
        ));
    }
    s
}

/// The grid's extent in local metres (east, south) and its centre sample.
fn extent(grid: &Grid) -> f64 {
    let g = grid.georef();
    let (e0, s0) = g.local_metres(0.0, 0.0);
    let (e1, s1) = g.local_metres((grid.width() - 1) as f64, (grid.height() - 1) as f64);
    (e1 - e0).abs().min((s1 - s0).abs())
}

/// A view at fractional sample `(col, row)` (clamped into the grid), `clearance` metres above
/// the ground there (at least 1 m), with the template's size and field of view.
fn view_at(
    grid: &Grid,
    template: &FlightCamera,
    col: f64,
    row: f64,
    clearance: f64,
    heading: f64,
    pitch: f64,
) -> FlightCamera {
    let col = col.clamp(0.0, (grid.width() - 1) as f64);
    let row = row.clamp(0.0, (grid.height() - 1) as f64);
    let (x, y) = grid.georef().sample_xy(col, row);
    let ground = ground_height(grid, col, row).unwrap_or_else(|| grid.height_range().1 as f64);
    FlightCamera {
        eye_x: x,
        eye_y: y,
        altitude: ground + clearance.max(1.0),
        heading_deg: heading,
        pitch_deg: pitch,
        roll_deg: 0.0,
        ..template.clone()
    }
}

/// `frames` views on a circle of `radius_frac` of the grid's smaller extent around its centre,
/// `clearance_frac` of that extent above the ground under each eye, looking toward the centre
/// (heading) at `pitch_deg`. The eye stays inside the grid (the radius is capped at 0.45 of the
/// extent).
pub fn orbit(
    grid: &Grid,
    template: &FlightCamera,
    frames: u32,
    radius_frac: f64,
    clearance_frac: f64,
    pitch_deg: f64,
) -> Vec<FlightCamera> {
    let (w, h) = ((grid.width() - 1) as f64, (grid.height() - 1) as f64);
    let r = radius_frac.clamp(0.0, 0.45) * w.min(h);
    let ext = extent(grid);
    (0..frames)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / frames.max(1) as f64;
            // Sample offsets: column grows east, row grows south; heading is clockwise from north.
            let (col, row) = (0.5 * w + r * a.sin(), 0.5 * h - r * a.cos());
            let heading = (a.to_degrees() + 180.0).rem_euclid(360.0);
            view_at(
                grid,
                template,
                col,
                row,
                clearance_frac * ext,
                heading,
                pitch_deg,
            )
        })
        .collect()
}

/// A view of the study path with the segment it belongs to.
#[derive(Clone, Debug, PartialEq)]
pub struct PathView {
    /// `look-down`, `low`, `grazing`, `turn` or `slow-pass`.
    pub segment: &'static str,
    pub view: FlightCamera,
}

/// The built-in study path over `grid` (26 views; size and field of view from `template`):
///
/// - `look-down` (4): from 0.4 of the extent above the ground, pitch −50° to −90°;
/// - `low` (4): 2 % of the extent above the ground, pitch −20° to −8°, heading north;
/// - `grazing` (4): 1 % of the extent up, pitch −2° to −5°, looking across the grid;
/// - `turn` (6): 8 % up, pitch −25°, heading from 0° to 150° while the eye moves east;
/// - `slow-pass` (8): 4 % up, pitch −30°, consecutive eyes 1/200 of the extent apart (for
///   frame-to-frame flicker).
///
/// Eyes are placed by fractions of the grid, so every eye lies inside it and above the ground.
pub fn study_path(grid: &Grid, template: &FlightCamera) -> Vec<PathView> {
    let (w, h) = ((grid.width() - 1) as f64, (grid.height() - 1) as f64);
    let ext = extent(grid);
    let mut out = Vec::with_capacity(26);
    let mut push = |segment, col_f: f64, row_f: f64, clear_f: f64, heading, pitch| {
        out.push(PathView {
            segment,
            view: view_at(
                grid,
                template,
                col_f * w,
                row_f * h,
                clear_f * ext,
                heading,
                pitch,
            ),
        })
    };
    for (i, pitch) in [-50.0, -65.0, -80.0, -90.0].into_iter().enumerate() {
        push("look-down", 0.5, 0.55 - 0.05 * i as f64, 0.4, 0.0, pitch);
    }
    for (i, pitch) in [-20.0, -15.0, -11.0, -8.0].into_iter().enumerate() {
        push("low", 0.45, 0.9 - 0.04 * i as f64, 0.02, 0.0, pitch);
    }
    for (i, pitch) in [-5.0, -4.0, -3.0, -2.0].into_iter().enumerate() {
        push("grazing", 0.2 + 0.05 * i as f64, 0.95, 0.01, 20.0, pitch);
    }
    for i in 0..6 {
        let t = i as f64 / 5.0;
        push("turn", 0.2 + 0.3 * t, 0.7, 0.08, 150.0 * t, -25.0);
    }
    for i in 0..8 {
        push("slow-pass", 0.5, 0.8 - 0.005 * i as f64, 0.04, 0.0, -30.0);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::Georef;

    fn grid() -> Grid {
        let n = 33u32;
        let h = (0..n * n).map(|i| (i % n) as f32).collect();
        Grid::new("ramp", n, n, h, Georef::local(10.0)).unwrap()
    }

    #[test]
    fn csv_with_header_in_any_order_and_comments() {
        let g = grid();
        let t = FlightCamera::over(&g);
        let text = "# a path\npitch, heading, altitude, y, x, fov\n-10,90,150,-100,50,60\n\n";
        let v = parse_path(text, "p.csv", &t).unwrap();
        assert_eq!(v.len(), 1);
        let v = &v[0];
        assert_eq!(
            (
                v.eye_x,
                v.eye_y,
                v.altitude,
                v.heading_deg,
                v.pitch_deg,
                v.hfov_deg
            ),
            (50.0, -100.0, 150.0, 90.0, -10.0, 60.0)
        );
        assert_eq!(v.roll_deg, t.roll_deg);
    }

    #[test]
    fn bad_lines_name_the_line() {
        let t = FlightCamera::over(&grid());
        let e = parse_path("1,2,3,4,5\n1,2,x,4,5\n", "f.csv", &t).unwrap_err();
        assert!(matches!(e, PathError::Line { line: 2, .. }), "{e}");
        assert!(e.to_string().starts_with("f.csv:2: altitude = 'x'"), "{e}");
        let e = parse_path("x,y,altitude,heading\n", "f.csv", &t).unwrap_err();
        assert!(
            e.to_string().contains("lacks the required column 'pitch'"),
            "{e}"
        );
        let e = parse_path("x,y,alt,heading,pitch\n", "f.csv", &t).unwrap_err();
        assert!(e.to_string().contains("unknown column 'alt'"), "{e}");
        let e = parse_path("1,2,3,4,5,6,7,8\n", "f.csv", &t).unwrap_err();
        assert!(matches!(e, PathError::Line { line: 1, .. }));
        let e = parse_path("1,2,3,4,NaN\n", "f.csv", &t).unwrap_err();
        assert!(matches!(e, PathError::Line { line: 1, .. }));
        assert!(matches!(
            parse_path("# nothing\n", "f.csv", &t),
            Err(PathError::Empty { .. })
        ));
        // A view that parses but is not a valid camera (eye outside the grid) names its line.
        let g = grid();
        let e = parse_path_for(
            "x,y,altitude,heading,pitch\n# ok\n100,-100,500,0,-10\n9999,-100,500,0,-10\n",
            "f.csv",
            &t,
            &g,
        )
        .unwrap_err();
        assert!(matches!(e, PathError::Line { line: 4, .. }), "{e}");
        assert!(e.to_string().contains("outside the 33 x 33 grid"), "{e}");
    }

    #[test]
    fn json_paths_and_their_errors() {
        let t = FlightCamera::over(&grid());
        let v = parse_path(
            r#"[{"x": 1, "y": -2, "altitude": 300, "heading": 45, "pitch": -20, "roll": 5}]"#,
            "p.json",
            &t,
        )
        .unwrap();
        assert_eq!((v[0].eye_x, v[0].roll_deg), (1.0, 5.0));
        let e = parse_path("[\n{\"x\": 1,\n}]", "p.json", &t).unwrap_err();
        assert!(matches!(e, PathError::Json { line: 3, .. }), "{e}");
        let e = parse_path(
            r#"[{"x": 1, "y": 2, "altitude": 3, "heading": 4, "pitch": 5}, {"x": 1}]"#,
            "p.json",
            &t,
        )
        .unwrap_err();
        assert_eq!(e.to_string(), "p.json: element 1: missing 'y'");
    }

    #[test]
    fn csv_round_trip_and_valid_generated_paths() {
        let g = grid();
        let t = FlightCamera {
            width: 32,
            height: 24,
            ..FlightCamera::over(&g)
        };
        let o = orbit(&g, &t, 12, 0.3, 0.1, -20.0);
        assert_eq!(o.len(), 12);
        assert!(o.iter().all(|v| v.camera(&g).is_ok()));
        assert_eq!(parse_path(&to_csv(&o), "o.csv", &t).unwrap(), o);
        let s = study_path(&g, &t);
        assert!(s.len() >= 20);
        for seg in ["look-down", "low", "grazing", "turn", "slow-pass"] {
            assert!(s.iter().any(|p| p.segment == seg));
        }
        assert!(s.iter().all(|p| p.view.camera(&g).is_ok()));
    }
}
