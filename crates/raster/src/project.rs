//! World -> eye -> screen for triangle vertices, and near-plane / guard-band clipping.
//!
//! A vertex is carried in homogeneous screen coordinates `(X, Y, W)`: the pixel position is
//! `(X/W, Y/W)`, `W` is the eye-space depth for a perspective camera and 1 for an orthographic
//! one, and `1/W` is affine in screen space, which is what makes perspective-correct
//! interpolation work (every attribute `a` is interpolated as `a/W` and divided by `1/W` per pixel).
//!
//! Vertices that are in front of the near plane and within the guard band (`GUARD` pixels of the
//! image centre) are snapped to fixed point with [`SUB_BITS`] fractional bits; the rest are
//! flagged, and their triangles take the slow path: Sutherland–Hodgman clipping in `(X, Y, W,
//! depth)` against the near plane and the four guard-band planes, then a fan. The guard band keeps
//! fixed-point coordinates below 2^27, so edge functions (products of two coordinate differences)
//! fit easily in i64.

use glam::Vec3;
use texmap_core::camera::Camera;
use texmap_core::lanes::F32x4;

/// Fractional bits of the fixed-point screen coordinates.
pub(crate) const SUB_BITS: u32 = 8;
pub(crate) const SUB: f32 = (1 << SUB_BITS) as f32;
/// Vertices farther than this from the image centre (pixels) take the clipping path.
pub(crate) const GUARD: f32 = (1 << 18) as f32;
/// The clipping planes sit inside the flag threshold so clipped vertices always snap safely.
const CLIP_GUARD: f32 = GUARD * 0.5;

/// Most varyings (per-vertex values interpolated perspective-correctly) one program uses.
pub(crate) const MAX_VAR: usize = 3;
pub(crate) type Var = [f32; MAX_VAR];

/// A projected vertex: fixed-point screen position, `1/W` and `depth/W`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct PVert {
    pub x: i32,
    pub y: i32,
    pub q: f32,
    pub dw: f32,
}

/// `x` value marking a vertex that cannot be snapped; `y` then says why.
pub(crate) const FLAG_X: i32 = i32::MIN;
pub(crate) const FLAG_INVALID: i32 = 0;
pub(crate) const FLAG_CLIP: i32 = 1;

impl PVert {
    #[inline]
    pub fn flagged(&self) -> bool {
        self.x == FLAG_X
    }
}

/// The camera reduced to what the vertex and fragment stages need.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Proj {
    eye: Vec3,
    right: Vec3,
    up: Vec3,
    back: Vec3,
    /// Focal length k in pixels (perspective) or pixels per world unit (orthographic).
    pub k: f32,
    pub cx: f32,
    pub cy: f32,
    pub persp: bool,
    pub near: f32,
    pub far: f32,
}

impl Proj {
    pub fn new(cam: &Camera) -> Proj {
        Proj {
            eye: cam.eye(),
            right: cam.right(),
            up: cam.up(),
            back: -cam.forward(),
            k: cam.scale(),
            cx: cam.width() as f32 * 0.5,
            cy: cam.height() as f32 * 0.5,
            persp: !cam.is_orthographic(),
            near: cam.near(),
            far: cam.far(),
        }
    }

