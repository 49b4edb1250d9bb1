//! Volumetric data on a grid: the values a Gaussian cube file or a VASP CHGCAR / PARCHG /
//! LOCPOT / ELFCAR holds next to its atoms (electron densities, orbitals, potentials), the
//! input of isosurfaces.
//!
//! A [`Volume`] is a grid of `nx x ny x nz` points at `origin + i·steps[0] + j·steps[1] +
//! k·steps[2]` (Å; the steps need not be orthogonal), its values stored with `i` fastest.
//! A periodic volume (VASP's, on the unit cell) wraps: point `nx` along the first axis is
//! point 0 again, so the cells between the last points and the first are part of it too.
//!
//! ```
//! use texmap_md_io::volume::Volume;
//!
//! // A 3 x 2 x 2 grid, 0.5 Å apart, values i + 10 j + 100 k.
//! let data = (0..12).map(|n| ((n % 3) + 10 * ((n / 3) % 2) + 100 * (n / 6)) as f32).collect();
//! let steps = [[0.5, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.5]];
//! let v = Volume::new([0.0; 3], steps, [3, 2, 2], data, false, "demo").unwrap();
//! assert_eq!(v.at(2, 1, 1), 112.0);
//! assert_eq!(v.point(2, 1, 1), [1.0, 0.5, 0.5]);
//! assert_eq!(v.range(), Some((0.0, 112.0)));
//! ```

/// Values on a grid of points (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    /// Position (Å) of grid point (0, 0, 0).
    pub origin: [f64; 3],
    /// The steps (Å) from point (i, j, k) to (i + 1, j, k), (i, j + 1, k) and (i, j, k + 1).
    pub steps: [[f64; 3]; 3],
    /// Points along each axis (each at least 2, or 1 along a periodic axis).
    pub dims: [usize; 3],
    /// `dims[0]·dims[1]·dims[2]` finite values, point (i, j, k) at `(k·ny + j)·nx + i`.
    pub data: Vec<f32>,
    /// The grid wraps around (VASP's grids over the unit cell); a cube file's does not.
    pub periodic: bool,
    /// What the values are, as the file says it (`"total density (e/Å³)"`, `"orbital 12"`).
    pub name: String,
}

/// Why [`Volume::new`] refused its arguments.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VolumeShapeError(pub String);

impl std::fmt::Display for VolumeShapeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for VolumeShapeError {}

impl Volume {
    /// A volume, checked: as many finite values as points, at least two points along each
    /// axis that does not wrap, finite steps spanning a non-zero volume, a finite origin.
    pub fn new(
        origin: [f64; 3],
        steps: [[f64; 3]; 3],
        dims: [usize; 3],
        data: Vec<f32>,
        periodic: bool,
        name: &str,
    ) -> Result<Volume, VolumeShapeError> {
        let err = |m: String| Err(VolumeShapeError(m));
        let min = if periodic { 1 } else { 2 };
        if dims.iter().any(|&d| d < min) {
            return err(format!(
                "a grid of {}x{}x{} points (at least {min} along each axis)",
                dims[0], dims[1], dims[2]
            ));
        }
        let n = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
        if n != Some(data.len()) {
            return err(format!(
                "{} values for a grid of {}x{}x{} points",
                data.len(),
                dims[0],
                dims[1],
                dims[2]
            ));
        }
        if let Some(i) = data.iter().position(|v| !v.is_finite()) {
            return err(format!("value {i} is not a finite number"));
        }
        if !origin
            .iter()
            .chain(steps.iter().flatten())
            .all(|v| v.is_finite())
        {
            return err("a grid origin or step that is not a finite number".into());
        }
        let det = det3(steps);
        if det == 0.0 || !det.is_finite() {
            return err("grid steps that span no volume".into());
        }
        Ok(Volume {
            origin,
            steps,
            dims,
            data,
            periodic,
            name: name.to_string(),
        })
    }

    /// The value at point (i, j, k) (panics outside the grid).
    #[inline]
    pub fn at(&self, i: usize, j: usize, k: usize) -> f32 {
        let [nx, ny, _] = self.dims;
        self.data[(k * ny + j) * nx + i]
    }

    /// The position (Å) of point (i, j, k); fractional indices are allowed.
    #[inline]
    pub fn point(&self, i: impl Into<f64>, j: impl Into<f64>, k: impl Into<f64>) -> [f64; 3] {
        let (i, j, k) = (i.into(), j.into(), k.into());
        std::array::from_fn(|a| {
            self.origin[a] + i * self.steps[0][a] + j * self.steps[1][a] + k * self.steps[2][a]
        })
    }

    /// The smallest and largest value (`None` for no values).
    pub fn range(&self) -> Option<(f32, f32)> {
        let mut it = self.data.iter().copied();
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), v| (lo.min(v), hi.max(v))))
    }

    /// The volume (Å³) of one grid cell: `|det(steps)|`.
    pub fn cell_volume(&self) -> f64 {
        det3(self.steps).abs()
    }

    /// The integral of the values over the grid (sum times cell volume; for a periodic grid,
    /// over the unit cell): a density's electron count.
    pub fn integral(&self) -> f64 {
        self.data.iter().map(|&v| v as f64).sum::<f64>() * self.cell_volume()
    }
}

fn det3(m: [[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_volume_refuses_what_it_cannot_hold() {
        let s = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(Volume::new([0.0; 3], s, [2, 2, 2], vec![0.0; 7], false, "").is_err());
        assert!(Volume::new([0.0; 3], s, [1, 2, 2], vec![0.0; 4], false, "").is_err());
        assert!(Volume::new([0.0; 3], s, [1, 2, 2], vec![0.0; 4], true, "").is_ok());
        let mut nan = vec![0.0; 8];
        nan[5] = f32::NAN;
        let e = Volume::new([0.0; 3], s, [2, 2, 2], nan, false, "").unwrap_err();
        assert!(e.0.contains("value 5"), "{e}");
        let flat = [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(Volume::new([0.0; 3], flat, [2, 2, 2], vec![0.0; 8], false, "").is_err());
        assert!(
            Volume::new([0.0; 3], s, [usize::MAX, 2, 2], vec![], false, "").is_err(),
            "an overflowing point count"
        );
    }

    #[test]
    fn the_integral_of_a_constant_is_its_value_times_the_volume() {
        // A skewed cell: steps (0.5, 0, 0), (0.25, 0.5, 0), (0, 0, 0.4): cell volume 0.1 Å³.
        let s = [[0.5, 0.0, 0.0], [0.25, 0.5, 0.0], [0.0, 0.0, 0.4]];
        let v = Volume::new([1.0, 2.0, 3.0], s, [4, 5, 6], vec![2.0; 120], true, "c").unwrap();
        assert!((v.cell_volume() - 0.1).abs() < 1e-12);
        assert!((v.integral() - 24.0).abs() < 1e-9);
        assert_eq!(v.point(1, 2, 0.5), [2.0, 3.0, 3.2]);
    }
}
