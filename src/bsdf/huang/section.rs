//! The fibre's elliptical cross-section, in the (y, z) plane of the hair frame: semi-axis
//! 1 (one fibre radius) along the major axis, `aspect` along the minor one. Its points are
//! kept in the coordinates where it is the unit circle (the minor component divided by the
//! aspect): lines stay lines there, so where a ray meets the section and where a chord
//! leaves it are the circle's closed forms.

use glam::Vec2;

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Section {
    major: Vec2,
    minor: Vec2,
    aspect: f32,
}

impl Section {
    /// `major`: the major axis as a unit (y, z) direction.
    pub(super) fn new(aspect: f32, major: Vec2) -> Self {
        Self {
            major,
            minor: major.perp(),
            aspect,
        }
    }

    fn circle_of(&self, p: Vec2) -> Vec2 {
        Vec2::new(p.dot(self.major), p.dot(self.minor) / self.aspect)
    }

    /// The outward unit normal, in (y, z), at the point `q` (circle coordinates).
    pub(super) fn normal(&self, q: Vec2) -> Vec2 {
        (self.major * q.x + self.minor * (q.y / self.aspect)).normalize()
    }

    /// Where a ray toward -`view` (a unit (y, z) direction toward the viewer) first meets
    /// the section, passing its centre at `h` times the section's half-width seen from
    /// `view`, measured along `view` turned a quarter turn clockwise (the frame's y for a
    /// view along z). `h` in [-1, 1]; circle coordinates.
    pub(super) fn entry(&self, view: Vec2, h: f32) -> Vec2 {
        let across = -view.perp();
        let half_width = (across.dot(self.major).powi(2)
            + (self.aspect * across.dot(self.minor)).powi(2))
        .sqrt();
        let q0 = self.circle_of(across * (h * half_width));
        let qd = self.circle_of(view);
        // |q0 + t qd| = 1, the root nearer the viewer.
        let a = qd.length_squared();
        let b = q0.dot(qd);
        // q0 may lie outside the section (the line's nearest point to the centre is not q0
        // on a turned ellipse): c > 0 is then right, and the roots are still real.
        let c = q0.length_squared() - 1.0;
        let t = (-b + (b * b - a * c).max(0.0).sqrt()) / a;
        (q0 + qd * t).normalize()
    }

    /// The chord from `q` (circle coordinates, on the section) along the unit (y, z)
    /// direction `d`: where it leaves the section and its length in (y, z). None when `d`
    /// does not point into the section there.
    pub(super) fn chord(&self, q: Vec2, d: Vec2) -> Option<(Vec2, f32)> {
        let qd = self.circle_of(d);
        let t = -2.0 * q.dot(qd) / qd.length_squared();
        (t > 0.0).then(|| ((q + qd * t).normalize(), t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a circle the entry is the point at h across and the chord the circle's; on an
    /// ellipse the entry's normal mirrors the view into the tangent-plane reflection
    /// direction of the ellipse (checked against the implicit equation).
    #[test]
    fn entry_and_chord() {
        let round = Section::new(1.0, Vec2::X);
        let q = round.entry(Vec2::Y, 0.5);
        assert!((q - Vec2::new(0.5, 0.75f32.sqrt())).length() < 1e-6, "{q}");
        let (q2, len) = round.chord(q, -Vec2::Y).unwrap();
        assert!((q2 - Vec2::new(0.5, -(0.75f32.sqrt()))).length() < 1e-6);
        assert!((len - 3.0f32.sqrt()).abs() < 1e-6);
        assert!(round.chord(q, Vec2::Y).is_none());

        // An ellipse of aspect 0.5 with its major axis along z, seen along z: its half
        // width is 0.5, so h = 1 grazes it at y = 0.5.
        let e = Section::new(0.5, Vec2::Y);
        let q = e.entry(Vec2::Y, 1.0);
        let p = e.major * q.x + e.minor * (q.y * e.aspect);
        assert!((p - Vec2::new(0.5, 0.0)).length() < 1e-3, "{p}");
        let q = e.entry(Vec2::Y, 0.0);
        let p = e.major * q.x + e.minor * (q.y * e.aspect);
        assert!((p - Vec2::new(0.0, 1.0)).length() < 1e-6, "{p}");
        assert!((e.normal(q) - Vec2::Y).length() < 1e-6);
    }
}
