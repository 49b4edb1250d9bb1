//! The one error type of the crate: what was wrong and where (which object, triangle, texel).

use texmap_core::camera::CameraError;
use texmap_core::mip::MipError;
use texmap_raster::RasterError;

/// What went wrong building a scene or an environment, or rendering.
#[derive(Debug)]
#[non_exhaustive]
pub enum EnvMapError {
    /// A latitude-longitude environment must be twice as wide as it is high (and not empty).
    EnvironmentShape { width: u32, height: u32 },
    /// The texel buffer does not hold `width · height` texels.
    EnvironmentLength { expected: usize, actual: usize },
    /// A texel of the environment is not finite or is negative.
    EnvironmentTexel { x: u32, y: u32 },
    /// An index of refraction must be finite and positive.
    BadIor { ior: f32 },
    /// The target has no surface: a sphere of non-positive or non-finite radius, or a mesh with no
    /// triangle of non-zero area and finite vertices.
    EmptyTarget { what: &'static str },
    /// A triangle of a mesh refers to a vertex that does not exist (`object` is `None` for the
    /// target).
    MeshIndex {
        object: Option<usize>,
        triangle: usize,
        index: u32,
        vertex_count: usize,
    },
    /// A mesh attribute (normals) does not have one entry per vertex.
    MeshAttribute {
        object: Option<usize>,
        attribute: &'static str,
        len: usize,
        expected: usize,
    },
    /// A map side outside `MIN_MAP_SIZE..=MAX_MAP_SIZE`.
    MapSize { size: u32 },
    /// `Options::cube_faces_per_frame` outside 1..=6.
    FacesPerFrame { faces: u32 },
    /// A render option is out of range.
    BadOption { what: &'static str },
    /// The camera could not be built (e.g. a face camera for a degenerate probe).
    Camera(CameraError),
    /// The rasteriser refused a draw.
    Raster(RasterError),
    /// A map level could not be built.
    Mip(MipError),
}

impl std::fmt::Display for EnvMapError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let who = |o: &Option<usize>| match o {
            Some(i) => format!("object {i}"),
            None => "target".to_string(),
        };
        match self {
            EnvMapError::EnvironmentShape { width, height } => write!(
                f,
                "environment image is {width}x{height}: a latitude-longitude map must be 2:1 \
                 (width = 2 · height, height ≥ 1)"
            ),
            EnvMapError::EnvironmentLength { expected, actual } => write!(
                f,
                "environment image holds {actual} texels, expected width · height = {expected}"
            ),
            EnvMapError::EnvironmentTexel { x, y } => {
                write!(f, "environment texel ({x}, {y}) is negative or not finite")
            }
            EnvMapError::BadIor { ior } => write!(
                f,
                "index of refraction {ior} is invalid: expected a finite number > 0"
            ),
            EnvMapError::EmptyTarget { what } => write!(f, "the target has no surface: {what}"),
            EnvMapError::MeshIndex {
                object,
                triangle,
                index,
                vertex_count,
            } => write!(
                f,
                "{}: triangle {triangle} uses vertex {index}, but the mesh has {vertex_count} vertices",
                who(object)
            ),
            EnvMapError::MeshAttribute {
                object,
                attribute,
                len,
                expected,
            } => write!(
                f,
                "{}: {len} {attribute} for {expected} vertices (expected one per vertex)",
                who(object)
            ),
            EnvMapError::MapSize { size } => write!(
                f,
                "map size {size} is out of range: expected {}..={}",
                crate::MIN_MAP_SIZE,
                crate::MAX_MAP_SIZE
            ),
            EnvMapError::FacesPerFrame { faces } => write!(
                f,
                "cube faces per frame {faces} is out of range: expected 1..=6 (6 redraws the \
                 whole cube map every frame, fewer spread it over several frames)"
            ),
            EnvMapError::BadOption { what } => write!(f, "bad render option: {what}"),
            EnvMapError::Camera(e) => write!(f, "camera: {e}"),
            EnvMapError::Raster(e) => write!(f, "rasteriser: {e}"),
            EnvMapError::Mip(e) => write!(f, "map pyramid: {e}"),
        }
    }
}

impl std::error::Error for EnvMapError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            EnvMapError::Camera(e) => Some(e),
            EnvMapError::Raster(e) => Some(e),
            EnvMapError::Mip(e) => Some(e),
            _ => None,
        }
    }
}

impl From<CameraError> for EnvMapError {
    fn from(e: CameraError) -> Self {
        EnvMapError::Camera(e)
    }
}

impl From<RasterError> for EnvMapError {
    fn from(e: RasterError) -> Self {
        EnvMapError::Raster(e)
    }
}

impl From<MipError> for EnvMapError {
    fn from(e: MipError) -> Self {
        EnvMapError::Mip(e)
    }
}
