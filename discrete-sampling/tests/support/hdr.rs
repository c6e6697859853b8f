//! Luminance of the Radiance `.hdr` images in `$TRILUX_DATA/hdr`, shared by
//! the real-data tests and the comparison example.

use std::path::{Path, PathBuf};

/// A decoded image's luminance, row-major, row 0 at the top.
pub(crate) struct Luminance {
    pub(crate) name: String,
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) values: Vec<f32>,
}

/// The data folder named by `TRILUX_DATA`, or `None` when it is unset.
///
/// A relative path is taken from the workspace root (where the README's
/// commands run), since cargo runs tests and examples from other folders. A
/// variable that names no folder is a mistake, not a reason to skip.
pub(crate) fn data_dir() -> Option<PathBuf> {
    let given = PathBuf::from(std::env::var_os("TRILUX_DATA")?);
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let candidates = [given.clone(), workspace.join(&given)];
    match candidates.into_iter().find(|p| p.is_dir()) {
        Some(dir) => Some(dir),
        None => panic!(
            "TRILUX_DATA={} is neither a folder nor one relative to the workspace root",
            given.display()
        ),
    }
}

/// The `.hdr` files in `$TRILUX_DATA/hdr`, sorted; `None` when the variable
/// is unset (the caller prints a notice and skips).
pub(crate) fn hdr_files() -> Option<Vec<PathBuf>> {
    let dir = data_dir()?.join("hdr");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| {
            panic!(
                "TRILUX_DATA is set but {} is unreadable: {e}",
                dir.display()
            )
        })
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("hdr")))
        .collect();
    files.sort();
    Some(files)
}

/// Rec. 709 luminance `0.2126 R + 0.7152 G + 0.0722 B` of an HDR image.
pub(crate) fn load_luminance(path: &Path) -> Result<Luminance, String> {
    let image = image::open(path)
        .map_err(|e| format!("{}: {e}", path.display()))?
        .to_rgb32f();
    let (width, height) = (image.width() as usize, image.height() as usize);
    let values = image
        .pixels()
        .map(|p| discrete_sampling::luminance([p[0], p[1], p[2]]))
        .collect();
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Luminance {
        name,
        width,
        height,
        values,
    })
}
