//! Time-sliced cube maps (`Options::cube_faces_per_frame`): a Renderer redraws N of the six faces
//! per frame, round robin, and keeps the others (texels and pyramids) from the previous frame.
//! Checked against full updates of the same scene, face by face and byte by byte.

use texmap_envmap::address::{Face, MapFrame};
use texmap_envmap::maps::{MapScratch, UpdateParams, update_cube, update_cube_faces};
use texmap_envmap::scene::{TunnelParams, tunnel_camera, tunnel_scene};
use texmap_envmap::{EnvMap, EnvMapError, EnvScene, Method, Options, Output, Renderer, RimPolicy};

const ALL: u8 = 0b11_1111;

fn tunnel(time: f32) -> EnvScene {
    tunnel_scene(TunnelParams {
        time,
        ..Default::default()
    })
    .unwrap()
}

fn opts(method: Method, n: u32) -> Options {
    let mut o = Options::new(method);
    o.map_size = 64;
    o.cube_faces_per_frame = n;
    o
}

/// Whether face `i` of two maps holds the same texels on every level of its pyramid.
fn same_face(a: &EnvMap, b: &EnvMap, i: usize) -> bool {
    let (x, y) = (&a.faces()[i], &b.faces()[i]);
    x.level_count() == y.level_count()
        && x.texels().len() == y.texels().len()
        && x.texels()
            .iter()
            .zip(y.texels())
            .all(|(p, q)| p.to_array().map(f32::to_bits) == q.to_array().map(f32::to_bits))
}

