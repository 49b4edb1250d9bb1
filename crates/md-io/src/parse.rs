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

/// Correctly rounded negative powers of ten, for the f32 path (see [`field_f32`]).
const INV_POW10: [f64; 23] = [
    1e0, 1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14,
    1e-15, 1e-16, 1e-17, 1e-18, 1e-19, 1e-20, 1e-21, 1e-22,
];

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
    match fast_prefix::<true>(s, 0) {
        Some((v, end)) if end == s.len() => Some(v),
        _ => None,
    }
}

/// Eight bytes at `s[i..i + 8]` as a little-endian word.
#[inline(always)]
fn load8(s: &[u8], i: usize) -> u64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(&s[i..i + 8]);
    u64::from_le_bytes(b)
}

/// True when all eight bytes of `v` are ASCII digits: each byte's high nibble is 3 and adding
/// 6 does not carry into it.
#[cfg(test)]
fn all_digits8(v: u64) -> bool {
    let a = v & 0xF0F0_F0F0_F0F0_F0F0;
    let b = (v.wrapping_add(0x0606_0606_0606_0606) & 0xF0F0_F0F0_F0F0_F0F0) >> 4;
    (a | b) == 0x3333_3333_3333_3333
}

/// The value of eight ASCII digits (first digit in the lowest byte) by three multiply-adds
/// that combine pairs, then quads, then the two halves.
#[inline(always)]
#[cfg(test)]
fn value8(v: u64) -> u64 {
    combine8(v - 0x3030_3030_3030_3030)
}

/// Number of leading ASCII digits (0..=8) in the little-endian word `v`: per byte, a high
/// nibble other than 3 or a low nibble above 9 marks a non-digit. Adding 6 may carry out of a
/// non-digit byte into later bytes, which only disturbs bytes after the first non-digit.
#[inline(always)]
fn leading_digits8(v: u64) -> usize {
    let high = (v & 0xF0F0_F0F0_F0F0_F0F0) ^ 0x3030_3030_3030_3030;
    let over = ((v.wrapping_add(0x0606_0606_0606_0606) & 0xF0F0_F0F0_F0F0_F0F0)
        ^ 0x3030_3030_3030_3030)
        >> 4;
    let bad = high | over;
    (bad.trailing_zeros() / 8) as usize
}

/// The value of eight decimal digit values 0..=9 (first digit in the lowest byte).
#[inline(always)]
fn combine8(v: u64) -> u64 {
    let v = (v * 10) + (v >> 8);
    let lo = (v & 0x0000_00FF_0000_00FF).wrapping_mul(100 + (1_000_000 << 32));
    let hi = ((v >> 16) & 0x0000_00FF_0000_00FF).wrapping_mul(1 + (10_000 << 32));
    (lo.wrapping_add(hi) >> 32) & 0xFFFF_FFFF
}

const POW10_U64: [u64; 9] = [
    1,
    10,
    100,
    1_000,
    10_000,
    100_000,
    1_000_000,
    10_000_000,
    100_000_000,
];

/// Digits from `s[*i]` on into `mant` (wrapping; the caller rejects more than 19 digits),
/// eight bytes at a time while eight bytes remain: the run of leading digits in the word is
/// shifted to the top (zeros below) and combined. Returns how many digits there were.
#[inline(always)]
fn digits(s: &[u8], i: &mut usize, mant: &mut u64) -> usize {
    let start = *i;
    while *i + 8 <= s.len() {
        let v = load8(s, *i);
        let k = leading_digits8(v);
        if k == 0 {
            return *i - start;
        }
        // Digit values of the first k bytes, moved up so that the value reads as 8 digits.
        let d = (v ^ 0x3030_3030_3030_3030) << (8 * (8 - k));
        *mant = mant.wrapping_mul(POW10_U64[k]).wrapping_add(combine8(d));
        *i += k;
        if k < 8 {
            return *i - start;
        }
    }
    while *i < s.len() && s[*i].is_ascii_digit() {
        *mant = mant.wrapping_mul(10).wrapping_add((s[*i] - b'0') as u64);
        *i += 1;
    }
    *i - start
}

