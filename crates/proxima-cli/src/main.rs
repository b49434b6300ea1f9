//! `proxima`: the command-line tool of the Proxima library (design §4).
//!
//! This file only parses arguments and dispatches; each command lives in its own
//! module, and the broad-phase indices they run are listed once in [`indices`].

mod collide;
mod default_run;
mod indices;
mod replay;
mod scene;
mod trace;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Spatial queries and collision detection for dynamic 3D scenes.
///
/// Without a command: runs the default scene (moving spheres) through every
/// broad-phase index and prints a comparison table.
#[derive(Parser, Debug)]
#[command(name = "proxima", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Replay a recorded scene trace against one index or all of them.
    Replay(replay::Args),
    /// Mesh-vs-mesh contacts (exact triangle pairs) with the seed's cost counters:
    /// `collide A B [--bv aabb|kdop14|kdop18|kdop26|obb|sphere] [--split mean|median|sah]
    /// [--first] [--poses FILE] [--stats] [--time] [--leaf N] [--rotation auto|refit|conservative]`.
    #[command(disable_help_flag = true)]
    Collide {
        /// Meshes and options, parsed by the command itself.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
}

/// The last line of defence: a panic (a bug: bad input is reported as an error
/// with exit code 2) prints one line naming where it happened, not a backtrace
/// banner, and exits with code 101.
fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        let payload = info.payload();
        let msg = payload
            .downcast_ref::<&str>()
            .copied()
            .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
            .unwrap_or("panic");
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        let first = msg.lines().next().unwrap_or("");
        eprintln!("proxima: internal error (please report): {first}{at}");
        std::process::exit(101);
    }));
}

fn main() -> ExitCode {
    install_panic_hook();
    let cli = Cli::parse();
    match cli.command {
        None => default_run::main(),
        Some(Command::Replay(args)) => replay::main(&args),
        Some(Command::Collide { args }) => ExitCode::from(collide::main(&args) as u8),
    }
}
