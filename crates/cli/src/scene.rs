//! Glue: an md-io frame (atoms in Å) becomes an impostor `SphereScene`, and a camera is chosen.

use anyhow::{Context, Result};
use glam::Vec3;
use texmap_core::camera::Camera;
use texmap_core::color::{hsv_to_rgb, srgb_to_linear};
use texmap_core::shade::Material;
use texmap_impostor::SphereScene;
use texmap_md_io::{AtomStyle, Frame};

use crate::args::{ColorBy, RenderArgs, usage};

/// Reusable conversion from md-io frames to sphere scenes: one material per distinct colour,
/// kept stable across frames so per-material tables survive from frame to frame.
pub struct SceneBuilder {
    style: AtomStyle,
    color_by: ColorBy,
    palette: Vec<[u32; 3]>,
    types: Vec<String>,
    radii: Vec<f32>,
    colors: Vec<[f32; 3]>,
}

/// A distinct, evenly spaced hue per type index (golden-angle hues).
fn type_color(i: usize) -> [f32; 3] {
    let c = hsv_to_rgb(Vec3::new((i as f32 * 137.507_77) % 360.0, 0.65, 0.95));
    [c.x, c.y, c.z]
}

impl SceneBuilder {
    pub fn new(color_by: ColorBy, radius_scale: f32) -> Result<SceneBuilder> {
        let mut style = AtomStyle::new();
        if !(radius_scale.is_finite() && radius_scale > 0.0) {
            return usage(format!(
                "--radius-scale must be finite and > 0, got {radius_scale}"
            ));
        }
        style.set_radius_scale(radius_scale)?;
        Ok(SceneBuilder {
            style,
            color_by,
            palette: Vec::new(),
            types: Vec::new(),
            radii: Vec::new(),
            colors: Vec::new(),
        })
    }

    fn kind_of(&mut self, srgb: [f32; 3]) -> u16 {
        // Quantise to 8 bits per channel so near-identical colours share a material.
        let key = srgb.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u32);
        match self.palette.iter().position(|p| *p == key) {
            Some(i) => i as u16,
            None => {
                self.palette.push(key);
                (self.palette.len() - 1) as u16
            }
        }
    }

    /// Fill `scene` (cleared first) from `frame` (whose colour column is dropped unless colouring
    /// by property). Atoms with non-finite coordinates are kept as
    /// they are: the renderers skip and count them.
    pub fn build(&mut self, frame: &mut Frame, scene: &mut SphereScene) {
        if self.color_by != ColorBy::Property {
            // Element and type colouring ignore colour columns in the file.
            frame.colors.clear();
        }
        self.style.apply(frame, &mut self.radii, &mut self.colors);
        scene.centers.clear();
        scene.radii.clear();
        scene.kinds.clear();
        scene.bonds.clear();
        for i in 0..frame.n_atoms() {
            let p = frame.positions[i];
            let color = match self.color_by {
                ColorBy::Type => {
                    let label = frame
                        .types
                        .get(i)
                        .or(frame.names.get(i))
                        .map(|l| l.as_str().to_string())
                        .unwrap_or_default();
                    let idx = match self.types.iter().position(|t| *t == label) {
                        Some(j) => j,
                        None => {
                            self.types.push(label);
                            self.types.len() - 1
                        }
                    };
                    type_color(idx)
                }
                _ => self.colors[i],
            };
            let kind = self.kind_of(color);
            scene.push(Vec3::from(p), self.radii[i], kind);
        }
        scene.materials = self
            .palette
            .iter()
            .map(|c| {
                Material::plastic(Vec3::new(
                    srgb_to_linear(c[0] as f32 / 255.0),
                    srgb_to_linear(c[1] as f32 / 255.0),
                    srgb_to_linear(c[2] as f32 / 255.0),
                ))
            })
            .collect();
    }
}

/// The 8 corners of a periodic cell, corner `c` at fractional coordinates of its bits (x, y, z).
pub fn cell_corners(cell: &texmap_md_io::UnitCell) -> [Vec3; 8] {
    std::array::from_fn(|c| {
        let p = cell.to_cartesian([(c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64]);
        Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32)
    })
}

fn parse_vec3(s: &str, what: &str) -> Result<Vec3> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return usage(format!(
            "{what} {s:?}: expected three comma-separated numbers X,Y,Z"
        ));
    }
    let mut v = [0f32; 3];
    for (k, p) in parts.iter().enumerate() {
        v[k] = match p.parse::<f32>() {
            Ok(x) if x.is_finite() => x,
            _ => return usage(format!("{what} {s:?}: {p:?} is not a finite number")),
        };
    }
    Ok(Vec3::from(v))
}

