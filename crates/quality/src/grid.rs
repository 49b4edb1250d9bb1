//! The crate's own ray caster: the scene's drawable spheres and bonds (capped cylinders) in a
//! uniform grid, walked cell by cell (Amanatides and Woo's 3D DDA).
//!
//! Three queries share it: the **closest hit** of a camera ray (anti-aliasing samples and the
//! recovery of the primitive behind an impostor pixel), and the **any hit** of a short ambient
//! occlusion ray or a shadow ray toward the key light.
//!
//! - A primitive is listed in every cell its axis-aligned box overlaps. The cell side is the
//!   cube root of the scene box volume per primitive, widened until the grid holds at most
//!   `8·n + 4096` cells, so a cell lists a handful of primitives whatever the density.
//! - Spheres use the cancellation-free discriminant `r² − |f − (f·d) d|²` (`f = o − c`, `d`
//!   unit), bonds the capped-cylinder form of the impostor crate's bond pass: the infinite
//!   cylinder interval from `g·(d × u)` and the slab between the cap planes; entering the solid
//!   is the `max` of the two lower ends. A hit is the first root in `[tmin, tmax]`, so a ray
//!   starting inside a solid (a camera cut by the near plane) takes the exit.
//! - Bonds follow `SphereScene`'s rules (both atoms drawable, distinct centres, a finite
//!   positive bond radius) and are half-bond coloured: the half nearer atom `i` has its material.
//!
//! All arithmetic is plain `f32` IEEE operations (no fused multiply-add), so every query gives
//! the same bits on every thread.

// `!(a <= b)` comparisons are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use glam::{IVec3, Vec3};
use texmap_impostor::SphereScene;

/// A primitive: a sphere or a bond's capped cylinder.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Prim {
    Sphere {
        c: Vec3,
        r: f32,
        mat: u16,
    },
    Bond {
        /// Start (atom i's centre), unit axis toward atom j, length, radius.
        a: Vec3,
        u: Vec3,
        len: f32,
        r: f32,
        mat_a: u16,
        mat_b: u16,
    },
}

impl Prim {
    fn bounds(&self) -> (Vec3, Vec3) {
        match *self {
            Prim::Sphere { c, r, .. } => (c - Vec3::splat(r), c + Vec3::splat(r)),
            Prim::Bond { a, u, len, r, .. } => {
                let b = a + u * len;
                (a.min(b) - Vec3::splat(r), a.max(b) + Vec3::splat(r))
            }
        }
    }

    /// A sphere enclosing the primitive: centre and radius.
    pub(crate) fn bounding_sphere(&self) -> (Vec3, f32) {
        match *self {
            Prim::Sphere { c, r, .. } => (c, r),
            Prim::Bond { a, u, len, r, .. } => (a + u * (0.5 * len), 0.5 * len + r),
        }
    }

    /// The radius (sphere or bond), used as the depth gap of outlines.
    pub(crate) fn radius(&self) -> f32 {
        match *self {
            Prim::Sphere { r, .. } | Prim::Bond { r, .. } => r,
        }
    }

