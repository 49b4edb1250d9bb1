//! Baking a reflection probe: the scene's dynamic cube map around a point, handed out as images
//! in the layouts engines and tools import (linear f32 RGB radiance, in memory: the caller writes
//! the files).
//!
//! [`bake`] runs the cube map's own dynamic update ([`maps::update_cube`]: six 90° cameras at the
//! probe, the objects flat-lit over the environment) at `size²` texels per face and keeps the
//! finest level without its border. The target is never drawn into its own probe, as in the
//! dynamic map; the scene is taken as given, so an animated scene is built at the wanted time by
//! the caller (`scene::tunnel_scene(TunnelParams { time, .. })`).
//!
//! # Face convention
//! Faces come in the OpenGL order `+X, −X, +Y, −Y, +Z, −Z` ([`Face::ALL`]; also KTX's and DDS's)
//! and each face is oriented as the OpenGL specification's cube-map table defines it for a
//! direction `r` of our world: with the major axis `ma`,
//!
//! | face | `sc` | `tc` | `ma` |
//! |---|---|---|---|
//! | +X | −r_z | −r_y | r_x |
//! | −X | +r_z | −r_y | r_x |
//! | +Y | +r_x | +r_z | r_y |
//! | −Y | +r_x | −r_z | r_y |
//! | +Z | +r_x | −r_y | r_z |
//! | −Z | −r_x | −r_y | r_z |
//!
//! `s = ½(sc/|ma| + 1)` along a row, `t = ½(tc/|ma| + 1)` down the rows (row 0 at `t = 0`).
//! The map's own faces ([`crate::address::cube_face_uv`]) are the face cameras' images: the
//! same `t` (`v`), and `u = 1 − s` on every face (a camera in a right-handed world sees the
//! spec's left-handed faces mirrored), so texel column `i` of a baked face is column `n − 1 − i`
//! of the map's. In our right-handed world a viewer inside the cube therefore sees each face
//! mirrored; that is the specification's convention and what KTX/DDS readers and `samplerCube`
//! expect.
//!
//! # Layouts ([`Layout`])
//! - [`Layout::Faces`]: the six faces, `n × n` each;
//! - [`Layout::Cross`]: the horizontal cross, `4n × 3n`, the faces as above unrotated: `+Y` over
//!   `+Z`, the row `−X, +Z, +X, −Z`, `−Y` under `+Z` (every shared edge continuous); the rest is
//!   black;
//! - [`Layout::C3x2`]: ffmpeg's `v360` `c3x2`, `3n × 2n`, faces `r l u / d f b`, each as ffmpeg's
//!   `cube_to_xyz` defines it (libavfilter/vf_v360.c; pixel `(uf, vf) ∈ [−1, 1]²`, `uf` right,
//!   `vf` down): r `(1, −vf, uf)`, l `(−1, −vf, −uf)`, u `(uf, 1, −vf)`, d `(uf, −1, vf)`,
//!   f `(uf, −vf, −1)`, b `(−uf, −vf, 1)`. ffmpeg's frame is ours (y up, front −z), so r, l, f,
//!   b are the OpenGL faces +X, −X, −Z, +Z mirrored left-right and u, d are +Y, −Y flipped
//!   upside down: texels are moved, never resampled;
//! - [`Layout::Equirect`]: latitude-longitude, `4n × 2n`, in the layout of
//!   [`Environment::lat_long`](crate::Environment::lat_long) (centre −z, top +y), so a baked
//!   equirect used as the environment reproduces the surroundings. It is **resampled** from the
//!   cube: bilinear on the finest level at each texel centre's direction ([`EnvMap::lookup`]; the
//!   cube's border texels, drawn from the scene, make lookups across a face edge seamless).
//!
//! Rejected: a second rasteriser or a ray caster for the probe (the dynamic update is the
//! method being exported, and the reference ray tracer is the oracle it is tested against).
//!
//! # References
//! - The OpenGL 4.6 core profile specification, §8.13 "Cube Map Texture Selection" (the face
//!   table above); KTX 2.0 and DDS store cube faces in the same order and orientation.
//! - FFmpeg's `v360` filter (libavfilter/vf_v360.c, `cube_to_xyz` and the `c3x2` layout's
//!   default face order `rludfb`), checked against ffmpeg itself by the CLI's tests.

use glam::{Vec2, Vec3};

use crate::address::{Face, MapFrame};
use crate::error::EnvMapError;
use crate::maps::{self, EnvMap, MapScratch, UpdateParams};
use crate::scene::EnvScene;

/// Where and how finely to bake.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeOptions {
    /// The probe position; `None`: the target's centre ([`EnvScene::centre`]).
    pub at: Option<Vec3>,
    /// Texels per face side, [`maps::MIN_MAP_SIZE`]..=[`maps::MAX_MAP_SIZE`].
    pub size: u32,
}

impl Default for BakeOptions {
    fn default() -> Self {
        BakeOptions {
            at: None,
            size: 256,
        }
    }
}

