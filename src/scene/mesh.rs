//! Triangle meshes (scalp, head, floor), validated before they reach Embree. OBJ and PLY
//! files are read by `formats::mesh`.

use crate::embree::MAX_TIME_STEPS;
use crate::error::{Result, invalid_arg};
use crate::validate;

/// A triangle mesh with optional per-vertex normals, which may deform over the shutter.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// The vertices, at the first time step when the mesh deforms.
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// One per position when present; they become the shading normal. A mesh that deforms
    /// has none: its geometric normal at the ray's time shades it.
    pub normals: Option<Vec<[f32; 3]>>,
    /// For a mesh that deforms, its vertices at each later time step, spread evenly over
    /// the shutter with `positions` the first (`math::time_steps`); empty for one that
    /// stays put.
    pub later_positions: Vec<Vec<[f32; 3]>>,
}

impl Mesh {
    /// A mesh from arrays, validated (see [`Mesh::validate`]).
    pub fn new(
        positions: Vec<[f32; 3]>,
        triangles: Vec<[u32; 3]>,
        normals: Option<Vec<[f32; 3]>>,
    ) -> Result<Self> {
        let mesh = Mesh {
            positions,
            triangles,
            normals,
            later_positions: Vec::new(),
        };
        mesh.validate()?;
        Ok(mesh)
    }

    /// Checks at least one triangle, indices in range, positions within
    /// +-1e15 (what Embree can trace) at every time step, as many at each, finite normals,
    /// and one normal per position (none for a mesh that deforms).
    pub fn validate(&self) -> Result<()> {
        for (k, later) in (1..).zip(&self.later_positions) {
            if later.len() != self.positions.len() {
                return Err(invalid_arg!(
                    "time step {k} has {} vertices, time step 0 {}",
                    later.len(),
                    self.positions.len()
                ));
            }
            validate::positions("vertex", later)
                .map_err(|e| e.context(format!("time step {k}")))?;
        }
        if self.later_positions.len() >= MAX_TIME_STEPS {
            return Err(invalid_arg!(
                "{} time steps: a mesh in motion takes 1 to {MAX_TIME_STEPS}",
                self.later_positions.len() + 1
            ));
        }
        if self.normals.is_some() && !self.later_positions.is_empty() {
            return Err(invalid_arg!(
                "vertex normals on a mesh that deforms: leave them out (its geometric normal \
                 at each ray's time shades it)"
            ));
        }
        if self.triangles.is_empty() {
            return Err(invalid_arg!(
                "{} vertices and 0 triangles: a mesh needs at least one triangle",
                self.positions.len()
            ));
        }
        validate::positions("vertex", &self.positions)?;
        let n = self.positions.len();
        if let Some(t) = self
            .triangles
            .iter()
            .position(|t| t.iter().any(|&v| v as usize >= n))
        {
            return Err(invalid_arg!(
                "triangle {t} = {:?} names a vertex beyond the {n} given",
                self.triangles[t]
            ));
        }
        if let Some(normals) = &self.normals {
            if normals.len() != n {
                return Err(invalid_arg!("{} normals for {n} vertices", normals.len()));
            }
            if let Some(i) = normals
                .iter()
                .position(|v| !v.iter().all(|c| c.is_finite()))
            {
                return Err(invalid_arg!("normal {i} = {:?} is not finite", normals[i]));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_normal_per_position_or_none() {
        assert!(Mesh::new(vec![[0.0; 3]; 3], vec![[0, 1, 2]], Some(vec![[0.0; 3]; 2])).is_err());
        assert!(Mesh::new(vec![[0.0; 3]; 3], vec![[0, 1, 2]], Some(vec![[0.0; 3]; 3])).is_ok());
        assert!(Mesh::new(vec![[0.0; 3]; 3], vec![[0, 1, 3]], None).is_err());
    }

    /// A mesh that deforms has as many vertices, all finite, at every time step, and no
    /// vertex normals; each refusal names what is wrong.
    #[test]
    fn a_deforming_mesh_keeps_its_vertices_at_every_step() {
        let mesh = |later: Vec<Vec<[f32; 3]>>, normals| Mesh {
            positions: vec![[0.0; 3]; 3],
            triangles: vec![[0, 1, 2]],
            normals,
            later_positions: later,
        };
        assert!(mesh(vec![vec![[1.0; 3]; 3]], None).validate().is_ok());
        let e = mesh(vec![vec![[1.0; 3]; 2]], None).validate().unwrap_err();
        assert!(e.to_string().contains("time step 1 has 2 vertices"), "{e}");
        let e = mesh(vec![vec![[1.0; 3]; 3], vec![[f32::NAN; 3]; 3]], None)
            .validate()
            .unwrap_err();
        assert!(e.to_string().contains("time step 2: vertex 0"), "{e}");
        let e = mesh(vec![vec![[1.0; 3]; 3]], Some(vec![[0.0, 1.0, 0.0]; 3]))
            .validate()
            .unwrap_err();
        assert!(
            e.to_string().contains("normals on a mesh that deforms"),
            "{e}"
        );
    }
}
