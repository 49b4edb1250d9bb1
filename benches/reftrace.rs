//! Reference ray tracer speed: BVH build time and primary rays per second on the named sphere
//! scenes S2 (100k spheres r 0.5 in a 100³ box) and S3 (1M spheres r 0.3 in a 200³ box) at
//! 1920x1080, and on a 2M-triangle heightfield; for every layout (obvhs's bvh2 and cwbvh with
//! their own traversals, and our 4-wide traversal `wide4`, the default).
//!
//! Two measurements per scene and layout, so that the comparison with issue #3's anchor (an obvhs
//! demo tracing primary rays for closest hits only) is fair:
//! - `trace` — trace only: the closest hit and its exact depth for every pixel
//!   ([`Scene::depth_image`]);
//! - `trace_shade` — the full reference render: trace, shade with the shared model, sRGB encode
//!   ([`Scene::render`], one sample per pixel).
//!
//! S2 is measured with two cameras: `s2_100k_spheres` keeps this bench's original view (40°
//! horizontal field of view, 68% of the pixels covered), `s2_study_view` uses texmap-study's
//! canonical S2 view (the box framed in the image: 69.0° for 1080p, eye along (0.45, 0.35, 1),
//! 28% covered), the view of PERFORMANCE-NOTES.md.
//!
//! Run: `cargo bench --bench reftrace -- --warm-up-time 1 --measurement-time 3`.
//! In test mode (`cargo test --bench reftrace`) the scenes shrink 10x and the image to 192x108 so
//! the run stays short.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use std::hint::black_box;
use texmap_core::camera::Camera;
use texmap_core::shade::{Lighting, Material};
use texmap_reftrace::{BvhKind, RenderOptions, Scene, SceneBuilder, SurfaceMaterial};

/// Full-size scenes only when criterion measures (`--bench`), not in test mode.
fn full_size() -> bool {
    std::env::args().any(|a| a == "--bench")
}

struct Lcg(u64);
impl Lcg {
    fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
}

/// `count` spheres of radius `r` uniformly in a cube of side `side` centred at the origin.
fn spheres(count: usize, side: f32, r: f32, kind: BvhKind) -> SceneBuilder {
    let mut rng = Lcg(2024);
    let mut b = SceneBuilder::with_sphere_capacity(count).bvh(kind);
    for k in 0..count {
        let p = Vec3::new(rng.f(), rng.f(), rng.f()) - Vec3::splat(0.5);
        b.add_sphere(p * side, r, (k % 4) as u32);
    }
    b
}

/// A heightfield of `n x n` vertices (2 (n−1)² triangles) over a 100 x 100 square.
fn heightfield(n: u32, kind: BvhKind) -> SceneBuilder {
    let mut pos = Vec::with_capacity((n * n) as usize);
    for j in 0..n {
        for i in 0..n {
            let (x, z) = (i as f32 / (n - 1) as f32, j as f32 / (n - 1) as f32);
            let y = 5.0 * (x * 17.0).sin() * (z * 13.0).cos() + 2.0 * ((x + z) * 41.0).sin();
            pos.push(Vec3::new(100.0 * x - 50.0, y, 100.0 * z - 50.0));
        }
    }
    let mut idx = Vec::with_capacity(((n - 1) * (n - 1) * 6) as usize);
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i;
            idx.extend([a, a + n, a + 1, a + 1, a + n, a + n + 1]);
        }
    }
    let mut b = SceneBuilder::new().bvh(kind);
    b.add_mesh(&pos, &idx, None, 0).expect("valid heightfield");
    b
}

fn materials() -> Vec<SurfaceMaterial> {
    [
        Vec3::new(0.8, 0.2, 0.2),
        Vec3::new(0.2, 0.7, 0.3),
        Vec3::new(0.2, 0.3, 0.9),
        Vec3::new(0.9, 0.9, 0.9),
    ]
    .map(|c| SurfaceMaterial::opaque(Material::plastic(c)))
    .to_vec()
}

