//! Where the examples find the real data: the folder `TRILUX_DATA` names,
//! as given or relative to the workspace (`../shared/data` from a
//! checkout).

use std::path::{Path, PathBuf};

/// The data folder, or `None` when `TRILUX_DATA` is unset or names no
/// folder.
pub(crate) fn data_dir() -> Option<PathBuf> {
    let given = PathBuf::from(std::env::var_os("TRILUX_DATA")?);
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    [given.clone(), workspace.join(&given)]
        .into_iter()
        .find(|p| p.is_dir())
}
