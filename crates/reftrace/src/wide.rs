//! A 4-wide BVH collapsed from obvhs's binary BVH, and its closest-hit traversal.
//!
//! obvhs builds the tree (PLOC + reinsertion + leaf collapse, [`obvhs::bvh2`]); this module only
//! changes its layout and walks it. Each [`Node4`] holds the boxes of up to four children as
//! structure-of-arrays lanes (`[f32; 4]` per plane), so one node visit is one fixed-width slab
//! test over four boxes that the compiler turns into SSE, followed by a nearest-first push of the
//! children that were hit.
//!
//! # Why not obvhs's own traversals
//! Measured with callgrind on the S2-like scene (100k spheres, 480x270 primary rays, one thread;
//! docs/PERFORMANCE.md): obvhs's cwbvh traversal decodes eight quantised child boxes from
//! bytes at every node (48 `u8 → f32` conversions) and its bvh2 traversal tests two boxes per step
//! with a data-dependent swap. The 4-wide layout keeps full-precision boxes (128 bytes a node, two
//! cache lines) and halves the depth of the binary tree: 2,469 instructions per primary ray
//! (trace only) against 4,119 for cwbvh and 4,202 for bvh2. Besides, obvhs's cwbvh traversal
//! misses some rays with a zero direction component (axis-parallel rays; see
//! `tests/reference.rs`), which this one and obvhs's bvh2 do not.
//!
//! # Robustness
//! - The slab test picks the near and far plane per axis from the sign of the direction (chosen
//!   once per ray), so an empty child slot (lo = +∞, hi = −∞) never hits.
//! - `max`/`min` of the slab distances keep the running value when the new one is NaN (`0 · ∞`
//!   when the origin lies on a slab plane of an axis the ray runs parallel to): glam's
//!   `Vec4::max(t, running)` is SSE `maxps`, which returns its second operand when either is NaN,
//!   and `f32::max` in the scalar fallback ignores a NaN operand. So a NaN never culls a box, it
//!   only fails to narrow the interval (unit test `nan_never_culls_and_empty_lanes_never_hit`).
//! - The boxes are the padded primitive boxes of [`crate::scene`], so rounding in the slab test
//!   cannot cull a ray that grazes a primitive; the leaf tests decide.
//! - The traversal stack has a fixed capacity ([`STACK_SIZE`]); [`Wide4::from_bvh2`] refuses a
//!   tree deep enough to overflow it (the scene then keeps obvhs's binary traversal).

use glam::Vec4;
use obvhs::bvh2::Bvh2;

/// Capacity of the traversal stack. A visited node descends into its nearest inner child and
/// pushes the others (at most three, written as a fixed block of three), so at depth `d` the
/// stack holds at most `3·(d − 1)` entries and the block ends below `3·d ≤ STACK_SIZE`.
pub(crate) const STACK_SIZE: usize = 128;

/// Number of set bits of a 4-bit mask.
const POPCOUNT4: [u8; 16] = [0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4];

/// The deepest tree the fixed stack can walk.
const MAX_DEPTH: usize = STACK_SIZE / 3;

/// Up to four child boxes (planes in lanes `[lo_x, lo_y, lo_z, hi_x, hi_y, hi_z]`) and what each
/// child is: bit `k` of `leaf_bits` clear for an inner node (`child[k]` = node index), set for a
/// leaf of `count[k]` primitives starting at slot `child[k]`. Empty slots have an empty box, a
/// clear bit and `child = 0`; their box never hits. 128 bytes, two cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node4 {
    planes: [[f32; 4]; 6],
    child: [u32; 4],
    count: [u16; 4],
    leaf_bits: u32,
}

const EMPTY_NODE: Node4 = Node4 {
    planes: [
        [f32::INFINITY; 4],
        [f32::INFINITY; 4],
        [f32::INFINITY; 4],
        [f32::NEG_INFINITY; 4],
        [f32::NEG_INFINITY; 4],
        [f32::NEG_INFINITY; 4],
    ],
    child: [0; 4],
    count: [0; 4],
    leaf_bits: 0,
};

/// One traversal stack entry: an inner node and the distance at which the ray enters its box.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Entry {
    index: u32,
    dist: f32,
}

/// Scratch for one traversal at a time; create once per thread or row and reuse.
pub(crate) struct TraversalStack {
    entries: [Entry; STACK_SIZE],
}

