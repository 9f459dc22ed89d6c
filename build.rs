//! Embeds the built web page (`web/dist`, made by `npm run build` in `web/`) into the
//! binary when it is present; without it the service serves a page saying how to build it.
//! Writes `$OUT_DIR/web_assets.rs`: a list of (path, bytes) pairs, empty without the UI.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Most files embedded: a Vite build has a handful; more means a wrong directory.
const MAX_FILES: usize = 500;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR")?);
    let dist = root.join("web").join("dist");
    // Without `web/dist`, watch `web/` so that a later `npm run build` is picked up; with
    // it, watch the built files only.
    if dist.is_dir() {
        println!("cargo:rerun-if-changed=web/dist");
    } else {
        println!("cargo:rerun-if-changed=web");
    }
    let mut files = Vec::new();
    if dist.join("index.html").is_file() {
        collect(&dist, &dist, &mut files)?;
    }
    files.sort();
    if files.len() > MAX_FILES {
        return Err(format!("{} holds over {MAX_FILES} files", dist.display()).into());
    }
    let mut out = String::from("&[\n");
    for (rel, abs) in &files {
        writeln!(out, "    ({rel:?}, include_bytes!({abs:?})),")?;
    }
    out.push(']');
    let target = PathBuf::from(std::env::var("OUT_DIR")?).join("web_assets.rs");
    std::fs::write(target, out)?;
    Ok(())
}

/// Every file under `dir`, as (path relative to `base` with `/` separators, absolute path).
fn collect(
    base: &Path,
    dir: &Path,
    files: &mut Vec<(String, String)>,
) -> Result<(), Box<dyn std::error::Error>> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_dir() {
            collect(base, &path, files)?;
        } else if path.is_file() {
            let rel = path.strip_prefix(base)?;
            let rel: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            files.push((rel.join("/"), path.to_string_lossy().into_owned()));
        }
        if files.len() > MAX_FILES {
            return Err(format!("{} holds over {MAX_FILES} files", base.display()).into());
        }
    }
    Ok(())
}
