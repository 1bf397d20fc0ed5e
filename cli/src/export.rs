//! A scene written out for another renderer: what the peer benchmark (`bench/peer`)
//! hands to Blender Cycles so that both render the same strands, meshes, lights and
//! camera. Grooms go out as world-space `.hair` files (thickness = diameter), with their
//! curve normals beside them where they have some, meshes as OBJ with their shading normals, the rest as one JSON file (`scene.json`); the format
//! is documented in `bench/README.md`.
//!
//! Only what both renderers can express is exported: an explicit camera, hair materials
//! without per-strand variation, round linear or Catmull-Rom curves (Cycles' thick curves
//! are Catmull-Rom splines), pinhole cameras that stay put, meshes that do not deform.
//! Anything else is an error naming it, never a silently different scene. A USD groom
//! read at a frame under an open shutter goes out as its file too, for the peer to import
//! with its own USD reader and blur (bench/README.md).

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use hairtrace::description::{
    EnvironmentSource, GroomSource, LightDesc, MaterialDesc, SceneDescription, Shutter, Transform,
    is_sequence,
};
use hairtrace::embree::CurveBasis;
use hairtrace::formats::hair::{HairTag, Thickness, write_tagged_hair_file};
use hairtrace::formats::units::StageUnits;
use hairtrace::formats::usd::{Wrap, is_usd_path};
use hairtrace::scene::{GroomShape, HairModel, Mesh};
use hairtrace::{Error, Result};

/// An invalid-argument error from a format string.
macro_rules! invalid_arg {
    ($($arg:tt)*) => {
        Error::InvalidArg(format!($($arg)*))
    };
}

#[derive(Serialize)]
struct PeerScene {
    width: u32,
    height: u32,
    camera: PeerCamera,
    grooms: Vec<PeerGroom>,
    meshes: Vec<PeerMesh>,
    lights: Vec<PeerLight>,
    /// The frame and the shutter (open, close, in frames from it) when the shutter is open
    /// on a scene whose grooms move.
    #[serde(skip_serializing_if = "Option::is_none")]
    motion: Option<PeerMotion>,
}

#[derive(Serialize)]
struct PeerMotion {
    frame: f64,
    shutter: [f32; 2],
}

#[derive(Serialize)]
struct PeerCamera {
    eye: [f32; 3],
    target: [f32; 3],
    up: [f32; 3],
    fov_y_deg: f32,
}

#[derive(Serialize)]
struct PeerGroom {
    file: String,
    /// The animated USD file the groom moves by (absolute), for the peer to import as its
    /// own tools do: the `.hair` file is its frame, still.
    #[serde(skip_serializing_if = "Option::is_none")]
    usd: Option<String>,
    /// The groom's curve normals, where it has them (`write_normals`).
    #[serde(skip_serializing_if = "Option::is_none")]
    normals: Option<String>,
    basis: &'static str,
    shape: &'static str,
    material: PeerHair,
}

#[derive(Serialize)]
struct PeerHair {
    sigma_a: [f32; 3],
    eta: f32,
    alpha_deg: f32,
    #[serde(flatten)]
    model: PeerModel,
}

/// The hair model and its roughnesses: Cycles' Principled Hair BSDF has both.
#[derive(Serialize)]
#[serde(tag = "model", rename_all = "snake_case")]
enum PeerModel {
    Chiang { beta_m: f32, beta_n: f32 },
    Huang { roughness: f32, aspect: f32 },
}

#[derive(Serialize)]
struct PeerMesh {
    file: String,
    albedo: [f32; 3],
}

#[derive(Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
enum PeerLight {
    Environment {
        radiance: [f32; 3],
    },
    EnvironmentMap {
        file: String,
        scale: f32,
        rotation_deg: f32,
    },
    Distant {
        direction: [f32; 3],
        irradiance: [f32; 3],
        angular_radius_deg: f32,
    },
}

