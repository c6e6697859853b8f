//! Sets `cfg(trilux_data)` when the data folder is given, so that real-data tests run (and show as ignored otherwise).

fn main() {
    println!("cargo::rustc-check-cfg=cfg(trilux_data)");
    println!("cargo::rerun-if-env-changed=TRILUX_DATA");
    if std::env::var_os("TRILUX_DATA").is_some() {
        println!("cargo::rustc-cfg=trilux_data");
    }
}
