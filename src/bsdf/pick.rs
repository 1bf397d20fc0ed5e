//! Choosing among a BSDF's lobes (or a lobe's parts) with one uniform number, and the
//! number rescaled for the choice's own sampling.

use crate::math::sampling::ONE_MINUS_EPSILON;

/// Picks p with probability `weights[p]` (they sum to one) and rescales u into [0, 1) for
/// reuse. A u that rounding carries past the weights goes to the last nonzero weight.
pub(crate) fn pick(weights: &[f32], u: f32) -> (usize, f32) {
    let last = weights
        .iter()
        .rposition(|&w| w > 0.0)
        .unwrap_or(weights.len() - 1);
    let mut u = u;
    for (p, &w) in weights.iter().enumerate().take(last) {
        if u < w {
            return (p, (u / w).min(ONE_MINUS_EPSILON));
        }
        u -= w;
    }
    let w = weights[last];
    (
        last,
        if w > 0.0 {
            (u / w).clamp(0.0, ONE_MINUS_EPSILON)
        } else {
            0.0
        },
    )
}

/// Half the spacing of uniform f32 numbers in [0, 1).
pub(crate) const U_MIN: f32 = 1.0 / 33_554_432.0;
