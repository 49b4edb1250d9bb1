//! Seed 004 (Kitayama, Fujishiro, Hirano): disc billboards textured with a window cut from a
//! template texture.
//!
//! - **Template.** Concentric shading, brightest at the centre: the texel at distance `ρ·r_w`
//!   from the template centre (`r_w = 1/4` texture units is the window radius, `ρ ∈ [0, 2]`) holds
//!   the lit sphere at the point whose normal makes angle `asin ρ` with the highlight direction
//!   (the unit sphere seen head-on with the light at the eye) for `ρ ≤ 1`, and ambient only beyond
//!   (the unlit side). The template stores a shading *index* (`u8`, `ρ` quantised to 256 steps);
//!   a 256-entry palette per kind turns it into colour. With
//!   [`TemplateColoring::HueRecolor`] the palette is Seed 004's "one grey template recoloured by
//!   HSV hue": the grey template's value with the kind's hue and saturation (and its value as a
//!   scale); with [`TemplateColoring::PerKind`] it is "one template per colour": each kind's
//!   material shaded by [`Lighting::shade`] (ambient + the first light). Index + palette stores the
//!   same pixels as RGB templates would, in a quarter of the memory.
//! - **Pyramid.** Levels of side `template_size, /2, /4, … ≥ 4`, each evaluated directly at its
//!   texel centres. A sphere of screen radius `h` uses the coarsest level whose window (diameter
//!   `size/2` texels) still has at least one texel per pixel, i.e. `size ≥ 4h`.
//! - **Window** (Seed 004): centred at `x_tex = 0.5 − r_w·sin(θ/2)`, `y_tex = 0.5 + r_w·sin(φ/2)`,
//!   θ (φ) the signed angle from `v` (centre → eye) to `a` (toward the first light) after
//!   projecting both on the eye-space xz (yz) plane, positive toward +x (+y). The `+` in `y_tex` is
//!   the paper's `−` with our texture rows running downward. So the template's bright centre
//!   appears on the side of the light, at the half angle (where the Blinn highlight sits).
//! - **Depth.** [`TemplateDepth::Billboard`]: the billboard plane through the centre (`z0`), as the
//!   paper; [`TemplateDepth::DepthImage`]: Seed 002's depth image, `z = z0 + D·R`.
//! - **Projection** as Seed 002 ([`crate::lut::square`]): centre projected, radius `k·R/z0`.
//! - **Near plane** as Seed 002 (the `lut` module): a fragment nearer than the near plane is
//!   replaced by the sphere's far side (`z0 + R·sqrt(1 − ρ²)` with billboard depth, `z0 − D·R`
//!   with the depth image) when that is in range, so spheres cut by the near plane, including
//!   those whose centre is behind it, are drawn; only spheres wholly nearer are culled.
//!
//! Record layout ([`Proj::f`]): `[sx, sy, 1/h, z0, R]`; `aux` packs the window offsets
//! `sin(θ/2)`, `sin(φ/2)` as two `i8` in units of 1/127.

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use glam::Vec3;
use texmap_core::color::{hsv_to_rgb, linear_to_srgb8, rgb_to_hsv};
use texmap_core::shade::{Lighting, Material};

use crate::lut::{depth_image, square};
use crate::options::{TemplateColoring, TemplateDepth};
use crate::pipeline::{Kernel, Proj, Projected, TILE, TileBuf, TileRect, View, clip};

/// Window radius in template texture units (the window centre moves by up to this much, so the
/// window always stays inside `[0, 1]²`).
const R_W: f32 = 0.25;
/// Side of the depth image used by [`TemplateDepth::DepthImage`].
const DEPTH_SIZE: u32 = 256;

/// Seed 004's template pyramid and per-kind palettes.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TemplateTables {
    pub size: u32,
    pub coloring: TemplateColoring,
    pub lighting: Lighting,
    pub materials: Vec<Material>,
    /// Level `l` has side `size >> l`; `offsets[l]` is its start in `texels`.
    pub levels: u32,
    pub offsets: Vec<usize>,
    pub texels: Vec<u8>,
    /// 256 sRGB8 colours per kind.
    pub palette: Vec<[u8; 4]>,
    pub depth: Vec<f32>,
}

