//! Procedural grooms, deterministic from a seed: the built-in demos and the test and
//! benchmark data at any size (10^3 to 10^6 strands and more).
//!
//! Strands come out as polylines of `segments + 1` control points each, written straight
//! into the flat arrays of [`Strands`] (no per-strand allocation), with radii tapering
//! linearly from root to tip. The same parameters and seed give the same strands, bit for
//! bit, on every platform and any number of threads: each strand draws a fixed count of
//! PCG random numbers, so a task of strands jumps the generator to its first strand's.

use super::strands::Strands;
use crate::error::{Result, invalid_arg};
use crate::threads;
use crate::validate::{non_negative, positive};
use glam::{DVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

/// Most control points a procedural groom may have: 2^28 points take 4 GiB as points and
/// radii, as much as a workstation can spare for one groom; more is surely a mistake in
/// the inputs.
pub(crate) const MAX_GROOM_POINTS: usize = 1 << 28;
/// Bytes per control point in [`Strands`] without colours (xyz + radius).
const BYTES_PER_POINT: usize = 16;
/// Most segments per strand: what a `.hair` file can hold, so every groom can be saved.
pub(crate) const MAX_SEGMENTS: u32 = u16::MAX as u32;

/// A sphere covered in fur: roots spread evenly over it, strands growing outward and
/// bending with gravity, curl, noise and clumping.
#[derive(Debug, Clone, PartialEq)]
pub struct FurBall {
    /// Number of strands, >= 1.
    pub strands: usize,
    /// Segments per strand, in 1..=65535 (each strand has `segments + 1` points).
    pub segments: u32,
    /// Radius of the sphere the roots sit on, > 0.
    pub radius: f32,
    /// Length of each strand along the fibre, > 0.
    pub length: f32,
    /// Fibre radius at the root, > 0.
    pub root_radius: f32,
    /// Fibre radius at the tip, > 0 (usually smaller than the root's).
    pub tip_radius: f32,
    /// Helix slope: the tangent of the angle between the fibre and the strand's outward
    /// axis (0 straight, 1 a 45 degree helix), >= 0. Two turns per strand.
    pub curl: f32,
    /// How far gravity (towards -y) bends a strand sideways: the tangent of the bend at
    /// the tip, >= 0.
    pub gravity: f32,
    /// Amplitude of a smooth random wander (same scale as `curl`), >= 0.
    pub noise: f32,
    /// How strongly tips gather into clumps, in [0, 1] (1: the tips reach their clump's
    /// centre strand).
    pub clumping: f32,
    /// Seed of every random choice.
    pub seed: u64,
}

impl Default for FurBall {
    fn default() -> Self {
        FurBall {
            strands: 10_000,
            segments: 16,
            radius: 1.0,
            length: 0.4,
            root_radius: 0.004,
            tip_radius: 0.001,
            curl: 0.3,
            gravity: 0.3,
            noise: 0.2,
            clumping: 0.3,
            seed: 0,
        }
    }
}

/// How strands on a [`ScalpPatch`] wind around their centre line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HairStyle {
    /// No winding: the fibre is the centre line.
    Straight,
    /// A planar sine wave.
    #[default]
    Wavy,
    /// A helix.
    Curly,
}

/// Hair on a patch of a sphere (a scalp): strands leave the surface along its normal,
/// turn downward (-y) under gravity, slide over the sphere instead of entering it, and
/// wave or curl about that centre line as `style` says.
#[derive(Debug, Clone, PartialEq)]
pub struct ScalpPatch {
    pub style: HairStyle,
    /// Number of strands, >= 1.
    pub strands: usize,
    /// Segments per strand, in 1..=65535; about 8 per `period` keep waves and curls round.
    pub segments: u32,
    /// Radius of the head sphere, > 0.
    pub radius: f32,
    /// Size of the patch measured along the sphere, in latitude and in longitude around
    /// its centre (latitude 30 degrees, facing +z); > 0 and at most pi/2 * radius.
    pub width: f32,
    /// Length of each strand's centre line, > 0 (waves and curls wind the fibre around
    /// it, so the fibre itself is longer).
    pub length: f32,
    /// Fibre radius at the root, > 0.
    pub root_radius: f32,
    /// Fibre radius at the tip, > 0.
    pub tip_radius: f32,
    /// Wave amplitude or curl radius, >= 0 (unused by `Straight`).
    pub amplitude: f32,
    /// Wavelength of the wave or pitch of the curl along the centre line, > 0.
    pub period: f32,
    /// How fast the centre line turns downward, in radians per unit length (roughly), >= 0.
    pub gravity: f32,
    /// Seed of every random choice.
    pub seed: u64,
}

