//! A colour bar legend drawn onto a rendered image (and, with the same font, a one-line caption
//! at the top left, [`draw_caption`], atom labels, [`draw_atom_label`], and a coordinate tripod
//! at the bottom left, [`draw_axes_tripod`]): the colour map from
//! the range's maximum (top) to its minimum (bottom) in a thin dark frame, tick labels for the
//! minimum, the middle and the maximum beside it and a title above, on a light backdrop at the
//! right edge of the image.
//!
//! The image is 8-bit sRGB RGBA with straight (not premultiplied) alpha, row-major, row 0 at
//! the top, as a [`Frame`](texmap_core::frame::Frame) and a PNG hold it.
//!
//! # Layout
//!
//! Everything scales with the image height `h`: the bar's colour area has the largest odd row
//! count not above `h / 2`, its middle row at row `h / 2` (integer division), and every other
//! size is a multiple of an integer scale `s = max(1, round(h / 360))` (1 for 300-pixel images, 2
//! for 720, 3 for 1080), so text pixels stay whole `s`-by-`s` blocks and read crisply:
//!
//! | part | size |
//! |---|---|
//! | margin to the image edges, padding inside the backdrop | `4s` each |
//! | bar colour area | `12s` wide |
//! | frame around the bar, tick marks | `ceil(s / 2)` thick; ticks `3s` long, then `3s` to the label |
//! | glyph cell | `5s` wide plus `s` spacing, `8s` tall (7 above the baseline, 1 descender) |
//!
//! Row `y` of the bar shows `map.srgb(t)` with `t = (bottom - y) / (rows - 1)`: the top row is
//! exactly the colour of `t = 1` (`max`), the bottom row that of `t = 0` (`min`), the middle row
//! that of `t = 0.5`. The title may widen the backdrop up to half the image width (or the width
//! the bar and labels need, if larger); characters past that are dropped. When the backdrop does
//! not fit inside the margins, or the bar has fewer than three label heights of rows, nothing is
//! drawn and [`draw_color_bar`] returns false.
//!
//! # Backdrop and colours
//!
//! The backdrop is near-white sRGB 248 at 80 % opacity, blended in linear light over the image;
//! pixels it covers become opaque, a transparent pixel counting as backdrop colour beneath it,
//! so the legend reads on dark, light and transparent renders alike. Text, frame and ticks are
//! opaque sRGB 24 grey, the bar opaque map colours (`round(c * 255)`, as
//! [`Palette::kind_of`](crate::palette::Palette::kind_of) quantises).
//!
//! # Labels
//!
//! About three significant digits, as short as the value allows: fixed notation for magnitudes
//! from 0.001 to below 9999.5 with trailing zeros dropped (`0.125`, `-3.2`, `42`, `1234`), else
//! scientific with a signed two-digit exponent (`1.5e+04`, `-2e-05`); zero is `0`.
//!
//! # Font
//!
//! A 5x7 pixel font of our own for printable ASCII 32..=126 with one descender row, one `u64`
//! per glyph. Other characters of a title are drawn as `?`.
//!
//! # Edge cases
//!
//! - `min == max`: a one-coloured bar, the colour of `t = 0.5` (the middle of a range of no
//!   width), and three equal labels.
//! - `min > max`: drawn as given: `max` labels the top, coloured as `t = 1`.
//! - NaN or infinite `min` or `max`: nothing is drawn and the result is false; a bar labelled
//!   `NaN` would explain nothing.
//!
//! Drawing is deterministic (one thread, a fixed order of operations: the same input gives the
//! same bytes) and allocates nothing.

use std::fmt::Write as _;

use texmap_core::color::{linear_to_srgb8_exact, srgb8_to_linear};

use crate::colormap::Colormap;

/// A colour bar: the map, the values of its ends, and the title above it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColorBar<'a> {
    /// The colour map, `t = 0` at `min` and `t = 1` at `max`.
    pub map: Colormap,
    /// The value of `t = 0`, at the bottom of the bar.
    pub min: f32,
    /// The value of `t = 1`, at the top of the bar.
    pub max: f32,
    /// The title above the bar (for example the quantity and its unit); empty for none.
    pub title: &'a str,
}

/// Draws `bar` at the right edge of the `width` x `height` sRGB RGBA image `rgba` (row-major,
/// row 0 at the top), vertically centred: the map from `max` (top) to `min` (bottom), a thin
/// dark frame, tick labels for `min`, the middle and `max` beside it, and the title above it,
/// all on a light backdrop (see the module docs for sizes and colours).
///
/// Returns false and draws nothing when the image is too small to hold the legend legibly, or
/// when `min` or `max` is NaN or infinite.
///
/// # Panics
///
/// If `rgba.len() != width * height * 4`.
///
/// # Examples
///
/// ```
/// use texmap_md_scene::{ColorBar, Colormap, draw_color_bar};
///
/// let (width, height) = (640, 480);
/// let mut rgba = vec![0u8; width * height * 4]; // transparent
/// let bar = ColorBar { map: Colormap::Coolwarm, min: -0.8, max: 0.8, title: "charge (e)" };
/// assert!(draw_color_bar(&mut rgba, width, height, &bar));
///
/// // The bar's middle row holds coolwarm's centre colour, near white, opaque.
/// let centre = Colormap::Coolwarm.srgb(0.5).map(|c| (c * 255.0).round() as u8);
/// let middle = &rgba[height / 2 * width * 4..(height / 2 + 1) * width * 4];
/// assert!(middle.chunks_exact(4).any(|px| px == [centre[0], centre[1], centre[2], 255]));
/// // The left half of the image stays transparent.
/// assert!(middle[..width / 2 * 4].iter().all(|&b| b == 0));
///
/// // Too small to read: nothing drawn.
/// let mut tiny = vec![0u8; 20 * 20 * 4];
/// assert!(!draw_color_bar(&mut tiny, 20, 20, &bar));
/// assert!(tiny.iter().all(|&b| b == 0));
/// ```
pub fn draw_color_bar(rgba: &mut [u8], width: usize, height: usize, bar: &ColorBar) -> bool {
    check_buffer("draw_color_bar", rgba, width, height);
    let Some(layout) = Layout::new(width, height, bar) else {
        return false;
    };
    let mut image = Image { rgba, width };

    // Backdrop, then the frame as a dark rectangle the bar's colours are drawn inside.
    image.blend_backdrop(layout.panel);
    image.fill(layout.bar.grow(layout.frame), INK);
    for y in layout.bar.y0..layout.bar.y1 {
        let t = if bar.min == bar.max {
            0.5
        } else {
            (layout.bar.y1 - 1 - y) as f32 / (layout.bar.height() - 1) as f32
        };
        let c = bar.map.srgb(t).map(|c| (c * 255.0).round() as u8);
        image.fill(
            Rect {
                y0: y,
                y1: y + 1,
                ..layout.bar
            },
            [c[0], c[1], c[2], 255],
        );
    }

    // Ticks and labels of max, the middle and min.
    let s = layout.scale;
    for (row, label) in layout.tick_rows.into_iter().zip(&layout.labels) {
        let y0 = row - (layout.frame - 1) / 2;
        let x0 = layout.bar.x1 + layout.frame;
        image.fill(
            Rect {
                x0,
                x1: x0 + layout.tick,
                y0,
                y1: y0 + layout.frame,
            },
            INK,
        );
        let top = row - (CAP_HEIGHT * s - 1) / 2;
        image.text(layout.label_x, top, s, label.as_str().chars(), layout.panel);
    }
    if layout.title_chars > 0 {
        let title = bar.title.chars().take(layout.title_chars);
        image.text(layout.title_x, layout.title_y, s, title, layout.panel);
    }
    true
}

