//! pbrt-v4 shapes: `curve` statements gathered into one groom per (material, shape,
//! basis), and `trianglemesh` / `plymesh` into meshes, all placed in world space here.
//!
//! A pbrt curve's control points are already laid out for its basis, as Embree takes
//! them: a cubic Bezier curve has 3n + 1 points (segments share their end points), a
//! uniform cubic B-spline n + 3. Both go to Embree unchanged. Degree 2 curves are raised
//! to cubic Bezier segments, which is exact. pbrt's width varies linearly from `width0`
//! at the root to `width1` at the tip over the curve parameter; radii that are an
//! arithmetic sequence over the control points give exactly that linear variation in
//! both bases, so each control point gets half the width at its parameter (a B-spline
//! whose outer points would get a negative width is turned into its Bezier segments).

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat3, DMat4, DVec3, Vec3};

use super::params::{Params, Warning};
use crate::description::{GroomDesc, GroomSource, MeshDesc, MeshSource};
use crate::embree::{CurveBasis, CurveShape};
use crate::error::Result;
use crate::formats::mesh::read_mesh_file;
use crate::scene::mesh::Mesh;
use crate::scene::shapes;

/// Grooms being gathered, one per (material, shape, basis).
#[derive(Default)]
pub(super) struct Grooms {
    index: HashMap<(String, CurveShape, CurveBasis), usize>,
    pub list: Vec<GroomDesc>,
}

/// Relative tolerance on a transform being a rotation times a uniform scale.
const SIMILARITY_TOLERANCE: f64 = 1e-4;

impl Grooms {
    /// Adds one `Shape "curve"` statement, placed by `to_world`, in `material`.
    pub fn add_curve(
        &mut self,
        p: &Params,
        to_world: &DMat4,
        material: &str,
        warn: &mut Vec<Warning>,
    ) -> Result<()> {
        let points = p
            .triples("P", &["point3", "point"])?
            .ok_or_else(|| p.fail("needs \"point3 P\""))?;
        let degree = p.int("degree")?.unwrap_or(3);
        let basis = p.string("basis")?.unwrap_or("bezier");
        let kind = p.string("type")?.unwrap_or("flat");
        let shape = match kind {
            "flat" => CurveShape::Flat,
            "cylinder" => CurveShape::Round,
            "ribbon" => {
                p.ignore("N");
                warn.push(p.warning(
                    "ribbon curves are drawn as flat curves facing the ray: their normals \
                     \"N\" are ignored",
                ));
                CurveShape::Flat
            }
            other => return Err(p.fail(format_args!("unknown curve type {other:?}"))),
        };
        if kind != "ribbon" && p.triples("N", &["normal", "normal3"])?.is_some() {
            warn.push(p.warning("normals \"N\" apply only to ribbon curves: ignored"));
        }
        p.ignore("splitdepth");
        let width = p.float("width")?.unwrap_or(1.0);
        let width0 = p.float("width0")?.unwrap_or(width);
        let width1 = p.float("width1")?.unwrap_or(width);
        for (name, w) in [("width", width), ("width0", width0), ("width1", width1)] {
            if w < 0.0 {
                return Err(p.fail(format_args!("{name} = {w}: must be >= 0")));
            }
        }
        let (mut basis, mut control) = layout(&points, basis, degree).map_err(|m| p.fail(m))?;
        if basis == CurveBasis::BSpline {
            // The end points of a B-spline sit a segment beyond its ends, where a steep
            // taper would give them a negative width: the same curve as Bezier segments
            // then keeps every width between width0 and width1.
            let beyond = (width1 - width0) / (control.len() - 3) as f64;
            if width0 - beyond < 0.0 || width1 + beyond < 0.0 {
                (basis, control) = (CurveBasis::Bezier, bspline_to_bezier(&control));
            }
        }
        let scale = uniform_scale(to_world, p, warn);
        let segments = control.len() as f64 - 1.0;
        let (offset, span) = match basis {
            // Point i of a B-spline sits at parameter (i - 1) / (n - 3).
            CurveBasis::BSpline => (1.0, segments - 2.0),
            // Point i of a Bezier curve at i / (n - 1).
            _ => (0.0, segments),
        };
        let key = (material.to_string(), shape, basis);
        let i = *self.index.entry(key).or_insert_with(|| {
            let source = GroomSource::ControlPoints {
                points: Vec::new(),
                counts: Vec::new(),
                basis,
            };
            let mut groom = GroomDesc::new(source, material);
            groom.shape = shape.into();
            self.list.push(groom);
            self.list.len() - 1
        });
        let GroomSource::ControlPoints { points, counts, .. } = &mut self.list[i].source else {
            unreachable!("pbrt grooms hold control points");
        };
        counts.push(u32::try_from(control.len()).map_err(|_| p.fail("too many control points"))?);
        points.extend(control.iter().enumerate().map(|(j, c)| {
            let t = (j as f64 - offset) / span;
            let w = width0 + (width1 - width0) * t;
            let q = to_world.transform_point3(DVec3::from_array(*c));
            [
                q.x as f32,
                q.y as f32,
                q.z as f32,
                (0.5 * w * scale).max(0.0) as f32,
            ]
        }));
        Ok(())
    }
}