/// Parses the plain decimal starting at `s[start]` and returns it with the index just past
/// it; `None` when it is not a plain decimal within the exact range (then use the slow path).
///
/// `EXACT`: divide by the power of ten (one correct rounding). Otherwise multiply by its
/// rounded reciprocal: a division costs ~13 cycles of latency (measured as the hottest
/// instruction of the XYZ loop), a multiplication 3, and the result is within 2 f64 ulps of
/// the exact quotient, which [`field_f32`] accounts for.
#[inline(always)]
fn fast_prefix<const EXACT: bool>(s: &[u8], start: usize) -> Option<(f64, usize)> {
    let mut i = start;
    let n = s.len();
    // Sign.
    let neg = match s.get(i) {
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
    // Integer digits, then fraction digits, into one mantissa.
    let mut mant: u64 = 0;
    let int_digits = digits(s, &mut i, &mut mant);
    let mut frac_digits = 0;
    if i < n && s[i] == b'.' {
        i += 1;
        frac_digits = digits(s, &mut i, &mut mant);
    }
    let ndig = int_digits + frac_digits;
    if ndig == 0 {
        return None;
    }
    let mut exp = -(frac_digits as i32);
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
        if i == es || (i < n && s[i].is_ascii_digit()) {
            return None;
        }
        exp += if eneg { -e } else { e };
    }
    if ndig > 19 || mant > (1u64 << 53) || !(-22..=22).contains(&exp) {
        return None;
    }
    let m = mant as f64;
    let v = if exp >= 0 {
        m * POW10[exp as usize]
    } else if EXACT {
        m / POW10[(-exp) as usize]
    } else {
        m * INV_POW10[(-exp) as usize]
    };
    Some((if neg { -v } else { v }, i))
}

/// Parses the next space/tab separated field of `line` from `*i` as f64 (as [`parse_f64`]),
/// in one pass for plain decimals; on failure returns the offending field. Advances `*i`.
#[inline(always)]
pub fn field_f64<'a>(line: &'a [u8], i: &mut usize) -> Result<f64, &'a [u8]> {
    let mut k = *i;
    while k < line.len() && (line[k] == b' ' || line[k] == b'\t') {
        k += 1;
    }
    if let Some((v, end)) = fast_prefix::<true>(line, k)
        && (end == line.len() || line[end] == b' ' || line[end] == b'\t')
    {
        *i = end;
        return Ok(v);
    }
    let f = next_field(line, i);
    parse_f64(f).ok_or(f)
}

/// Parses the next space/tab separated field of `line` from `*i` as f32 (as [`parse_f32`]),
/// in one pass over the bytes for plain decimals. On failure returns the offending field (for
/// the error message). Advances `*i` past the field.
#[inline(always)]
pub fn field_f32<'a>(line: &'a [u8], i: &mut usize) -> Result<f32, &'a [u8]> {
    let mut k = *i;
    while k < line.len() && (line[k] == b' ' || line[k] == b'\t') {
        k += 1;
    }
    // The f64 is within 2 ulps of the exact value: unless it lies within 4 ulps of a point
    // half-way between two f32s (low 29 mantissa bits near 1000…0), the exact value is on the
    // same side of it and `as f32` rounds it correctly.
    if let Some((v, end)) = fast_prefix::<false>(line, k)
        && (end == line.len() || line[end] == b' ' || line[end] == b'\t')
        && (v.to_bits() & 0x1FFF_FFFF).abs_diff(0x1000_0000) > 4
    {
        let f = v as f32;
        if f.is_finite() {
            *i = end;
            return Ok(f);
        }
    }
    // Anything else: the whole field through the general parser.
    let f = next_field(line, i);
    parse_f32(f).ok_or(f)
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

/// A residue number that may carry an insertion code: an integer (optional sign) and at most
/// one ASCII letter after it (`36A` -> 36), as PDB2PQR and CHARMM write them; `None` otherwise.
pub(crate) fn res_number(s: &[u8]) -> Option<i64> {
    match s {
        [digits @ .., b] if b.is_ascii_alphabetic() => parse_i64(digits),
        _ => parse_i64(s),
    }
}

/// Parses a non-negative count.
#[inline]
pub fn parse_usize(s: &[u8]) -> Option<usize> {
    parse_i64(s).and_then(|v| usize::try_from(v).ok())
}

