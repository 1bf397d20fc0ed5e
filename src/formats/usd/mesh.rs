//! One Mesh prim: its faces fanned into triangles, its points under its composed world
//! transform. Normals, primvars and subdivision are not read: the mesh is traced as its
//! control cage, flat shaded.

use openusd::schemas::geom::Mesh;
use openusd::sdf::{self, Value};
use openusd::usd::Stage;

use super::prim::{animation, points_at, transform_point, world_transform, wrong_type};
use super::time::{Animation, Clock, ReadAt};
use crate::error::{Result, invalid_arg};
use crate::formats::units::StageUnits;
use crate::validate;

/// One Mesh prim, under its transform and in the stage's units.
#[derive(Debug, Clone, PartialEq)]
pub struct UsdMesh {
    pub path: String,
    pub animation: Animation,
    pub units: StageUnits,
    /// The points under the prim's transform, in the stage's units.
    pub points: Vec<[f32; 3]>,
    /// The faces fanned from their first vertex, counter-clockwise seen from the front
    /// (a `leftHanded` prim's turned round).
    pub triangles: Vec<[u32; 3]>,
}

impl UsdMesh {
    /// The points in the world, each mapped by `point` (a scene's placement).
    pub fn world_points(&self, point: impl Fn([f32; 3]) -> [f32; 3]) -> Vec<[f32; 3]> {
        (self.points.iter())
            .map(|&p| point(self.units.to_world(p)))
            .collect()
    }
}

fn ints(value: Option<Value>, what: &str) -> Result<Vec<i32>> {
    match value {
        Some(Value::IntVec(v)) => Ok(v),
        Some(v) => Err(wrong_type(what, "int[]", &v)),
        None => Err(invalid_arg!("no {what}")),
    }
}

/// Reads the Mesh prim at `path`. `file_bytes` bounds the counts.
pub(super) fn read_mesh(
    stage: &Stage,
    path: &sdf::Path,
    file_bytes: u64,
    (units, clock): (StageUnits, &Clock),
    at: ReadAt,
) -> Result<UsdMesh> {
    let mesh = Mesh::get(stage, path.clone())
        .map_err(|e| invalid_arg!("{e:#}"))?
        .ok_or_else(|| invalid_arg!("not a Mesh prim"))?;
    let prim = stage.prim(path.clone());
    let value = |name: &str| at.value(&prim.attribute(name));
    let points = points_at(&prim, at, clock)?.ok_or_else(|| invalid_arg!("no points"))?;
    validate::positions("points: point", &points)?;
    let counts = ints(value("faceVertexCounts")?, "faceVertexCounts")?;
    let indices = ints(value("faceVertexIndices")?, "faceVertexIndices")?;
    if counts.len() as u64 > file_bytes {
        return Err(invalid_arg!(
            "faceVertexCounts: {} faces, more than the file could hold",
            counts.len()
        ));
    }
    let mut total: u64 = 0;
    for (i, &c) in counts.iter().enumerate() {
        if c < 3 {
            return Err(invalid_arg!(
                "faceVertexCounts[{i}] = {c}: a face has at least 3 vertices"
            ));
        }
        total += c as u64;
    }
    if total != indices.len() as u64 {
        return Err(invalid_arg!(
            "faceVertexCounts add up to {total} but faceVertexIndices has {}",
            indices.len()
        ));
    }
    if let Some(i) =
        (indices.iter()).position(|&v| !(0..points.len() as i64).contains(&i64::from(v)))
    {
        return Err(invalid_arg!(
            "faceVertexIndices[{i}] = {}: out of range for {} points",
            indices[i],
            points.len()
        ));
    }
    let left_handed = match value("orientation")? {
        None => false,
        Some(Value::Token(t)) if t.as_str() == "rightHanded" => false,
        Some(Value::Token(t)) if t.as_str() == "leftHanded" => true,
        Some(v) => {
            return Err(invalid_arg!(
                "orientation: {v:?} is not rightHanded or leftHanded"
            ));
        }
    };
    let mut holes: Vec<i32> = match value("holeIndices")? {
        None => Vec::new(),
        v => ints(v, "holeIndices")?,
    };
    holes.sort_unstable();
    let mut triangles = Vec::with_capacity(indices.len().saturating_sub(2 * counts.len()));
    let mut start = 0;
    for (face, &c) in counts.iter().enumerate() {
        let v = &indices[start..start + c as usize];
        start += c as usize;
        if holes.binary_search(&(face as i32)).is_ok() {
            continue;
        }
        for k in 1..v.len() - 1 {
            let t = [v[0], v[k], v[k + 1]].map(|i| i as u32);
            triangles.push(if left_handed { [t[0], t[2], t[1]] } else { t });
        }
    }
    if triangles.is_empty() {
        return Err(invalid_arg!("no faces"));
    }
    let m = world_transform(stage, path, &mesh, at)?;
    let points: Vec<[f32; 3]> = points.iter().map(|&p| transform_point(&m, p)).collect();
    validate::positions("point (in world space)", &points)?;
    // A transform that mirrors turns the faces' winding round with it.
    let det = {
        let r = |i: usize| glam::DVec3::new(m.0[4 * i], m.0[4 * i + 1], m.0[4 * i + 2]);
        r(0).dot(r(1).cross(r(2)))
    };
    if det < 0.0 {
        for t in &mut triangles {
            t.swap(1, 2);
        }
    }
    Ok(UsdMesh {
        path: path.as_str().to_string(),
        animation: animation(stage, path)?,
        units,
        points,
        triangles,
    })
}