/// Linear colour of the template at shading index `i` for material `m`: the unit sphere lit
/// head-on (light at the eye) at normal angle `asin ρ`, `ρ = 2i/255`; ambient only for `ρ > 1`.
fn template_shade(lighting: &Lighting, m: &Material, i: usize) -> Vec3 {
    let rho = 2.0 * i as f32 / 255.0;
    let ambient_only = Lighting::new(lighting.ambient, &[]).expect("ambient is finite");
    if rho > 1.0 {
        return ambient_only.shade(m, Vec3::Z, Vec3::Z);
    }
    let key = lighting
        .lights()
        .first()
        .map(|l| l.color)
        .unwrap_or(Vec3::ZERO);
    let head_on = Lighting::new(lighting.ambient, &[(Vec3::Z, key)]).expect("valid light");
    let n = Vec3::new(rho, 0.0, (1.0 - rho * rho).max(0.0).sqrt());
    head_on.shade(m, n, Vec3::Z)
}

impl TemplateTables {
    pub fn build(
        size: u32,
        coloring: TemplateColoring,
        lighting: &Lighting,
        materials: &[Material],
    ) -> TemplateTables {
        // The pyramid: each level evaluated at its own texel centres.
        let mut offsets = Vec::new();
        let mut texels = Vec::new();
        let mut n = size;
        while n >= 4 {
            offsets.push(texels.len());
            for j in 0..n {
                for i in 0..n {
                    let x = (i as f32 + 0.5) / n as f32 - 0.5;
                    let y = (j as f32 + 0.5) / n as f32 - 0.5;
                    let rho = ((x * x + y * y).sqrt() / R_W).min(2.0);
                    texels.push((rho * 127.5 + 0.5) as u8);
                }
            }
            n /= 2;
        }
        // The palettes.
        let grey = Material {
            base_color: Vec3::splat(0.8),
            specular: 0.35,
            shininess: 40.0,
        };
        let mut palette = Vec::with_capacity(256 * materials.len());
        for m in materials {
            let hsv = rgb_to_hsv(m.base_color);
            for i in 0..256 {
                let c = match coloring {
                    TemplateColoring::PerKind => template_shade(lighting, m, i),
                    TemplateColoring::HueRecolor => {
                        // One grey template: replace hue and saturation, scale the value.
                        let g = template_shade(lighting, &grey, i).x;
                        hsv_to_rgb(Vec3::new(hsv.x, hsv.y, g * hsv.z / grey.base_color.x))
                    }
                };
                palette.push(linear_to_srgb8(c, 255));
            }
        }
        TemplateTables {
            size,
            coloring,
            lighting: *lighting,
            materials: materials.to_vec(),
            levels: offsets.len() as u32,
            offsets,
            texels,
            palette,
            depth: depth_image(DEPTH_SIZE),
        }
    }

    pub fn matches(
        &self,
        size: u32,
        coloring: TemplateColoring,
        lighting: &Lighting,
        materials: &[Material],
    ) -> bool {
        self.size == size
            && self.coloring == coloring
            && self.lighting == *lighting
            && self.materials == materials
    }
}

/// `sin(θ/2)` for the signed angle θ from 2-D direction `v` to unit 2-D direction `a`
/// (components `(x, z)`), positive when `a` lies toward +x of `v`.
#[inline]
fn sin_half_angle(vx: f32, vz: f32, ax: f32, az: f32) -> f32 {
    let len = (vx * vx + vz * vz).sqrt();
    if !(len > 0.0) {
        return 0.0;
    }
    let cos = ((vx * ax + vz * az) / len).clamp(-1.0, 1.0);
    let cross = vz * ax - vx * az;
    // sin(θ/2) = ±sqrt((1 − cos θ)/2).
    ((1.0 - cos) * 0.5).sqrt().copysign(cross)
}

/// Per-frame constants of the window placement: the first light projected on xz and yz.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LightDirs {
    ax: (f32, f32),
    ay: (f32, f32),
}

impl LightDirs {
    pub fn new(lighting: &Lighting) -> LightDirs {
        let a = lighting
            .lights()
            .first()
            .map(|l| l.to_light)
            .unwrap_or(Vec3::Z);
        let unit = |x: f32, z: f32| {
            let l = (x * x + z * z).sqrt();
            if l > 0.0 { (x / l, z / l) } else { (0.0, 1.0) }
        };
        LightDirs {
            ax: unit(a.x, a.z),
            ay: unit(a.y, a.z),
        }
    }
}

