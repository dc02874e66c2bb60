//! The `veach` command line: a thin shell over the library, one file per subcommand.

mod args;
#[cfg(feature = "bench")]
mod bench;
mod denoise;
mod info;
mod label;
mod merge;
mod plot;
mod plot_image;
mod render;
mod strategies;
#[cfg(feature = "viewer")]
mod view;

use clap::Parser;
use std::process::ExitCode;
use veach::Error;

/// How a command ended, when it did not fail.
pub enum Outcome {
    Done,
    /// Stopped by a signal, with its work kept.
    Interrupted,
}

/// Exit status of an interrupted render that kept its work.
const EXIT_INTERRUPTED: u8 = 130;

fn main() -> ExitCode {
    quiet_vulkan_loader();
    // A bug must still be one line on stderr, never a backtrace in a user's face.
    std::panic::set_hook(Box::new(|info| {
        let msg = info.payload().downcast_ref::<&str>().map(|s| s.to_string());
        let msg = msg.or_else(|| info.payload().downcast_ref::<String>().cloned()).unwrap_or_default();
        let at = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
        eprintln!("veach: internal error{at}: {msg} (please report it)");
    }));
    let cli = match args::Cli::try_parse() {
        Ok(cli) => cli,
        // Help and version go to stdout as clap prints them; a bad flag is one line, exit 2.
        Err(e) if !e.use_stderr() => e.exit(),
        Err(e) => {
            let text = e.render().to_string();
            // clap's message is its first paragraph (a missing flag is named on the next line).
            let message: Vec<&str> =
                text.lines().map(str::trim).skip_while(|l| l.is_empty()).take_while(|l| !l.is_empty()).collect();
            let message = message.join(" ");
            eprintln!("veach: {} (--help lists the flags)", message.trim_start_matches("error: "));
            return ExitCode::from(2);
        }
    };
    let done = |r: Result<(), Error>| r.map(|_| Outcome::Done);
    let result = match cli.command {
        args::Command::Render(a) => render::run(&a),
        args::Command::Merge(a) => done(merge::run(&a)),
        args::Command::Denoise(a) => done(denoise::run(&a)),
        #[cfg(feature = "viewer")]
        args::Command::View(a) => done(view::run(a)),
        args::Command::Strategies(a) => done(strategies::run(&a)),
        #[cfg(feature = "bench")]
        args::Command::Bench(a) => done(bench::run(&a)),
        args::Command::PlotConvergence(a) => done(plot::run(&a)),
        args::Command::Info(a) => done(info::run(&a)),
    };
    match result {
        Ok(Outcome::Done) => ExitCode::SUCCESS,
        Ok(Outcome::Interrupted) => ExitCode::from(EXIT_INTERRUPTED),
        Err(e) => {
            eprintln!("veach: {e}");
            ExitCode::from(2)
        }
    }
}

/// Mesa's window-system code complains on every device creation when XDG_RUNTIME_DIR is
/// unset (headless machines, CI); give it a private directory before any thread starts.
fn quiet_vulkan_loader() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        let dir = std::env::temp_dir().join("veach-xdg-runtime");
        #[cfg(unix)]
        {
            use std::os::unix::fs::DirBuilderExt;
            let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
        }
        if dir.is_dir() {
            // SAFETY: called first thing in main, before any other thread exists.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
        }
    }
}

/// Prints the loader's warnings, one line each, naming the file.
pub fn warn_all(what: &std::path::Path, warnings: &[String]) {
    for w in warnings {
        eprintln!("veach: warning: {}: {w}", what.display());
    }
}

/// A renderer on the requested backend, and why it is that one (`--stats-json`); with
/// `auto` (the default) the faster engine for this machine, saying so in one line when that
/// is the CPU engine.
pub fn open_renderer(
    packed: veach::PackedScene,
    camera: &veach::Camera,
    settings: &veach::Settings,
    backend: veach::Backend,
) -> Result<(veach::Renderer, String), Error> {
    use veach::{Backend, Renderer};
    match backend {
        Backend::Auto => {
            let (renderer, why) = Renderer::auto(packed, camera, settings)?;
            if renderer.backend() == Backend::Cpu {
                eprintln!("veach: rendering on the CPU backend: {why}");
            }
            Ok((renderer, format!("auto: {why}")))
        }
        b => Ok((Renderer::new(packed, camera, settings, b)?, "requested".to_string())),
    }
}
