//! The `budget` subcommand: the sweep over error budgets ([`BudgetSweep`]) and, by its
//! flags, the cost model's calibration ([`CalibrateSweep`]), predicted against measured
//! error by object size ([`ObjectsSweep`]) and the frame scope's trace ([`TraceSweep`]);
//! [`BudgetCommand`] picks one. Also the sweep's charts.

use super::{calibrate, objects, run, trace, Calibration, ObjectRow, Row, Settings, TraceRow};
use super::{ALONE, REPRESENTATIONS};
use crate::bench::{execute, Listed, Progress, RunFlags, Sweep};
use crate::chart::{Chart, Line, Lines};
use clap::{ArgMatches, Args, FromArgMatches};

/// The `budget` subcommand's flags.
#[derive(Args, Clone, Debug)]
pub struct BudgetFlags {
    #[command(flatten)]
    pub run: RunFlags,
    /// Time the cost model's experiments instead and print the fitted per-unit costs.
    #[arg(long)]
    pub calibrate: bool,
    /// Instead, each image representation's predicted against measured error on the
    /// objects it draws, binned by their size on screen (`budget_objects.csv`).
    #[arg(long)]
    pub objects: bool,
    /// Instead, the frame-scope planner at this error budget, object by object and frame
    /// by frame: representation, predicted and measured error (`budget_trace.csv`).
    #[arg(long)]
    pub trace: Option<f32>,
    /// Only this scene.
    #[arg(long, value_parser = ["showcase", "city", "world"])]
    pub scene: Option<String>,
    /// Only these methods (repeat the option; the names of the CSV's `method` column:
    /// `geometry`, `impostors`, `planner`, `planner-frame`, `layers`, or one representation
    /// run alone such as `billboards`).
    #[arg(long)]
    pub method: Vec<String>,
    /// The planners' relative error spread (default: the planner's own, `plan::SPREAD`;
    /// 0: the frame scope keeps the predicted mean alone). The `spread_fit` column says
    /// what spread each run's frames needed.
    #[arg(long)]
    pub spread: Option<f32>,
    /// Target sizes, `WIDTHxHEIGHT` (repeat the option: each size's rows in one CSV;
    /// default 640x360).
    #[arg(long, value_parser = parse_size)]
    pub size: Vec<(u32, u32)>,
    /// Only these error budgets, levels (repeat the option; default: the sweep's own).
    #[arg(long)]
    pub budget: Vec<f32>,
    /// Print each measured frame's stage times (ms) and work counters to stderr, one line
    /// a frame starting `stages`.
    #[arg(long)]
    pub stages: bool,
}

/// `WIDTHxHEIGHT`, each from 1 to 8192.
fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("expected WIDTHxHEIGHT (e.g. 1280x720), got {s:?}");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if !(1..=8192).contains(&w) || !(1..=8192).contains(&h) {
        return Err(format!("{s:?}: each side from 1 to 8192 pixels"));
    }
    Ok((w, h))
}

impl AsRef<RunFlags> for BudgetFlags {
    fn as_ref(&self) -> &RunFlags {
        &self.run
    }
}

impl BudgetFlags {
    /// The settings the flags ask for, narrowed to their scene, methods and spread.
    fn settings(&self) -> Settings {
        let base = self
            .run
            .pick(Settings::tiny, Settings::quick, Settings::full);
        let budgets = |own: Vec<f32>| match self.budget.is_empty() {
            true => own,
            false => self.budget.clone(),
        };
        Settings {
            only: self.scene.clone(),
            methods: self.method.clone(),
            spread: self.spread,
            stages: self.stages,
            size: self.size.first().copied().unwrap_or(base.size),
            budgets: budgets(base.budgets.clone()),
            frame_budgets: if self.budget.is_empty() {
                base.frame_budgets.clone()
            } else {
                Vec::new()
            },
            ..base
        }
    }
}

/// The `budget` subcommand: one of the four sweeps below, as its flags say.
#[derive(Clone, Copy, Debug)]
pub struct BudgetCommand;

impl Listed for BudgetCommand {
    fn name(&self) -> &'static str {
        BudgetSweep::NAME
    }

    fn command(&self) -> clap::Command {
        BudgetFlags::augment_args(clap::Command::new(BudgetSweep::NAME)).about(BudgetSweep::ABOUT)
    }

    fn run(&self, matches: &ArgMatches) -> Result<(), String> {
        let flags = BudgetFlags::from_arg_matches(matches).map_err(|e| e.to_string())?;
        if flags.calibrate {
            execute(&CalibrateSweep, &flags)
        } else if flags.trace.is_some() {
            execute(&TraceSweep, &flags)
        } else if flags.objects {
            execute(&ObjectsSweep, &flags)
        } else {
            execute(&BudgetSweep, &flags)
        }
    }
}

