//! The automatic camera of a frame, the view axes, and the centre of a selection.
//!
//! [`fit_camera`] frames what a frame draws: the scene's spheres (the selected atoms, and the
//! box outline when it is drawn), or the periodic cell's corners when no sphere is drawn, or
//! the unit sphere at the origin when there is neither. The smallest sphere about the centre
//! of their bounding box that holds them all is fitted into the image with
//! [`Camera::fit_sphere`] and a margin of [`FIT_MARGIN`], so every drawn atom lies inside the
//! picture whatever the view direction (the sphere around the box itself would be up to √3
//! times larger: a compact molecule would fill a third of the picture less than it can).

use glam::Vec3;
use texmap_core::camera::{Camera, CameraError};
use texmap_impostor::SphereScene;
use texmap_md_io::{Frame, Selection, SelectionError};

use crate::outline::cell_corners;

/// Direction from the target toward the eye of the automatic three-quarter view (unit after
/// normalisation): oblique, from the upper right front, so that no lattice-like alignment of a
/// box faces the viewer. The study's scenes are seen from the same direction.
pub const AUTO_VIEW_DIRECTION: Vec3 = Vec3::new(0.45, 0.35, 1.0);

/// How much larger than the drawn sphere the fitted view is (5% of air around the atoms).
pub const FIT_MARGIN: f32 = 1.05;

/// Where the automatic camera sits: the three-quarter view, or on a coordinate axis looking
/// back at the target (`X`: on the +x axis, looking toward −x).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewAxis {
    Auto,
    X,
    NegX,
    Y,
    NegY,
    Z,
    NegZ,
}

impl ViewAxis {
    /// The axis named `auto`, `x`, `-x`, `y`, `-y`, `z` or `-z`; `None` for anything else.
    pub fn parse(s: &str) -> Option<ViewAxis> {
        Some(match s {
            "auto" => ViewAxis::Auto,
            "x" => ViewAxis::X,
            "-x" => ViewAxis::NegX,
            "y" => ViewAxis::Y,
            "-y" => ViewAxis::NegY,
            "z" => ViewAxis::Z,
            "-z" => ViewAxis::NegZ,
            _ => return None,
        })
    }

    /// The viewing direction (from the camera toward the target) and the up vector: `+z` up
    /// when looking along x or y, `+y` up otherwise.
    pub fn direction(self) -> (Vec3, Vec3) {
        match self {
            ViewAxis::Auto => (-AUTO_VIEW_DIRECTION.normalize(), Vec3::Y),
            ViewAxis::X => (-Vec3::X, Vec3::Z),
            ViewAxis::NegX => (Vec3::X, Vec3::Z),
            ViewAxis::Y => (-Vec3::Y, Vec3::Z),
            ViewAxis::NegY => (Vec3::Y, Vec3::Z),
            ViewAxis::Z => (-Vec3::Z, Vec3::Y),
            ViewAxis::NegZ => (Vec3::Z, Vec3::Y),
        }
    }
}

/// The axis-aligned box around what `frame` draws as `scene`: the scene's valid spheres, else
/// the corners of the frame's periodic cell; `None` when there is neither.
pub fn drawn_bounds(frame: &Frame, scene: &SphereScene) -> Option<(Vec3, Vec3)> {
    if let Some(b) = scene.bounds() {
        return Some(b);
    }
    let cell = frame.cell.as_ref()?;
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for p in cell_corners(cell) {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    (lo.x <= hi.x).then_some((lo, hi))
}

/// Radius of the spheres [`push_framed_points`] adds: the smallest that [`fit_camera`] counts
/// (a sphere of radius 0 is not valid, and the fit would leave its point out).
pub const POINT_RADIUS: f32 = 1e-3;

/// Adds `points` to `scene` (a copy made for [`fit_camera`]) as spheres of [`POINT_RADIUS`]
/// and material 0, so that the camera also frames what is drawn beside the spheres: the
/// vertices of polyhedra, arrows, isosurfaces.
pub fn push_framed_points<'a>(scene: &mut SphereScene, points: impl IntoIterator<Item = &'a Vec3>) {
    for p in points {
        scene.push(*p, POINT_RADIUS, 0);
    }
}

