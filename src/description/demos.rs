//! The built-in scenes and the quick look at a bare groom.

use std::collections::BTreeMap;
use std::path::Path;

use super::{
    EnvironmentSource, GroomDesc, GroomSource, LightDesc, MaterialDesc, MeshDesc, MeshSource,
    SceneDescription, Transform,
};
use crate::error::{Error, Result, invalid_arg};
use crate::formats::hair::Thickness;
use crate::render::settings::RenderSettings;
use crate::scene::groom::{FurBall, ScalpPatch};
use crate::scene::material::{HairColor, HairMaterial};

/// Names of the built-in scenes of [`demo`].
pub const DEMOS: [&str; 3] = ["furball", "furnace", "scalp"];

/// A built-in scene (see [`DEMOS`]): `"furball"` (the default demo: 20k strands of brown
/// fur on a ball over a floor, under the default lights), `"furnace"` (white fur, sigma_a = 0, around
/// a white diffuse sphere under a uniform environment of radiance 1: every pixel's
/// expected value is 1) or `"scalp"` (wavy auburn hair on a head).
///
/// A demo is a [`SceneDescription`] like any other, to change in code before the build;
/// here the host's own strands replace the fur:
///
/// ```no_run
/// use std::sync::Arc;
/// use hairtrace::description::{GroomDesc, GroomSource, demo};
/// use hairtrace::embree::CurveBasis;
/// use hairtrace::{Aovs, NoProgress};
/// # fn main() -> hairtrace::Result<()> {
/// let mut scene = demo("furball")?;
/// // Two strands of three control points each: x, y, z, radius.
/// let points = vec![
///     [0.0, 0.0, 0.0, 0.01], [0.0, 0.5, 0.1, 0.008], [0.0, 1.0, 0.0, 0.005],
///     [0.2, 0.0, 0.0, 0.01], [0.2, 0.5, 0.1, 0.008], [0.2, 1.0, 0.0, 0.005],
/// ];
/// let basis = CurveBasis::BSpline;
/// let source = GroomSource::ControlPoints { points, counts: vec![3, 3], basis };
/// scene.grooms = vec![GroomDesc::new(source, "hair")];
/// scene.render.set("spp", "64")?;
/// let mut built = scene.build(Arc::new(scene.render.device()?))?;
/// let image = built.render(Aovs::default(), &NoProgress)?.film;
/// # let _ = image;
/// # Ok(()) }
/// ```
pub fn demo(name: &str) -> Result<SceneDescription> {
    let scene = match name {
        "furball" => furball_demo(),
        "furnace" => furnace_demo(),
        "scalp" => scalp_demo(),
        _ => {
            return Err(invalid_arg!(
                "unknown demo {name:?} (choose one of: {})",
                DEMOS.join(", ")
            ));
        }
    };
    Ok(SceneDescription {
        origin: format!("demo {name}"),
        ..scene
    })
}

/// A quick look at a groom file: the default brown hair ([`HairMaterial::default`]), the
/// file's own curves (a `.hair` file that does not say its basis needs one set on the
/// groom before the build), the default lights and an automatic camera. Fails early,
/// before any scene is built, when the file cannot be read.
pub fn quick_look(hair_file: &Path) -> Result<SceneDescription> {
    std::fs::metadata(hair_file).map_err(|e| Error::io(hair_file, e))?;
    let file = GroomSource::File {
        path: hair_file.to_path_buf(),
        thickness: Thickness::default(),
        frame: None,
    };
    Ok(SceneDescription {
        materials: BTreeMap::from([(
            "hair".to_string(),
            MaterialDesc::Hair(HairMaterial::default()),
        )]),
        grooms: vec![GroomDesc::new(file, "hair")],
        lights: default_lights(),
        origin: hair_file.display().to_string(),
        ..SceneDescription::default()
    })
}

/// The lights of the demos and quick looks: a soft bluish sky and a warm key light from
/// above, left of the automatic camera (which looks from the front right), small enough
/// to give the hair a crisp highlight and soft enough to avoid aliased shadow edges.
pub(crate) fn default_lights() -> Vec<LightDesc> {
    vec![
        LightDesc::Environment {
            source: EnvironmentSource::Uniform([0.25, 0.28, 0.32]),
            rotation_deg: 0.0,
            scale: 1.0,
        },
        LightDesc::Distant {
            direction: [-0.5, 1.0, 0.8],
            irradiance: [3.0, 2.85, 2.6],
            angular_radius_deg: 1.0,
        },
    ]
}

