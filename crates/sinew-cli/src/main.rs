//! `sinew`: the stiffness of cable-driven hyper-redundant manipulators from the command line,
//! as aligned tables or one JSON document (`--json`, schema in docs/cli.md).
//!
//! - `sinew routing`: the expanded routing and the joints;
//! - `sinew joint`: one joint's feasible tension interval and stiffness range;
//! - `sinew arm`: T0, tensions, K_q, K_W, C_x, K_x, K_fd, the ellipsoid and stability;
//! - `sinew sweep`: a joint's min/max stiffness maps over its angles (Fig. 5);
//! - `sinew plan`: the tensions that optimise the end stiffness, certified by a gap;
//! - `sinew import caspr`: a robot folder from a CASPR model's XML files;
//! - `sinew export mjcf`: the robot, its cables and chosen tensions as a MuJoCo model.
//!
//! Errors print one line, `sinew: <message>`, on standard error and exit with 2 (bad input)
//! or 1 (the model has no answer, e.g. an infeasible load); never a panic.

mod arm_cmd;
mod arm_friction;
mod cli;
mod error;
mod export_cmd;
mod friction_args;
mod import_cmd;
mod input;
mod joint_cmd;
mod output;
mod plan_cmd;
mod routing_cmd;
mod sweep_cmd;
mod trajectory_cmd;

use std::process::ExitCode;

use clap::Parser as _;

use crate::cli::{Cli, Command, ExportTarget, ImportSource};
use crate::error::CliError;

fn run(cli: &Cli) -> Result<(), CliError> {
    match &cli.command {
        Command::Routing(args) => routing_cmd::run(args),
        Command::Joint(args) => joint_cmd::run(args),
        Command::Arm(args) => arm_cmd::run(args),
        Command::Sweep(args) => sweep_cmd::run(args),
        Command::Plan(args) if args.trajectory.is_some() => trajectory_cmd::run(args),
        Command::Plan(args) => plan_cmd::run(args),
        Command::Import(ImportSource::Caspr(args)) => import_cmd::caspr(args),
        Command::Export(ExportTarget::Mjcf(args)) => export_cmd::mjcf(args),
    }
}

/// clap's usage error as one line naming the option: its message without the `error: `
/// prefix, the usage and the `--help` hint, the remaining lines joined by `; `.
fn usage_line(e: &clap::Error) -> String {
    let text = e.to_string();
    let parts: Vec<String> = text
        .lines()
        .map(str::trim)
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .filter(|l| !l.is_empty())
        .map(|l| {
            l.strip_prefix("error: ").unwrap_or(l).split_whitespace().collect::<Vec<_>>().join(" ")
        })
        .collect();
    if parts.is_empty() {
        "no command given: see `sinew --help`".to_owned()
    } else {
        parts.join("; ")
    }
}

fn main() -> ExitCode {
    // --help and --version print as clap does (exit 0); a usage error is one line, exit 2.
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => match e.kind() {
            clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion => {
                e.exit()
            }
            clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                eprintln!(
                    "sinew: no command given: routing, joint, arm, sweep, plan or import (see `sinew --help`)"
                );
                return ExitCode::from(2);
            }
            _ => {
                eprintln!("sinew: {}", usage_line(&e));
                return ExitCode::from(2);
            }
        },
    };
    match run(&cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sinew: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