/// The automatic camera for `frame` drawn as `scene`, and the point it looks at (see the module
/// docs): perspective with horizontal field of view `hfov_deg`, or orthographic for `None`.
///
/// Errors: those of [`Camera::fit_sphere`] (image size, field of view, non-finite bounds).
pub fn fit_camera(
    frame: &Frame,
    scene: &SphereScene,
    axis: ViewAxis,
    hfov_deg: Option<f32>,
    width: u32,
    height: u32,
) -> Result<(Camera, Vec3), CameraError> {
    let (dir, up) = axis.direction();
    let (center, radius) = match drawn_bounds(frame, scene) {
        Some((lo, hi)) => {
            let c = (lo + hi) * 0.5;
            // Within the box's circumsphere by construction; the tighter of the two.
            let spheres = (0..scene.len())
                .filter(|&i| scene.is_valid(i))
                .map(|i| (scene.centers[i] - c).length() + scene.radii[i]);
            let corners = frame
                .cell
                .as_ref()
                .filter(|_| scene.bounds().is_none())
                .map(|cell| cell_corners(cell).map(|p| (p - c).length()))
                .into_iter()
                .flatten();
            let r = spheres.chain(corners).fold(0.0f32, f32::max);
            (c, r.min((hi - lo).length() * 0.5))
        }
        None => (Vec3::ZERO, 1.0),
    };
    Camera::fit_sphere(
        center,
        radius.max(1e-3),
        dir,
        up,
        hfov_deg,
        width,
        height,
        FIT_MARGIN,
    )
    .map(|c| (c, center))
}

/// The view width of an orthographic camera placed by hand (eye, target, up given): the
/// diagonal of the scene's bounding box, or 1 for an empty scene.
pub fn ortho_extent(scene: &SphereScene) -> f32 {
    scene
        .bounds()
        .map(|(lo, hi)| (hi - lo).length())
        .unwrap_or(1.0)
}