    /// The first ray parameter in `[tmin, tmax]` where the ray `o + t·d` (unit `d`) meets the
    /// surface, with the flag "on a flat cap" for bonds.
    #[inline]
    pub(crate) fn intersect(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<(f32, bool)> {
        let pick = |t0: f32, t1: f32| {
            if t0 >= tmin && t0 <= tmax {
                Some(t0)
            } else if t1 >= tmin && t1 <= tmax {
                Some(t1)
            } else {
                None
            }
        };
        match *self {
            Prim::Sphere { c, r, .. } => {
                let f = o - c;
                let b = f.dot(d);
                let q = f - d * b;
                let disc = r * r - q.dot(q);
                if !(disc >= 0.0) {
                    return None;
                }
                let s = disc.sqrt();
                pick(-b - s, -b + s).map(|t| (t, false))
            }
            Prim::Bond { a, u, len, r, .. } => {
                let g = o - a;
                let dxu = d.cross(u);
                let big_a = dxu.dot(dxu);
                let gu = g.dot(u);
                let du = d.dot(u);
                // Infinite cylinder.
                let (c0, c1) = if big_a > 1e-12 {
                    let m = g.dot(dxu);
                    let disc = r * r * big_a - m * m;
                    if !(disc >= 0.0) {
                        return None;
                    }
                    let gp = g - u * gu;
                    let dp = d - u * du;
                    let s = -gp.dot(dp) / big_a;
                    let half = disc.sqrt() / big_a;
                    (s - half, s + half)
                } else {
                    let gp = g - u * gu;
                    if !(gp.dot(gp) <= r * r) {
                        return None;
                    }
                    (f32::NEG_INFINITY, f32::INFINITY)
                };
                // Slab between the cap planes.
                let (s0, s1) = if du.abs() > 1e-12 {
                    let ta = -gu / du;
                    let tb = (len - gu) / du;
                    (ta.min(tb), ta.max(tb))
                } else if gu >= 0.0 && gu <= len {
                    (f32::NEG_INFINITY, f32::INFINITY)
                } else {
                    return None;
                };
                let t0 = c0.max(s0);
                let t1 = c1.min(s1);
                if !(t0 <= t1) {
                    return None;
                }
                if t0 >= tmin && t0 <= tmax {
                    Some((t0, s0 > c0))
                } else if t1 >= tmin && t1 <= tmax {
                    Some((t1, s1 < c1))
                } else {
                    None
                }
            }
        }
    }

    /// Outward unit normal and material at surface point `p` (`cap` from [`Prim::intersect`]).
    #[inline]
    fn surface(&self, p: Vec3, cap: bool) -> (Vec3, u16) {
        match *self {
            Prim::Sphere { c, r, mat } => ((p - c) / r, mat),
            Prim::Bond {
                a,
                u,
                len,
                mat_a,
                mat_b,
                ..
            } => {
                let h = (p - a).dot(u);
                let mat = if h < 0.5 * len { mat_a } else { mat_b };
                let n = if cap {
                    if h < 0.5 * len { -u } else { u }
                } else {
                    (p - a - u * h).normalize_or(u)
                };
                (n, mat)
            }
        }
    }
}

/// A closest hit.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hit {
    pub t: f32,
    pub prim: u32,
    pub point: Vec3,
    /// Outward unit normal (not yet turned toward the viewer).
    pub normal: Vec3,
    pub material: u16,
}

/// The primitives of a scene in a uniform grid.
#[derive(Debug)]
pub(crate) struct Grid {
    pub prims: Vec<Prim>,
    lo: Vec3,
    hi: Vec3,
    cell: f32,
    inv_cell: f32,
    dims: IVec3,
    /// Cell `k` lists `items[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
}

/// Whether bond `[i, j]` of `scene`, of radius `r`, is drawn (the impostor crate's rules).
fn bond_ok(scene: &SphereScene, i: usize, j: usize, r: f32) -> bool {
    r.is_finite()
        && r > 0.0
        && i < scene.len()
        && j < scene.len()
        && scene.is_valid(i)
        && scene.is_valid(j)
        && scene.centers[i] != scene.centers[j]
}

impl Grid {
    /// The drawable spheres of `scene` and, with `bonds`, its drawable bonds.
    pub fn build(scene: &SphereScene, bonds: bool) -> Grid {
        let mut prims = Vec::with_capacity(scene.len() + scene.bonds.len());
        for i in 0..scene.len() {
            if scene.is_valid(i) {
                prims.push(Prim::Sphere {
                    c: scene.centers[i],
                    r: scene.radii[i],
                    mat: scene.kinds[i],
                });
            }
        }
        if bonds {
            for (k, &[i, j]) in scene.bonds.iter().enumerate() {
                let (i, j) = (i as usize, j as usize);
                let r = scene.bond_radius_of(k);
                if bond_ok(scene, i, j, r) {
                    let (a, b) = (scene.centers[i], scene.centers[j]);
                    let len = (b - a).length();
                    if !(len.is_finite() && len > 0.0) {
                        continue;
                    }
                    prims.push(Prim::Bond {
                        a,
                        u: (b - a) / len,
                        len,
                        r,
                        mat_a: scene.kinds[i],
                        mat_b: scene.kinds[j],
                    });
                }
            }
        }
        Grid::from_prims(prims)
    }

