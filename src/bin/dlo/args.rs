//! The command line: commands, arguments and their help.

use super::*;

#[derive(Parser)]
#[command(
    name = "dlo",
    version,
    about = "Static shapes and deformation paths of deformable linear objects (Wakamatsu & Hirai 2004)"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(Subcommand)]
pub(crate) enum Command {
    /// Solve the static shape of a case (minimum internal energy under its constraints).
    Shape {
        /// Case files (JSON) or folders of them; several run in parallel, with a summary.
        #[arg(required = true, value_name = "CASE")]
        cases: Vec<PathBuf>,
        /// With several cases: how many run at a time (default: the machine's cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Print a JSON object on stdout instead of the readable summary.
        #[arg(long)]
        json: bool,
        /// Directory of the MCAP log (`<case name>.mcap`).
        #[arg(long, default_value = "logs")]
        log_dir: PathBuf,
    },
    /// Evaluate the shape given by the case's explicit coefficients, without optimising.
    Energy {
        /// Case file (JSON) with a `shape` section.
        case: PathBuf,
        /// Print a JSON object on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Plan a deformation path (the case's `plan` section), verify it and replay it by the
    /// controlled end; log every shape to `<log-dir>/<case name>.mcap`.
    Plan {
        /// Case files (JSON) with a `plan` section, or folders of case files (those with a
        /// `plan` section run); several run in parallel, with a summary.
        #[arg(required = true, value_name = "CASE")]
        cases: Vec<PathBuf>,
        /// With several cases: how many run at a time (default: the machine's cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Print a JSON object on stdout.
        #[arg(long)]
        json: bool,
        /// Also write an SVG picture of the plan next to the log.
        #[arg(long)]
        plot: bool,
        /// Directory of the MCAP log and the gripper trajectory (`<case name>.trajectory.csv`).
        #[arg(long, default_value = "logs")]
        log_dir: PathBuf,
        /// Time the gripper trajectory for an end that moves at most this fast (case length
        /// units per second).
        #[arg(long, value_name = "SPEED")]
        max_speed: Option<f64>,
        /// With `--max-speed`: the end also turns at most this fast (rad/s; default unlimited).
        #[arg(long, value_name = "RAD_PER_S", requires = "max_speed")]
        max_angular_speed: Option<f64>,
        /// Threads of each plan's path optimisation (instead of the case's `plan.threads`;
        /// the plan is the same on any number). A batch that runs several cases at a time
        /// gives each plan one unless this says otherwise.
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=256))]
        threads: Option<u16>,
        /// Seconds each plan's search may take (instead of the case's `plan.time_limit`): then
        /// nothing new starts and the best plan so far is replayed and reported, with
        /// `time_limit_reached` set.
        #[arg(long, value_name = "SECONDS")]
        time_limit: Option<f64>,
    },
    /// Disturbance force margin of a grasp (the case's `grasp` section, paper §6): `F_mub` for
    /// each friction coefficient, where and in which direction it is attained.
    Margin {
        /// Case files (JSON) with fingers among their constraints and a `grasp` section, or
        /// folders of case files (those with a `grasp` section run).
        #[arg(required = true, value_name = "CASE")]
        cases: Vec<PathBuf>,
        /// With several cases: how many run at a time (default: the machine's cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Print a JSON object on stdout.
        #[arg(long)]
        json: bool,
        /// Also write the F_mub–μ curve as SVG next to the log.
        #[arg(long)]
        plot: bool,
        /// Directory of the MCAP log.
        #[arg(long, default_value = "logs")]
        log_dir: PathBuf,
    },
    /// Rewrite an MCAP file whose writer was killed into a fully indexed one.
    Recover {
        /// The broken file.
        broken: PathBuf,
        /// Where to write the recovered file.
        fixed: PathBuf,
    },
    /// Print an MCAP file's topics, schemas, message counts and time range.
    Inspect {
        /// The file.
        file: PathBuf,
        /// Print a JSON object on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Draw the optimal and feasible paths of a plan's MCAP log as SVG.
    Plot {
        /// The log written by `dlo plan`.
        file: PathBuf,
        /// The SVG to write (default: the log's name with `.svg`).
        output: Option<PathBuf>,
    },
}