/// Writes `description` into the folder `dir` (created if missing) for a peer renderer.
pub fn export_for_peer(description: &SceneDescription, dir: &Path) -> Result<()> {
    let d = description;
    let io = |e: std::io::Error| Error::io(dir, e);
    std::fs::create_dir_all(dir).map_err(io)?;
    let (Some(eye), Some(target)) = (d.camera.eye, d.camera.target) else {
        return Err(invalid_arg!(
            "{}: give the camera's eye and target: an automatic camera is not exported",
            d.origin
        ));
    };
    if d.camera.aperture_radius != 0.0 {
        return Err(invalid_arg!(
            "{}: only pinhole cameras are exported",
            d.origin
        ));
    }
    let material = |name: &str| {
        d.materials
            .get(name)
            .ok_or_else(|| invalid_arg!("{}: no material {name:?}", d.origin))
    };
    let shutter = Shutter::of(&d.render);
    let (open, close) = (shutter.open, shutter.close);
    if close > open && d.camera.shutter_close.is_some() {
        return Err(invalid_arg!(
            "{}: the camera moves over the shutter: a moving camera is not exported",
            d.origin
        ));
    }
    let mut motion = None;
    let mut grooms = Vec::new();
    for (i, g) in d.grooms.iter().enumerate() {
        // A USD groom read at a frame, under an open shutter, moves by its time samples.
        let moving = match &g.source {
            GroomSource::File {
                path,
                frame: Some(frame),
                ..
            } if close > open && is_usd_path(path) => Some((path, *frame)),
            _ => None,
        };
        let usd = match moving {
            Some((path, frame)) => {
                if is_sequence(path) {
                    return Err(invalid_arg!(
                        "groom[{i}]: {} is a sequence of per-frame files: a moving groom is \
                         exported as one file, whose time samples the peer imports",
                        path.display()
                    ));
                }
                if g.transform != Transform::default() || g.radius_scale != 1.0 {
                    return Err(invalid_arg!(
                        "groom[{i}]: a moving USD groom is exported as its file, which the peer \
                         imports as it is: give it no transform or radius_scale"
                    ));
                }
                motion = Some(PeerMotion {
                    frame,
                    shutter: [open, close],
                });
                let path = std::path::absolute(path).map_err(|e| Error::io(path, e))?;
                Some(path.display().to_string())
            }
            None => None,
        };
        // `auto` is an approximation of round tubes, which the peer traces exactly.
        if g.shape == GroomShape::Flat {
            return Err(invalid_arg!("groom[{i}]: only round curves are exported"));
        }
        let MaterialDesc::Hair(hair) = material(&g.material)? else {
            return Err(invalid_arg!("groom[{i}]: its material is not hair"));
        };
        let prepared = hair.prepare()?;
        if !prepared.is_uniform() {
            return Err(invalid_arg!(
                "groom[{i}]: material {:?} varies per strand, which a peer cannot reproduce",
                g.material
            ));
        }
        let p = prepared.params_at(0, 0.0, None);
        let sets = g
            .placed_strands()
            .map_err(|e| e.context(format_args!("groom[{i}]")))?;
        let many = sets.len() > 1;
        // A moving USD groom goes out once, as its file: the peer imports all its prims.
        let sets = match usd {
            Some(_) => &sets[..sets.len().min(1)],
            None => &sets[..],
        };
        for (k, set) in sets.iter().enumerate() {
            let layout = set.curves.layout();
            let basis = match (layout.basis, layout.wrap) {
                (CurveBasis::Linear, Wrap::Nonperiodic | Wrap::Pinned) => "linear",
                (CurveBasis::CatmullRom, Wrap::Pinned) => "catmull-rom",
                _ => {
                    let (kind, basis, wrap) = layout.tokens();
                    return Err(invalid_arg!(
                        "groom[{i}]{}: {kind} {basis} {wrap} curves have no Cycles equivalent \
                         (linear, or pinned Catmull-Rom)",
                        set.prim
                            .as_deref()
                            .map(|p| format!(" {p}"))
                            .unwrap_or_default()
                    ));
                }
            };
            let stem = match many {
                true => format!("groom{i}_{k}"),
                false => format!("groom{i}"),
            };
            let file = format!("{stem}.hair");
            let tag = HairTag {
                layout,
                units: StageUnits::WORLD,
            };
            write_tagged_hair_file(
                &dir.join(&file),
                &set.strands,
                Thickness::Diameter,
                Some(&tag),
            )?;
            let normals = match &set.normals {
                Some(n) if n.len() != set.strands.point_count() => {
                    return Err(invalid_arg!(
                        "groom[{i}]: {} curve normals for {} points",
                        n.len(),
                        set.strands.point_count()
                    ));
                }
                Some(n) => Some(write_normals(dir, &format!("{stem}.normals"), n)?),
                None => None,
            };
            grooms.push(PeerGroom {
                file,
                usd: usd.clone(),
                normals,
                basis,
                shape: "round",
                material: PeerHair {
                    sigma_a: p.sigma_a,
                    eta: p.eta,
                    alpha_deg: p.alpha,
                    model: match hair.model {
                        HairModel::Chiang => PeerModel::Chiang {
                            beta_m: p.beta_m,
                            beta_n: p.beta_n,
                        },
                        HairModel::Huang { roughness, aspect } => {
                            PeerModel::Huang { roughness, aspect }
                        }
                    },
                },
            });
        }
    }
    let mut meshes = Vec::new();
    for (i, m) in d.meshes.iter().enumerate() {
        let MaterialDesc::Diffuse { albedo } = material(&m.material)? else {
            return Err(invalid_arg!("mesh[{i}]: its material is not diffuse"));
        };
        let file = format!("mesh{i}.obj");
        let mesh = m.mesh(shutter)?;
        if !mesh.later_positions.is_empty() {
            return Err(invalid_arg!(
                "mesh[{i}]: it deforms over the shutter: a moving mesh is not exported"
            ));
        }
        std::fs::write(dir.join(&file), obj_text(&mesh)).map_err(io)?;
        meshes.push(PeerMesh {
            file,
            albedo: *albedo,
        });
    }
    let lights = d
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| peer_light(i, l))
        .collect::<Result<Vec<_>>>()?;
    let scene = PeerScene {
        width: d.render.width,
        height: d.render.height,
        camera: PeerCamera {
            eye,
            target,
            up: d.camera.up,
            fov_y_deg: d.camera.fov_deg,
        },
        grooms,
        meshes,
        lights,
        motion,
    };
    let json = serde_json::to_string_pretty(&scene).map_err(|e| invalid_arg!("scene.json: {e}"))?;
    std::fs::write(dir.join("scene.json"), json).map_err(io)
}

