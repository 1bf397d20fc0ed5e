//! Triangle meshes (scalp, head, floor), validated before they reach Embree. OBJ and PLY
//! files are read by `formats::mesh`.

use crate::error::{Result, invalid_arg};
use crate::validate;

/// A triangle mesh with optional per-vertex normals.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// One per position when present; they become the shading normal.
    pub normals: Option<Vec<[f32; 3]>>,
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
        };
        mesh.validate()?;
        Ok(mesh)
    }

    /// Checks at least one triangle, indices in range, positions within
    /// +-1e15 (what Embree can trace), finite normals, and one normal
    /// per position.
    pub fn validate(&self) -> Result<()> {
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
}
