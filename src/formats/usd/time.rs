//! A stage's clock, and what a read at a frame takes from its time samples.
//!
//! USD authors values at time codes: `timeCodesPerSecond` says how long one is and
//! `framesPerSecond` how long a frame is, so frame F is time code
//! F x timeCodesPerSecond / framesPerSecond (F itself where the two are equal, as Blender,
//! Houdini and Maya write them). Between two samples a value is interpolated linearly, as
//! USD defines it and openusd does (held where the two samples' arrays differ in length, or
//! for types without interpolation, such as `curveVertexCounts`). Points are the exception
//! UsdGeomPointBased makes: where `velocities` are authored at the earlier sample, the
//! points move from it by velocity (and `accelerations`) over the time since, in seconds;
//! where the point count changes between two samples with no velocities, the points between
//! them are undefined and refused.

use openusd::sdf;
use openusd::usd::{Attribute, Stage, TimeCode};

use crate::error::{Result, invalid_arg};

/// The stage's `timeCodesPerSecond`, `framesPerSecond` and authored time range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clock {
    pub codes_per_second: f64,
    pub frames_per_second: f64,
    /// `startTimeCode` and `endTimeCode`, where both are authored.
    pub authored_range: Option<(f64, f64)>,
}

impl Clock {
    /// The stage's clock, USD's fallbacks (24 per second) where not authored.
    pub(super) fn of(stage: &Stage) -> Result<Clock> {
        let clock = Clock {
            codes_per_second: stage.time_codes_per_second(),
            frames_per_second: stage.frames_per_second(),
            authored_range: stage
                .has_authored_time_code_range()
                .then(|| (stage.start_time_code(), stage.end_time_code())),
        };
        for (name, v) in [
            ("timeCodesPerSecond", clock.codes_per_second),
            ("framesPerSecond", clock.frames_per_second),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid_arg!("{name} = {v}: must be finite and > 0"));
            }
        }
        if let Some((start, end)) = clock.authored_range
            && !(start.is_finite() && end.is_finite() && start <= end)
        {
            return Err(invalid_arg!(
                "startTimeCode {start} and endTimeCode {end}: must be finite, start <= end"
            ));
        }
        Ok(clock)
    }

    /// The time code of frame `frame`.
    pub fn time_code(&self, frame: f64) -> f64 {
        frame * self.codes_per_second / self.frames_per_second
    }

    /// The frame at time code `code`.
    pub fn frame(&self, code: f64) -> f64 {
        code * self.frames_per_second / self.codes_per_second
    }
}

/// What of a prim moves: its attributes with two or more time samples (its own and its
/// ancestors', whose transforms move it), and the first and last time code of any sample.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Animation {
    pub attributes: Vec<String>,
    pub span: Option<(f64, f64)>,
    /// Every time code any of those attributes has a sample at, ascending.
    pub times: Vec<f64>,
}

/// When a read takes each attribute's value: its default (else its earliest sample, for a
/// stage read as a still), or its value at a time code.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum ReadAt {
    Still,
    Code(f64),
}

impl ReadAt {
    /// `attr`'s value at this time; None when nothing is authored.
    pub(super) fn value(self, attr: &Attribute) -> Result<Option<openusd::sdf::Value>> {
        let err = |e| failed(attr.path(), e);
        match self {
            ReadAt::Code(t) => attr.get_at(TimeCode::new(t)).map_err(err),
            ReadAt::Still => {
                if let Some(v) = attr.get().map_err(err)? {
                    return Ok(Some(v));
                }
                match sample_times(attr)?.first() {
                    Some(&t) => attr.get_at(TimeCode::new(t)).map_err(err),
                    None => Ok(None),
                }
            }
        }
    }

    /// The time code transforms are read at.
    pub(super) fn transform_time(self) -> TimeCode {
        match self {
            ReadAt::Still => TimeCode::EARLIEST,
            ReadAt::Code(t) => TimeCode::new(t),
        }
    }
}

/// An error of the USD library about `path`, its causes included.
pub(super) fn failed(path: &sdf::Path, e: impl std::fmt::Display) -> crate::Error {
    invalid_arg!("{}: {e:#}", path.as_str())
}

/// `attr`'s authored sample times, ascending.
pub(super) fn sample_times(attr: &Attribute) -> Result<Vec<f64>> {
    attr.time_sample_times().map_err(|e| failed(attr.path(), e))
}

/// The two samples around `t` when it lies strictly between two of `times`.
pub(super) fn between(times: &[f64], t: f64) -> Option<(f64, f64)> {
    let hi = times.iter().position(|&x| x > t)?;
    (hi > 0 && times[hi - 1] < t).then(|| (times[hi - 1], times[hi]))
}

/// How points move from a sample: by velocity and acceleration, per second.
pub(super) struct Motion {
    pub velocities: Vec<[f32; 3]>,
    pub accelerations: Option<Vec<[f32; 3]>>,
}

impl Motion {
    /// `points` (those of a sample) `seconds` after it.
    pub(super) fn moved(&self, points: &[[f32; 3]], seconds: f64) -> Vec<[f32; 3]> {
        let dt = seconds as f32;
        points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let v = self.velocities[i];
                let a = self.accelerations.as_ref().map_or([0.0; 3], |a| a[i]);
                std::array::from_fn(|k| p[k] + dt * (v[k] + 0.5 * dt * a[k]))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_time_between_two_samples_finds_them_and_one_on_or_outside_none() {
        let times = [1.0, 5.0, 9.0];
        assert_eq!(between(&times, 3.0), Some((1.0, 5.0)));
        assert_eq!(between(&times, 8.5), Some((5.0, 9.0)));
        for t in [0.0, 1.0, 5.0, 9.0, 10.0] {
            assert_eq!(between(&times, t), None, "{t}");
        }
        assert_eq!(between(&[], 1.0), None);
    }

    #[test]
    fn a_frame_is_time_codes_at_the_stages_rates() {
        let clock = Clock {
            codes_per_second: 48.0,
            frames_per_second: 24.0,
            authored_range: None,
        };
        assert_eq!(clock.time_code(3.0), 6.0);
        assert_eq!(clock.frame(6.0), 3.0);
    }

    #[test]
    fn points_move_by_velocity_and_acceleration() {
        let m = Motion {
            velocities: vec![[1.0, 0.0, -2.0]],
            accelerations: Some(vec![[0.0, 4.0, 0.0]]),
        };
        assert_eq!(m.moved(&[[1.0, 1.0, 1.0]], 0.5), vec![[1.5, 1.5, 0.0]]);
    }
}