/// The planner against single representations over the error budgets (the module docs of
/// [`super`]).
#[derive(Clone, Copy, Debug)]
pub struct BudgetSweep;

impl Sweep for BudgetSweep {
    const NAME: &'static str = "budget";
    const ABOUT: &'static str = "The planner against single representations used everywhere: frame time and measured error over the error budget, on the city and a large world";
    type Flags = BudgetFlags;
    type Settings = Settings;
    type Row = Row;

    fn settings(&self, flags: &BudgetFlags) -> Result<Settings, String> {
        Ok(flags.settings())
    }

    fn rows(
        &self,
        settings: &Settings,
        flags: &BudgetFlags,
        progress: Progress,
    ) -> Result<Vec<Row>, String> {
        let mut rows = run(settings, progress);
        for &size in flags.size.iter().skip(1) {
            rows.extend(run(
                &Settings {
                    size,
                    ..settings.clone()
                },
                progress,
            ));
        }
        Ok(rows)
    }

    fn report(&self, rows: &[Row]) {
        for r in rows {
            println!(
                "{:<8} {:<13} {:>5} {}x{} {:>6} objects {:>9} tris  median {:>8.2} ms  measured {:>6.3} (p99 {:>6.3}, within {:>5.1}%, objects over {:>5.2}%)  predicted {:>6.3} max {:>7.3} bound {:>6.3} (spread fit {:>5.2})  geometry {:>7.1} images {:>7.1} [{}] switches {:>6.2} rebuilds {:>6.2}  {:>7.1} MB  planning {:>6.2} ms (p99 {:>5.2}, max {:>5.2}, within 2 ms {:>5.1}%)",
                r.scene,
                r.method,
                r.budget,
                r.width,
                r.height,
                r.objects,
                r.triangles,
                r.time.median_ms,
                r.measured_mean,
                r.measured_p99,
                100.0 * r.within,
                100.0 * r.objects_over,
                r.predicted_mean,
                r.predicted_max,
                r.predicted_bound,
                r.spread_fit,
                r.geometry_per_frame,
                r.images_per_frame,
                r.mix,
                r.switches_per_frame,
                r.rebuilds_per_frame,
                r.memory_mb,
                r.planning_ms,
                r.planning_p99_ms,
                r.planning_max_ms,
                r.planning_within * 100.0,
            );
        }
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, Chart)> {
        charts(rows)
    }
}

/// `budget --calibrate`: the cost model's experiments timed, its fit printed.
#[derive(Clone, Copy, Debug)]
pub struct CalibrateSweep;

impl Sweep for CalibrateSweep {
    const NAME: &'static str = "calibrate";
    const ABOUT: &'static str =
        "The planner's cost model: its experiments timed and its per-unit costs fitted";
    type Flags = BudgetFlags;
    /// Image size, scale of the experiments, repetitions.
    type Settings = ((u32, u32), f32, usize);
    type Row = Calibration;

    fn settings(&self, flags: &BudgetFlags) -> Result<Self::Settings, String> {
        Ok(if flags.run.tiny {
            ((160, 96), 0.05, 1)
        } else {
            ((640, 360), 1.0, 9)
        })
    }

    fn rows(
        &self,
        &(size, scale, reps): &Self::Settings,
        _: &BudgetFlags,
        _: Progress,
    ) -> Result<Vec<Calibration>, String> {
        let (model, rows) = calibrate(size, scale, reps);
        println!(
            "cost model: {:.1} ns per triangle, {:.2} ns per lit pixel, {:.2} ns per image pixel, {:.1} us per capture, {:.2} ns per captured texel, {:.1} us per image pass, {:.2} ns per pass pixel, {:.2} ns per sample",
            model.ns_per_triangle, model.ns_per_pixel, model.ns_per_image_pixel, model.us_per_capture, model.ns_per_capture_texel, model.us_per_pass, model.ns_per_pass_pixel, model.ns_per_sample
        );
        Ok(rows)
    }

    fn report(&self, rows: &[Calibration]) {
        for r in rows {
            println!(
                "{:<9} {:>9} triangles {:>9} pixels {:>9} image pixels {:>4} captures {:>3} passes {:>7} pass pixels {:>7} samples {:>8.3} ms",
                r.experiment, r.triangles, r.pixels, r.image_pixels, r.captures, r.passes, r.pass_pixels, r.samples, r.ms
            );
        }
    }
}

/// `budget --objects`: each image representation's predicted against measured error,
/// binned by object size.
#[derive(Clone, Copy, Debug)]
pub struct ObjectsSweep;

impl Sweep for ObjectsSweep {
    const NAME: &'static str = "budget_objects";
    const ABOUT: &'static str = "Each image representation's predicted against measured error on the objects it draws, binned by their size on screen";
    const ROWS: &'static str = "bins";
    type Flags = BudgetFlags;
    type Settings = Settings;
    type Row = ObjectRow;

