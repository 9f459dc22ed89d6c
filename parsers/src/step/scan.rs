//! The file structure (ISO 10303-21 clauses 8-11) and the lazy instance index.
//!
//! [`scan`] makes one pass over the file: it parses the header, finds every entity
//! instance's `#id`, keyword and body slice with `memchr` (string- and comment-aware), and
//! builds an `#id -> instance` index. Parameters are decoded only when asked for
//! ([`Scanned::decode`]), so a reader that needs the B-splines of a large file decodes only
//! those and the points they reference. [`parse`] decodes everything into an [`Exchange`].
//!
//! Error recovery is per statement: a syntax error inside one instance yields a located
//! error for that instance and scanning resumes after its terminating `;`. Only a broken
//! file structure (no `ISO-10303-21;`, no `HEADER;`) is fatal.

use std::collections::HashMap;

use super::ast::{Body, DataSection, Exchange, Instance, Parameter, Record};
use super::error::{LineIndex, ParseError, ParseErrorKind};
use super::grammar::{self, Cursor, LexError, ParamLimits};
use super::specials::{Specials, statement_end, statement_end_in};
use crate::{Limits, Stop};

/// An entity instance found by [`scan`], not yet decoded: where it is in the text.
///
/// Kept small (24 bytes, no pointer into the text: [`RawInstance::body`] and
/// [`RawInstance::keyword`] take the scanned text): a large file has one per statement,
/// alive for most of the read, so its size is a direct share of the reader's peak memory
/// (issue: peak <= 3x file size).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RawInstance<'a> {
    /// The instance name `n` of `#n`.
    pub id: u64,
    /// The byte offset of the `#` (low [`OFFSET_BITS`] bits), the length of the keyword at
    /// the start of the body (the next 16 bits; 0 for a complex instance `( ... )`) and its
    /// first byte (the high 8 bits). The keyword's first byte is kept here so that passes
    /// over every instance (which entity kinds are there?) can reject most of them without
    /// touching the text: on a large file each such touch is a cache miss.
    packed: u64,
    /// The bytes from the `#` to the body.
    head_len: u32,
    /// The body's length: from after `=` to before `;`.
    body_len: u32,
    /// The text the offsets are in.
    text: std::marker::PhantomData<&'a str>,
}

/// Bits of [`RawInstance`]'s packed word holding the offset: texts up to 1 TiB.
const OFFSET_BITS: u32 = 40;

/// Largest offset a [`RawInstance`] records; an instance beyond it is a statement error.
const MAX_OFFSET: u64 = (1 << OFFSET_BITS) - 1;

/// Longest keyword a [`RawInstance`] records (65,535 bytes; ISO 10303-21 names are under
/// 100). A longer one is reported as a statement error.
const MAX_KEYWORD_LEN: u64 = u16::MAX as u64;

impl<'a> RawInstance<'a> {
    /// Byte offset of the `#`.
    #[inline]
    pub fn offset(&self) -> usize {
        usize::try_from(self.packed & MAX_OFFSET).unwrap_or(usize::MAX)
    }

    /// Byte offset where the body (after `=`) starts.
    #[inline]
    pub fn body_offset(&self) -> usize {
        self.offset()
            .saturating_add(usize::try_from(self.head_len).unwrap_or(usize::MAX))
    }

    /// The body's length in bytes.
    #[inline]
    pub fn body_len(&self) -> usize {
        usize::try_from(self.body_len).unwrap_or(usize::MAX)
    }

    /// The body text, from after `=` to before `;`, in `text` (the text scanned).
    #[inline]
    pub fn body(&self, text: &'a str) -> &'a str {
        let start = self.body_offset();
        text.get(start..start.saturating_add(self.body_len()))
            .unwrap_or_default()
    }

    /// The length of the keyword (0 for a complex instance).
    #[inline]
    pub(crate) fn keyword_len(&self) -> usize {
        usize::try_from((self.packed >> OFFSET_BITS) & MAX_KEYWORD_LEN).unwrap_or(0)
    }

    /// The keyword of a simple instance in `text` (the text scanned); `None` for a complex
    /// instance `( ... )`.
    #[inline]
    pub fn keyword(&self, text: &'a str) -> Option<&'a str> {
        match self.keyword_len() {
            0 => None,
            n => {
                let start = self.body_offset();
                text.get(start..start.saturating_add(n))
            }
        }
    }

    /// The first byte of [`RawInstance::keyword`], read without touching the input text;
    /// `None` for a complex instance.
    #[inline]
    pub fn keyword_initial(&self) -> Option<u8> {
        match self.keyword_len() {
            0 => None,
            _ => u8::try_from(self.packed >> 56).ok(),
        }
    }
}

/// A data section as found by [`scan`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SectionInfo<'a> {
    /// The section's parameters (`DATA('name',('SCHEMA'));`), usually empty.
    pub params: Vec<Parameter<'a>>,
    /// The range of [`Scanned::instances`] in this section.
    pub instances: std::ops::Range<usize>,
}

/// `#id -> position` in [`Scanned::instances`]: a direct table when ids are dense (the usual
/// case, 1..n), a hash map otherwise.
#[derive(Debug)]
enum IdIndex {
    Dense(Vec<u32>),
    Sparse(HashMap<u64, u32>),
}

impl IdIndex {
    const NONE: u32 = u32::MAX;

    #[inline]
    fn get(&self, id: u64) -> Option<usize> {
        match self {
            IdIndex::Dense(v) => {
                let i = usize::try_from(id).ok()?;
                match v.get(i) {
                    Some(&p) if p != Self::NONE => usize::try_from(p).ok(),
                    _ => None,
                }
            }
            IdIndex::Sparse(m) => m.get(&id).and_then(|&p| usize::try_from(p).ok()),
        }
    }
}

/// A scanned exchange structure: the decoded header, every instance located but not
/// decoded, the `#id` index, and the errors recovered from.
#[derive(Debug)]
pub struct Scanned<'a> {
    /// The whole input.
    pub text: &'a str,
    /// The header entities.
    pub header: Vec<Record<'a>>,
    /// The data sections.
    pub sections: Vec<SectionInfo<'a>>,
    /// Every instance in file order (duplicates included; the index keeps the first).
    pub instances: Vec<RawInstance<'a>>,
    /// Errors recovered from while scanning (bad statements, duplicate ids, skipped
    /// sections...).
    pub errors: Vec<ParseError>,
    index: IdIndex,
    /// The largest id in `instances` (0 when empty), kept while scanning so that building
    /// the index needs no extra pass over every instance.
    max_id: u64,
    lines: LineIndex,
    limits: ParamLimits,
}