/// Parse `WxH`.
pub fn parse_size(s: &str) -> Result<(u32, u32)> {
    let bad = || {
        usage(format!(
            "size {s:?}: expected WxH with 1 ≤ W, H ≤ 16384, e.g. 1280x720"
        ))
    };
    let Some((w, h)) = s.split_once(['x', 'X']) else {
        return bad();
    };
    match (w.trim().parse::<u32>(), h.trim().parse::<u32>()) {
        (Ok(w), Ok(h))
            if (1..=texmap_core::camera::MAX_IMAGE_SIDE).contains(&w)
                && (1..=texmap_core::camera::MAX_IMAGE_SIDE).contains(&h) =>
        {
            Ok((w, h))
        }
        _ => bad(),
    }
}

/// Parse `R,G,B` (0–255) into an opaque sRGB colour.
pub fn parse_background(s: &str) -> Result<[u8; 4]> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let parsed: Vec<Option<u8>> = parts.iter().map(|p| p.parse::<u8>().ok()).collect();
    match parsed.as_slice() {
        [Some(r), Some(g), Some(b)] => Ok([*r, *g, *b, 255]),
        _ => usage(format!(
            "--background {s:?}: expected R,G,B with each 0-255"
        )),
    }
}

/// The view direction (from the camera toward the target) for `--view`.
fn view_direction(view: &str) -> Result<(Vec3, Vec3)> {
    Ok(match view {
        "auto" => (-texmap_study::scenes::VIEW_DIRECTION.normalize(), Vec3::Y),
        "x" => (-Vec3::X, Vec3::Z),
        "-x" => (Vec3::X, Vec3::Z),
        "y" => (-Vec3::Y, Vec3::Z),
        "-y" => (Vec3::Y, Vec3::Z),
        "z" => (-Vec3::Z, Vec3::Y),
        "-z" => (Vec3::Z, Vec3::Y),
        other => {
            return usage(format!(
                "--view {other:?}: expected auto, x, y, z, -x, -y or -z (the axis the camera sits on)"
            ));
        }
    })
}

/// The camera for a render: exactly `--eye/--target/--up` when given, else fitted to the first
/// frame's atoms and box.
pub fn camera_for(args: &RenderArgs, first: &Frame, scene: &SphereScene) -> Result<Camera> {
    let (w, h) = parse_size(&args.size)?;
    let hfov = if args.ortho { None } else { Some(args.fov) };
    if let Some(f) = hfov
        && !(f.is_finite() && f > 0.0 && f < 180.0)
    {
        return usage(format!(
            "--fov {f}: must be strictly between 0 and 180 degrees"
        ));
    }
    match (&args.eye, &args.target, &args.up) {
        (Some(e), Some(t), Some(u)) => {
            let (e, t, u) = (
                parse_vec3(e, "--eye")?,
                parse_vec3(t, "--target")?,
                parse_vec3(u, "--up")?,
            );
            let cam = match hfov {
                Some(f) => Camera::perspective_look_at(e, t, u, f, w, h),
                None => {
                    // Orthographic with an explicit camera: frame the scene's extent.
                    let extent = scene
                        .bounds()
                        .map(|(lo, hi)| (hi - lo).length())
                        .unwrap_or(1.0);
                    Camera::orthographic_look_at(e, t, u, extent, w, h)
                }
            };
            return cam.map_err(|e| crate::args::UsageError(format!("camera: {e}")).into());
        }
        (None, None, None) => {}
        _ => return usage("--eye, --target and --up go together: give all three or none"),
    }
    let (dir, up) = view_direction(&args.view)?;
    // Frame the union of the atoms and the periodic box (when the file has one).
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    if let Some((a, b)) = scene.bounds() {
        lo = a;
        hi = b;
    }
    if let Some(cell) = &first.cell {
        for p in cell_corners(cell) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    let (center, radius) = if lo.x <= hi.x {
        ((lo + hi) * 0.5, (hi - lo).length() * 0.5)
    } else {
        (Vec3::ZERO, 1.0)
    };
    Camera::fit_sphere(center, radius.max(1e-3), dir, up, hfov, w, h, 1.05)
        .context("automatic camera")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_colours_parse_or_fail_clearly() {
        assert_eq!(parse_size("640x480").unwrap(), (640, 480));
        for bad in ["640", "0x10", "10x", "axb", "20000x10"] {
            let e = parse_size(bad).unwrap_err();
            assert!(
                e.downcast_ref::<crate::args::UsageError>().is_some(),
                "{bad}"
            );
        }
        assert_eq!(parse_background("1,2,3").unwrap(), [1, 2, 3, 255]);
        assert!(parse_background("1,2").is_err());
        assert!(parse_background("1,2,300").is_err());
        assert_eq!(
            parse_vec3("1,-2.5,3", "x").unwrap(),
            Vec3::new(1.0, -2.5, 3.0)
        );
        assert!(parse_vec3("1,nan,3", "x").is_err());
    }
}
