//! The benchmark sweeps behind the `bench` CLI, one module per sweep, and what they share
//! ([`sweep`]: CSV rows, progress steps, the timed-frames loop).
//!
//! Every sweep implements [`Sweep`]: its flags, its settings (tiny, quick or full), its rows
//! and their CSV file, what it prints and its charts. [`sweeps`] lists them in the CLI's
//! order as [`Listed`], the face the CLI builds its subcommands from and runs; [`execute`]
//! is the one run of a sweep: progress bar, rows printed, `OUT/NAME.csv`, `OUT/NAME_*.png`.
//! A new sweep is one module here and one line in [`sweeps`].

pub mod billboards;
pub mod budget;
pub mod impostors;
pub mod layers;
pub mod lightfield;
pub mod morph;
pub mod objects;
pub mod panorama;
pub mod portals;
pub mod raster;
pub mod scaling;
pub mod stereo;
pub mod sweep;
pub mod warp;

use crate::chart::{self, Chart, Drawn};
use clap::{ArgMatches, Args, FromArgMatches};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::Instant;
use sweep::CsvRow;

/// The flags every sweep takes.
#[derive(Args, Clone, Debug)]
pub struct RunFlags {
    /// Folder for SWEEP.csv and the charts (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// A reduced sweep (every point, few frames): about a minute at most.
    #[arg(long)]
    pub quick: bool,
    /// A seconds-long smoke run for tests: tiny sizes and counts (and no models).
    #[arg(long, hide = true)]
    pub tiny: bool,
}

impl RunFlags {
    /// The settings the flags ask for: tiny, quick or full.
    pub fn pick<S>(&self, tiny: fn() -> S, quick: fn() -> S, full: fn() -> S) -> S {
        if self.tiny {
            tiny()
        } else if self.quick {
            quick()
        } else {
            full()
        }
    }
}

impl AsRef<RunFlags> for RunFlags {
    fn as_ref(&self) -> &RunFlags {
        self
    }
}

/// Progress of a sweep: the step's 0-based index, the total, and what it is.
pub type Progress<'a> = &'a mut dyn FnMut(usize, usize, &str);

/// One benchmark sweep: its flags, settings, rows (and so its CSV), printout and charts.
pub trait Sweep: Sync {
    /// The subcommand's name, also the CSV's file stem (`NAME.csv`).
    const NAME: &'static str;
    /// The subcommand's help.
    const ABOUT: &'static str;
    /// What its rows are called in the closing line (`rows`, `points`, `measurements`).
    const ROWS: &'static str = "rows";
    /// Its flags: [`RunFlags`] and any of its own.
    type Flags: Args + FromArgMatches + AsRef<RunFlags>;
    /// How much it measures.
    type Settings;
    /// One line of its CSV.
    type Row: CsvRow;

    /// The settings the flags ask for (anything they need loaded, loaded).
    fn settings(&self, flags: &Self::Flags) -> Result<Self::Settings, String>;
    /// Measures: its rows, reporting each step to `progress`.
    fn rows(
        &self,
        settings: &Self::Settings,
        flags: &Self::Flags,
        progress: Progress,
    ) -> Result<Vec<Self::Row>, String>;
    /// One row as the terminal shows it; `None` for a row not shown on its own.
    fn line(&self, row: &Self::Row) -> Option<String> {
        let _ = row;
        None
    }
    /// Lines shown after the rows: what is said over several of them.
    fn summary(&self, rows: &[Self::Row]) -> Vec<String> {
        let _ = rows;
        Vec::new()
    }
    /// Prints the rows for the terminal: each row's [`Sweep::line`], then the
    /// [`Sweep::summary`]. The one printing path of every sweep.
    fn report(&self, rows: &[Self::Row]) {
        for line in rows.iter().filter_map(|r| self.line(r)) {
            println!("{line}");
        }
        for line in self.summary(rows) {
            println!("{line}");
        }
    }
    /// Its charts of the rows: file name and chart.
    fn charts(&self, rows: &[Self::Row]) -> Vec<(&'static str, Chart)> {
        let _ = rows;
        Vec::new()
    }
}