/// A fully decoded file: the syntax tree and the errors recovered from.
#[derive(Debug)]
pub struct Parsed<'a> {
    /// The syntax tree (instances that failed to parse are left out).
    pub exchange: Exchange<'a>,
    /// Located errors, in file order.
    pub errors: Vec<ParseError>,
}

/// Parses a whole file: [`scan`], decode every instance, check that every reference is
/// defined. Returns the tree and the located errors recovered from; `Err` only when the
/// file structure is broken (no `ISO-10303-21;`/`HEADER;`, or a size limit).
///
/// ```
/// # use nurbsx_parsers::{Limits, step};
/// let text = "ISO-10303-21;HEADER;FILE_DESCRIPTION(('x'),'2;1');ENDSEC;DATA;\
///             #1=CARTESIAN_POINT('',(0.,1.,2.));ENDSEC;END-ISO-10303-21;";
/// let parsed = step::parse(text, &Limits::default()).unwrap();
/// assert!(parsed.errors.is_empty());
/// assert_eq!(parsed.exchange.instances().count(), 1);
/// ```
pub fn parse<'a>(text: &'a str, limits: &Limits) -> Result<Parsed<'a>, ParseError> {
    let scanned = scan(text, limits)?;
    let mut errors = scanned.errors.clone();
    let mut data = Vec::with_capacity(scanned.sections.len());
    for section in &scanned.sections {
        let mut instances = Vec::with_capacity(section.instances.len());
        for raw in scanned
            .instances
            .get(section.instances.clone())
            .unwrap_or_default()
        {
            match scanned.decode(raw) {
                Ok(inst) => {
                    check_references(&scanned, raw, &inst, &mut errors);
                    instances.push(inst);
                }
                Err(e) => errors.push(e),
            }
        }
        data.push(DataSection {
            params: section.params.clone(),
            instances,
        });
    }
    errors.sort_by_key(|e| e.offset);
    Ok(Parsed {
        exchange: Exchange {
            header: scanned.header,
            data,
        },
        errors,
    })
}

/// Reports every reference in `inst` to an undefined instance.
fn check_references(
    s: &Scanned<'_>,
    raw: &RawInstance<'_>,
    inst: &Instance<'_>,
    errors: &mut Vec<ParseError>,
) {
    for_each_reference(&inst.body, |id| {
        if s.get(id).is_none() {
            errors.push(s.error_at(
                ParseErrorKind::DanglingReference(id),
                raw.offset(),
                Some(raw.id),
            ));
        }
    });
}

/// Calls `f` with every `#id` referenced anywhere in `body` (iteratively: no recursion).
pub fn for_each_reference(body: &Body<'_>, mut f: impl FnMut(u64)) {
    let mut stack: Vec<&Parameter<'_>> = Vec::new();
    for r in body.records() {
        stack.extend(r.params.iter().rev());
        while let Some(p) = stack.pop() {
            match p {
                Parameter::Reference(id) => f(*id),
                Parameter::List(l) => stack.extend(l.iter().rev()),
                Parameter::Typed(_, inner) => stack.push(inner),
                _ => {}
            }
        }
    }
}

/// Scans the file structure and locates every instance (see the module documentation).
pub fn scan<'a>(text: &'a str, limits: &Limits) -> Result<Scanned<'a>, ParseError> {
    scan_impl(text, limits, 1, PARALLEL_MIN_BYTES, Stop::NEVER)
}

/// [`scan`] using up to `threads` threads for large DATA sections: the section is cut into
/// `threads` pieces at likely statement starts (`;` then `#`), the pieces are scanned at
/// the same time, and each piece is kept only if the scan of the piece before it ended
/// exactly where it starts (a cut inside a string or comment is detected that way and the
/// rest is scanned sequentially). The result is identical to [`scan`]'s, instances and
/// errors in file order.
///
/// Every piece polls `stop` every [`SCAN_POLL`](crate::stop::SCAN_POLL) statements (and
/// the HEADER section every as many records); once it has fired the scan ends with
/// [`ParseErrorKind::Stopped`].
pub fn scan_parallel<'a>(
    text: &'a str,
    limits: &Limits,
    threads: usize,
    stop: Stop<'_>,
) -> Result<Scanned<'a>, ParseError> {
    scan_impl(text, limits, threads, PARALLEL_MIN_BYTES, stop)
}

/// Below this many bytes a DATA section is scanned by one thread (a thread start costs
/// more than scanning a few megabytes is worth splitting).
const PARALLEL_MIN_BYTES: usize = 4 << 20;

