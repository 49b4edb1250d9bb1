//! The quantized-mesh export of the real SRTM tile, decoded by an independent reader (the
//! quantized-mesh-tile package, through tests/tools/qmesh_decode.py; CI installs it, elsewhere the
//! decoding checks say SKIPPED): every vertex where the grid (plus PROJ's EGM96 undulation) puts
//! it, every lattice sample of the finest tiles within the stated error of the decoded mesh,
//! triangles counter-clockwise, the edge lists exactly the vertices on each edge, and every
//! vertex inside the header's bounding sphere. Also: the tile ranges of layer.json, and the same
//! bytes for any thread count, and gzipped tiles that inflate to the same bytes.

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::DVec3;
use texmap_terrain::db::{self, BuildOptions, Database};
use texmap_terrain::dem::{Grid, ReadOptions, read_dem};
use texmap_terrain::geodesy::ecef;
use texmap_terrain::geoid::Geoid;
use texmap_terrain::qmesh::{QuantizedMeshOptions, level_zero_error, write_quantized_mesh};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The finest level of the test export: tiles of 0.176°, lattice steps of 0.0027° (about three
/// SRTM samples), so the export stays small.
const LEVEL: u32 = 10;

/// Bilinear height of the SRTM grid at `(lon, lat)` (sample centres at whole 1/1200 degrees
/// from the tile's north-west corner), `None` off the grid.
fn srtm_height(grid: &Grid, lon: f64, lat: f64) -> Option<f64> {
    let col = (lon + 72.0) * 1200.0;
    let row = (45.0 - lat) * 1200.0;
    if !(-1e-9..=1200.0 + 1e-9).contains(&col) || !(-1e-9..=1200.0 + 1e-9).contains(&row) {
        return None;
    }
    let (col, row) = (col.clamp(0.0, 1200.0), row.clamp(0.0, 1200.0));
    let (c0, r0) = (
        (col.floor() as usize).min(1199),
        (row.floor() as usize).min(1199),
    );
    let (fc, fr) = (col - c0 as f64, row - r0 as f64);
    let h = |c: usize, r: usize| grid.heights()[r * 1201 + c] as f64;
    let top = h(c0, r0) * (1.0 - fc) + h(c0 + 1, r0) * fc;
    let bottom = h(c0, r0 + 1) * (1.0 - fc) + h(c0 + 1, r0 + 1) * fc;
    Some(top * (1.0 - fr) + bottom * fr)
}

fn export(dir: &Path, db: &Database, geoid: &Geoid, name: &str, gzip: bool) -> PathBuf {
    let out = dir.join(name);
    let options = QuantizedMeshOptions {
        geoid: Some(geoid),
        max_level: Some(LEVEL),
        gzip,
    };
    let s = write_quantized_mesh(db, &out, &options).unwrap();
    assert_eq!(s.levels, LEVEL + 1);
    out
}

/// One decoded tile.
#[derive(Default)]
struct Tile {
    z: u32,
    bounds: [f64; 4],
    range: [f64; 2],
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
    edges: Vec<Vec<usize>>,
    sphere: [f64; 4],
    normals: Vec<DVec3>,
}

fn parse(text: &str) -> Vec<Tile> {
    let mut tiles: Vec<Tile> = Vec::new();
    for line in text.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        let num = |k: usize| f[k].parse::<f64>().unwrap();
        match f[0] {
            "tile" => tiles.push(Tile {
                z: f[1].parse().unwrap(),
                bounds: [num(4), num(5), num(6), num(7)],
                range: [num(10), num(11)],
                ..Tile::default()
            }),
            "v" => tiles
                .last_mut()
                .unwrap()
                .vertices
                .push([num(1), num(2), num(3)]),
            "t" => tiles
                .last_mut()
                .unwrap()
                .triangles
                .push([1, 2, 3].map(|k| f[k].parse().unwrap())),
            "edges" => {
                tiles.last_mut().unwrap().edges = f[1..]
                    .iter()
                    .map(|l| match *l {
                        "-" => Vec::new(),
                        l => l.split(',').map(|i| i.parse().unwrap()).collect(),
                    })
                    .collect()
            }
            "sphere" => tiles.last_mut().unwrap().sphere = [num(1), num(2), num(3), num(4)],
            "n" => tiles
                .last_mut()
                .unwrap()
                .normals
                .push(DVec3::new(num(1), num(2), num(3))),
            other => panic!("unexpected line {other}"),
        }
    }
    tiles
}

