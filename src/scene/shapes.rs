//! Procedural meshes for scenes without modelled props: a sphere (the head under a scalp
//! patch, the core of a fur ball) and a ground quad to catch shadows.

use std::collections::HashMap;

use glam::Vec3;

use super::mesh::Mesh;
use crate::error::{Result, invalid_arg};
use crate::validate::positive;

/// Most subdivisions of [`sphere`]: 7 gives 327,680 triangles, far past the point where
/// smooth normals hide the facets; more is surely a typo.
pub(crate) const MAX_SPHERE_SUBDIVISIONS: u32 = 7;

/// Subdivisions of a scene file's sphere (`shape = "sphere"`, pbrt's `sphere`): 5120
/// triangles, whose silhouette strays from the true sphere by under 0.05% of its radius.
pub(crate) const SPHERE_SUBDIVISIONS: u32 = 4;

/// The golden ratio: the icosahedron's vertices are the cyclic permutations of
/// (+-1, +-PHI, 0).
const PHI: f32 = 1.618_034;

const ICOSAHEDRON_VERTICES: [[f32; 3]; 12] = [
    [-1.0, PHI, 0.0],
    [1.0, PHI, 0.0],
    [-1.0, -PHI, 0.0],
    [1.0, -PHI, 0.0],
    [0.0, -1.0, PHI],
    [0.0, 1.0, PHI],
    [0.0, -1.0, -PHI],
    [0.0, 1.0, -PHI],
    [PHI, 0.0, -1.0],
    [PHI, 0.0, 1.0],
    [-PHI, 0.0, -1.0],
    [-PHI, 0.0, 1.0],
];

/// Counter-clockwise seen from outside, so geometric normals point outward.
const ICOSAHEDRON_FACES: [[u32; 3]; 20] = [
    [0, 11, 5],
    [0, 5, 1],
    [0, 1, 7],
    [0, 7, 10],
    [0, 10, 11],
    [1, 5, 9],
    [5, 11, 4],
    [11, 10, 2],
    [10, 7, 6],
    [7, 1, 8],
    [3, 9, 4],
    [3, 4, 2],
    [3, 2, 6],
    [3, 6, 8],
    [3, 8, 9],
    [4, 9, 5],
    [2, 4, 11],
    [6, 2, 10],
    [8, 6, 7],
    [9, 8, 1],
];