/// The control points for Embree and their basis: cubic curves as given, degree 2 raised
/// to cubic Bezier segments. Counts are checked as pbrt checks them.
fn layout(
    points: &[[f64; 3]],
    basis: &str,
    degree: i64,
) -> std::result::Result<(CurveBasis, Vec<[f64; 3]>), String> {
    let n = points.len();
    let bad = || format!("{n} control points do not make a degree {degree} {basis} curve");
    let elevate = |q: [[f64; 3]; 3]| -> [[f64; 3]; 3] {
        let [a, b, c] = q.map(DVec3::from_array);
        [a + (b - a) * (2.0 / 3.0), c + (b - c) * (2.0 / 3.0), c].map(|v| v.to_array())
    };
    match (basis, degree) {
        ("bezier", 3) if n >= 4 && (n - 1) % 3 == 0 => Ok((CurveBasis::Bezier, points.to_vec())),
        ("bspline", 3) if n >= 4 => Ok((CurveBasis::BSpline, points.to_vec())),
        ("bezier", 2) if n >= 3 && (n - 1) % 2 == 0 => {
            let mut out = vec![points[0]];
            for s in points[..n - 1]
                .chunks_exact(2)
                .zip(points[2..].iter().step_by(2))
            {
                out.extend(elevate([s.0[0], s.0[1], *s.1]));
            }
            Ok((CurveBasis::Bezier, out))
        }
        ("bspline", 2) if n >= 3 => {
            // Each quadratic B-spline segment is the quadratic Bezier from the midpoint
            // of its first two points, through the middle one, to the next midpoint.
            let mid = |a: [f64; 3], b: [f64; 3]| {
                ((DVec3::from_array(a) + DVec3::from_array(b)) * 0.5).to_array()
            };
            let mut out = vec![mid(points[0], points[1])];
            for w in points.windows(3) {
                out.extend(elevate([mid(w[0], w[1]), w[1], mid(w[1], w[2])]));
            }
            Ok((CurveBasis::Bezier, out))
        }
        ("bezier" | "bspline", 2 | 3) => Err(bad()),
        ("bezier" | "bspline", _) => Err(format!("degree {degree}: only 2 and 3 are supported")),
        _ => Err(format!(
            "basis {basis:?}: only \"bezier\" and \"bspline\" are supported"
        )),
    }
}

/// A cubic uniform B-spline as the same curve in cubic Bezier segments.
fn bspline_to_bezier(points: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let p: Vec<DVec3> = points.iter().map(|q| DVec3::from_array(*q)).collect();
    let mut out = Vec::with_capacity(3 * p.len());
    for w in p.windows(4) {
        let bezier = CurveBasis::BSpline.bezier_form::<DVec3, f64>([w[0], w[1], w[2], w[3]]);
        // Consecutive segments share their end point.
        let first = if out.is_empty() { 0 } else { 1 };
        out.extend_from_slice(&bezier[first..]);
    }
    out.iter().map(DVec3::to_array).collect()
}

/// The factor by which `m` scales lengths: exact for a rotation times a uniform scale;
/// otherwise the cube root of the volume change, with a warning (a tube under a
/// non-uniform scale is no longer round).
fn uniform_scale(m: &DMat4, p: &Params, warn: &mut Vec<Warning>) -> f64 {
    let linear = DMat3::from_mat4(*m);
    let scale = linear.determinant().abs().cbrt();
    let gram = linear.transpose() * linear;
    let expected = DMat3::from_diagonal(DVec3::splat(scale * scale));
    if !gram.abs_diff_eq(expected, SIMILARITY_TOLERANCE * scale * scale) {
        warn.push(
            p.warning("the transform scales unevenly: curve widths are scaled by the mean factor"),
        );
    }
    scale
}

