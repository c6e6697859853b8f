//! Arguments, the conventions every subcommand shares (progress on
//! stderr, `--json` on stdout, readable errors, safe outputs), and the
//! dispatch.

use std::fmt::Display;
use std::io::IsTerminal;
use std::path::Path;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use trilux::Error;

mod args;
mod bench;
mod colors;
mod demo;
mod diffuse;
mod hair;
mod info;
mod ops;
#[cfg(feature = "paint")]
mod paint;
mod sample;
mod tetra;
#[cfg(feature = "view")]
mod view;
#[cfg(feature = "web")]
mod web;

pub(crate) type Result<T> = std::result::Result<T, Error>;

/// An error with a message of our own.
pub(crate) fn invalid(message: impl Into<String>) -> Error {
    Error::Invalid(message.into())
}

/// A wrong command line (exit code 2), found by a check of ours rather
/// than by the parser.
pub(crate) fn usage(message: impl Into<String>) -> Error {
    Error::Usage(message.into())
}

// Every error reads `WHERE: WHAT`: WHERE is a file, or an argument as it
// was typed (`--light dir:0,1`), named once; WHAT says what is wrong, in
// lower case, as one sentence without a closing full stop, a hint after
// a semicolon or in parentheses. A file's problem exits with 1, an
// argument's with 2.

/// A problem with a file: `PATH: problem` (exit code 1).
pub(crate) fn file_error(path: &Path, problem: impl Display) -> Error {
    placed(path.display(), false, invalid(problem.to_string()))
}

/// A problem with an argument: `ARGUMENT: problem` (exit code 2), where
/// `argument` is the option as typed, with its value (`--size 0`).
pub(crate) fn arg_error(argument: impl Display, problem: impl Display) -> Error {
    placed(argument, true, usage(problem.to_string()))
}

/// An output path the command cannot write, such as an unknown extension:
/// `PATH: problem`, a usage error (exit code 2) since the path is an
/// argument as typed.
pub(crate) fn output_error(path: &Path, problem: impl Display) -> Error {
    placed(path.display(), true, usage(problem.to_string()))
}

/// A library's error `e` about a file: `PATH: e` with `e` kept as the
/// source (its own causes follow it in the printed chain).
pub(crate) fn file_cause(path: &Path, e: impl std::error::Error + Send + Sync + 'static) -> Error {
    placed(path.display(), false, e)
}

/// A library's error `e` about an argument as typed (exit code 2).
pub(crate) fn arg_cause(
    argument: impl Display,
    e: impl std::error::Error + Send + Sync + 'static,
) -> Error {
    placed(argument, true, e)
}

/// `source` at `place` (a file, an argument as typed, or a step).
pub(crate) fn placed(
    place: impl Display,
    usage: bool,
    source: impl std::error::Error + Send + Sync + 'static,
) -> Error {
    Error::At {
        place: place.to_string(),
        usage,
        source: Box::new(source),
    }
}

/// `e` with `place` (a file or an argument) in front, unless `e` already
/// starts with it; a usage error stays one.
pub(crate) fn at(place: impl Display, e: impl Into<Error>) -> Error {
    let e = e.into();
    let place = place.to_string();
    if e.place().as_deref() == Some(place.as_str()) {
        return e;
    }
    let usage = e.is_usage();
    placed(place, usage, e)
}

/// Checks that an input file exists, so that every subcommand says so in
/// the same words.
pub(crate) fn check_input(path: &Path) -> Result<()> {
    if path.is_dir() {
        Err(file_error(path, "a folder, not a file"))
    } else if !path.exists() {
        Err(file_error(path, "no such file"))
    } else {
        Ok(())
    }
}

/// The help heading of the options every subcommand takes, so that a
/// subcommand's help lists them once, apart from its own.
const GLOBAL: &str = "Global options";