    fn from_prims(prims: Vec<Prim>) -> Grid {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        let mut max_extent = 0f32;
        for p in &prims {
            let (a, b) = p.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
            max_extent = max_extent.max((b - a).min_element());
        }
        if prims.is_empty() {
            lo = Vec3::ZERO;
            hi = Vec3::ONE;
            max_extent = 1.0;
        }
        let ext = (hi - lo).max(Vec3::splat(1e-6));
        let n = prims.len().max(1) as f64;
        let volume = ext.x as f64 * ext.y as f64 * ext.z as f64;
        let mut cell = ((volume / n).cbrt() as f32)
            .max(max_extent * 1e-3)
            .max(1e-6);
        let max_cells = 32.0 * n + 4096.0;
        let count = |cell: f32| {
            let d = (ext / cell).ceil().max(Vec3::ONE);
            (d, d.x as f64 * d.y as f64 * d.z as f64)
        };
        let mut dims = count(cell);
        while dims.1 > max_cells {
            cell *= 1.25;
            dims = count(cell);
        }
        let dims = dims.0.as_ivec3();
        let inv_cell = 1.0 / cell;
        let ncells = (dims.x * dims.y * dims.z) as usize;
        let cell_range = |p: &Prim| {
            let (a, b) = p.bounds();
            let clamp = |v: Vec3| {
                ((v - lo) * inv_cell)
                    .max(Vec3::ZERO)
                    .as_ivec3()
                    .min(dims - 1)
            };
            (clamp(a), clamp(b))
        };
        let mut start = vec![0u32; ncells + 1];
        for p in &prims {
            let (a, b) = cell_range(p);
            for z in a.z..=b.z {
                for y in a.y..=b.y {
                    for x in a.x..=b.x {
                        start[((z * dims.y + y) * dims.x + x) as usize + 1] += 1;
                    }
                }
            }
        }
        for k in 0..ncells {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; start[ncells] as usize];
        for (id, p) in prims.iter().enumerate() {
            let (a, b) = cell_range(p);
            for z in a.z..=b.z {
                for y in a.y..=b.y {
                    for x in a.x..=b.x {
                        let k = ((z * dims.y + y) * dims.x + x) as usize;
                        items[fill[k] as usize] = id as u32;
                        fill[k] += 1;
                    }
                }
            }
        }
        Grid {
            prims,
            lo,
            hi,
            cell,
            inv_cell,
            dims,
            start,
            items,
        }
    }

    #[inline]
    pub(crate) fn cell_items(&self, c: IVec3) -> &[u32] {
        let k = ((c.z * self.dims.y + c.y) * self.dims.x + c.x) as usize;
        &self.items[self.start[k] as usize..self.start[k + 1] as usize]
    }

    /// The cell holding point `p` (clamped into the grid).
    #[inline]
    pub(crate) fn cell_of(&self, p: Vec3) -> IVec3 {
        // Truncation after `max(0)` is `floor` (and maps NaN to 0).
        ((p - self.lo) * self.inv_cell)
            .max(Vec3::ZERO)
            .as_ivec3()
            .min(self.dims - 1)
    }

