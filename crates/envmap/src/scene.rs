//! The scene an environment-mapped frame is drawn from: one reflective or refractive target among
//! opaque objects, an environment at infinity and the workspace's lighting.
//!
//! [`EnvScene::new`] validates everything once (indices, attribute lengths, a target with a
//! surface, a positive index of refraction); the renderer then trusts the data. Objects are
//! flat-shaded with their [`Material`] (the reference ray tracer shades its flat meshes the same
//! way), so a difference between a method and the reference is in the reflection alone.

use glam::{Quat, Vec3};
use texmap_core::camera::Camera;
use texmap_core::shade::{Lighting, Material};
use texmap_mesh::TriMesh;

use crate::environment::Environment;
use crate::error::EnvMapError;
use crate::shapes;

/// An opaque scene object.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub mesh: TriMesh,
    pub material: Material,
}

/// The target's geometry.
#[derive(Clone, Debug, PartialEq)]
pub enum TargetShape {
    /// An analytic sphere (drawn exactly, per pixel; tessellated for the per-vertex method).
    Sphere { centre: Vec3, radius: f32 },
    /// A triangle mesh; smooth vertex normals from the mesh, or averaged from the faces.
    Mesh(TriMesh),
}

/// How the target sends light on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Surface {
    /// A perfect mirror (reflectance 1).
    Mirror,
    /// A clear dielectric of index `ior` (outside index 1), refraction only; total internal
    /// reflection reflects.
    Refractive { ior: f32 },
}

/// The reflective or refractive object the maps are made for.
#[derive(Clone, Debug, PartialEq)]
pub struct Target {
    pub shape: TargetShape,
    pub surface: Surface,
}

/// A validated scene (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvScene {
    objects: Vec<Object>,
    target: Target,
    environment: Environment,
    lighting: Lighting,
    /// The target's centre (the probe position of every map).
    centre: Vec3,
    /// The target's bounding radius about `centre`.
    radius: f32,
    /// The proxy box of the box-projected cube map (`None`: the objects' bounds).
    proxy: Option<(Vec3, Vec3)>,
    /// The target's smooth normals when it is a mesh.
    target_normals: Vec<Vec3>,
}

fn check_mesh(m: &TriMesh, object: Option<usize>) -> Result<(), EnvMapError> {
    let n = m.positions.len();
    if let Some(normals) = &m.normals
        && normals.len() != n
    {
        return Err(EnvMapError::MeshAttribute {
            object,
            attribute: "normals",
            len: normals.len(),
            expected: n,
        });
    }
    for (t, tri) in m.triangles.iter().enumerate() {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= n) {
            return Err(EnvMapError::MeshIndex {
                object,
                triangle: t,
                index,
                vertex_count: n,
            });
        }
    }
    Ok(())
}

/// Area-weighted smooth normals (a mesh's own normals where finite and non-zero).
fn smooth_normals(m: &TriMesh) -> Vec<Vec3> {
    let mut acc = vec![Vec3::ZERO; m.positions.len()];
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let f = (b - a).cross(c - a);
        if f.is_finite() {
            for &i in t {
                acc[i as usize] += f;
            }
        }
    }
    acc.iter()
        .enumerate()
        .map(|(i, a)| {
            let given = m.normals.as_ref().and_then(|n| n[i].try_normalize());
            given.unwrap_or_else(|| a.normalize_or(Vec3::Y))
        })
        .collect()
}

impl EnvScene {
    /// A scene; see [`EnvScene`] for what is checked.
    pub fn new(
        objects: Vec<Object>,
        target: Target,
        environment: Environment,
        lighting: Lighting,
    ) -> Result<EnvScene, EnvMapError> {
        for (i, o) in objects.iter().enumerate() {
            check_mesh(&o.mesh, Some(i))?;
        }
        if let Surface::Refractive { ior } = target.surface
            && !(ior.is_finite() && ior > 0.0)
        {
            return Err(EnvMapError::BadIor { ior });
        }
        let (centre, radius, target_normals) = match &target.shape {
            TargetShape::Sphere { centre, radius } => {
                if !(centre.is_finite() && radius.is_finite() && *radius > 0.0) {
                    return Err(EnvMapError::EmptyTarget {
                        what: "sphere radius must be finite and positive (and the centre finite)",
                    });
                }
                (*centre, *radius, Vec::new())
            }
            TargetShape::Mesh(m) => {
                check_mesh(m, None)?;
                let mut lo = Vec3::splat(f32::INFINITY);
                let mut hi = Vec3::splat(f32::NEG_INFINITY);
                let mut any = false;
                for t in &m.triangles {
                    let [a, b, c] = t.map(|i| m.positions[i as usize]);
                    let area = (b - a).cross(c - a).length();
                    if a.is_finite() && b.is_finite() && c.is_finite() && area > 0.0 {
                        any = true;
                        for p in [a, b, c] {
                            lo = lo.min(p);
                            hi = hi.max(p);
                        }
                    }
                }
                if !any {
                    return Err(EnvMapError::EmptyTarget {
                        what: "the mesh has no triangle with finite vertices and non-zero area",
                    });
                }
                let c = (lo + hi) * 0.5;
                (c, ((hi - lo) * 0.5).length(), smooth_normals(m))
            }
        };
        Ok(EnvScene {
            objects,
            target,
            environment,
            lighting,
            centre,
            radius,
            proxy: None,
            target_normals,
        })
    }