impl Default for ScalpPatch {
    fn default() -> Self {
        ScalpPatch {
            style: HairStyle::Wavy,
            strands: 10_000,
            segments: 48,
            radius: 1.0,
            width: 1.2,
            length: 2.0,
            root_radius: 0.004,
            tip_radius: 0.002,
            amplitude: 0.05,
            period: 0.5,
            gravity: 3.0,
            seed: 0,
        }
    }
}

/// Checks the strand and segment counts and returns the number of points.
fn point_total(what: &str, strands: usize, segments: u32) -> Result<usize> {
    if strands == 0 {
        return Err(invalid_arg!("{what}.strands = 0: at least 1 is needed"));
    }
    if !(1..=MAX_SEGMENTS).contains(&segments) {
        return Err(invalid_arg!(
            "{what}.segments = {segments}: must be in 1..={MAX_SEGMENTS}"
        ));
    }
    let points = strands
        .checked_mul(segments as usize + 1)
        .filter(|&p| p <= MAX_GROOM_POINTS);
    points.ok_or_else(|| {
        let wanted = strands as f64 * (f64::from(segments) + 1.0);
        let gib = |points: f64| points * BYTES_PER_POINT as f64 / f64::from(1u32 << 30);
        invalid_arg!(
            "{what}.strands * (segments + 1) = {strands} * {} = {wanted:.0} points would need \
             {:.1} GiB; the limit is {MAX_GROOM_POINTS} points ({:.0} GiB)",
            segments + 1,
            gib(wanted),
            gib(MAX_GROOM_POINTS as f64)
        )
    })
}

/// Radii of one strand's points, tapering linearly from root to tip.
fn taper(root: f32, tip: f32, segments: u32) -> Vec<f32> {
    (0..=segments)
        .map(|k| {
            // In f64 so that the ends are exact and the taper is monotone after rounding.
            let t = f64::from(k) / f64::from(segments);
            (f64::from(root) + (f64::from(tip) - f64::from(root)) * t) as f32
        })
        .collect()
}

/// Strands per task of [`in_parallel`].
const TASK_STRANDS: usize = 1024;

/// A groom of `n` strands with the points of `radii` (root to tip) each, written in tasks
/// side by side: strand `i`'s points by `strand(i, rng, points)`, with `rng` where a
/// loop over the strands in turn from `rng` would have it, since each strand draws
/// exactly `draws` numbers (every `random` of an `f32` or `f64` takes one step of PCG).
fn in_parallel(
    n: usize,
    radii: &[f32],
    (rng, draws): (&Pcg64Mcg, u128),
    strand: impl Fn(usize, &mut Pcg64Mcg, &mut [[f32; 3]]) + Sync,
) -> Result<Strands> {
    let len = radii.len();
    let at = |i: usize| {
        let mut r = rng.clone();
        r.advance(draws * i as u128);
        r
    };
    let (points, radii) = threads::scoped(0, || {
        // Zeroed memory, so that the pages are faulted in by the tasks that write them.
        let mut points = vec![[0.0f32; 3]; n * len];
        (points.par_chunks_mut(TASK_STRANDS * len).enumerate()).for_each(|(task, chunk)| {
            let first = task * TASK_STRANDS;
            let mut r = at(first);
            for (k, p) in chunk.chunks_exact_mut(len).enumerate() {
                strand(first + k, &mut r, p);
            }
            debug_assert!(
                r == at(first + chunk.len() / len),
                "a strand drew other than {draws}"
            );
        });
        let mut all = vec![0.0f32; n * len];
        (all.par_chunks_mut(len)).for_each(|r| r.copy_from_slice(radii));
        (points, all)
    })?;
    Ok(Strands {
        points,
        radii,
        counts: vec![len as u32; n],
        colors: None,
    })
}

