//! CCP4 / MRC maps (`.mrc`, `.map`, `.ccp4`, `.rec`): the densities of cryo-EM (EMDB's
//! maps), crystallography (CCP4's FFT maps) and tomography, as ChimeraX, VMD, PyMOL and
//! mrcfile read them. See [`crate::volume`] for what is read.

use crate::error::{Error, Location};
use crate::volume::{MAX_POINTS, Volume};
use std::io::Read;
use std::sync::Arc;

/// Bytes of the fixed header.
const HEADER: usize = 1024;

/// Reads a map's one volume from `src` (`len`: the file's length, when known).
pub(crate) fn read<R: Read>(
    mut src: R,
    file: Arc<str>,
    len: Option<u64>,
) -> Result<Vec<Volume>, Error> {
    let at = |byte: usize| Location::binary(&file, 0, byte as u64);
    let bad = |byte: usize, expected: &'static str, found: String| Error::Parse {
        at: at(byte),
        expected,
        found,
    };
    let mut h = [0u8; HEADER];
    let got = read_full(&mut src, &mut h).map_err(|e| Error::Io {
        at: at(0),
        source: e,
    })?;
    if got < HEADER {
        return Err(Error::Truncated {
            at: at(got),
            expected: format!("the {HEADER}-byte MRC header, found {got} bytes"),
        });
    }
    // Byte order: MACHST (byte 212) is 0x44 0x44 (or 0x44 0x41) little-endian, 0x11 0x11
    // big-endian; older files without it are told by which order gives a sane header.
    let le = match h[212] {
        0x44 => true,
        0x11 => false,
        _ => {
            let sane = |le: bool| {
                let w = |i: usize| word(&h, i, le);
                (0..3).all(|i| (1..=1 << 20).contains(&w(i))) && mode_size(w(3)).is_some()
            };
            match (sane(true), sane(false)) {
                (true, _) => true,
                (false, true) => false,
                _ => {
                    return Err(bad(
                        212,
                        "an MRC/CCP4 header: MACHST 0x44 (little-endian) or 0x11 (big-endian), \
                         or column, row and section counts and a MODE that read as such",
                        format!("{:02x} {:02x}", h[212], h[213]),
                    ));
                }
            }
        }
    };
    let w = |i: usize| word(&h, i, le);
    let f = |i: usize| f32::from_bits(word(&h, i, le) as u32) as f64;
    let counts = [w(0), w(1), w(2)];
    for (k, &n) in counts.iter().enumerate() {
        if n < 1 {
            return Err(bad(
                4 * k,
                "NC, NR, NS: the column, row and section counts, each ≥ 1",
                n.to_string(),
            ));
        }
    }
    let n = counts
        .iter()
        .try_fold(1usize, |a, &c| a.checked_mul(c as usize))
        .filter(|&n| n <= MAX_POINTS)
        .ok_or_else(|| {
            bad(
                0,
                "a map of at most 2^30 points",
                format!("{}x{}x{}", counts[0], counts[1], counts[2]),
            )
        })?;
    let mode = w(3);
    let size = mode_size(mode).ok_or_else(|| {
        bad(
            12,
            "MODE 0 (int8), 1 (int16), 2 (float32), 6 (uint16) or 12 (float16): complex and \
             4-bit maps are not read",
            mode.to_string(),
        )
    })?;
    let nstart = [w(4), w(5), w(6)];
    let sampling = [w(7), w(8), w(9)];
    if let Some(k) = sampling.iter().position(|&m| m < 1) {
        return Err(bad(
            28 + 4 * k,
            "MX, MY, MZ: the sampling along the cell's axes, each ≥ 1",
            sampling[k].to_string(),
        ));
    }
    let cell = [f(10), f(11), f(12)];
    if let Some(k) = cell.iter().position(|c| !(c.is_finite() && *c > 0.0)) {
        return Err(bad(
            40 + 4 * k,
            "the cell's lengths (Å), finite and > 0",
            cell[k].to_string(),
        ));
    }
    // Angles of 0 (written by some programs) mean 90°.
    let angles = [f(13), f(14), f(15)].map(|a| if a == 0.0 { 90.0 } else { a });
    if let Some(k) = angles
        .iter()
        .position(|a| !(a.is_finite() && *a > 0.0 && *a < 180.0))
    {
        return Err(bad(
            52 + 4 * k,
            "the cell's angles, between 0° and 180°",
            angles[k].to_string(),
        ));
    }
    // MAPC, MAPR, MAPS: the axis (1 = X, 2 = Y, 3 = Z) of columns, rows and sections.
    let mut axes = [w(16), w(17), w(18)];
    if axes == [0, 0, 0] {
        axes = [1, 2, 3];
    }
    let mut sorted = axes;
    sorted.sort_unstable();
    if sorted != [1, 2, 3] {
        return Err(bad(
            64,
            "MAPC, MAPR, MAPS: the axes 1, 2, 3 in some order",
            format!("{} {} {}", axes[0], axes[1], axes[2]),
        ));
    }
    let axis = axes.map(|a| (a - 1) as usize);
    let nsymbt = w(23);
    let data_start = HEADER as u64 + nsymbt.max(0) as u64;
    let data_bytes = n as u64 * size as u64;
    if nsymbt < 0 {
        return Err(bad(
            92,
            "NSYMBT: the extended header's bytes, ≥ 0",
            nsymbt.to_string(),
        ));
    }
    if let Some(l) = len
        && data_start > l
    {
        return Err(Error::Truncated {
            at: at(l as usize),
            expected: format!("the extended header's {nsymbt} bytes (NSYMBT)"),
        });
    }
    if let Some(l) = len
        && data_start + data_bytes > l
    {
        return Err(Error::Truncated {
            at: at(l as usize),
            expected: format!(
                "{n} values ({data_bytes} bytes) of the {}x{}x{} map from byte {data_start}, found {} bytes",
                counts[0],
                counts[1],
                counts[2],
                l - data_start
            ),
        });
    }
    let origin = [f(49), f(50), f(51)];
    if let Some(k) = origin.iter().position(|o| !o.is_finite()) {
        return Err(bad(
            196 + 4 * k,
            "ORIGIN x, y, z (Å), finite numbers",
            origin[k].to_string(),
        ));
    }
    let labels = w(55).clamp(0, 10) as usize;
    let name = (0..labels)
        .map(|l| {
            let label = &h[224 + 80 * l..304 + 80 * l];
            let end = label.iter().position(|&b| b == 0).unwrap_or(label.len());
            String::from_utf8_lossy(&label[..end]).trim().to_string()
        })
        .find(|l| !l.is_empty())
        .unwrap_or_else(|| "density".to_string());

    // The extended header, then the values.
    let mut skip = (&mut src).take(data_start - HEADER as u64);
    let skipped = std::io::copy(&mut skip, &mut std::io::sink()).map_err(|e| Error::Io {
        at: at(HEADER),
        source: e,
    })?;
    if skipped < data_start - HEADER as u64 {
        return Err(Error::Truncated {
            at: at(HEADER + skipped as usize),
            expected: format!("the extended header's {nsymbt} bytes (NSYMBT)"),
        });
    }
    let reserve = if len.is_some() { n } else { n.min(1 << 16) };
    let mut raw: Vec<f32> = Vec::with_capacity(reserve);
    let mut chunk = vec![0u8; (1 << 16) * size];
    while raw.len() < n {
        let want = ((n - raw.len()) * size).min(chunk.len());
        let got = read_full(&mut src, &mut chunk[..want]).map_err(|e| Error::Io {
            at: at(data_start as usize + raw.len() * size),
            source: e,
        })?;
        for v in chunk[..got - got % size].chunks_exact(size) {
            let x = value(v, mode, le);
            if !x.is_finite() {
                let byte = data_start as usize + raw.len() * size;
                return Err(bad(byte, "a finite map value", x.to_string()));
            }
            raw.push(x);
        }
        if got < want {
            return Err(Error::Truncated {
                at: at(data_start as usize + raw.len() * size),
                expected: format!(
                    "{n} values of the {}x{}x{} map, found {}",
                    counts[0],
                    counts[1],
                    counts[2],
                    raw.len()
                ),
            });
        }
    }

    // Columns, rows and sections onto X, Y and Z.
    let mut dims = [0usize; 3];
    for k in 0..3 {
        dims[axis[k]] = counts[k] as usize;
    }
    let data = if axis == [0, 1, 2] {
        raw
    } else {
        let [nc, nr, _] = counts.map(|c| c as usize);
        let mut data = vec![0.0f32; n];
        let [nx, ny, _] = dims;
        for (p, &v) in raw.iter().enumerate() {
            let file_index = [p % nc, (p / nc) % nr, p / (nc * nr)];
            let mut xyz = [0usize; 3];
            for k in 0..3 {
                xyz[axis[k]] = file_index[k];
            }
            data[(xyz[2] * ny + xyz[1]) * nx + xyz[0]] = v;
        }
        data
    };
    // The cell's edge vectors (a along x, b in the xy plane), each cut into its sampling.
    let [a, b, c] = cell;
    // Right angles exactly (cos 90° is not 0 in floating point).
    let cos = |d: f64| if d == 90.0 { 0.0 } else { d.to_radians().cos() };
    let sin = |d: f64| if d == 90.0 { 1.0 } else { d.to_radians().sin() };
    let [al, be, ga] = angles;
    let (cx, cy) = (c * cos(be), c * (cos(al) - cos(be) * cos(ga)) / sin(ga));
    let lattice = [
        [a, 0.0, 0.0],
        [b * cos(ga), b * sin(ga), 0.0],
        [cx, cy, (c * c - cx * cx - cy * cy).max(0.0).sqrt()],
    ];
    let steps: [[f64; 3]; 3] = std::array::from_fn(|x| lattice[x].map(|v| v / sampling[x] as f64));
    let det = crate::volume::det3(steps);
    if det == 0.0 || !det.is_finite() {
        return Err(bad(
            52,
            "cell angles that span a volume",
            format!("{} {} {}", angles[0], angles[1], angles[2]),
        ));
    }
    // ORIGIN plus the first point's index along each axis (NXSTART of the column axis, …),
    // as GridDataFormats places a map.
    let mut start = [0.0f64; 3];
    for k in 0..3 {
        start[axis[k]] = nstart[k] as f64;
    }
    let place: [f64; 3] =
        std::array::from_fn(|d| origin[d] + (0..3).map(|x| start[x] * steps[x][d]).sum::<f64>());
    let v = Volume::new(place, steps, dims, data, false, &name)
        .map_err(|e| Error::InvalidValue { what: e.0 })?;
    Ok(vec![v])
}

