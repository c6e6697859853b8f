//! The `trilux` command: sample meshes, convert textures to mesh colours
//! and back, inspect files, preview, benchmark, and a demo on built-in
//! data. `trilux --help` lists the subcommands, each with an example.

mod app;

fn main() -> std::process::ExitCode {
    app::run()
}
