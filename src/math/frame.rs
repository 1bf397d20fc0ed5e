//! An orthonormal frame: where a BSDF's local directions live (z the normal of a surface,
//! or toward the viewer across a fibre; x the fibre tangent for hair).

use glam::{DVec3, Vec3};

/// Three orthonormal axes; world directions go in with [`Frame::to_local`] and come out
/// with [`Frame::to_world`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub x: Vec3,
    pub y: Vec3,
    pub z: Vec3,
}

impl Frame {
    /// A frame whose z is the unit vector `n`, with any x and y around it.
    pub(crate) fn from_z(n: Vec3) -> Self {
        let (x, y) = n.any_orthonormal_pair();
        Frame { x, y, z: n }
    }

    /// A world direction in this frame.
    pub fn to_local(&self, w: Vec3) -> Vec3 {
        Vec3::new(w.dot(self.x), w.dot(self.y), w.dot(self.z))
    }

    /// A direction of this frame back in world space.
    pub fn to_world(&self, l: Vec3) -> Vec3 {
        self.x * l.x + self.y * l.y + self.z * l.z
    }
}

/// The hair frame (docs/conventions.md) for a ray of direction `dir` from `org` past a
/// fibre of tangent `tangent`, and the ray's offset from the axis point `axis` along y in
/// units of `radius`, unclamped (not finite when the radius is 0). x = normalize(tangent),
/// y = normalize(cross(x, dir)), z = cross(x, y). Computed in f64 (`scene::hit` says why).
///
/// Degenerate input never gives NaN axes: a zero tangent becomes a direction perpendicular
/// to the ray, and a ray along the tangent gets an arbitrary y perpendicular to x.
pub fn hair_frame_offset(
    tangent: Vec3,
    dir: Vec3,
    org: Vec3,
    axis: Vec3,
    radius: f32,
) -> (Frame, f64) {
    let d = dir.as_dvec3();
    let x = tangent.as_dvec3().try_normalize().unwrap_or_else(|| {
        d.try_normalize()
            .unwrap_or(DVec3::Z)
            .any_orthonormal_vector()
    });
    let y = x
        .cross(d)
        .try_normalize()
        .unwrap_or_else(|| x.any_orthonormal_vector());
    let z = x.cross(y);
    let offset = (org.as_dvec3() - axis.as_dvec3()).dot(y) / f64::from(radius);
    let frame = Frame {
        x: x.as_vec3(),
        y: y.as_vec3(),
        z: z.as_vec3(),
    };
    (frame, offset)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_keeps_z() {
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        let f = Frame::from_z(n);
        assert!((f.x.dot(f.y)).abs() < 1e-6 && (f.x.dot(n)).abs() < 1e-6);
        assert!((f.to_local(n) - Vec3::Z).length() < 1e-6);
        let w = Vec3::new(-0.2, 0.9, 0.1).normalize();
        assert!((f.to_world(f.to_local(w)) - w).length() < 1e-6);
    }
}