    /// Walk the cells the ray `o + t·d`, `t ∈ [tmin, tmax]`, passes, in order; `visit(cell,
    /// t_cell_exit)` returns true to stop.
    #[inline]
    fn walk(
        &self,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
        mut visit: impl FnMut(&[u32], f32) -> bool,
    ) {
        if !(o.is_finite() && d.is_finite()) || d == Vec3::ZERO {
            return;
        }
        // Clip to the grid box.
        let mut t0 = tmin;
        let mut t1 = tmax;
        for k in 0..3 {
            if d[k] == 0.0 {
                if o[k] < self.lo[k] || o[k] > self.hi[k] {
                    return;
                }
            } else {
                let inv = 1.0 / d[k];
                let a = (self.lo[k] - o[k]) * inv;
                let b = (self.hi[k] - o[k]) * inv;
                t0 = t0.max(a.min(b));
                t1 = t1.min(a.max(b));
            }
        }
        if !(t0 <= t1) {
            return;
        }
        let mut c = self.cell_of(o + d * t0);
        let mut step = IVec3::ZERO;
        let mut next = Vec3::splat(f32::INFINITY);
        let mut delta = Vec3::splat(f32::INFINITY);
        for k in 0..3 {
            if d[k] > 0.0 {
                step[k] = 1;
                let edge = self.lo[k] + (c[k] + 1) as f32 * self.cell;
                next[k] = (edge - o[k]) / d[k];
                delta[k] = self.cell / d[k];
            } else if d[k] < 0.0 {
                step[k] = -1;
                let edge = self.lo[k] + c[k] as f32 * self.cell;
                next[k] = (edge - o[k]) / d[k];
                delta[k] = -self.cell / d[k];
            }
        }
        loop {
            let exit = next.min_element();
            if visit(self.cell_items(c), exit.min(t1)) {
                return;
            }
            if exit > t1 {
                return;
            }
            let k = if next.x <= next.y && next.x <= next.z {
                0
            } else if next.y <= next.z {
                1
            } else {
                2
            };
            c[k] += step[k];
            if c[k] < 0 || c[k] >= self.dims[k] {
                return;
            }
            next[k] += delta[k];
        }
    }

    /// The closest hit of the ray in `[tmin, tmax]`.
    pub fn closest(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        let mut best: Option<(f32, u32, bool)> = None;
        self.walk(o, d, tmin, tmax, |items, cell_exit| {
            for &id in items {
                let limit = best.map_or(tmax, |b| b.0);
                if let Some((t, cap)) = self.prims[id as usize].intersect(o, d, tmin, limit) {
                    // Strict, then the lower id: the same winner in any cell order.
                    let better = match best {
                        None => true,
                        Some((bt, bid, _)) => t < bt || (t == bt && id < bid),
                    };
                    if better {
                        best = Some((t, id, cap));
                    }
                }
            }
            best.is_some_and(|b| b.0 <= cell_exit)
        });
        best.map(|(t, id, cap)| self.hit(o, d, t, id, cap))
    }

    /// The closest hit among the primitives listed in the cell holding point `p` only (the
    /// recovery of an impostor pixel whose surface point is known to lie near `p`).
    pub fn closest_near(&self, p: Vec3, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        let mut best: Option<(f32, u32, bool)> = None;
        for &id in self.cell_items(self.cell_of(p)) {
            let limit = best.map_or(tmax, |b| b.0);
            if let Some((t, cap)) = self.prims[id as usize].intersect(o, d, tmin, limit) {
                let better = match best {
                    None => true,
                    Some((bt, bid, _)) => t < bt || (t == bt && id < bid),
                };
                if better {
                    best = Some((t, id, cap));
                }
            }
        }
        best.map(|(t, id, cap)| self.hit(o, d, t, id, cap))
    }

