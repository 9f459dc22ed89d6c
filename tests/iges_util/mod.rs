//! A small column-exact IGES line builder for the tests, independent of the crate's writer
//! (the gimli test-assembler idea): every record is formatted here by hand.
#![allow(dead_code)]

/// One 80-column record.
pub fn rec(data: &str, section: char, seq: usize) -> String {
    assert!(data.len() <= 72, "{data}");
    format!("{data:<72}{section}{seq:07}\n")
}

/// Builds a file record by record.
#[derive(Default)]
pub struct Builder {
    pub start: Vec<String>,
    pub global: Vec<String>,
    pub d: Vec<String>,
    pub p: Vec<String>,
    pub pd: char,
    pub rd: char,
}

pub struct De<'a> {
    pub ty: i64,
    pub form: i64,
    pub transform: i64,
    pub status: &'a str,
    pub label: &'a str,
}

impl Default for De<'_> {
    fn default() -> Self {
        De {
            ty: 126,
            form: 0,
            transform: 0,
            status: "00000000",
            label: "",
        }
    }
}

impl Builder {
    pub fn new(global: &str) -> Self {
        let mut b = Builder {
            pd: ',',
            rd: ';',
            ..Default::default()
        };
        b.start.push("nurbsx test file".into());
        let mut rest = global;
        while !rest.is_empty() {
            let take = rest.len().min(72);
            b.global.push(rest[..take].to_owned());
            rest = &rest[take..];
        }
        b
    }

    pub fn with_delims(mut self, pd: char, rd: char) -> Self {
        self.pd = pd;
        self.rd = rd;
        self
    }

    /// Adds an entity whose parameter text is split greedily at parameter delimiters
    /// (no Hollerith strings in `params`). Returns the DE pointer.
    pub fn entity(&mut self, de: De<'_>, params: &str) -> usize {
        let mut lines = Vec::new();
        let mut cur = String::new();
        for (k, piece) in params.split_inclusive([self.pd, self.rd]).enumerate() {
            let _ = k;
            if cur.len() + piece.len() > 64 {
                lines.push(std::mem::take(&mut cur));
            }
            cur.push_str(piece);
        }
        if !cur.is_empty() {
            lines.push(cur);
        }
        self.entity_lines(de, &lines)
    }

    /// Adds an entity from data lines given verbatim (each at most 64 columns).
    pub fn entity_lines(&mut self, de: De<'_>, lines: &[String]) -> usize {
        let pointer = self.d.len() + 1;
        let pstart = self.p.len() + 1;
        self.d.push(format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
            de.ty, pstart, 0, 0, 0, 0, de.transform, 0, de.status
        ));
        self.d.push(format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
            de.ty,
            0,
            0,
            lines.len(),
            de.form,
            "",
            "",
            de.label,
            0
        ));
        for l in lines {
            assert!(l.len() <= 64, "{l}");
            self.p.push(format!("{l:<64} {pointer:>7}"));
        }
        pointer
    }

    pub fn build(&self) -> String {
        let mut s = String::new();
        for (k, l) in self.start.iter().enumerate() {
            s += &rec(l, 'S', k + 1);
        }
        for (k, l) in self.global.iter().enumerate() {
            s += &rec(l, 'G', k + 1);
        }
        for (k, l) in self.d.iter().enumerate() {
            s += &rec(l, 'D', k + 1);
        }
        for (k, l) in self.p.iter().enumerate() {
            s += &rec(l, 'P', k + 1);
        }
        s += &rec(
            &format!(
                "S{:7}G{:7}D{:7}P{:7}",
                self.start.len(),
                self.global.len(),
                self.d.len(),
                self.p.len()
            ),
            'T',
            1,
        );
        s
    }
}

/// The Open CASCADE 7.4 Global section quoted in spec.md a.2.
pub const OCCT_GLOBAL: [&str; 4] = [
    ",,31HOpen CASCADE IGES processor 7.4,13HFilename.iges,",
    "16HOpen CASCADE 7.4,31HOpen CASCADE IGES processor 7.4,32,308,15,308,15,",
    ",1.,2,2HMM,1,0.01,15H20260730.183948,0.0026726,158.75,,,11,0,",
    "15H20260730.183948,;",
];

/// A comma list of `n` reals `base, base+1, ...` written with one decimal.
pub fn seq_reals(base: f64, n: usize) -> String {
    (0..n)
        .map(|k| format!("{:.1}", base + k as f64))
        .collect::<Vec<_>>()
        .join(",")
}
