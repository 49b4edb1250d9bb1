//! End-to-end through the facade's public API: a trajectory written by another program (MDAnalysis)
//! is read, drawn by every sphere method, and compared with the reference ray tracer.

use texmap::core::camera::Camera;
use texmap::core::color::srgb_to_linear;
use texmap::core::glam::Vec3;
use texmap::core::shade::{Lighting, Material};
use texmap::impostor::{Method, Renderer, SphereScene};
use texmap::md_io::{AtomStyle, Frame, Trajectory};
use texmap::study::harness;

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("crates/md-io/tests/data")
        .join(name)
}

/// The spheres of frame `n` of an MDAnalysis-written PDB, one material per distinct colour.
fn scene_from_pdb(n: usize) -> SphereScene {
    let mut traj = Trajectory::open(data("mda_multi.pdb")).expect("test file opens");
    let mut frame = Frame::new();
    traj.read_frame(n, &mut frame).expect("frame reads");
    let style = AtomStyle::new();
    let mut scene = SphereScene::new(Vec::new());
    let mut palette: Vec<[f32; 3]> = Vec::new();
    for i in 0..frame.n_atoms() {
        let (r, c) = style.resolve(&frame, i);
        let kind = match palette.iter().position(|p| *p == c) {
            Some(k) => k,
            None => {
                palette.push(c);
                palette.len() - 1
            }
        };
        scene.push(Vec3::from(frame.positions[i]), r, kind as u16);
    }
    scene.materials = palette
        .iter()
        .map(|c| Material::plastic(Vec3::from(c.map(srgb_to_linear))))
        .collect();
    scene
}

fn camera_for(scene: &SphereScene, hfov: Option<f32>) -> Camera {
    let (lo, hi) = scene.bounds().expect("atoms");
    Camera::fit_sphere(
        (lo + hi) * 0.5,
        (hi - lo).length() * 0.5,
        Vec3::new(-0.3, -0.4, -1.0),
        Vec3::Y,
        hfov,
        640,
        480,
        1.05,
    )
    .expect("camera")
}

#[test]
fn raycast_matches_the_reference_on_a_file_from_another_program() {
    let scene = scene_from_pdb(0);
    assert_eq!(scene.len(), 11);
    for hfov in [Some(30.0), Some(75.0), None] {
        let cam = camera_for(&scene, hfov);
        let lighting = Lighting::default_for(&cam);
        let mut r = Renderer::new();
        let out = r.render(
            &scene,
            &cam,
            &harness::study_options(Method::Raycast, lighting),
        );
        assert_eq!(out.stats.skipped_invalid, 0);
        let reference = harness::render_reference(
            &harness::reference_scene(&scene),
            &harness::reference_materials(&scene),
            &cam,
            lighting,
            [0, 0, 0, 255],
            1,
        )
        .expect("reference renders");
        let m = harness::compare(&out.frame, &reference).expect("same size");
        assert!(
            m.psnr_db >= 45.0,
            "hfov {hfov:?}: PSNR {} < 45 dB",
            m.psnr_db
        );
        assert!(
            m.silhouette_px <= 0.5,
            "hfov {hfov:?}: silhouette {} px > 0.5",
            m.silhouette_px
        );
        let covered = out.frame.coverage_count();
        assert!(
            covered > 100,
            "hfov {hfov:?}: the atoms are in view ({covered} px covered)"
        );
    }
}

#[test]
fn every_method_is_byte_identical_for_one_and_two_threads() {
    let scene = scene_from_pdb(1);
    let cam = camera_for(&scene, Some(50.0));
    let lighting = Lighting::default_for(&cam);
    for method in Method::ALL {
        let opts = harness::study_options(method, lighting);
        let frames: Vec<_> = [1, 2]
            .into_iter()
            .map(|t| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(t)
                    .build()
                    .unwrap()
                    .install(|| Renderer::new().render(&scene, &cam, &opts).frame)
            })
            .collect();
        assert_eq!(
            frames[0].color,
            frames[1].color,
            "{}: colour",
            method.name()
        );
        let bits = |f: &texmap::core::frame::Frame| -> Vec<u32> {
            f.depth.iter().map(|d| d.to_bits()).collect()
        };
        assert_eq!(
            bits(&frames[0]),
            bits(&frames[1]),
            "{}: depth",
            method.name()
        );
    }
}

#[test]
fn invalid_atoms_are_skipped_and_counted_by_every_method() {
    let mut scene = scene_from_pdb(0);
    scene.push(Vec3::new(f32::NAN, 0.0, 0.0), 1.0, 0);
    scene.push(Vec3::ZERO, -1.0, 0);
    scene.push(Vec3::ZERO, 0.0, 0);
    scene.push(Vec3::splat(f32::INFINITY), 1.0, 0);
    let cam = camera_for(&scene_from_pdb(0), Some(40.0));
    let lighting = Lighting::default_for(&cam);
    for method in Method::ALL {
        let out = Renderer::new().render(&scene, &cam, &harness::study_options(method, lighting));
        assert_eq!(out.stats.skipped_invalid, 4, "{}", method.name());
        assert!(
            out.frame.depth.iter().all(|d| !d.is_nan()),
            "{}: no NaN depth",
            method.name()
        );
    }
}