fn peer_light(i: usize, light: &LightDesc) -> Result<PeerLight> {
    Ok(match light {
        LightDesc::Environment {
            source: EnvironmentSource::Uniform(radiance),
            rotation_deg: _,
            scale,
        } => PeerLight::Environment {
            radiance: radiance.map(|v| v * scale),
        },
        LightDesc::Environment {
            source: EnvironmentSource::Map(path),
            rotation_deg,
            scale,
        } => PeerLight::EnvironmentMap {
            file: std::path::absolute(path)
                .map_err(|e| Error::io(path, e))?
                .display()
                .to_string(),
            scale: *scale,
            rotation_deg: *rotation_deg,
        },
        LightDesc::Environment {
            source: EnvironmentSource::LatLong { .. },
            ..
        } => {
            return Err(invalid_arg!(
                "light[{i}]: an environment given as texels (from a pbrt file) is not exported"
            ));
        }
        LightDesc::Distant {
            direction,
            irradiance,
            angular_radius_deg,
        } => PeerLight::Distant {
            direction: *direction,
            irradiance: *irradiance,
            angular_radius_deg: *angular_radius_deg,
        },
        LightDesc::Rect { .. } => {
            return Err(invalid_arg!(
                "light[{i}]: rect lights are not exported (their power conventions differ \
                 between renderers)"
            ));
        }
    })
}

/// Writes a groom's curve normals into `dir/file` and returns `file`: 3 little-endian f32
/// per point of its `.hair` file, in the same order (as it is exported, one per segment end),
/// so that the peer orients an elliptical fibre as hairtrace does (`HairHit::major_axis`).
fn write_normals(dir: &Path, file: &str, normals: &[[f32; 3]]) -> Result<String> {
    let bytes: Vec<u8> = normals
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let path = dir.join(file);
    std::fs::write(&path, bytes).map_err(|e| Error::io(&path, e))?;
    Ok(file.to_owned())
}

/// A mesh as OBJ text: positions, normals when it has them, 1-based faces.
fn obj_text(mesh: &Mesh) -> String {
    let mut s = String::new();
    for p in &mesh.positions {
        let _ = writeln!(s, "v {} {} {}", p[0], p[1], p[2]);
    }
    for n in mesh.normals.iter().flatten() {
        let _ = writeln!(s, "vn {} {} {}", n[0], n[1], n[2]);
    }
    let with_normals = mesh.normals.is_some();
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| i + 1);
        let _ = if with_normals {
            writeln!(s, "f {a}//{a} {b}//{b} {c}//{c}")
        } else {
            writeln!(s, "f {a} {b} {c}")
        };
    }
    s
}
