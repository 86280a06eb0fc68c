//! `hilsim record SCENARIO --out DIR [--seed N]`.

use anyhow::{Context, Result};
use hilsim_lidar_emulator::Emulation;

use crate::cli::RecordArgs;

pub fn record(args: &RecordArgs) -> Result<()> {
    let scenario = super::load_scenario(Some(&args.scenario), args.seed)?;
    let run = Emulation::new(&scenario, scenario.seed)
        .with_context(|| format!("{}: sensor model", args.scenario.display()))?
        .run();
    run.recording.write_dir(&args.out)?;
    Ok(())
}
