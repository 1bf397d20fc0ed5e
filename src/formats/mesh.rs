//! Triangle meshes from OBJ (`tobj`) and PLY (`ply-rs-bw`) files: every object of an OBJ
//! merged into one mesh, PLY polygons fanned into triangles, validated as any mesh is.

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use crate::Error;
use crate::error::{Result, invalid_arg};
use crate::scene::mesh::Mesh;

/// Reads an `.obj` or `.ply` file (by extension); errors name the file.
pub fn read_mesh_file(path: impl AsRef<Path>) -> Result<Mesh> {
    let path = path.as_ref();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let opened = || File::open(path).map_err(|e| Error::io(path, e));
    // A missing or unreadable file is an i/o error whatever its format.
    match ext.as_deref() {
        Some("obj") => opened().and_then(|_| from_obj(path)),
        Some("ply") => opened().and_then(|_| from_ply(path)),
        _ => Err(invalid_arg!(
            "{}: unknown mesh format (expected .obj or .ply)",
            path.display()
        )),
    }
}

/// Every object of an OBJ file, merged into one mesh; polygons are triangulated.
fn from_obj(path: impl AsRef<Path>) -> Result<Mesh> {
    let path = path.as_ref();
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _materials) = tobj::load_obj(path, &options)
        .map_err(|e| file_error(path, format_args!("cannot read OBJ: {e}")))?;
    let mut mesh = Mesh::default();
    let mut all_normals = Some(Vec::new());
    for model in models {
        let m = model.mesh;
        let base = mesh.positions.len() as u64;
        if m.positions.len() % 3 != 0 || m.indices.len() % 3 != 0 {
            return Err(file_error(
                path,
                format_args!("object {:?}: ragged arrays", model.name),
            ));
        }
        let count = m.positions.len() / 3;
        mesh.positions
            .extend(m.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        for t in m.indices.chunks_exact(3) {
            let tri: Option<Vec<u32>> = t
                .iter()
                .map(|&i| u32::try_from(base + u64::from(i)).ok())
                .collect();
            let tri = tri.ok_or_else(|| file_error(path, format_args!("too many vertices")))?;
            mesh.triangles.push([tri[0], tri[1], tri[2]]);
        }
        // Normals only when every object has one per vertex.
        all_normals = all_normals.filter(|_| m.normals.len() == 3 * count);
        if let Some(n) = &mut all_normals {
            n.extend(m.normals.chunks_exact(3).map(|v| [v[0], v[1], v[2]]));
        }
    }
    mesh.normals = all_normals.filter(|n| !n.is_empty());
    mesh.validate()
        .map_err(|e| file_error(path, format_args!("{e}")))?;
    Ok(mesh)
}

/// The `vertex` (x, y, z and, if all present, nx, ny, nz) and `face` (`vertex_indices`
/// or `vertex_index`, polygons fanned into triangles) elements of a PLY file, ASCII or
/// binary.
fn from_ply(path: impl AsRef<Path>) -> Result<Mesh> {
    let path = path.as_ref();
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut BufReader::new(file))
        .map_err(|e| file_error(path, format_args!("cannot read PLY: {e}")))?;
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| file_error(path, format_args!("no `vertex` element")))?;
    let mut mesh = Mesh::default();
    let mut normals = Vec::new();
    for (i, v) in vertices.iter().enumerate() {
        let coord = |key: &str| v.get(key).and_then(scalar);
        let (Some(x), Some(y), Some(z)) = (coord("x"), coord("y"), coord("z")) else {
            return Err(file_error(
                path,
                format_args!("vertex {i} lacks a numeric x, y or z"),
            ));
        };
        mesh.positions.push([x, y, z]);
        if let (Some(a), Some(b), Some(c)) = (coord("nx"), coord("ny"), coord("nz")) {
            normals.push([a, b, c]);
        }
    }
    if normals.len() == mesh.positions.len() && !normals.is_empty() {
        mesh.normals = Some(normals);
    }
    let faces = ply
        .payload
        .get("face")
        .map(Vec::as_slice)
        .unwrap_or_default();
    for (f, face) in faces.iter().enumerate() {
        let list = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .and_then(index_list)
            .ok_or_else(|| {
                file_error(
                    path,
                    format_args!("face {f} has no integer vertex_indices list"),
                )
            })?;
        if list.len() < 3 {
            return Err(file_error(
                path,
                format_args!("face {f} has {} vertices", list.len()),
            ));
        }
        mesh.triangles
            .extend((1..list.len() - 1).map(|k| [list[0], list[k], list[k + 1]]));
    }
    mesh.validate()
        .map_err(|e| file_error(path, format_args!("{e}")))?;
    Ok(mesh)
}

fn file_error(path: &Path, what: std::fmt::Arguments) -> Error {
    invalid_arg!("{}: {what}", path.display())
}

fn scalar(p: &Property) -> Option<f32> {
    Some(match *p {
        Property::Float(v) => v,
        Property::Double(v) => v as f32,
        Property::Char(v) => f32::from(v),
        Property::UChar(v) => f32::from(v),
        Property::Short(v) => f32::from(v),
        Property::UShort(v) => f32::from(v),
        Property::Int(v) => v as f32,
        Property::UInt(v) => v as f32,
        _ => return None,
    })
}

/// A face's vertex list as u32; None for a negative index or a non-integer list.
fn index_list(p: &Property) -> Option<Vec<u32>> {
    fn conv<T: Copy>(v: &[T], f: impl Fn(T) -> Option<u32>) -> Option<Vec<u32>> {
        v.iter().map(|&x| f(x)).collect()
    }
    match p {
        Property::ListChar(v) => conv(v, |x| u32::try_from(x).ok()),
        Property::ListUChar(v) => conv(v, |x| Some(u32::from(x))),
        Property::ListShort(v) => conv(v, |x| u32::try_from(x).ok()),
        Property::ListUShort(v) => conv(v, |x| Some(u32::from(x))),
        Property::ListInt(v) => conv(v, |x| u32::try_from(x).ok()),
        Property::ListUInt(v) => Some(v.clone()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str, text: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("hairtrace-mesh-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn obj_quad_is_triangulated() {
        let path = temp(
            "quad.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n",
        );
        let m = read_mesh_file(&path).unwrap();
        assert_eq!(m.triangles.len(), 2);
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.normals.as_ref().map(Vec::len), Some(4));
    }

    #[test]
    fn ply_ascii_polygon_is_fanned() {
        let path = temp(
            "quad.ply",
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
             property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
             end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n",
        );
        let m = read_mesh_file(&path).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals, None);
    }

    #[test]
    fn errors_name_the_file_and_the_problem() {
        let path = temp("bad.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
        let err = read_mesh_file(&path).unwrap_err().to_string();
        assert!(err.contains("bad.obj") && err.contains("vertex 2"), "{err}");
        let path = temp(
            "range.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
             property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
             end_header\n0 0 0\n1 0 0\n1 1 0\n3 0 1 7\n",
        );
        let err = read_mesh_file(&path).unwrap_err().to_string();
        assert!(
            err.contains("range.ply") && err.contains("triangle 0"),
            "{err}"
        );
        let path = temp("trunc.ply", "ply\nformat ascii 1.0\nelement vertex 3\n");
        let err = read_mesh_file(&path).unwrap_err().to_string();
        assert!(err.contains("trunc.ply"), "{err}");
        let err = read_mesh_file("/nonexistent/x.ply")
            .unwrap_err()
            .to_string();
        assert!(err.contains("/nonexistent/x.ply"), "{err}");
        assert!(read_mesh_file("mesh.stl").is_err());
    }
}