#[test]
fn srtm_terrain_decodes_where_the_grid_and_the_geoid_put_it() {
    let dir = tempfile::tempdir().unwrap();
    let grid = read_dem(data("N44W072.hgt"), &ReadOptions::default()).unwrap();
    let path = dir.path().join("srtm.db");
    db::build(
        &grid,
        "srtm",
        None,
        &BuildOptions::default(),
        &path,
        |_, _| {},
    )
    .unwrap();
    let db = Database::open(&path).unwrap();
    let geoid = Geoid::open(data("egm96_cut.gtx")).unwrap();
    let out = export(dir.path(), &db, &geoid, "qm", false);

    // layer.json: both level-0 tiles, then the tiles over the SRTM tile's degree square.
    let layer: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("layer.json")).unwrap()).unwrap();
    assert_eq!(layer["format"], "quantized-mesh-1.0");
    assert_eq!(layer["maxzoom"], LEVEL);
    let available = layer["available"].as_array().unwrap();
    assert_eq!(available.len() as u32, LEVEL + 1);
    let r = &available[0][0];
    assert_eq!(
        [&r["startX"], &r["endX"], &r["startY"], &r["endY"]],
        [0, 1, 0, 0]
    );
    for (z, ranges) in available.iter().enumerate().skip(1) {
        let w = 180.0 / (1u64 << z) as f64;
        let r = &ranges[0];
        let get = |k: &str| r[k].as_f64().unwrap();
        // The ranges cover the square [-72, -71] x [44, 45] and no tile wholly outside it.
        assert!(-180.0 + get("startX") * w <= -72.0 && -180.0 + (get("endX") + 1.0) * w >= -71.0);
        assert!(-90.0 + get("startY") * w <= 44.0 && -90.0 + (get("endY") + 1.0) * w >= 45.0);
        assert!(-180.0 + (get("startX") + 1.0) * w > -72.0 && -180.0 + get("endX") * w <= -71.0);
        assert!(-90.0 + (get("startY") + 1.0) * w > 44.0 && -90.0 + get("endY") * w <= 45.0);
        for x in get("startX") as u32..=get("endX") as u32 {
            for y in get("startY") as u32..=get("endY") as u32 {
                assert!(out.join(format!("{z}/{x}/{y}.terrain")).exists());
            }
        }
    }

    // The same bytes with one thread.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let one = pool.install(|| export(dir.path(), &db, &geoid, "qm1", false));
    for z in 0..=LEVEL {
        for entry in walk(&out.join(z.to_string())) {
            let rel = entry.strip_prefix(&out).unwrap();
            assert_eq!(
                std::fs::read(&entry).unwrap(),
                std::fs::read(one.join(rel)).unwrap(),
                "{}",
                rel.display()
            );
        }
    }

    // Gzipped tiles: each a gzip member whose content is the plain tile, byte for byte;
    // layer.json as it was.
    let gz = export(dir.path(), &db, &geoid, "qmgz", true);
    let (mut plain_bytes, mut gz_bytes) = (0, 0);
    for entry in walk_all(&out) {
        let rel = entry.strip_prefix(&out).unwrap();
        let packed = std::fs::read(gz.join(rel)).unwrap();
        assert_eq!(packed[..3], [0x1f, 0x8b, 8], "{}", rel.display());
        let mut inflated = Vec::new();
        std::io::Read::read_to_end(
            &mut flate2::read::GzDecoder::new(&packed[..]),
            &mut inflated,
        )
        .unwrap();
        let plain = std::fs::read(&entry).unwrap();
        assert_eq!(inflated, plain, "{}", rel.display());
        plain_bytes += plain.len();
        gz_bytes += packed.len();
    }
    assert_eq!(
        std::fs::read(out.join("layer.json")).unwrap(),
        std::fs::read(gz.join("layer.json")).unwrap()
    );
    eprintln!("gzip: {gz_bytes} of {plain_bytes} bytes");
    assert!(
        gz_bytes * 10 < plain_bytes * 7,
        "{gz_bytes} of {plain_bytes}"
    );

    // The independent decoder, on the plain and the gzipped tiles (which it inflates itself).
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/tools/qmesh_decode.py");
    let decoded = Command::new("python3").arg(&script).arg(&out).output();
    let decoded = match decoded {
        Ok(o) if o.status.success() => String::from_utf8(o.stdout).unwrap(),
        Ok(o) => {
            let err = String::from_utf8_lossy(&o.stderr);
            if err.contains("No module named 'quantized_mesh_tile'") {
                eprintln!(
                    "SKIPPED: decoding by quantized-mesh-tile (pip install quantized-mesh-tile)"
                );
                return;
            }
            panic!("qmesh_decode.py failed: {err}");
        }
        Err(e) => {
            eprintln!("SKIPPED: decoding by quantized-mesh-tile (python3: {e})");
            return;
        }
    };
    let from_gz = Command::new("python3")
        .arg(&script)
        .arg(&gz)
        .output()
        .unwrap();
    assert!(
        from_gz.status.success(),
        "{}",
        String::from_utf8_lossy(&from_gz.stderr)
    );
    assert!(
        from_gz.stdout == decoded.as_bytes(),
        "the gzipped tiles decode differently"
    );
    let tiles = parse(&decoded);
    let expected_tiles: usize = walk_all(&out).len();
    assert_eq!(tiles.len(), expected_tiles);
    let mut checked = 0usize;
    let mut normal_angles = Vec::new();
    let mut worst_vertex = 0f64;
    let mut worst_mesh = 0f64;
    for t in &tiles {
        let [west, south, east, north] = t.bounds;
        let w = east - west;
        let n = t.vertices.len();
        let step = (t.range[1] - t.range[0]) / 32767.0;
        // Vertices: on the 65² lattice, at the grid's height plus the undulation (sea level
        // plus the undulation off the grid), within half a height quantum.
        let mut lattice = Vec::with_capacity(n);
        for v in &t.vertices {
            let c = (v[0] - west) / w * 64.0;
            let r = (north - v[1]) / w * 64.0;
            assert!(
                (c - c.round()).abs() < 2e-3 && (r - r.round()).abs() < 2e-3,
                "{v:?}"
            );
            let (lon, lat) = (west + w * c.round() / 64.0, north - w * r.round() / 64.0);
            let want = srtm_height(&grid, lon, lat).unwrap_or(0.0)
                + geoid.undulation(lon, lat).unwrap_or(0.0);
            let d = (v[2] - want).abs();
            worst_vertex = worst_vertex.max(d - step / 2.0);
            assert!(
                d <= step / 2.0 + 2e-3,
                "tile z{} {v:?}: expected {want}",
                t.z
            );
            lattice.push([c.round(), r.round(), v[2]]);
        }
        // Triangles: valid indices, counter-clockwise seen from above (lon east, lat north).
        for tri in &t.triangles {
            assert!(tri.iter().all(|&i| i < n));
            let [a, b, c] = tri.map(|i| t.vertices[i]);
            let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            assert!(area > 0.0, "z{}: triangle {tri:?} is clockwise", t.z);
        }
        // Edge lists: exactly the vertices on each edge.
        let on = |k: usize, i: usize| {
            let v = t.vertices[i];
            let eps = w * 1e-9;
            [
                (v[0] - west).abs(),
                (v[1] - south).abs(),
                (v[0] - east).abs(),
                (v[1] - north).abs(),
            ][k] < eps
        };
        for k in 0..4 {
            let want: Vec<usize> = (0..n).filter(|&i| on(k, i)).collect();
            let mut got = t.edges[k].clone();
            got.sort_unstable();
            assert_eq!(got, want, "z{} edge {k}", t.z);
        }
        // Normals: unit, pointing up out of the terrain, and at the finest level close to the
        // mean of the adjacent faces' normals (the surface the lattice samples).
        assert_eq!(t.normals.len(), n);
        let world: Vec<DVec3> = t
            .vertices
            .iter()
            .map(|v| DVec3::from(ecef(v[0], v[1], v[2])))
            .collect();
        let mut faces = vec![DVec3::ZERO; n];
        for tri in &t.triangles {
            let [a, b, c] = tri.map(|i| world[i]);
            let f = (b - a).cross(c - a);
            for &i in tri {
                faces[i] += f;
            }
        }
        for (i, normal) in t.normals.iter().enumerate() {
            let up = DVec3::from(ecef(t.vertices[i][0], t.vertices[i][1], 1.0))
                - DVec3::from(ecef(t.vertices[i][0], t.vertices[i][1], 0.0));
            assert!((normal.length() - 1.0).abs() < 1e-3);
            assert!(
                normal.dot(up) > 0.2,
                "z{} vertex {i}: normal {normal} not up",
                t.z
            );
            if t.z == LEVEL && faces[i].length() > 0.0 {
                normal_angles.push(normal.angle_between(faces[i]).to_degrees());
            }
        }
        // Bounding sphere.
        let centre = DVec3::new(t.sphere[0], t.sphere[1], t.sphere[2]);
        for v in &t.vertices {
            let p = DVec3::from(ecef(v[0], v[1], v[2]));
            assert!(p.distance(centre) <= t.sphere[3] + 0.01);
        }
        // The finest level: every lattice sample within the database's error (1 m) of the
        // decoded mesh, plus a height quantum.
        if t.z == LEVEL && t.vertices.len() > 4 {
            let bound = 1.0f64.min(level_zero_error() / (1u64 << LEVEL) as f64);
            for tri in &t.triangles {
                let p = tri.map(|i| lattice[i]);
                let (xmin, xmax) = (
                    p.iter().map(|q| q[0]).fold(f64::MAX, f64::min),
                    p.iter().map(|q| q[0]).fold(f64::MIN, f64::max),
                );
                let (ymin, ymax) = (
                    p.iter().map(|q| q[1]).fold(f64::MAX, f64::min),
                    p.iter().map(|q| q[1]).fold(f64::MIN, f64::max),
                );
                let det = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1])
                    - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
                for r in ymin as i64..=ymax as i64 {
                    for c in xmin as i64..=xmax as i64 {
                        let (x, y) = (c as f64, r as f64);
                        let l1 = ((x - p[0][0]) * (p[2][1] - p[0][1])
                            - (p[2][0] - p[0][0]) * (y - p[0][1]))
                            / det;
                        let l2 = ((p[1][0] - p[0][0]) * (y - p[0][1])
                            - (x - p[0][0]) * (p[1][1] - p[0][1]))
                            / det;
                        let l0 = 1.0 - l1 - l2;
                        if l0 < -1e-9 || l1 < -1e-9 || l2 < -1e-9 {
                            continue;
                        }
                        let mesh = l0 * p[0][2] + l1 * p[1][2] + l2 * p[2][2];
                        let (lon, lat) = (west + w * x / 64.0, north - w * y / 64.0);
                        let sample = srtm_height(&grid, lon, lat).unwrap_or(0.0)
                            + geoid.undulation(lon, lat).unwrap_or(0.0);
                        let d = (mesh - sample).abs();
                        worst_mesh = worst_mesh.max(d);
                        assert!(
                            d <= bound + step + 1e-3,
                            "z{} lattice ({c}, {r}): {d} m",
                            t.z
                        );
                        checked += 1;
                    }
                }
            }
        }
    }
    eprintln!(
        "decoded {} tiles: vertices within {worst_vertex:.2e} m of a half quantum; \
         {checked} finest-level lattice checks, worst {worst_mesh:.3} m",
        tiles.len()
    );
    assert!(checked > 10_000, "{checked}");
    normal_angles.sort_by(f64::total_cmp);
    let median = normal_angles[normal_angles.len() / 2];
    eprintln!("normals against the adjacent faces' mean: median {median:.2}°");
    assert!(median < 5.0, "{median}");
}

/// Every file under `dir`, sorted.
fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Every tile file of an export.
fn walk_all(out: &Path) -> Vec<PathBuf> {
    walk(out)
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "terrain"))
        .collect()
}
