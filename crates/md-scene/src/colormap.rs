//! Colour coding: a scalar per atom (charge, velocity, potential energy, a coordinate) mapped to
//! a colour, as OVITO's "Color coding" modifier and VMD's colour scales do it.
//!
//! | map | kind | for |
//! |---|---|---|
//! | [`Viridis`](Colormap::Viridis) | perceptually uniform sequential (dark blue to yellow) | any magnitude; the default, readable in grey print and by colour-blind viewers |
//! | [`Plasma`](Colormap::Plasma) | perceptually uniform sequential (blue through magenta to yellow) | the same uses, with a brighter, more saturated middle |
//! | [`Coolwarm`](Colormap::Coolwarm) | diverging (blue, grey-white centre, red), Moreland 2009 | signed values around zero, such as partial charges, with a range symmetric about 0 |
//! | [`Turbo`](Colormap::Turbo) | rainbow (dark blue through green to dark red), Mikhailov 2019 | the blue, green, red order of VMD's BGR colour scale, for readers used to rainbows; not perceptually uniform, so viridis reads values better |
//! | [`Gray`](Colormap::Gray) | linear black to white | print, or a second quantity beside a coloured one |
//!
//! Names and colours are matplotlib's (`matplotlib.colormaps[name]`), so a figure made with
//! matplotlib from the same numbers shows the same colours.
//!
//! # Representation
//!
//! Each map is a piecewise-linear curve in sRGB through a few knots `(t, r, g, b)`: 19 for
//! viridis, 18 for plasma, 20 for coolwarm, 35 for turbo, 2 for gray. [`Colormap::srgb`] finds
//! the segment holding `t` and interpolates linearly. The knots are not matplotlib's tables: the
//! script `tests/data/gen_colormaps.py` fits them to matplotlib's colours (knot positions chosen
//! greedily where the curve bends, colours by least squares over 256 samples) and prints the
//! tables below, which are pasted unchanged; rerun it to refit.
//!
//! Rejected (errors from `gen_colormaps.py --alternatives`, worst 8-bit code over the 256
//! samples): a least-squares polynomial per channel, which at degree 6 leaves turbo 27 codes and
//! plasma 8 codes off, and at degree 12 still leaves turbo 5 codes off; and uniformly spaced
//! knots, which need 36 for plasma (its sharp bend at the yellow end) to stay within 2 codes,
//! where free positions keep 18 within 1 code.
//!
//! # Accuracy
//!
//! Against matplotlib 3.11.2 at t = i/255, i = 0..=255, as 8-bit sRGB codes (`round(c * 255)`),
//! measured by `tests/colormap.rs` and by the fitting script: the largest difference of any
//! channel is 1 code for viridis, plasma, coolwarm and turbo and 0 for gray. Before rounding the
//! curves lie within 0.62 (viridis), 0.61 (plasma), 0.49 (coolwarm) and 0.54 (turbo) codes of
//! matplotlib's colours.
//!
//! # References
//! - S. van der Walt, N. Smith: viridis, plasma (matplotlib 1.5, 2015), designed in CAM02-UCS.
//! - K. Moreland: "Diverging Color Maps for Scientific Visualization", ISVC 2009.
//! - A. Mikhailov: "Turbo, An Improved Rainbow Colormap for Visualization", Google AI blog, 2019.

/// A colour scale from t = 0 to t = 1; see the module docs for what each is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Colormap {
    /// Perceptually uniform sequential, dark blue to yellow.
    #[default]
    Viridis,
    /// Perceptually uniform sequential, blue through magenta to yellow.
    Plasma,
    /// Diverging blue, grey-white, red (Moreland), for signed values.
    Coolwarm,
    /// Rainbow, dark blue through green to dark red.
    Turbo,
    /// Black to white.
    Gray,
}

impl Colormap {
    /// Every map, in declaration order.
    pub const ALL: [Colormap; 5] = [
        Colormap::Viridis,
        Colormap::Plasma,
        Colormap::Coolwarm,
        Colormap::Turbo,
        Colormap::Gray,
    ];

