//! Direct decoding of entities 126 and 128 from the Parameter Data bytes (IGES 5.3 sections
//! 2.2.4, 4.23, 4.24): the parameter tokenizer and the typed decoders fused into one pass.
//!
//! [`IgesFile::parameters`] cuts an entity's data into a vector of tokens and the typed
//! decoders then parse every token; for the reals that make up nearly all of a B-spline
//! entity this reads each byte twice and stores a token per parameter. The reader here walks
//! the same joined data once: at each parameter it reads the real in place
//! ([`iges_real_at`]), then expects blanks and a delimiter, and stores the value straight into
//! the knot, weight or pole vector.
//!
//! Exactness: the direct reader only ever *succeeds* on data where it is sure to give what
//! the general path gives; on anything else (a Hollerith string, a token the real lexer does
//! not read whole, a missing parameter, a tokenizer error, a limit, a bad count) it gives up
//! and the general path `parameters` + `from_params` decodes the entity, producing the same
//! record or the same located error as before. Property tests below compare the two on
//! random and mutated records.

use super::schema::{Curve126, CurveLayout, Surface128, SurfaceLayout};
use super::{DirectoryEntry, IgesFile, P_DATA_COLUMNS, ParseError, ParseWarning, join_data};
use crate::real::iges_real_at;

/// The outcome of decoding one entity: the warnings about its parameter lines (present when
/// its records could be found and tokenized, as in [`super::Parameters::warnings`]) and the
/// typed record or the located error.
#[derive(Debug, Clone, PartialEq)]
pub struct Decoded<T> {
    /// Non-fatal findings for this entity (`param_line_count`).
    pub warnings: Vec<ParseWarning>,
    /// The typed record, or the error of the general path.
    pub record: Result<T, ParseError>,
}

/// Reusable buffer for the joined data of one entity (keeps one allocation per thread
/// instead of one per entity).
#[derive(Debug, Default)]
pub struct Scratch {
    data: String,
}

impl<'a> IgesFile<'a> {
    /// Decodes a 126 entity: the same result as
    /// [`IgesFile::parameters`] followed by [`Curve126::from_params`] (warnings of the
    /// parameters first), read in one pass when the data allows.
    pub fn decode_curve126(
        &self,
        entry: &DirectoryEntry,
        scratch: &mut Scratch,
    ) -> Decoded<Curve126> {
        self.decode(entry, scratch, read_curve, Curve126::from_params)
    }

    /// Decodes a 128 entity: the same result as
    /// [`IgesFile::parameters`] followed by [`Surface128::from_params`], read in one pass
    /// when the data allows.
    pub fn decode_surface128(
        &self,
        entry: &DirectoryEntry,
        scratch: &mut Scratch,
    ) -> Decoded<Surface128> {
        self.decode(entry, scratch, read_surface, Surface128::from_params)
    }