/// Bytes per value of `mode`; `None` for modes not read.
fn mode_size(mode: i32) -> Option<usize> {
    match mode {
        0 => Some(1),
        1 | 6 | 12 => Some(2),
        2 => Some(4),
        _ => None,
    }
}

/// Header word `i` (4 bytes at 4·i).
fn word(h: &[u8], i: usize, le: bool) -> i32 {
    let b = [h[4 * i], h[4 * i + 1], h[4 * i + 2], h[4 * i + 3]];
    if le {
        i32::from_le_bytes(b)
    } else {
        i32::from_be_bytes(b)
    }
}

/// One value of `mode` from its bytes.
fn value(b: &[u8], mode: i32, le: bool) -> f32 {
    let two = |b: &[u8]| {
        if le { [b[0], b[1]] } else { [b[1], b[0]] }
    };
    match mode {
        0 => b[0] as i8 as f32,
        1 => i16::from_le_bytes(two(b)) as f32,
        6 => u16::from_le_bytes(two(b)) as f32,
        12 => f16_to_f32(u16::from_le_bytes(two(b))),
        _ => {
            let w = [b[0], b[1], b[2], b[3]];
            if le {
                f32::from_le_bytes(w)
            } else {
                f32::from_be_bytes(w)
            }
        }
    }
}

/// IEEE half precision to single.
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = ((h >> 10) & 0x1f) as i32;
    let frac = (h & 0x3ff) as f32;
    match exp {
        0 => sign * frac * 2f32.powi(-24),
        31 if frac == 0.0 => sign * f32::INFINITY,
        31 => f32::NAN,
        _ => sign * (1.0 + frac / 1024.0) * 2f32.powi(exp - 15),
    }
}

/// Reads until `buf` is full or the source ends; the bytes read.
fn read_full(src: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match src.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(k) => got += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_precision_values() {
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x3555), 0.333_251_95);
        assert_eq!(f16_to_f32(0x0001), 2f32.powi(-24));
        assert!(f16_to_f32(0x7c00).is_infinite());
        assert!(f16_to_f32(0x7e00).is_nan());
    }
}
