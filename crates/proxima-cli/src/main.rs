//! `proxima`: the command-line tool of the Proxima library [sources: cli].
//!
//! This file only parses arguments and dispatches; each command lives in its own
//! module. What the commands share with the benchmarks, fuzz targets and tests
//! (the index names, the scene generators, the trace parser and replay engine) is
//! in the `proxima-harness` crate.

mod collide;
mod demo;
mod demo_world;
mod draw;
mod pictures;
mod render;
mod replay;
mod world;
mod world_picture;

use clap::error::ErrorKind;
use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Spatial queries and collision detection for dynamic 3D scenes.
///
/// Without a command: `proxima demo` (its options may be given directly).
#[derive(Parser, Debug)]
#[command(
    name = "proxima",
    version,
    about,
    args_conflicts_with_subcommands = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    demo: demo::Args,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// The main job: moving spheres through every broad-phase index, a table and
    /// pictures of the partitions (the default).
    Demo(demo::Args),
    /// Replay a recorded scene trace against one index or all of them.
    Replay(replay::Args),
    /// Mesh-vs-mesh contacts (exact triangle pairs) with cost counters (docs/sources.md#bvh-cost):
    /// `collide A B [--bv aabb|kdop14|kdop18|kdop26|obb|sphere] [--split mean|median|sah]
    /// [--first] [--poses FILE] [--stats] [--time] [--leaf N] [--rotation auto|refit|conservative]`.
    #[command(disable_help_flag = true)]
    Collide {
        /// Meshes and options, parsed by the command itself.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
    /// Pictures: the partitions of a trace's end state, or two meshes and their
    /// intersecting triangles (`--collide A B [--pose ...]`).
    Render(render::Args),
    /// Run a world trace (meshes at poses, contacts, rays, spheres) on the
    /// collision world: `world TRACE [--index NAME] [--bv NAME] [--first]
    /// [--check] [--time]`.
    World(world::Args),
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
        if first.contains("Broken pipe") {
            // The reader closed stdout early (`proxima demo | head`): stop quietly
            // with the status a shell reports for SIGPIPE.
            std::process::exit(141);
        }
        eprintln!("proxima: internal error (please report): {first}{at}");
        std::process::exit(101);
    }));
}

fn main() -> ExitCode {
    install_panic_hook();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => match e.kind() {
            ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => e.exit(),
            _ => {
                // One line, never clap's multi-line report.
                let text = e.to_string();
                let first = text.lines().next().unwrap_or("bad arguments");
                let first = first.strip_prefix("error: ").unwrap_or(first);
                eprintln!("proxima: {first} (see proxima --help)");
                return ExitCode::from(2);
            }
        },
    };
    match cli.command {
        None => demo::main(&cli.demo),
        Some(Command::Demo(args)) => demo::main(&args),
        Some(Command::Replay(args)) => replay::main(&args),
        Some(Command::Collide { args }) => ExitCode::from(collide::main(&args) as u8),
        Some(Command::Render(args)) => render::main(&args),
        Some(Command::World(args)) => world::main(&args),
    }
}
