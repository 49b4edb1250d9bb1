//! What a render is asked for (the method and its options) and what it reports (the statistics).

use texmap_core::shade::Lighting;

/// The drawing methods (a closed set).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    Polygon,
    Lut,
    Template,
    Raycast,
}

impl Method {
    pub const ALL: [Method; 4] = [
        Method::Polygon,
        Method::Lut,
        Method::Template,
        Method::Raycast,
    ];

    /// The lower-case name used on the command line and in results files.
    pub fn name(self) -> &'static str {
        match self {
            Method::Polygon => "polygon",
            Method::Lut => "lut",
            Method::Template => "template",
            Method::Raycast => "raycast",
        }
    }

    /// Parse [`Method::name`].
    pub fn from_name(s: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == s)
    }
}

/// How the Seed 004 template method writes depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TemplateDepth {
    /// The billboard plane through the sphere centre, as the paper does.
    Billboard,
    /// Seed 002's depth image: `z = z0 + D(s,t)·R/d0`.
    DepthImage,
}

/// How the Seed 004 template method colours spheres.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TemplateColoring {
    /// One grey template recoloured per sphere by the material's HSV hue and saturation.
    HueRecolor,
    /// One template per material.
    PerKind,
}

/// How the polygon method lights its triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PolygonShading {
    /// Per pixel with the interpolated vertex normal.
    Phong,
    /// Per vertex, colours interpolated.
    Gouraud,
}

/// Drawing options shared by all methods; fields a method does not use are ignored by it.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    pub method: Method,
    pub lighting: Lighting,
    /// Background colour, sRGB RGBA.
    pub background: [u8; 4],
    /// Side of the Seed 002 colour/depth images (texels).
    pub lut_size: u32,
    /// Side of the finest Seed 004 template (texels); coarser levels halve it.
    pub template_size: u32,
    pub template_depth: TemplateDepth,
    pub template_coloring: TemplateColoring,
    /// Polygon method: largest allowed distance, in pixels, between the true silhouette and the
    /// tessellated one; the tessellation level per sphere is chosen from it.
    pub polygon_max_error_px: f32,
    /// Polygon method: Phong (default) or Gouraud.
    pub polygon_shading: PolygonShading,
    /// Draw `SphereScene::bonds` as cylinders after the spheres (every method; see the crate docs).
    pub draw_bonds: bool,
}

impl Options {
    /// Defaults for a method: 256² Seed 002 images, 128² finest template with billboard depth and
    /// hue recolouring, polygon silhouettes within 0.25 px, bonds drawn.
    pub fn new(method: Method, lighting: Lighting) -> Options {
        Options {
            method,
            lighting,
            background: [0, 0, 0, 255],
            lut_size: 256,
            template_size: 128,
            template_depth: TemplateDepth::Billboard,
            template_coloring: TemplateColoring::HueRecolor,
            polygon_max_error_px: 0.25,
            polygon_shading: PolygonShading::Phong,
            draw_bonds: true,
        }
    }
}

/// What happened to the spheres of a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Spheres that reached the pixel stage.
    pub drawn: usize,
    /// Valid spheres outside the view frustum (including behind the camera).
    pub culled: usize,
    /// Spheres skipped for a non-finite centre, a non-positive or non-finite radius or an unknown
    /// kind.
    pub skipped_invalid: usize,
    /// Bonds that reached the pixel stage (0 when [`Options::draw_bonds`] is off).
    pub bonds_drawn: usize,
    /// Valid bonds outside the view frustum (including behind the camera) or covering no pixel
    /// centre.
    pub bonds_culled: usize,
    /// Bonds skipped: an atom index out of range, an atom that is itself skipped (see
    /// `skipped_invalid`), two atoms at the same centre, or a non-positive or non-finite
    /// radius ([`crate::SphereScene::bond_radius_of`]).
    pub bonds_skipped: usize,
}