/// A perspective camera looking at the origin with horizontal field of view `hfov`.
fn camera(eye: Vec3, hfov: f32, w: u32, h: u32) -> Camera {
    Camera::perspective_look_at(eye, Vec3::ZERO, Vec3::Y, hfov, w, h).expect("valid camera")
}

fn bench_scene(
    c: &mut Criterion,
    name: &str,
    make: &dyn Fn(BvhKind) -> SceneBuilder,
    (eye, hfov): (Vec3, f32),
    kinds: &[BvhKind],
) {
    let (w, h) = if full_size() {
        (1920, 1080)
    } else {
        (192, 108)
    };
    let mats = materials();
    let mut g = c.benchmark_group(format!("reftrace/{name}"));
    g.sample_size(10);
    for &kind in kinds {
        let label = format!("{kind:?}").to_lowercase();
        let scene: Scene = make(kind).build();
        let st = scene.stats();
        let prims = (st.spheres + st.cylinders + st.triangles) as u64;
        // Build: throughput in primitives per second.
        g.throughput(Throughput::Elements(prims));
        g.bench_function(BenchmarkId::new("build", &label), |b| {
            b.iter_batched(
                || make(kind),
                |builder| black_box(builder.build()),
                criterion::BatchSize::PerIteration,
            )
        });
        let cam = camera(eye, hfov, w, h);
        let opts = RenderOptions::new(Lighting::default_for(&cam), &mats);
        // Trace only: closest hit and exact depth per pixel; throughput in primary rays.
        g.throughput(Throughput::Elements(w as u64 * h as u64));
        g.bench_function(BenchmarkId::new("trace", &label), |b| {
            b.iter(|| black_box(scene.depth_image(&cam)))
        });
        // Trace + shade: the full reference render at one sample per pixel.
        g.bench_function(BenchmarkId::new("trace_shade", &label), |b| {
            b.iter(|| black_box(scene.render(&cam, &opts).expect("valid options")))
        });
    }
    g.finish();
}

fn benches(c: &mut Criterion) {
    let scale = if full_size() { 1 } else { 10 };
    let all = [BvhKind::Wide4, BvhKind::CwBvh, BvhKind::Bvh2];
    let oblique = Vec3::new(0.3, 0.4, 1.0).normalize();
    // S2: 100k spheres r 0.5 in a 100³ box, eye 2.4 box lengths from the centre.
    let n2 = 100_000 / scale;
    let s2 = |k| spheres(n2, 100.0, 0.5, k);
    bench_scene(c, "s2_100k_spheres", &s2, (oblique * 240.0, 40.0), &all);
    // The same scene from texmap-study's S2 view: VIEW_DIRECTION (0.45, 0.35, 1), 2.4 box
    // lengths, the horizontal FOV that frames the box's circumscribed sphere in 1920x1080
    // (scenes::framing_hfov_deg: 69.0°).
    let study = Vec3::new(0.45, 0.35, 1.0).normalize() * 240.0;
    bench_scene(
        c,
        "s2_study_view",
        &s2,
        (study, 69.0),
        &[BvhKind::Wide4, BvhKind::CwBvh],
    );
    // S3: 1M spheres r 0.3 in a 200³ box.
    let n3 = 1_000_000 / scale;
    let s3 = |k| spheres(n3, 200.0, 0.3, k);
    bench_scene(c, "s3_1m_spheres", &s3, (oblique * 480.0, 40.0), &all);
    // 2M-triangle heightfield (1001 x 1001 vertices) seen obliquely.
    let hn = if full_size() { 1001 } else { 101 };
    let hf = |k| heightfield(hn, k);
    bench_scene(
        c,
        "heightfield_2m_tris",
        &hf,
        (Vec3::new(0.0, 60.0, 110.0), 40.0),
        &all,
    );
}

criterion_group!(reftrace, benches);
criterion_main!(reftrace);