fn scan_impl<'a>(
    text: &'a str,
    limits: &Limits,
    threads: usize,
    parallel_min_bytes: usize,
    stop: Stop<'_>,
) -> Result<Scanned<'a>, ParseError> {
    let lines = LineIndex::default();
    if text.len() > limits.max_input_bytes {
        return Err(lines.error(
            text,
            ParseErrorKind::InputTooLarge {
                size: text.len(),
                limit: limits.max_input_bytes,
            },
            0,
            None,
        ));
    }
    let plimits = ParamLimits::from(limits);
    let mut s = Scanned {
        text,
        header: Vec::new(),
        sections: Vec::new(),
        instances: Vec::new(),
        errors: Vec::new(),
        index: IdIndex::Sparse(HashMap::new()),
        max_id: 0,
        lines,
        limits: plimits,
    };
    let fatal = |s: &Scanned<'a>, (kind, at): LexError| s.error_at(kind, at, None);
    let mut c = Cursor::new(text, 0, text.len());
    if text.starts_with('\u{feff}') {
        c.pos = 3;
    }
    c.skip_ws().map_err(|e| fatal(&s, e))?;
    if !c.starts_with("ISO-10303-21") {
        return Err(s.error_at(ParseErrorKind::Missing("ISO-10303-21;"), c.pos, None));
    }
    c.pos += "ISO-10303-21".len();
    end_of_keyword_statement(&mut c).map_err(|e| fatal(&s, e))?;
    c.skip_ws().map_err(|e| fatal(&s, e))?;
    if !c.starts_with("HEADER") {
        return Err(s.error_at(ParseErrorKind::Missing("HEADER;"), c.pos, None));
    }
    c.pos += "HEADER".len();
    end_of_keyword_statement(&mut c).map_err(|e| fatal(&s, e))?;
    s.scan_header(&mut c, stop)?;

    let mut ended = false;
    loop {
        c.skip_ws().map_err(|e| fatal(&s, e))?;
        if c.peek().is_none() {
            break;
        }
        if ended {
            s.errors
                .push(s.error_at(ParseErrorKind::TrailingGarbage, c.pos, None));
            break;
        }
        if c.starts_with("END-ISO-10303-21") {
            c.pos += "END-ISO-10303-21".len();
            end_of_keyword_statement(&mut c).map_err(|e| fatal(&s, e))?;
            ended = true;
        } else if section_keyword(&c, "DATA") {
            s.scan_data(&mut c, limits, threads, parallel_min_bytes, stop)?;
        } else if let Some(name) = ["ANCHOR", "REFERENCE", "SIGNATURE"]
            .into_iter()
            .find(|k| section_keyword(&c, k))
        {
            let at = c.pos;
            s.skip_section(&mut c, stop)?;
            s.errors
                .push(s.error_at(ParseErrorKind::SkippedSection(name), at, None));
        } else {
            return Err(fatal(&s, c.expected("DATA; or END-ISO-10303-21;")));
        }
    }
    if !ended {
        s.errors.push(s.error_at(
            ParseErrorKind::Missing("END-ISO-10303-21;"),
            text.len(),
            None,
        ));
    }
    s.build_index(limits);
    Ok(s)
}

/// How a run of statements ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
enum RunEnd {
    /// At the first statement boundary at or after the requested stop (the offset just
    /// after that statement's `;`).
    Stop(usize),
    /// At `ENDSEC;` (the offset after its `;`).
    EndSec(usize),
    /// At the end of the input (the section is not closed, or an unterminated string or
    /// comment swallowed the rest).
    #[default]
    Eof,
}

/// The statements of one piece of a DATA section, as [`scan_statements`] found them.
#[derive(Debug, Default)]
struct Run<'a> {
    /// Where the piece started.
    from: usize,
    instances: Vec<RawInstance<'a>>,
    /// The largest id in `instances` (0 when empty).
    max_id: u64,
    errors: Vec<ParseError>,
    end: RunEnd,
    /// An error that ends the scan of the file (bad `ENDSEC`, entity limit).
    fatal: Option<ParseError>,
}

/// Scans entity instances from `from` until `ENDSEC;`, the end of input, or the first
/// statement boundary at or after `stop` (ISO 10303-21 clause 10: `#id = body;`). Errors
/// are recovered from per statement: scanning resumes after the statement's `;`.
fn scan_statements<'a>(
    text: &'a str,
    lines: &LineIndex,
    from: usize,
    stop: usize,
    limits: &Limits,
    signal: Stop<'_>,
) -> Run<'a> {
    let bytes = text.as_bytes();
    let mut run = Run {
        from,
        ..Run::default()
    };
    // Sized up front: growing by doubling would copy (and fault in) the vector several
    // times on a large file.
    let _ = run
        .instances
        .try_reserve(estimate_statements(bytes, from, stop, limits));
    let error = |k, at, id| lines.error(text, k, at, id);
    let mut c = Cursor::new(text, from, text.len());
    // One special-byte cursor for the whole run: statements share its 64-byte masks.
    let mut specials = Specials::new(bytes);
    let mut statements = 0usize;
    loop {
        if c.pos >= stop {
            run.end = RunEnd::Stop(c.pos);
            return run;
        }
        statements += 1;
        if signal.at(statements) {
            run.fatal = Some(ParseError::stopped(c.pos));
            run.end = RunEnd::Eof;
            return run;
        }
        if let Err((k, at)) = c.skip_ws() {
            run.errors.push(error(k, at, None));
            c.pos = c.end;
        }
        if c.peek().is_none() {
            run.errors.push(error(
                ParseErrorKind::Missing("ENDSEC; closing DATA"),
                c.pos,
                None,
            ));
            run.end = RunEnd::Eof;
            return run;
        }
        if section_keyword(&c, "ENDSEC") {
            c.pos += "ENDSEC".len();
            if let Err((k, at)) = end_of_keyword_statement(&mut c) {
                run.fatal = Some(error(k, at, None));
            }
            run.end = RunEnd::EndSec(c.pos);
            return run;
        }
        let start = c.pos;
        let end = match statement_end_in(&mut specials, start) {
            Ok(e) => e,
            Err((k, at)) => {
                // An unterminated string or comment swallows the rest of the file.
                // Name the instance it started in (a truncated file's last one).
                let id = match instance_head(text, start, text.len()) {
                    Ok((id, _, _)) => Some(id),
                    Err((_, _, id)) => id,
                };
                run.errors.push(error(k, at, id));
                c.pos = c.end;
                continue;
            }
        };
        match instance_head(text, start, end) {
            Ok((id, body_offset, keyword)) => {
                if run.instances.len() >= limits.max_entities {
                    run.fatal = Some(error(
                        ParseErrorKind::TooManyInstances(limits.max_entities),
                        start,
                        Some(id),
                    ));
                    run.end = RunEnd::Eof;
                    return run;
                }
                // Keywords longer than 64 KiB, heads or bodies of 4 GiB and more and
                // instances beyond 1 TiB cannot be represented; they are reported instead
                // of truncated.
                let keyword_len = keyword.map_or(0, str::len);
                let initial = keyword.and_then(|k| k.bytes().next()).unwrap_or(0);
                let head_len = u32::try_from(body_offset.saturating_sub(start));
                let body_len = u32::try_from(end.saturating_sub(body_offset));
                match (
                    u64::try_from(start).ok().filter(|&o| o <= MAX_OFFSET),
                    u64::try_from(keyword_len)
                        .ok()
                        .filter(|&n| n <= MAX_KEYWORD_LEN),
                    head_len.ok().zip(body_len.ok()),
                ) {
                    (Some(offset), Some(keyword_len), Some((head_len, body_len))) => {
                        run.max_id = run.max_id.max(id);
                        run.instances.push(RawInstance {
                            id,
                            packed: offset
                                | (keyword_len << OFFSET_BITS)
                                | (u64::from(initial) << 56),
                            head_len,
                            body_len,
                            text: std::marker::PhantomData,
                        });
                    }
                    (None, ..) => run.errors.push(error(
                        ParseErrorKind::InvalidId("(instance beyond 1 TiB)".to_owned()),
                        start,
                        Some(id),
                    )),
                    (_, None, _) => run.errors.push(error(
                        ParseErrorKind::InvalidId("(keyword too long)".to_owned()),
                        start,
                        Some(id),
                    )),
                    (.., None) => run.errors.push(error(
                        ParseErrorKind::InvalidId("(instance of 4 GiB or more)".to_owned()),
                        start,
                        Some(id),
                    )),
                }
            }
            Err((k, at, id)) => run.errors.push(error(k, at, id)),
        }
        c.pos = end + 1;
    }
}

