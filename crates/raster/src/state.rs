//! Fixed-function state of a draw: depth test, depth write, culling, blending.

/// Which fragments pass the depth test against the stored depth (eye-space distance, smaller is
/// nearer; cleared to `INFINITY`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DepthTest {
    /// Pass when nearer than the stored depth (the usual z-buffer).
    #[default]
    Less,
    /// Pass when nearer or equal (redrawing the same surface passes).
    LessEqual,
    /// Always pass.
    Always,
}

/// Which triangles are discarded by their facing.
///
/// A triangle is front-facing when its vertices appear counter-clockwise to the viewer (the
/// right-handed convention: the normal `(p1 − p0) × (p2 − p0)` points toward the eye).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Cull {
    /// Draw both sides (lit programs then light the back side with the flipped normal).
    None,
    /// Discard back-facing triangles.
    #[default]
    Back,
    /// Discard front-facing triangles.
    Front,
}

/// How a fragment's colour combines with the stored colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Blend {
    /// Overwrite.
    #[default]
    Replace,
    /// Add (linear light): glow, and counting how often each pixel is written.
    Add,
}

/// The fixed-function state of one draw call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawState {
    pub depth_test: DepthTest,
    /// Whether passing fragments write their depth.
    pub depth_write: bool,
    pub cull: Cull,
    pub blend: Blend,
}

impl Default for DrawState {
    /// Opaque surfaces: `Less`, depth write on, back faces culled, colour replaced.
    fn default() -> Self {
        DrawState {
            depth_test: DepthTest::Less,
            depth_write: true,
            cull: Cull::Back,
            blend: Blend::Replace,
        }
    }
}

impl DrawState {
    /// Every fragment counts once: no depth test, no depth write, no culling, additive colour.
    pub fn additive_overlay() -> Self {
        DrawState {
            depth_test: DepthTest::Always,
            depth_write: false,
            cull: Cull::None,
            blend: Blend::Add,
        }
    }
}
