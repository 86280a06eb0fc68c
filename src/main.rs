//! `hilsim`: the command line. Glue only: parse, validate, call the libraries, print.
//!
//! Exit codes: 0 success; 1 a check or assertion failed; 2 bad input or usage (every error is
//! one line on stderr naming the file, and the line where there is one).

mod cli;
mod commands;
mod progress;

use std::io::Write;
use std::process::ExitCode;

use clap::{CommandFactory, Parser};

use cli::{Cli, Command, ScenarioCommand};

fn main() -> ExitCode {
    let args: Vec<std::ffi::OsString> = std::env::args_os().collect();
    let cli = match Cli::try_parse_from(&args) {
        Ok(cli) => cli,
        // --help and --version: on stdout, a success.
        Err(err) if !err.use_stderr() => {
            let _ = err.print();
            return ExitCode::SUCCESS;
        }
        Err(err) => {
            eprintln!(
                "hilsim: {}",
                hilsim_usage::error_line(&err, Cli::command(), &args)
            );
            return ExitCode::from(2);
        }
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let result = match &cli.command {
        Command::Run(args) => commands::run::run(args, &mut out),
        Command::Record(args) => commands::record::record(args),
        Command::Calibrate(args) => commands::calibrate::calibrate(args, &mut out),
        Command::Smooth(args) => commands::calibrate::smooth(args, &mut out),
        Command::Serve(args) => commands::serve::serve(args, &mut out),
        Command::Decode(args) => commands::decode::decode(args, &mut out),
        Command::Scenario(ScenarioCommand::Test(args)) => {
            commands::scenario_test::test(args, &mut out)
        }
        Command::Dataset(args) => commands::dataset::dataset(args, &mut out),
        Command::Hil(args) => commands::hil::hil(args, &mut out),
        Command::Diagnose(args) => commands::diagnose::diagnose(args, &mut out),
        Command::Report(args) => commands::report::report(args, &mut out),
        Command::Import(args) => commands::import::import(args, &mut out),
        Command::Export(args) => commands::export::export(args, &mut out),
        Command::World(args) => commands::world::world(args, &mut out),
    };
    let _ = out.flush();
    match result {
        Ok(code) => code,
        // A reader that stopped reading (`hilsim … | head`) is not an error: stop quietly, as
        // ripgrep does.
        Err(err) if is_broken_pipe(&err) => ExitCode::SUCCESS,
        Err(err) => {
            // One line: the chain of context joined by ": ".
            let line = format!("{err:#}").replace('\n', " ");
            eprintln!("hilsim: {line}");
            ExitCode::from(2)
        }
    }
}

/// Whether `err` comes from writing to a pipe whose reader has gone.
fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|cause| {
        let io = cause.downcast_ref::<std::io::Error>();
        io.is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
            || cause
                .downcast_ref::<hilsim_recording::Error>()
                .is_some_and(hilsim_recording::Error::is_broken_pipe)
            || cause
                .downcast_ref::<hilsim_ros2::Error>()
                .is_some_and(hilsim_ros2::Error::is_broken_pipe)
    })
}