/// A closed icosphere: the icosahedron with each triangle split into four `subdivisions`
/// times (20 * 4^n triangles, 10 * 4^n + 2 vertices), every vertex pushed onto the sphere.
/// An icosphere rather than a UV sphere: its triangles are nearly equal, with no slivers
/// at the poles. Vertex normals are the exact sphere normals (outward), so shading is
/// smooth whatever the subdivision; triangles wind counter-clockwise seen from outside.
pub fn sphere(centre: Vec3, radius: f32, subdivisions: u32) -> Result<Mesh> {
    if !centre.is_finite() {
        return Err(invalid_arg!("sphere centre {centre} is not finite"));
    }
    positive("sphere radius", radius)?;
    if subdivisions > MAX_SPHERE_SUBDIVISIONS {
        return Err(invalid_arg!(
            "sphere subdivisions {subdivisions}: must be at most {MAX_SPHERE_SUBDIVISIONS}"
        ));
    }
    let mut units: Vec<Vec3> = ICOSAHEDRON_VERTICES
        .iter()
        .map(|&v| Vec3::from_array(v).normalize())
        .collect();
    let mut faces = ICOSAHEDRON_FACES.to_vec();
    for _ in 0..subdivisions {
        // Each edge is split once, whichever of its two triangles reaches it first, so
        // neighbours share the midpoint and the mesh stays closed.
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::with_capacity(faces.len() * 3 / 2);
        let mut midpoint = |a: u32, b: u32| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                units.push((units[a as usize] + units[b as usize]).normalize());
                (units.len() - 1) as u32
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (midpoint(a, b), midpoint(b, c), midpoint(c, a));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    let positions = units
        .iter()
        .map(|&n| (centre + radius * n).to_array())
        .collect();
    let normals = units.iter().map(|n| n.to_array()).collect();
    Mesh::new(positions, faces, Some(normals))
}

/// A horizontal square at height `y`, from -`half_size` to `half_size` in x and z: two
/// triangles facing +y, with +y normals.
pub fn ground(y: f32, half_size: f32) -> Result<Mesh> {
    if !y.is_finite() {
        return Err(invalid_arg!("ground height {y} is not finite"));
    }
    positive("ground half size", half_size)?;
    let h = half_size;
    Mesh::new(
        vec![[-h, y, -h], [h, y, -h], [h, y, h], [-h, y, h]],
        vec![[0, 3, 2], [0, 2, 1]],
        Some(vec![[0.0, 1.0, 0.0]; 4]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn face_normal(mesh: &Mesh, t: [u32; 3]) -> (Vec3, Vec3) {
        let [a, b, c] = t.map(|i| Vec3::from_array(mesh.positions[i as usize]));
        ((b - a).cross(c - a), (a + b + c) / 3.0)
    }

    #[test]
    fn sphere_is_closed_outward_and_on_its_radius() {
        let centre = Vec3::new(1.0, -2.0, 0.5);
        for n in 0..=3 {
            let mesh = sphere(centre, 2.0, n).unwrap();
            assert_eq!(mesh.positions.len(), 10 * 4usize.pow(n) + 2);
            assert_eq!(mesh.triangles.len(), 20 * 4usize.pow(n));
            let normals = mesh.normals.as_ref().unwrap();
            for (p, nrm) in mesh.positions.iter().zip(normals) {
                let d = Vec3::from_array(*p) - centre;
                assert!(
                    (d.length() - 2.0).abs() < 1e-5,
                    "vertex off the sphere: {d}"
                );
                let nrm = Vec3::from_array(*nrm);
                assert!((nrm.length() - 1.0).abs() < 1e-5);
                assert!(nrm.dot(d.normalize()) > 0.9999, "normal not outward");
            }
            for &t in &mesh.triangles {
                let (g, mid) = face_normal(&mesh, t);
                assert!(g.dot(mid - centre) > 0.0, "triangle {t:?} winds inward");
            }
            // Closed: every edge is shared by exactly two triangles, once each way.
            let mut edges = HashMap::new();
            for &[a, b, c] in &mesh.triangles {
                for e in [(a, b), (b, c), (c, a)] {
                    *edges.entry(e).or_insert(0) += 1;
                }
            }
            for (&(a, b), &count) in &edges {
                assert_eq!(count, 1, "edge {a}-{b} repeated");
                assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}-{b} is open");
            }
        }
    }

    #[test]
    fn ground_faces_up() {
        let mesh = ground(-0.5, 3.0).unwrap();
        for &t in &mesh.triangles {
            let (g, mid) = face_normal(&mesh, t);
            assert!(g.normalize().abs_diff_eq(Vec3::Y, 1e-6));
            assert_eq!(mid.y, -0.5);
        }
        assert!(
            mesh.positions
                .iter()
                .all(|p| p[0].abs() == 3.0 && p[2].abs() == 3.0)
        );
    }

    #[test]
    fn bad_arguments_are_errors() {
        assert!(sphere(Vec3::ZERO, 0.0, 2).is_err());
        assert!(sphere(Vec3::ZERO, f32::NAN, 2).is_err());
        assert!(sphere(Vec3::splat(f32::INFINITY), 1.0, 2).is_err());
        assert!(sphere(Vec3::ZERO, 1.0, MAX_SPHERE_SUBDIVISIONS + 1).is_err());
        assert!(sphere(Vec3::splat(f32::MAX), f32::MAX, 1).is_err());
        assert!(ground(f32::NAN, 1.0).is_err());
        assert!(ground(0.0, -1.0).is_err());
    }
}
