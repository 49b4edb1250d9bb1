//! Environment mapping on the built-in tunnel at ~100k triangles (detail 16): a 1024x768 frame
//! with a dynamic 6 x 256² cube map re-rendered every frame, the same frame with the cube map
//! time-sliced (`cube_faces_per_frame` 1 and 2: one Renderer across iterations, so each
//! iteration redraws the next faces of the kept map, round robin — the steady state of an
//! animation; the scene is static, which changes nothing in the cost), and each map update alone
//! (the cube's also time-sliced, through `maps::update_cube_faces` with the kept map). Each
//! full update hands its map back to the scratch (`MapScratch::recycle`), as the Renderer does
//! with the last frame's map, so the pyramids are rebuilt into the same buffers.
//!
//! `cargo bench --bench envmap`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use texmap_envmap::address::MapFrame;
use texmap_envmap::maps::{
    EnvMap, MapScratch, UpdateParams, update_cube, update_cube_faces, update_paraboloid,
    update_sphere,
};
use texmap_envmap::scene::{TunnelParams, tunnel_camera, tunnel_scene};
use texmap_envmap::{EnvMapError, Method, Options, Renderer, RimPolicy};

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
    for n in [1u32, 2] {
        let mut r = Renderer::new();
        let mut opts = Options::new(Method::Cube);
        opts.cube_faces_per_frame = n;
        let name = format!("frame_1024x768_100k/cube_{n}_of_6_faces_per_frame");
        g.bench_function(name, |b| {
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
    // A full update, its map recycled into the scratch for the next one.
    let update = |s: &mut MapScratch,
                  f: &dyn Fn(&mut MapScratch) -> Result<EnvMap, EnvMapError>| {
        let m = f(s).unwrap();
        let n = black_box(m.size());
        s.recycle(m);
        n
    };
    let mut s = MapScratch::default();
    g.bench_function("update_256/cube", |b| {
        b.iter(|| update(&mut s, &|s| update_cube(&p(MapFrame::WORLD), s)))
    });
    // Time-sliced: N faces of the kept map per iteration, round robin, as the Renderer does.
    for n in [1usize, 2] {
        let mut s = MapScratch::default();
        let mut kept = Some(update_cube(&p(MapFrame::WORLD), &mut s).unwrap());
        let mut next = 0;
        let name = format!("update_256/cube_{n}_of_6_faces");
        g.bench_function(name, |b| {
            b.iter(|| {
                let faces = (0..n).fold(0u8, |m, k| m | 1 << ((next + k) % 6));
                next = (next + n) % 6;
                let m = update_cube_faces(&p(MapFrame::WORLD), &mut s, faces, kept.take());
                kept = Some(m.unwrap());
                black_box(kept.as_ref().map(|m| m.size()))
            })
        });
    }
    let mut s = MapScratch::default();
    let eye = MapFrame::of_camera(&cam);
    g.bench_function("update_256/sphere", |b| {
        b.iter(|| update(&mut s, &|s| update_sphere(&p(eye), s)))
    });
    let mut s = MapScratch::default();
    g.bench_function("update_256/paraboloid", |b| {
        b.iter(|| update(&mut s, &|s| update_paraboloid(&p(MapFrame::WORLD), s)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