/// About how many statements `bytes[from..stop]` holds, estimated from the `;` in its
/// first 256 KiB (plus an eighth), capped by the entity limit; 0 for small ranges, which
/// are not worth estimating. Capacity reserved from this and never used is never touched,
/// so an over-estimate costs address space, not memory.
fn estimate_statements(bytes: &[u8], from: usize, stop: usize, limits: &Limits) -> usize {
    const SAMPLE: usize = 256 * 1024;
    let rest = stop.min(bytes.len()).saturating_sub(from);
    if rest <= SAMPLE {
        return 0;
    }
    let sample = bytes.get(from..from + SAMPLE).unwrap_or_default();
    let statements = memchr::memchr_iter(b';', sample).count().max(1);
    (rest / SAMPLE + 1)
        .saturating_mul(statements)
        .saturating_add(statements / 8)
        .min(limits.max_entities)
}

/// Up to `pieces - 1` offsets that split `bytes[from..]` into pieces of about equal size,
/// each just after a `;` that is followed (after blanks) by `#`: where a statement most
/// likely starts. "Likely" because the `;` may be inside a string or comment; the caller
/// checks each cut against the sequential scan.
fn cut_points(bytes: &[u8], from: usize, pieces: usize) -> Vec<usize> {
    let len = bytes.len().saturating_sub(from);
    let mut cuts = Vec::new();
    let mut last = from;
    for k in 1..pieces {
        let target = (from + len / pieces * k).max(last);
        let mut at = target;
        let cut = loop {
            let Some(p) = bytes
                .get(at..)
                .and_then(|hay| memchr::memchr(b';', hay))
                .map(|p| at + p)
            else {
                break None;
            };
            let next = bytes
                .get(p + 1..)
                .unwrap_or_default()
                .iter()
                .position(|b| !matches!(b, b' ' | b'\t' | b'\r' | b'\n'))
                .map(|q| p + 1 + q);
            match next {
                Some(q) if bytes.get(q) == Some(&b'#') => break Some(p + 1),
                _ => at = p + 1,
            }
        };
        match cut {
            Some(c) if c > last => {
                cuts.push(c);
                last = c;
            }
            Some(_) => {}
            None => break,
        }
    }
    cuts
}

/// Whether the cursor is at the keyword `kw` followed by a non-keyword character.
#[inline]
fn section_keyword(c: &Cursor<'_>, kw: &'static str) -> bool {
    // Nearly every statement starts with `#`: one comparison rejects it.
    c.starts_with(kw) && c.matches(grammar::structure_keyword(kw))
}

/// After a structure keyword: optional whitespace/comments, then `;`.
fn end_of_keyword_statement(c: &mut Cursor<'_>) -> Result<(), LexError> {
    c.rule(grammar::end_of_keyword_statement)
}

impl<'a> Scanned<'a> {
    /// A located error at a byte offset.
    pub fn error_at(&self, kind: ParseErrorKind, offset: usize, entity: Option<u64>) -> ParseError {
        self.lines.error(self.text, kind, offset, entity)
    }

    /// `(line, column)` (1-based) of a byte offset.
    pub fn locate(&self, offset: usize) -> (usize, usize) {
        self.lines.locate(self.text, offset)
    }

    /// The 1-based line of a byte offset ([`Scanned::locate`]'s line alone).
    pub fn line(&self, offset: usize) -> usize {
        self.lines.line(self.text, offset)
    }

    /// The parameter limits the instances are decoded under.
    pub(crate) fn param_limits(&self) -> ParamLimits {
        self.limits
    }