fn furball_demo() -> SceneDescription {
    let fur = FurBall {
        strands: 20_000,
        ..FurBall::default()
    };
    // Nothing hangs lower than a strand's length below the ball.
    let floor = -(fur.radius + fur.length);
    let hair = HairMaterial {
        absorption_variation: 0.2,
        roughness_variation: 0.1,
        seed: 1,
        ..HairMaterial::default()
    };
    SceneDescription {
        materials: BTreeMap::from([
            ("brown".to_string(), MaterialDesc::Hair(hair)),
            (
                "skin".to_string(),
                MaterialDesc::Diffuse {
                    albedo: [0.3, 0.2, 0.15],
                },
            ),
            (
                "floor".to_string(),
                MaterialDesc::Diffuse { albedo: [0.4; 3] },
            ),
        ]),
        meshes: vec![
            // The skin under the fur, so the floor does not show through the ball.
            MeshDesc::new(
                MeshSource::Sphere {
                    centre: [0.0; 3],
                    radius: fur.radius,
                },
                "skin",
            ),
            MeshDesc::new(
                MeshSource::Ground {
                    y: floor,
                    half_size: 10.0,
                },
                "floor",
            ),
        ],
        grooms: vec![GroomDesc::new(GroomSource::FurBall(fur), "brown")],
        lights: default_lights(),
        ..SceneDescription::default()
    }
}

fn furnace_demo() -> SceneDescription {
    let fur = FurBall::default();
    let white_hair = HairMaterial {
        color: HairColor::SigmaA([0.0; 3]),
        beta_m: 0.3,
        beta_n: 0.3,
        ..HairMaterial::default()
    };
    SceneDescription {
        render: RenderSettings::default(),
        materials: BTreeMap::from([
            ("white_hair".to_string(), MaterialDesc::Hair(white_hair)),
            (
                "white".to_string(),
                MaterialDesc::Diffuse { albedo: [1.0; 3] },
            ),
        ]),
        meshes: vec![MeshDesc::new(
            MeshSource::Sphere {
                centre: [0.0; 3],
                // Just inside the roots: where the fibres' root tubes crossed the facets, a
                // path scattered inside the closed white sphere was lost to the depth cap
                // (1% of the groom's light at radius 1).
                radius: 0.99 * fur.radius,
            },
            "white",
        )],
        grooms: vec![GroomDesc::new(GroomSource::FurBall(fur), "white_hair")],
        lights: vec![LightDesc::Environment {
            source: EnvironmentSource::Uniform([1.0; 3]),
            rotation_deg: 0.0,
            scale: 1.0,
        }],
        ..SceneDescription::default()
    }
}

fn scalp_demo() -> SceneDescription {
    let scalp = ScalpPatch::default();
    // The patch faces +z: turned, the automatic camera sees the head beside the hair.
    let three_quarter = Transform::Trs {
        translate: [0.0; 3],
        rotate_deg: [0.0, 60.0, 0.0],
        scale: 1.0,
    };
    let auburn = HairMaterial {
        color: HairColor::Melanin {
            eumelanin: 0.8,
            pheomelanin: 0.6,
        },
        absorption_variation: 0.15,
        roughness_variation: 0.1,
        seed: 2,
        ..HairMaterial::default()
    };
    SceneDescription {
        materials: BTreeMap::from([
            ("auburn".to_string(), MaterialDesc::Hair(auburn)),
            (
                "skin".to_string(),
                MaterialDesc::Diffuse {
                    albedo: [0.63, 0.45, 0.38],
                },
            ),
        ]),
        meshes: vec![MeshDesc {
            transform: three_quarter,
            ..MeshDesc::new(
                MeshSource::Sphere {
                    centre: [0.0; 3],
                    radius: scalp.radius,
                },
                "skin",
            )
        }],
        grooms: vec![GroomDesc {
            transform: three_quarter,
            ..GroomDesc::new(GroomSource::Scalp(scalp), "auburn")
        }],
        lights: default_lights(),
        ..SceneDescription::default()
    }
}
