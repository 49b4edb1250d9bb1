//! What a draw keeps between its stages: binned triangle records (snapped vertices, varyings in
//! the program's layout, source triangle and facing) and the scratch buffers a framebuffer reuses
//! from draw to draw. The draw stages (`draw`), the fragment programs (`program`) and the
//! framebuffer all take these from here, so none of them reaches into another's module.

use crate::bin::TileBins;
use crate::project::{MAX_VAR, PVert, Var};
use crate::sprite::Sprite;

/// A binned triangle: snapped vertices oriented for the edge functions (positive
/// [`area2`]), varyings in the program's storage `V`, and its source triangle with the facing in
/// the top bit (triangle indices are below 2^31, see [`Mesh`]).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Rec<V> {
    pub v: [PVert; 3],
    pub var: V,
    pub tri_front: u32,
}

pub(crate) const FRONT_BIT: u32 = 1 << 31;

impl<V: VarStore> Rec<V> {
    /// The record of a snapped triangle with `area2(v) != 0` whose facing survives culling:
    /// front faces are re-oriented (vertices 1 and 2 swapped) so that every record is clockwise.
    #[inline]
    pub fn new(mut v: [PVert; 3], mut var: [Var; 3], tri: u32, front: bool) -> Self {
        if front {
            v.swap(1, 2);
            var.swap(1, 2);
        }
        Rec {
            v,
            var: V::pack(var),
            tri_front: tri | if front { FRONT_BIT } else { 0 },
        }
    }
}

/// How a record stores its varyings: not at all (52-byte records for programs without
/// varyings), or all three vertices' (88 bytes).
pub(crate) trait VarStore: Copy + Default + Send + Sync + 'static {
    fn pack(var: [Var; 3]) -> Self;
    fn unpack(&self) -> [Var; 3];
    fn bins(s: &mut TriBins) -> &mut TileBins<Rec<Self>>;
}

impl VarStore for () {
    #[inline]
    fn pack(_: [Var; 3]) {}
    #[inline]
    fn unpack(&self) -> [Var; 3] {
        [[0.0; MAX_VAR]; 3]
    }
    fn bins(s: &mut TriBins) -> &mut TileBins<Rec<()>> {
        &mut s.bare
    }
}

impl VarStore for [Var; 3] {
    #[inline]
    fn pack(var: [Var; 3]) -> Self {
        var
    }
    #[inline]
    fn unpack(&self) -> [Var; 3] {
        *self
    }
    fn bins(s: &mut TriBins) -> &mut TileBins<Rec<[Var; 3]>> {
        &mut s.with_var
    }
}

/// Triangle bins for both record layouts.
#[derive(Default)]
pub(crate) struct TriBins {
    pub bare: TileBins<Rec<()>>,
    pub with_var: TileBins<Rec<[Var; 3]>>,
}

/// Buffers reused from draw to draw (no per-draw allocation of the big arrays once warm).
#[derive(Default)]
pub(crate) struct Scratch {
    pub pverts: Vec<PVert>,
    pub tris: TriBins,
    pub sprites: TileBins<Sprite>,
}

impl std::fmt::Debug for Scratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = self.tris.bare.len() + self.tris.with_var.len();
        write!(f, "Scratch({n} binned triangles)")
    }
}

impl Clone for Scratch {
    /// Scratch holds no state between draws: a clone starts empty.
    fn clone(&self) -> Self {
        Scratch::default()
    }
}