    /// The instance `#id` (the first one if the id is duplicated).
    #[inline]
    pub fn get(&self, id: u64) -> Option<&RawInstance<'a>> {
        self.index.get(id).and_then(|i| self.instances.get(i))
    }

    /// Decodes an instance's parameters.
    pub fn decode(&self, raw: &RawInstance<'a>) -> Result<Instance<'a>, ParseError> {
        let start = raw.body_offset();
        let end = start + raw.body_len();
        let limits = self.limits;
        grammar::run(self.text.as_bytes(), start, end, |i| {
            grammar::entity_instance_body(i, limits)
        })
        .map(|(body, _)| Instance { id: raw.id, body })
        .map_err(|(kind, at)| self.error_at(kind, at, Some(raw.id)))
    }

    /// Decodes instance `#id`; `referrer` (the instance holding the reference) locates the
    /// error when `#id` is undefined.
    pub fn decode_id(
        &self,
        id: u64,
        referrer: &RawInstance<'a>,
    ) -> Result<Instance<'a>, ParseError> {
        match self.get(id) {
            Some(raw) => self.decode(raw),
            None => Err(self.error_at(
                ParseErrorKind::DanglingReference(id),
                referrer.offset(),
                Some(referrer.id),
            )),
        }
    }

    /// Looks for reference cycles reachable from `roots`, decoding the instances on the way
    /// (iterative depth-first search; each instance is visited once). Returns one located
    /// error per cycle found, at the instance that closes it. Undecodable and undefined
    /// instances are treated as leaves (they are reported elsewhere).
    pub fn find_cycles(&self, roots: impl IntoIterator<Item = u64>) -> Vec<ParseError> {
        const NEW: u8 = 0;
        const ON_PATH: u8 = 1;
        const DONE: u8 = 2;
        // One byte per instance, by its position in the file (a map by id took about 55
        // bytes per instance, 27 MB for a 45 MB file). An undefined id references nothing,
        // so it is on no cycle: it counts as done.
        let mut state = vec![NEW; self.instances.len()];
        let mut state_of = |id: u64, set: Option<u8>| -> u8 {
            match self.index.get(id).and_then(|i| state.get_mut(i)) {
                Some(s) => {
                    if let Some(new) = set {
                        *s = new;
                    }
                    *s
                }
                None => DONE,
            }
        };
        let mut errors = Vec::new();
        for root in roots {
            if state_of(root, None) != NEW {
                continue;
            }
            // (id, references of id, next reference to follow)
            let mut stack: Vec<(u64, Vec<u64>, usize)> = Vec::new();
            state_of(root, Some(ON_PATH));
            stack.push((root, self.references_of(root), 0));
            while let Some((id, refs, next)) = stack.last_mut() {
                let id = *id;
                let Some(&child) = refs.get(*next) else {
                    state_of(id, Some(DONE));
                    stack.pop();
                    continue;
                };
                *next += 1;
                match state_of(child, None) {
                    ON_PATH => {
                        let mut path: Vec<u64> = stack
                            .iter()
                            .map(|f| f.0)
                            .skip_while(|&i| i != child)
                            .collect();
                        path.push(child);
                        let offset = self.get(id).map_or(0, |r| r.offset());
                        errors.push(self.error_at(
                            ParseErrorKind::ReferenceCycle(path),
                            offset,
                            Some(id),
                        ));
                    }
                    DONE => {}
                    _ => {
                        state_of(child, Some(ON_PATH));
                        let refs = self.references_of(child);
                        stack.push((child, refs, 0));
                    }
                }
            }
        }
        errors
    }

    /// The ids an instance references (empty if undefined or undecodable).
    fn references_of(&self, id: u64) -> Vec<u64> {
        let mut out = Vec::new();
        if let Some(raw) = self.get(id) {
            if let Ok(inst) = self.decode(raw) {
                for_each_reference(&inst.body, |r| out.push(r));
            }
        }
        out
    }

    /// Header: records up to `ENDSEC;`. A bad record is a recovered error.
    fn scan_header(&mut self, c: &mut Cursor<'a>, stop: Stop<'_>) -> Result<(), ParseError> {
        let mut records = 0usize;
        loop {
            records += 1;
            if stop.at(records) {
                return Err(ParseError::stopped(c.pos));
            }
            c.skip_ws().map_err(|(k, at)| self.error_at(k, at, None))?;
            if c.peek().is_none() {
                return Err(self.error_at(
                    ParseErrorKind::Missing("ENDSEC; closing HEADER"),
                    c.pos,
                    None,
                ));
            }
            if section_keyword(c, "ENDSEC") {
                c.pos += "ENDSEC".len();
                return end_of_keyword_statement(c).map_err(|(k, at)| self.error_at(k, at, None));
            }
            let end = statement_end(self.text.as_bytes(), c.pos)
                .map_err(|(k, at)| self.error_at(k, at, None))?;
            let limits = self.limits;
            let record = grammar::run(self.text.as_bytes(), c.pos, end, |i| {
                grammar::header_entity(i, limits)
            });
            match record {
                Ok((r, _)) => self.header.push(r),
                Err((k, at)) => self.errors.push(self.error_at(k, at, None)),
            }
            c.pos = end + 1;
        }
    }

    /// Skips an ANCHOR/REFERENCE/SIGNATURE section up to its `ENDSEC;`.
    fn skip_section(&mut self, c: &mut Cursor<'a>, stop: Stop<'_>) -> Result<(), ParseError> {
        let mut statements = 0usize;
        loop {
            statements += 1;
            if stop.at(statements) {
                return Err(ParseError::stopped(c.pos));
            }
            let end = statement_end(self.text.as_bytes(), c.pos)
                .map_err(|(k, at)| self.error_at(k, at, None))?;
            let stmt = self.text.get(c.pos..end).unwrap_or_default().trim();
            c.pos = end + 1;
            if stmt == "ENDSEC" {
                return Ok(());
            }
        }
    }

    /// A DATA section (ISO 10303-21 clause 10), from `DATA` to `ENDSEC;`.
    fn scan_data(
        &mut self,
        c: &mut Cursor<'a>,
        limits: &Limits,
        threads: usize,
        parallel_min_bytes: usize,
        stop: Stop<'_>,
    ) -> Result<(), ParseError> {
        let err = |s: &Scanned<'a>, (k, at): LexError| s.error_at(k, at, None);
        c.pos += "DATA".len();
        c.skip_ws().map_err(|e| err(self, e))?;
        let mut params = Vec::new();
        if c.peek() == Some(b'(') {
            let limits = self.limits;
            params = c
                .rule(|i| grammar::parameter_list(i, limits))
                .map_err(|e| err(self, e))?;
        }
        end_of_keyword_statement(c).map_err(|e| err(self, e))?;
        let first = self.instances.len();
        let bytes = self.text.as_bytes();
        let cuts = if threads > 1 && bytes.len() - c.pos >= parallel_min_bytes {
            cut_points(bytes, c.pos, threads)
        } else {
            Vec::new()
        };
        let text = self.text;
        let lines = &self.lines;
        let mut runs: Vec<Run<'a>> = if cuts.is_empty() {
            vec![scan_statements(
                text,
                lines,
                c.pos,
                usize::MAX,
                limits,
                stop,
            )]
        } else {
            // Piece k runs from cuts[k-1] (or the section start) to cuts[k] (or the end).
            let starts: Vec<usize> = std::iter::once(c.pos).chain(cuts.iter().copied()).collect();
            let stops: Vec<usize> = cuts.iter().copied().chain([usize::MAX]).collect();
            std::thread::scope(|scope| {
                let handles: Vec<_> = starts
                    .iter()
                    .zip(&stops)
                    .skip(1)
                    .map(|(&from, &end)| {
                        scope.spawn(move || scan_statements(text, lines, from, end, limits, stop))
                    })
                    .collect();
                let mut runs = vec![scan_statements(text, lines, c.pos, stops[0], limits, stop)];
                for h in handles {
                    // A piece whose thread failed is dropped; the sequential
                    // continuation below covers its bytes.
                    match h.join() {
                        Ok(r) => runs.push(r),
                        Err(_) => break,
                    }
                }
                runs
            })
        };
        // Keep the pieces that continue exactly where the previous one stopped.
        let mut expected = c.pos;
        let mut k = 0;
        let end = loop {
            let run = match runs.get_mut(k) {
                Some(run) if run.from == expected => std::mem::take(run),
                // No valid piece continues here: finish the section sequentially.
                _ => scan_statements(text, lines, expected, usize::MAX, limits, stop),
            };
            k += 1;
            if self.instances.len() + run.instances.len() > limits.max_entities {
                let over = run
                    .instances
                    .get(limits.max_entities - self.instances.len())
                    .copied();
                return Err(self.error_at(
                    ParseErrorKind::TooManyInstances(limits.max_entities),
                    over.map_or(run.from, |r| r.offset()),
                    over.map(|r| r.id),
                ));
            }
            self.max_id = self.max_id.max(run.max_id);
            if self.instances.is_empty() {
                // The usual case (one DATA section, first piece): take the vector as it
                // is rather than copy 32 bytes per statement.
                self.instances = run.instances;
            } else {
                self.instances.extend(run.instances);
            }
            self.errors.extend(run.errors);
            if let Some(fatal) = run.fatal {
                return Err(fatal);
            }
            match run.end {
                RunEnd::Stop(p) => expected = p,
                other => break other,
            }
        };
        match end {
            RunEnd::EndSec(after) => c.pos = after,
            _ => c.pos = c.end,
        }
        self.sections.push(SectionInfo {
            params,
            instances: first..self.instances.len(),
        });
        Ok(())
    }

    /// Builds the `#id` index; a duplicate id is a recovered error (the first one wins).
    fn build_index(&mut self, _limits: &Limits) {
        let n = self.instances.len();
        let max = self.max_id;
        debug_assert_eq!(max, self.instances.iter().map(|r| r.id).max().unwrap_or(0));
        let dense_ok = usize::try_from(max)
            .ok()
            .filter(|&m| m <= n.saturating_mul(4).saturating_add(1024));
        let mut dups = Vec::new();
        let index = match dense_ok {
            Some(m) => {
                let mut v = vec![IdIndex::NONE; m + 1];
                for (pos, r) in self.instances.iter().enumerate() {
                    let (Ok(slot), Ok(p)) = (usize::try_from(r.id), u32::try_from(pos)) else {
                        continue;
                    };
                    if let Some(cell) = v.get_mut(slot) {
                        if *cell == IdIndex::NONE {
                            *cell = p;
                        } else {
                            dups.push((pos, *cell));
                        }
                    }
                }
                IdIndex::Dense(v)
            }
            None => {
                let mut m = HashMap::with_capacity(n);
                for (pos, r) in self.instances.iter().enumerate() {
                    let Ok(p) = u32::try_from(pos) else { continue };
                    match m.entry(r.id) {
                        std::collections::hash_map::Entry::Vacant(e) => {
                            e.insert(p);
                        }
                        std::collections::hash_map::Entry::Occupied(e) => {
                            dups.push((pos, *e.get()))
                        }
                    }
                }
                IdIndex::Sparse(m)
            }
        };
        self.index = index;
        for (pos, first) in dups {
            let (Some(r), Some(f)) = (
                self.instances.get(pos),
                usize::try_from(first)
                    .ok()
                    .and_then(|f| self.instances.get(f)),
            ) else {
                continue;
            };
            let first_line = self.locate(f.offset()).0;
            let e = self.error_at(
                ParseErrorKind::DuplicateId {
                    id: r.id,
                    first_line,
                },
                r.offset(),
                Some(r.id),
            );
            self.errors.push(e);
        }
        self.errors.sort_by_key(|e| e.offset);
    }
}

