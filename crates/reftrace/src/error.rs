//! Error types of the reference ray tracer.

/// Why a mesh was refused by [`crate::SceneBuilder::add_mesh`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SceneError {
    /// The index list length is not a multiple of 3.
    IndicesNotTriangles { len: usize },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        vertex_count: usize,
    },
    /// Texture coordinates were given but not one per vertex.
    UvCountMismatch { uvs: usize, vertices: usize },
    /// More primitives than the 32-bit ids can name.
    TooManyPrimitives,
    /// Vertex normals were given but not one per vertex.
    NormalCountMismatch { normals: usize, vertices: usize },
}

impl std::fmt::Display for SceneError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SceneError::IndicesNotTriangles { len } => {
                write!(f, "{len} indices is not a whole number of triangles")
            }
            SceneError::IndexOutOfRange {
                triangle,
                index,
                vertex_count,
            } => write!(
                f,
                "triangle {triangle} refers to vertex {index}, but the mesh has {vertex_count} vertices"
            ),
            SceneError::UvCountMismatch { uvs, vertices } => write!(
                f,
                "{uvs} texture coordinates given for {vertices} vertices (need one per vertex)"
            ),
            SceneError::TooManyPrimitives => write!(f, "more than 2^32 - 1 primitives"),
            SceneError::NormalCountMismatch { normals, vertices } => write!(
                f,
                "{normals} vertex normals given for {vertices} vertices (need one per vertex)"
            ),
        }
    }
}

impl std::error::Error for SceneError {}

/// Why a render was refused. Checked once before any ray is traced.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum RenderError {
    /// `samples_per_axis` is 0 or above [`crate::MAX_SAMPLES_PER_AXIS`].
    BadSamples { samples_per_axis: u32 },
    /// `max_depth` is above [`crate::MAX_RECURSION_DEPTH`].
    BadMaxDepth { max_depth: u32 },
    /// The scene uses a material id that `materials` does not hold.
    MissingMaterial { material_id: u32, materials: usize },
    /// A material names a texture that `textures` does not hold.
    MissingTexture {
        material: usize,
        texture: u32,
        textures: usize,
    },
    /// A material parameter is out of range (non-finite colour, reflectance outside [0, 1],
    /// index of refraction not finite and positive).
    BadMaterial { material: usize, what: &'static str },
    /// The background colour is not finite.
    BadBackground,
    /// Ambient occlusion with 0 or more than [`crate::MAX_AO_SAMPLES_PER_AXIS`] samples per
    /// axis, or a distance that is not finite and positive.
    BadAmbientOcclusion {
        samples_per_axis: u32,
        distance: f32,
    },
    /// Depth cueing with non-finite depths, `start >= end`, a strength outside [0, 1] or a
    /// non-finite colour.
    BadFog,
    /// Soft shadows with 0 or more than [`crate::MAX_SHADOW_SAMPLES_PER_AXIS`] samples per
    /// axis, or a light size outside `0..=`[`crate::MAX_LIGHT_SIZE_DEG`] degrees.
    BadSoftShadows {
        samples_per_axis: u32,
        size_deg: f32,
    },
    /// An outline width of 0 or more than [`crate::MAX_OUTLINE_PX`] pixels.
    BadOutline { width_px: u32 },
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RenderError::BadSamples { samples_per_axis } => write!(
                f,
                "samples_per_axis = {samples_per_axis}; must be 1..={}",
                crate::MAX_SAMPLES_PER_AXIS
            ),
            RenderError::BadMaxDepth { max_depth } => write!(
                f,
                "max_depth = {max_depth}; must be at most {}",
                crate::MAX_RECURSION_DEPTH
            ),
            RenderError::MissingMaterial {
                material_id,
                materials,
            } => write!(
                f,
                "the scene uses material {material_id} but only {materials} materials were given"
            ),
            RenderError::MissingTexture {
                material,
                texture,
                textures,
            } => write!(
                f,
                "material {material} uses texture {texture} but only {textures} textures were given"
            ),
            RenderError::BadMaterial { material, what } => {
                write!(f, "material {material}: {what}")
            }
            RenderError::BadBackground => write!(f, "background colour must be finite"),
            RenderError::BadAmbientOcclusion {
                samples_per_axis,
                distance,
            } => write!(
                f,
                "ambient occlusion with {samples_per_axis} samples per axis and distance {distance}: need 1..={} samples per axis and a finite positive distance",
                crate::MAX_AO_SAMPLES_PER_AXIS
            ),
            RenderError::BadFog => write!(
                f,
                "fog needs finite depths start < end, a strength in [0, 1] and a finite colour"
            ),
            RenderError::BadSoftShadows {
                samples_per_axis,
                size_deg,
            } => write!(
                f,
                "soft shadows with {samples_per_axis} samples per axis and a {size_deg}° light: need 1..={} samples per axis and a light size in 0..={} degrees",
                crate::MAX_SHADOW_SAMPLES_PER_AXIS,
                crate::MAX_LIGHT_SIZE_DEG
            ),
            RenderError::BadOutline { width_px } => write!(
                f,
                "outline width {width_px} px is not allowed (1..={})",
                crate::MAX_OUTLINE_PX
            ),
        }
    }
}

impl std::error::Error for RenderError {}

/// Why a texture was refused by [`crate::Texture::new`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum TextureError {
    /// Width or height is zero.
    Empty { width: u32, height: u32 },
    /// The texel count is not `width * height`.
    SizeMismatch {
        width: u32,
        height: u32,
        texels: usize,
    },
    /// A texel holds a NaN or infinity.
    NonFinite { x: u32, y: u32 },
}

impl std::fmt::Display for TextureError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TextureError::Empty { width, height } => {
                write!(f, "texture size {width}x{height} is empty")
            }
            TextureError::SizeMismatch {
                width,
                height,
                texels,
            } => write!(f, "{texels} texels given for a {width}x{height} texture"),
            TextureError::NonFinite { x, y } => write!(f, "texel ({x}, {y}) is not finite"),
        }
    }
}

impl std::error::Error for TextureError {}
