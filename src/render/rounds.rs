//! How a render's passes are grouped into rounds of tiles. The samples of a pixel are the
//! same whatever the grouping; a round is where the render may stop. Each round costs a
//! sweep over the frame besides its samples (a 128x128 fur ball at 256 spp: 1.16x the time
//! in rounds of one 8-spp pass, the plain render's time in rounds of four), so a render
//! in rounds (one that may stop early, or whose progress sink keeps passes) grows them: at
//! most as many passes as it has taken, and no more than its noise estimate says the
//! target needs, or than its time budget has room for.

use std::ops::Range;

/// When a render's rounds end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Stops {
    /// At the pilot (if any), then once, at the end.
    Never,
    /// In growing rounds: where the noise reaches `noise_target`, before a round that
    /// would end past `time_budget` seconds, or (with neither) only where a cancel
    /// leaves the whole frame at the rounds its pixels finished (a progress sink that
    /// keeps passes).
    Growing {
        noise_target: Option<f32>,
        time_budget: Option<f32>,
    },
}

/// The rounds of a render of `passes` passes, the first of them a pilot or not.
#[derive(Debug)]
pub(super) struct Rounds {
    passes: u32,
    pilot: bool,
    stops: Stops,
    /// Passes taken so far.
    done: u32,
    /// Passes of the last round.
    last: u32,
}

/// What the round just taken told.
#[derive(Debug, Clone, Copy)]
pub(super) struct Taken {
    /// The estimated noise after it, if any.
    pub noise: Option<f32>,
    /// Its seconds.
    pub seconds: f64,
    /// Seconds since the render began.
    pub elapsed: f64,
}

impl Rounds {
    pub fn new(passes: u32, pilot: bool, stops: Stops) -> Self {
        Rounds {
            passes,
            pilot,
            stops,
            done: 0,
            last: 0,
        }
    }

    /// The passes of the next round, after `taken` (None before the first); None when
    /// the render is done.
    pub fn next(&mut self, taken: Option<Taken>) -> Option<Range<u32>> {
        let left = self.passes - self.done;
        let size = match (self.stops, taken) {
            _ if left == 0 => 0,
            (_, None) if self.pilot => 1,
            (Stops::Never, _) => left,
            (Stops::Growing { .. }, None) => 1,
            (
                Stops::Growing {
                    noise_target,
                    time_budget,
                },
                Some(taken),
            ) => {
                let wanted = match (noise_target, taken.noise) {
                    (Some(t), Some(n)) if n <= t => 0,
                    // Noise falls as 1 / sqrt(samples): the passes that reach the target.
                    (Some(t), Some(n)) => {
                        let needed = f64::from(self.done) * f64::from(n / t).powi(2);
                        (needed.ceil() - f64::from(self.done)).clamp(1.0, f64::from(left)) as u32
                    }
                    _ => left,
                };
                let room = match time_budget {
                    Some(budget) => {
                        let per_pass = taken.seconds / f64::from(self.last.max(1));
                        let room = (f64::from(budget) - taken.elapsed) / per_pass;
                        room.clamp(0.0, f64::from(left)) as u32
                    }
                    None => left,
                };
                wanted.min(room).min(self.done)
            }
        };
        if size == 0 {
            return None;
        }
        let round = self.done..self.done + size;
        (self.done, self.last) = (round.end, size);
        Some(round)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rounds of `rounds` when every round reports `noise(passes done)` and takes a
    /// second a pass.
    fn sizes(mut rounds: Rounds, noise: impl Fn(u32) -> Option<f32>) -> Vec<u32> {
        let (mut out, mut taken, mut elapsed) = (Vec::new(), None, 0.0);
        while let Some(r) = rounds.next(taken) {
            let seconds = f64::from(r.len() as u32);
            elapsed += seconds;
            out.push(r.len() as u32);
            taken = Some(Taken {
                noise: noise(r.end),
                seconds,
                elapsed,
            });
        }
        out
    }

    #[test]
    fn a_plain_render_is_one_round_after_its_pilot() {
        assert_eq!(sizes(Rounds::new(8, false, Stops::Never), |_| None), [8]);
        assert_eq!(sizes(Rounds::new(8, true, Stops::Never), |_| None), [1, 7]);
    }

    #[test]
    fn rounds_that_may_stop_double_up_to_what_the_noise_target_needs() {
        let target = |t| Stops::Growing {
            noise_target: Some(t),
            time_budget: None,
        };
        // Noise 1 / sqrt(passes): a target of 0.1 needs 100 passes.
        let noise = |p: u32| Some(1.0 / (p as f32).sqrt());
        assert_eq!(
            sizes(Rounds::new(128, false, target(0.1)), noise),
            [1, 1, 2, 4, 8, 16, 32, 36]
        );
        // Unreachable: every pass is taken, in doubling rounds.
        let sum: u32 = sizes(Rounds::new(40, false, target(1e-3)), noise)
            .iter()
            .sum();
        assert_eq!(sum, 40);
        // Reached after the first pass that has an estimate.
        assert_eq!(sizes(Rounds::new(40, false, target(2.0)), noise), [1]);
    }

    #[test]
    fn a_time_budget_starts_no_round_that_would_end_past_it() {
        let budget = Stops::Growing {
            noise_target: None,
            time_budget: Some(10.5),
        };
        // 1 + 1 + 2 + 4 passes of a second each, then 2.5 s left: 2 more.
        assert_eq!(
            sizes(Rounds::new(64, false, budget), |_| None),
            [1, 1, 2, 4, 2]
        );
    }
}