impl TraversalStack {
    pub(crate) const fn new() -> TraversalStack {
        TraversalStack {
            entries: [Entry {
                index: 0,
                dist: 0.0,
            }; STACK_SIZE],
        }
    }
}

/// Per-ray constants of the slab test.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SlabRay {
    origin: [f32; 3],
    inv_dir: [f32; 3],
    /// Per axis: the ray runs toward −∞ (its near plane is the box's `hi`).
    neg: [bool; 3],
}

impl SlabRay {
    #[inline]
    pub(crate) fn new(origin: glam::Vec3, dir: glam::Vec3) -> SlabRay {
        let inv = glam::Vec3::ONE / dir;
        // A zero component (either sign) has an infinite inverse of the same sign.
        SlabRay {
            origin: origin.to_array(),
            inv_dir: inv.to_array(),
            neg: [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0],
        }
    }
}

/// The 4-wide tree. Leaf ranges index the primitive slots of obvhs's `primitive_indices` order.
#[derive(Clone, Debug)]
pub(crate) struct Wide4 {
    nodes: Vec<Node4>,
}

impl Wide4 {
    /// Collapse a binary BVH: each 4-wide node takes the two children of a binary node and keeps
    /// opening its largest-area inner child until it has four children or only leaves. `None` if
    /// the result is too deep for [`STACK_SIZE`].
    pub(crate) fn from_bvh2(b: &Bvh2) -> Option<Wide4> {
        if b.nodes.is_empty() {
            return Some(Wide4 { nodes: Vec::new() });
        }
        let root = &b.nodes[0];
        if root.is_leaf() {
            // A single leaf: one node with one child.
            let mut n = EMPTY_NODE;
            set_lane(&mut n, 0, root);
            set_leaf(&mut n, 0, root)?;
            return Some(Wide4 { nodes: vec![n] });
        }
        let mut nodes = Vec::with_capacity(b.nodes.len() / 2 + 1);
        nodes.push(EMPTY_NODE);
        // Work list of (binary inner node, wide node slot, depth).
        let mut work = vec![(0usize, 0usize, 1usize)];
        let mut max_depth = 1;
        while let Some((bi, wi, depth)) = work.pop() {
            max_depth = max_depth.max(depth);
            // Gather up to four children by opening the largest inner candidate.
            let first = b.nodes[bi].first_index as usize;
            let mut kids: [usize; 4] = [first, first + 1, 0, 0];
            let mut n_kids = 2;
            while n_kids < 4 {
                let mut best: Option<(usize, f32)> = None;
                for (k, &ci) in kids[..n_kids].iter().enumerate() {
                    let c = &b.nodes[ci];
                    if !c.is_leaf() {
                        let area = c.aabb().half_area();
                        if best.is_none_or(|(_, a)| area > a) {
                            best = Some((k, area));
                        }
                    }
                }
                let Some((k, _)) = best else { break };
                let open = kids[k];
                let f = b.nodes[open].first_index as usize;
                kids[k] = f;
                kids[n_kids] = f + 1;
                n_kids += 1;
            }
            let mut node = EMPTY_NODE;
            for (lane, &ci) in kids[..n_kids].iter().enumerate() {
                let c = &b.nodes[ci];
                set_lane(&mut node, lane, c);
                if c.is_leaf() {
                    set_leaf(&mut node, lane, c)?;
                } else {
                    let slot = nodes.len();
                    nodes.push(EMPTY_NODE);
                    node.child[lane] = slot as u32;
                    work.push((ci, slot, depth + 1));
                }
            }
            nodes[wi] = node;
        }
        (max_depth <= MAX_DEPTH).then_some(Wide4 { nodes })
    }

