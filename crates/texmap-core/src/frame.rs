//! The common output of every drawing method: an RGBA8 sRGB colour image plus an f32 depth image.
//!
//! Depth is the eye-space distance along the view axis (ARCHITECTURE.md); pixels that no surface
//! covers hold `f32::INFINITY` and the background colour. Coverage is therefore
//! `depth.is_finite()`, which the silhouette metric uses.

/// A rendered image: `width * height` pixels, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    width: u32,
    height: u32,
    /// sRGB-encoded RGBA, row-major.
    pub color: Vec<[u8; 4]>,
    /// Eye-space depth along the view axis; `INFINITY` where nothing was drawn.
    pub depth: Vec<f32>,
}

impl Frame {
    /// A frame cleared to `background` colour and infinite depth.
    pub fn new(width: u32, height: u32, background: [u8; 4]) -> Frame {
        let n = width as usize * height as usize;
        Frame {
            width,
            height,
            color: vec![background; n],
            depth: vec![f32::INFINITY; n],
        }
    }

    /// A frame from its parts; `None` unless both buffers hold `width * height` pixels.
    pub fn from_parts(
        width: u32,
        height: u32,
        color: Vec<[u8; 4]>,
        depth: Vec<f32>,
    ) -> Option<Frame> {
        let n = width as usize * height as usize;
        (color.len() == n && depth.len() == n).then_some(Frame {
            width,
            height,
            color,
            depth,
        })
    }

    #[inline]
    pub fn width(&self) -> u32 {
        self.width
    }
    #[inline]
    pub fn height(&self) -> u32 {
        self.height
    }
    #[inline]
    pub fn len(&self) -> usize {
        self.depth.len()
    }
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.depth.is_empty()
    }
    /// Row-major index of pixel (x, y).
    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        debug_assert!(x < self.width && y < self.height);
        y as usize * self.width as usize + x as usize
    }
    /// Whether a surface covers pixel `i`.
    #[inline]
    pub fn covered(&self, i: usize) -> bool {
        self.depth[i].is_finite()
    }
    /// Number of covered pixels.
    pub fn coverage_count(&self) -> usize {
        self.depth.iter().filter(|d| d.is_finite()).count()
    }
    /// The colour as a packed RGBA8 byte slice (for PNG writers).
    pub fn color_bytes(&self) -> &[u8] {
        self.color.as_flattened()
    }

    /// The frame shrunk by `factor` in each direction (a supersampled image box-filtered to its
    /// output size; `None` unless `factor ≥ 1` divides both sides): each output pixel is the
    /// mean of its `factor²` pixels in linear light, weighted by their alpha (so a transparent
    /// background adds no colour), its alpha their mean alpha, its depth the nearest of theirs.
    /// A factor of 1 is the frame itself.
    pub fn downsample(&self, factor: u32) -> Option<Frame> {
        if factor == 0 || !self.width.is_multiple_of(factor) || !self.height.is_multiple_of(factor)
        {
            return None;
        }
        if factor == 1 {
            return Some(self.clone());
        }
        let (w, h) = (self.width / factor, self.height / factor);
        let mut out = Frame::new(w, h, [0, 0, 0, 0]);
        let n = (factor * factor) as f32;
        for y in 0..h {
            for x in 0..w {
                let (mut sum, mut alpha, mut depth) = (glam::Vec3::ZERO, 0.0f32, f32::INFINITY);
                for sy in 0..factor {
                    let row = (y * factor + sy) as usize * self.width as usize;
                    for sx in 0..factor {
                        let i = row + (x * factor + sx) as usize;
                        let a = self.color[i][3] as f32 / 255.0;
                        sum += crate::color::srgb8_to_linear_rgb(self.color[i]) * a;
                        alpha += a;
                        depth = depth.min(self.depth[i]);
                    }
                }
                let o = out.index(x, y);
                let c = if alpha > 0.0 {
                    sum / alpha
                } else {
                    glam::Vec3::ZERO
                };
                out.color[o] = crate::color::linear_to_srgb8(c, (alpha / n * 255.0).round() as u8);
                out.depth[o] = depth;
            }
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn downsampling_averages_light_and_keeps_the_nearest_depth() {
        // A 2x2 block of black and white: half the light, sRGB code 188 (0.5 linear); the
        // background of a transparent image adds no colour, only transparency.
        let mut f = Frame::new(4, 2, [0, 0, 0, 255]);
        f.color[1] = [255, 255, 255, 255];
        f.color[4] = [255, 255, 255, 255];
        f.depth[4] = 3.0;
        f.depth[5] = 2.0;
        f.color[2] = [255, 0, 0, 255];
        f.color[3] = [9, 9, 9, 0];
        f.color[6] = [9, 9, 9, 0];
        f.color[7] = [9, 9, 9, 0];
        let d = f.downsample(2).unwrap();
        assert_eq!(d.color[0], [188, 188, 188, 255]);
        assert_eq!(d.depth[0], 2.0);
        assert_eq!(d.color[1], [255, 0, 0, 64]);
        assert_eq!(d.depth[1], f32::INFINITY);
        assert!(f.downsample(3).is_none() && f.downsample(0).is_none());
        assert_eq!(f.downsample(1).unwrap(), f);
    }

    #[test]
    fn parts_must_match_size() {
        assert!(Frame::from_parts(2, 2, vec![[0; 4]; 4], vec![0.0; 4]).is_some());
        assert!(Frame::from_parts(2, 2, vec![[0; 4]; 3], vec![0.0; 4]).is_none());
        let f = Frame::new(3, 2, [1, 2, 3, 4]);
        assert_eq!(f.color_bytes().len(), 24);
        assert_eq!(f.coverage_count(), 0);
        assert_eq!(f.index(2, 1), 5);
    }
}
