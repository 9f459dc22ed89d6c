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

/// A DE field outside the range IGES 5.3 section 2.2.4.4 gives it: the field number
/// (1-20), the sequence number of the DE line holding it, and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldProblem {
    /// The field number (1-20).
    pub field: u8,
    /// The sequence number of the DE line that holds it.
    pub sequence: usize,
    /// What is wrong.
    pub message: String,
}

impl DirectoryEntry {
    /// The fields of this entry outside their ranges (IGES 5.3 section 2.2.4.4): the entity
    /// type a defined one (2.2.4.4.1), the form one of the type's (2.2.4.4.15, for the types
    /// [`crate::iges::records::is_defined_form`] knows), the status digit pairs (2.2.4.4.9:
    /// blank 0-1, subordinate 0-3, entity use 0-6, hierarchy 0-2), structure 0 or negated,
    /// line font 0-5 or negated, level >= 0 or negated, view, transformation matrix and
    /// label display 0 or positive, line weight 0 to the Global line weight gradations
    /// (parameter 16, when given), color 0-8 or negated. Which entity a pointer names is
    /// the pointer check's.
    pub fn field_problems(&self, line_weight_gradations: Option<i64>) -> Vec<FieldProblem> {
        let mut out = Vec::new();
        let first = self.pointer;
        let second = self.pointer + 1;
        let mut bad = |field: u8, sequence: usize, message: String| {
            out.push(FieldProblem {
                field,
                sequence,
                message,
            });
        };
        if !crate::iges::records::is_defined_entity_type(self.entity_type) {
            bad(
                1,
                first,
                format!(
                    "entity type {} is not one IGES 5.3 defines",
                    self.entity_type
                ),
            );
        }
        if crate::iges::records::is_defined_form(self.entity_type, self.form) == Some(false) {
            bad(
                15,
                second,
                format!(
                    "form {} is not a form of entity type {}",
                    self.form, self.entity_type
                ),
            );
        }
        let s = self.status;
        for (name, value, max) in [
            ("blank status", s.blank, 1),
            ("subordinate entity switch", s.subordinate, 3),
            ("entity use flag", s.use_flag, 6),
            ("hierarchy", s.hierarchy, 2),
        ] {
            if value > max {
                bad(
                    9,
                    first,
                    format!("status number: {name} {value:02} is not 00-{max:02}"),
                );
            }
        }
        if self.structure > 0 {
            bad(
                3,
                first,
                format!(
                    "structure {} is positive: it is 0 or a negated DE pointer",
                    self.structure
                ),
            );
        }
        if self.line_font > 5 {
            bad(
                4,
                first,
                format!(
                    "line font pattern {} is not 0-5 or a negated DE pointer",
                    self.line_font
                ),
            );
        }
        for (field, name, value) in [
            (6, "view", self.view),
            (7, "transformation matrix", self.transform),
            (8, "label display associativity", self.label_display),
        ] {
            if value < 0 {
                bad(
                    field,
                    first,
                    format!("{name} {value} is negative: it is 0 or a DE pointer"),
                );
            }
        }
        let weight_ok = self.line_weight >= 0
            && line_weight_gradations.is_none_or(|g| self.line_weight <= g.max(0));
        if !weight_ok {
            bad(
                12,
                second,
                match line_weight_gradations {
                    Some(g) => format!(
                        "line weight number {} is not 0-{g} (Global parameter 16)",
                        self.line_weight
                    ),
                    None => format!("line weight number {} is negative", self.line_weight),
                },
            );
        }
        if self.color > 8 {
            bad(
                13,
                second,
                format!(
                    "color number {} is not 0-8 or a negated DE pointer",
                    self.color
                ),
            );
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(f: impl FnOnce(&mut DirectoryEntry)) -> Vec<u8> {
        let mut e = DirectoryEntry {
            pointer: 5,
            entity_type: 126,
            ..DirectoryEntry::default()
        };
        f(&mut e);
        e.field_problems(Some(4)).iter().map(|p| p.field).collect()
    }

    /// The ends of each range pass; one past them fails, at the field.
    #[test]
    fn field_ranges_at_their_ends() {
        assert_eq!(entry(|_| {}), Vec::<u8>::new());
        let top = Status {
            blank: 1,
            subordinate: 3,
            use_flag: 6,
            hierarchy: 2,
        };
        assert_eq!(
            entry(|e| {
                e.status = top;
                e.line_font = 5;
                e.line_weight = 4;
                e.color = 8;
                e.form = 5;
                e.structure = -7;
                e.line_font = -9;
                e.level = -11;
                e.view = 3;
            }),
            Vec::<u8>::new()
        );
        assert_eq!(entry(|e| e.status.hierarchy = 3), vec![9]);
        assert_eq!(entry(|e| e.line_weight = 5), vec![12]);
        assert_eq!(entry(|e| e.color = 9), vec![13]);
        assert_eq!(entry(|e| e.form = 6), vec![15]);
        assert_eq!(entry(|e| e.entity_type = 127), vec![1]);
        // Implementor-defined types and forms, macro instances: defined.
        assert_eq!(entry(|e| e.entity_type = 5001), Vec::<u8>::new());
        assert_eq!(entry(|e| e.entity_type = 600), Vec::<u8>::new());
        assert_eq!(
            entry(|e| {
                e.entity_type = 402;
                e.form = 5001;
            }),
            Vec::<u8>::new()
        );
        // The second-line fields are located on the second line.
        let e = DirectoryEntry {
            pointer: 5,
            entity_type: 126,
            color: 9,
            ..DirectoryEntry::default()
        };
        assert_eq!(e.field_problems(None)[0].sequence, 6);
    }

    /// The form lists of IGES 5.3 chapter 4 for 104 (4.5), 106 (sections 4.6-4.11), the
    /// annotation entities 202-230 (4.55-4.68), 304 (4.70), 310 (4.74), 312 (4.75), 314
    /// (4.76), 316 (4.77), 320 (4.78), 322 (4.79), 404 (4.96), 406 (4.97, its forms
    /// 4.98-4.132), 410 (4.134, 4.135), 412 (4.136), 414 (4.137), 416 (4.138), 418 (4.139),
    /// 420 (4.140), 422 (4.141) and 430 (4.142): each form the standard gives passes, a
    /// form it does not give is reported at field 15. A type whose forms are not checked
    /// reports nothing, so dropping a type from the table fails here.
    #[test]
    fn forms_of_the_standard_and_others() {
        let with_form = |entity_type: i64, form: i64| {
            entry(|e| {
                e.entity_type = entity_type;
                e.form = form;
            })
        };
        let cases: &[(i64, &[i64], &[i64])] = &[
            (104, &[0, 1, 2, 3], &[4, -1]),
            (202, &[0], &[1]),
            (204, &[0], &[1]),
            (206, &[0], &[1]),
            (208, &[0], &[1]),
            (210, &[0], &[1]),
            (
                212,
                &[0, 1, 4, 8, 100, 101, 102, 105],
                &[9, 99, 103, 104, 106, 5001, -1],
            ),
            (213, &[0], &[1]),
            (214, &[1, 2, 6, 11, 12], &[0, 13, 5001, -1]),
            (216, &[0, 1, 2], &[3]),
            (218, &[0, 1], &[2]),
            (220, &[0], &[1]),
            (222, &[0, 1], &[2]),
            (228, &[0, 1, 2, 3, 5001, 9999], &[4, 5000, 10000, -1]),
            (230, &[0, 1], &[2]),
            (310, &[0], &[1]),
            (312, &[0, 1], &[2]),
            (320, &[0], &[1]),
            (322, &[0, 1, 2], &[3]),
            (412, &[0], &[1]),
            (414, &[0], &[1]),
            (418, &[0], &[1]),
            (420, &[0], &[1]),
            (422, &[0, 1], &[2]),
            (
                106,
                &[1, 2, 3, 11, 12, 13, 20, 21, 31, 34, 38, 40, 63],
                &[0, 4, 10, 14, 19, 22, 30, 39, 41, 62, 64],
            ),
            (304, &[1, 2], &[0, 3]),
            (314, &[0], &[1, -1]),
            (316, &[0], &[1]),
            (404, &[0, 1], &[2, -1]),
            (
                406,
                &[1, 2, 3, 5, 10, 11, 15, 27, 36, 5001, 9999],
                &[0, 4, 37, 5000, 10000],
            ),
            (410, &[0, 1], &[2]),
            (416, &[0, 1, 2, 3, 4], &[5, -1]),
            (430, &[0, 1], &[2]),
        ];
        for &(entity_type, defined, undefined) in cases {
            for &form in defined {
                assert_eq!(
                    with_form(entity_type, form),
                    Vec::<u8>::new(),
                    "{entity_type} form {form}"
                );
            }
            for &form in undefined {
                assert_eq!(
                    with_form(entity_type, form),
                    vec![15],
                    "{entity_type} form {form}"
                );
            }
        }
    }
}
