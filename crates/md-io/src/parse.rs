//! Number parsing over byte slices: the hot path of every text reader.
//!
//! [`parse_f64`] takes a fast path for plain decimals (`-12.345`, `1.5e-3`): up to 19 significant
//! digits gathered into a `u64` and, when the mantissa is < 2^53 and the decimal exponent within
//! ±22, one exact multiplication or division by a power of ten, which IEEE arithmetic rounds
//! correctly (Clinger's fast path). Anything else (more digits, `inf`, `nan`, exotic exponents)
//! falls back to `str::parse`, so results always equal `str::parse`'s.
//!
//! [`parse_f32`] rounds that f64 to f32. Rounding twice can differ from rounding once only when
//! the f64 lies exactly half-way between two f32s; then it re-parses with `str::parse::<f32>`,
//! so it too is correctly rounded.
//!
//! Both return `None` for non-finite values: no NaN or infinity enters a [`crate::Frame`].

/// Exact powers of ten representable in f64.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Parses a decimal number (as `str::parse::<f64>` would), returning `None` when it is not a
/// number or not finite.
#[inline]
pub fn parse_f64(s: &[u8]) -> Option<f64> {
    match fast_f64(s) {
        Some(v) => Some(v),
        None => slow::<f64>(s).filter(|v| v.is_finite()),
    }
}

/// Parses a decimal number correctly rounded to f32 (as `str::parse::<f32>`), `None` when not a
/// finite number.
#[inline]
pub fn parse_f32(s: &[u8]) -> Option<f32> {
    match fast_f64(s) {
        Some(v) => {
            // Half-way between two f32s: the low 29 bits of the f64 mantissa are 1000…0.
            if v.to_bits() & 0x1FFF_FFFF == 0x1000_0000 {
                return slow::<f32>(s).filter(|v| v.is_finite());
            }
            let f = v as f32;
            f.is_finite().then_some(f)
        }
        None => slow::<f32>(s).filter(|v| v.is_finite()),
    }
}

#[cold]
fn slow<T: std::str::FromStr>(s: &[u8]) -> Option<T> {
    std::str::from_utf8(s).ok()?.parse().ok()
}

/// Clinger's fast path; `None` when the input is not a plain decimal within its exact range.
#[inline]
fn fast_f64(s: &[u8]) -> Option<f64> {
    let mut i = 0;
    let n = s.len();
    // Sign.
    let neg = match s.first() {
        Some(b'-') => {
            i = 1;
            true
        }
        Some(b'+') => {
            i = 1;
            false
        }
        _ => false,
    };
    // Integer digits, then fraction digits, into one mantissa.
    let mut mant: u64 = 0;
    let mut ndig = 0u32;
    let mut exp: i32 = 0;
    let start = i;
    while i < n && s[i].is_ascii_digit() {
        mant = mant.wrapping_mul(10).wrapping_add((s[i] - b'0') as u64);
        ndig += 1;
        i += 1;
    }
    let int_digits = i - start;
    let mut frac_digits = 0;
    if i < n && s[i] == b'.' {
        i += 1;
        let fs = i;
        while i < n && s[i].is_ascii_digit() {
            mant = mant.wrapping_mul(10).wrapping_add((s[i] - b'0') as u64);
            ndig += 1;
            i += 1;
        }
        frac_digits = i - fs;
        exp = -(frac_digits as i32);
    }
    if int_digits + frac_digits == 0 {
        return None;
    }
    // Exponent.
    if i < n && (s[i] == b'e' || s[i] == b'E') {
        i += 1;
        let eneg = match s.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let es = i;
        let mut e: i32 = 0;
        while i < n && s[i].is_ascii_digit() && i - es < 4 {
            e = e * 10 + (s[i] - b'0') as i32;
            i += 1;
        }
        if i == es {
            return None;
        }
        exp += if eneg { -e } else { e };
    }
    // Anything left (more exponent digits, letters) goes to the slow path.
    if i != n || ndig > 19 {
        return None;
    }
    if mant > (1u64 << 53) || !(-22..=22).contains(&exp) {
        return None;
    }
    let m = mant as f64;
    let v = if exp >= 0 {
        m * POW10[exp as usize]
    } else {
        m / POW10[(-exp) as usize]
    };
    Some(if neg { -v } else { v })
}