/// The image layouts of a baked probe (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Layout {
    /// Six `n × n` faces, OpenGL order and orientation.
    Faces,
    /// The horizontal cross, `4n × 3n`.
    Cross,
    /// ffmpeg's `v360` `c3x2`, `3n × 2n`.
    C3x2,
    /// Latitude-longitude, `4n × 2n`, resampled bilinearly from the cube.
    Equirect,
}

/// A linear RGB image, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec3>,
}

impl Image {
    fn black(width: u32, height: u32) -> Image {
        Image {
            width,
            height,
            texels: vec![Vec3::ZERO; width as usize * height as usize],
        }
    }
}

/// The short name of a face in file names: `px nx py ny pz nz`.
pub fn face_name(face: Face) -> &'static str {
    match face {
        Face::PosX => "px",
        Face::NegX => "nx",
        Face::PosY => "py",
        Face::NegY => "ny",
        Face::PosZ => "pz",
        Face::NegZ => "nz",
    }
}

/// A baked probe: six faces in the OpenGL convention (module docs).
#[derive(Clone, Debug)]
pub struct Probe {
    size: u32,
    centre: Vec3,
    /// Indexed by [`Face::index`], `size²` texels each.
    faces: [Vec<Vec3>; 6],
    /// The cube map the faces come from (with its border), for resampled layouts.
    map: EnvMap,
}

/// Bake the scene's cube map around `opts.at` (see the module docs). Errors: a size out of
/// range, a probe position that is not finite.
pub fn bake(scene: &EnvScene, opts: &BakeOptions) -> Result<Probe, EnvMapError> {
    let centre = opts.at.unwrap_or(scene.centre());
    if !centre.is_finite() {
        return Err(EnvMapError::BadOption {
            what: "the probe position must be finite",
        });
    }
    let p = UpdateParams {
        objects: scene.objects(),
        lighting: scene.lighting(),
        environment: scene.environment(),
        centre,
        frame: MapFrame::WORLD,
        size: opts.size,
        min_distance: 0.0,
        rim: maps::RimPolicy::Split,
    };
    let map = maps::update_cube(&p, &mut MapScratch::default())?;
    let n = opts.size as i64;
    let b = maps::CUBE_BORDER as i64;
    // Level 0 without the border; OpenGL column i is the map's column n − 1 − i (module docs).
    let faces = Face::ALL.map(|face| {
        let tex = &map.faces()[face.index()];
        let mut out = Vec::with_capacity((n * n) as usize);
        for j in 0..n {
            for i in 0..n {
                let t = tex
                    .texel(0, b + n - 1 - i, b + j)
                    .expect("level 0 holds the face and its border");
                out.push(t.truncate());
            }
        }
        out
    });
    Ok(Probe {
        size: opts.size,
        centre,
        faces,
        map,
    })
}

/// How a face's texels are placed in a layout: texel `(i, j)` of the placed face comes from the
/// OpenGL face's texel `(i, j)`, `(n−1−i, j)` or `(i, n−1−j)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Orient {
    Same,
    MirrorLeftRight,
    UpsideDown,
}

impl Probe {
    /// Texels per face side.
    pub fn size(&self) -> u32 {
        self.size
    }

    /// The probe position.
    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    /// One face, OpenGL orientation, `size²` texels row-major (row 0 at `t = 0`).
    pub fn face(&self, face: Face) -> &[Vec3] {
        &self.faces[face.index()]
    }

    /// The probe in a layout: six images for [`Layout::Faces`] (in [`Face::ALL`] order), one
    /// otherwise.
    pub fn layout(&self, layout: Layout) -> Vec<Image> {
        match layout {
            Layout::Faces => Face::ALL
                .map(|f| Image {
                    width: self.size,
                    height: self.size,
                    texels: self.face(f).to_vec(),
                })
                .to_vec(),
            Layout::Cross => vec![self.cross()],
            Layout::C3x2 => vec![self.c3x2()],
            Layout::Equirect => vec![self.equirect()],
        }
    }

    /// Copy `face` into `img` with its top-left texel at face cell `(cx, cy)` (in faces).
    fn place(&self, img: &mut Image, face: Face, cx: u32, cy: u32, orient: Orient) {
        let n = self.size as usize;
        let src = self.face(face);
        let w = img.width as usize;
        let (x0, y0) = (cx as usize * n, cy as usize * n);
        for j in 0..n {
            for i in 0..n {
                let (si, sj) = match orient {
                    Orient::Same => (i, j),
                    Orient::MirrorLeftRight => (n - 1 - i, j),
                    Orient::UpsideDown => (i, n - 1 - j),
                };
                img.texels[(y0 + j) * w + x0 + i] = src[sj * n + si];
            }
        }
    }

    /// The horizontal cross (module docs).
    pub fn cross(&self) -> Image {
        let n = self.size;
        let mut img = Image::black(4 * n, 3 * n);
        for (face, cx, cy) in [
            (Face::PosY, 1, 0),
            (Face::NegX, 0, 1),
            (Face::PosZ, 1, 1),
            (Face::PosX, 2, 1),
            (Face::NegZ, 3, 1),
            (Face::NegY, 1, 2),
        ] {
            self.place(&mut img, face, cx, cy, Orient::Same);
        }
        img
    }