    /// The hit of the ray on primitive `id` (`prim`) alone.
    #[inline]
    pub fn hit_on(
        &self,
        id: u32,
        prim: &Prim,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> Option<Hit> {
        prim.intersect(o, d, tmin, tmax)
            .map(|(t, cap)| self.hit(o, d, t, id, cap))
    }

    #[inline]
    fn hit(&self, o: Vec3, d: Vec3, t: f32, id: u32, cap: bool) -> Hit {
        let point = o + d * t;
        let (normal, material) = self.prims[id as usize].surface(point, cap);
        Hit {
            t,
            prim: id,
            point,
            normal,
            material,
        }
    }

    /// Whether anything meets the ray in `[tmin, tmax]`.
    pub fn occluded(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> bool {
        let mut hit = false;
        self.walk(o, d, tmin, tmax, |items, _| {
            for &id in items {
                if self.prims[id as usize]
                    .intersect(o, d, tmin, tmax)
                    .is_some()
                {
                    hit = true;
                    return true;
                }
            }
            false
        });
        hit
    }
}

/// Every primitive in a 2D grid on the plane perpendicular to one direction (the key light):
/// a shadow ray toward the light from `p` can only meet the primitives listed in the cell of
/// `p`'s projection, so it tests one short list instead of walking the 3D grid.
#[derive(Debug)]
pub(crate) struct LightGrid {
    dir: Vec3,
    e1: Vec3,
    e2: Vec3,
    lo: [f32; 2],
    inv_cell: f32,
    dims: [i32; 2],
    start: Vec<u32>,
    /// `(primitive id, largest extent along dir)`.
    items: Vec<(u32, f32)>,
}

impl LightGrid {
    /// The primitives of `grid` seen along unit `dir`; `basis` completes `dir` to an
    /// orthonormal frame. `spread` is the tangent of the widest angle a shadow ray may make
    /// with `dir` (0 for hard shadows; a disc light's angular radius for soft ones): each
    /// primitive's square is widened by how far such a ray drifts sideways between the lowest
    /// point of the scene along `dir` and the primitive's far side, so the cell of a ray's origin
    /// still lists every primitive the ray can meet.
    pub fn build(grid: &Grid, dir: Vec3, basis: (Vec3, Vec3), spread: f32) -> LightGrid {
        let (e1, e2) = basis;
        let lowest = grid.prims.iter().fold(f32::INFINITY, |m, p| {
            let (c, r) = p.bounding_sphere();
            m.min(c.dot(dir) - r)
        });
        // Per primitive: its projected square and its reach along the light.
        let boxes: Vec<([f32; 4], f32)> = grid
            .prims
            .iter()
            .map(|p| {
                let (c, r) = p.bounding_sphere();
                let (x, y) = (c.dot(e1), c.dot(e2));
                let reach = c.dot(dir) + r;
                // Hard shadows keep the exact square (no arithmetic on `r`).
                let r = if spread > 0.0 {
                    r + spread * (reach - lowest)
                } else {
                    r
                };
                ([x - r, y - r, x + r, y + r], reach)
            })
            .collect();
        let (mut lo, mut hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
        for (b, _) in &boxes {
            lo = [lo[0].min(b[0]), lo[1].min(b[1])];
            hi = [hi[0].max(b[2]), hi[1].max(b[3])];
        }
        if boxes.is_empty() {
            lo = [0.0; 2];
            hi = [1.0; 2];
        }
        let ext = [(hi[0] - lo[0]).max(1e-6), (hi[1] - lo[1]).max(1e-6)];
        let n = grid.prims.len().max(1) as f64;
        // About one primitive footprint per cell, at most 4n + 4096 cells.
        let mut cell = (0.5 * grid.cell).max(ext[0].max(ext[1]) * 1e-4);
        let max_cells = 4.0 * n + 4096.0;
        let count = |cell: f32| {
            let d = [
                (ext[0] / cell).ceil().max(1.0),
                (ext[1] / cell).ceil().max(1.0),
            ];
            (d, d[0] as f64 * d[1] as f64)
        };
        let mut dims = count(cell);
        while dims.1 > max_cells {
            cell *= 1.25;
            dims = count(cell);
        }
        let dims = [dims.0[0] as i32, dims.0[1] as i32];
        let inv_cell = 1.0 / cell;
        let range = |b: &[f32; 4]| {
            let f = |v: f32, k: usize| (((v - lo[k]) * inv_cell).max(0.0) as i32).min(dims[k] - 1);
            (f(b[0], 0), f(b[1], 1), f(b[2], 0), f(b[3], 1))
        };
        let ncells = (dims[0] * dims[1]) as usize;
        let mut start = vec![0u32; ncells + 1];
        for (b, _) in &boxes {
            let (x0, y0, x1, y1) = range(b);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    start[(y * dims[0] + x) as usize + 1] += 1;
                }
            }
        }
        for k in 0..ncells {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut items = vec![(0u32, 0f32); start[ncells] as usize];
        for (id, (b, reach)) in boxes.iter().enumerate() {
            let (x0, y0, x1, y1) = range(b);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let k = (y * dims[0] + x) as usize;
                    items[fill[k] as usize] = (id as u32, *reach);
                    fill[k] += 1;
                }
            }
        }
        LightGrid {
            dir,
            e1,
            e2,
            lo,
            inv_cell,
            dims,
            start,
            items,
        }
    }

