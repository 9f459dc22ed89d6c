//! Directory Entries: two 80-column records of ten 8-column fields each (IGES 5.3 section
//! 2.2.4.4). The rule that reads them is [`super::grammar::directory`].

/// The status number (DE field 9): four 2-digit fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Status {
    /// Digits 1-2: 0 visible, 1 blanked.
    pub blank: u8,
    /// Digits 3-4: 0 independent, 1 physically dependent, 2 logically, 3 both.
    pub subordinate: u8,
    /// Digits 5-6: 0 geometry, 1 annotation, 2 definition, 3 other, 4 logical/positional,
    /// 5 2-D parametric, 6 construction.
    pub use_flag: u8,
    /// Digits 7-8: 0 global top-down, 1 global defer, 2 use hierarchy property.
    pub hierarchy: u8,
}

impl Status {
    /// The 8-digit form written in DE field 9.
    pub fn to_digits(self) -> String {
        format!(
            "{:02}{:02}{:02}{:02}",
            self.blank % 100,
            self.subordinate % 100,
            self.use_flag % 100,
            self.hierarchy % 100
        )
    }
}

/// One Directory Entry, all twenty fields (the two sequence fields as `pointer`).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct DirectoryEntry {
    /// The DE pointer: the sequence number of the first record (odd; `2 i + 1` for the
    /// `i`-th entry, counted by position).
    pub pointer: usize,
    /// 1-based file line of the first record.
    pub line: usize,
    /// Field 1 (and 11): entity type number.
    pub entity_type: i64,
    /// Field 2: parameter data pointer (P sequence number of the first line).
    pub parameter_pointer: i64,
    /// Field 3: structure (0 or negated DE pointer).
    pub structure: i64,
    /// Field 4: line font pattern.
    pub line_font: i64,
    /// Field 5: level.
    pub level: i64,
    /// Field 6: view.
    pub view: i64,
    /// Field 7: transformation matrix (0 or DE pointer of a 124).
    pub transform: i64,
    /// Field 8: label display associativity.
    pub label_display: i64,
    /// Field 9: status number.
    pub status: Status,
    /// Field 12: line weight number.
    pub line_weight: i64,
    /// Field 13: color number.
    pub color: i64,
    /// Field 14: parameter line count.
    pub parameter_line_count: i64,
    /// Field 15: form number.
    pub form: i64,
    /// Fields 16-17: reserved (kept as text).
    pub reserved: [String; 2],
    /// Field 18: entity label (up to 8 characters, trimmed).
    pub label: String,
    /// Field 19: entity subscript number.
    pub subscript: i64,
}