#[derive(Debug, Parser)]
#[command(
    name = "trilux",
    version,
    about = "Sample meshes, convert textures to mesh colours and back, fill surfaces with tetrahedra, render translucent diffusion, inspect files, benchmark",
    long_about = None,
    after_help = "Start with `trilux demo`, which runs every pipeline on built-in data and writes previews."
)]
struct Cli {
    /// No progress bars (they are also hidden when stderr is not a terminal).
    #[arg(long, short, global = true, help_heading = GLOBAL)]
    quiet: bool,
    /// Print one JSON object with the results on stdout instead of text.
    #[arg(long, global = true, help_heading = GLOBAL)]
    json: bool,
    /// Overwrite existing output files.
    #[arg(long, global = true, help_heading = GLOBAL)]
    force: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    Info(info::Args),
    Sample(sample::Args),
    #[command(subcommand)]
    Colors(colors::Command),
    Tetra(tetra::Args),
    Diffuse(Box<diffuse::Args>),
    Demo(demo::Args),
    Bench(bench::Args),
    #[cfg(feature = "view")]
    View(view::Args),
    #[cfg(feature = "paint")]
    Paint(paint::Args),
}

/// What every subcommand gets: the shared flags, progress, timings.
pub(crate) struct Context {
    pub(crate) json: bool,
    pub(crate) force: bool,
    progress: bool,
    pub(crate) timings: Vec<(String, f64)>,
}

impl Context {
    /// Runs `f` as a named step: a spinner with the elapsed time on stderr
    /// (when shown), and its time recorded for the summary.
    pub(crate) fn step<T>(&mut self, name: &str, f: impl FnOnce() -> T) -> T {
        let bar = self.spinner(name);
        let start = Instant::now();
        let out = f();
        let seconds = start.elapsed().as_secs_f64();
        bar.finish_and_clear();
        self.timings.push((name.to_string(), seconds));
        out
    }

    /// A spinner (hidden when progress is off).
    pub(crate) fn spinner(&self, message: &str) -> ProgressBar {
        if !self.progress {
            return ProgressBar::hidden();
        }
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.set_message(message.to_string());
        bar.enable_steady_tick(Duration::from_millis(120));
        bar
    }

    /// The recorded step times as a JSON object.
    /// The steps' times by name, seconds; a step run more than once (one
    /// solve per fractured piece) is the sum of its runs.
    pub(crate) fn timings_json(&self) -> serde_json::Value {
        let mut map = serde_json::Map::new();
        for (name, seconds) in &self.timings {
            let total = map
                .get(name)
                .and_then(serde_json::Value::as_f64)
                .unwrap_or(0.0)
                + seconds;
            map.insert(name.clone(), serde_json::json!(total));
        }
        for value in map.values_mut() {
            *value = serde_json::json!(round(value.as_f64().unwrap_or(0.0), 4));
        }
        serde_json::Value::Object(map)
    }

    /// Prints `text` (human) or `json` (with `--json`) on stdout.
    pub(crate) fn report(&self, text: &str, json: serde_json::Value) {
        if self.json {
            println!("{json}");
        } else {
            print!("{text}");
        }
    }
}

/// `x` rounded to `digits` decimals (for JSON and summaries).
pub(crate) fn round(x: f64, digits: i32) -> f64 {
    let p = 10f64.powi(digits);
    (x * p).round() / p
}

/// Parses the arguments, runs the subcommand, prints an error as one
/// readable line on stderr (exit code 1; usage errors, the parser's and
/// [`Error::Usage`], exit with 2). With `--json` a failure is also one
/// JSON object on stdout, `{"error": "...", "exit_code": N}`, where a
/// success's result would have gone.
pub(crate) fn run() -> ExitCode {
    let cli = match parse() {
        Ok(cli) => cli,
        Err(e) => return parse_failure(&e),
    };
    let mut context = Context {
        json: cli.json,
        force: cli.force,
        progress: !cli.quiet && std::io::stderr().is_terminal(),
        timings: Vec::new(),
    };
    let result = match cli.command {
        Command::Info(args) => info::run(&mut context, args),
        Command::Sample(args) => sample::run(&mut context, args),
        Command::Colors(command) => colors::run(&mut context, command),
        Command::Tetra(args) => tetra::run(&mut context, args),
        Command::Diffuse(args) => diffuse::run(&mut context, *args),
        Command::Demo(args) => demo::run(&mut context, args),
        Command::Bench(args) => bench::run(&mut context, args),
        #[cfg(feature = "view")]
        Command::View(args) => view::run(&mut context, args),
        #[cfg(feature = "paint")]
        Command::Paint(args) => paint::run(&mut context, args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let text = message(&e);
            let code = exit_code(&e);
            eprintln!("error: {text}");
            if cli.json {
                json_error(&text, code);
            }
            ExitCode::from(code)
        }
    }
}