    /// The same scene with an explicit proxy box for the box-projected cube map. Errors if the
    /// box is not finite, inverted, or does not hold the target's centre.
    pub fn with_proxy_box(mut self, lo: Vec3, hi: Vec3) -> Result<EnvScene, EnvMapError> {
        let c = self.centre;
        if !(lo.is_finite() && hi.is_finite() && lo.cmplt(c).all() && c.cmplt(hi).all()) {
            return Err(EnvMapError::BadOption {
                what: "the proxy box must be finite and hold the target's centre strictly inside",
            });
        }
        self.proxy = Some((lo, hi));
        Ok(self)
    }

    pub fn objects(&self) -> &[Object] {
        &self.objects
    }

    pub fn target(&self) -> &Target {
        &self.target
    }

    pub fn environment(&self) -> &Environment {
        &self.environment
    }

    pub fn lighting(&self) -> &Lighting {
        &self.lighting
    }

    /// The target's centre: the sphere's centre, or the centre of the mesh's bounds.
    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    /// The target's bounding radius about [`EnvScene::centre`].
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// The target mesh's unit vertex normals (empty for a sphere target).
    pub fn target_normals(&self) -> &[Vec3] {
        &self.target_normals
    }

    /// The proxy box of the box-projected cube map: the one given, or the bounds of every
    /// object's finite vertices together with the target (`None` for a scene with no object).
    pub fn proxy_box(&self) -> Option<(Vec3, Vec3)> {
        if let Some(b) = self.proxy {
            return Some(b);
        }
        let mut lo = self.centre - Vec3::splat(self.radius);
        let mut hi = self.centre + Vec3::splat(self.radius);
        let mut any = false;
        for o in &self.objects {
            for p in o.mesh.positions.iter().filter(|p| p.is_finite()) {
                lo = lo.min(*p);
                hi = hi.max(*p);
                any = true;
            }
        }
        any.then_some((lo, hi))
    }

    /// The number of object triangles.
    pub fn object_triangles(&self) -> usize {
        self.objects.iter().map(|o| o.mesh.triangles.len()).sum()
    }
}

/// Parameters of the built-in scene, after Seed 003's demo: a mirror sphere flying down a striped
/// tunnel with objects orbiting it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TunnelParams {
    /// Animation time in seconds (the orbiting objects move).
    pub time: f32,
    /// Tessellation multiplier: 1 gives about 6k triangles; about 16 gives 100k.
    pub detail: u32,
    /// The target's surface.
    pub surface: Surface,
}

impl Default for TunnelParams {
    fn default() -> Self {
        TunnelParams {
            time: 0.0,
            detail: 1,
            surface: Surface::Mirror,
        }
    }
}

/// Radius of the built-in tunnel (the target sphere has radius 1 at the origin).
pub const TUNNEL_RADIUS: f32 = 4.0;

/// The built-in scene (see [`TunnelParams`]): a unit mirror sphere at the origin, a tunnel of
/// radius [`TUNNEL_RADIUS`] along z in two colours, three tori and three boxes orbiting the sphere
/// at 2.2–3 radii, the built-in sky, and a key light from the upper left.
pub fn tunnel_scene(p: TunnelParams) -> Result<EnvScene, EnvMapError> {
    let d = p.detail.clamp(1, 64);
    let s = (d as f32).sqrt();
    let seg = (48.0 * s) as u32;
    let rings = (40.0 * s) as u32;
    let mut objects = Vec::new();
    let stripe_colours = [Vec3::new(0.85, 0.85, 0.80), Vec3::new(0.15, 0.35, 0.75)];
    for (m, c) in shapes::tunnel(TUNNEL_RADIUS, -30.0, 12.0, seg, rings, 2)
        .into_iter()
        .zip(stripe_colours)
    {
        objects.push(Object {
            mesh: m,
            material: Material::matte(c),
        });
    }
    let t = p.time;
    let colours = [
        Vec3::new(0.9, 0.2, 0.15),
        Vec3::new(0.2, 0.8, 0.25),
        Vec3::new(0.95, 0.75, 0.1),
    ];
    for k in 0..3 {
        let a = t * 0.9 + k as f32 * std::f32::consts::TAU / 3.0;
        let r = 2.4 + 0.3 * k as f32;
        let c = Vec3::new(a.cos() * r, a.sin() * r, -1.0 + 0.5 * k as f32);
        objects.push(Object {
            mesh: shapes::torus(
                c,
                Vec3::new(a.sin(), 0.3, a.cos()),
                0.45,
                0.15,
                (24.0 * s) as u32,
                (12.0 * s) as u32,
            ),
            material: Material::matte(colours[k]),
        });
        let b = -t * 0.6 + (k as f32 + 0.5) * std::f32::consts::TAU / 3.0;
        let c = Vec3::new(b.cos() * 2.8, b.sin() * 2.8, -3.0 - k as f32);
        objects.push(Object {
            mesh: shapes::cuboid(
                c - Vec3::splat(0.3),
                c + Vec3::splat(0.3),
                Quat::from_euler(glam::EulerRot::XYZ, t + k as f32, 0.7 * t, 0.3),
            ),
            material: Material::matte(colours[(k + 1) % 3] * 0.8),
        });
    }
    let target = Target {
        shape: TargetShape::Sphere {
            centre: Vec3::ZERO,
            radius: 1.0,
        },
        surface: p.surface,
    };
    let lighting = tunnel_lighting();
    EnvScene::new(objects, target, Environment::Sky, lighting)
}

