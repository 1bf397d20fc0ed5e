//! `hairtrace report`: measures what each choice costs in time and buys in accuracy (the
//! hair BSDF's variants, the render knobs on the bench scenes, how building and tracing
//! scale with strand count, the peer renderer) and writes `REPORT.md` with its PNG plots
//! and the gallery's contact sheet. Every figure comes from this run on this machine; the
//! sections are independent, each a module.

mod bsdf;
mod gallery;
mod machine;
mod markdown;
mod peers;
mod plots;
mod real_bias;
mod render;
mod scale;
mod scale_cycles;

use hairtrace::{Error, Result};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::Instant;

use machine::Machine;

/// What `hairtrace report` was asked for.
pub struct ReportOptions {
    /// Tiny sizes everywhere: a check that the whole report still builds (the test suite
    /// runs it), not a measurement to quote.
    pub quick: bool,
    /// Where REPORT.md and its PNGs go (created if missing).
    pub output: PathBuf,
    /// The bench scenes (bench/scenes/*.toml).
    pub scenes: PathBuf,
    /// Results of an earlier `bench/peer --json` run, used instead of running the peer.
    pub peers: Option<PathBuf>,
}

/// What every section reads: the options, the machine and the progress bar.
pub struct Context {
    pub quick: bool,
    pub output: PathBuf,
    pub scenes: PathBuf,
    pub peers: Option<PathBuf>,
    pub machine: Machine,
    /// The report's own link to (or copy of) this binary, which sections that render in a
    /// process of their own run (`OwnBinary`).
    pub hairtrace: PathBuf,
    bar: ProgressBar,
}

impl Context {
    /// Shows the step a section is on.
    pub fn step(&self, what: impl Into<String>) {
        self.bar.set_message(what.into());
    }

    /// Counts one step of the section done.
    pub fn done(&self) {
        self.bar.inc(1);
    }

    /// A file of the report's folder.
    pub fn path(&self, name: &str) -> PathBuf {
        self.output.join(name)
    }
}

/// A section: its title, the function that measures and writes it, and how many progress
/// steps it takes.
struct Section {
    title: &'static str,
    run: fn(&Context) -> Result<String>,
    steps: fn(&Context) -> u64,
}

const SECTIONS: [Section; 6] = [
    Section {
        title: "BSDF: time against accuracy",
        run: bsdf::section,
        steps: bsdf::steps,
    },
    Section {
        title: "Render: error against time on the bench scenes",
        run: render::section,
        steps: render::steps,
    },
    Section {
        title: "Gallery",
        run: gallery::section,
        steps: gallery::steps,
    },
    Section {
        title: "Scale: strand count, build time, memory, rays per second",
        run: scale::section,
        steps: scale::steps,
    },
    Section {
        title: "Real grooms: the defaults against round curves",
        run: real_bias::section,
        steps: real_bias::steps,
    },
    Section {
        title: "Peers: Blender Cycles",
        run: peers::section,
        steps: peers::steps,
    },
];

