//! A scene written out for another renderer: what the peer benchmark (`bench/peer`)
//! hands to Blender Cycles so that both render the same strands, meshes, lights and
//! camera. Grooms go out as world-space `.hair` files (thickness = diameter), meshes as
//! OBJ with their shading normals, the rest as one JSON file (`scene.json`); the format
//! is documented in `bench/README.md`.
//!
//! Only what both renderers can express is exported: an explicit camera, hair materials
//! without per-strand variation, round linear or Catmull-Rom curves (Cycles' thick curves
//! are Catmull-Rom splines), pinhole cameras. Anything else is an error naming it, never
//! a silently different scene.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use hairtrace::description::{EnvironmentSource, LightDesc, MaterialDesc, SceneDescription};
use hairtrace::embree::CurveBasis;
use hairtrace::formats::hair::{Thickness, write_hair_file};
use hairtrace::scene::{GroomShape, Mesh};
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
    basis: &'static str,
    shape: &'static str,
    material: PeerHair,
}

#[derive(Serialize)]
struct PeerHair {
    sigma_a: [f32; 3],
    eta: f32,
    beta_m: f32,
    beta_n: f32,
    alpha_deg: f32,
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
    let mut grooms = Vec::new();
    for (i, g) in d.grooms.iter().enumerate() {
        let basis = match g.basis {
            CurveBasis::Linear => "linear",
            CurveBasis::CatmullRom => "catmull-rom",
            other => {
                return Err(invalid_arg!(
                    "groom[{i}]: basis {other:?} has no Cycles equivalent (use linear or \
                     catmull-rom)"
                ));
            }
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
        let file = format!("groom{i}.hair");
        write_hair_file(&dir.join(&file), &g.strands()?, Thickness::Diameter)?;
        grooms.push(PeerGroom {
            file,
            basis,
            shape: "round",
            material: PeerHair {
                sigma_a: p.sigma_a,
                eta: p.eta,
                beta_m: p.beta_m,
                beta_n: p.beta_n,
                alpha_deg: p.alpha,
            },
        });
    }
    let mut meshes = Vec::new();
    for (i, m) in d.meshes.iter().enumerate() {
        let MaterialDesc::Diffuse { albedo } = material(&m.material)? else {
            return Err(invalid_arg!("mesh[{i}]: its material is not diffuse"));
        };
        let file = format!("mesh{i}.obj");
        std::fs::write(dir.join(&file), obj_text(&m.mesh()?)).map_err(io)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use hairtrace::description::GroomSource;
    use hairtrace::formats::hair::read_hair_file;

    /// The peer benchmark's scenes (`bench/scenes`), with fewer strands, all export.
    #[test]
    fn bench_scenes_export_for_the_peer() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../bench/scenes");
        let mut found = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                let mut desc = SceneDescription::load(&path).unwrap();
                for g in &mut desc.grooms {
                    match &mut g.source {
                        GroomSource::FurBall(f) => f.strands = 300,
                        GroomSource::Scalp(s) => s.strands = 300,
                        _ => {}
                    }
                }
                let out = std::env::temp_dir()
                    .join(format!("hairtrace-peer-{}-{found}", std::process::id()));
                export_for_peer(&desc, &out).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                assert!(out.join("scene.json").is_file());
                std::fs::remove_dir_all(&out).unwrap();
                found += 1;
            }
        }
        assert!(found >= 4, "only {found} bench scenes");
    }

    const SCENE: &str = r#"
[render]
width = 32
height = 24
[camera]
eye = [0, 0, 5]
target = [0, 0, 0]
fov_deg = 30
[materials.brown]
type = "hair"
melanin = [1.3, 0.0]
[materials.floor]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
[[groom]]
procedural = "fur_ball"
basis = "linear"
material = "brown"
[groom.params]
strands = 50
segments = 4
[[mesh]]
shape = "ground"
y = -2
half_size = 3
material = "floor"
[[light]]
type = "environment"
radiance = [0.5, 0.5, 0.5]
scale = 2
[[light]]
type = "distant"
direction = [0, 1, 0]
irradiance = [3, 3, 3]
angular_radius_deg = 2
"#;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("hairtrace-peer-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn a_scene_goes_out_whole() {
        let d = SceneDescription::from_toml(SCENE, Path::new("."), "test").unwrap();
        let dir = scratch("whole");
        export_for_peer(&d, &dir).unwrap();
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("scene.json")).unwrap())
                .unwrap();
        assert_eq!(json["width"], 32);
        assert_eq!(json["camera"]["fov_y_deg"], 30.0);
        let groom = &json["grooms"][0];
        assert_eq!(groom["basis"], "linear");
        let sigma_a = hairtrace::bsdf::sigma_a_from_melanin(1.3, 0.0).unwrap();
        let exported = groom["material"]["sigma_a"][1].as_f64().unwrap() as f32;
        assert_eq!(exported, sigma_a[1], "f32 values survive the text exactly");
        // The environment's scale is folded into its radiance.
        assert_eq!(json["lights"][0]["radiance"][0], 1.0);
        assert_eq!(json["lights"][1]["type"], "distant");
        let strands = read_hair_file(&dir.join("groom0.hair"), Thickness::Diameter).unwrap();
        assert_eq!(strands, d.grooms[0].strands().unwrap());
        let obj = std::fs::read_to_string(dir.join("mesh0.obj")).unwrap();
        assert!(obj.lines().any(|l| l.starts_with("vn ")) && obj.contains("f 1//1"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn what_a_peer_cannot_render_is_refused() {
        let refused = |from: &str, to: &str, expect: &str| {
            let text = SCENE.replace(from, to);
            let d = SceneDescription::from_toml(&text, Path::new("."), "test").unwrap();
            let dir = scratch("refused");
            let e = export_for_peer(&d, &dir).unwrap_err().to_string();
            assert!(e.contains(expect), "{e}");
            let _ = std::fs::remove_dir_all(&dir);
        };
        refused("eye = [0, 0, 5]\ntarget = [0, 0, 0]", "", "eye and target");
        refused(
            "basis = \"linear\"",
            "basis = \"bspline\"",
            "no Cycles equivalent",
        );
        refused(
            "melanin = [1.3, 0.0]",
            "melanin = [1.3, 0.0]\nabsorption_variation = 0.2",
            "varies per strand",
        );
    }
}