/// Draws `text` as a caption at the top left of `rgba` (8-bit sRGB RGBA, `width` x `height`,
/// row 0 at the top): the colour bar's font at its scale, on the same backdrop, one line, the
/// characters that do not fit within half the image width dropped (non-ASCII ones but `Å` and `°` drawn as `?`).
/// Returns the number of characters drawn (0, and nothing drawn, for an empty text or an image
/// too small for one character). Movies use it for the frame's time (`texmap render --label`).
///
/// ```
/// use texmap_md_scene::draw_caption;
/// let (width, height) = (360, 240);
/// let mut rgba = vec![0u8; width * height * 4];
/// assert_eq!(draw_caption(&mut rgba, width, height, "t = 2.5 ns"), 10);
/// // Top left is covered, the rest of the image untouched.
/// assert_eq!(rgba[(6 * width + 6) * 4 + 3], 255);
/// assert!(rgba[(height / 2 * width) * 4..].iter().all(|&b| b == 0));
/// ```
pub fn draw_caption(rgba: &mut [u8], width: usize, height: usize, text: &str) -> usize {
    check_buffer("draw_caption", rgba, width, height);
    let s = scale_of(height);
    let (margin, pad) = (4 * s, 4 * s);
    let room = (width / 2).saturating_sub(margin + 2 * pad);
    let chars = text.chars().count().min((room + s) / (ADVANCE * s));
    let panel = Rect {
        x0: margin,
        y0: margin,
        x1: margin + 2 * pad + (chars * ADVANCE * s).saturating_sub(s),
        y1: margin + 2 * pad + CELL_HEIGHT * s,
    };
    if chars == 0 || panel.y1 + margin > height {
        return 0;
    }
    let mut image = Image { rgba, width };
    image.blend_backdrop(panel);
    image.text(
        margin + pad,
        margin + pad,
        s,
        text.chars().take(chars),
        panel,
    );
    chars
}

/// Draws `text` as an atom's label (`texmap render --atom-label`): the colour bar's font at its
/// scale `s`, on the same backdrop with `s` of padding, centred horizontally on `anchor` (pixel
/// coordinates, x right, y down: the atom's projected centre) with the backdrop's bottom edge `2s`
/// above it, so the label sits just over the atom. A label that would cross an image edge is
/// moved inside it; nothing is drawn for an anchor outside the image, a non-finite anchor, an
/// empty text or an image too small for the label. At most [`MAX_LABEL_CHARS`] characters are
/// drawn. Returns whether the label was drawn.
///
/// ```
/// use texmap_md_scene::draw_atom_label;
/// let (width, height) = (360, 240);
/// let mut rgba = vec![0u8; width * height * 4];
/// assert!(draw_atom_label(&mut rgba, width, height, [180.0, 120.0], "ALA 10"));
/// // The backdrop, 37 x 10 px (6 glyph cells of 6 px less the last spacing column, 8 px rows,
/// // 1 px padding per side), spans x = 162..=198 around 180 and ends 2 px above row 120.
/// let opaque = |x: usize, y: usize| rgba[(y * width + x) * 4 + 3] == 255;
/// assert!(opaque(162, 117) && opaque(198, 117) && opaque(180, 108));
/// assert!(!opaque(161, 117) && !opaque(199, 117) && !opaque(180, 118) && !opaque(180, 107));
/// assert!(!draw_atom_label(&mut rgba, width, height, [-5.0, 120.0], "off screen"));
/// ```
pub fn draw_atom_label(
    rgba: &mut [u8],
    width: usize,
    height: usize,
    anchor: [f32; 2],
    text: &str,
) -> bool {
    check_buffer("draw_atom_label", rgba, width, height);
    let [ax, ay] = anchor;
    let inside = ax.is_finite() && ay.is_finite() && ax >= 0.0 && ay >= 0.0;
    if !inside || ax >= width as f32 || ay >= height as f32 {
        return false;
    }
    let s = scale_of(height);
    let chars = text.chars().count().min(MAX_LABEL_CHARS);
    let panel_w = (chars * ADVANCE * s).saturating_sub(s) + 2 * s;
    let panel_h = CELL_HEIGHT * s + 2 * s;
    if chars == 0 || panel_w > width || panel_h > height {
        return false;
    }
    // Centred on the anchor, ending 2s above it, then moved inside the image.
    let x0 = (ax.floor() as i64 - (panel_w / 2) as i64).clamp(0, (width - panel_w) as i64);
    let y1 = ay.floor() as i64 - 2 * s as i64;
    let y0 = (y1 - panel_h as i64).clamp(0, (height - panel_h) as i64);
    let panel = Rect {
        x0: x0 as usize,
        y0: y0 as usize,
        x1: x0 as usize + panel_w,
        y1: y0 as usize + panel_h,
    };
    let mut image = Image { rgba, width };
    image.blend_backdrop(panel);
    image.text(
        panel.x0 + s,
        panel.y0 + s,
        s,
        text.chars().take(chars),
        panel,
    );
    true
}

/// One axis of [`draw_axes_tripod`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TripodAxis {
    /// The axis's unit direction in eye space (x right, y up, z toward the viewer):
    /// `Camera::dir_to_eye` of a world direction.
    pub eye: [f32; 3],
    /// Its label (one character: `x`, `a`, ...).
    pub label: char,
    /// Its colour, sRGB.
    pub color: [u8; 3],
}