/// Runs every section and writes `REPORT.md`.
pub fn run(options: &ReportOptions) -> Result<()> {
    check_scenes(&options.scenes)?;
    if let Some(peers) = &options.peers {
        peers::check_file(peers)?;
    }
    std::fs::create_dir_all(&options.output).map_err(|e| Error::io(&options.output, e))?;
    plots::load_font()?;
    let start = Instant::now();
    let binary = OwnBinary::keep()?;
    let mut ctx = Context {
        quick: options.quick,
        output: options.output.clone(),
        scenes: options.scenes.clone(),
        peers: options.peers.clone(),
        machine: Machine::this(),
        hairtrace: binary.0.clone(),
        bar: ProgressBar::hidden(),
    };
    let total: u64 = SECTIONS.iter().map(|s| (s.steps)(&ctx)).sum();
    ctx.bar = ProgressBar::new(total).with_style(
        ProgressStyle::with_template(
            "report {bar:40} {pos}/{len} {elapsed_precise} eta {eta_precise} {msg}",
        )
        .expect("a valid progress template"),
    );
    let mut body = String::new();
    for (i, s) in SECTIONS.iter().enumerate() {
        ctx.step(s.title);
        let section_start = Instant::now();
        let text = (s.run)(&ctx).map_err(|e| e.context(format!("report, {}", s.title)))?;
        body += &format!(
            "\n## {}. {}\n\n{}\n\n*This section took {:.0} s.*\n",
            i + 1,
            s.title,
            text.trim_end(),
            section_start.elapsed().as_secs_f64()
        );
    }
    ctx.bar.finish_and_clear();
    let report = format!(
        "# hairtrace: speed against error\n\n\
         Written by `hairtrace report{}` in {:.0} s on {}. Every figure below was measured \
         in that run{}.{}\n{body}",
        if ctx.quick { " --quick" } else { "" },
        start.elapsed().as_secs_f64(),
        ctx.machine.describe(),
        if ctx.quick {
            " at the quick sizes (tiny images, few samples, small grooms): they show that the \
             report is produced, not what the knobs cost"
        } else {
            ""
        },
        match &ctx.peers {
            Some(peers) => format!(
                " The peers section reads an earlier peer benchmark's run instead (`{}`).",
                peers.display()
            ),
            None => String::new(),
        },
    );
    let path = ctx.path("REPORT.md");
    crate::files::write_file(&path, report)?;
    eprintln!("{}", path.display());
    Ok(())
}

/// The running binary kept under a name of the report's own, in a folder removed when
/// dropped. A full report takes most of an hour, and a build in that time replaces
/// target/release/hairtrace: a section that started the new binary would measure another
/// renderer, or fail where the file was being written (as one run did). A hard link keeps
/// the file a build unlinks (the linker writes a new one) and writes nothing; a copy where
/// the temporary folder is on another file system.
struct OwnBinary(PathBuf);

impl OwnBinary {
    fn keep() -> Result<Self> {
        let exe =
            std::env::current_exe().map_err(|e| Error::io(Path::new("current executable"), e))?;
        let dir = std::env::temp_dir().join(format!("hairtrace-report-{}", std::process::id()));
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        let own = dir.join("hairtrace");
        if std::fs::hard_link(&exe, &own).is_err() {
            std::fs::copy(&exe, &own).map_err(|e| Error::io(&own, e))?;
        }
        Ok(OwnBinary(own))
    }
}

impl Drop for OwnBinary {
    fn drop(&mut self) {
        if let Some(dir) = self.0.parent() {
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}

/// The median of a non-empty list.
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

/// The names of the scenes folder's scene files (`*.toml`), sorted.
pub fn all_scene_names(ctx: &Context) -> Result<Vec<String>> {
    let dir = std::fs::read_dir(&ctx.scenes).map_err(|e| Error::io(&ctx.scenes, e))?;
    let mut names: Vec<String> = dir
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    names.sort();
    Ok(names)
}

/// A bench scene by name, read from the scenes folder.
pub fn bench_scene(ctx: &Context, name: &str) -> Result<hairtrace::SceneDescription> {
    hairtrace::SceneDescription::from_file(&scene_path(&ctx.scenes, name))
}

/// Refuses a scenes folder without the files the sections read, before minutes of work.
fn check_scenes(dir: &Path) -> Result<()> {
    let needed: Vec<PathBuf> = (render::QUICK_SCENES.iter().chain(&["demo_fur_ball"]))
        .map(|name| scene_path(dir, name))
        .chain([scale::scalp_path(dir)])
        .collect();
    match needed.iter().find(|p| !p.is_file()) {
        Some(missing) => Err(Error::InvalidArg(format!(
            "{} not found: run from the repository's root or pass --scenes with the \
             bench scenes' folder (bench/scenes)",
            missing.display()
        ))),
        None => Ok(()),
    }
}

fn scene_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.toml"))
}
