//! The polygon baseline against the f64 ray-sphere reference.

use crate::common;

use common::{random_scene, reference};
use texmap_core::camera::Camera;
use texmap_core::glam::Vec3;
use texmap_core::metrics::{psnr, silhouette_error};
use texmap_core::shade::Lighting;
use texmap_impostor::{Method, Options, PolygonShading, render};

#[test]
fn polygon_silhouette_stays_within_the_requested_error() {
    let scene = random_scene(31, 120, 10.0, 0.5, 2.5);
    let cam = Camera::perspective_look_at(
        Vec3::new(3.0, 4.0, 40.0),
        Vec3::ZERO,
        Vec3::Y,
        45.0,
        240,
        180,
    )
    .unwrap();
    let refr = reference(&scene, &cam, &Lighting::default_for(&cam), [0, 0, 0, 255]);
    let mut last = f64::INFINITY;
    for err in [2.0f32, 0.25] {
        let mut o = Options::new(Method::Polygon, Lighting::default_for(&cam));
        o.polygon_max_error_px = err;
        let out = render(&scene, &cam, &o);
        let sil = silhouette_error(&out.frame, &refr).unwrap();
        // The tessellation lies inside the sphere by at most `err` px: the mean outline shift
        // is below it (plus the half-pixel sampling of a shifted edge).
        assert!(
            sil.mean_displacement_px <= err as f64,
            "max error {err}: mean outline shift expected ≤ {err}, got {}",
            sil.mean_displacement_px
        );
        assert!(sil.mean_displacement_px <= last, "finer must not be worse");
        last = sil.mean_displacement_px;
    }
    for shading in [PolygonShading::Phong, PolygonShading::Gouraud] {
        let mut o = Options::new(Method::Polygon, Lighting::default_for(&cam));
        o.polygon_shading = shading;
        let out = render(&scene, &cam, &o);
        let p = psnr(&out.frame, &refr).unwrap();
        assert!(p >= 25.0, "{shading:?}: PSNR expected ≥ 25 dB, got {p}");
    }
}