    /// The one-pass reader where it applies, else the general path.
    fn decode<T>(
        &self,
        entry: &DirectoryEntry,
        scratch: &mut Scratch,
        read: impl FnOnce(&mut Reader<'_>) -> Option<T>,
        from_params: impl FnOnce(&super::Parameters<'_>) -> Result<T, ParseError>,
    ) -> Decoded<T> {
        match self.direct(entry, scratch, read) {
            Some((warnings, record)) => Decoded {
                warnings,
                record: Ok(record),
            },
            None => self.general(entry, from_params),
        }
    }

    /// The general path: tokens, then the typed decoder.
    fn general<T>(
        &self,
        entry: &DirectoryEntry,
        from_params: impl FnOnce(&super::Parameters<'_>) -> Result<T, ParseError>,
    ) -> Decoded<T> {
        match self.parameters(entry) {
            Ok(p) => Decoded {
                record: from_params(&p),
                warnings: p.warnings,
            },
            Err(e) => Decoded {
                warnings: Vec::new(),
                record: Err(e),
            },
        }
    }

    /// The direct path; `None` = leave the entity to the general path.
    fn direct<T>(
        &self,
        entry: &DirectoryEntry,
        scratch: &mut Scratch,
        read: impl FnOnce(&mut Reader<'_>) -> Option<T>,
    ) -> Option<(Vec<ParseWarning>, T)> {
        let (records, _, warnings) = self.entity_records(entry).ok()?;
        scratch.data.clear();
        scratch
            .data
            .reserve(records.len().saturating_mul(P_DATA_COLUMNS));
        join_data(records, &mut scratch.data);
        let b = scratch.data.as_bytes();
        let t = self.tokenizer;
        // The tokenizer refuses data of 4 GiB or more; delimiters that can be part of a
        // real, a blank or equal to each other change what a token is: general path.
        let plain = |c: u8| c.is_ascii_graphic() && !is_real_byte(c) && !matches!(c, b'H' | b'h');
        if u32::try_from(b.len()).is_err()
            || !plain(t.param)
            || !plain(t.record)
            || t.param == t.record
        {
            return None;
        }
        let mut r = Reader {
            b,
            i: 0,
            param: t.param,
            record: t.record,
            count: 0,
            max: self.limits.max_params_per_entity,
            done: false,
        };
        // `parameters` checks the entity type token against the DE.
        if r.int()? != entry.entity_type {
            return None;
        }
        let value = read(&mut r)?;
        Some((warnings, value))
    }
}

/// Bytes that can occur inside an IGES real.
fn is_real_byte(c: u8) -> bool {
    c.is_ascii_digit() || matches!(c, b'+' | b'-' | b'.' | b'E' | b'e' | b'D' | b'd')
}

/// One parameter as the tokenizer would give it, for the few non-real parameters.
enum Item<'d> {
    /// Two adjacent delimiters: the default value.
    Empty,
    /// A plain token's trimmed text.
    Plain(&'d [u8]),
}

/// The tokenizer of [`super::Tokenizer::tokenize`], step by step over joined data, with
/// reals converted where they stand. Every method returns `None` where the tokenizer or the
/// typed decoder could fail or where a parameter is not the simple case (a Hollerith string).
struct Reader<'d> {
    b: &'d [u8],
    /// The offset of the next parameter (just after the previous delimiter).
    i: usize,
    param: u8,
    record: u8,
    /// Parameters read so far (the tokenizer's `out.len()`).
    count: usize,
    /// The tokenizer's `max_tokens`.
    max: usize,
    /// The record delimiter has been read: no parameter follows.
    done: bool,
}

impl<'d> Reader<'d> {
    /// The offset of the first non-blank byte from `i` (blanks are `' '` only, as in the
    /// tokenizer).
    #[inline(always)]
    fn skip_blanks(&self, mut i: usize) -> usize {
        while self.b.get(i) == Some(&b' ') {
            i += 1;
        }
        i
    }

    /// Consumes the delimiter at `at` (a parameter ended there); `None` if `at` holds
    /// anything else (the token would be longer than what was read) or the data ends.
    #[inline(always)]
    fn end_at(&mut self, at: usize) -> Option<()> {
        let c = *self.b.get(at)?;
        if c == self.param {
        } else if c == self.record {
            self.done = true;
        } else {
            return None;
        }
        self.i = at + 1;
        self.count += 1;
        Some(())
    }

    /// Whether a next parameter may be read: the record is not over and the tokenizer's
    /// parameter limit is not reached (the tokenizer fails at that point).
    #[inline(always)]
    fn open(&self) -> bool {
        !self.done && self.count < self.max
    }

    /// The next parameter as the tokenizer cuts it; `None` for a Hollerith string or a
    /// tokenizer error, or after the record's end.
    fn item(&mut self) -> Option<Item<'d>> {
        if !self.open() {
            return None;
        }
        let start = self.skip_blanks(self.i);
        let c = *self.b.get(start)?;
        if c == self.param || c == self.record {
            self.end_at(start)?;
            return Some(Item::Empty);
        }
        let mut j = start;
        while self.b.get(j).is_some_and(u8::is_ascii_digit) {
            j += 1;
        }
        if j > start && matches!(self.b.get(j), Some(b'H' | b'h')) {
            return None;
        }
        let k = j + memchr::memchr2(self.param, self.record, self.b.get(j..)?)?;
        let mut e = k;
        while e > start && self.b.get(e - 1) == Some(&b' ') {
            e -= 1;
        }
        let text = self.b.get(start..e)?;
        self.end_at(k)?;
        Some(Item::Plain(text))
    }

    /// A required integer ([`super::Parameters::int`]).
    fn int(&mut self) -> Option<i64> {
        match self.item()? {
            Item::Plain(t) => super::params::parse_int(std::str::from_utf8(t).ok()?),
            Item::Empty => None,
        }
    }

    /// An integer with default 0 when empty ([`super::Parameters::int_or`]).
    fn int_or_zero(&mut self) -> Option<i64> {
        match self.item()? {
            Item::Plain(t) => super::params::parse_int(std::str::from_utf8(t).ok()?),
            Item::Empty => Some(0),
        }
    }

    /// A required real ([`super::Parameters::real`]: empty = 0.0), converted in place.
    #[inline(always)]
    fn real(&mut self) -> Option<f64> {
        if !self.open() {
            return None;
        }
        let start = self.skip_blanks(self.i);
        let c = *self.b.get(start)?;
        if c == self.param || c == self.record {
            self.end_at(start)?;
            return Some(0.0);
        }
        let (v, end) = iges_real_at(self.b, start).ok()?;
        // Usually the delimiter follows at once; blanks may come first.
        let at = if self.b.get(end) == Some(&self.param) {
            end
        } else {
            self.skip_blanks(end)
        };
        self.end_at(at)?;
        Some(v)
    }

    /// The parameters after the required ones, up to the record delimiter: the first
    /// `N` as optional reals (`None` when absent or empty) where `wanted(k)` says so, and
    /// how many there are. `None` if a wanted one is not a real, or the tokenizer fails.
    fn tail<const N: usize>(
        &mut self,
        wanted: impl Fn(usize, usize) -> bool,
    ) -> Option<([Option<f64>; N], usize)> {
        // Read all tokens first (their number decides which are read, as `p.len()` does).
        let mut first: [Option<Item<'d>>; N] = std::array::from_fn(|_| None);
        let mut n = 0usize;
        while !self.done {
            let item = self.item()?;
            if let Some(slot) = first.get_mut(n) {
                *slot = Some(item);
            }
            n += 1;
        }
        let mut out = [None; N];
        for (k, (slot, item)) in out.iter_mut().zip(first).enumerate() {
            if !wanted(k, n) {
                continue;
            }
            *slot = match item {
                None | Some(Item::Empty) => None,
                Some(Item::Plain(t)) => {
                    Some(crate::real::parse_iges_real(std::str::from_utf8(t).ok()?).ok()?)
                }
            };
        }
        Some((out, n))
    }
}

/// Bails when a count read from the file names more parameters than the data can hold
/// (every parameter takes at least its delimiter byte), before anything is allocated.
fn fits(r: &Reader<'_>, required: usize) -> Option<()> {
    (required < r.b.len() && required < r.max).then_some(())
}

fn reals(r: &mut Reader<'_>, count: usize) -> Option<Vec<f64>> {
    let mut v = Vec::with_capacity(count);
    for _ in 0..count {
        v.push(r.real()?);
    }
    Some(v)
}

fn points(r: &mut Reader<'_>, count: usize) -> Option<Vec<[f64; 3]>> {
    let mut v = Vec::with_capacity(count);
    for _ in 0..count {
        v.push([r.real()?, r.real()?, r.real()?]);
    }
    Some(v)
}

/// Entity 126 (see [`Curve126::from_params`]); the entity type is already read.
fn read_curve(r: &mut Reader<'_>) -> Option<Curve126> {
    let k = r.int()?;
    let m = r.int()?;
    let props = [
        r.int_or_zero()?,
        r.int_or_zero()?,
        r.int_or_zero()?,
        r.int_or_zero()?,
    ];
    let l = CurveLayout::new(k, m).ok()?;
    fits(r, l.required)?;
    // The layout is contiguous (knots, weights, points): read it in order.
    if r.count != l.knots || l.weights != l.knots + l.knot_count || l.points != l.weights + l.poles
    {
        return None;
    }
    let knots = reals(r, l.knot_count)?;
    let weights = reals(r, l.poles)?;
    let points = points(r, l.poles)?;
    if r.count != l.required + 1 || l.v0 != l.required + 1 || l.normal != l.v0 + 2 {
        return None;
    }
    // V(0), V(1) always; the normal only when all three of its slots exist (`p.len() >
    // normal + 2`), as `from_params` does.
    let ([v0, v1, x, y, z], n) = r.tail::<5>(|k, n| k < 2 || n >= 5)?;
    let len = l.required + 1 + n;
    let normal = if len > l.normal + 2 {
        match (x, y, z) {
            (None, None, None) => None,
            (x, y, z) => Some([x.unwrap_or(0.0), y.unwrap_or(0.0), z.unwrap_or(0.0)]),
        }
    } else {
        None
    };
    Some(Curve126 {
        degree: l.m,
        planar: props[0],
        closed: props[1],
        polynomial: props[2],
        periodic: props[3],
        knots,
        weights,
        points,
        v0,
        v1,
        normal,
        extra: len.saturating_sub(l.full + 1),
    })
}

/// Entity 128 (see [`Surface128::from_params`]); the entity type is already read.
fn read_surface(r: &mut Reader<'_>) -> Option<Surface128> {
    let k1 = r.int()?;
    let k2 = r.int()?;
    let m1 = r.int()?;
    let m2 = r.int()?;
    let closed = [r.int_or_zero()?, r.int_or_zero()?];
    let polynomial = r.int_or_zero()?;
    let periodic = [r.int_or_zero()?, r.int_or_zero()?];
    let l = SurfaceLayout::new(k1, k2, m1, m2).ok()?;
    fits(r, l.required)?;
    let n = l.pole_count();
    if r.count != l.knots_u
        || l.knots_v != l.knots_u + l.knot_count[0]
        || l.weights != l.knots_v + l.knot_count[1]
        || l.points != l.weights + n
    {
        return None;
    }
    let knots_u = reals(r, l.knot_count[0])?;
    let knots_v = reals(r, l.knot_count[1])?;
    let weights = reals(r, n)?;
    let points = points(r, n)?;
    if r.count != l.required + 1 || l.range != l.required + 1 {
        return None;
    }
    let ([a, b, c, d], extra) = r.tail::<4>(|_, _| true)?;
    let range = match (a, b, c, d) {
        (Some(a), Some(b), Some(c), Some(d)) => Some([a, b, c, d]),
        _ => None,
    };
    let len = l.required + 1 + extra;
    Some(Surface128 {
        degree: l.m,
        poles: l.poles,
        closed,
        polynomial,
        periodic,
        knots_u,
        knots_v,
        weights,
        points,
        range,
        extra: len.saturating_sub(l.full + 1),
    })
}

#[cfg(test)]
mod tests;
