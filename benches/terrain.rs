//! Terrain meshing: the RTIN error map of a 513² grid, a 10 m mesh from it, the greedy Delaunay
//! mesh at 10 m, and a 4097² grid to the full chunk quadtree. The grid is the seeded diamond-square surface of the martini/delatin
//! peer harness (same generator, seed and 3 km relief), so triangle counts compare at equal error;
//! they are printed once before timing.
//!
//! `fuji_*` times the same two steps on mapbox's Fuji tile (martini's own fixture, made 513² as
//! martini's test does), the terrain the martini figures were measured on (89.5k
//! triangles at 10 m). The bench writes that grid as little-endian f32 to
//! `target/fuji-513.f32` so the peer harness can time martini on the very same samples:
//! `node bench.mjs <that file> 513 10`.
//!
//! `laz_read_*` decodes LASzip's 110,017-point, three-chunk survey
//! (`crates/terrain/tests/data/lidar/lidar_chunked_12.laz`) on one and on two threads: the
//! chunks are decoded side by side, so the ratio is the parallel decoding's gain.
//!
//!     cargo bench --bench terrain

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use texmap_terrain::chunks;
use texmap_terrain::dem::las::LasReader;
use texmap_terrain::dem::{Georef, Grid};
use texmap_terrain::greedy::greedy;
use texmap_terrain::rtin::{ErrorMap, extract};

/// The peers' diamond-square (f32 like their Float32Array), LCG seed 42, amplitude 3000, roughness 0.9.
fn diamond_square(n: usize, amp: f64, rough: f64, seed: u32) -> Vec<f32> {
    let mut s = seed;
    let mut rnd = move || {
        s = s.wrapping_mul(1664525).wrapping_add(1013904223);
        s as f64 / 4294967296.0 - 0.5
    };
    let mut t = vec![0.0f32; n * n];
    let (mut step, mut a) = (n - 1, amp);
    while step > 1 {
        let h = step / 2;
        let mut y = h;
        while y < n {
            let mut x = h;
            while x < n {
                let v = (t[(y - h) * n + x - h]
                    + t[(y - h) * n + x + h]
                    + t[(y + h) * n + x - h]
                    + t[(y + h) * n + x + h])
                    / 4.0;
                t[y * n + x] = (v as f64 + rnd() * a) as f32;
                x += step;
            }
            y += step;
        }
        let mut y = 0;
        while y < n {
            let mut x = if (y / h) % 2 == 0 { h } else { 0 };
            while x < n {
                let (mut sum, mut c) = (0.0f32, 0.0f32);
                if y >= h {
                    sum += t[(y - h) * n + x];
                    c += 1.0;
                }
                if y + h < n {
                    sum += t[(y + h) * n + x];
                    c += 1.0;
                }
                if x >= h {
                    sum += t[y * n + x - h];
                    c += 1.0;
                }
                if x + h < n {
                    sum += t[y * n + x + h];
                    c += 1.0;
                }
                t[y * n + x] = ((sum / c) as f64 + rnd() * a) as f32;
                x += step;
            }
            y += h;
        }
        step /= 2;
        a *= 0.5f64.powf(rough);
    }
    t
}

/// Mapbox's Fuji Terrain-RGB tile as a 513² grid (last row and column repeated, as martini's test).
fn fuji() -> Vec<f32> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/terrain/tests/data/fuji.png"
    );
    let img = image::open(path).unwrap().to_rgba8();
    let w = img.width();
    let n = w + 1;
    let mut g = Vec::with_capacity((n * n) as usize);
    for y in 0..n {
        for x in 0..n {
            let p = img.get_pixel(x.min(w - 1), y.min(w - 1));
            g.push(texmap_terrain::dem::png::terrain_rgb_height(p[0], p[1], p[2]) as f32);
        }
    }
    g
}

fn bench(c: &mut Criterion) {
    let n = 513u32;
    let h = diamond_square(n as usize, 3000.0, 0.9, 42);
    let map = ErrorMap::new(&h, n);
    for e in [1.0f32, 5.0, 10.0, 30.0] {
        let m = extract(&map, &h, 0, 0, n - 1, e, 1);
        eprintln!(
            "texmap RTIN 513² synthetic: {e} m -> {} triangles",
            m.triangles.len()
        );
    }
    let grid513 = Grid::new("synthetic", n, n, h.clone(), Georef::local(1.0)).unwrap();
    for e in [5.0f32, 10.0, 30.0] {
        let t0 = std::time::Instant::now();
        let m = greedy(&grid513, e).unwrap();
        eprintln!(
            "texmap greedy 513² synthetic: {e} m -> {} triangles in {:.1} ms (one run)",
            m.triangles.len(),
            t0.elapsed().as_secs_f64() * 1e3
        );
    }
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let mut g = c.benchmark_group("terrain");
    g.sample_size(20);
    g.bench_function("rtin_error_map_513_1core", |b| {
        b.iter(|| one.install(|| ErrorMap::new(black_box(&h), n)))
    });
    g.bench_function("rtin_mesh_10m_513", |b| {
        b.iter(|| extract(&map, black_box(&h), 0, 0, n - 1, 10.0, 1))
    });
    let fj = fuji();
    let peer_input = concat!(env!("CARGO_MANIFEST_DIR"), "/target/fuji-513.f32");
    let bytes: Vec<u8> = fj.iter().flat_map(|v| v.to_le_bytes()).collect();
    if std::fs::write(peer_input, bytes).is_ok() {
        eprintln!(
            "fuji grid for the peer harness: {peer_input} (node bench.mjs {peer_input} 513 10)"
        );
    }
    let fmap = ErrorMap::new(&fj, n);
    eprintln!(
        "texmap RTIN fuji 513²: 10 m -> {} triangles",
        extract(&fmap, &fj, 0, 0, n - 1, 10.0, 1).triangles.len()
    );
    g.bench_function("fuji_error_map_513_1core", |b| {
        b.iter(|| one.install(|| ErrorMap::new(black_box(&fj), n)))
    });
    g.bench_function("fuji_mesh_10m_513", |b| {
        b.iter(|| extract(&fmap, black_box(&fj), 0, 0, n - 1, 10.0, 1))
    });
    g.sample_size(10);
    g.bench_function("greedy_10m_513", |b| {
        b.iter(|| greedy(black_box(&grid513), 10.0).unwrap())
    });
    let big = 4097u32;
    let hb = diamond_square(big as usize, 3000.0, 0.9, 42);
    let grid = Grid::new("synthetic", big, big, hb, Georef::local(10.0)).unwrap();
    g.sample_size(10);
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    g.bench_function("full_quadtree_4097_2cores", |b| {
        b.iter(|| two.install(|| chunks::build(black_box(&grid), 5.0, 257).unwrap()))
    });
    let laz = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/terrain/tests/data/lidar/lidar_chunked_12.laz"
    );
    let read_all = || {
        let mut r = LasReader::open(laz).unwrap();
        let (mut batch, mut n) = (Vec::new(), 0);
        while r.read_batch(&mut batch).unwrap() > 0 {
            n += batch.len();
        }
        n
    };
    g.bench_function("laz_read_110k_1core", |b| b.iter(|| one.install(read_all)));
    g.bench_function("laz_read_110k_2cores", |b| b.iter(|| two.install(read_all)));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
