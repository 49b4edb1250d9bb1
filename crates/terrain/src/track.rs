//! Recorded flights as flight paths: GPS tracks in GPX and IGC replayed over the terrain, as a
//! simulator's debriefing replays a sortie.
//!
//! **Reading.** [`parse_gpx`] reads GPX 1.0 and 1.1 (Garmin devices, Strava, gpxpy, `ogr2ogr -f
//! GPX`): the track points (`trk/trkseg/trkpt`, every segment in order) or, in a file without
//! tracks, the route points (`rte/rtept`), each with `lat` and `lon`, and `ele` (metres) and
//! `time` (ISO 8601, UTC unless an offset is given) where present; waypoints are not a path and
//! are left out. [`parse_igc`] reads the FAI's IGC flight recorder format that gliding and
//! paragliding loggers write: the date from the `HFDTE` header (`HFDTE150723` or
//! `HFDTEDATE:150723,01`) and one fix per `B` record (time, latitude and longitude in degrees and
//! thousandths of minutes, validity, pressure and GNSS altitudes), times carried past midnight;
//! the altitude is the GNSS one, or the pressure altitude where the GNSS one is missing (a `V`
//! fix or zero). A bad fix is an error naming the file and its line.
//!
//! **Views** ([`track_views`]). Positions go through the grid's georeference
//! ([`Placement`]: degrees, UTM, Web Mercator). With a `speedup`, frames are taken every
//! `speedup / fps` seconds of the track's clock and the fixes interpolated linearly between them
//! (a 1 Hz track at `--speedup 10 --fps 25` gives 2.5 frames per fix); without one, one frame per
//! fix. Each view looks along the track: the heading is the direction from the position
//! [`WINDOW`] seconds before to the one after (one fix each way for a track without times), kept
//! when the craft stands still; the view banks as a coordinated turn does, roll =
//! atan(v·ω/g) from the speed v and the turn rate ω over the same window (clamped to ±60°; none
//! without times). The altitude is the track's plus `above` metres (a view from above and behind
//! the pilot's eye is `above` > 0); a fix without one is flown 100 m above the ground; an eye
//! less than 2 m above the ground (a walker's track, a landing, GPS noise) is lifted to 2 m and
//! counted. Frames whose eye lies outside the grid are left out and counted, so a flight that
//! starts outside the DEM tile is replayed over it; a track entirely outside is an error.
//!
//! ```
//! use texmap_terrain::dem::{CrsKind, Georef, Grid};
//! use texmap_terrain::track::{parse_gpx, track_views, TrackOptions};
//! use texmap_terrain::view::FlightCamera;
//!
//! let georef = Georef { crs: CrsKind::Geographic, epsg: Some(4326), origin_x: 7.0,
//!     origin_y: 46.1, dx: 0.001, dy: -0.001 };
//! let grid = Grid::new("flat", 101, 101, vec![400.0; 101 * 101], georef)?;
//! let gpx = r#"<gpx version="1.1" creator="doc" xmlns="http://www.topografix.com/GPX/1/1">
//!   <trk><trkseg>
//!     <trkpt lat="46.05" lon="7.05"><ele>900</ele><time>2024-06-01T10:00:00Z</time></trkpt>
//!     <trkpt lat="46.06" lon="7.05"><ele>910</ele><time>2024-06-01T10:00:40Z</time></trkpt>
//!   </trkseg></trk></gpx>"#;
//! let track = parse_gpx(gpx, "flight.gpx")?;
//! let template = FlightCamera { width: 64, height: 48, ..FlightCamera::over(&grid) };
//! // 10x real time at 25 frames a second: a frame every 0.4 s of the 40 s track.
//! let opts = TrackOptions { speedup: Some(10.0), fps: 25.0, ..TrackOptions::default() };
//! let v = track_views(&track, &grid, &template, &opts)?;
//! assert_eq!(v.views.len(), 101);
//! // Northward (within the grid's local metres, whose east axis shrinks with latitude), level,
//! // climbing from 900 to 910 m.
//! let h = v.views[50].heading_deg; // degrees clockwise from north, in [0, 360)
//! assert!(h.min(360.0 - h) < 0.1 && v.views[50].roll_deg.abs() < 1e-9);
//! assert!((v.views[50].altitude - 905.0).abs() < 1e-9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::Path;

