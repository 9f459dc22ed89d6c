//! What a file that is neither STEP nor IGES is: empty, another text encoding, another
//! format (PDF, DXF, STL, glTF, ZIP, gzip, STEP-XML ...), binary data or plain text.
//!
//! ISO 10303-21 clause 5 makes an exchange structure a sequence of 8-bit characters that
//! starts with `ISO-10303-21;`; IGES 5.3 section 1.4 makes a file 80-column ASCII records
//! (section 2.1) whose first record carries `S` (or `G`, or `C`/`B` for the compressed and
//! binary forms) in column 73. A file that does neither gets a message that says what it
//! is, so the user can fix the real problem (decompress it, export it again as STEP ...).

/// Why the content is not a STEP or IGES file: a stable code and a sentence.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NotExchange {
    /// `format.empty`, `encoding.utf16`, `encoding.utf32`, `format.other`,
    /// `format.binary`, `format.unknown`.
    pub code: &'static str,
    /// What the content is, in words.
    pub what: String,
}

/// Every code [`describe`] gives.
pub const CODES: [&str; 6] = [
    "format.empty",
    "encoding.utf16",
    "encoding.utf32",
    "format.other",
    "format.binary",
    "format.unknown",
];

fn not(code: &'static str, what: impl Into<String>) -> NotExchange {
    NotExchange {
        code,
        what: what.into(),
    }
}