/// Project one eye-space sphere for the template kernel.
#[inline]
pub(crate) fn project(view: &View, dirs: &LightDirs, c: Vec3, r: f32, kind: u16) -> Projected {
    let Some((sx, sy, h, z0)) = square(view, c, r) else {
        return Projected::Culled;
    };
    let (x0, x1) = View::pixel_range(sx - h, sx + h, view.width);
    let (y0, y1) = View::pixel_range(sy - h, sy + h, view.height);
    if x0 >= x1 || y0 >= y1 || !(h > 0.0) {
        return Projected::Culled;
    }
    // Seed 004: θ, φ between v (centre → eye) and a (toward the light) on xz and yz.
    let v = if view.ortho { Vec3::Z } else { -c };
    let st = sin_half_angle(v.x, v.z, dirs.ax.0, dirs.ax.1);
    let sp = sin_half_angle(v.y, v.z, dirs.ay.0, dirs.ay.1);
    let qt = (st * 127.0).round() as i8 as u8 as u16;
    let qp = (sp * 127.0).round() as i8 as u8 as u16;
    Projected::Draw(Proj {
        f: [sx, sy, 1.0 / h, z0, r],
        bbox: [x0, y0, x1, y1],
        kind,
        aux: qt | (qp << 8),
    })
}

/// The Seed 004 kernel.
pub(crate) struct TemplateKernel<'a> {
    pub view: View,
    pub tables: &'a TemplateTables,
    pub depth_mode: TemplateDepth,
}

impl Kernel for TemplateKernel<'_> {
    #[inline(never)]
    fn raster(&self, recs: &[Proj], tile: TileRect, buf: &mut TileBuf) {
        let near = self.view.near;
        let dn = DEPTH_SIZE as f32;
        for (idx, p) in recs.iter().enumerate() {
            let Some((x0, y0, x1, y1)) = clip(p, tile) else {
                continue;
            };
            let [sx, sy, inv_h, z0, r] = p.f;
            for j in y0..y1 {
                let w = ((tile.y0 + j) as f32 + 0.5 - sy) * inv_h;
                let row = (j * TILE) as usize;
                for i in x0..x1 {
                    let u = ((tile.x0 + i) as f32 + 0.5 - sx) * inv_h;
                    // The disc billboard.
                    if !(u * u + w * w <= 1.0) {
                        continue;
                    }
                    let z = match self.depth_mode {
                        TemplateDepth::Billboard => z0,
                        TemplateDepth::DepthImage => {
                            let ti = (((u + 1.0) * 0.5 * dn) as u32).min(DEPTH_SIZE - 1);
                            let tj = (((w + 1.0) * 0.5 * dn) as u32).min(DEPTH_SIZE - 1);
                            // Seed 002's depth image (finite inside the disc tested above).
                            let dd = self.tables.depth[(tj * DEPTH_SIZE + ti) as usize];
                            let dd = if dd.is_finite() { dd } else { 0.0 };
                            z0 + dd * r
                        }
                    };
                    // Clipped by the near plane: the far side of the sphere instead.
                    let z = if z < near {
                        z0 + r * (1.0 - (u * u + w * w)).max(0.0).sqrt()
                    } else {
                        z
                    };
                    if !(z >= near) {
                        continue;
                    }
                    let b = row + i as usize;
                    if z < buf.depth[b] {
                        buf.depth[b] = z;
                        buf.win[b] = idx as u32;
                    }
                }
            }
        }
    }

    fn resolve(&self, rec: &Proj, x: u32, y: u32, _depth: f32, _flags: u32) -> [u8; 4] {
        let t = self.tables;
        let [sx, sy, inv_h, _, _] = rec.f;
        // Pyramid level: the coarsest with size ≥ 4h (one texel per pixel or more).
        let want = 4.0 / inv_h;
        let mut level = 0u32;
        while level + 1 < t.levels && ((t.size >> (level + 1)) as f32) >= want {
            level += 1;
        }
        let n = t.size >> level;
        let u = (x as f32 + 0.5 - sx) * inv_h;
        let w = (y as f32 + 0.5 - sy) * inv_h;
        // Seed 004 window centre.
        let st = (rec.aux & 0xff) as u8 as i8 as f32 / 127.0;
        let sp = (rec.aux >> 8) as u8 as i8 as f32 / 127.0;
        let xt = 0.5 - R_W * st + R_W * u;
        let yt = 0.5 + R_W * sp + R_W * w;
        let i = ((xt * n as f32).max(0.0) as u32).min(n - 1);
        let j = ((yt * n as f32).max(0.0) as u32).min(n - 1);
        let idx = t.texels[t.offsets[level as usize] + (j * n + i) as usize];
        t.palette[rec.kind as usize * 256 + idx as usize]
    }
}