/// `#n = ` at the start of a statement: the id, the offset of the body, and the keyword of
/// a simple instance (`None` for a complex one). Inlined into the scan loop: called once
/// per statement, and a call returned its result through memory.
#[allow(clippy::type_complexity)]
#[inline(always)]
fn instance_head(
    text: &str,
    start: usize,
    end: usize,
) -> Result<(u64, usize, Option<&str>), (ParseErrorKind, usize, Option<u64>)> {
    match quick_head(text.as_bytes(), start, end) {
        Some((id, body, keyword_end)) => {
            Ok((id, body, keyword_end.and_then(|e| text.get(body..e))))
        }
        None => instance_head_general(text, start, end),
    }
}

/// The head as nearly every file writes it, `#123=KEYWORD(`, `#123 = KEYWORD(` or
/// `#123 = (` (complex), read without the general lexer: the id (at most 19 digits), the
/// body offset and the end of the keyword (`None` for a complex instance). `None` for any
/// other shape (more blanks, comments, lower case, `!` keywords, errors...), which
/// [`instance_head_general`] then reads; where this answers, it answers the same (tested).
#[inline(always)]
fn quick_head(b: &[u8], start: usize, end: usize) -> Option<(u64, usize, Option<usize>)> {
    let end = end.min(b.len());
    let at = |i: usize| if i < end { b.get(i).copied() } else { None };
    if at(start) != Some(b'#') {
        return None;
    }
    let digits = start + 1;
    // Up to eight digits in one word (most ids), then one at a time.
    let (mut id, n) = crate::real::digit_word(b, digits);
    let mut i = digits + n;
    if i > end {
        return None;
    }
    // 19 digits cannot overflow a u64; a longer id goes to the general path.
    while n == 8 && i - digits < 19 {
        match at(i) {
            Some(c @ b'0'..=b'9') => id = id * 10 + u64::from(c - b'0'),
            _ => break,
        }
        i += 1;
    }
    if i == digits || at(i).is_some_and(|c| c.is_ascii_digit()) {
        return None;
    }
    i += usize::from(at(i) == Some(b' '));
    if at(i) != Some(b'=') {
        return None;
    }
    i += 1;
    i += usize::from(at(i) == Some(b' '));
    match at(i) {
        Some(b'(') => Some((id, i, None)),
        Some(c) if c.is_ascii_uppercase() => {
            // The commonest keyword by far (most statements of a B-spline file are control
            // points) is recognised by one 16-byte comparison instead of the run scan.
            let e = if i + 16 <= end && b.get(i..i + 16) == Some(b"CARTESIAN_POINT(") {
                i + 15
            } else {
                super::keyword_run::keyword_run(b, i, end)
            };
            // A lower-case letter continuing the keyword is an error the general path
            // reports.
            (!at(e).is_some_and(|c| c.is_ascii_lowercase())).then_some((id, i, Some(e)))
        }
        _ => None,
    }
}

