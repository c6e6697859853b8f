//! Marks real-data tests as ignored (visibly) when `TRILUX_DATA` is unset.

fn main() {
    println!("cargo::rustc-check-cfg=cfg(trilux_data)");
    println!("cargo::rerun-if-env-changed=TRILUX_DATA");
    if std::env::var_os("TRILUX_DATA").is_some() {
        println!("cargo::rustc-cfg=trilux_data");
    }
}