/// Any unit vector perpendicular to the unit vector `n` (Duff et al. 2017, branchless).
fn perpendicular(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Rotates (cos, sin) by the angle whose (cos, sin) is `by`: curls and waves advance by
/// a fixed phase per segment, so the inner loops need no trigonometry.
fn rotate((c, s): (f32, f32), by: (f32, f32)) -> (f32, f32) {
    (c * by.0 - s * by.1, s * by.0 + c * by.1)
}

/// Clump centres on a cube-map grid of `g` x `g` cells per face: finding the clump of a
/// direction is a projection, not a search.
struct Clumps {
    g: usize,
    centres: Vec<Vec3>,
}

impl Clumps {
    /// About this many strands share a clump.
    const STRANDS_PER_CLUMP: f64 = 40.0;

    fn new(strands: usize, rng: &mut Pcg64Mcg) -> Clumps {
        let g = ((strands as f64 / (6.0 * Self::STRANDS_PER_CLUMP))
            .sqrt()
            .round() as usize)
            .clamp(1, 256);
        let mut centres = Vec::with_capacity(6 * g * g);
        for face in 0..6 {
            for i in 0..g {
                for j in 0..g {
                    // Jitter inside the cell so that clumps do not line up on a grid.
                    let u = (i as f32 + 0.15 + 0.7 * rng.random::<f32>()) / g as f32 * 2.0 - 1.0;
                    let v = (j as f32 + 0.15 + 0.7 * rng.random::<f32>()) / g as f32 * 2.0 - 1.0;
                    centres.push(Self::face_point(face, u, v).normalize());
                }
            }
        }
        Clumps { g, centres }
    }

    /// Point (u, v) of cube face `face` (0..3: +x, +y, +z; 3..6: -x, -y, -z).
    fn face_point(face: usize, u: f32, v: f32) -> Vec3 {
        let sign = if face < 3 { 1.0 } else { -1.0 };
        match face % 3 {
            0 => Vec3::new(sign, u, v),
            1 => Vec3::new(u, sign, v),
            _ => Vec3::new(u, v, sign),
        }
    }

    /// Centre of the clump whose cell holds unit direction `n`.
    fn centre(&self, n: Vec3) -> Vec3 {
        let a = n.abs();
        let axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let (major, u, v) = match axis {
            0 => (n.x, n.y, n.z),
            1 => (n.y, n.x, n.z),
            _ => (n.z, n.x, n.y),
        };
        let face = axis + if major < 0.0 { 3 } else { 0 };
        let cell = |t: f32| {
            let c = ((t / major.abs() + 1.0) * 0.5 * self.g as f32) as usize;
            c.min(self.g - 1)
        };
        self.centres[(face * self.g + cell(u)) * self.g + cell(v)]
    }
}

/// Largest tangent of the angle between a fur strand's direction and its root normal:
/// 70 degrees, so each segment still climbs by cos(70) = 0.34 of its length and no strand
/// turns back into the ball.
const FUR_MAX_TAN: f32 = 2.747_477_4;
/// Curl turns per fur strand.
const FUR_CURL_TURNS: f32 = 2.0;

impl FurBall {
    /// Checks every field (the error names the first bad one) and returns the number of
    /// control points the groom will have.
    pub fn validate(&self) -> Result<usize> {
        let points = point_total("FurBall", self.strands, self.segments)?;
        positive("FurBall.radius", self.radius)?;
        positive("FurBall.length", self.length)?;
        positive("FurBall.root_radius", self.root_radius)?;
        positive("FurBall.tip_radius", self.tip_radius)?;
        non_negative("FurBall.curl", self.curl)?;
        non_negative("FurBall.gravity", self.gravity)?;
        non_negative("FurBall.noise", self.noise)?;
        if !(0.0..=1.0).contains(&self.clumping) {
            return Err(invalid_arg!(
                "FurBall.clumping = {}: must be in [0, 1]",
                self.clumping
            ));
        }
        Ok(points)
    }

    /// Builds the fur.
    ///
    /// Roots sit on a jittered Fibonacci lattice (equal-area bands in y, golden-angle
    /// steps in azimuth), so density is even without the clusters of plain random points.
    /// Each segment of length `length / segments` points along the root normal n
    /// deflected by a tangential vector (gravity and clump pull growing towards the tip,
    /// curl, a random walk), capped at 70 degrees: the tip lies between
    /// `radius + length * cos(70°)` and `radius + length` from the centre.
    pub fn build(&self) -> Result<Strands> {
        self.validate()?;
        let n = self.strands;
        let segs = self.segments as usize;
        let mut rng = Pcg64Mcg::seed_from_u64(self.seed);
        let clumps = Clumps::new(n, &mut rng);
        let radii_one = taper(self.root_radius, self.tip_radius, self.segments);
        let step = self.length / segs as f32;
        // Pull that takes a tip to its clump centre's tip: the deflections add up to
        // about half their tip value over the strand, hence the 2.
        let pull = 2.0 * self.clumping * (self.radius + self.length) / self.length;
        let noise_scale = self.noise * (3.0 / segs as f32).sqrt();
        let turn = std::f32::consts::TAU * FUR_CURL_TURNS / segs as f32;
        let turn = (turn.cos(), turn.sin());
        let down = Vec3::NEG_Y;
        // Azimuthal jitter is a fraction of the lattice spacing.
        let spacing = (4.0 * std::f64::consts::PI / n as f64).sqrt();
        let golden_angle = std::f64::consts::PI * (3.0 - 5.0f64.sqrt());

        // Each strand draws its root's two numbers, its curl phase and two a segment.
        let draws = 3 + 2 * segs as u128;
        in_parallel(n, &radii_one, (&rng, draws), |i, rng, points| {
            let y = 1.0 - 2.0 * (i as f64 + rng.random::<f64>()) / n as f64;
            let ring = (1.0 - y * y).max(0.0).sqrt();
            let phi = golden_angle * i as f64
                + (rng.random::<f64>() - 0.5) * 0.5 * spacing / ring.max(spacing);
            let normal = DVec3::new(ring * phi.cos(), y, ring * phi.sin()).normalize();
            let mut p = (normal * f64::from(self.radius)).as_vec3();
            let nrm = normal.as_vec3();
            let (t1, t2) = perpendicular(nrm);
            let gravity_t = (down - down.dot(nrm) * nrm) * self.gravity;
            let c = clumps.centre(nrm);
            let clump_t = (c - c.dot(nrm) * nrm) * pull;
            let phase = std::f32::consts::TAU * rng.random::<f32>();
            let mut curl = (phase.cos(), phase.sin());
            let mut wander = Vec3::ZERO;

            points[0] = p.to_array();
            for (k, point) in points[1..].iter_mut().enumerate() {
                let t = (k as f32 + 0.5) / segs as f32;
                let r1 = rng.random::<f32>() * 2.0 - 1.0;
                let r2 = rng.random::<f32>() * 2.0 - 1.0;
                wander += (r1 * t1 + r2 * t2) * noise_scale;
                let mut v =
                    (gravity_t + clump_t) * t + (curl.0 * t1 + curl.1 * t2) * self.curl + wander;
                let len2 = v.length_squared();
                if len2 > FUR_MAX_TAN * FUR_MAX_TAN {
                    v *= FUR_MAX_TAN / len2.sqrt();
                }
                // v is perpendicular to n, so |n + v| >= 1: never degenerate.
                p += (nrm + v).normalize() * step;
                *point = p.to_array();
                curl = rotate(curl, turn);
            }
        })
    }
}

/// Latitude of a scalp patch's centre.
const PATCH_LATITUDE: f64 = std::f64::consts::PI / 6.0;
/// Constants of the R2 low-discrepancy sequence (1/g and 1/g^2 for the plastic number g):
/// even root spacing on the patch at any strand count.
const R2: [f64; 2] = [0.754_877_666_246_692_8, 0.569_840_290_998_053_2];

impl ScalpPatch {
    /// Checks every field (the error names the first bad one) and returns the number of
    /// control points the groom will have.
    pub fn validate(&self) -> Result<usize> {
        let points = point_total("ScalpPatch", self.strands, self.segments)?;
        positive("ScalpPatch.radius", self.radius)?;
        positive("ScalpPatch.width", self.width)?;
        let max_width = std::f32::consts::FRAC_PI_2 * self.radius;
        if self.width > max_width {
            return Err(invalid_arg!(
                "ScalpPatch.width = {}: must be at most pi/2 * radius = {max_width}",
                self.width
            ));
        }
        positive("ScalpPatch.length", self.length)?;
        positive("ScalpPatch.root_radius", self.root_radius)?;
        positive("ScalpPatch.tip_radius", self.tip_radius)?;
        non_negative("ScalpPatch.amplitude", self.amplitude)?;
        positive("ScalpPatch.period", self.period)?;
        non_negative("ScalpPatch.gravity", self.gravity)?;
        Ok(points)
    }

    /// Builds the hair.
    ///
    /// Roots follow the R2 sequence (randomly shifted by the seed) mapped equal-area onto
    /// the patch. Each centre line starts along the surface normal, turns toward -y by
    /// `gravity * step` per segment (each strand's gravity varied by +-20%), and is kept at
    /// least `radius + amplitude + root_radius` from the centre once it got there (never
    /// moving back inward before), so it slides over the head. The wave or curl offset
    /// grows from zero at the root over one period and lies in a frame carried along the
    /// centre line; a final check keeps every point but the root outside the sphere by its
    /// own fibre radius.
    pub fn build(&self) -> Result<Strands> {
        self.validate()?;
        let n = self.strands;
        let segs = self.segments as usize;
        let mut rng = Pcg64Mcg::seed_from_u64(self.seed);
        let radii_one = taper(self.root_radius, self.tip_radius, self.segments);
        let step = self.length / segs as f32;
        let amplitude = match self.style {
            HairStyle::Straight => 0.0,
            HairStyle::Wavy | HairStyle::Curly => self.amplitude,
        };
        let clearance = self.radius + amplitude + self.root_radius;
        let half = f64::from(self.width / self.radius) * 0.5;
        let (sin_lo, sin_hi) = ((PATCH_LATITUDE - half).sin(), (PATCH_LATITUDE + half).sin());
        let shift: [f64; 2] = [rng.random(), rng.random()];
        let down = Vec3::NEG_Y;

        // Each strand draws its gravity, period, phase and two for its tilt.
        in_parallel(n, &radii_one, (&rng, 5), |i, rng, points| {
            let u = (shift[0] + R2[0] * i as f64).fract();
            let v = (shift[1] + R2[1] * i as f64).fract();
            let lon = (u * 2.0 - 1.0) * half;
            let sin_lat = sin_lo + (sin_hi - sin_lo) * v;
            let cos_lat = (1.0 - sin_lat * sin_lat).max(0.0).sqrt();
            let normal = DVec3::new(cos_lat * lon.sin(), sin_lat, cos_lat * lon.cos()).normalize();
            let nrm = normal.as_vec3();
            let mut centre = (normal * f64::from(self.radius)).as_vec3();
            let gravity = self.gravity * step * (0.8 + 0.4 * rng.random::<f32>());
            let period = self.period * (0.9 + 0.2 * rng.random::<f32>());
            let phase = std::f32::consts::TAU * rng.random::<f32>();
            let turn = std::f32::consts::TAU * step / period;
            let turn = (turn.cos(), turn.sin());
            let mut wave = (phase.cos(), phase.sin());
            // Start along the normal, tilted a little at random so strands do not comb.
            let (t1, t2) = perpendicular(nrm);
            let tilt = (rng.random::<f32>() - 0.5) * t1 + (rng.random::<f32>() - 0.5) * t2;
            let mut dir = (nrm + 0.2 * tilt).normalize();
            let mut e1 = (t1 * wave.0 + t2 * wave.1 - dir * dir.dot(t1 * wave.0 + t2 * wave.1))
                .normalize_or(t1);
            let mut farthest = self.radius;

            points[0] = centre.to_array();
            for (k, (point, &fibre_radius)) in points.iter_mut().zip(&radii_one).enumerate().skip(1)
            {
                dir = (dir + down * gravity).normalize_or(dir);
                let mut next = centre + dir * step;
                let floor = farthest.min(clearance);
                let dist = next.length();
                if dist < floor {
                    next *= floor / dist;
                }
                farthest = farthest.max(next.length());
                dir = (next - centre).normalize_or(dir);
                centre = next;
                // Carry the wave frame along the centre line (parallel transport).
                e1 = (e1 - dir * dir.dot(e1)).normalize_or(e1);
                let e2 = dir.cross(e1);

                let s = k as f32 * step;
                let ramp = (s / period).min(1.0);
                wave = rotate(wave, turn);
                let offset = match self.style {
                    HairStyle::Straight => Vec3::ZERO,
                    HairStyle::Wavy => e1 * (amplitude * ramp * wave.1),
                    HairStyle::Curly => (e1 * wave.0 + e2 * wave.1) * (amplitude * ramp),
                };
                let mut q = centre + offset;
                let min_dist = self.radius + fibre_radius;
                let dist = q.length();
                if dist < min_dist {
                    q *= min_dist / dist;
                }
                *point = q.to_array();
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perpendicular_is_orthonormal() {
        for n in [Vec3::X, Vec3::NEG_Z, Vec3::new(0.3, -0.5, 0.8).normalize()] {
            let (a, b) = perpendicular(n);
            for (x, y) in [(a, b), (a, n), (b, n)] {
                assert!(x.dot(y).abs() < 1e-6);
            }
            assert!((a.length() - 1.0).abs() < 1e-6 && (b.length() - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn clump_centre_is_near_its_strands() {
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        let clumps = Clumps::new(100_000, &mut rng);
        for d in [Vec3::X, Vec3::new(-0.2, 0.9, 0.1).normalize(), Vec3::NEG_Z] {
            // A cell spans 90 / g degrees; the centre is within that of every direction in it.
            let cell = std::f32::consts::FRAC_PI_2 / clumps.g as f32;
            assert!(clumps.centre(d).angle_between(d) < 2.0 * cell);
        }
    }

    /// A digest of every bit of a groom's points and radii.
    fn digest(strands: &Strands) -> u64 {
        let bits = strands.points.iter().flatten().chain(&strands.radii);
        bits.fold(0xcbf2_9ce4_8422_2325, |h: u64, x| {
            (h ^ u64::from(x.to_bits())).wrapping_mul(0x0100_0000_01b3)
        })
    }

    #[test]
    fn grooms_written_in_tasks_are_the_bits_of_one_loop() {
        // Recorded from the generators as one loop over the strands in turn, before they
        // were written in tasks: three tasks, the last one short.
        let strands = 2 * TASK_STRANDS + 953;
        let fur = FurBall {
            strands,
            ..FurBall::default()
        }
        .build()
        .unwrap();
        let scalp = ScalpPatch {
            strands,
            ..ScalpPatch::default()
        }
        .build()
        .unwrap();
        assert_eq!(digest(&fur), 0x5829_3a93_7f5e_826b);
        assert_eq!(digest(&scalp), 0xeebc_a09e_1242_2be5);
        let points = ScalpPatch::default().segments + 1;
        assert_eq!(
            (scalp.counts.len(), scalp.counts[strands - 1]),
            (strands, points)
        );
    }
}
