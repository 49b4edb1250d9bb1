//! Environment mapping on the built-in tunnel at ~100k triangles (detail 16): a 1024x768 frame
//! with a dynamic 6 x 256² cube map re-rendered every frame, and each map update alone.
//!
//! `cargo bench --bench envmap`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use texmap_envmap::address::MapFrame;
use texmap_envmap::maps::{
    MapScratch, UpdateParams, update_cube, update_paraboloid, update_sphere,
};
use texmap_envmap::scene::{TunnelParams, tunnel_camera, tunnel_scene};
use texmap_envmap::{Method, Options, Renderer, RimPolicy};

fn bench(c: &mut Criterion) {
    let scene = tunnel_scene(TunnelParams {
        detail: 16,
        ..Default::default()
    })
    .unwrap();
    let cam = tunnel_camera(1024, 768).unwrap();
    let mut g = c.benchmark_group("envmap");
    g.sample_size(20);
    for method in [
        Method::Cube,
        Method::SphereDynamic,
        Method::SphereStatic,
        Method::Paraboloid,
    ] {
        let mut r = Renderer::new();
        let opts = Options::new(method);
        g.bench_function(format!("frame_1024x768_100k/{}", method.name()), |b| {
            b.iter(|| {
                let out = r.render(&scene, &cam, &opts).unwrap();
                let n = black_box(out.frame.len());
                r.recycle(out.frame);
                n
            })
        });
    }
    let p = |frame| UpdateParams {
        objects: scene.objects(),
        lighting: scene.lighting(),
        environment: scene.environment(),
        centre: scene.centre(),
        frame,
        size: 256,
        min_distance: 0.0,
        rim: RimPolicy::Split,
    };
    let mut s = MapScratch::default();
    g.bench_function("update_256/cube", |b| {
        b.iter(|| black_box(update_cube(&p(MapFrame::WORLD), &mut s).unwrap().size()))
    });
    let mut s = MapScratch::default();
    let eye = MapFrame::of_camera(&cam);
    g.bench_function("update_256/sphere", |b| {
        b.iter(|| black_box(update_sphere(&p(eye), &mut s).unwrap().size()))
    });
    let mut s = MapScratch::default();
    g.bench_function("update_256/paraboloid", |b| {
        b.iter(|| {
            black_box(
                update_paraboloid(&p(MapFrame::WORLD), &mut s)
                    .unwrap()
                    .size(),
            )
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