use crate::dem::Grid;
use crate::flight::PathError;
use crate::geodesy::Placement;
use crate::view::{FlightCamera, ground_height};

/// One recorded position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fix {
    /// Degrees, WGS 84.
    pub lon: f64,
    pub lat: f64,
    /// Metres (GPX `ele`; IGC GNSS or pressure altitude).
    pub altitude: Option<f64>,
    /// Seconds since 1970-01-01 UTC.
    pub time: Option<f64>,
    /// The 1-based line of the fix in its file.
    pub line: usize,
}

/// A track's fixes in recording order.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    pub source: String,
    pub fixes: Vec<Fix>,
}

/// Half-width of the window, seconds, over which heading, speed and turn rate are measured.
pub const WINDOW: f64 = 2.0;

/// Whether `path` names a track file by its extension (`.gpx`, `.igc`, any case).
pub fn is_track(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gpx") || e.eq_ignore_ascii_case("igc"))
}

/// Read a GPX or IGC file, told by its extension (else by its content: `<` starts GPX).
pub fn read_track(path: &Path) -> Result<Track, PathError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| PathError::Io {
        file: file.clone(),
        source,
    })?;
    // IGC files are ASCII, some with Latin-1 in their headers: read those bytes as Latin-1.
    let text = match String::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => e.into_bytes().iter().map(|&b| b as char).collect(),
    };
    let igc = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("igc"));
    if igc || !text.trim_start().starts_with('<') {
        parse_igc(&text, &file)
    } else {
        parse_gpx(&text, &file)
    }
}

fn bad_line(file: &str, line: usize, message: impl Into<String>) -> PathError {
    PathError::Line {
        file: file.into(),
        line,
        message: message.into(),
    }
}

/// Parse GPX text (see the module docs); `file` names it in errors.
pub fn parse_gpx(text: &str, file: &str) -> Result<Track, PathError> {
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let p = e.pos();
        PathError::Json {
            file: file.into(),
            line: p.row as usize,
            column: p.col as usize,
            message: format!("not well-formed XML: {e}"),
        }
    })?;
    if doc.root_element().tag_name().name() != "gpx" {
        return Err(bad_line(
            file,
            1,
            format!(
                "expected a <gpx> document, found <{}>",
                doc.root_element().tag_name().name()
            ),
        ));
    }
    let named = |n: &str| {
        doc.descendants()
            .filter(|e| e.is_element() && e.tag_name().name() == n)
            .collect::<Vec<_>>()
    };
    let mut points = named("trkpt");
    if points.is_empty() {
        points = named("rtept");
    }
    let mut fixes = Vec::with_capacity(points.len());
    for p in points {
        let line = doc.text_pos_at(p.range().start).row as usize;
        let tag = p.tag_name().name();
        let coord = |name: &str, limit: f64| -> Result<f64, PathError> {
            let v = p.attribute(name).ok_or_else(|| {
                bad_line(
                    file,
                    line,
                    format!("<{tag}> without its '{name}' attribute"),
                )
            })?;
            match v.trim().parse::<f64>() {
                Ok(x) if x.is_finite() && x.abs() <= limit => Ok(x),
                _ => Err(bad_line(
                    file,
                    line,
                    format!("<{tag}> {name}=\"{v}\": expected degrees within ±{limit}"),
                )),
            }
        };
        let (lat, lon) = (coord("lat", 90.0)?, coord("lon", 180.0)?);
        let child = |name: &str| {
            p.children()
                .find(|c| c.is_element() && c.tag_name().name() == name)
                .map(|c| (c, c.text().unwrap_or("").trim()))
        };
        let altitude = match child("ele") {
            None => None,
            Some((c, t)) => match t.parse::<f64>() {
                Ok(x) if x.is_finite() && x.abs() < 1e6 => Some(x),
                _ => {
                    let line = doc.text_pos_at(c.range().start).row as usize;
                    return Err(bad_line(
                        file,
                        line,
                        format!("<ele>{t}</ele>: expected metres"),
                    ));
                }
            },
        };
        let time = match child("time") {
            None => None,
            Some((c, t)) => Some(iso8601(t).ok_or_else(|| {
                let line = doc.text_pos_at(c.range().start).row as usize;
                bad_line(
                    file,
                    line,
                    format!("<time>{t}</time>: expected an ISO 8601 time (2024-06-01T10:00:00Z)"),
                )
            })?),
        };
        fixes.push(Fix {
            lon,
            lat,
            altitude,
            time,
            line,
        });
    }
    if fixes.is_empty() {
        return Err(PathError::Empty { file: file.into() });
    }
    Ok(Track {
        source: file.into(),
        fixes,
    })
}