    /// matplotlib's name of the map: "viridis", "plasma", "coolwarm", "turbo", "gray".
    pub fn name(self) -> &'static str {
        match self {
            Colormap::Viridis => "viridis",
            Colormap::Plasma => "plasma",
            Colormap::Coolwarm => "coolwarm",
            Colormap::Turbo => "turbo",
            Colormap::Gray => "gray",
        }
    }

    /// The map of a name as [`name`](Colormap::name) gives it, ignoring ASCII case; `None` for
    /// any other name.
    pub fn from_name(s: &str) -> Option<Colormap> {
        Colormap::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(s))
    }

    /// The sRGB colour, each channel in [0, 1], of the value `t` in [0, 1].
    ///
    /// `t` below 0 gives the colour of 0 and above 1 that of 1; NaN gives the colour of 0, so
    /// every input has a colour (a caller that wants NaN to stand out tests for it first).
    /// Exact at the knots, so `srgb(0.0)` and `srgb(1.0)` are the first and last knots.
    pub fn srgb(self, t: f32) -> [f32; 3] {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        let knots = self.knots();
        // Find the segment [knots[i - 1], knots[i]] holding t (the first knot is at 0).
        let i = knots
            .partition_point(|k| k[0] <= t)
            .clamp(1, knots.len() - 1);
        let (a, b) = (knots[i - 1], knots[i]);
        let f = (t - a[0]) / (b[0] - a[0]);
        // (1 - f) a + f b rather than a + f (b - a): exact at both ends of the segment.
        [1, 2, 3].map(|c| a[c] * (1.0 - f) + b[c] * f)
    }

    /// The knots `(t, r, g, b)` of the map, t rising from 0 to 1.
    fn knots(self) -> &'static [[f32; 4]] {
        match self {
            Colormap::Viridis => &VIRIDIS,
            Colormap::Plasma => &PLASMA,
            Colormap::Coolwarm => &COOLWARM,
            Colormap::Turbo => &TURBO,
            Colormap::Gray => &GRAY,
        }
    }
}

