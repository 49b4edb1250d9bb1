//! The study's error type.

use std::path::PathBuf;

use texmap_core::camera::CameraError;
use texmap_core::metrics::MetricError;
use texmap_reftrace::RenderError;

/// Why a study step failed.
#[derive(Debug)]
#[non_exhaustive]
pub enum StudyError {
    /// A camera for a scene or a sweep point could not be built.
    Camera(CameraError),
    /// Two frames could not be compared.
    Metric(MetricError),
    /// The reference ray tracer refused its options.
    Reference(RenderError),
    /// A harness or sweep option is out of range.
    BadOption { what: &'static str, value: String },
    /// A file could not be written.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Records could not be encoded as JSON.
    Json(serde_json::Error),
    /// plotters failed to draw or encode a chart.
    Chart { chart: String, message: String },
}

impl std::fmt::Display for StudyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StudyError::Camera(e) => write!(f, "camera: {e}"),
            StudyError::Metric(e) => write!(f, "metric: {e}"),
            StudyError::Reference(e) => write!(f, "reference ray tracer: {e}"),
            StudyError::BadOption { what, value } => {
                write!(f, "option {what} = {value} is out of range")
            }
            StudyError::Io { path, source } => write!(f, "{}: {source}", path.display()),
            StudyError::Json(e) => write!(f, "results JSON: {e}"),
            StudyError::Chart { chart, message } => write!(f, "chart {chart}: {message}"),
        }
    }
}

impl std::error::Error for StudyError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            StudyError::Camera(e) => Some(e),
            StudyError::Metric(e) => Some(e),
            StudyError::Reference(e) => Some(e),
            StudyError::Io { source, .. } => Some(source),
            StudyError::Json(e) => Some(e),
            _ => None,
        }
    }
}

impl From<CameraError> for StudyError {
    fn from(e: CameraError) -> Self {
        StudyError::Camera(e)
    }
}

impl From<MetricError> for StudyError {
    fn from(e: MetricError) -> Self {
        StudyError::Metric(e)
    }
}

impl From<RenderError> for StudyError {
    fn from(e: RenderError) -> Self {
        StudyError::Reference(e)
    }
}

/// Write `bytes` to `path` atomically (a temporary file beside it, then a rename, so a failed
/// write never leaves a partial file), mapping the error to [`StudyError::Io`].
pub(crate) fn write_file(path: PathBuf, bytes: &[u8]) -> Result<(), StudyError> {
    let mut name = std::ffi::OsString::from(".");
    name.push(path.file_name().unwrap_or_default());
    name.push(".tmp");
    let tmp = path.with_file_name(name);
    let result = std::fs::write(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, &path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(|source| StudyError::Io { path, source })
}
