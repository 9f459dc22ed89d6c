//! Test inputs shared by the one-pass readers' tests: every STEP file of the repository,
//! a file around some DATA statements, and random damage to a statement.

use crate::Limits;
use proptest::prelude::*;

pub(super) fn file(data: &str) -> String {
    format!(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('x'),'2;1');\nENDSEC;\nDATA;\n{data}\nENDSEC;\nEND-ISO-10303-21;\n"
    )
}

fn walk(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    for e in rd.flatten() {
        let p = e.path();
        if p.is_dir() {
            walk(&p, out);
        } else if p
            .extension()
            .is_some_and(|x| x.eq_ignore_ascii_case("step") || x.eq_ignore_ascii_case("stp"))
        {
            out.push(p);
        }
    }
}

pub(super) fn repo_files() -> Vec<(std::path::PathBuf, String)> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut paths = Vec::new();
    walk(&root.join("samples"), &mut paths);
    walk(&root.join("tests"), &mut paths);
    paths.sort();
    paths
        .into_iter()
        .filter_map(|p| {
            let bytes = std::fs::read(&p).ok()?;
            Some((p, String::from_utf8(bytes).ok()?))
        })
        .collect()
}

#[derive(Debug, Clone)]
pub(super) enum Edit {
    Delete(usize),
    Duplicate(usize),
    Replace(usize, u8),
    Insert(usize, &'static str),
    /// Drop the point of the n-th real (`1.` -> `1`).
    Integer(usize),
}

pub(super) fn edit() -> impl Strategy<Value = Edit> {
    let bytes = prop::sample::select(b"#(),.'$*/ 0123456789E+-_AFTUX\t\n".to_vec());
    let inserts = prop::sample::select(vec![
        " ", "\r\n", "\t", "/* c */", "''", "'", "(", ")", ",", "1", "$", "E5", "A()",
    ]);
    prop_oneof![
        any::<usize>().prop_map(Edit::Delete),
        any::<usize>().prop_map(Edit::Duplicate),
        (any::<usize>(), bytes).prop_map(|(i, c)| Edit::Replace(i, c)),
        (any::<usize>(), inserts).prop_map(|(i, s)| Edit::Insert(i, s)),
        any::<usize>().prop_map(Edit::Integer),
    ]
}

fn apply(stmt: &str, edits: &[Edit]) -> String {
    let mut b = stmt.as_bytes().to_vec();
    for e in edits {
        // Keep `#id=` and the final `;` so the statement stays one instance.
        let Some(eq) = b.iter().position(|&c| c == b'=') else {
            break;
        };
        let lo = eq + 1;
        let hi = b.len().saturating_sub(1);
        if hi <= lo {
            break;
        }
        let at = |i: usize| lo + i % (hi - lo);
        match e {
            Edit::Delete(i) => {
                b.remove(at(*i));
            }
            Edit::Duplicate(i) => {
                let k = at(*i);
                b.insert(k, b[k]);
            }
            Edit::Replace(i, c) => {
                let k = at(*i);
                b[k] = *c;
            }
            Edit::Insert(i, s) => {
                let k = at(*i);
                b.splice(k..k, s.bytes());
            }
            Edit::Integer(n) => {
                // The n-th `digit.` followed by a delimiter.
                let spots: Vec<usize> = (lo + 1..hi)
                    .filter(|&k| {
                        b[k] == b'.'
                            && b[k - 1].is_ascii_digit()
                            && matches!(b.get(k + 1), Some(b',' | b')'))
                    })
                    .collect();
                if !spots.is_empty() {
                    b.remove(spots[n % spots.len()]);
                }
            }
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

/// `stmt` damaged by `edits`, after a point in a file, checked by a reader's `check_text`
/// (which asserts its contract) under the default limits and under `max_params` parameters
/// and `max_depth` nesting.
pub(super) fn check_damaged(
    stmt: &str,
    edits: &[Edit],
    max_params: usize,
    max_depth: usize,
    check_text: impl Fn(&str, &Limits) -> (usize, usize),
) {
    let damaged = apply(stmt, edits);
    let text = file(&format!("#1=CARTESIAN_POINT('',(0.,0.,0.));\n{damaged}"));
    check_text(&text, &Limits::default());
    let tight = Limits {
        max_params_per_entity: max_params,
        max_nesting_depth: max_depth,
        ..Limits::default()
    };
    check_text(&text, &tight);
}