    /// Closest-hit traversal over `(tmin, tmax)`. `leaf(slot)` tests primitive `slot`, keeps the
    /// nearest hit itself and returns the current nearest distance (≤ its input bound); the
    /// traversal culls every box entered beyond it.
    #[inline(always)]
    pub(crate) fn traverse<F: FnMut(usize) -> f32>(
        &self,
        ray: &SlabRay,
        tmin: f32,
        tmax: f32,
        stack: &mut TraversalStack,
        mut leaf: F,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let mut best = tmax;
        let st = &mut stack.entries;
        let mut sp = 0usize;
        let mut cur = 0u32;
        'visit: loop {
            let node = &self.nodes[cur as usize];
            // Slab test of the four child boxes.
            let (tn, tf) = slab4(node, ray, tmin, best);
            let mask = tn.cmple(tf).bitmask();
            let tn = tn.to_array();
            // Test the leaves hit right away: they are cheap and shrink `best` for the rest.
            let mut leaves = mask & node.leaf_bits;
            let mut inner = mask & !node.leaf_bits;
            if leaves != 0 {
                while leaves != 0 {
                    let k = leaves.trailing_zeros() as usize;
                    leaves &= leaves - 1;
                    let start = node.child[k] as usize;
                    for slot in start..start + node.count[k] as usize {
                        best = leaf(slot);
                    }
                }
                // Drop inner children entered beyond the nearest hit found.
                for (k, &d) in tn.iter().enumerate() {
                    if d > best {
                        inner &= !(1 << k);
                    }
                }
            }
            // Population count of a 4-bit mask by table (the portable x86-64 baseline has no
            // POPCNT instruction; `count_ones` would be a dozen instructions).
            match POPCOUNT4[inner as usize] {
                0 => {}
                1 => {
                    // One child: descend without touching the stack.
                    cur = node.child[inner.trailing_zeros() as usize];
                    continue 'visit;
                }
                n => {
                    // Several: sort by decreasing entry distance, push all but the nearest.
                    let mut hit = [Entry::default(); 4];
                    let mut m = 0;
                    while inner != 0 {
                        let k = inner.trailing_zeros() as usize;
                        inner &= inner - 1;
                        let x = Entry {
                            index: node.child[k],
                            dist: tn[k],
                        };
                        let mut j = m;
                        while j > 0 && hit[j - 1].dist < x.dist {
                            hit[j] = hit[j - 1];
                            j -= 1;
                        }
                        hit[j] = x;
                        m += 1;
                    }
                    let n = n as usize;
                    // Fixed three-entry store (no memcpy call); only `n − 1` become live. The
                    // depth bound of `from_bvh2` keeps `sp + 3 ≤ STACK_SIZE`.
                    st[sp] = hit[0];
                    st[sp + 1] = hit[1];
                    st[sp + 2] = hit[2];
                    sp += n - 1;
                    cur = hit[n - 1].index;
                    continue 'visit;
                }
            }
            // Pop the nearest pending node that is not beyond the nearest hit.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let e = st[sp];
                if e.dist <= best {
                    cur = e.index;
                    continue 'visit;
                }
            }
        }
    }
}

/// Slab test of a node's four child boxes against `(tmin, tmax)`: entry and exit distance per
/// lane; a lane is hit when `entry ≤ exit`. Four lanes at once in glam's `Vec4` (SSE on x86-64).
#[inline(always)]
fn slab4(node: &Node4, ray: &SlabRay, tmin: f32, tmax: f32) -> (Vec4, Vec4) {
    let mut tn = Vec4::splat(tmin);
    let mut tf = Vec4::splat(tmax);
    for axis in 0..3 {
        let o = Vec4::splat(ray.origin[axis]);
        let inv = Vec4::splat(ray.inv_dir[axis]);
        // Near and far plane by the sign of the direction (a select, not an index: no bounds
        // check in the loop).
        let (lo, hi) = (&node.planes[axis], &node.planes[axis + 3]);
        let (near, far) = if ray.neg[axis] { (hi, lo) } else { (lo, hi) };
        let t0 = (Vec4::from_array(*near) - o) * inv;
        let t1 = (Vec4::from_array(*far) - o) * inv;
        // NaN-ignoring max/min: a NaN in t0/t1 keeps the running value (see `nan_never_culls`).
        tn = t0.max(tn);
        tf = t1.min(tf);
    }
    (tn, tf)
}

/// Make lane `k` a leaf of the binary leaf `c` (`None` if its count does not fit).
fn set_leaf(n: &mut Node4, k: usize, c: &obvhs::bvh2::node::Bvh2Node) -> Option<()> {
    n.child[k] = c.first_index;
    n.count[k] = u16::try_from(c.prim_count).ok()?;
    n.leaf_bits |= 1 << k;
    Some(())
}