/// The command line as [`Cli`]. `info` writes nothing, so its help does
/// not list the global `--force`: it has a hidden `--force` of its own,
/// which the global one then leaves alone (given, it is accepted and has
/// nothing to overwrite).
fn parse() -> std::result::Result<Cli, clap::Error> {
    use clap::{Arg, ArgAction, CommandFactory, FromArgMatches};
    let mut command = Cli::command().mut_subcommand("info", |info| {
        info.arg(
            Arg::new("force")
                .long("force")
                .action(ArgAction::SetTrue)
                .hide(true),
        )
    });
    let matches = command.try_get_matches_from_mut(std::env::args_os())?;
    Cli::from_arg_matches(&matches).map_err(|e| e.format(&mut command))
}

/// A failure as the one JSON object `--json` promises on stdout.
fn json_error(text: &str, code: u8) {
    println!("{}", serde_json::json!({"error": text, "exit_code": code}));
}

/// Prints the parser's message (help and version are not failures), and
/// with `--json` anywhere before a `--` also the JSON object: the
/// arguments did not parse, so `--json` is looked for in them as given.
fn parse_failure(e: &clap::Error) -> ExitCode {
    let _ = e.print();
    if !e.use_stderr() {
        return ExitCode::SUCCESS;
    }
    let code = u8::try_from(e.exit_code()).unwrap_or(2);
    let json = std::env::args_os()
        .skip(1)
        .take_while(|a| a != "--")
        .any(|a| a == "--json");
    if json {
        // The first paragraph of the parser's text (its usage and tips
        // follow a blank line) as one line, without its "error: ".
        let rendered = e.render().to_string();
        let first = rendered.split("\n\n").next().unwrap_or_default();
        let text = first.split_whitespace().collect::<Vec<_>>().join(" ");
        json_error(text.strip_prefix("error: ").unwrap_or(&text), code);
    }
    ExitCode::from(code)
}

/// 2 for a wrong command line, 1 for anything else.
fn exit_code(e: &Error) -> u8 {
    if e.is_usage() { 2 } else { 1 }
}

/// The error and its causes as one line, joined by `": "` (every error
/// type of the workspace shows its cause or returns it from `source()`,
/// never both), without a closing full stop.
fn message(e: &Error) -> String {
    let mut parts = vec![e.to_string()];
    let mut source = std::error::Error::source(e);
    while let Some(s) = source {
        parts.push(s.to_string());
        source = s.source();
    }
    let text = parts.join(": ");
    let text = text.split_whitespace().collect::<Vec<_>>().join(" ");
    text.trim_end_matches('.').to_string()
}

/// Reads a triangle mesh, naming the file in any error.
pub(crate) fn read_mesh(context: &mut Context, path: &Path) -> Result<trilux_io::mesh::TriMesh> {
    check_input(path)?;
    let mesh = context.step("reading the mesh", || trilux_io::mesh::TriMesh::read(path))?;
    if mesh.indices.is_empty() {
        return Err(file_error(
            path,
            "the file has no triangles (a point cloud or an empty mesh)",
        ));
    }
    Ok(mesh)
}

/// Reads a tetrahedral mesh, naming the file in any error.
pub(crate) fn read_tets(context: &mut Context, path: &Path) -> Result<trilux_io::tet::TetMesh> {
    check_input(path)?;
    Ok(context.step("reading the tetrahedra", || {
        trilux_io::tet::TetMesh::read(path)
    })?)
}

/// Reads an image.
pub(crate) fn read_image(
    context: &mut Context,
    path: &Path,
    raw: bool,
) -> Result<trilux_io::image::Image> {
    check_input(path)?;
    let options = trilux_io::image::ReadOptions {
        raw,
        ..Default::default()
    };
    Ok(context.step("reading the image", || {
        trilux_io::image::read_with(path, options)
    })?)
}

