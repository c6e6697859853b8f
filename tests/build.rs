//! `cfg(trilux_data)` when `TRILUX_DATA` names the data folder, so that the
//! real-data tests show as ignored (not silently passed) without it.

fn main() {
    println!("cargo::rustc-check-cfg=cfg(trilux_data)");
    println!("cargo::rerun-if-env-changed=TRILUX_DATA");
    if std::env::var_os("TRILUX_DATA").is_some() {
        println!("cargo::rustc-cfg=trilux_data");
    }
}