/// Days since 1970-01-01 of a proleptic Gregorian date (Howard Hinnant's `days_from_civil`).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// Seconds since 1970 UTC of `YYYY-MM-DDTHH:MM:SS[.fff][Z|±HH:MM]` (a space for the `T` too).
fn iso8601(s: &str) -> Option<f64> {
    let b = s.as_bytes();
    if b.len() < 19 || b[4] != b'-' || b[7] != b'-' || !matches!(b[10], b'T' | b't' | b' ') {
        return None;
    }
    let num = |r: std::ops::Range<usize>| -> Option<i64> {
        let t = s.get(r)?;
        t.bytes()
            .all(|c| c.is_ascii_digit())
            .then(|| t.parse().ok())?
    };
    let (y, mo, d) = (num(0..4)?, num(5..7)?, num(8..10)?);
    if b[13] != b':' || b[16] != b':' {
        return None;
    }
    let (h, mi, sec) = (num(11..13)?, num(14..16)?, num(17..19)?);
    if !(1..=12).contains(&mo) || !(1..=31).contains(&d) || h > 23 || mi > 59 || sec > 60 {
        return None;
    }
    let mut rest = &s[19..];
    let mut frac = 0.0;
    if let Some(r) = rest.strip_prefix('.') {
        let n = r.bytes().take_while(u8::is_ascii_digit).count();
        if n == 0 {
            return None;
        }
        frac = format!("0.{}", &r[..n]).parse().ok()?;
        rest = &r[n..];
    }
    let offset = match rest {
        "" | "Z" | "z" => 0,
        _ => {
            let sign = match rest.as_bytes()[0] {
                b'+' => 1,
                b'-' => -1,
                _ => return None,
            };
            let r = &rest[1..];
            let (oh, om) = match r.len() {
                5 if r.as_bytes()[2] == b':' => (r[..2].parse::<i64>().ok()?, r[3..].parse().ok()?),
                4 => (r[..2].parse::<i64>().ok()?, r[2..].parse().ok()?),
                2 => (r.parse::<i64>().ok()?, 0),
                _ => return None,
            };
            sign * (oh * 3600 + om * 60)
        }
    };
    let days = days_from_civil(y, mo, d);
    Some((days * 86_400 + h * 3600 + mi * 60 + sec - offset) as f64 + frac)
}