    /// ffmpeg's `c3x2` (module docs).
    pub fn c3x2(&self) -> Image {
        let n = self.size;
        let mut img = Image::black(3 * n, 2 * n);
        for (face, cx, cy, orient) in [
            (Face::PosX, 0, 0, Orient::MirrorLeftRight),
            (Face::NegX, 1, 0, Orient::MirrorLeftRight),
            (Face::PosY, 2, 0, Orient::UpsideDown),
            (Face::NegY, 0, 1, Orient::UpsideDown),
            (Face::NegZ, 1, 1, Orient::MirrorLeftRight),
            (Face::PosZ, 2, 1, Orient::MirrorLeftRight),
        ] {
            self.place(&mut img, face, cx, cy, orient);
        }
        img
    }

    /// Latitude-longitude, `4n × 2n`, bilinear from the cube (module docs): texel `(x, y)` shows
    /// the direction of `u = (x + ½)/w`, `v = (y + ½)/h` in [`crate::environment`]'s layout,
    /// `d = (sin θ sin φ, cos θ, −sin θ cos φ)` with `φ = 2π(u − ½)`, `θ = πv`.
    pub fn equirect(&self) -> Image {
        let (w, h) = (4 * self.size, 2 * self.size);
        let mut img = Image::black(w, h);
        for (k, t) in img.texels.iter_mut().enumerate() {
            let uv = Vec2::new(
                ((k % w as usize) as f32 + 0.5) / w as f32,
                ((k / w as usize) as f32 + 0.5) / h as f32,
            );
            let phi = std::f32::consts::TAU * (uv.x - 0.5);
            let theta = std::f32::consts::PI * uv.y;
            let d = Vec3::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                -theta.sin() * phi.cos(),
            );
            *t = self.map.lookup(d);
        }
        img
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::address::cube_dir;

    /// The OpenGL table (module docs) inverted: the direction through `(s, t)` of `face`.
    fn gl_dir(face: Face, s: f32, t: f32) -> Vec3 {
        let (sc, tc) = (2.0 * s - 1.0, 2.0 * t - 1.0);
        match face {
            Face::PosX => Vec3::new(1.0, -tc, -sc),
            Face::NegX => Vec3::new(-1.0, -tc, sc),
            Face::PosY => Vec3::new(sc, 1.0, tc),
            Face::NegY => Vec3::new(sc, -1.0, -tc),
            Face::PosZ => Vec3::new(sc, -tc, 1.0),
            Face::NegZ => Vec3::new(-sc, -tc, -1.0),
        }
        .normalize()
    }

    #[test]
    fn the_maps_faces_are_the_opengl_faces_mirrored_left_right() {
        for face in Face::ALL {
            for (s, t) in [(0.1, 0.2), (0.8, 0.3), (0.5, 0.9), (0.95, 0.05)] {
                let gl = gl_dir(face, s, t);
                let ours = cube_dir(face, Vec2::new(1.0 - s, t));
                assert!(
                    (gl - ours).length() < 1e-6,
                    "{face:?} ({s},{t}): {gl} vs {ours}"
                );
            }
        }
    }

    #[test]
    fn c3x2_orientations_follow_ffmpegs_table() {
        // ffmpeg's cube_to_xyz (module docs) at face pixel (uf, vf) against the OpenGL face
        // texel `place` reads for it.
        type FfmpegDir = fn(f32, f32) -> Vec3;
        let cases: [(Face, Orient, FfmpegDir); 6] = [
            (Face::PosX, Orient::MirrorLeftRight, |u, v| {
                Vec3::new(1.0, -v, u)
            }),
            (Face::NegX, Orient::MirrorLeftRight, |u, v| {
                Vec3::new(-1.0, -v, -u)
            }),
            (Face::PosY, Orient::UpsideDown, |u, v| Vec3::new(u, 1.0, -v)),
            (Face::NegY, Orient::UpsideDown, |u, v| Vec3::new(u, -1.0, v)),
            (Face::NegZ, Orient::MirrorLeftRight, |u, v| {
                Vec3::new(u, -v, -1.0)
            }),
            (Face::PosZ, Orient::MirrorLeftRight, |u, v| {
                Vec3::new(-u, -v, 1.0)
            }),
        ];
        for (face, orient, ff) in cases {
            for (x, y) in [(0.1f32, 0.2f32), (0.7, 0.4), (0.3, 0.9)] {
                let want = ff(2.0 * x - 1.0, 2.0 * y - 1.0).normalize();
                let (s, t) = match orient {
                    Orient::Same => (x, y),
                    Orient::MirrorLeftRight => (1.0 - x, y),
                    Orient::UpsideDown => (x, 1.0 - y),
                };
                let got = gl_dir(face, s, t);
                assert!((want - got).length() < 1e-6, "{face:?}: {want} vs {got}");
            }
        }
    }
}