/// A sweep as the CLI lists it: its subcommand, and its run from the parsed flags. Every
/// [`Sweep`] is one; a subcommand of several sweeps (`budget`) implements it by hand.
pub trait Listed: Sync {
    /// The subcommand's name.
    fn name(&self) -> &'static str;
    /// The subcommand, with its help and flags.
    fn command(&self) -> clap::Command;
    /// Runs the sweep the flags ask for.
    fn run(&self, matches: &ArgMatches) -> Result<(), String>;
}

impl<S: Sweep> Listed for S {
    fn name(&self) -> &'static str {
        S::NAME
    }

    fn command(&self) -> clap::Command {
        S::Flags::augment_args(clap::Command::new(S::NAME)).about(about(S::NAME, S::ABOUT))
    }

    fn run(&self, matches: &ArgMatches) -> Result<(), String> {
        let flags = S::Flags::from_arg_matches(matches).map_err(|e| e.to_string())?;
        execute(self, &flags)
    }
}

/// A sweep's help: its own, then the techniques of `ibr::catalog()` it measures (those
/// whose entry names it as their sweep).
pub fn about(name: &str, about: &str) -> String {
    let measured: Vec<&str> = ibr::catalog()
        .iter()
        .filter(|e| e.sweep == Some(name))
        .map(|e| e.name)
        .collect();
    if measured.is_empty() {
        about.to_string()
    } else {
        format!("{about} (catalogue: {})", measured.join(", "))
    }
}

/// Every sweep of the `bench` CLI, in its order.
pub fn sweeps() -> [&'static dyn Listed; 13] {
    [
        &raster::RasterSweep,
        &billboards::BillboardsSweep,
        &impostors::ImpostorsSweep,
        &scaling::ScalingSweep,
        &warp::WarpSweep,
        &portals::PortalsSweep,
        &lightfield::LightfieldSweep,
        &stereo::StereoSweep,
        &morph::MorphSweep,
        &panorama::PanoramaSweep,
        &layers::LayersSweep,
        &budget::BudgetCommand,
        &objects::ObjectsSweep,
    ]
}

/// Runs one sweep under a progress bar, prints its rows, writes `OUT/NAME.csv` and its
/// charts, and says what it wrote.
pub fn execute<S: Sweep>(sweep: &S, flags: &S::Flags) -> Result<(), String> {
    let run = flags.as_ref();
    let settings = sweep.settings(flags)?;
    std::fs::create_dir_all(&run.out)
        .map_err(|e| format!("cannot create {}: {e}", run.out.display()))?;
    let start = Instant::now();
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let measured = sweep.rows(&settings, flags, &mut |i, total, what| {
        bar.set_length(total as u64);
        bar.set_position(i as u64);
        bar.set_message(what.to_string());
    });
    bar.finish_and_clear();
    let measured = measured?;
    sweep.report(&measured);
    let name = S::NAME;
    let csv = run.out.join(format!("{name}.csv"));
    sweep::write_csv(&csv, &measured)
        .map_err(|e| format!("cannot write {}: {e}", csv.display()))?;
    for (file, chart) in sweep.charts(&measured) {
        drawn(&run.out.join(file), &chart)?;
    }
    println!(
        "bench: {} {} in {:.1} s on {} threads; wrote {} and {}/{name}_*.png",
        measured.len(),
        S::ROWS,
        start.elapsed().as_secs_f64(),
        rayon::current_num_threads(),
        csv.display(),
        run.out.display(),
    );
    Ok(())
}

/// Draws one chart, saying so when it had to go without text.
fn drawn(path: &Path, chart: &Chart) -> Result<(), String> {
    match chart::draw(path, chart) {
        Ok(Drawn::WithText) => Ok(()),
        Ok(Drawn::WithoutText) => {
            println!(
                "bench: the chart font could not be used; {} was drawn without text",
                path.display()
            );
            Ok(())
        }
        Err(e) => Err(format!("cannot draw {}: {e}", path.display())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every sweep the catalogue names is a sweep here, and its help lists the technique.
    #[test]
    fn every_catalogued_sweep_is_listed_and_names_its_techniques() {
        for e in ibr::catalog() {
            let Some(name) = e.sweep else { continue };
            let sweep = sweeps().into_iter().find(|s| s.name() == name);
            let sweep = sweep.unwrap_or_else(|| panic!("{}: no sweep {name}", e.name));
            let help = sweep.command().get_about().map(|a| a.to_string());
            assert!(
                help.is_some_and(|h| h.contains(e.name)),
                "{name}: {}",
                e.name
            );
        }
    }
}
