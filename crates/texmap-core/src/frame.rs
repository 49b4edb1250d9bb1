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
}

#[cfg(test)]
mod tests {
    use super::*;

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