/// The built-in scene's lighting: ambient 0.25 and one white key light.
pub fn tunnel_lighting() -> Lighting {
    Lighting::new(
        Vec3::splat(0.25),
        &[(Vec3::new(-0.4, 0.7, 0.6).normalize(), Vec3::splat(0.85))],
    )
    .expect("constant, valid lighting")
}

/// The built-in scene's camera: behind and above the sphere, looking down the tunnel.
pub fn tunnel_camera(width: u32, height: u32) -> Result<Camera, EnvMapError> {
    Ok(Camera::perspective_look_at(
        Vec3::new(0.6, 0.9, 5.0),
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::Y,
        55.0,
        width,
        height,
    )?)
}

/// A smooth latitude-longitude environment (64x32: a sine in longitude, a ramp in latitude), for
/// studies where the environment's own detail must not matter and only the objects' parallax is
/// left to see.
pub fn smooth_environment() -> Environment {
    let (w, h) = (64u32, 32u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            Vec3::new(
                0.3 + 0.3 * (x * std::f32::consts::TAU).sin(),
                0.2 + 0.6 * (1.0 - y),
                0.5,
            )
        })
        .collect();
    Environment::lat_long(w, h, texels).expect("2:1 and finite by construction")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere_target() -> Target {
        Target {
            shape: TargetShape::Sphere {
                centre: Vec3::ZERO,
                radius: 1.0,
            },
            surface: Surface::Mirror,
        }
    }

    #[test]
    fn bad_input_is_refused_with_its_location() {
        let l = tunnel_lighting();
        let broken = TriMesh {
            positions: vec![Vec3::ZERO; 3],
            triangles: vec![[0, 1, 2], [0, 1, 7]],
            uvs: None,
            normals: None,
        };
        let e = EnvScene::new(
            vec![Object {
                mesh: broken.clone(),
                material: Material::matte(Vec3::ONE),
            }],
            sphere_target(),
            Environment::Sky,
            l,
        )
        .unwrap_err();
        assert!(
            matches!(
                e,
                EnvMapError::MeshIndex {
                    object: Some(0),
                    triangle: 1,
                    index: 7,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("triangle 1 uses vertex 7"), "{e}");
        for ior in [0.0, -1.5, f32::NAN] {
            let t = Target {
                surface: Surface::Refractive { ior },
                ..sphere_target()
            };
            let e = EnvScene::new(vec![], t, Environment::Sky, l).unwrap_err();
            assert!(matches!(e, EnvMapError::BadIor { .. }), "{e}");
        }
        // A flat (zero-area) mesh has no surface.
        let flat = TriMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
            triangles: vec![[0, 1, 2]],
            uvs: None,
            normals: None,
        };
        for shape in [
            TargetShape::Mesh(flat),
            TargetShape::Mesh(TriMesh::default()),
            TargetShape::Sphere {
                centre: Vec3::ZERO,
                radius: 0.0,
            },
        ] {
            let t = Target {
                shape,
                surface: Surface::Mirror,
            };
            let e = EnvScene::new(vec![], t, Environment::Sky, l).unwrap_err();
            assert!(matches!(e, EnvMapError::EmptyTarget { .. }), "{e}");
        }
        let t = Target {
            shape: TargetShape::Mesh(broken),
            surface: Surface::Mirror,
        };
        let e = EnvScene::new(vec![], t, Environment::Sky, l).unwrap_err();
        assert!(
            matches!(e, EnvMapError::MeshIndex { object: None, .. }),
            "{e}"
        );
    }

    #[test]
    fn the_tunnel_scene_scales_with_detail() {
        let s1 = tunnel_scene(TunnelParams::default()).unwrap();
        let s16 = tunnel_scene(TunnelParams {
            detail: 16,
            ..Default::default()
        })
        .unwrap();
        assert!(
            (3_000..15_000).contains(&s1.object_triangles()),
            "{}",
            s1.object_triangles()
        );
        assert!(
            (80_000..140_000).contains(&s16.object_triangles()),
            "{}",
            s16.object_triangles()
        );
        assert_eq!(s1.centre(), Vec3::ZERO);
        let (lo, hi) = s1.proxy_box().unwrap();
        assert!(lo.x <= -TUNNEL_RADIUS + 1e-3 && hi.x >= TUNNEL_RADIUS - 1e-3);
    }
}