/// A `trianglemesh`, `plymesh` or `sphere` statement as a mesh in world space (a sphere
/// tessellated as a `[[mesh]] shape = "sphere"` is); `dir` is the folder of the file that
/// names it.
pub(super) fn mesh(
    kind: &str,
    p: &Params,
    to_world: &DMat4,
    dir: &Path,
    material: &str,
) -> Result<MeshDesc> {
    let mut mesh = match kind {
        "trianglemesh" => {
            let positions = p
                .triples("P", &["point3", "point"])?
                .ok_or_else(|| p.fail("needs \"point3 P\""))?;
            let indices = match p.nums("indices", &["integer"])? {
                Some(v) => v.to_vec(),
                None if positions.len() == 3 => vec![0.0, 1.0, 2.0],
                None => return Err(p.fail("needs \"integer indices\"")),
            };
            if indices.len() % 3 != 0 {
                return Err(p.fail(format_args!(
                    "{} indices: not whole triangles",
                    indices.len()
                )));
            }
            let index = |v: f64| {
                (v >= 0.0 && v.fract() == 0.0 && v < positions.len() as f64)
                    .then_some(v as u32)
                    .ok_or_else(|| p.fail(format_args!("index {v} is not a vertex")))
            };
            let triangles = indices
                .chunks_exact(3)
                .map(|t| Ok([index(t[0])?, index(t[1])?, index(t[2])?]))
                .collect::<Result<Vec<_>>>()?;
            let positions = positions.iter().map(|q| q.map(|c| c as f32)).collect();
            Mesh {
                positions,
                triangles,
                ..Mesh::default()
            }
        }
        "sphere" => {
            let radius = p.float("radius")?.unwrap_or(1.0);
            let full = [("zmin", -radius), ("zmax", radius), ("phimax", 360.0)];
            for (name, whole) in full {
                if p.float(name)?.is_some_and(|v| v != whole) {
                    return Err(p.fail(format_args!("{name}: only whole spheres are supported")));
                }
            }
            shapes::sphere(Vec3::ZERO, radius as f32, shapes::SPHERE_SUBDIVISIONS)
                .map_err(|e| p.context(e))?
        }
        _ => {
            let file = p
                .string("filename")?
                .ok_or_else(|| p.fail("needs \"string filename\""))?;
            read_mesh_file(dir.join(file))
                .map_err(|e| e.context(format_args!("{}: {}", p.loc, p.what)))?
        }
    };
    let normal_matrix = DMat3::from_mat4(*to_world).inverse().transpose();
    for q in &mut mesh.positions {
        let w = to_world.transform_point3(DVec3::from_array(q.map(f64::from)));
        *q = w.as_vec3().to_array();
    }
    for n in mesh.normals.iter_mut().flatten() {
        let w = normal_matrix * DVec3::from_array(n.map(f64::from));
        *n = w.normalize_or_zero().as_vec3().to_array();
    }
    mesh.validate()
        .map_err(|e| e.context(format_args!("{}: {}", p.loc, p.what)))?;
    Ok(MeshDesc::new(MeshSource::Triangles(mesh), material))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eval_bezier(c: &[[f64; 3]], t: f64) -> DVec3 {
        let [a, b, cc, d] = [c[0], c[1], c[2], c[3]].map(DVec3::from_array);
        let s = 1.0 - t;
        a * s * s * s + b * 3.0 * s * s * t + cc * 3.0 * s * t * t + d * t * t * t
    }

    #[test]
    fn quadratic_curves_become_the_same_cubic_bezier_curves() {
        let q = [[0.0, 0.0, 0.0], [1.0, 2.0, 0.0], [2.0, 0.0, 1.0]];
        let (basis, c) = layout(&q, "bezier", 2).unwrap();
        assert_eq!((basis, c.len()), (CurveBasis::Bezier, 4));
        for t in [0.0, 0.3, 0.5, 1.0] {
            let [a, b, cc] = q.map(DVec3::from_array);
            let s = 1.0 - t;
            let quad = a * s * s + b * 2.0 * s * t + cc * t * t;
            assert!(eval_bezier(&c, t).abs_diff_eq(quad, 1e-12), "t = {t}");
        }
        // A quadratic B-spline of 4 points: 2 segments, joined at the middle midpoint.
        let q4 = [[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let (basis, c) = layout(&q4, "bspline", 2).unwrap();
        assert_eq!((basis, c.len()), (CurveBasis::Bezier, 7));
        assert_eq!(c[0], [0.5, 0.0, 0.0]);
        assert_eq!(c[3], [1.0, 0.5, 0.0]);
        assert_eq!(c[6], [0.5, 1.0, 0.0]);
    }

    #[test]
    fn counts_are_checked_as_pbrt_does() {
        let p = |n| vec![[0.0; 3]; n];
        assert!(layout(&p(7), "bezier", 3).is_ok());
        assert!(
            layout(&p(6), "bezier", 3)
                .unwrap_err()
                .contains("6 control points")
        );
        assert!(layout(&p(3), "bspline", 3).is_err());
        assert!(
            layout(&p(4), "bspline", 4)
                .unwrap_err()
                .contains("only 2 and 3")
        );
        assert!(
            layout(&p(4), "hermite", 3)
                .unwrap_err()
                .contains("\"hermite\"")
        );
    }
}