/// Draws coordinate axes as a tripod at the bottom left of the image (OVITO's coordinate
/// tripod, VESTA's axes), on the legend's backdrop: from a common origin a line per axis, its
/// length on the screen `16s` times the axis's projection (short for an axis toward or away
/// from the viewer), anti-aliased, `1.5s` wide, in the axis's colour, with its label beyond the
/// tip; the axis nearest the viewer drawn last. Returns false (nothing drawn) when the image is
/// too small for it (the panel needs `60s` square and the margin).
///
/// ```
/// use texmap_md_scene::{TripodAxis, draw_axes_tripod};
/// let (width, height) = (320, 240);
/// let mut rgba = vec![0u8; width * height * 4];
/// let axes = [
///     TripodAxis { eye: [1.0, 0.0, 0.0], label: 'x', color: [220, 40, 40] },
///     TripodAxis { eye: [0.0, 1.0, 0.0], label: 'y', color: [40, 160, 40] },
///     TripodAxis { eye: [0.0, 0.0, 1.0], label: 'z', color: [40, 80, 230] },
/// ];
/// assert!(draw_axes_tripod(&mut rgba, width, height, &axes));
/// ```
pub fn draw_axes_tripod(rgba: &mut [u8], width: usize, height: usize, axes: &[TripodAxis]) -> bool {
    check_buffer("draw_axes_tripod", rgba, width, height);
    let s = scale_of(height);
    let (margin, reach) = (4 * s, 16 * s);
    // The origin in the middle of a square that holds every tip and label around it.
    let half = reach + 2 * ADVANCE * s + 2 * s;
    let side = 2 * half;
    if side + 2 * margin > width || side + 2 * margin > height {
        return false;
    }
    let panel = Rect {
        x0: margin,
        y0: height - margin - side,
        x1: margin + side,
        y1: height - margin,
    };
    let mut image = Image { rgba, width };
    image.blend_backdrop(panel);
    // On a pixel centre, so that an axis along a row or column covers it whole.
    let origin = [
        (panel.x0 + half) as f32 + 0.5,
        (panel.y0 + half) as f32 + 0.5,
    ];
    let mut order: Vec<&TripodAxis> = axes
        .iter()
        .filter(|a| a.eye.iter().all(|v| v.is_finite()))
        .collect();
    order.sort_by(|a, b| a.eye[2].total_cmp(&b.eye[2]));
    for axis in order {
        let [x, y, _] = axis.eye;
        let dir = [x, -y];
        let tip = [
            origin[0] + dir[0] * reach as f32,
            origin[1] + dir[1] * reach as f32,
        ];
        image.segment(panel, origin, tip, 1.5 * s as f32, axis.color);
        // The label centred a glyph's half-width beyond the tip (beside the origin for an axis
        // that points at the viewer).
        let len = (dir[0] * dir[0] + dir[1] * dir[1]).sqrt();
        let unit = if len > 0.2 {
            [dir[0] / len, dir[1] / len]
        } else {
            [
                std::f32::consts::FRAC_1_SQRT_2,
                -std::f32::consts::FRAC_1_SQRT_2,
            ]
        };
        let gap = (ADVANCE * s) as f32;
        let centre = [tip[0] + unit[0] * gap, tip[1] + unit[1] * gap];
        let x0 = (centre[0] - (GLYPH_WIDTH * s) as f32 / 2.0)
            .round()
            .max(0.0) as usize;
        let y0 = (centre[1] - (CAP_HEIGHT * s) as f32 / 2.0).round().max(0.0) as usize;
        let mut ink = [0u8; 4];
        ink[..3].copy_from_slice(&axis.color);
        ink[3] = 255;
        image.text_in(x0, y0, s, std::iter::once(axis.label), panel, ink);
    }
    true
}

/// The longest atom label [`draw_atom_label`] draws, in characters.
pub const MAX_LABEL_CHARS: usize = 40;

/// Panics unless `rgba` holds `width` x `height` RGBA pixels (a caller's bug, named after
/// `what`).
fn check_buffer(what: &str, rgba: &[u8], width: usize, height: usize) {
    let expected = width.checked_mul(height).and_then(|n| n.checked_mul(4));
    assert!(
        expected == Some(rgba.len()),
        "{what}: {width} x {height} RGBA needs {expected:?} bytes, got {}",
        rgba.len()
    );
}

/// Text, frame and tick colour: opaque dark grey (sRGB).
const INK: [u8; 4] = [24, 24, 24, 255];
/// Backdrop colour (sRGB code per channel) and opacity.
const BACKDROP: u8 = 248;
const BACKDROP_OPACITY: f32 = 0.8;

/// Glyph cell in font pixels: 5 wide plus one column of spacing, 7 rows above the baseline and
/// one descender row.
const GLYPH_WIDTH: usize = 5;
const ADVANCE: usize = GLYPH_WIDTH + 1;
const CAP_HEIGHT: usize = 7;
const CELL_HEIGHT: usize = 8;

/// The font scale of an image `height` pixels tall: `max(1, round(height / 360))`.
fn scale_of(height: usize) -> usize {
    ((height + 180) / 360).max(1)
}

/// A pixel rectangle, half-open: columns `x0..x1`, rows `y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Rect {
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
}

impl Rect {
    fn height(self) -> usize {
        self.y1 - self.y0
    }

    /// The rectangle grown by `d` on every side (the caller keeps it inside the image).
    fn grow(self, d: usize) -> Rect {
        Rect {
            x0: self.x0 - d,
            y0: self.y0 - d,
            x1: self.x1 + d,
            y1: self.y1 + d,
        }
    }

    fn contains(self, x: usize, y: usize) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }
}

/// Where everything goes; `None` when the legend does not fit (see the module docs).
#[derive(Debug)]
struct Layout {
    scale: usize,
    /// The backdrop, inside the image's margins.
    panel: Rect,
    /// The bar's colour area, inside the frame.
    bar: Rect,
    /// Frame and tick thickness, and the ticks' length.
    frame: usize,
    tick: usize,
    /// Rows of the ticks of max, the middle and min.
    tick_rows: [usize; 3],
    /// Labels of max, the middle and min, and their left edge.
    labels: [Label; 3],
    label_x: usize,
    /// Title characters drawn (0 for none) and the top left of the first.
    title_chars: usize,
    title_x: usize,
    title_y: usize,
}