    /// The primitives listed in the cell of `p`'s projection (`(id, reach along the light)`),
    /// and `p`'s own coordinate along the light; a primitive whose reach is not beyond it cannot
    /// meet a ray leaving `p` toward the light.
    #[inline]
    fn cell_of(&self, p: Vec3) -> (&[(u32, f32)], f32) {
        let (x, y) = (p.dot(self.e1), p.dot(self.e2));
        let cx = (x - self.lo[0]) * self.inv_cell;
        let cy = (y - self.lo[1]) * self.inv_cell;
        if !(cx >= 0.0 && cy >= 0.0) {
            return (&[], 0.0);
        }
        let (cx, cy) = (cx as i32, cy as i32);
        if cx >= self.dims[0] || cy >= self.dims[1] {
            return (&[], 0.0);
        }
        let k = (cy * self.dims[0] + cx) as usize;
        (
            &self.items[self.start[k] as usize..self.start[k + 1] as usize],
            p.dot(self.dir),
        )
    }

    /// Whether the ray from `p` toward the light meets any primitive of `grid`.
    #[inline]
    pub fn occluded(&self, grid: &Grid, p: Vec3) -> bool {
        let (items, s) = self.cell_of(p);
        items.iter().any(|&(id, reach)| {
            reach > s
                && grid.prims[id as usize]
                    .intersect(p, self.dir, 0.0, f32::INFINITY)
                    .is_some()
        })
    }

    /// How many of the unit directions `dirs(k)`, `k < count` (each within the `spread` the
    /// grid was built with), leave `p` without meeting a primitive of `grid`.
    #[inline]
    pub fn open_count(
        &self,
        grid: &Grid,
        p: Vec3,
        count: u32,
        mut dirs: impl FnMut(u32) -> Vec3,
    ) -> u32 {
        let (items, s) = self.cell_of(p);
        let mut open = 0;
        for k in 0..count {
            let d = dirs(k);
            let blocked = items.iter().any(|&(id, reach)| {
                reach > s
                    && grid.prims[id as usize]
                        .intersect(p, d, 0.0, f32::INFINITY)
                        .is_some()
            });
            open += (!blocked) as u32;
        }
        open
    }
}

/// For each primitive seen in the image, the primitives whose bounding spheres come within
/// `reach` of its bounding sphere: the only possible occluders of ambient-occlusion rays of
/// length `reach` leaving its surface.
#[derive(Debug)]
pub(crate) struct Neighbours {
    /// Per primitive: `u32::MAX` when not seen, else its row in `start`.
    row: Vec<u32>,
    start: Vec<u32>,
    items: Vec<u32>,
    /// Bounding sphere `(centre, radius)` of every primitive.
    pub spheres: Vec<(Vec3, f32)>,
}

impl Neighbours {
    /// Neighbour lists of the primitives flagged in `seen` (rows in increasing id order).
    pub fn build(grid: &Grid, seen: &[bool], reach: f32) -> Neighbours {
        use rayon::prelude::*;
        let spheres: Vec<(Vec3, f32)> = grid.prims.iter().map(|p| p.bounding_sphere()).collect();
        let rmax = spheres.iter().fold(0f32, |m, s| m.max(s.1));
        let ids: Vec<u32> = (0..grid.prims.len() as u32)
            .filter(|&i| seen[i as usize])
            .collect();
        let lists: Vec<Vec<u32>> = ids
            .par_iter()
            .with_min_len(64)
            .map(|&i| {
                let (c, r) = spheres[i as usize];
                let ext = Vec3::splat(r + reach + rmax);
                let (a, b) = (grid.cell_of(c - ext), grid.cell_of(c + ext));
                let mut out = Vec::new();
                for z in a.z..=b.z {
                    for y in a.y..=b.y {
                        for x in a.x..=b.x {
                            for &j in grid.cell_items(IVec3::new(x, y, z)) {
                                if j == i {
                                    continue;
                                }
                                let (cj, rj) = spheres[j as usize];
                                let lim = r + reach + rj;
                                if (cj - c).length_squared() < lim * lim {
                                    out.push(j);
                                }
                            }
                        }
                    }
                }
                out.sort_unstable();
                out.dedup();
                out
            })
            .collect();
        let mut row = vec![u32::MAX; grid.prims.len()];
        let mut start = Vec::with_capacity(ids.len() + 1);
        let mut items = Vec::new();
        start.push(0u32);
        for (k, (&i, l)) in ids.iter().zip(&lists).enumerate() {
            row[i as usize] = k as u32;
            items.extend_from_slice(l);
            start.push(items.len() as u32);
        }
        Neighbours {
            row,
            start,
            items,
            spheres,
        }
    }

