//! Located errors of the Part 21 layer: [`ParseError`] (syntax and structure) and
//! [`SchemaError`] (a typed record's attribute does not match the EXPRESS definition).
//!
//! Every error carries a 1-based line and column (columns count bytes; Part 21 files are
//! ASCII outside strings) and the `#id` of the instance when one is known.

use std::sync::OnceLock;

use crate::real::RealError;

/// What went wrong while reading the exchange structure (ISO 10303-21 clauses 5-12).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ParseErrorKind {
    /// A token other than the one the grammar requires at this place.
    #[error("expected {expected}, found {found}")]
    Expected {
        /// What the grammar requires here.
        expected: &'static str,
        /// A short rendering of what is there instead.
        found: String,
    },
    /// A keyword with lower-case letters (ISO 10303-21 6.4: keywords are upper case).
    #[error("keyword `{0}` is not upper case")]
    LowercaseKeyword(String),
    /// A string without its closing apostrophe.
    #[error("unterminated string")]
    UnterminatedString,
    /// A `/*` comment without `*/`.
    #[error("unterminated comment")]
    UnterminatedComment,
    /// A binary literal `"..."` that is not a hex digit string starting with 0-3.
    #[error("invalid binary literal")]
    InvalidBinary,
    /// A REAL token that does not match the grammar (`1.52.3`, `1.e5`, `.5`).
    #[error("invalid REAL `{0}`")]
    InvalidReal(String),
    /// A REAL token whose value overflows `f64` (`1.E400`).
    #[error("REAL `{0}` is not finite")]
    NonFiniteReal(String),
    /// An INTEGER token outside the `i64` range.
    #[error("INTEGER `{0}` is out of range")]
    IntegerOverflow(String),
    /// An entity instance name `#n` outside the `u64` range (or `#` without digits).
    #[error("invalid instance name `#{0}`")]
    InvalidId(String),
    /// A typed parameter `KEYWORD(...)` with other than one parameter.
    #[error("typed parameter `{0}` must hold exactly one parameter")]
    TypedArity(String),
    /// Lists nested deeper than [`Limits::max_nesting_depth`](crate::Limits).
    #[error("parameter lists nested deeper than the limit of {0}")]
    NestingTooDeep(usize),
    /// More parameters in one instance than [`Limits::max_params_per_entity`](crate::Limits).
    #[error("more than {0} parameters in one instance")]
    TooManyParameters(usize),
    /// More instances than [`Limits::max_entities`](crate::Limits).
    #[error("more than {0} entity instances")]
    TooManyInstances(usize),
    /// The caller's [`Stop`](crate::Stop) signal fired during the scan. Only the offset
    /// is set (line and column are 0): locating it would cost a pass over the text.
    #[error("the scan was stopped by its caller")]
    Stopped,
    /// Input larger than [`Limits::max_input_bytes`](crate::Limits).
    #[error("input of {size} bytes exceeds the limit of {limit} bytes")]
    InputTooLarge {
        /// Input size.
        size: usize,
        /// The limit.
        limit: usize,
    },
    /// The same instance name defined twice.
    #[error("instance #{id} is defined twice (first at line {first_line})")]
    DuplicateId {
        /// The id.
        id: u64,
        /// Line of the first definition.
        first_line: usize,
    },
    /// A reference to an instance that is not defined.
    #[error("reference to undefined instance #{0}")]
    DanglingReference(u64),
    /// A reference chain that returns to where it started.
    #[error("reference cycle {}", render_cycle(.0))]
    ReferenceCycle(Vec<u64>),
    /// Input after `END-ISO-10303-21;`.
    #[error("unexpected input after END-ISO-10303-21;")]
    TrailingGarbage,
    /// An edition-3 ANCHOR, REFERENCE or SIGNATURE section, skipped (its content is not
    /// needed for geometry).
    #[error("{0} section skipped")]
    SkippedSection(&'static str),
    /// A required part of the file structure is missing (`ISO-10303-21;`, `HEADER;`...).
    #[error("missing {0}")]
    Missing(&'static str),
}

fn render_cycle(ids: &[u64]) -> String {
    // A hostile file can make a cycle of millions of instances: show its ends only, so
    // the message stays readable and small.
    const SHOWN: usize = 8;
    let names = |s: &[u64]| s.iter().map(|id| format!("#{id}")).collect::<Vec<_>>();
    if ids.len() <= 2 * SHOWN {
        return names(ids).join(" -> ");
    }
    let (head, tail) = (&ids[..SHOWN], &ids[ids.len() - SHOWN..]);
    format!(
        "{} -> ... ({} more) -> {}",
        names(head).join(" -> "),
        ids.len() - 2 * SHOWN,
        names(tail).join(" -> ")
    )
}

/// A located Part 21 error.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}, column {column}{}: {kind}", entity_suffix(*.entity))]
pub struct ParseError {
    /// What went wrong.
    pub kind: ParseErrorKind,
    /// Byte offset in the input.
    pub offset: usize,
    /// 1-based line.
    pub line: usize,
    /// 1-based column (in bytes).
    pub column: usize,
    /// The instance the error belongs to, when known.
    pub entity: Option<u64>,
}

impl ParseError {
    /// The error of a scan stopped at `offset` ([`ParseErrorKind::Stopped`], not located).
    pub(crate) fn stopped(offset: usize) -> Self {
        ParseError {
            kind: ParseErrorKind::Stopped,
            offset,
            line: 0,
            column: 0,
            entity: None,
        }
    }
}

fn entity_suffix(entity: Option<u64>) -> String {
    entity.map(|id| format!(" (#{id})")).unwrap_or_default()
}

/// Why a typed record could not be read from an instance (ISO 10303-42 attribute lists).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "line {line}, column {column} (#{entity}): {entity_type}{}: {message}",
    attribute_suffix(.attribute)
)]
pub struct SchemaError {
    /// The instance.
    pub entity: u64,
    /// The entity type (or the partial entity of a complex instance) being read.
    pub entity_type: String,
    /// The attribute: its 1-based position within the record as written (the partial record
    /// for a complex instance), and its EXPRESS name.
    pub attribute: Option<(usize, &'static str)>,
    /// Expected vs found, or what else is wrong.
    pub message: String,
    /// 1-based line of the instance.
    pub line: usize,
    /// 1-based column of the instance.
    pub column: usize,
}

impl SchemaError {
    /// The message without the line/column prefix: entity, attribute and what is wrong
    /// (for callers that show the location separately).
    pub fn detail(&self) -> String {
        format!(
            "{}{}: {}",
            self.entity_type,
            attribute_suffix(&self.attribute),
            self.message
        )
    }
}

fn attribute_suffix(a: &Option<(usize, &'static str)>) -> String {
    match a {
        Some((i, name)) => format!(" parameter {i} `{name}`"),
        None => String::new(),
    }
}

/// Maps byte offsets to 1-based line and column numbers.
///
/// The table is built on first use (files without errors and callers that never ask for a
/// line pay nothing) and is indexed by *byte blocks*, not lines: for every
/// `LineIndex::BLOCK`-byte (1 KiB) block it stores the number of newlines before the block and
/// where the line containing the block's first byte starts. Building it is one SIMD count
/// per block (no per-newline work, which is what dominated a per-line table on a
/// 100 MB file with a million lines), it takes 16 bytes per KiB of input (1.6 % of the
/// file), and a lookup counts newlines in at most one block (a whole-part read looks up the
/// line of every entity, vertex, edge and face it makes: with 4 KiB blocks these counts
/// were 5 % of its instructions outside the pcurve fitting).
#[derive(Debug, Default)]
pub struct LineIndex {
    /// `blocks[k]` = (newlines in `text[..k * BLOCK]`, start of the line containing byte
    /// `k * BLOCK`).
    blocks: OnceLock<Vec<(usize, usize)>>,
}

impl LineIndex {
    /// Bytes per block.
    const BLOCK: usize = 1024;

    /// `(line, column)` of `offset` in `text`, both 1-based.
    pub fn locate(&self, text: &str, offset: usize) -> (usize, usize) {
        let bytes = text.as_bytes();
        let blocks = self.blocks.get_or_init(|| {
            let mut v = Vec::with_capacity(bytes.len() / Self::BLOCK + 1);
            let (mut newlines, mut line_start) = (0, 0);
            for (k, chunk) in bytes.chunks(Self::BLOCK).enumerate() {
                v.push((newlines, line_start));
                let (count, last) = block_newlines(chunk);
                newlines += count;
                if let Some(p) = last {
                    line_start = k * Self::BLOCK + p + 1;
                }
            }
            v
        });
        let offset = offset.min(bytes.len());
        let k = offset / Self::BLOCK;
        // `offset == len` on a block boundary falls just past the table: use the last block.
        let (k, (before, block_line_start)) = match blocks.get(k) {
            Some(&b) => (k, b),
            None => match blocks.len().checked_sub(1) {
                Some(last) => (last, blocks.get(last).copied().unwrap_or((0, 0))),
                None => (0, (0, 0)),
            },
        };
        let from = k * Self::BLOCK;
        let hay = bytes.get(from..offset).unwrap_or_default();
        // The newlines before `offset` in its block, counted over the shorter side: from the
        // block's start, or back from the next block's count (every locate of a large read
        // counted half a block on average; now at most that).
        let to = from + Self::BLOCK;
        let newlines = match blocks.get(k + 1) {
            Some(&(after, _)) if offset - from > to - offset => {
                let rest = bytes.get(offset..to).unwrap_or_default();
                after - before - memchr::memchr_iter(b'\n', rest).count()
            }
            _ => memchr::memchr_iter(b'\n', hay).count(),
        };
        let line_start = memchr::memrchr(b'\n', hay).map_or(block_line_start, |p| from + p + 1);
        (before + newlines + 1, offset - line_start + 1)
    }

    /// A located error at `offset`.
    pub fn error(
        &self,
        text: &str,
        kind: ParseErrorKind,
        offset: usize,
        entity: Option<u64>,
    ) -> ParseError {
        let (line, column) = self.locate(text, offset);
        ParseError {
            kind,
            offset,
            line,
            column,
            entity,
        }
    }
}

impl From<(RealError, String)> for ParseErrorKind {
    fn from((e, token): (RealError, String)) -> Self {
        match e {
            RealError::Syntax => ParseErrorKind::InvalidReal(token),
            RealError::NonFinite => ParseErrorKind::NonFiniteReal(token),
        }
    }
}

/// The number of `\n` in `chunk` (at most [`LineIndex::BLOCK`] bytes) and the position of
/// the last one.
///
/// Sixteen bytes per compare: each gives 0xFF (-1) per newline lane; four are added and the
/// sum subtracted from a byte counter per lane (a lane counts at most 64 of a 1 KiB block,
/// and a sum of four is at least -4, so nothing wraps),
/// summed once per block; no work per newline (a per-match count costs tens of
/// instructions per line, which on a 10 MB file was 2 % of a whole B-spline read). The
/// last newline is searched from the end, where it usually lies within one line's length.
fn block_newlines(chunk: &[u8]) -> (usize, Option<usize>) {
    use wide::u8x16;
    let nl = u8x16::splat(b'\n');
    let lane = |c: &[u8]| {
        let mut a = [0u8; 16];
        a.copy_from_slice(c);
        u8x16::new(a).cmp_eq(nl)
    };
    let mut lanes = u8x16::splat(0);
    // 64 bytes per iteration (four compares, one loop step), then 16 at a time.
    let mut quads = chunk.chunks_exact(64);
    for q in quads.by_ref() {
        let (a, b) = q.split_at(32);
        let ((a0, a1), (b0, b1)) = (a.split_at(16), b.split_at(16));
        lanes -= (lane(a0) + lane(a1)) + (lane(b0) + lane(b1));
    }
    let mut full = quads.remainder().chunks_exact(16);
    for c in full.by_ref() {
        lanes -= lane(c);
    }
    let tail = full.remainder();
    let mut count: usize = lanes.to_array().iter().map(|&n| usize::from(n)).sum();
    count += tail.iter().filter(|&&b| b == b'\n').count();
    if count == 0 {
        return (0, None);
    }
    if let Some(p) = tail.iter().rposition(|&b| b == b'\n') {
        return (count, Some(chunk.len() - tail.len() + p));
    }
    let full_len = chunk.len() - tail.len();
    let mut end = full_len;
    while end >= 16 {
        let mut a = [0u8; 16];
        a.copy_from_slice(chunk.get(end - 16..end).unwrap_or(&[0; 16]));
        // One bit per lane in the low 16 bits (never negative), so the narrowing is exact.
        #[allow(clippy::cast_sign_loss, clippy::cast_possible_truncation)]
        let mask = u8x16::new(a).cmp_eq(nl).move_mask() as u16;
        if mask != 0 {
            return (count, Some(end - 16 + 15 - mask.leading_zeros() as usize));
        }
        end -= 16;
    }
    (count, None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_newline_count_agrees_with_a_byte_loop() {
        // Every block length up to a full block, newlines at every lane position, runs
        // of newlines that fill whole lanes (a lane counts up to 64 in a full block).
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        for len in 0..=LineIndex::BLOCK {
            for density in [0u64, 1, 8, 64, 256] {
                let block: Vec<u8> = (0..len)
                    .map(|_| {
                        state ^= state << 13;
                        state ^= state >> 7;
                        state ^= state << 17;
                        if state % 256 < density {
                            b'\n'
                        } else {
                            state.to_le_bytes()[1] | 1
                        }
                    })
                    .collect();
                let count = block.iter().filter(|&&b| b == b'\n').count();
                let last = block.iter().rposition(|&b| b == b'\n');
                assert_eq!(block_newlines(&block), (count, last), "length {len}");
            }
        }
        let all = vec![b'\n'; LineIndex::BLOCK];
        assert_eq!(
            block_newlines(&all),
            (LineIndex::BLOCK, Some(LineIndex::BLOCK - 1))
        );
    }

    #[test]
    fn block_line_index_agrees_with_counting() {
        // Lines of varying length, CRLF and empty lines, across several index blocks; then
        // lines longer than a block (a line start several blocks back), and a text whose
        // length is an exact multiple of the block.
        let mut text = String::new();
        for i in 0..3000 {
            text.push_str(&"x".repeat(i % 7));
            text.push_str(if i % 3 == 0 { "\r\n" } else { "\n" });
        }
        text.push_str(&"y".repeat(3 * LineIndex::BLOCK + 17));
        text.push('\n');
        text.push_str(&"z".repeat(LineIndex::BLOCK * 8 - text.len() % LineIndex::BLOCK));
        assert_eq!(text.len() % LineIndex::BLOCK, 0);
        let index = LineIndex::default();
        for offset in (0..=text.len())
            .step_by(3)
            .chain([text.len(), text.len() + 5])
        {
            let offset = offset.min(text.len());
            let before = &text[..offset];
            let line = before.matches('\n').count() + 1;
            let column = offset - before.rfind('\n').map_or(0, |p| p + 1) + 1;
            assert_eq!(
                index.locate(&text, offset),
                (line, column),
                "offset {offset}"
            );
        }
    }

    #[test]
    fn long_cycles_are_shortened() {
        assert_eq!(render_cycle(&[1, 2, 1]), "#1 -> #2 -> #1");
        let ids: Vec<u64> = (1..=100_000).chain([1]).collect();
        let s = render_cycle(&ids);
        assert!(s.starts_with("#1 -> #2 -> "), "{s}");
        assert!(s.contains("(99985 more)"), "{s}");
        assert!(s.ends_with("#99999 -> #100000 -> #1"), "{s}");
        assert!(s.len() < 200);
    }
}