/// Copy a binary node's box into lane `k`.
fn set_lane(n: &mut Node4, k: usize, c: &obvhs::bvh2::node::Bvh2Node) {
    let a = c.aabb();
    n.planes[0][k] = a.min.x;
    n.planes[1][k] = a.min.y;
    n.planes[2][k] = a.min.z;
    n.planes[3][k] = a.max.x;
    n.planes[4][k] = a.max.y;
    n.planes[5][k] = a.max.z;
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec3, Vec3A};
    use obvhs::{BvhBuildParams, aabb::Aabb, bvh2::builder::build_bvh2};

    fn node_with(lo: Vec3, hi: Vec3) -> Node4 {
        let mut n = EMPTY_NODE;
        for (axis, (l, h)) in [(lo.x, hi.x), (lo.y, hi.y), (lo.z, hi.z)]
            .into_iter()
            .enumerate()
        {
            n.planes[axis][0] = l;
            n.planes[axis + 3][0] = h;
        }
        n
    }

    #[test]
    fn nan_never_culls_and_empty_lanes_never_hit() {
        // Box [0,1]³ in lane 0, lanes 1..3 empty. Rays parallel to x (dir.y = dir.z = ±0) whose
        // origin lies exactly on the y = 0 or y = 1 plane: (plane − o)·(1/0) is 0·∞ = NaN.
        let n = node_with(Vec3::ZERO, Vec3::ONE);
        for y in [0.0f32, 1.0] {
            for dir in [Vec3::X, Vec3::NEG_X, Vec3::new(1.0, -0.0, 0.0)] {
                let origin = Vec3::new(if dir.x > 0.0 { -5.0 } else { 5.0 }, y, 0.5);
                let ray = SlabRay::new(origin, dir);
                let (tn, tf) = slab4(&n, &ray, 0.0, f32::INFINITY);
                let mask = tn.cmple(tf).bitmask();
                assert_eq!(
                    mask, 1,
                    "origin {origin} dir {dir}: lanes hit {mask:04b}, expected 0001"
                );
            }
        }
        // A ray that clearly misses the box hits no lane; every empty lane misses for every
        // direction octant.
        for dir in [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::new(-1.0, -1.0, -1.0).normalize(),
        ] {
            let ray = SlabRay::new(Vec3::new(0.5, 7.0, 0.5) - dir * 5.0, dir);
            let (tn, tf) = slab4(&n, &ray, 0.0, f32::INFINITY);
            assert_eq!(
                tn.cmple(tf).bitmask() & 0b1110,
                0,
                "empty lane hit for {dir}"
            );
        }
    }

    #[test]
    fn collapse_keeps_every_primitive_exactly_once_and_boxes_nest() {
        // Random boxes; walk the 4-wide tree and check that the leaf ranges partition the slots
        // and that each child box lies inside its parent's box.
        let mut s = 7u64;
        let mut f = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 40) as f32) / (1u64 << 24) as f32
        };
        for (count, leaf) in [(1usize, 1u32), (3, 1), (1000, 1), (1000, 4)] {
            let boxes: Vec<Aabb> = (0..count)
                .map(|_| {
                    let c = Vec3A::new(f(), f(), f()) * 100.0;
                    Aabb::new(c, c + Vec3A::splat(1.0 + f()))
                })
                .collect();
            let params = BvhBuildParams {
                max_prims_per_leaf: leaf,
                ..BvhBuildParams::medium_build()
            };
            let b2 = build_bvh2(&boxes, params, &mut Default::default());
            let w = Wide4::from_bvh2(&b2).expect("shallow tree");
            let mut seen = vec![0u32; count];
            let mut todo = vec![(
                0u32,
                Vec3::splat(f32::NEG_INFINITY),
                Vec3::splat(f32::INFINITY),
            )];
            while let Some((i, plo, phi)) = todo.pop() {
                let n = &w.nodes[i as usize];
                for k in 0..4 {
                    let lo = Vec3::new(n.planes[0][k], n.planes[1][k], n.planes[2][k]);
                    let hi = Vec3::new(n.planes[3][k], n.planes[4][k], n.planes[5][k]);
                    if lo.x > hi.x {
                        continue; // empty lane
                    }
                    assert!(
                        lo.cmpge(plo).all() && hi.cmple(phi).all(),
                        "child box escapes its parent"
                    );
                    if n.leaf_bits & (1 << k) != 0 {
                        let start = n.child[k] as usize;
                        for c in &mut seen[start..start + n.count[k] as usize] {
                            *c += 1;
                        }
                    } else {
                        todo.push((n.child[k], lo, hi));
                    }
                }
            }
            assert!(
                seen.iter().all(|&c| c == 1),
                "{count} boxes: slots seen {:?}",
                &seen[..seen.len().min(20)]
            );
        }
    }
}