/// Parse IGC text (see the module docs); `file` names it in errors.
pub fn parse_igc(text: &str, file: &str) -> Result<Track, PathError> {
    let mut date: Option<i64> = None;
    let mut fixes: Vec<Fix> = Vec::new();
    let mut day_offset = 0.0;
    let mut last = None::<f64>;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim_end();
        let n = i + 1;
        if line
            .as_bytes()
            .get(..5)
            .is_some_and(|h| h.eq_ignore_ascii_case(b"HFDTE"))
        {
            // HFDTEDDMMYY or HFDTEDATE:DDMMYY[,NN]
            let rest = &line[5..];
            let rest = rest.split_once(':').map_or(rest, |(_, r)| r);
            let d = rest
                .get(..6)
                .filter(|d| d.bytes().all(|c| c.is_ascii_digit()));
            let Some(d) = d else {
                return Err(bad_line(
                    file,
                    n,
                    format!("'{line}': expected the date as HFDTEDDMMYY"),
                ));
            };
            let p = |r: std::ops::Range<usize>| d[r].parse::<i64>().unwrap_or(0);
            let (dd, mm, yy) = (p(0..2), p(2..4), p(4..6));
            if !(1..=31).contains(&dd) || !(1..=12).contains(&mm) {
                return Err(bad_line(file, n, format!("'{line}': no such date")));
            }
            // Two-digit years: the FAI's recorders date from 1980 on.
            let year = if yy >= 80 { 1900 + yy } else { 2000 + yy };
            date = Some(days_from_civil(year, mm, dd) * 86_400);
            continue;
        }
        if !line.starts_with('B') {
            continue;
        }
        let b = line.as_bytes();
        let bad = |what: &str| {
            bad_line(
                file,
                n,
                format!(
                    "B record: {what} (expected B HHMMSS DDMMmmmN DDDMMmmmE A PPPPP GGGGG, 35 characters)"
                ),
            )
        };
        if b.len() < 35 || !line.is_ascii() {
            return Err(bad(&format!("{} characters", b.len())));
        }
        let digits = |r: std::ops::Range<usize>, what: &str| -> Result<i64, PathError> {
            let t = &line[r];
            if t.bytes().all(|c| c.is_ascii_digit()) {
                Ok(t.parse().unwrap_or(0))
            } else {
                Err(bad(&format!("{what} '{t}'")))
            }
        };
        let (h, m, s) = (
            digits(1..3, "hours")?,
            digits(3..5, "minutes")?,
            digits(5..7, "seconds")?,
        );
        if h > 23 || m > 59 || s > 59 {
            return Err(bad(&format!("time {}", &line[1..7])));
        }
        let (lat_d, lat_m) = (digits(7..9, "latitude")?, digits(9..14, "latitude")?);
        let (lon_d, lon_m) = (digits(15..18, "longitude")?, digits(18..23, "longitude")?);
        let lat_sign = match b[14] {
            b'N' => 1.0,
            b'S' => -1.0,
            _ => return Err(bad("latitude hemisphere, not N or S")),
        };
        let lon_sign = match b[23] {
            b'E' => 1.0,
            b'W' => -1.0,
            _ => return Err(bad("longitude hemisphere, not E or W")),
        };
        let lat = lat_sign * (lat_d as f64 + lat_m as f64 / 60_000.0);
        let lon = lon_sign * (lon_d as f64 + lon_m as f64 / 60_000.0);
        if lat.abs() > 90.0 || lon.abs() > 180.0 || lat_m >= 60_000 || lon_m >= 60_000 {
            return Err(bad(&format!("position {}", &line[7..24])));
        }
        let valid = match b[24] {
            b'A' => true,
            b'V' => false,
            _ => return Err(bad("validity, not A or V")),
        };
        let alt = |r: std::ops::Range<usize>, what: &str| -> Result<i64, PathError> {
            line[r.clone()]
                .trim_start_matches(' ')
                .parse::<i64>()
                .map_err(|_| bad(&format!("{what} '{}'", &line[r])))
        };
        let pressure = alt(25..30, "pressure altitude")?;
        let gnss = alt(30..35, "GNSS altitude")?;
        let altitude = if valid && gnss != 0 { gnss } else { pressure };
        let t = (h * 3600 + m * 60 + s) as f64;
        // Past midnight UTC: the clock starts again.
        if last.is_some_and(|l| t + day_offset < l - 43_200.0) {
            day_offset += 86_400.0;
        }
        let time = t + day_offset;
        last = Some(time);
        fixes.push(Fix {
            lon,
            lat,
            altitude: Some(altitude as f64),
            time: Some(time + date.unwrap_or(0) as f64),
            line: n,
        });
    }
    if fixes.is_empty() {
        return Err(PathError::Empty { file: file.into() });
    }
    Ok(Track {
        source: file.into(),
        fixes,
    })
}