    #[inline]
    pub fn to_eye(self, p: Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.back))
    }

    #[inline]
    pub fn dir_to_eye(&self, d: Vec3) -> Vec3 {
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.back))
    }

    /// Unit vector from the surface toward the viewer for the fragment at screen (x, y), in eye
    /// space (the depth does not matter: the eye ray direction does). The scalar reference of
    /// the four-lane version in `program`.
    #[cfg(test)]
    pub fn view_dir(&self, x: f32, y: f32) -> Vec3 {
        if self.persp {
            Vec3::new((self.cx - x) / self.k, (y - self.cy) / self.k, 1.0).normalize()
        } else {
            Vec3::Z
        }
    }

    /// Project a world point: snapped, or flagged invalid (non-finite) / needing clipping.
    #[inline]
    pub fn project(&self, p: Vec3) -> PVert {
        let e = self.to_eye(p);
        let depth = -e.z;
        if !e.is_finite() {
            return PVert {
                x: FLAG_X,
                y: FLAG_INVALID,
                q: 0.0,
                dw: 0.0,
            };
        }
        // Near-plane test (also catches depth <= 0 for perspective).
        let clip = PVert {
            x: FLAG_X,
            y: FLAG_CLIP,
            q: 0.0,
            dw: 0.0,
        };
        // (`e` is finite here, so `depth` is not NaN.)
        if depth < self.near {
            return clip;
        }
        let (q, dw) = if self.persp {
            (1.0 / depth, 1.0)
        } else {
            (1.0, depth)
        };
        let sx = self.k * e.x * q;
        let sy = -self.k * e.y * q;
        // Guard band: keep fixed-point coordinates small (also rejects infinities).
        if !(sx.abs() <= GUARD && sy.abs() <= GUARD) {
            return clip;
        }
        PVert {
            x: snap((self.cx + sx) * SUB),
            y: snap((self.cy + sy) * SUB),
            q,
            dw,
        }
    }
}

impl Proj {
    /// [`Proj::project`] of four points at once (four lanes, the same operations in the same
    /// order, so the result is bit-identical to four scalar calls).
    #[inline]
    pub fn project4(&self, p: &[Vec3]) -> [PVert; 4] {
        let lane = |f: fn(&Vec3) -> f32| F32x4::new([f(&p[0]), f(&p[1]), f(&p[2]), f(&p[3])]);
        let s = F32x4::splat;
        // World -> eye: d = p − eye, then dot products, (x·x + y·y) + z·z as glam sums them.
        let dx = lane(|v| v.x).sub(s(self.eye.x));
        let dy = lane(|v| v.y).sub(s(self.eye.y));
        let dz = lane(|v| v.z).sub(s(self.eye.z));
        let dot = |a: Vec3| dx.mul(s(a.x)).add(dy.mul(s(a.y))).add(dz.mul(s(a.z)));
        let (ex, ey, ez) = (dot(self.right), dot(self.up), dot(self.back));
        let depth = ez.mul(s(-1.0));
        // Classify: non-finite (x − x is NaN for ±inf and NaN), in front of the near plane.
        let zero = s(0.0);
        let finite = ex
            .sub(ex)
            .eq(zero)
            .and(ey.sub(ey).eq(zero))
            .and(ez.sub(ez).eq(zero));
        let near = depth.lt(s(self.near));
        // Screen position.
        let (q, dw) = if self.persp {
            (s(1.0).div(depth), s(1.0))
        } else {
            (s(1.0), depth)
        };
        let sx = s(self.k).mul(ex).mul(q);
        let sy = s(-self.k).mul(ey).mul(q);
        let sign = s(-0.0);
        let guard = sx
            .and_not(sign)
            .le(s(GUARD))
            .and(sy.and_not(sign).le(s(GUARD)));
        // snap(): v + copysign(0.5, v), truncated.
        let snap4 = |v: F32x4| v.add(s(0.5).or(v.and(sign))).trunc_i32().cast_f32();
        let x = snap4(s(self.cx).add(sx).mul(s(SUB)));
        let y = snap4(s(self.cy).add(sy).mul(s(SUB)));
        // Flagged lanes: x = FLAG_X, y = why, q = dw = 0.
        let bits = |v: i32| F32x4::splat(f32::from_bits(v as u32));
        let all = bits(-1);
        let clip = finite.and(near.or(all.and_not(guard)));
        let flagged = clip.or(all.and_not(finite));
        let x = F32x4::select(flagged, bits(FLAG_X), x);
        let y = F32x4::select(
            flagged,
            F32x4::select(clip, bits(FLAG_CLIP), bits(FLAG_INVALID)),
            y,
        );
        let q = F32x4::select(flagged, zero, q);
        let dw = F32x4::select(flagged, zero, dw);
        F32x4::transpose([x, y, q, dw]).map(|v| {
            let a = v.to_array();
            PVert {
                x: a[0].to_bits() as i32,
                y: a[1].to_bits() as i32,
                q: a[2],
                dw: a[3],
            }
        })
    }