/// [`instance_head`] for any input, by the grammar rule (blanks and comments anywhere,
/// located errors).
#[allow(clippy::type_complexity)]
#[cold]
fn instance_head_general(
    text: &str,
    start: usize,
    end: usize,
) -> Result<(u64, usize, Option<&str>), (ParseErrorKind, usize, Option<u64>)> {
    let input = text.as_bytes().get(start..end).unwrap_or_default();
    match grammar::entity_instance_head(input) {
        Ok((_, (id, body, keyword))) => Ok((id, end - body.len(), keyword)),
        Err(e) => {
            let (kind, at) = grammar::located(e, end);
            match grammar::entity_instance_name(input) {
                // A failure after the id names the instance.
                Ok((_, id)) => Err((kind, at, Some(id))),
                // No valid id: show what stands after the `#`.
                Err(_) if input.first() == Some(&b'#') => {
                    let shown: String = text
                        .get(start + 1..end)
                        .unwrap_or_default()
                        .chars()
                        .take_while(|c| c.is_ascii_alphanumeric())
                        .take(30)
                        .collect();
                    Err((ParseErrorKind::InvalidId(shown), start, None))
                }
                Err(_) => Err((kind, at, None)),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// Where the quick head reader answers, the general one answers the same.
        #[test]
        fn quick_head_agrees_with_the_general_reader(
            parts in proptest::collection::vec(proptest::prop_oneof![
                proptest::prelude::Just("#".to_owned()),
                proptest::prelude::Just(" ".to_owned()),
                proptest::prelude::Just("=".to_owned()),
                proptest::prelude::Just("(".to_owned()),
                proptest::prelude::Just("/* c */".to_owned()),
                proptest::prelude::Just("\n".to_owned()),
                "[0-9]{1,22}",
                "[A-Z_][A-Z0-9_]{0,20}",
                proptest::prelude::Just("CARTESIAN_POINT".to_owned()),
                "[a-zA-Z_!][a-zA-Z0-9_]{0,12}",
            ], 1..8),
            cut in 0usize..64,
        ) {
            let text: String = ["#".to_owned()].into_iter().chain(parts).collect();
            let end = cut.min(text.len());
            if let Some((id, body, kw_end)) = quick_head(text.as_bytes(), 0, end) {
                let general = instance_head_general(&text, 0, end);
                proptest::prop_assert_eq!(
                    general,
                    Ok((id, body, kw_end.and_then(|e| text.get(body..e))))
                );
            }
        }
    }

    #[test]
    fn keyword_initial_is_the_keywords_first_byte() {
        let text = file(
            "DATA;\n#1 = CARTESIAN_POINT('',(0.,0.,0.));\n#2=B_SPLINE_CURVE_WITH_KNOTS('',1,(#1,#1),.UNSPECIFIED.,.F.,.F.,(2,2),(0.,1.),.UNSPECIFIED.);\n#3 = ( BOUNDED_CURVE() CURVE() );\n#4 = /* c */ Q_X(1);\n#5 = !USER(1);\n",
        );
        let s = scan(&text, &Limits::default()).unwrap();
        assert_eq!(s.instances.len(), 5);
        for raw in &s.instances {
            assert_eq!(
                raw.keyword_initial(),
                raw.keyword(&text).and_then(|k| k.bytes().next()),
                "#{}",
                raw.id
            );
        }
        let initials: Vec<_> = s.instances.iter().map(|r| r.keyword_initial()).collect();
        assert_eq!(
            initials,
            [Some(b'C'), Some(b'B'), None, Some(b'Q'), Some(b'!')]
        );
    }

    /// The index's entry stays at 24 bytes (a share of every large read's peak memory).
    #[test]
    fn raw_instances_take_24_bytes() {
        assert_eq!(std::mem::size_of::<RawInstance<'_>>(), 24);
    }

    /// The body and keyword read back from the text are the statement's, for the usual
    /// head, a spaced one with a comment, and a complex instance.
    #[test]
    fn bodies_and_keywords_are_read_from_the_text() {
        let text = file("DATA;\n#1=A(1);\n#22 = /* c */ BB ( 2 ) ;\n#3=(X(1)Y(2));\nENDSEC;\n");
        let s = scan(&text, &Limits::default()).unwrap();
        let got: Vec<_> = s
            .instances
            .iter()
            .map(|r| {
                (
                    r.id,
                    r.keyword(&text),
                    r.body(&text),
                    &text[r.offset()..r.offset() + 1],
                )
            })
            .collect();
        assert_eq!(
            got,
            [
                (1, Some("A"), "A(1)", "#"),
                (22, Some("BB"), "BB ( 2 ) ", "#"),
                (3, None, "(X(1)Y(2))", "#"),
            ]
        );
    }

    #[test]
    fn keywords_over_64_kib_are_reported_not_truncated() {
        let long = "A".repeat(usize::from(u16::MAX) + 1);
        let text = file(&format!("DATA;\n#1 = {long}(1);\n#2 = B(2);\nENDSEC;\n"));
        let s = scan(&text, &Limits::default()).unwrap();
        let ids: Vec<u64> = s.instances.iter().map(|r| r.id).collect();
        assert_eq!(ids, [2]);
        assert!(
            s.errors
                .iter()
                .any(|e| e.entity == Some(1) && matches!(e.kind, ParseErrorKind::InvalidId(_))),
            "{:?}",
            s.errors
        );
        // One byte shorter is kept, with its keyword.
        let ok = &long[1..];
        let text = file(&format!("DATA;\n#1 = {ok}(1);\nENDSEC;\n"));
        let s = scan(&text, &Limits::default()).unwrap();
        assert_eq!(s.instances.len(), 1);
        assert_eq!(s.instances[0].keyword(&text).map(str::len), Some(ok.len()));
        assert_eq!(s.instances[0].keyword_initial(), Some(b'A'));
    }

    #[test]
    fn quick_head_reads_the_usual_shapes() {
        for (text, expected) in [
            ("#12=A(", Some((12, 4, Some(5)))),
            ("#12 = CARTESIAN_POINT(", Some((12, 6, Some(21)))),
            ("#12 = CARTESIAN_POINTS(", Some((12, 6, Some(22)))),
            ("#12 = CARTESIAN_POINT (", Some((12, 6, Some(21)))),
            ("#12 = CARTESIAN_POINTx(", None),
            ("#7 = ( A() B() )", Some((7, 5, None))),
            (
                "#1234567890123456789 = A(",
                Some((1234567890123456789, 23, Some(24))),
            ),
            ("#12345678 = A(", Some((12345678, 12, Some(13)))),
            ("#123456789=A(", Some((123456789, 11, Some(12)))),
            ("#12345678901234567890 = A(", None),
            ("#12  = A(", None),
            ("#12 = Ab(", None),
            ("#12 = !A(", None),
            ("#12 /**/ = A(", None),
            ("# 12 = A(", None),
        ] {
            assert_eq!(
                quick_head(text.as_bytes(), 0, text.len()),
                expected,
                "{text}"
            );
        }
    }

    /// Everything a scan produces, for comparing two scans.
    fn summary(s: &Scanned<'_>) -> String {
        format!(
            "{:?}\n{:?}\n{:?}",
            s.instances,
            s.errors,
            s.sections
                .iter()
                .map(|x| x.instances.clone())
                .collect::<Vec<_>>()
        )
    }

    fn agree(text: &str, limits: &Limits) {
        let one = scan(text, limits);
        for threads in [2, 3, 4, 7] {
            let many = scan_impl(text, limits, threads, 0, Stop::NEVER);
            match (&one, &many) {
                (Ok(a), Ok(b)) => assert_eq!(summary(a), summary(b), "{threads} threads"),
                (Err(a), Err(b)) => assert_eq!(a, b, "{threads} threads"),
                _ => panic!("{threads} threads: {one:?} vs {many:?}"),
            }
        }
    }

    fn file(data: &str) -> String {
        format!(
            "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\nENDSEC;\n{data}END-ISO-10303-21;\n"
        )
    }

    #[test]
    fn scan_stops_when_its_signal_fires() {
        use crate::stop::SCAN_POLL;
        use std::sync::atomic::{AtomicUsize, Ordering};
        let points: String = (1..=50_000)
            .map(|i| format!("#{i}=CARTESIAN_POINT('',({i}.,0.,0.));\n"))
            .collect();
        let text = file(&format!("DATA;\n{points}ENDSEC;\n"));
        for threads in [1, 4] {
            // Never fires: the same scan, polled once per SCAN_POLL statements.
            let polls = AtomicUsize::new(0);
            let poll = || {
                polls.fetch_add(1, Ordering::Relaxed);
                false
            };
            let scanned =
                scan_impl(&text, &Limits::default(), threads, 0, Stop::new(&poll)).expect("scans");
            assert_eq!(scanned.instances.len(), 50_000);
            assert_eq!(
                summary(&scanned),
                summary(&scan(&text, &Limits::default()).expect("scans"))
            );
            let n = polls.load(Ordering::Relaxed);
            assert!(
                (50_000 / SCAN_POLL..=50_000 / SCAN_POLL + 2 * threads).contains(&n),
                "{n} polls"
            );
            // Fires at its 3rd poll: the scan ends there, with `Stopped`.
            let polls = AtomicUsize::new(0);
            let fire_at = 3;
            let poll = || polls.fetch_add(1, Ordering::Relaxed) + 1 >= fire_at;
            let e = scan_impl(&text, &Limits::default(), threads, 0, Stop::new(&poll))
                .expect_err("stopped");
            assert_eq!(e.kind, ParseErrorKind::Stopped, "{threads} threads");
            // Each piece stops at its first poll after the signal fired.
            assert!(
                polls.load(Ordering::Relaxed) <= fire_at + threads,
                "{threads} threads"
            );
        }
    }

    #[test]
    fn parallel_scan_equals_sequential_on_tricky_files() {
        let points: String = (1..200)
            .map(|i| format!("#{i} = CARTESIAN_POINT('p;\n#{i}',({i}.,0.,0.));\n"))
            .collect();
        let cases = [
            // Strings and comments containing `;` + `#`, where a cut may land.
            file(&format!("DATA;\n{points}ENDSEC;\n")),
            file(&format!(
                "DATA;\n{points}/* ;\n#5 = X(); */ #900 = A('');\nENDSEC;\n"
            )),
            // Two DATA sections, an error statement in the middle, an unterminated string.
            file(&format!(
                "DATA;\n{points}#x = BAD;\n{points}ENDSEC;\nDATA;\n{points}ENDSEC;\n"
            )),
            file(&format!("DATA;\n{points}#1000 = A('unterminated);\n")),
            file(&format!("DATA;\n{points}")),
            file(&format!("DATA;\n{points}ENDSEC x\n")),
            file("DATA;\nENDSEC;\n"),
        ];
        for text in &cases {
            agree(text, &Limits::default());
            // The entity limit crossed in the middle and near the end.
            for max in [1, 57, 150, 198, 199, 200, 1000] {
                let limits = Limits {
                    max_entities: max,
                    ..Limits::default()
                };
                agree(text, &limits);
            }
        }
    }

    #[test]
    fn parallel_scan_equals_sequential_on_the_samples() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/freecad");
        let mut n = 0;
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "step") {
                let text = std::fs::read_to_string(&path).unwrap();
                agree(&text, &Limits::default());
                n += 1;
            }
        }
        assert!(n > 40, "{n} samples");
    }

    #[test]
    fn cut_points_land_after_a_semicolon_before_a_hash() {
        let text = b"DATA;\n#1=A();\n#2=B('x;y');  \n #3=C();\nENDSEC;";
        for pieces in 2..6 {
            for c in cut_points(text, 6, pieces) {
                assert_eq!(text[c - 1], b';');
                let next = text[c..].iter().find(|b| !b.is_ascii_whitespace());
                assert_eq!(next, Some(&b'#'));
            }
        }
    }
}