    fn settings(&self, flags: &BudgetFlags) -> Result<Settings, String> {
        Ok(flags.settings())
    }

    fn rows(
        &self,
        settings: &Settings,
        _: &BudgetFlags,
        progress: Progress,
    ) -> Result<Vec<ObjectRow>, String> {
        Ok(objects(settings, progress))
    }

    fn report(&self, rows: &[ObjectRow]) {
        for r in rows {
            println!(
                "{:<8} {:<11} side >= {:>3} px {:>7} object-frames  predicted {:>7.3}  measured {:>6.3} (p95 {:>6.3})  within prediction {:>5.1}%  overlap {:>5.2}",
                r.scene, r.representation, r.side, r.count, r.predicted_mean, r.measured_mean, r.measured_p95, 100.0 * r.within, r.overlap
            );
        }
    }
}

/// `budget --trace BUDGET`: the frame-scope planner object by object and frame by frame.
#[derive(Clone, Copy, Debug)]
pub struct TraceSweep;

impl Sweep for TraceSweep {
    const NAME: &'static str = "budget_trace";
    const ABOUT: &'static str =
        "The frame-scope planner at one error budget, object by object and frame by frame";
    type Flags = BudgetFlags;
    type Settings = Settings;
    type Row = TraceRow;

    fn settings(&self, flags: &BudgetFlags) -> Result<Settings, String> {
        Ok(flags.settings())
    }

    fn rows(
        &self,
        settings: &Settings,
        flags: &BudgetFlags,
        _: Progress,
    ) -> Result<Vec<TraceRow>, String> {
        let budget = flags.trace.ok_or("budget --trace needs an error budget")?;
        Ok(trace(settings, budget))
    }

    fn report(&self, rows: &[TraceRow]) {
        let mut last = None;
        for r in rows {
            if last != Some((r.scene, r.frame)) {
                last = Some((r.scene, r.frame));
                println!(
                    "{} frame {:>3}: measured {:>7.3} bound {:>7.3}",
                    r.scene, r.frame, r.frame_measured, r.frame_bound
                );
            }
        }
    }
}

/// `(file, chart)` for every chart of the sweep: per scene, frame time against measured
/// error, one line per method over the budgets.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Chart)> {
    let mut out = Vec::new();
    for (scene, file) in [
        ("showcase", "budget_time_error_showcase.png"),
        ("city", "budget_time_error_city.png"),
        ("world", "budget_time_error_world.png"),
    ] {
        if !rows.iter().any(|r| r.scene == scene) {
            continue;
        }
        // Each point labelled with its error budget.
        let series = |method: &str| {
            let of: Vec<&Row> = rows
                .iter()
                .filter(|r| r.scene == scene && r.method == method)
                .collect();
            let pts = of.iter().map(|r| (r.time.median_ms, r.measured_mean));
            let labels = of.iter().map(|r| format!("b{}", r.budget)).collect();
            Line::new(format!("{method} ({scene})"), pts.collect()).labelled(labels)
        };
        out.push((
            file,
            Chart::Lines(Lines::new(
                "Measured error against frame time (labels: error budget bN)",
                "median frame time (ms)",
                "mean abs error over objects (8-bit levels)",
                ["geometry", "impostors", "layers"]
                    .into_iter()
                    .chain(REPRESENTATIONS[ALONE..].iter().copied())
                    .chain(["planner", "planner-frame"])
                    .map(series)
                    .collect(),
            )),
        ));
    }
    // The planner's predicted against measured error, and the budget itself.
    let planner = |scene: &str, f: &dyn Fn(&Row) -> f64| {
        let pts = rows
            .iter()
            .filter(|r| r.scene == scene && r.method == "planner")
            .map(|r| (f64::from(r.budget), f(r)))
            .collect();
        pts
    };
    let mut lines = Vec::new();
    for scene in ["showcase", "city", "world"] {
        if rows.iter().any(|r| r.scene == scene) {
            let predicted = planner(scene, &|r| r.predicted_mean);
            let measured = planner(scene, &|r| r.measured_mean);
            let p99 = planner(scene, &|r| r.measured_p99);
            lines.push(Line::new(format!("predicted ({scene})"), predicted));
            lines.push(Line::new(format!("measured ({scene})"), measured));
            lines.push(Line::new(format!("measured, p99 frame ({scene})"), p99));
        }
    }
    let budgets: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.method == "planner" && r.scene == "city")
        .map(|r| (f64::from(r.budget), f64::from(r.budget)))
        .collect();
    lines.push(Line::reference("the budget", budgets));
    out.push((
        "budget_predicted_measured.png",
        Chart::Lines(Lines::new(
            "The planner's error against its budget",
            "error budget (8-bit levels)",
            "error over objects (8-bit levels)",
            lines,
        )),
    ));
    out
}