    /// Project `p` into `out` (same length), four points at a time.
    pub fn project_slice(&self, p: &[Vec3], out: &mut [PVert]) {
        debug_assert_eq!(p.len(), out.len());
        let mut pc = p.chunks_exact(4);
        let mut oc = out.chunks_exact_mut(4);
        for (pi, oi) in (&mut pc).zip(&mut oc) {
            oi.copy_from_slice(&self.project4(pi));
        }
        for (pi, oi) in pc.remainder().iter().zip(oc.into_remainder()) {
            *oi = self.project(*pi);
        }
    }
}

/// Round to the nearest integer, halves away from zero (same as `f32::round`, but a truncating
/// conversion instead of a libm call on baseline x86-64, which lacks SSE4.1 `roundss`).
/// Exact below 2^23 (32768 pixels of 256 steps); farther out in the guard band f32 has no
/// fraction and the result may differ from `round` by one step (1/256 px). Snapping stays a
/// function of the vertex alone, so shared edges remain watertight either way.
#[inline(always)]
fn snap(v: f32) -> i32 {
    (v + 0.5f32.copysign(v)) as i32
}

/// A clip-space vertex: `[X, Y, W, depth]` and its varyings.
#[derive(Clone, Copy, Debug)]
struct CVert {
    h: [f32; 4],
    var: Var,
}

/// A triangle produced by clipping, ready for set-up; `tri` is the source triangle.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ClipTri {
    pub v: [PVert; 3],
    pub var: [Var; 3],
    pub tri: u32,
}

const MAX_POLY: usize = 3 + 5;

impl Proj {
    fn clip_vertex(&self, p: Vec3, var: Var) -> CVert {
        let e = self.to_eye(p);
        let depth = -e.z;
        let w = if self.persp { depth } else { 1.0 };
        CVert {
            h: [
                self.cx * w + self.k * e.x,
                self.cy * w - self.k * e.y,
                w,
                depth,
            ],
            var,
        }
    }

    /// Signed distances of a clip vertex to the five planes (inside >= 0).
    #[inline]
    fn plane_dist(&self, plane: usize, h: &[f32; 4]) -> f32 {
        let [x, y, w, depth] = *h;
        match plane {
            // Near plane: depth >= near.
            0 => depth - self.near,
            // Guard band: cx - G <= X/W <= cx + G, same for y (W > 0 once the near plane is done).
            1 => x - (self.cx - CLIP_GUARD) * w,
            2 => (self.cx + CLIP_GUARD) * w - x,
            3 => y - (self.cy - CLIP_GUARD) * w,
            _ => (self.cy + CLIP_GUARD) * w - y,
        }
    }

