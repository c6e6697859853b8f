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

/// Refuses an existing `path` unless `force`, and a folder at `path`
/// even with `force` (a file cannot replace it).
///
/// # Errors
/// [`Error::Exists`], or [`Error::Invalid`] naming the folder.
pub fn check_new(path: &Path, force: bool) -> Result<()> {
    if path.is_dir() {
        return Err(Error::Invalid(format!(
            "{}: a folder is in the way of this output (remove it, or write to another name)",
            path.display()
        )));
    }
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
/// its textures; a `.gltf` and its `.bin`): `write(path in a temporary
/// folder beside path)` writes them all into a hidden folder next to
/// `path`, then each is renamed into place, `path` itself last (a failed
/// rename never leaves a new `path` referring to files that did not
/// arrive). Nothing is moved if one of them exists (unless `force`), if
/// one of them is a folder (even with `force`), or if the writing fails;
/// the temporary folder is removed either way. Returns the paths written,
/// sorted.
///
/// # Errors
/// [`Error::Exists`] naming the first file in the way, [`Error::Invalid`]
/// naming a folder in the way (and what was being written), `write`'s
/// error, or a rename's.
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
            files.push((entry.path(), target));
        }
        // `path` last, the others in a stable order.
        files.sort_by_key(|(_, to)| (to.as_path() == path, to.clone()));
        // Every target checked before any is replaced: a refusal leaves
        // nothing half-written.
        for (_, to) in &files {
            if to.is_dir() {
                return Err(Error::Invalid(format!(
                    "{}: a folder is in the way of writing {}; nothing was moved into place \
                     (remove the folder, or write to another name)",
                    to.display(),
                    described(path, &files)
                )));
            }
            check_new(to, force)?;
        }
        for (from, to) in &files {
            std::fs::rename(from, to).map_err(file_error(to))?;
        }
        let mut written: Vec<PathBuf> = files.into_iter().map(|(_, to)| to).collect();
        written.sort();
        Ok(written)
    })();
    let _ = std::fs::remove_dir_all(&tmp);
    result
}

/// What a set of files is: `out.gltf with out.bin`, `out.obj with
/// out.mtl and out_0.png`.
fn described(path: &Path, files: &[(PathBuf, PathBuf)]) -> String {
    let others: Vec<String> = files
        .iter()
        .filter(|(_, to)| to != path)
        .map(|(_, to)| to.display().to_string())
        .collect();
    match others.split_last() {
        None => path.display().to_string(),
        Some((last, [])) => format!("{} with {last}", path.display()),
        Some((last, rest)) => format!("{} with {} and {last}", path.display(), rest.join(", ")),
    }
}

/// Writes a glTF output by extension, atomically, refusing to overwrite
/// unless `force`: `.glb` as one file ([`write_atomic`]), `.gltf` with its
/// `.bin` beside it ([`write_atomic_files`], both or neither). `write`
/// writes to a temporary path; its errors name `path` (and the `.bin`
/// beside it), not the temporary files. Returns the files written,
/// sorted.
///
/// # Errors
/// As [`write_atomic_files`].
pub fn write_gltf(
    path: &Path,
    force: bool,
    write: impl FnOnce(&Path) -> trilux_io::Result<()>,
) -> Result<Vec<PathBuf>> {
    let gltf = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf"));
    if gltf {
        write_atomic_files(path, force, |tmp| {
            write(tmp).map_err(|e| at_output(e, tmp, path))
        })
    } else {
        write_atomic(path, force, |tmp| {
            write(tmp).map_err(|e| at_output(e, tmp, path))
        })?;
        Ok(vec![path.to_path_buf()])
    }
}

/// A writer's error about the temporary file `tmp` (or a file beside it
/// in the temporary folder of a set of files) as one about `path`.
fn at_output(mut e: trilux_io::Error, tmp: &Path, path: &Path) -> Error {
    if e.path == tmp {
        e.path = path.to_path_buf();
    } else if tmp.file_name() == path.file_name()
        && let Some(name) = e.path.file_name()
        && e.path.parent() == tmp.parent()
    {
        // A set of files: `tmp` is `path`'s name in a temporary folder.
        e.path = path.with_file_name(name);
    }
    Error::from(e)
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

    /// Writes `out.gltf` and `out.bin` into the temporary folder, as the
    /// glTF writer does.
    fn gltf_and_bin(tmp: &Path) -> Result<()> {
        let write = |p: &Path, text: &str| {
            std::fs::write(p, text).map_err(|source| Error::File {
                path: p.into(),
                source,
            })
        };
        write(tmp, "new gltf")?;
        write(&tmp.with_extension("bin"), "new bin")
    }

    #[test]
    fn a_folder_in_the_way_of_a_set_of_files_is_refused_before_anything_is_moved() {
        let dir = tempfile::tempdir().unwrap();
        let gltf = dir.path().join("x.gltf");
        let bin = dir.path().join("x.bin");
        std::fs::create_dir(&bin).unwrap();
        // With --force, and without an old x.gltf ...
        let e = write_atomic_files(&gltf, true, gltf_and_bin).unwrap_err();
        let text = e.to_string();
        assert!(matches!(e, Error::Invalid(_)), "{e:?}");
        assert!(
            text.starts_with(&format!("{}: a folder is in the way", bin.display())),
            "{text}"
        );
        assert!(
            text.contains(&format!(
                "writing {} with {}",
                gltf.display(),
                bin.display()
            )),
            "{text}"
        );
        assert!(text.contains("nothing was moved"), "{text}");
        assert!(!gltf.exists(), "a .gltf without its .bin");
        // ... and with one, which is kept as it was.
        std::fs::write(&gltf, "old gltf").unwrap();
        write_atomic_files(&gltf, true, gltf_and_bin).unwrap_err();
        assert_eq!(std::fs::read_to_string(&gltf).unwrap(), "old gltf");
        assert!(bin.is_dir());
        // No temporary folder or file left.
        let mut names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["x.bin", "x.gltf"]);
        // Once the folder is gone, both are written, the paths sorted.
        std::fs::remove_dir(&bin).unwrap();
        let files = write_atomic_files(&gltf, true, gltf_and_bin).unwrap();
        assert_eq!(files, [bin.clone(), gltf.clone()]);
        assert_eq!(std::fs::read_to_string(&bin).unwrap(), "new bin");
        assert_eq!(std::fs::read_to_string(&gltf).unwrap(), "new gltf");
    }

    #[test]
    fn a_folder_where_the_output_goes_is_refused_even_with_force() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.png");
        std::fs::create_dir(&out).unwrap();
        for force in [false, true] {
            let mut called = false;
            let e = write_atomic(&out, force, |_| {
                called = true;
                Ok(())
            })
            .unwrap_err();
            assert!(!called, "written before the check");
            let text = e.to_string();
            assert!(
                text.starts_with(&format!("{}: a folder is in the way", out.display())),
                "{text}"
            );
            let e = write_atomic_files(&out, force, |_| Ok(())).unwrap_err();
            assert!(matches!(e, Error::Invalid(_)), "{e:?}");
        }
        assert!(out.is_dir());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
