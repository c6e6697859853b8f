//! The binary starts and lists its subcommands.

#[test]
fn help_lists_every_subcommand() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_trilux"))
        .arg("--help")
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for sub in ["info", "sample", "colors", "demo", "bench"] {
        assert!(text.contains(sub), "{sub} missing from {text}");
    }
}
