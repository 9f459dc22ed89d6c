//! The repository's exchange files for tests (test-only): every file with one of the given
//! extensions under the given folders, for the tests that compare a fast reader with the
//! general one on all of them.

use std::path::{Path, PathBuf};

/// Every file under `dirs` (relative to the crate root, searched recursively) whose
/// extension is one of `extensions` (lower case; matched case-insensitively), sorted.
pub(crate) fn repository_files(dirs: &[&str], extensions: &[&str]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack: Vec<PathBuf> = dirs
        .iter()
        .map(|d| Path::new(env!("CARGO_MANIFEST_DIR")).join(d))
        .collect();
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                stack.push(path);
            } else if path
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| extensions.contains(&e.to_ascii_lowercase().as_str()))
            {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}