impl Layout {
    fn new(width: usize, height: usize, bar: &ColorBar) -> Option<Layout> {
        if !(bar.min.is_finite() && bar.max.is_finite()) {
            return None;
        }
        let s = scale_of(height);
        let (margin, pad, frame, tick) = (4 * s, 4 * s, s.div_ceil(2), 3 * s);
        // A gap as long as the tick, so a tick never reads as the label's minus sign.
        let label_gap = 3 * s;
        let text_width = |chars: usize| (chars * ADVANCE * s).saturating_sub(s);

        // The bar: the largest odd row count not above h / 2, centred; three label heights at
        // least.
        let rows = (height / 2).saturating_sub(1) | 1;
        if rows < 3 * CELL_HEIGHT * s {
            return None;
        }
        let bar_y0 = (height - rows).div_ceil(2); // the middle row is height / 2
        let tick_rows = [bar_y0, bar_y0 + rows / 2, bar_y0 + rows - 1];

        // Labels of max, the middle (no overflow for huge finite ends) and min.
        let mid = 0.5 * bar.min + 0.5 * bar.max;
        let labels = [bar.max, mid, bar.min].map(Label::of);
        let label_chars = labels.iter().map(|l| l.len).max().unwrap_or(0);
        let block_width = 2 * frame + 12 * s + tick + label_gap + text_width(label_chars);

        // The title widens the backdrop up to half the image (or the block's width).
        let inner_max = width.checked_sub(2 * margin + 2 * pad)?;
        let title_max = block_width.max(width / 2).min(inner_max);
        let title_len = bar.title.chars().count();
        let title_chars = title_len.min((title_max + s) / (ADVANCE * s));
        let content_width = block_width.max(text_width(title_chars));
        if content_width > inner_max {
            return None;
        }

        // Vertical extent: frame and the half labels over the bar's ends, the title above.
        let label_top = tick_rows[0].checked_sub((CAP_HEIGHT * s - 1) / 2)?;
        let mut top = label_top.min(bar_y0.checked_sub(frame)?);
        let label_bottom = tick_rows[2] - (CAP_HEIGHT * s - 1) / 2 + CELL_HEIGHT * s;
        let bottom = label_bottom.max(bar_y0 + rows + frame);
        let mut title_y = 0;
        if title_chars > 0 {
            title_y = top.checked_sub(CELL_HEIGHT * s + 3 * s)?;
            top = title_y;
        }
        let panel = Rect {
            x0: width - margin - content_width - 2 * pad,
            y0: top.checked_sub(pad)?,
            x1: width - margin,
            y1: bottom + pad,
        };
        if panel.y0 < margin || panel.y1 + margin > height {
            return None;
        }

        // Horizontal placement: the block and the title centred in the backdrop.
        let content_x = panel.x0 + pad;
        let block_x = content_x + (content_width - block_width) / 2;
        let bar_x0 = block_x + frame;
        let bar = Rect {
            x0: bar_x0,
            y0: bar_y0,
            x1: bar_x0 + 12 * s,
            y1: bar_y0 + rows,
        };
        Some(Layout {
            scale: s,
            panel,
            bar,
            frame,
            tick,
            tick_rows,
            labels,
            label_x: bar.x1 + frame + tick + label_gap,
            title_chars,
            title_x: content_x + (content_width - text_width(title_chars)) / 2,
            title_y,
        })
    }
}

/// An RGBA8 image being drawn on.
struct Image<'a> {
    rgba: &'a mut [u8],
    width: usize,
}

impl Image<'_> {
    fn fill(&mut self, r: Rect, c: [u8; 4]) {
        for y in r.y0..r.y1 {
            let row = &mut self.rgba[(y * self.width + r.x0) * 4..(y * self.width + r.x1) * 4];
            for px in row.chunks_exact_mut(4) {
                px.copy_from_slice(&c);
            }
        }
    }

    /// The backdrop over `r`, in linear light: `out = o B + (1 - o) (a C + (1 - a) B)` for the
    /// backdrop B at opacity o over the pixel C of alpha a; the result is opaque.
    fn blend_backdrop(&mut self, r: Rect) {
        let b = srgb8_to_linear(BACKDROP);
        for y in r.y0..r.y1 {
            let row = &mut self.rgba[(y * self.width + r.x0) * 4..(y * self.width + r.x1) * 4];
            for px in row.chunks_exact_mut(4) {
                let a = px[3] as f32 / 255.0;
                for c in &mut px[..3] {
                    let under = a * srgb8_to_linear(*c) + (1.0 - a) * b;
                    *c = linear_to_srgb8_exact(
                        BACKDROP_OPACITY * b + (1.0 - BACKDROP_OPACITY) * under,
                    );
                }
                px[3] = 255;
            }
        }
    }

    /// `text` in [`INK`] at scale `s`, the first cell's top left at (`x`, `y`); pixels outside
    /// `clip` are skipped.
    fn text(&mut self, x: usize, y: usize, s: usize, text: impl Iterator<Item = char>, clip: Rect) {
        self.text_in(x, y, s, text, clip, INK);
    }

    /// A line from `a` to `b` (pixel coordinates) `width` pixels wide in `color`, anti-aliased
    /// by each pixel centre's distance from the segment, blended in linear light; pixels outside
    /// `clip` are left.
    fn segment(&mut self, clip: Rect, a: [f32; 2], b: [f32; 2], width: f32, color: [u8; 3]) {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len2 = dx * dx + dy * dy;
        let r = width * 0.5;
        let lo_x = (a[0].min(b[0]) - r - 1.0).max(clip.x0 as f32) as usize;
        let hi_x = ((a[0].max(b[0]) + r + 2.0) as usize).min(clip.x1);
        let lo_y = (a[1].min(b[1]) - r - 1.0).max(clip.y0 as f32) as usize;
        let hi_y = ((a[1].max(b[1]) + r + 2.0) as usize).min(clip.y1);
        for y in lo_y..hi_y {
            for x in lo_x..hi_x {
                let (px, py) = (x as f32 + 0.5 - a[0], y as f32 + 0.5 - a[1]);
                let t = if len2 > 0.0 {
                    ((px * dx + py * dy) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (ex, ey) = (px - t * dx, py - t * dy);
                let cover = (r + 0.5 - (ex * ex + ey * ey).sqrt()).clamp(0.0, 1.0);
                if cover <= 0.0 {
                    continue;
                }
                let px = &mut self.rgba[(y * self.width + x) * 4..(y * self.width + x) * 4 + 4];
                for (c, &over) in px[..3].iter_mut().zip(&color) {
                    let v = cover * srgb8_to_linear(over) + (1.0 - cover) * srgb8_to_linear(*c);
                    *c = linear_to_srgb8_exact(v);
                }
                px[3] = 255;
            }
        }
    }

    /// [`Image::text`] in the colour `ink`.
    fn text_in(
        &mut self,
        x: usize,
        y: usize,
        s: usize,
        text: impl Iterator<Item = char>,
        clip: Rect,
        ink: [u8; 4],
    ) {
        for (i, ch) in text.enumerate() {
            let glyph = glyph(ch);
            let cell_x = x + i * ADVANCE * s;
            for row in 0..CELL_HEIGHT {
                let bits = (glyph >> (8 * (CELL_HEIGHT - 1 - row))) as u8;
                for col in 0..GLYPH_WIDTH {
                    if bits & (0x10 >> col) == 0 {
                        continue;
                    }
                    let (px, py) = (cell_x + col * s, y + row * s);
                    if clip.contains(px, py) && clip.contains(px + s - 1, py + s - 1) {
                        self.fill(
                            Rect {
                                x0: px,
                                y0: py,
                                x1: px + s,
                                y1: py + s,
                            },
                            ink,
                        );
                    }
                }
            }
        }
    }
}

/// A tick label, formatted into a fixed buffer (see the module docs for the format).
#[derive(Clone, Copy, Debug)]
struct Label {
    buf: [u8; 24],
    len: usize,
}

impl Label {
    const EMPTY: Label = Label {
        buf: [0; 24],
        len: 0,
    };

    fn as_str(&self) -> &str {
        // Only ASCII is ever written (digits, '-', '+', '.', 'e').
        std::str::from_utf8(&self.buf[..self.len]).unwrap_or("?")
    }

    fn push(&mut self, b: u8) {
        if self.len < self.buf.len() {
            self.buf[self.len] = b;
            self.len += 1;
        }
    }

    /// The compact label of a finite value.
    fn of(v: f32) -> Label {
        let mut out = Label::EMPTY;
        if v == 0.0 {
            out.push(b'0');
            return out;
        }
        let a = v.abs();
        let mut raw = Label::EMPTY;
        if (1e-3..9999.5).contains(&a) {
            // Fixed: decimals for three significant digits (compared with powers of ten rather
            // than through log10, whose rounding varies by platform), trailing zeros dropped.
            let decimals = [100.0, 10.0, 1.0, 0.1, 0.01]
                .iter()
                .position(|&p| a >= p)
                .unwrap_or(5);
            let _ = write!(raw, "{v:.decimals$}");
            let digits = trim_fraction(raw.as_str());
            digits.bytes().for_each(|b| out.push(b));
        } else {
            // Scientific: Rust writes "1.50e4" / "-2.00e-5"; keep the mantissa's significant
            // digits and write the exponent signed, at least two digits.
            let _ = write!(raw, "{v:.2e}");
            let (mantissa, exponent) = raw.as_str().split_once('e').unwrap_or((raw.as_str(), "0"));
            trim_fraction(mantissa).bytes().for_each(|b| out.push(b));
            let exponent: i32 = exponent.parse().unwrap_or(0);
            let sign = if exponent < 0 { '-' } else { '+' };
            let _ = write!(out, "e{sign}{:02}", exponent.unsigned_abs());
        }
        out
    }
}

impl std::fmt::Write for Label {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        if self.len + s.len() > self.buf.len() {
            return Err(std::fmt::Error);
        }
        s.bytes().for_each(|b| self.push(b));
        Ok(())
    }
}

