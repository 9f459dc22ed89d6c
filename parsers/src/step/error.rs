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
/// `LineIndex::BLOCK`-byte (256-byte) block it stores the number of newlines before the
/// block, as a 32-bit count relative to its superblock of `LineIndex::SUPER` blocks (16 MiB,
/// so the count cannot wrap) plus one full count per superblock. Building it is one SIMD
/// count per block (no per-newline work, which is what dominated a per-line table on a
/// 100 MB file with a million lines), it takes 4 bytes per 256 of input (1.6 % of the
/// file), and a lookup counts newlines in at most half a block, on the side of the offset
/// nearer a block edge. A whole-part read looks up the line of every entity, vertex, edge
/// and face it makes, mostly where the text is no longer in cache: 1 KiB blocks with a
/// line start each made those lookups 5 % of a 100 MB B-rep read's time.
///
/// The start of the line (for the column) is the last newline before the offset in its
/// block; when the block has none (a line longer than the block's start), the block that
/// holds that newline is found by a binary search of the counts (the first block with the
/// same count as the offset's follows it), so a file of one long line costs a logarithm per
/// lookup, never a walk back.
#[derive(Debug, Default)]
pub struct LineIndex {
    table: OnceLock<LineTable>,
}

/// [`LineIndex`]'s counts.
#[derive(Debug)]
struct LineTable {
    /// Newlines before each superblock.
    base: Vec<usize>,
    /// Newlines before each block, less its superblock's base.
    relative: Vec<u32>,
}

impl LineTable {
    fn new(bytes: &[u8]) -> Self {
        let blocks = bytes.len().div_ceil(LineIndex::BLOCK);
        let mut base = Vec::with_capacity(blocks / LineIndex::SUPER + 1);
        let mut relative = Vec::with_capacity(blocks);
        let mut total = 0usize;
        for (k, chunk) in bytes.chunks(LineIndex::BLOCK).enumerate() {
            if k % LineIndex::SUPER == 0 {
                base.push(total);
            }
            let from = base.last().copied().unwrap_or(0);
            // At most SUPER * BLOCK (2^24) bytes since the base: it fits.
            relative.push(u32::try_from(total - from).unwrap_or(u32::MAX));
            total += block_newlines(chunk);
        }
        LineTable { base, relative }
    }

    /// Newlines before block `k` (`k` < the number of blocks).
    #[inline]
    fn before(&self, k: usize) -> usize {
        let base = self.base.get(k / LineIndex::SUPER).copied().unwrap_or(0);
        let rel = self.relative.get(k).copied().unwrap_or(0);
        base + usize::try_from(rel).unwrap_or(0)
    }

    fn blocks(&self) -> usize {
        self.relative.len()
    }
}

impl LineIndex {
    /// Bytes per block.
    const BLOCK: usize = 256;
    /// Blocks per superblock (16 MiB: fewer newlines than a `u32` holds).
    const SUPER: usize = 1 << 16;

    /// `(line, column)` of `offset` in `text`, both 1-based.
    pub fn locate(&self, text: &str, offset: usize) -> (usize, usize) {
        let bytes = text.as_bytes();
        let (table, offset, k, line) = self.count(bytes, offset);
        let from = k * Self::BLOCK;
        let hay = bytes.get(from..offset).unwrap_or_default();
        let line_start = match memchr::memrchr(b'\n', hay) {
            Some(p) => from + p + 1,
            None => Self::line_start_before(table, bytes, k, table.before(k)),
        };
        (line, offset - line_start + 1)
    }

    /// The 1-based line of `offset` in `text`: [`LineIndex::locate`]'s line, without
    /// looking for where the line starts.
    pub fn line(&self, text: &str, offset: usize) -> usize {
        self.count(text.as_bytes(), offset).3
    }

    /// The table, `offset` within `bytes`, the block holding it and its 1-based line.
    #[inline]
    fn count(&self, bytes: &[u8], offset: usize) -> (&LineTable, usize, usize, usize) {
        let table = self.table.get_or_init(|| LineTable::new(bytes));
        let offset = offset.min(bytes.len());
        // `offset == len` on a block boundary falls just past the table: use the last block.
        let k = (offset / Self::BLOCK).min(table.blocks().saturating_sub(1));
        let from = k * Self::BLOCK;
        let before = table.before(k);
        // The newlines before `offset` in its block, counted over the shorter side: from the
        // block's start, or back from the next block's count.
        let to = from + Self::BLOCK;
        let newlines = if k + 1 < table.blocks() && offset - from > to - offset {
            let rest = bytes.get(offset..to).unwrap_or_default();
            table.before(k + 1) - before - block_newlines(rest)
        } else {
            block_newlines(bytes.get(from..offset).unwrap_or_default())
        };
        (table, offset, k, before + newlines + 1)
    }

