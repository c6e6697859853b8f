//! Sets `cfg(trilux_data)` when `TRILUX_DATA` names the real-data folder,
//! so that the tests needing it show as ignored (not passed) without it.

fn main() {
    println!("cargo::rustc-check-cfg=cfg(trilux_data)");
    println!("cargo::rerun-if-env-changed=TRILUX_DATA");
    if std::env::var_os("TRILUX_DATA").is_some() {
        println!("cargo::rustc-cfg=trilux_data");
    }
}