    /// Clip triangle `tri` (world positions `p`, varyings `var`) and append the fan pieces to
    /// `out`. Returns the number of pieces.
    pub fn clip_triangle(
        &self,
        p: [Vec3; 3],
        var: [Var; 3],
        tri: u32,
        out: &mut Vec<ClipTri>,
    ) -> usize {
        // Build the polygon in clip space.
        let mut poly = [CVert {
            h: [0.0; 4],
            var: [0.0; MAX_VAR],
        }; MAX_POLY];
        let mut n = 3;
        for i in 0..3 {
            poly[i] = self.clip_vertex(p[i], var[i]);
        }
        // Sutherland–Hodgman against each plane in turn.
        for plane in 0..5 {
            let mut next = poly;
            let mut m = 0;
            for i in 0..n {
                let a = poly[i];
                let b = poly[(i + 1) % n];
                let da = self.plane_dist(plane, &a.h);
                let db = self.plane_dist(plane, &b.h);
                if da >= 0.0 && m < MAX_POLY {
                    next[m] = a;
                    m += 1;
                }
                if (da >= 0.0) != (db >= 0.0) {
                    // The edge crosses the plane: emit the intersection.
                    let t = da / (da - db);
                    let mut c = a;
                    for k in 0..4 {
                        c.h[k] = a.h[k] + (b.h[k] - a.h[k]) * t;
                    }
                    for k in 0..MAX_VAR {
                        c.var[k] = a.var[k] + (b.var[k] - a.var[k]) * t;
                    }
                    if m < MAX_POLY {
                        next[m] = c;
                        m += 1;
                    }
                }
            }
            poly = next;
            n = m;
            if n < 3 {
                return 0;
            }
        }
        // Project the clipped polygon and emit a fan.
        let mut pv = [PVert::default(); MAX_POLY];
        for i in 0..n {
            let [x, y, w, depth] = poly[i].h;
            let q = 1.0 / w;
            let sx = x * q;
            let sy = y * q;
            if !(q.is_finite() && sx.is_finite() && sy.is_finite()) {
                return 0;
            }
            pv[i] = PVert {
                x: snap(sx * SUB),
                y: snap(sy * SUB),
                q,
                dw: depth * q,
            };
        }
        for i in 1..n - 1 {
            out.push(ClipTri {
                v: [pv[0], pv[i], pv[i + 1]],
                var: [poly[0].var, poly[i].var, poly[i + 1].var],
                tri,
            });
        }
        n - 2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn project4_is_bit_identical_to_scalar_project() {
        let cams = [
            Camera::perspective_look_at(
                Vec3::new(0.3, 1.0, 5.0),
                Vec3::ZERO,
                Vec3::Y,
                70.0,
                640,
                480,
            )
            .unwrap()
            .with_clip(0.5, 50.0)
            .unwrap(),
            Camera::orthographic_look_at(
                Vec3::new(0.0, 0.0, 9.0),
                Vec3::ZERO,
                Vec3::Y,
                8.0,
                33,
                17,
            )
            .unwrap(),
        ];
        let mut s = 3u64;
        let mut r = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        // Random points near and far (inside, beside, behind the camera, across the near plane
        // and the guard band) plus special values.
        let mut pts = Vec::new();
        for i in 0..4000 {
            let scale = [1.0, 10.0, 1e3, 1e6][i % 4];
            pts.push(Vec3::new(r(), r(), r() * 3.0) * scale);
        }
        let specials = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -0.0,
            0.0,
            4.5,
            1e30,
        ];
        for &a in &specials {
            for &b in &specials {
                pts.push(Vec3::new(a, b, 0.0));
                pts.push(Vec3::new(0.1, a, b));
                pts.push(Vec3::new(b, 0.2, a));
            }
        }
        pts.push(Vec3::new(0.0, 0.0, 4.5)); // on the near plane of the first camera
        for cam in &cams {
            let proj = Proj::new(cam);
            let mut out = vec![PVert::default(); pts.len()];
            proj.project_slice(&pts, &mut out);
            let mut kinds = [0usize; 3];
            for (p, got) in pts.iter().zip(&out) {
                let want = proj.project(*p);
                let key = |v: &PVert| (v.x, v.y, v.q.to_bits(), v.dw.to_bits());
                assert_eq!(key(got), key(&want), "{p}: expected {want:?} got {got:?}");
                kinds[if !want.flagged() {
                    0
                } else {
                    1 + want.y as usize
                }] += 1;
            }
            // Every outcome is exercised: snapped, invalid, clipped.
            assert!(kinds.iter().all(|&k| k > 10), "{kinds:?}");
        }
    }
}