/// The mean position of the atoms `sel` selects in `frame`, or `None` when it selects none.
/// The sum runs in f64, so a million atoms far from the origin keep their centre to well below
/// an atom's size.
pub fn centre_of(sel: &Selection, frame: &Frame) -> Result<Option<Vec3>, SelectionError> {
    let idx = sel.indices(frame)?;
    if idx.is_empty() {
        return Ok(None);
    }
    let mut sum = [0f64; 3];
    for &i in &idx {
        for (s, p) in sum.iter_mut().zip(frame.positions[i]) {
            *s += p as f64;
        }
    }
    let n = idx.len() as f64;
    Ok(Some(Vec3::new(
        (sum[0] / n) as f32,
        (sum[1] / n) as f32,
        (sum[2] / n) as f32,
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use texmap_md_io::UnitCell;

    /// Whether the whole sphere (c, r) projects inside the image of `cam`: a dense sample of its
    /// surface, projected with the camera's own projection, lands inside the image.
    fn sphere_inside(cam: &Camera, c: Vec3, r: f32) -> bool {
        let (w, h) = (cam.width() as f32, cam.height() as f32);
        let n = 48;
        for i in 0..=n {
            let th = std::f32::consts::PI * i as f32 / n as f32;
            for j in 0..2 * n {
                let ph = std::f32::consts::PI * j as f32 / n as f32;
                let p = c + r * Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                let Some((s, _)) = cam.project(p) else {
                    return false;
                };
                if !(s.x >= 0.0 && s.x <= w && s.y >= 0.0 && s.y <= h) {
                    return false;
                }
            }
        }
        true
    }

    /// One sphere of radius `r` per point, one material.
    fn scene_of(points: &[[f32; 3]], r: f32) -> SphereScene {
        let mut scene = SphereScene::default();
        scene
            .materials
            .push(texmap_core::shade::Material::plastic(Vec3::ONE));
        for p in points {
            scene.push(Vec3::from(*p), r, 0);
        }
        scene
    }

    fn frame_of(points: &[[f32; 3]]) -> Frame {
        let mut f = Frame::new();
        f.positions = points.to_vec();
        f
    }

    #[test]
    fn the_fitted_camera_sees_every_atom_from_every_axis() {
        let pts = [
            [-3.0, 1.0, 40.0],
            [5.0, -2.0, 44.0],
            [0.5, 7.0, 38.0],
            [1.0, 1.0, 52.0],
        ];
        let (frame, scene) = (frame_of(&pts), scene_of(&pts, 1.2));
        for axis in ["auto", "x", "-x", "y", "-y", "z", "-z"] {
            let axis = ViewAxis::parse(axis).unwrap();
            for hfov in [Some(20.0), Some(40.0), Some(100.0), None] {
                for (w, h) in [(640, 480), (300, 900)] {
                    let (cam, target) = fit_camera(&frame, &scene, axis, hfov, w, h).unwrap();
                    let (lo, hi) = scene.bounds().unwrap();
                    assert!((target - (lo + hi) * 0.5).length() < 1e-4);
                    // Every atom's whole sphere is in the picture...
                    for p in &pts {
                        assert!(
                            sphere_inside(&cam, Vec3::from(*p), 1.2),
                            "{axis:?} {hfov:?}"
                        );
                    }
                    // ... and the picture is not much larger than the bounding sphere about the
                    // target: grown by a quarter, that sphere no longer fits.
                    let tight = pts
                        .iter()
                        .map(|p| (Vec3::from(*p) - target).length() + 1.2)
                        .fold(0.0f32, f32::max);
                    let big = tight * 1.25;
                    assert!(
                        !sphere_inside(&cam, target, big),
                        "{axis:?} {hfov:?} too loose"
                    );
                    // The camera looks along the axis asked for.
                    let (dir, _) = axis.direction();
                    assert!(cam.forward().dot(dir.normalize()) > 0.9999);
                }
            }
        }
    }

    #[test]
    fn a_round_molecule_fills_the_picture_not_its_boxs_circumsphere() {
        // Atoms on a sphere of radius 20 Å: the box around them is 42 Å a side, and the sphere
        // around that box is √3 times too large to frame them.
        let n = 400;
        let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        let pts: Vec<[f32; 3]> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let r = (1.0 - z * z).sqrt();
                let a = golden * i as f32;
                [20.0 * r * a.cos(), 20.0 * r * a.sin(), 20.0 * z]
            })
            .collect();
        let (frame, scene) = (frame_of(&pts), scene_of(&pts, 1.0));
        for axis in ["auto", "x", "z"] {
            let axis = ViewAxis::parse(axis).unwrap();
            let (cam, target) = fit_camera(&frame, &scene, axis, Some(40.0), 640, 480).unwrap();
            assert!(pts.iter().all(|p| sphere_inside(&cam, Vec3::from(*p), 1.0)));
            // The 21 Å sphere holding every atom fills the picture within the 5 % margin.
            assert!(!sphere_inside(&cam, target, 21.0 * 1.08), "{axis:?}");
        }
    }

    #[test]
    fn an_empty_scene_frames_the_cell_or_the_origin() {
        let mut frame = frame_of(&[]);
        let scene = SphereScene::default();
        let (_, t) = fit_camera(&frame, &scene, ViewAxis::Z, Some(40.0), 64, 64).unwrap();
        assert_eq!(t, Vec3::ZERO);
        frame.cell = Some(UnitCell::orthorhombic(4.0, 6.0, 8.0).unwrap());
        let (cam, t) = fit_camera(&frame, &scene, ViewAxis::Auto, Some(40.0), 64, 64).unwrap();
        assert!((t - Vec3::new(2.0, 3.0, 4.0)).length() < 1e-5);
        // The cell's circumscribed sphere fits: every corner projects inside.
        for c in cell_corners(frame.cell.as_ref().unwrap()) {
            let (s, _) = cam.project(c).unwrap();
            assert!(s.x > 0.0 && s.x < 64.0 && s.y > 0.0 && s.y < 64.0);
        }
        assert_eq!(ViewAxis::parse("w"), None);
    }

    #[test]
    fn selection_centres_are_means_of_the_selected_atoms() {
        // Atoms far from the origin: an f32 sum would lose the offsets.
        let base = 1.0e6f32;
        let mut frame = frame_of(&[[base, 0.0, 0.0], [base + 2.0, 4.0, 0.0], [0.0, 0.0, 9.0]]);
        frame.names = ["A", "A", "B"]
            .map(|s| texmap_md_io::Label::new(s).unwrap())
            .to_vec();
        let sel = Selection::parse("name A").unwrap();
        let c = centre_of(&sel, &frame).unwrap().unwrap();
        assert_eq!(c, Vec3::new(base + 1.0, 2.0, 0.0));
        let none = Selection::parse("name C").unwrap();
        assert_eq!(centre_of(&none, &frame).unwrap(), None);
    }
}
