//! Where a ray's time falls among a motion-blurred geometry's time steps.
//!
//! A geometry in motion holds its points at K time steps spread evenly over the shutter:
//! step 0 where it opens, step K - 1 where it closes. A ray's time is its fraction of the
//! shutter, in [0, 1]. Between two steps the points move linearly, as Embree moves them,
//! so a curve (a linear function of its control points) at a time is the same blend of
//! the curves at the two steps around it.

/// The step at or before `time` (a fraction of the shutter, clamped to [0, 1]) among
/// `steps` time steps, and the fraction of the way to the next step: `(0, 0.0)` for a
/// geometry of one step. The fraction is 0 only at a step, and the step is never the last
/// one when it is above 0, so `step + 1` is a step whenever the fraction is used.
pub fn time_step(time: f32, steps: usize) -> (usize, f32) {
    if steps < 2 {
        return (0, 0.0);
    }
    let last = (steps - 1) as f32;
    let at = time.clamp(0.0, 1.0) * last;
    // NaN clamps to NaN: treated as the shutter's opening.
    let at = if at.is_nan() { 0.0 } else { at };
    let step = (at.floor() as usize).min(steps - 2);
    (step, at - step as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_and_fractions_cover_the_shutter() {
        assert_eq!(time_step(0.3, 1), (0, 0.0));
        assert_eq!(time_step(0.0, 2), (0, 0.0));
        assert_eq!(time_step(0.25, 2), (0, 0.25));
        assert_eq!(time_step(1.0, 2), (0, 1.0));
        assert_eq!(time_step(0.5, 3), (1, 0.0));
        assert_eq!(time_step(0.75, 3), (1, 0.5));
        assert_eq!(time_step(1.0, 3), (1, 1.0));
        assert_eq!(time_step(-1.0, 3), (0, 0.0));
        assert_eq!(time_step(2.0, 3), (1, 1.0));
        assert_eq!(time_step(f32::NAN, 3), (0, 0.0));
    }
}
