//! The stages of building a scene, before the first pixel: what a progress display shows
//! and what `--stats` times. On a large groom they take longer than the render itself.

use std::sync::Mutex;
use std::time::Instant;

use crate::embree::cancelled;
use crate::error::Result;

/// One stage of a scene build, in the order they run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Stage {
    /// Reading groom and mesh files, or generating procedural grooms and shapes.
    Read,
    /// Converting strands into the curve buffers Embree reads (`Curves::from_strands`),
    /// then the build's part: spatial order, and `auto` grooms shared out for the view.
    Curves,
    /// Embree's BVH build (`rtcCommitScene`).
    Bvh,
}

impl Stage {
    /// Every stage, in the order they run.
    pub const ALL: [Stage; 3] = [Stage::Read, Stage::Curves, Stage::Bvh];

    /// The stage's name in progress displays and in `--stats` JSON.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Read => "read",
            Stage::Curves => "curves",
            Stage::Bvh => "bvh",
        }
    }
}

/// Told how far a scene build has got, one call at a time. Each groom is read, then
/// converted ([`Stage::Read`], [`Stage::Curves`]), the meshes are read after the grooms,
/// and the BVH is built last; each stage's `fraction` (of all its grooms and meshes)
/// never decreases from call to call and ends at exactly 1. Returning `false` cancels the
/// build, which fails with a cancellation error ([`crate::embree::is_cancelled`]): inside the BVH build at
/// Embree's next check, elsewhere at the next update.
pub trait StageProgress: Sync {
    fn update(&self, stage: Stage, fraction: f64) -> bool;
}

/// Reports nowhere and never cancels.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoStages;

impl StageProgress for NoStages {
    fn update(&self, _stage: Stage, _fraction: f64) -> bool {
        true
    }
}

/// Seconds spent in each stage, summed over grooms and meshes.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StageTimes {
    pub read: f64,
    pub curves: f64,
    pub bvh: f64,
}

impl StageTimes {
    pub fn get(&self, stage: Stage) -> f64 {
        match stage {
            Stage::Read => self.read,
            Stage::Curves => self.curves,
            Stage::Bvh => self.bvh,
        }
    }

    fn get_mut(&mut self, stage: Stage) -> &mut f64 {
        match stage {
            Stage::Read => &mut self.read,
            Stage::Curves => &mut self.curves,
            Stage::Bvh => &mut self.bvh,
        }
    }
}

/// Runs the stages of one build against a [`StageProgress`]: keeps the calls monotone
/// and one at a time (Embree reports from several threads), and times each stage.
pub struct StageRunner<'a> {
    progress: &'a dyn StageProgress,
    /// The stage reported last, and each stage's last fraction (-1 before its first).
    last: Mutex<(Stage, [f64; 3])>,
    times: StageTimes,
}

impl<'a> StageRunner<'a> {
    pub fn new(progress: &'a dyn StageProgress) -> Self {
        StageRunner {
            progress,
            last: Mutex::new((Stage::Read, [-1.0; 3])),
            times: StageTimes::default(),
        }
    }

    /// Reports `fraction` of `stage` if it moves on; an error if the sink cancels.
    pub fn report(&self, stage: Stage, fraction: f64) -> Result<()> {
        if self.forward(stage, fraction) {
            Ok(())
        } else {
            Err(cancelled())
        }
    }

    /// Forwards `fraction` of `stage` to the sink when it is ahead of that stage's last
    /// report, or when the build comes back to an unfinished stage; returns whether to go on.
    pub fn forward(&self, stage: Stage, fraction: f64) -> bool {
        let fraction = fraction.clamp(0.0, 1.0);
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        let (current, done) = &mut *last;
        let prev = done[stage as usize];
        if !(fraction > prev || (stage != *current && (0.0..1.0).contains(&prev))) {
            return true;
        }
        *current = stage;
        done[stage as usize] = fraction.max(prev);
        self.progress.update(stage, done[stage as usize])
    }

    /// Runs `work` as (part of) `stage`, `part` of `parts`: reports the part's start and
    /// end and adds its time to the stage's.
    pub fn run<T>(
        &mut self,
        stage: Stage,
        (part, parts): (usize, usize),
        work: impl FnOnce(&Self) -> Result<T>,
    ) -> Result<T> {
        let parts = parts.max(1) as f64;
        let start = Instant::now();
        self.report(stage, part as f64 / parts)?;
        let out = work(self)?;
        *self.times.get_mut(stage) += start.elapsed().as_secs_f64();
        self.report(stage, (part + 1) as f64 / parts)?;
        Ok(out)
    }

    /// The seconds each stage took.
    pub fn times(&self) -> StageTimes {
        self.times
    }
}