/// The next space/tab separated field of `line` at or after `*i` (empty at the end of the
/// line, as a slice at the line's end so that errors can point there); advances `*i`.
#[inline(always)]
pub fn next_field<'a>(line: &'a [u8], i: &mut usize) -> &'a [u8] {
    let mut k = *i;
    while k < line.len() && (line[k] == b' ' || line[k] == b'\t') {
        k += 1;
    }
    let start = k;
    while k < line.len() && line[k] != b' ' && line[k] != b'\t' {
        k += 1;
    }
    *i = k;
    &line[start..k]
}

/// Whitespace (space, tab) separated fields of a line.
#[inline]
pub fn fields(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| *b == b' ' || *b == b'\t')
        .filter(|f| !f.is_empty())
}

/// Bytes `[a, b)` (0-based) of a fixed-column line, cut to its length (empty past its end).
#[inline]
pub fn span(line: &[u8], a: usize, b: usize) -> &[u8] {
    &line[a.min(line.len())..b.min(line.len())]
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
    fn field_parser_agrees_with_parse_f32() {
        let mut rng = Rng(12345);
        for k in 0..100_000 {
            let x = f64::from_bits(rng.next() >> 2) % 1e4;
            let prec = (rng.next() % 16) as usize;
            let s = match k % 3 {
                0 => format!("  {x:.prec$}\t-{x:.prec$} x"),
                1 => format!("{x:e} {:.prec$}", x * 1e-9),
                _ => format!("{x:.prec$}1234567890123 1e400 "),
            };
            let b = s.as_bytes();
            let (mut i, mut j) = (0, 0);
            loop {
                let f = next_field(b, &mut j);
                if f.is_empty() {
                    break;
                }
                let got = field_f32(b, &mut i);
                assert_eq!(i, j, "{s}");
                match parse_f32(f) {
                    Some(v) => assert_eq!(got.map(f32::to_bits), Ok(v.to_bits()), "{s}"),
                    None => assert_eq!(got, Err(f), "{s}"),
                }
            }
        }
        // Eight-digit groups, with and without a non-digit inside.
        assert_eq!(
            field_f32(b"12345678.87654321", &mut 0),
            Ok(12345678.87654321)
        );
        assert_eq!(field_f32(b"1234a678", &mut 0), Err(&b"1234a678"[..]));
        assert_eq!(value8(u64::from_le_bytes(*b"01234567")), 1_234_567);
        assert!(!all_digits8(u64::from_le_bytes(*b"0123456:")));
        assert!(!all_digits8(u64::from_le_bytes(*b"/1234567")));
        for (w, k) in [
            (b"12.45678", 2),
            (b"12345678", 8),
            (b"-1234567", 0),
            (b"1234567\xff", 7),
            (b"9\xfa\xff34567", 1),
        ] {
            assert_eq!(leading_digits8(u64::from_le_bytes(*w)), k, "{w:?}");
        }
    }

    #[test]
    fn field_parser_is_correctly_rounded_next_to_f32_midpoints() {
        // Decimals within a few f64 ulps of a point half-way between two f32s are where the
        // multiply-by-reciprocal path could round the wrong way: compare with str::parse.
        let mut rng = Rng(777);
        for k in 0..200_000 {
            let x = f32::from_bits((rng.next() as u32 & 0x3FFF_FFFF) | 0x3000_0000);
            let mid = (x as f64 + f32::from_bits(x.to_bits() + 1) as f64) / 2.0;
            let prec = 6 + (k % 12);
            for v in [mid, mid * (1.0 + 1e-16), mid * (1.0 - 1e-16)] {
                let s = format!("{v:.prec$e}");
                let want: f32 = s.parse().unwrap();
                assert_eq!(field_f32(s.as_bytes(), &mut 0), Ok(want), "{s}");
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
        assert_eq!(res_number(b"36A"), Some(36));
        assert_eq!(res_number(b"-5"), Some(-5));
        assert_eq!(res_number(b"A"), None);
        assert_eq!(res_number(b"12AB"), None);
        assert_eq!(res_number(b""), None);
        assert_eq!(
            fields(b"  a \tbb  c ").collect::<Vec<_>>(),
            vec![&b"a"[..], b"bb", b"c"]
        );
        assert_eq!(trim(b" \tx y \r"), b"x y");
    }
}