/// `s` without trailing zeros after a decimal point, nor a bare trailing point.
fn trim_fraction(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// The glyph of `c` ([`FONT`], and `Å` and `°` for the measurements' units), `?` for other
/// characters outside printable ASCII.
fn glyph(c: char) -> u64 {
    match c {
        'Å' => 0x04_0a_04_0a_11_1f_11_00,
        '°' => 0x0c_12_12_0c_00_00_00_00,
        ' '..='~' => FONT[c as usize - 32],
        _ => FONT['?' as usize - 32],
    }
}

/// The 5x7 font, printable ASCII 32..=126 in order. One glyph per `u64`: the most significant
/// byte is the top row, eight rows (seven above the baseline, one descender); in each byte bit 4
/// is the left column and bit 0 the right, bits 5..=7 are zero.
const FONT: [u64; 95] = [
    0x00_00_00_00_00_00_00_00, // ' '
    0x04_04_04_04_04_00_04_00, // '!'
    0x0a_0a_0a_00_00_00_00_00, // '"'
    0x0a_0a_1f_0a_1f_0a_0a_00, // '#'
    0x04_0f_14_0e_05_1e_04_00, // '$'
    0x18_19_02_04_08_13_03_00, // '%'
    0x0c_12_14_08_15_12_0d_00, // '&'
    0x04_04_04_00_00_00_00_00, // '\''
    0x02_04_08_08_08_04_02_00, // '('
    0x08_04_02_02_02_04_08_00, // ')'
    0x00_04_15_0e_15_04_00_00, // '*'
    0x00_04_04_1f_04_04_00_00, // '+'
    0x00_00_00_00_00_0c_04_08, // ','
    0x00_00_00_1f_00_00_00_00, // '-'
    0x00_00_00_00_00_0c_0c_00, // '.'
    0x00_01_02_04_08_10_00_00, // '/'
    0x0e_11_13_15_19_11_0e_00, // '0'
    0x04_0c_04_04_04_04_0e_00, // '1'
    0x0e_11_01_02_04_08_1f_00, // '2'
    0x1f_02_04_02_01_11_0e_00, // '3'
    0x02_06_0a_12_1f_02_02_00, // '4'
    0x1f_10_1e_01_01_11_0e_00, // '5'
    0x06_08_10_1e_11_11_0e_00, // '6'
    0x1f_01_02_04_08_08_08_00, // '7'
    0x0e_11_11_0e_11_11_0e_00, // '8'
    0x0e_11_11_0f_01_02_0c_00, // '9'
    0x00_0c_0c_00_0c_0c_00_00, // ':'
    0x00_0c_0c_00_0c_04_08_00, // ';'
    0x02_04_08_10_08_04_02_00, // '<'
    0x00_00_1f_00_1f_00_00_00, // '='
    0x08_04_02_01_02_04_08_00, // '>'
    0x0e_11_01_02_04_00_04_00, // '?'
    0x0e_11_01_0d_15_15_0e_00, // '@'
    0x0e_11_11_1f_11_11_11_00, // 'A'
    0x1e_11_11_1e_11_11_1e_00, // 'B'
    0x0e_11_10_10_10_11_0e_00, // 'C'
    0x1c_12_11_11_11_12_1c_00, // 'D'
    0x1f_10_10_1e_10_10_1f_00, // 'E'
    0x1f_10_10_1e_10_10_10_00, // 'F'
    0x0e_11_10_17_11_11_0f_00, // 'G'
    0x11_11_11_1f_11_11_11_00, // 'H'
    0x0e_04_04_04_04_04_0e_00, // 'I'
    0x07_02_02_02_02_12_0c_00, // 'J'
    0x11_12_14_18_14_12_11_00, // 'K'
    0x10_10_10_10_10_10_1f_00, // 'L'
    0x11_1b_15_15_11_11_11_00, // 'M'
    0x11_11_19_15_13_11_11_00, // 'N'
    0x0e_11_11_11_11_11_0e_00, // 'O'
    0x1e_11_11_1e_10_10_10_00, // 'P'
    0x0e_11_11_11_15_12_0d_00, // 'Q'
    0x1e_11_11_1e_14_12_11_00, // 'R'
    0x0f_10_10_0e_01_01_1e_00, // 'S'
    0x1f_04_04_04_04_04_04_00, // 'T'
    0x11_11_11_11_11_11_0e_00, // 'U'
    0x11_11_11_11_11_0a_04_00, // 'V'
    0x11_11_11_15_15_15_0a_00, // 'W'
    0x11_11_0a_04_0a_11_11_00, // 'X'
    0x11_11_0a_04_04_04_04_00, // 'Y'
    0x1f_01_02_04_08_10_1f_00, // 'Z'
    0x0e_08_08_08_08_08_0e_00, // '['
    0x00_10_08_04_02_01_00_00, // '\\'
    0x0e_02_02_02_02_02_0e_00, // ']'
    0x04_0a_11_00_00_00_00_00, // '^'
    0x00_00_00_00_00_00_00_1f, // '_'
    0x08_04_02_00_00_00_00_00, // '`'
    0x00_00_0e_01_0f_11_0f_00, // 'a'
    0x10_10_16_19_11_11_1e_00, // 'b'
    0x00_00_0e_10_10_11_0e_00, // 'c'
    0x01_01_0d_13_11_11_0f_00, // 'd'
    0x00_00_0e_11_1f_10_0e_00, // 'e'
    0x06_09_08_1c_08_08_08_00, // 'f'
    0x00_00_0f_11_11_0f_01_0e, // 'g'
    0x10_10_16_19_11_11_11_00, // 'h'
    0x04_00_0c_04_04_04_0e_00, // 'i'
    0x02_00_06_02_02_02_12_0c, // 'j'
    0x10_10_12_14_18_14_12_00, // 'k'
    0x0c_04_04_04_04_04_0e_00, // 'l'
    0x00_00_1a_15_15_11_11_00, // 'm'
    0x00_00_16_19_11_11_11_00, // 'n'
    0x00_00_0e_11_11_11_0e_00, // 'o'
    0x00_00_1e_11_11_1e_10_10, // 'p'
    0x00_00_0f_11_11_0f_01_01, // 'q'
    0x00_00_16_19_10_10_10_00, // 'r'
    0x00_00_0f_10_0e_01_1e_00, // 's'
    0x08_08_1c_08_08_09_06_00, // 't'
    0x00_00_11_11_11_13_0d_00, // 'u'
    0x00_00_11_11_11_0a_04_00, // 'v'
    0x00_00_11_11_15_15_0a_00, // 'w'
    0x00_00_11_0a_04_0a_11_00, // 'x'
    0x00_00_11_11_11_0f_01_0e, // 'y'
    0x00_00_1f_02_04_08_1f_00, // 'z'
    0x02_04_04_08_04_04_02_00, // '{'
    0x04_04_04_04_04_04_04_00, // '|'
    0x08_04_04_02_04_04_08_00, // '}'
    0x00_00_08_15_02_00_00_00, // '~'
];

#[cfg(test)]
mod tests {
    use super::*;

    const BAR: ColorBar<'static> = ColorBar {
        map: Colormap::Viridis,
        min: -3.2,
        max: 1.5e4,
        title: "velocity (m/s)",
    };

    fn srgb8(map: Colormap, t: f32) -> [u8; 4] {
        let c = map.srgb(t).map(|c| (c * 255.0).round() as u8);
        [c[0], c[1], c[2], 255]
    }

    fn pixel(rgba: &[u8], width: usize, x: usize, y: usize) -> [u8; 4] {
        let i = (y * width + x) * 4;
        [rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]]
    }

    /// A mid-grey opaque image, the legend drawn on it, and its layout.
    fn drawn(width: usize, height: usize, bar: &ColorBar) -> (Vec<u8>, Layout) {
        let mut rgba = [128, 128, 128, 255].repeat(width * height);
        assert!(draw_color_bar(&mut rgba, width, height, bar));
        (rgba, Layout::new(width, height, bar).unwrap())
    }

    #[test]
    fn bar_ends_and_middle_are_the_maps_colours() {
        for map in Colormap::ALL {
            for (w, h) in [(640, 480), (300, 300), (1920, 1080), (401, 333)] {
                let (rgba, l) = drawn(w, h, &ColorBar { map, ..BAR });
                let x = (l.bar.x0 + l.bar.x1) / 2;
                let [top, mid, bottom] = l.tick_rows;
                assert_eq!((top, bottom), (l.bar.y0, l.bar.y1 - 1));
                assert_eq!(mid - top, bottom - mid, "{w}x{h}: middle row not centred");
                assert_eq!(
                    pixel(&rgba, w, x, top),
                    srgb8(map, 1.0),
                    "{} {w}x{h} top",
                    map.name()
                );
                assert_eq!(
                    pixel(&rgba, w, x, mid),
                    srgb8(map, 0.5),
                    "{} {w}x{h} mid",
                    map.name()
                );
                assert_eq!(
                    pixel(&rgba, w, x, bottom),
                    srgb8(map, 0.0),
                    "{} {w}x{h}",
                    map.name()
                );
                // The frame just outside the colour area.
                assert_eq!(pixel(&rgba, w, x, top - 1), INK);
                assert_eq!(pixel(&rgba, w, l.bar.x1, mid), INK);
            }
        }
    }

    #[test]
    fn bar_is_vertically_centred_at_the_right_edge_and_half_the_height() {
        for (w, h) in [(640, 480), (1920, 1080), (300, 300), (555, 333)] {
            let (_, l) = drawn(w, h, &BAR);
            assert_eq!(l.tick_rows[1], h / 2, "{w}x{h}");
            assert!(
                l.bar.height() % 2 == 1 && l.bar.height() * 2 <= h && l.bar.height() * 2 > h - 4
            );
            assert_eq!(l.panel.x1, w - 4 * l.scale);
        }
    }

    #[test]
    fn labels_and_title_put_ink_in_their_areas() {
        let (w, h) = (640, 480);
        let (rgba, l) = drawn(w, h, &BAR);
        let s = l.scale;
        // Each label: ink in the cells right of its tick, and none beyond the text.
        for (row, label) in l.tick_rows.into_iter().zip(&l.labels) {
            let top = row - (CAP_HEIGHT * s - 1) / 2;
            let text_x1 = l.label_x + label.len * ADVANCE * s;
            let ink = |x0: usize, x1: usize| {
                (top..top + CELL_HEIGHT * s)
                    .flat_map(|y| (x0..x1).map(move |x| (x, y)))
                    .filter(|&(x, y)| pixel(&rgba, w, x, y) == INK)
                    .count()
            };
            assert!(
                ink(l.label_x, text_x1) >= 10,
                "label {:?}: too little ink",
                label.as_str()
            );
            assert_eq!(
                ink(text_x1, l.panel.x1),
                0,
                "label {:?}: ink past the text",
                label.as_str()
            );
        }
        let title_ink = (l.title_y..l.title_y + CELL_HEIGHT * s)
            .flat_map(|y| (l.panel.x0..l.panel.x1).map(move |x| (x, y)))
            .filter(|&(x, y)| pixel(&rgba, w, x, y) == INK)
            .count();
        assert!(title_ink >= 30, "title ink {title_ink}");
        assert_eq!(l.title_chars, BAR.title.len());
    }

    #[test]
    fn nothing_outside_the_backdrop_changes() {
        let (w, h) = (640, 480);
        let (rgba, l) = drawn(w, h, &BAR);
        for y in 0..h {
            for x in 0..w {
                if !l.panel.contains(x, y) {
                    assert_eq!(pixel(&rgba, w, x, y), [128, 128, 128, 255], "({x}, {y})");
                }
            }
        }
        // The backdrop lightens grey 128 where nothing else is drawn.
        let corner = pixel(&rgba, w, l.panel.x0, l.panel.y0);
        assert!(
            corner[0] > 200 && corner[0] == corner[1] && corner[3] == 255,
            "{corner:?}"
        );
    }

    #[test]
    fn transparent_images_get_an_opaque_backdrop() {
        let (w, h) = (500, 400);
        let mut rgba = vec![0u8; w * h * 4];
        assert!(draw_color_bar(&mut rgba, w, h, &BAR));
        let l = Layout::new(w, h, &BAR).unwrap();
        for y in 0..h {
            for x in 0..w {
                let a = pixel(&rgba, w, x, y)[3];
                assert_eq!(
                    a,
                    if l.panel.contains(x, y) { 255 } else { 0 },
                    "({x}, {y})"
                );
            }
        }
        // A transparent pixel under the backdrop becomes the backdrop colour itself.
        assert_eq!(
            pixel(&rgba, w, l.panel.x0, l.panel.y0),
            [BACKDROP, BACKDROP, BACKDROP, 255]
        );
    }

    #[test]
    fn too_small_images_draw_nothing() {
        for (w, h) in [
            (0, 0),
            (20, 20),
            (0, 500),
            (500, 0),
            (1, 1000),
            (1000, 1),
            (60, 40),
            (40, 300),
        ] {
            let mut rgba = vec![7u8; w * h * 4];
            assert!(!draw_color_bar(&mut rgba, w, h, &BAR), "{w}x{h}");
            assert!(rgba.iter().all(|&b| b == 7), "{w}x{h} changed");
        }
        // The smallest square that holds the legend at scale 1 does.
        let fits = (40..400)
            .find(|&n| Layout::new(n, n, &BAR).is_some())
            .unwrap();
        assert!(fits < 150, "smallest square {fits}");
    }

    #[test]
    #[should_panic(expected = "draw_color_bar")]
    fn wrong_buffer_length_panics() {
        draw_color_bar(&mut [0u8; 10], 640, 480, &BAR);
    }

    #[test]
    fn long_and_odd_titles_are_clipped_without_panic() {
        let long = "x".repeat(500);
        let odd = "αβγ ☃ \u{0} tab\there ".repeat(40);
        for title in [long.as_str(), odd.as_str(), ""] {
            for (w, h) in [(640, 480), (120, 120), (1920, 1080), (100, 2000)] {
                let mut rgba = vec![0u8; w * h * 4];
                let bar = ColorBar { title, ..BAR };
                if draw_color_bar(&mut rgba, w, h, &bar) {
                    let l = Layout::new(w, h, &bar).unwrap();
                    assert!(l.panel.x0 >= 4 * l.scale && l.panel.x1 <= w && l.panel.y1 <= h);
                    assert!(l.title_chars <= title.chars().count());
                    let title_w = l.title_chars * ADVANCE * l.scale;
                    assert!(l.title_x + title_w <= l.panel.x1 + l.scale);
                }
            }
        }
        let l = Layout::new(
            640,
            480,
            &ColorBar {
                title: &long,
                ..BAR
            },
        )
        .unwrap();
        assert!(
            l.title_chars > 10 && l.title_chars < 500,
            "{}",
            l.title_chars
        );
        assert!(l.panel.x1 - l.panel.x0 <= 640 / 2 + 8 * l.scale);
    }

    #[test]
    fn non_finite_ends_draw_nothing() {
        let (w, h) = (640, 480);
        for (min, max) in [
            (f32::NAN, 1.0),
            (0.0, f32::NAN),
            (f32::NEG_INFINITY, 1.0),
            (0.0, f32::INFINITY),
            (f32::NAN, f32::NAN),
        ] {
            let mut rgba = vec![9u8; w * h * 4];
            assert!(!draw_color_bar(
                &mut rgba,
                w,
                h,
                &ColorBar { min, max, ..BAR }
            ));
            assert!(rgba.iter().all(|&b| b == 9), "{min} {max}");
        }
        // Huge finite ends: the middle does not overflow.
        let (_, l) = drawn(
            w,
            h,
            &ColorBar {
                min: -f32::MAX,
                max: f32::MAX,
                ..BAR
            },
        );
        assert_eq!(l.labels.map(|l| l.len), [7, 1, 8]);
        assert_eq!(l.labels[0].as_str(), "3.4e+38");
    }

    #[test]
    fn equal_ends_give_one_colour_and_equal_labels() {
        let (w, h) = (640, 480);
        let bar = ColorBar {
            min: 2.5,
            max: 2.5,
            ..BAR
        };
        let (rgba, l) = drawn(w, h, &bar);
        let x = (l.bar.x0 + l.bar.x1) / 2;
        for y in l.bar.y0..l.bar.y1 {
            assert_eq!(pixel(&rgba, w, x, y), srgb8(bar.map, 0.5), "row {y}");
        }
        assert!(l.labels.iter().all(|lab| lab.as_str() == "2.5"));
    }

    #[test]
    fn reversed_range_is_drawn_as_given() {
        let (w, h) = (640, 480);
        let bar = ColorBar {
            min: 10.0,
            max: -10.0,
            ..BAR
        };
        let (rgba, l) = drawn(w, h, &bar);
        let x = (l.bar.x0 + l.bar.x1) / 2;
        assert_eq!(pixel(&rgba, w, x, l.bar.y0), srgb8(bar.map, 1.0));
        assert_eq!(l.labels.map(|l| l.as_str().to_owned()), ["-10", "0", "10"]);
    }

    #[test]
    fn drawing_is_deterministic() {
        let (a, _) = drawn(777, 555, &BAR);
        let (b, _) = drawn(777, 555, &BAR);
        assert!(a == b);
    }

    #[test]
    fn labels_are_compact() {
        for (v, want) in [
            (0.0, "0"),
            (-0.0, "0"),
            (0.125, "0.125"),
            (-3.2, "-3.2"),
            (1.0, "1"),
            (42.0, "42"),
            (0.5, "0.5"),
            (123.456, "123"),
            (1234.0, "1234"),
            (9999.4, "9999"),
            (9999.6, "1e+04"),
            (15000.0, "1.5e+04"),
            (-2e-5, "-2e-05"),
            (0.001, "0.001"),
            (0.00123, "0.00123"),
            (0.000999, "9.99e-04"),
            (0.9996, "1"),
            (7.06349, "7.06"),
            (-1.5e-40, "-1.5e-40"),
            (6.02e23, "6.02e+23"),
            (f32::MAX, "3.4e+38"),
        ] {
            assert_eq!(Label::of(v).as_str(), want, "label of {v}");
        }
    }

    #[test]
    fn scale_follows_the_height() {
        let scales = [200, 300, 480, 540, 720, 1080, 2160].map(scale_of);
        assert_eq!(scales, [1, 1, 1, 2, 2, 3, 6]);
    }

    #[test]
    fn font_covers_printable_ascii_within_five_columns() {
        for (i, g) in FONT.iter().enumerate() {
            let c = char::from(32 + i as u8);
            assert_eq!(
                g & 0xe0e0_e0e0_e0e0_e0e0,
                0,
                "{c:?} uses columns past the fifth"
            );
            assert_eq!(*g == 0, c == ' ', "{c:?}: only the space is blank");
            // Only the descender letters and a few marks reach the descender row.
            let descends = g & 0xff != 0;
            assert_eq!(descends, ",_gjpqy".contains(c), "{c:?} descender");
        }
        assert_eq!(glyph('é'), glyph('?'));
        assert_eq!(glyph('\n'), glyph('?'));
    }

    #[test]
    fn captions_draw_the_fonts_glyphs_at_the_top_left_and_clip_to_half_the_width() {
        for (width, height) in [(360usize, 240usize), (1280, 720)] {
            let s = scale_of(height);
            let text = "t=1.5 ns";
            let mut rgba = vec![0u8; width * height * 4];
            assert_eq!(draw_caption(&mut rgba, width, height, text), text.len());
            let (x0, y0) = (8 * s, 8 * s);
            let px = |x: usize, y: usize| &rgba[(y * width + x) * 4..(y * width + x) * 4 + 4];
            for (i, ch) in text.chars().enumerate() {
                let g = glyph(ch);
                for row in 0..CELL_HEIGHT {
                    for col in 0..GLYPH_WIDTH {
                        let ink = (g >> (8 * (CELL_HEIGHT - 1 - row))) as u8 & (0x10 >> col) != 0;
                        // Every pixel of the s-by-s block.
                        for dy in 0..s {
                            for dx in 0..s {
                                let p = px(x0 + (i * ADVANCE + col) * s + dx, y0 + row * s + dy);
                                assert_eq!(p == INK, ink, "{ch:?} row {row} col {col}");
                            }
                        }
                    }
                }
            }
            // Below the backdrop nothing changed.
            let below = 8 * s + CELL_HEIGHT * s + 4 * s;
            assert!(rgba[below * width * 4..].iter().all(|&b| b == 0));
        }
        // A long text keeps to half the width; a tiny image gets nothing.
        let mut rgba = vec![0u8; 200 * 100 * 4];
        let n = draw_caption(&mut rgba, 200, 100, &"x".repeat(100));
        assert_eq!(n, (100 - 4 - 8 + 1) / ADVANCE);
        let mut tiny = vec![0u8; 10 * 10 * 4];
        assert_eq!(draw_caption(&mut tiny, 10, 10, "t"), 0);
        assert!(tiny.iter().all(|&b| b == 0));
    }

    #[test]
    fn the_tripod_points_its_axes_where_they_turn() {
        let (width, height) = (360, 360);
        let red = [220, 30, 30];
        let green = [30, 160, 30];
        let blue = [30, 60, 230];
        // The centroid of the pixels where `c`'s strongest channel leads the others by 60
        // codes, relative to the panel's centre.
        let centroid = |rgba: &[u8], c: [u8; 3]| {
            let k = (0..3).max_by_key(|&k| c[k]).unwrap();
            let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
            for (i, px) in rgba.chunks_exact(4).enumerate() {
                let lead = (0..3)
                    .filter(|&j| j != k)
                    .all(|j| px[k] as i32 > px[j] as i32 + 60);
                if lead {
                    sx += (i % width) as f64;
                    sy += (i / width) as f64;
                    n += 1.0;
                }
            }
            // Scale 1: panel 60 px square, 4 px from the left and bottom edges.
            let (ox, oy) = (4.0 + 30.0, (height - 4 - 30) as f64);
            (sx / n - ox, sy / n - oy, n as usize)
        };
        let draw = |eye: [[f32; 3]; 3]| {
            let mut rgba = vec![0u8; width * height * 4];
            let axes = [
                (eye[0], 'x', red),
                (eye[1], 'y', green),
                (eye[2], 'z', blue),
            ]
            .map(|(eye, label, color)| TripodAxis { eye, label, color });
            assert!(draw_axes_tripod(&mut rgba, width, height, &axes));
            rgba
        };
        // Looking down z: x to the right, y up, z at the viewer (a dot and its label).
        let img = draw([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        let (rx, ry, rn) = centroid(&img, red);
        let (gx, gy, gn) = centroid(&img, green);
        let (_, _, bn) = centroid(&img, blue);
        assert!(rx > 6.0 && ry.abs() < 3.0 && rn > 20, "x: {rx} {ry} {rn}");
        assert!(gy < -6.0 && gx.abs() < 3.0 && gn > 20, "y: {gx} {gy} {gn}");
        assert!(bn > 0 && bn < rn, "z: {bn} pixels");
        // Turned a quarter about the view axis: x up, y to the left.
        let img = draw([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
        let (rx, ry, _) = centroid(&img, red);
        let (gx, gy, _) = centroid(&img, green);
        assert!(ry < -6.0 && rx.abs() < 3.0, "x: {rx} {ry}");
        assert!(gx < -6.0 && gy.abs() < 3.0, "y: {gx} {gy}");
        // Nothing outside the panel; nothing at all in an image too small.
        let img = draw([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        for (i, px) in img.chunks_exact(4).enumerate() {
            let (x, y) = (i % width, i / width);
            if x >= 64 || y < height - 64 {
                assert_eq!(px, [0, 0, 0, 0], "({x}, {y})");
            }
        }
        let mut tiny = vec![0u8; 40 * 40 * 4];
        assert!(!draw_axes_tripod(&mut tiny, 40, 40, &[]));
        assert!(tiny.iter().all(|&b| b == 0));
    }
}
