//! Snapshot tests of everything the binary prints without doing any
//! work: every `--help` (`trilux --help`, each subcommand's, `trilux help
//! X`), every usage error (a missing or unknown argument, a bad value of
//! each typed option, a bad spec) and every one-line error about a file
//! (no such file, a bad format, an output that exists). Each case is a
//! `cmd/<kind>/<name>.toml` with the exact stdout, stderr and exit code
//! beside it (and `cmd/outputs/`: what `info` prints on them); the inputs are the tiny files of `cmd/inputs/`, copied into
//! a fresh folder for each case.
//!
//! After a deliberate change of a text, regenerate the snapshots with
//! `TRYCMD=overwrite cargo test -p trilux --test all cmd::` and review the diff.

#[test]
fn help_usage_and_error_texts_match_their_snapshots() {
    trycmd::TestCases::new()
        .register_bin("trilux", std::path::Path::new(env!("CARGO_BIN_EXE_trilux")))
        // A case that passed every argument check would start real work.
        .timeout(std::time::Duration::from_secs(60))
        .env("NO_COLOR", "1")
        .case("tests/cmd/help/*.toml")
        .case("tests/cmd/usage/*.toml")
        .case("tests/cmd/errors/*.toml")
        .case("tests/cmd/outputs/*.toml");
}