/// Writes an image as PNG (8-bit sRGB) or EXR (linear, f32) by extension,
/// atomically, refusing to overwrite without `--force`.
pub(crate) fn write_image(
    context: &Context,
    path: &Path,
    image: &trilux_io::image::Image,
) -> Result<()> {
    let ext = extension(path);
    trilux::output::write_atomic(path, context.force, |tmp| match ext.as_str() {
        "png" => Ok(trilux_io::image::write_png(
            tmp,
            image,
            trilux_io::image::PngDepth::Eight,
        )?),
        "exr" => Ok(trilux_io::image::write_exr(
            tmp,
            image,
            trilux_io::image::ExrPrecision::F32,
        )?),
        _ => Err(output_error(
            path,
            format!("unknown image extension {ext:?} (write .png or .exr)"),
        )),
    })
}

/// The lowercased extension.
pub(crate) fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default()
}

/// Checks an output, given as `option` (`-o`, `--glb`), before any long
/// computation: a file name (not a folder) with one of the `allowed`
/// extensions, in a folder that exists, new or `--force` given (and so
/// for a `.gltf`'s `.bin`). A wrong name is a usage error naming the
/// option as typed (`--glb b.ply: expected .glb or .gltf`); a missing
/// folder or a file in the way is the file's.
pub(crate) fn check_output(
    context: &Context,
    option: &str,
    path: &Path,
    allowed: &[&str],
) -> Result<()> {
    let typed = format!("{option} {}", path.display());
    let expected = one_of(allowed);
    if path.is_dir() {
        return Err(arg_error(
            typed,
            format!("a folder, not a file (expected a file name ending in {expected})"),
        ));
    }
    let ext = extension(path);
    if ext.is_empty() {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        // `.glb` is a hidden file's name, not an extension.
        let hidden = name.strip_prefix('.').filter(|rest| !rest.is_empty());
        let (hint, example) = match hidden {
            Some(rest) if allowed.contains(&rest.to_ascii_lowercase().as_str()) => (
                "a name starting with a dot is a hidden file's name; ",
                format!("out{name}"),
            ),
            _ => (
                "",
                format!(
                    "{}.{}",
                    name.trim_end_matches('.'),
                    allowed.first().copied().unwrap_or_default()
                ),
            ),
        };
        return Err(arg_error(
            typed,
            format!("the file name has no extension ({hint}expected {expected}, as in {example})"),
        ));
    }
    if !allowed.contains(&ext.as_str()) {
        return Err(arg_error(typed, format!("expected {expected}")));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
        && !dir.is_dir()
    {
        // The first part of the path that exists: a file where a folder
        // is needed, or a folder the rest is missing from.
        let problem = match dir
            .ancestors()
            .find(|a| !a.as_os_str().is_empty() && a.exists())
        {
            Some(file) if !file.is_dir() => {
                format!("{} is a file, not a folder", file.display())
            }
            _ => format!("the folder {} does not exist", dir.display()),
        };
        return Err(file_error(path, problem));
    }
    trilux::output::check_new(path, context.force)?;
    if ext == "gltf" {
        // The glTF writer puts NAME.bin beside NAME.gltf.
        let bin = path.with_extension("bin");
        if bin.is_dir() {
            return Err(file_error(
                &bin,
                format!(
                    "a folder is in the way of the .bin written beside {} (remove it, or write \
                     to another name)",
                    path.display()
                ),
            ));
        }
        trilux::output::check_new(&bin, context.force)?;
    }
    Ok(())
}

/// `.png`, `.glb or .gltf`, `.node, .ele, .mesh or .vtu`.
fn one_of(allowed: &[&str]) -> String {
    let dotted: Vec<String> = allowed.iter().map(|e| format!(".{e}")).collect();
    match dotted.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// Runs `f` on `threads` threads (all when `None`).
pub(crate) fn with_threads<T: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> T + Send,
) -> Result<T> {
    match threads {
        None => Ok(f()),
        Some(0) => Err(arg_error("--threads 0", "at least one thread is needed")),
        Some(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| placed(format!("--threads {n}"), false, e))?;
            Ok(pool.install(f))
        }
    }
}

/// A path for display in summaries.
pub(crate) fn shown(path: &Path) -> String {
    path.display().to_string()
}

/// Opens `url` in the system's browser (the web apps' `--open`).
#[cfg(feature = "web")]
pub(crate) fn open_browser(url: &str) {
    let command = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(windows) {
        "explorer"
    } else {
        "xdg-open"
    };
    if std::process::Command::new(command)
        .arg(url)
        .spawn()
        .is_err()
    {
        eprintln!("could not start {command}; open the URL yourself");
    }
}