    /// Where the line holding the first byte of block `k` starts, `before` being the
    /// newlines before that block: just after the last of them, which lies in the block
    /// before the first one whose count is `before` (found by a binary search).
    fn line_start_before(table: &LineTable, bytes: &[u8], k: usize, before: usize) -> usize {
        if before == 0 {
            return 0;
        }
        // Blocks 0..=k: counts non-decreasing, block 0's is 0 < before.
        let (mut lo, mut hi) = (0, k);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if table.before(mid) < before {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        // Block lo - 1 holds the newline (its count is below lo's).
        let from = lo.saturating_sub(1) * Self::BLOCK;
        let block = bytes.get(from..from + Self::BLOCK).unwrap_or_default();
        memchr::memrchr(b'\n', block).map_or(0, |p| from + p + 1)
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

/// The number of `\n` in `chunk` (at most [`LineIndex::BLOCK`] bytes): a block of the table,
/// or the part of one a lookup counts.
///
/// Sixteen bytes per compare: each gives 0xFF (-1) per newline lane; four are added and the
/// sum subtracted from a byte counter per lane (a lane counts at most 16 of a 256-byte
/// block, and a sum of four is at least -4, so nothing wraps), summed once per block; no
/// work per newline (a per-match count costs tens of instructions per line, which on a
/// 10 MB file was 2 % of a whole B-spline read).
fn block_newlines(chunk: &[u8]) -> usize {
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
    // The sixteen lane counts (each at most 16, so any eight sum below 256) added by one
    // multiply per half: the top byte of x * 0x0101..01 is the sum of x's bytes.
    let a = lanes.to_array();
    let half = |h: &[u8]| {
        let mut b = [0u8; 8];
        b.copy_from_slice(h);
        u64::from_le_bytes(b).wrapping_mul(0x0101_0101_0101_0101) >> 56
    };
    let (lo, hi) = a.split_at(8);
    let count = usize::try_from(half(lo) + half(hi)).unwrap_or(0);
    count + full.remainder().iter().filter(|&&b| b == b'\n').count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_newline_count_agrees_with_a_byte_loop() {
        // Every block length up to a full block, newlines at every lane position, runs
        // of newlines that fill whole lanes (a lane counts up to 16 in a full block).
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
                assert_eq!(block_newlines(&block), count, "length {len}");
            }
        }
        let all = vec![b'\n'; LineIndex::BLOCK];
        assert_eq!(block_newlines(&all), LineIndex::BLOCK);
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

    /// Lines of random lengths, from empty to several blocks long (line starts found
    /// blocks back), starting with a long line (its start is the text's); every offset.
    #[test]
    fn line_index_agrees_with_counting_on_random_lines() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = |m: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % m
        };
        for _ in 0..8 {
            let mut text = "a".repeat(usize::try_from(next(3 * 256)).unwrap_or(0));
            while text.len() < 6000 {
                let len = match next(4) {
                    0 => next(4),
                    1 => next(80),
                    2 => next(300),
                    _ => next(1200),
                };
                text.push('\n');
                text.push_str(&"b".repeat(usize::try_from(len).unwrap_or(0)));
            }
            let index = LineIndex::default();
            let (mut line, mut start) = (1, 0);
            for offset in 0..=text.len() {
                assert_eq!(
                    index.locate(&text, offset),
                    (line, offset - start + 1),
                    "offset {offset}"
                );
                assert_eq!(index.line(&text, offset), line, "offset {offset}");
                if text.as_bytes().get(offset) == Some(&b'\n') {
                    line += 1;
                    start = offset + 1;
                }
            }
        }
        assert_eq!(LineIndex::default().locate("", 0), (1, 1));
        assert_eq!(LineIndex::default().locate("\n\n", 2), (3, 1));
    }

    /// Across a superblock edge (16 MiB): the lines and columns of offsets around it, on a
    /// text of short lines and on one long line over the edge.
    #[test]
    fn line_index_counts_across_superblocks() {
        let edge = LineIndex::SUPER * LineIndex::BLOCK;
        for line_len in [9usize, 3 * LineIndex::BLOCK + 5] {
            let mut text = String::with_capacity(edge + 4096);
            while text.len() < edge + 4096 {
                text.push_str(&"c".repeat(line_len));
                text.push('\n');
            }
            // The long-line text gets one line over the edge: no newline in 2 KiB before it.
            if line_len > 9 {
                let bytes = blank_newlines(&mut text, edge - 2048, edge + 100);
                assert!(bytes > 0);
            }
            let index = LineIndex::default();
            let head = &text[..edge - 3000];
            let (mut line, mut start) = (
                head.matches('\n').count() + 1,
                head.rfind('\n').map_or(0, |p| p + 1),
            );
            for offset in edge - 3000..edge + 3000 {
                assert_eq!(
                    index.locate(&text, offset),
                    (line, offset - start + 1),
                    "offset {offset}, lines of {line_len}"
                );
                assert_eq!(index.line(&text, offset), line, "offset {offset}");
                if text.as_bytes()[offset] == b'\n' {
                    line += 1;
                    start = offset + 1;
                }
            }
        }
    }

    /// Replaces the newlines of `text[from..to]` by `d` (ASCII for ASCII: still text);
    /// returns how many it replaced.
    fn blank_newlines(text: &mut String, from: usize, to: usize) -> usize {
        let mut n = 0;
        let blanked: String = text[from..to]
            .chars()
            .map(|c| {
                if c == '\n' {
                    n += 1;
                    'd'
                } else {
                    c
                }
            })
            .collect();
        text.replace_range(from..to, &blanked);
        n
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