    /// The neighbour list of primitive `id`, `None` when it was not seen.
    #[inline]
    pub fn of(&self, id: u32) -> Option<&[u32]> {
        let r = self.row[id as usize];
        (r != u32::MAX).then(|| {
            let r = r as usize;
            &self.items[self.start[r] as usize..self.start[r + 1] as usize]
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use texmap_core::shade::Material;

    fn brute(g: &Grid, o: Vec3, d: Vec3) -> Option<(f32, u32)> {
        let mut best: Option<(f32, u32)> = None;
        for (id, p) in g.prims.iter().enumerate() {
            if let Some((t, _)) = p.intersect(o, d, 0.0, f32::INFINITY)
                && best.is_none_or(|b| t < b.0)
            {
                best = Some((t, id as u32));
            }
        }
        best
    }

    #[test]
    fn grid_walk_finds_the_brute_force_closest_hit() {
        let mut s = SphereScene::new(vec![Material::matte(Vec3::ONE); 2]);
        let mut x = 12345u32;
        let mut rnd = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x as f32 / u32::MAX as f32
        };
        for _ in 0..300 {
            let c = Vec3::new(rnd(), rnd(), rnd()) * 20.0;
            s.push(c, 0.3 + rnd(), (rnd() * 2.0) as u16 % 2);
        }
        for k in 0..100u32 {
            s.bonds.push([k, k + 1]);
        }
        s.bond_radius = 0.2;
        let g = Grid::build(&s, true);
        assert_eq!(g.prims.len(), 400);
        let mut checked = 0;
        for _ in 0..2000 {
            let o = Vec3::new(rnd(), rnd(), rnd()) * 40.0 - Vec3::splat(10.0);
            let d = (Vec3::new(rnd(), rnd(), rnd()) - 0.5).normalize();
            let a = g.closest(o, d, 0.0, f32::INFINITY);
            let b = brute(&g, o, d);
            assert_eq!(a.map(|h| h.t), b.map(|h| h.0), "ray {o} {d}");
            assert_eq!(
                g.occluded(o, d, 0.0, f32::INFINITY),
                b.is_some(),
                "ray {o} {d}"
            );
            checked += b.is_some() as u32;
        }
        assert!(checked > 200, "too few hits to test anything: {checked}");
    }

    #[test]
    fn capped_cylinder_hits_side_and_cap() {
        let p = Prim::Bond {
            a: Vec3::ZERO,
            u: Vec3::X,
            len: 4.0,
            r: 1.0,
            mat_a: 0,
            mat_b: 1,
        };
        // Side, from above: enters at y = 1.
        let (t, cap) = p
            .intersect(Vec3::new(1.0, 5.0, 0.0), -Vec3::Y, 0.0, 100.0)
            .unwrap();
        assert!((t - 4.0).abs() < 1e-6 && !cap);
        // Along the axis from beyond the far cap: the cap at x = 4, material of atom j.
        let (t, cap) = p
            .intersect(Vec3::new(10.0, 0.2, 0.0), -Vec3::X, 0.0, 100.0)
            .unwrap();
        assert!((t - 6.0).abs() < 1e-6 && cap);
        let (n, m) = p.surface(Vec3::new(4.0, 0.2, 0.0), true);
        assert_eq!((n, m), (Vec3::X, 1));
        // Missing beside it.
        assert!(
            p.intersect(Vec3::new(5.0, 5.0, 0.0), -Vec3::Y, 0.0, 100.0)
                .is_none()
        );
    }
}