/// Parses a decimal integer with optional sign; `None` on anything else or overflow.
#[inline]
pub fn parse_i64(s: &[u8]) -> Option<i64> {
    let (neg, digits) = match s.first() {
        Some(b'-') => (true, &s[1..]),
        Some(b'+') => (false, &s[1..]),
        _ => (false, s),
    };
    if digits.is_empty() || digits.len() > 18 {
        return if digits.len() > 18 {
            slow::<i64>(s)
        } else {
            None
        };
    }
    let mut v: i64 = 0;
    for &b in digits {
        if !b.is_ascii_digit() {
            return None;
        }
        v = v * 10 + (b - b'0') as i64;
    }
    Some(if neg { -v } else { v })
}

/// Parses a non-negative count.
#[inline]
pub fn parse_usize(s: &[u8]) -> Option<usize> {
    parse_i64(s).and_then(|v| usize::try_from(v).ok())
}

/// Whitespace (space, tab) separated fields of a line.
#[inline]
pub fn fields(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| *b == b' ' || *b == b'\t')
        .filter(|f| !f.is_empty())
}

/// The line with leading and trailing spaces and tabs removed.
#[inline]
pub fn trim(line: &[u8]) -> &[u8] {
    let is_ws = |b: &u8| *b == b' ' || *b == b'\t' || *b == b'\r';
    let start = line.iter().position(|b| !is_ws(b)).unwrap_or(line.len());
    let end = line
        .iter()
        .rposition(|b| !is_ws(b))
        .map_or(start, |e| e + 1);
    &line[start..end]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small xorshift generator so the tests need no crate and are reproducible.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
    }

    #[test]
    fn agrees_with_std_on_random_decimals() {
        // Compare bit for bit with str::parse on formatted random numbers of many shapes.
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        for k in 0..200_000 {
            let x = f64::from_bits(rng.next() >> 2) % 1e6;
            let prec = (rng.next() % 12) as usize;
            let s = match k % 4 {
                0 => format!("{x:.prec$}"),
                1 => format!("{:.prec$}", -x),
                2 => format!("{x:e}"),
                _ => format!("{:.prec$e}", x / 1e3),
            };
            let want64: f64 = s.parse().unwrap();
            let want32: f32 = s.parse().unwrap();
            if want64.is_finite() {
                assert_eq!(
                    parse_f64(s.as_bytes()).map(f64::to_bits),
                    Some(want64.to_bits()),
                    "{s}"
                );
            }
            if want32.is_finite() {
                assert_eq!(
                    parse_f32(s.as_bytes()).map(f32::to_bits),
                    Some(want32.to_bits()),
                    "{s}"
                );
            }
        }
    }

    #[test]
    fn double_rounding_case_uses_the_slow_path() {
        // 1 + 2^-24 is exactly half-way between two f32s; a bit more must round up.
        let s = "1.00000005960464477539062500000001";
        assert_eq!(parse_f32(s.as_bytes()), Some(s.parse::<f32>().unwrap()));
        let s = "1.000000059604644775390625";
        assert_eq!(parse_f32(s.as_bytes()), Some(s.parse::<f32>().unwrap()));
    }

    #[test]
    fn rejects_non_numbers_and_non_finite() {
        for s in [
            "", "-", ".", "e5", "1e", "1.2.3", "abc", "nan", "inf", "1e999", "1x",
        ] {
            assert_eq!(parse_f64(s.as_bytes()), None, "{s}");
            assert_eq!(parse_f32(s.as_bytes()), None, "{s}");
        }
        assert_eq!(parse_f32(b"1e39"), None);
        assert_eq!(parse_f64(b"+.5"), Some(0.5));
        assert_eq!(parse_f64(b"5."), Some(5.0));
        assert_eq!(parse_f64(b"1E+02"), Some(100.0));
        assert_eq!(
            parse_f64(b"12345678901234567890123"),
            Some(12345678901234567890123.0)
        );
    }

    #[test]
    fn integers() {
        assert_eq!(parse_i64(b"-42"), Some(-42));
        assert_eq!(parse_i64(b"+7"), Some(7));
        assert_eq!(parse_i64(b"9223372036854775807"), Some(i64::MAX));
        assert_eq!(parse_i64(b"9223372036854775808"), None);
        assert_eq!(parse_i64(b"1.0"), None);
        assert_eq!(parse_usize(b"-1"), None);
        assert_eq!(
            fields(b"  a \tbb  c ").collect::<Vec<_>>(),
            vec![&b"a"[..], b"bb", b"c"]
        );
        assert_eq!(trim(b" \tx y \r"), b"x y");
    }
}