/// Describes content that [`crate::Format::sniff`] did not recognise.
pub fn describe(bytes: &[u8]) -> NotExchange {
    let head = &bytes[..bytes.len().min(4096)];
    if bytes.is_empty() {
        return not("format.empty", "the file is empty (0 bytes)");
    }
    if head.iter().all(u8::is_ascii_whitespace) && bytes.len() == head.len() {
        return not(
            "format.empty",
            format!("the file holds only whitespace ({} bytes)", bytes.len()),
        );
    }
    if let Some(found) = encoding(head) {
        return found;
    }
    if let Some((kind, advice)) = other_format(bytes, head) {
        return not(
            "format.other",
            format!("this is {kind}, not a STEP (ISO 10303-21) or IGES 5.3 file{advice}"),
        );
    }
    let control = head
        .iter()
        .filter(|&&b| b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r' | 0x0c))
        .count();
    if control * 100 > head.len() {
        return not(
            "format.binary",
            format!(
                "binary data ({control} control bytes in the first {} bytes), not a STEP (ISO 10303-21) or IGES 5.3 text file",
                head.len()
            ),
        );
    }
    let first = head
        .split(|&b| b == b'\n')
        .find(|l| !l.iter().all(u8::is_ascii_whitespace))
        .unwrap_or(&[]);
    let first = first.strip_suffix(b"\r").unwrap_or(first);
    if let Some(iges) = iges_like(first) {
        return not("format.unknown", iges);
    }
    let shown: String = String::from_utf8_lossy(&first[..first.len().min(40)])
        .chars()
        .map(|c| if c.is_control() { '.' } else { c })
        .collect();
    not(
        "format.unknown",
        format!(
            "text that is neither a STEP file (it must start with ISO-10303-21;) nor an IGES file (S in column 73 of 80); it starts with \"{shown}\""
        ),
    )
}

/// Byte-order marks of UTF-16/UTF-32, and UTF-16 without one (NUL in every other byte).
fn encoding(head: &[u8]) -> Option<NotExchange> {
    let say = |code, name: &str| {
        Some(not(
            code,
            format!(
                "the file is {name} text; STEP (ISO 10303-21 clause 5) and IGES (5.3 section 1.4) files are 8-bit text: save it as UTF-8 or ASCII"
            ),
        ))
    };
    if head.starts_with(b"\xFF\xFE\x00\x00") {
        return say("encoding.utf32", "UTF-32 LE (byte-order mark FF FE 00 00)");
    }
    if head.starts_with(b"\x00\x00\xFE\xFF") {
        return say("encoding.utf32", "UTF-32 BE (byte-order mark 00 00 FE FF)");
    }
    if head.starts_with(b"\xFF\xFE") {
        return say("encoding.utf16", "UTF-16 LE (byte-order mark FF FE)");
    }
    if head.starts_with(b"\xFE\xFF") {
        return say("encoding.utf16", "UTF-16 BE (byte-order mark FE FF)");
    }
    let probe = &head[..head.len().min(64) & !1];
    if probe.len() >= 8 {
        let (even, odd) = probe.chunks(2).fold((0, 0), |(e, o), p| {
            (e + usize::from(p[0] == 0), o + usize::from(p[1] == 0))
        });
        let half = probe.len() / 2;
        if odd == half && even == 0 {
            return say("encoding.utf16", "UTF-16 LE (no byte-order mark)");
        }
        if even == half && odd == 0 {
            return say("encoding.utf16", "UTF-16 BE (no byte-order mark)");
        }
    }
    None
}

/// Signatures of the formats a STEP or IGES file is most often confused with.
fn other_format(bytes: &[u8], head: &[u8]) -> Option<(&'static str, &'static str)> {
    let starts = |s: &[u8]| head.starts_with(s);
    let text = trim_start(head);
    let lower: Vec<u8> = text[..text.len().min(512)].to_ascii_lowercase();
    let has = |s: &[u8]| memchr::memmem::find(&lower, s).is_some();
    if starts(b"PK\x03\x04") {
        return Some((
            "a ZIP archive (a compressed STEP such as .stpZ, a 3MF or an office document)",
            ": extract the STEP or IGES file first",
        ));
    }
    if starts(b"\x1F\x8B") {
        return Some((
            "gzip-compressed data (such as .stp.gz)",
            ": decompress it first",
        ));
    }
    let kind = if starts(b"%PDF-") {
        "a PDF document"
    } else if starts(b"glTF") {
        "a binary glTF (GLB) mesh"
    } else if starts(b"\x89PNG") {
        "a PNG image"
    } else if starts(b"\xFF\xD8\xFF") {
        "a JPEG image"
    } else if starts(b"3D Geometry File Format") {
        "a Rhino 3DM file"
    } else if starts(b"**ABCDEFGHIJKLMNOPQRSTUVWXYZ") {
        "a Parasolid transmit file (X_T)"
    } else if lower.starts_with(b"<?xml") || lower.starts_with(b"<") {
        if has(b"iso_10303_28") || has(b"iso-10303-28") || has(b"urn:oid:1.0.10303.28") {
            "a STEP-XML file (ISO 10303-28; nurbsx reads the clear-text encoding of ISO 10303-21)"
        } else if has(b"<html") || has(b"<!doctype html") {
            "an HTML page"
        } else if has(b"<svg") {
            "an SVG image"
        } else {
            "an XML document"
        }
    } else if lower.starts_with(b"#vrml") {
        "a VRML file"
    } else if lower.starts_with(b"ply\n") || lower.starts_with(b"ply\r\n") {
        "a PLY mesh"
    } else if lower.starts_with(b"solid") && has(b"facet") {
        "an ASCII STL mesh"
    } else if binary_stl(bytes) {
        "a binary STL mesh"
    } else if dxf(text) {
        "a DXF drawing"
    } else {
        return None;
    };
    Some((kind, ""))
}

fn trim_start(s: &[u8]) -> &[u8] {
    let n = s.iter().take_while(|b| b.is_ascii_whitespace()).count();
    &s[n..]
}

/// 80-byte header, a little-endian triangle count, 50 bytes per triangle.
fn binary_stl(bytes: &[u8]) -> bool {
    let Some(count) = bytes.get(80..84) else {
        return false;
    };
    let n = u32::from_le_bytes([count[0], count[1], count[2], count[3]]) as usize;
    n > 0 && n.checked_mul(50).and_then(|b| b.checked_add(84)) == Some(bytes.len())
}

/// DXF group code 0 followed by SECTION.
fn dxf(text: &[u8]) -> bool {
    let mut lines = text
        .split(|&b| b == b'\n')
        .map(|l| trim_start(l.strip_suffix(b"\r").unwrap_or(l)));
    matches!((lines.next(), lines.next()), (Some(b"0"), Some(b"SECTION")))
}

/// A first line that has an IGES section letter near column 73 but is not an 80-column
/// Start record, or names the compressed/binary IGES forms.
fn iges_like(first: &[u8]) -> Option<String> {
    if first.len() >= 74 && first.len() <= 84 {
        let letter = first[72];
        if letter == b'C' {
            return Some("an IGES file in the compressed ASCII form (C in column 73, IGES 5.3 appendix B), which nurbsx does not read; export it in the fixed 80-column form".into());
        }
        if letter == b'B' {
            return Some("an IGES file in the binary form (IGES 5.3 appendix C), which nurbsx does not read; export it in the fixed 80-column form".into());
        }
    }
    let s_at = first
        .iter()
        .enumerate()
        .rev()
        .find(|&(i, &b)| {
            (68..78).contains(&i)
                && matches!(b, b'S' | b'G')
                && first[i + 1..]
                    .iter()
                    .all(|c| c.is_ascii_digit() || *c == b' ')
                && first.len() > i + 1
        })
        .map(|(i, _)| i);
    s_at.map(|i| {
        format!(
            "text that looks like IGES with the section letter in column {} and {} columns on its first line; IGES 5.3 section 2.1 puts it in column 73 of 80",
            i + 1,
            first.len()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn code(b: &[u8]) -> &'static str {
        describe(b).code
    }

    #[test]
    fn names_what_the_file_is() {
        assert_eq!(code(b""), "format.empty");
        assert_eq!(code(b" \n\r\n\t"), "format.empty");
        assert_eq!(code(b"\xFF\xFEI\0S\0O\0"), "encoding.utf16");
        assert_eq!(
            code(b"I\0S\0O\0-\x001\x000\x003\x000\x003\0"),
            "encoding.utf16"
        );
        assert_eq!(
            code(b"\0I\0S\0O\0-\x001\x000\x003\x000\x003"),
            "encoding.utf16"
        );
        assert_eq!(code(b"\xFF\xFE\0\0I\0\0\0"), "encoding.utf32");
        assert_eq!(code(b"%PDF-1.7\n"), "format.other");
        assert!(describe(b"%PDF-1.7").what.contains("PDF"));
        assert!(
            describe(b"  0\r\nSECTION\r\n  2\r\nHEADER\r\n")
                .what
                .contains("DXF")
        );
        assert!(
            describe(b"solid x\n facet normal 0 0 1\n")
                .what
                .contains("ASCII STL")
        );
        let mut stl = vec![b' '; 80];
        stl.extend(1u32.to_le_bytes());
        stl.extend([0u8; 50]);
        assert!(describe(&stl).what.contains("binary STL"));
        assert!(describe(b"PK\x03\x04....").what.contains("ZIP"));
        assert!(describe(b"\x1F\x8B\x08\0").what.contains("gzip"));
        assert!(
            describe(b"<?xml version=\"1.0\"?><iso_10303_28 />")
                .what
                .contains("ISO 10303-28")
        );
        assert!(describe(b"<!DOCTYPE html><html>").what.contains("HTML"));
        let binary: Vec<u8> = (0..4096u32)
            .map(|i| (i * 131 % 256).to_le_bytes()[0])
            .collect();
        assert_eq!(code(&binary), "format.binary");
        let d = describe(b"hello, this is not CAD data\n");
        assert_eq!(d.code, "format.unknown");
        assert!(
            d.what.contains("\"hello, this is not CAD data\""),
            "{}",
            d.what
        );
    }

    #[test]
    fn names_iges_with_wrong_columns_and_other_forms() {
        let short = format!("{:<71}S{:>7}\n", "start", 1);
        let d = describe(short.as_bytes());
        assert!(
            d.what.contains("column 72") && d.what.contains("79 columns"),
            "{}",
            d.what
        );
        let compressed = format!("{:<72}C{:>7}\n", "start", 1);
        assert!(describe(compressed.as_bytes()).what.contains("compressed"));
    }
}