/// How a track becomes views (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackOptions {
    /// Track seconds per movie second; `None`: one view per fix.
    pub speedup: Option<f64>,
    /// Frames per movie second.
    pub fps: f64,
    /// Degrees above the horizon (negative looks down).
    pub pitch_deg: f64,
    /// Metres added to the track's altitude.
    pub above: f64,
}

impl Default for TrackOptions {
    fn default() -> Self {
        TrackOptions {
            speedup: None,
            fps: 25.0,
            pitch_deg: -10.0,
            above: 0.0,
        }
    }
}

/// A track's views and what was adjusted.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackViews {
    pub views: Vec<FlightCamera>,
    /// Frames left out because their eye lay outside the grid.
    pub outside: usize,
    /// Eyes lifted to 2 m above the ground.
    pub lifted: usize,
}

/// Most frames a track may give.
pub const MAX_FRAMES: usize = 1_000_000;

/// The views along `track` over `grid` (see the module docs); `template` gives the field of view
/// and the image size.
pub fn track_views(
    track: &Track,
    grid: &Grid,
    template: &FlightCamera,
    opts: &TrackOptions,
) -> Result<TrackViews, PathError> {
    let file = track.source.as_str();
    let whole = |message: String| PathError::Track {
        file: file.into(),
        message,
    };
    let g = grid.georef();
    let placement = Placement::of(g).ok_or_else(|| {
        whole(
            "the grid has no georeference in degrees, UTM or Web Mercator to place a GPS track on"
                .into(),
        )
    })?;
    let fixes = &track.fixes;
    // The clock each fix is at: its time, or its index without times.
    let timed = fixes.iter().all(|f| f.time.is_some());
    if opts.speedup.is_some() && !timed {
        let f = fixes
            .iter()
            .find(|f| f.time.is_none())
            .expect("some untimed");
        return Err(bad_line(
            file,
            f.line,
            "a fix without a time: a track is replayed by its clock only when every fix has one",
        ));
    }
    let clock: Vec<f64> = if timed {
        fixes.iter().map(|f| f.time.unwrap_or(0.0)).collect()
    } else {
        (0..fixes.len()).map(|i| i as f64).collect()
    };
    if let Some(i) = (1..fixes.len()).find(|&i| clock[i] < clock[i - 1]) {
        return Err(bad_line(
            file,
            fixes[i].line,
            "a fix earlier than the one before it (expected times in recording order)",
        ));
    }
    // Grid coordinates and local metres (east, north) of every fix.
    let place: Vec<[f64; 4]> = fixes
        .iter()
        .map(|f| {
            let (x, y) = placement.xy(f.lon, f.lat);
            let (col, row) = g.xy_to_sample(x, y);
            let (e, s) = g.local_metres(col, row);
            [x, y, e, -s]
        })
        .collect();
    // The state at clock value u, linear between the bracketing fixes.
    let at = |u: f64| -> ([f64; 4], Option<f64>) {
        let k = clock
            .partition_point(|&c| c <= u)
            .clamp(1, fixes.len().max(2) - 1);
        if fixes.len() == 1 {
            return (place[0], fixes[0].altitude);
        }
        let (c0, c1) = (clock[k - 1], clock[k]);
        let w = if c1 > c0 {
            ((u - c0) / (c1 - c0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let p = std::array::from_fn(|i| place[k - 1][i] + w * (place[k][i] - place[k - 1][i]));
        let alt = match (fixes[k - 1].altitude, fixes[k].altitude) {
            (Some(a), Some(b)) => Some(a + w * (b - a)),
            (a, b) => a.or(b),
        };
        (p, alt)
    };
    let window = if timed { WINDOW } else { 1.0 };
    let heading_at = |u: f64| -> Option<f64> {
        let (a, b) = (at(u - window).0, at(u + window).0);
        let (de, dn) = (b[2] - a[2], b[3] - a[3]);
        (de.hypot(dn) > 0.5).then(|| de.atan2(dn).to_degrees().rem_euclid(360.0))
    };
    let samples: Vec<f64> = match opts.speedup {
        None => clock.clone(),
        Some(s) => {
            if !(s.is_finite() && s > 0.0 && opts.fps.is_finite() && opts.fps > 0.0) {
                return Err(whole(format!(
                    "speedup {s} at {} frames a second: expected both > 0",
                    opts.fps
                )));
            }
            let step = s / opts.fps;
            let span = clock[clock.len() - 1] - clock[0];
            let n = (span / step + 1e-9).floor() + 1.0;
            if n > MAX_FRAMES as f64 {
                return Err(whole(format!(
                    "{n} frames for {span} s at speedup {s} and {} frames a second: more than {MAX_FRAMES}",
                    opts.fps
                )));
            }
            (0..n as usize)
                .map(|k| clock[0] + k as f64 * step)
                .collect()
        }
    };
    let (mut views, mut outside, mut lifted) = (Vec::new(), 0, 0);
    let mut heading = template.heading_deg;
    let last_col = (grid.width() - 1) as f64;
    let last_row = (grid.height() - 1) as f64;
    for &u in &samples {
        let (p, alt) = at(u);
        if let Some(h) = heading_at(u) {
            heading = h;
        }
        let (col, row) = g.xy_to_sample(p[0], p[1]);
        if !(0.0..=last_col).contains(&col) || !(0.0..=last_row).contains(&row) {
            outside += 1;
            continue;
        }
        let Some(ground) = ground_height(grid, col, row) else {
            outside += 1;
            continue;
        };
        let mut altitude = alt.map_or(ground + 100.0, |a| a) + opts.above;
        if altitude < ground + 2.0 {
            altitude = ground + 2.0;
            lifted += 1;
        }
        // A coordinated turn's bank from the speed and the turn rate over the window.
        let roll = match (timed, heading_at(u - window), heading_at(u + window)) {
            (true, Some(h0), Some(h1)) => {
                let turn = ((h1 - h0 + 540.0).rem_euclid(360.0) - 180.0).to_radians();
                let omega = turn / (2.0 * window);
                let (a, b) = (at(u - window).0, at(u + window).0);
                let v = (b[2] - a[2]).hypot(b[3] - a[3]) / (2.0 * window);
                (v * omega / 9.806_65)
                    .atan()
                    .to_degrees()
                    .clamp(-60.0, 60.0)
            }
            _ => template.roll_deg,
        };
        views.push(FlightCamera {
            eye_x: p[0],
            eye_y: p[1],
            altitude,
            heading_deg: heading,
            pitch_deg: opts.pitch_deg,
            roll_deg: roll,
            ..template.clone()
        });
    }
    if views.is_empty() {
        return Err(whole(format!(
            "no fix of the track lies over the grid (the track's first fix: {:.5}° E, {:.5}° N)",
            fixes[0].lon, fixes[0].lat
        )));
    }
    Ok(TrackViews {
        views,
        outside,
        lifted,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::{CrsKind, Georef};

    #[test]
    fn iso_times_are_seconds_since_1970() {
        assert_eq!(iso8601("1970-01-01T00:00:00Z"), Some(0.0));
        assert_eq!(iso8601("2000-03-01T00:00:00Z"), Some(951_868_800.0));
        assert_eq!(iso8601("2024-06-01T10:00:00.5Z"), Some(1_717_236_000.5));
        assert_eq!(iso8601("2024-06-01T12:00:00+02:00"), Some(1_717_236_000.0));
        assert_eq!(iso8601("2024-06-01 10:00:00"), Some(1_717_236_000.0));
        assert_eq!(iso8601("2024-13-01T10:00:00Z"), None);
        assert_eq!(iso8601("yesterday"), None);
    }

    #[test]
    fn igc_fixes_dates_and_midnight() {
        let igc = "AXXX001\r\nHFDTEDATE:311223,01\r\n\
                   B2359584546123N00656789EA0123401300\r\n\
                   B0000024546200S00656800WV0124000000\r\n";
        let t = parse_igc(igc, "f.igc").unwrap();
        assert_eq!(t.fixes.len(), 2);
        let f = t.fixes[0];
        assert!((f.lat - (45.0 + 46.123 / 60.0)).abs() < 1e-12);
        assert!((f.lon - (6.0 + 56.789 / 60.0)).abs() < 1e-12);
        assert_eq!(f.altitude, Some(1300.0));
        let day = days_from_civil(2023, 12, 31) as f64 * 86_400.0;
        assert_eq!(f.time, Some(day + 86_398.0));
        // Past midnight: 4 s later; a V fix takes the pressure altitude; south and west.
        let g = t.fixes[1];
        assert_eq!(g.time, Some(day + 86_402.0));
        assert_eq!(g.altitude, Some(1240.0));
        assert!(g.lat < 0.0 && g.lon < 0.0);
        let e = parse_igc("B12000045\n", "f.igc").unwrap_err().to_string();
        assert!(e.starts_with("f.igc:1: B record: 9 characters"), "{e}");
        let e = parse_igc("B1200004546123X00656789EA0123401300\n", "f.igc")
            .unwrap_err()
            .to_string();
        assert!(e.contains("hemisphere"), "{e}");
    }

    #[test]
    fn a_steady_turn_banks_as_a_coordinated_turn() {
        // A circle of 500 m at 25 m/s (ω = 0.05 rad/s), clockwise seen from above, 1 Hz fixes,
        // on a UTM grid: bank atan(v²/(g r)) = 7.26°, heading along the tangent.
        let georef = Georef {
            crs: CrsKind::Projected,
            epsg: Some(32632),
            origin_x: 400_000.0,
            origin_y: 5_100_000.0,
            dx: 20.0,
            dy: -20.0,
        };
        let grid = Grid::new("flat", 201, 201, vec![100.0; 201 * 201], georef).unwrap();
        let (cx, cy) = (402_000.0, 5_098_000.0);
        let p = Placement::of(&georef).unwrap();
        let fixes = (0..120)
            .map(|i| {
                let a = 0.05 * i as f64; // angle from north, clockwise
                let (x, y) = (cx + 500.0 * a.sin(), cy + 500.0 * a.cos());
                let (lon, lat) = p.lonlat(x, y);
                Fix {
                    lon,
                    lat,
                    altitude: Some(600.0),
                    time: Some(1000.0 + i as f64),
                    line: i + 1,
                }
            })
            .collect();
        let track = Track {
            source: "circle".into(),
            fixes,
        };
        let template = FlightCamera::over(&grid);
        let v = track_views(&track, &grid, &template, &TrackOptions::default()).unwrap();
        assert_eq!((v.views.len(), v.outside, v.lifted), (120, 0, 0));
        let bank = (25.0f64 * 25.0 / (9.806_65 * 500.0)).atan().to_degrees();
        for (i, c) in v.views.iter().enumerate().skip(5).take(100) {
            // Tangent of a clockwise circle at angle a: heading a + 90°.
            let want = (0.05 * i as f64).to_degrees() + 90.0;
            let dh = ((c.heading_deg - want + 540.0).rem_euclid(360.0)) - 180.0;
            // UTM grid north differs from the local metres' north by the convergence here.
            assert!(dh.abs() < 1.0, "{i}: heading {} vs {want}", c.heading_deg);
            assert!(
                (c.roll_deg - bank).abs() < 0.05,
                "{i}: roll {} vs {bank}",
                c.roll_deg
            );
        }
    }
}