// The knot tables as `tests/data/gen_colormaps.py` prints them (t, r, g, b; sRGB in [0, 1]).
const VIRIDIS: [[f32; 4]; 19] = [
    [0.0000, 0.2687, 0.0039, 0.3310],
    [0.0667, 0.2843, 0.1011, 0.4241],
    [0.1255, 0.2799, 0.1757, 0.4852],
    [0.1843, 0.2617, 0.2472, 0.5246],
    [0.2588, 0.2250, 0.3322, 0.5493],
    [0.3922, 0.1654, 0.4645, 0.5599],
    [0.5059, 0.1255, 0.5704, 0.5515],
    [0.5608, 0.1180, 0.6223, 0.5354],
    [0.6000, 0.1330, 0.6587, 0.5182],
    [0.6392, 0.1692, 0.6945, 0.4944],
    [0.6824, 0.2311, 0.7326, 0.4603],
    [0.7373, 0.3342, 0.7774, 0.4033],
    [0.8000, 0.4754, 0.8228, 0.3204],
    [0.8863, 0.6983, 0.8684, 0.1766],
    [0.9255, 0.8047, 0.8819, 0.1125],
    [0.9490, 0.8660, 0.8900, 0.0944],
    [0.9686, 0.9164, 0.8961, 0.0988],
    [0.9922, 0.9747, 0.9036, 0.1291],
    [1.0000, 0.9932, 0.9062, 0.1441],
];
const PLASMA: [[f32; 4]; 18] = [
    [0.0000, 0.0517, 0.0297, 0.5282],
    [0.0196, 0.1081, 0.0238, 0.5520],
    [0.0627, 0.1949, 0.0187, 0.5918],
    [0.1373, 0.3196, 0.0076, 0.6395],
    [0.2000, 0.4178, 0.0000, 0.6600],
    [0.2471, 0.4893, 0.0083, 0.6593],
    [0.2824, 0.5409, 0.0341, 0.6500],
    [0.3451, 0.6275, 0.1032, 0.6135],
    [0.4392, 0.7379, 0.2095, 0.5280],
    [0.5490, 0.8420, 0.3330, 0.4268],
    [0.6627, 0.9277, 0.4669, 0.3296],
    [0.7529, 0.9753, 0.5847, 0.2515],
    [0.8314, 0.9953, 0.6981, 0.1849],
    [0.8902, 0.9922, 0.7902, 0.1471],
    [0.9333, 0.9790, 0.8611, 0.1418],
    [0.9843, 0.9500, 0.9483, 0.1546],
    [0.9961, 0.9416, 0.9687, 0.1416],
    [1.0000, 0.9400, 0.9752, 0.1313],
];
const COOLWARM: [[f32; 4]; 20] = [
    [0.0000, 0.2294, 0.2990, 0.7551],
    [0.0706, 0.3134, 0.4206, 0.8569],
    [0.1333, 0.3936, 0.5230, 0.9266],
    [0.1922, 0.4730, 0.6119, 0.9723],
    [0.2510, 0.5543, 0.6909, 0.9969],
    [0.3098, 0.6357, 0.7577, 0.9998],
    [0.3686, 0.7142, 0.8101, 0.9811],
    [0.4275, 0.7877, 0.8466, 0.9417],
    [0.4902, 0.8560, 0.8656, 0.8781],
    [0.5098, 0.8765, 0.8616, 0.8519],
    [0.5647, 0.9271, 0.8266, 0.7715],
    [0.6235, 0.9595, 0.7723, 0.6805],
    [0.6824, 0.9712, 0.7019, 0.5874],
    [0.7412, 0.9622, 0.6173, 0.4952],
    [0.8000, 0.9337, 0.5202, 0.4060],
    [0.8627, 0.8827, 0.4039, 0.3165],
    [0.9216, 0.8166, 0.2795, 0.2397],
    [0.9490, 0.7799, 0.2110, 0.2071],
    [0.9686, 0.7527, 0.1576, 0.1843],
    [1.0000, 0.7057, 0.0157, 0.1502],
];
const TURBO: [[f32; 4]; 35] = [
    [0.0000, 0.1903, 0.0719, 0.2334],
    [0.0235, 0.2175, 0.1409, 0.4012],
    [0.0471, 0.2396, 0.2086, 0.5487],
    [0.0706, 0.2566, 0.2743, 0.6755],
    [0.0941, 0.2686, 0.3383, 0.7821],
    [0.1176, 0.2755, 0.4007, 0.8684],
    [0.1412, 0.2773, 0.4618, 0.9348],
    [0.1647, 0.2746, 0.5207, 0.9808],
    [0.1843, 0.2636, 0.5695, 0.9994],
    [0.2039, 0.2395, 0.6193, 0.9965],
    [0.2275, 0.2005, 0.6787, 0.9701],
    [0.2549, 0.1507, 0.7453, 0.9155],
    [0.2863, 0.1054, 0.8146, 0.8352],
    [0.3098, 0.0913, 0.8592, 0.7719],
    [0.3294, 0.0980, 0.8907, 0.7240],
    [0.3490, 0.1255, 0.9173, 0.6773],
    [0.3725, 0.1830, 0.9451, 0.6082],
    [0.4000, 0.2743, 0.9723, 0.5163],
    [0.4431, 0.4432, 0.9972, 0.3719],
    [0.4745, 0.5620, 0.9995, 0.2845],
    [0.4980, 0.6338, 0.9927, 0.2378],
    [0.5216, 0.6951, 0.9768, 0.2115],
    [0.5490, 0.7670, 0.9479, 0.2012],
    [0.5922, 0.8688, 0.8811, 0.2133],
    [0.6275, 0.9346, 0.8124, 0.2280],
    [0.6588, 0.9751, 0.7479, 0.2272],
    [0.6941, 0.9962, 0.6655, 0.2010],
    [0.7294, 0.9958, 0.5645, 0.1597],
    [0.7686, 0.9742, 0.4449, 0.1074],
    [0.8118, 0.9276, 0.3225, 0.0567],
    [0.8510, 0.8691, 0.2360, 0.0298],
    [0.8941, 0.7845, 0.1559, 0.0119],
    [0.9373, 0.6772, 0.0886, 0.0036],
    [0.9804, 0.5472, 0.0351, 0.0058],
    [1.0000, 0.4795, 0.0159, 0.0106],
];
const GRAY: [[f32; 4]; 2] = [
    [0.0000, 0.0000, 0.0000, 0.0000],
    [1.0000, 1.0000, 1.0000, 1.0000],
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn knot_tables_are_well_formed() {
        for map in Colormap::ALL {
            let k = map.knots();
            assert!(k.len() >= 2, "{}", map.name());
            assert_eq!((k[0][0], k[k.len() - 1][0]), (0.0, 1.0), "{}", map.name());
            for w in k.windows(2) {
                assert!(
                    w[0][0] < w[1][0],
                    "{}: knots not rising at t = {}",
                    map.name(),
                    w[1][0]
                );
            }
            for knot in k {
                assert!(
                    knot[1..].iter().all(|c| (0.0..=1.0).contains(c)),
                    "{}",
                    map.name()
                );
            }
        }
    }

    #[test]
    fn names_round_trip() {
        for map in Colormap::ALL {
            assert_eq!(Colormap::from_name(map.name()), Some(map));
            assert_eq!(Colormap::from_name(&map.name().to_uppercase()), Some(map));
        }
        assert_eq!(Colormap::from_name("jet"), None);
        assert_eq!(Colormap::from_name(""), None);
        assert_eq!(Colormap::default(), Colormap::Viridis);
    }

    #[test]
    fn nan_gives_the_colour_of_zero() {
        for map in Colormap::ALL {
            assert_eq!(map.srgb(f32::NAN), map.srgb(0.0), "{}", map.name());
            assert_eq!(map.srgb(f32::NEG_INFINITY), map.srgb(0.0), "{}", map.name());
            assert_eq!(map.srgb(f32::INFINITY), map.srgb(1.0), "{}", map.name());
        }
    }

    #[test]
    fn knots_are_hit_exactly() {
        for map in Colormap::ALL {
            for k in map.knots() {
                assert_eq!(
                    map.srgb(k[0]),
                    [k[1], k[2], k[3]],
                    "{} at t = {}",
                    map.name(),
                    k[0]
                );
            }
        }
    }
}
