//! Writing outputs so that nothing is lost or left half-written: an
//! existing file is replaced only when asked, and every file is written
//! under a temporary name in the same folder, then renamed into place
//! (atomic on the same file system).

use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// The temporary name `path` is written under: hidden, in the same
/// folder, with the process id, keeping the extension (writers pick the
/// format by it).
pub fn temporary_name(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.partial-{}{ext}", std::process::id()))
}

/// Refuses an existing `path` unless `force`.
///
/// # Errors
/// [`Error::Exists`].
pub fn check_new(path: &Path, force: bool) -> Result<()> {
    if !force && path.exists() {
        return Err(Error::Exists(path.to_path_buf()));
    }
    Ok(())
}

/// Writes `path` through `write(temporary path)`, then renames it into
/// place; on failure the temporary file is removed and `path` is left as
/// it was. An existing `path` is refused unless `force`.
///
/// # Errors
/// [`Error::Exists`], `write`'s error, or the rename's.
pub fn write_atomic(
    path: &Path,
    force: bool,
    write: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    check_new(path, force)?;
    let tmp = temporary_name(path);
    let result = write(&tmp).and_then(|()| {
        std::fs::rename(&tmp, path).map_err(|source| Error::File {
            path: path.to_path_buf(),
            source,
        })
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes a set of files that belong together (an OBJ, its `.mtl` and
/// its textures): `write(path in a temporary folder beside path)` writes
/// them all into a hidden folder next to `path`, then each is renamed
/// into place. Nothing is moved if one of them exists (unless `force`) or
/// the writing fails; the temporary folder is removed either way. Returns
/// the paths written.
///
/// # Errors
/// [`Error::Exists`] naming the first file in the way, `write`'s error,
/// or a rename's.
pub fn write_atomic_files(
    path: &Path,
    force: bool,
    write: impl FnOnce(&Path) -> Result<()>,
) -> Result<Vec<PathBuf>> {
    check_new(path, force)?;
    let parent = path.parent().filter(|d| !d.as_os_str().is_empty());
    let dir = parent.unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.partial-{}", std::process::id()));
    let file_error = |path: &Path| {
        let path = path.to_path_buf();
        move |source| Error::File { path, source }
    };
    std::fs::create_dir_all(&tmp).map_err(file_error(&tmp))?;
    let result = (|| {
        write(&tmp.join(&name))?;
        let mut files = Vec::new();
        for entry in std::fs::read_dir(&tmp).map_err(file_error(&tmp))? {
            let entry = entry.map_err(file_error(&tmp))?;
            // Beside `path` as it was given: `out.obj` → `out.mtl`, not
            // `./out.mtl`.
            let target = match parent {
                Some(d) => d.join(entry.file_name()),
                None => PathBuf::from(entry.file_name()),
            };
            check_new(&target, force)?;
            files.push((entry.path(), target));
        }
        for (from, to) in &files {
            std::fs::rename(from, to).map_err(file_error(to))?;
        }
        Ok(files.into_iter().map(|(_, to)| to).collect())
    })();
    let _ = std::fs::remove_dir_all(&tmp);
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_leaves_nothing_and_an_existing_file_is_kept() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.txt");
        let failed = write_atomic(&out, false, |tmp| {
            std::fs::write(tmp, "half").unwrap();
            Err(Error::Invalid("interrupted".into()))
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        std::fs::write(&out, "keep").unwrap();
        let refused = write_atomic(&out, false, |tmp| {
            std::fs::write(tmp, "new").map_err(|source| Error::File {
                path: tmp.into(),
                source,
            })
        });
        assert!(matches!(refused, Err(Error::Exists(_))));
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "keep");
        write_atomic(&out, true, |tmp| {
            std::fs::write(tmp, "new").map_err(|source| Error::File {
                path: tmp.into(),
                source,
            })
        })
        .unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
