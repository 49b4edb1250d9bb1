//! Bonds drawn as exact ray-cast cylinder impostors, after the sphere pass of every method.
//!
//! Molecules are drawn with their bonds; Seed 002 ends with "the same idea extends to pipes
//! (cylinders, i.e. bonds)". This pass draws every
//! [`SphereScene::bonds`] pair as a cylinder of its radius ([`SphereScene::bond_radius_of`]: per bond, or `bond_radius` for all) from one atom
//! centre to the other, **half-bond coloured** (the half nearer atom `i` in atom `i`'s material,
//! as VMD and OVITO do), lit with the workspace's one shading model in eye space.
//!
//! 1. **Project** (parallel over fixed chunks of [`BOND_CHUNK`] bonds): validate the bond (both
//!    indices in range, both atoms drawable, distinct centres, a finite positive radius), move the
//!    end points to eye space, clip the axis to depths `≥ near − r` (whatever lies nearer cannot
//!    produce a fragment at depth ≥ near), cull against the far plane, and bound the screen
//!    rectangle of the capped cylinder by the union of the rectangles of the two spheres of radius
//!    `r` around the clipped end points: the capped cylinder lies in the convex hull of those two
//!    spheres, and a perspective projection maps that hull onto the hull of their images (the
//!    eight tangent slopes of both spheres on one set of 8 lanes). A 96-byte [`BondRec`] holds
//!    the per-bond constants of the intersection below, formed in f64 and rounded once.
//! 2. **Bin** into the sphere pipeline's 32x32 tiles with the raster crate's binner
//!    ([`texmap_raster::bin`]): a copy of the record per tile, bond order kept within every tile.
//! 3. **Tiles** (parallel over bands of 32 rows): the tile's depth buffer starts as the depth the
//!    sphere pass wrote, so bonds and atoms interpenetrate correctly; every bond of the bin is
//!    intersected with the tile's eye rays 8 pixels at a time (one row, or two rows of 4 for
//!    boxes at most 4 px wide; rows of boxes wider than 16 px narrowed to the hull of the end
//!    rectangles) under a strict depth test (an atom wins a tie, then the earlier bond). A
//!    **hierarchical-z** test skips the 8 pixels when the stored depths are all nearer than the
//!    bond's nearest point (most bond pixels of a ball-and-stick image lie behind atoms). The
//!    lanes are SSE2 or, where the CPU has it, AVX2 (chosen once per frame; the same IEEE
//!    operations, so the same bits). Then each pixel won by a bond is shaded once (8 lanes,
//!    sRGB encoded over lanes) and written.
//!
//! # The intersection
//! A bond is the solid capped cylinder `{p : 0 ≤ h(p) ≤ L, |p − a − h(p)·u| ≤ r}` with
//! `h(p) = (p − a)·u`. A ray `o + t·d` (eye space; `d = (x/k, y/k, −1)` from the eye for a
//! perspective camera, `d = (0, 0, −1)` from the pixel's point on the eye plane for an orthographic
//! one, so that `t` is the depth in both) is inside it on the intersection of two intervals:
//! - the **infinite cylinder**: with `g = o − a`, `A = |d × u|²` and the ray–axis line distance
//!   `D = g·(d × u) / √A`, the ray is inside for `t ∈ s ∓ √(r²A − (g·(d × u))²) / A` around the
//!   closest approach `s`. The discriminant is written with `g·(d × u)` (for the perspective
//!   camera `−d·(u × a)`, a per-bond constant vector dotted with `d`) rather than `B² − AC`, which
//!   would cancel two numbers of size `|a|²` down to one of size `r²` (pbrt's robust sphere
//!   discriminant, carried to the cylinder). When the ray is parallel to the axis (`A ≤ 1e-12`)
//!   the interval is all or nothing by the ray's distance from the axis.
//! - the **slab** `0 ≤ h(o) + t·(d·u) ≤ L` between the two cap planes.
//!
//! Entering the solid at `max` of the lower ends hits the side or a flat cap: the exact capped
//! cylinder of the reference ray tracer, so bonds as thick as (or thicker than) an atom show flat
//! caps, and with thinner bonds the caps are hidden inside the atoms at no extra cost. **Near
//! plane** as the sphere ray caster: a fragment nearer than the near plane is clipped and the ray
//! takes the exit point instead (the inside of a cut bond), lit with the normal turned toward the
//! viewer, as the reference's two-sided surfaces.
//!
//! **Determinism:** chunk boundaries are fixed, bins keep bond order, the depth test is strict and
//! each tile writes only its own pixels, so the same input gives the same bytes for any number of
//! threads.
//!
//! # References
//! - Seed 002 (closing remark: pipes by the same method). We depart from its lookup tables: a
//!   cylinder seen at an angle has no single precomputable image, and the exact intersection costs
//!   a handful of multiplies per fragment.
//! - M. Pharr, W. Jakob, G. Humphreys, *Physically Based Rendering* (4th ed.), §6.2 (cylinders)
//!   and §6.8 (robust quadric discriminants).

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Lane loops index several fixed-width arrays with one lane counter (the vectorised form).
#![allow(clippy::needless_range_loop)]