fn same_frame(a: &Output, b: &Output) -> bool {
    a.frame.color == b.frame.color
        && a.frame
            .depth
            .iter()
            .zip(&b.frame.depth)
            .all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The output and the map of a fresh Renderer's first frame (a full update).
fn full(scene: &EnvScene, o: &Options) -> (Output, EnvMap) {
    let cam = tunnel_camera(96, 72).unwrap();
    let mut r = Renderer::new();
    let out = r.render(scene, &cam, o).unwrap();
    (out, r.map().unwrap().clone())
}

#[test]
fn six_faces_per_frame_is_the_full_update_every_frame() {
    let cam = tunnel_camera(96, 72).unwrap();
    for method in [Method::Cube, Method::CubeBox] {
        let mut kept = Renderer::new();
        let mut o = opts(method, 6);
        o.map_size = 256;
        assert_eq!(
            o.cube_faces_per_frame,
            Options::new(method).cube_faces_per_frame
        );
        for t in [0.0, 0.1, 0.2, 0.3] {
            let scene = tunnel(t);
            let a = kept.render(&scene, &cam, &o).unwrap();
            // A Renderer with nothing kept, at the default options.
            let mut fresh = Renderer::new();
            let b = fresh.render(&scene, &cam, &Options::new(method)).unwrap();
            assert!(same_frame(&a, &b), "{method:?} t {t}");
            assert_eq!((a.faces_updated, b.faces_updated), (ALL, ALL));
            // And the map is maps::update_cube's.
            let p = UpdateParams {
                objects: scene.objects(),
                lighting: scene.lighting(),
                environment: scene.environment(),
                centre: scene.centre(),
                frame: MapFrame::WORLD,
                size: 256,
                min_distance: 0.0,
                rim: RimPolicy::Split,
            };
            let m = update_cube(&p, &mut MapScratch::default()).unwrap();
            assert!((0..6).all(|i| same_face(&m, kept.map().unwrap(), i)));
        }
    }
}

#[test]
fn a_scene_that_stops_is_caught_up_after_ceil_6_over_n_frames() {
    let cam = tunnel_camera(96, 72).unwrap();
    // The objects move from t0 to t1, then stay: after ⌈6/N⌉ frames at t1 every face has been
    // redrawn at t1, and the frame is the full update's, byte for byte.
    let (s0, s1) = (tunnel(0.0), tunnel(0.5));
    let (want, want_map) = full(&s1, &opts(Method::Cube, 6));
    let (_, map0) = full(&s0, &opts(Method::Cube, 6));
    for n in 1..6u32 {
        let o = opts(Method::Cube, n);
        let mut r = Renderer::new();
        assert_eq!(r.render(&s0, &cam, &o).unwrap().faces_updated, ALL);
        let frames = 6u32.div_ceil(n);
        let mut seen = 0u8;
        for k in 1..=frames {
            let out = r.render(&s1, &cam, &o).unwrap();
            // Round robin in Face::ALL order from face 0.
            let expect = (0..n).fold(0u8, |m, j| m | 1 << (((k - 1) * n + j) % 6));
            assert_eq!(out.faces_updated, expect, "N {n} frame {k}");
            seen |= out.faces_updated;
            let map = r.map().unwrap();
            for i in 0..6 {
                // A face redrawn at t1 is t1's; one not yet redrawn is still t0's.
                let want_face = if seen & (1 << i) != 0 {
                    &want_map
                } else {
                    &map0
                };
                assert!(same_face(map, want_face, i), "N {n} frame {k} face {i}");
            }
            if k == 1 {
                // Not vacuous: the faces left stale differ from t1's.
                assert!(
                    (0..6).any(|i| seen & (1 << i) == 0 && !same_face(&map0, &want_map, i)),
                    "N {n}: the stale faces did not change between t0 and t1"
                );
            }
            if k == frames {
                assert_eq!(seen, ALL);
                assert!(same_frame(&out, &want), "N {n}");
            }
        }
    }
}

#[test]
fn one_face_per_frame_redraws_one_face_and_keeps_five() {
    let cam = tunnel_camera(96, 72).unwrap();
    let (s0, s1) = (tunnel(0.0), tunnel(0.25));
    for method in [Method::Cube, Method::CubeBox] {
        let o = opts(method, 1);
        let (full0, map0) = full(&s0, &opts(method, 6));
        let (full1, map1) = full(&s1, &opts(method, 6));
        let mut r = Renderer::new();
        let a = r.render(&s0, &cam, &o).unwrap();
        assert_eq!(a.faces_updated, ALL);
        assert!(same_frame(&a, &full0));
        let b = r.render(&s1, &cam, &o).unwrap();
        assert_eq!(b.faces_updated, 1 << Face::PosX.index());
        let m = r.map().unwrap();
        assert!(same_face(m, &map1, 0));
        assert!((1..6).all(|i| same_face(m, &map0, i)));
        // Not vacuous: +X and some other face change between t0 and t1, and the stale faces
        // show in the frame.
        assert!(!same_face(&map0, &map1, 0));
        assert!((1..6).any(|i| !same_face(&map0, &map1, i)));
        assert!(!same_frame(&b, &full1), "{method:?}");
    }
}

#[test]
fn a_changed_map_is_redrawn_whole() {
    let cam = tunnel_camera(96, 72).unwrap();
    let s = tunnel(0.0);
    let mut r = Renderer::new();
    let mut o = opts(Method::Cube, 2);
    let run = |r: &mut Renderer, o: &Options| r.render(&s, &cam, o).unwrap().faces_updated;
    assert_eq!(run(&mut r, &o), ALL);
    assert_eq!(run(&mut r, &o), 0b00_0011);
    // Cube and cube-box share the map.
    o.method = Method::CubeBox;
    assert_eq!(run(&mut r, &o), 0b00_1100);
    o.map_size = 32;
    assert_eq!(run(&mut r, &o), ALL);
    assert_eq!(run(&mut r, &o), 0b00_0011);
    o.min_object_distance = 2.0;
    assert_eq!(run(&mut r, &o), ALL);
    o.method = Method::SphereDynamic;
    assert_eq!(run(&mut r, &o), 0b1);
    o.method = Method::Cube;
    assert_eq!(run(&mut r, &o), ALL);
    // A static map made once reports no face redrawn when reused.
    o.method = Method::SphereStatic;
    assert_eq!(run(&mut r, &o), 0b1);
    assert_eq!(run(&mut r, &o), 0);
}

#[test]
fn sliced_frames_are_identical_for_one_and_two_threads() {
    let cam = tunnel_camera(96, 72).unwrap();
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut r = Renderer::new();
            (0..4)
                .map(|k| {
                    r.render(&tunnel(0.1 * k as f32), &cam, &opts(Method::Cube, 2))
                        .unwrap()
                })
                .collect::<Vec<_>>()
        })
    };
    let (a, b) = (run(1), run(2));
    assert!(a.iter().zip(&b).all(|(x, y)| same_frame(x, y)));
}

#[test]
fn faces_per_frame_out_of_range_is_an_error() {
    let cam = tunnel_camera(32, 24).unwrap();
    let s = tunnel(0.0);
    for method in [Method::Cube, Method::SphereDynamic] {
        for n in [0, 7, u32::MAX] {
            let e = Renderer::new().render(&s, &cam, &opts(method, n));
            assert!(
                matches!(e, Err(EnvMapError::FacesPerFrame { faces }) if faces == n),
                "{method:?} {n}: {e:?}"
            );
        }
    }
    // The maps function refuses a partial update without a matching previous map.
    let p = UpdateParams {
        objects: s.objects(),
        lighting: s.lighting(),
        environment: s.environment(),
        centre: s.centre(),
        frame: MapFrame::WORLD,
        size: 16,
        min_distance: 0.0,
        rim: RimPolicy::Split,
    };
    let mut scratch = MapScratch::default();
    assert!(update_cube_faces(&p, &mut scratch, 0b1, None).is_err());
    assert!(update_cube_faces(&p, &mut scratch, 0b100_0000, None).is_err());
    let m16 = update_cube(&p, &mut scratch).unwrap();
    let p32 = UpdateParams { size: 32, ..p };
    assert!(update_cube_faces(&p32, &mut scratch, 0b1, Some(m16.clone())).is_err());
    assert!(update_cube_faces(&p, &mut scratch, 0b1, Some(m16)).is_ok());
}