use glam::{DVec3, Vec3};
use texmap_core::frame::Frame;
#[cfg(target_arch = "x86_64")]
use texmap_core::lanes::F32x8Avx2;
use texmap_core::lanes::{self, F32x8, LANES8, LaneMask, Lanes8, SpecPow};
use texmap_core::shade::{Lighting, Material};

use crate::pipeline::{FLAG_INSIDE, LANES, NONE, TILE, TILE_BUF, TILE_PX, TileRect, View};
use crate::scene::SphereScene;
use texmap_raster::bin::{ChunkSink, TileBins};

mod kernel;
mod project;

use kernel::*;
use project::*;
pub(crate) use project::{BondBins, BondRec, BondStats};

/// Bonds per projection chunk: fixed, so results do not depend on the thread count.
pub(crate) const BOND_CHUNK: usize = 8192;
/// Flag bit in a winner entry: the hit is on a flat cap (normal `±u`), not on the side.
const FLAG_CAP: u32 = 1 << 30;
/// Mask of the record index in a winner entry.
const INDEX_MASK: u32 = FLAG_CAP - 1;
/// Below this `A = |d × u|²` a ray counts as parallel to the axis.
const PARALLEL_A: f32 = 1e-12;
/// The slab divides by `d·u`; a smaller magnitude is replaced by this one (a ray that parallel
/// to the cap planes is inside the slab everywhere or nowhere, which the huge quotients keep).
const MIN_DU: f32 = 1e-30;

/// The [`SpecPow`] of the materials when they all have the same shininess.
fn shared_spec_pow(materials: &[Material]) -> Option<SpecPow> {
    let m0 = materials.first()?;
    materials
        .iter()
        .all(|m| m.shininess.to_bits() == m0.shininess.to_bits())
        .then(|| lanes::spec_pow_of(F32x8::splat(m0.shininess)))
}

/// Whether the depth pass may use AVX2 lanes (checked once per frame).
fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        F32x8Avx2::available()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Draw the bonds of `scene` over `frame`, which holds the sphere pass's colour and depth.
/// `lighting` is in eye space.
pub(crate) fn draw(
    bins: &mut BondBins,
    scene: &SphereScene,
    view: &View,
    lighting: &Lighting,
    frame: &mut Frame,
) -> BondStats {
    let stats = bins.build(scene, view);
    if stats.drawn == 0 {
        return stats;
    }
    let kernel = Kernel {
        view: *view,
        avx2: avx2_available(),
        spec_pow: shared_spec_pow(&scene.materials),
        lighting: *lighting,
        materials: &scene.materials,
    };
    let bins = &*bins;
    let w = view.width as usize;
    let init = || TileBuf {
        depth: [f32::INFINITY; TILE_BUF],
        win: [NONE; TILE_BUF],
    };
    crate::pipeline::for_each_tile(view, frame, init, |buf, t, tile, color, depth| {
        let recs = bins.tile(t);
        if recs.is_empty() {
            return;
        }
        let TileRect {
            x0,
            y0,
            w: tw,
            h: th,
        } = tile;
        // Start from the sphere pass's depth (lanes past the tile stay infinite).
        buf.depth.fill(f32::INFINITY);
        buf.win.fill(NONE);
        for j in 0..th as usize {
            buf.depth[j * TILE as usize..j * TILE as usize + tw as usize]
                .copy_from_slice(&depth[j * w..j * w + tw as usize]);
        }
        kernel.raster(recs, x0, y0, tw, th, &mut *buf);
        kernel.resolve(recs, x0, y0, tw, th, &*buf, color, depth, w);
    });
    stats
}

#[cfg(test)]
mod tests;
