//! pbrt-v4 materials: `hair` and `diffuse` become [`MaterialDesc`]s with pbrt's
//! defaults; any other type is kept as the reason it cannot be rendered, which becomes an
//! error only when a shape uses it.

use super::params::{Color, Params, Warning};
use crate::description::MaterialDesc;
use crate::error::Result;
use crate::scene::material::{HairColor, HairMaterial};

/// pbrt-v4's `HairMaterial` defaults: eumelanin 1.3 when no colour is given, eta 1.55,
/// beta_m = beta_n = 0.3, alpha 2 degrees.
const DEFAULT_EUMELANIN: f32 = 1.3;
const DEFAULT_ETA: f32 = 1.55;
const DEFAULT_BETA: f32 = 0.3;
const DEFAULT_ALPHA_DEG: f32 = 2.0;
/// pbrt-v4's diffuse reflectance when none is given, also its default material's.
pub(super) const DEFAULT_REFLECTANCE: f32 = 0.5;

/// A material as read: what we render, or why we cannot.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Material {
    Supported(MaterialDesc),
    Unsupported(String),
}

/// Reads a material of `kind`; warnings (textures replaced by defaults, parameters
/// ignored) go to `warn`.
pub(super) fn material(kind: &str, p: &Params, warn: &mut Vec<Warning>) -> Result<Material> {
    let m = match kind {
        "hair" => Material::Supported(MaterialDesc::Hair(hair(p, warn)?)),
        "diffuse" => {
            let albedo = color(p, "reflectance", warn)?
                .unwrap_or([f64::from(DEFAULT_REFLECTANCE); 3])
                .map(|c| c as f32);
            Material::Supported(MaterialDesc::Diffuse { albedo })
        }
        "" | "none" | "interface" => {
            Material::Unsupported(format!("{}: {}: a material of no surface", p.loc, p.what))
        }
        _ => {
            for q in &p.list {
                p.ignore(&q.name);
            }
            warn.push(p.warning(format_args!(
                "material type {kind:?} is not supported: a shape that uses it is refused"
            )));
            Material::Unsupported(format!(
                "{}: {}: material type {kind:?} is not supported (only \"hair\" and \"diffuse\")",
                p.loc, p.what
            ))
        }
    };
    warn.extend(p.unused());
    Ok(m)
}

/// An RGB parameter; a texture is replaced by pbrt's default, with a warning.
fn color(p: &Params, name: &str, warn: &mut Vec<Warning>) -> Result<Option<[f64; 3]>> {
    Ok(match p.color(name)? {
        Some(Color::Rgb(c)) => Some(c),
        Some(Color::Texture(t)) => {
            warn.push(texture_warning(p, name, &t));
            None
        }
        None => None,
    })
}

fn float(p: &Params, name: &str, warn: &mut Vec<Warning>) -> Result<Option<f32>> {
    Ok(match p.float_or_texture(name)? {
        Some(Ok(v)) => Some(v as f32),
        Some(Err(t)) => {
            warn.push(texture_warning(p, name, &t));
            None
        }
        None => None,
    })
}

fn texture_warning(p: &Params, name: &str, texture: &str) -> Warning {
    p.warning(format_args!(
        "parameter {name:?} is the texture {texture:?}: textures are not supported, \
         pbrt's default value is used instead (THE IMAGE WILL DIFFER)"
    ))
}

/// pbrt's precedence: sigma_a, then reflectance (or pbrt-v3's `color`), then melanin;
/// the later ones are ignored with a warning, as pbrt does.
fn hair(p: &Params, warn: &mut Vec<Warning>) -> Result<HairMaterial> {
    let sigma_a = color(p, "sigma_a", warn)?;
    let reflectance = match color(p, "reflectance", warn)? {
        Some(c) => Some(c),
        None => color(p, "color", warn)?,
    };
    let eumelanin = float(p, "eumelanin", warn)?;
    let pheomelanin = float(p, "pheomelanin", warn)?;
    let melanin = eumelanin.is_some() || pheomelanin.is_some();
    let f32s = |c: [f64; 3]| c.map(|v| v as f32);
    let ignored = |names: &[&str], since: &str| {
        names
            .iter()
            .map(|n| {
                p.warning(format_args!(
                    "parameter {n:?} ignored, since {since:?} is given"
                ))
            })
            .collect::<Vec<_>>()
    };
    let hair_color = match (sigma_a, reflectance) {
        (Some(s), _) => {
            if reflectance.is_some() {
                warn.extend(ignored(&["reflectance"], "sigma_a"));
            }
            if melanin {
                warn.extend(ignored(&["eumelanin/pheomelanin"], "sigma_a"));
            }
            HairColor::SigmaA(f32s(s))
        }
        (None, Some(c)) => {
            if melanin {
                warn.extend(ignored(&["eumelanin/pheomelanin"], "reflectance"));
            }
            HairColor::Color(f32s(c))
        }
        (None, None) if melanin => HairColor::Melanin {
            eumelanin: eumelanin.unwrap_or(0.0),
            pheomelanin: pheomelanin.unwrap_or(0.0),
        },
        (None, None) => HairColor::Melanin {
            eumelanin: DEFAULT_EUMELANIN,
            pheomelanin: 0.0,
        },
    };
    Ok(HairMaterial {
        color: hair_color,
        eta: float(p, "eta", warn)?.unwrap_or(DEFAULT_ETA),
        beta_m: float(p, "beta_m", warn)?.unwrap_or(DEFAULT_BETA),
        beta_n: float(p, "beta_n", warn)?.unwrap_or(DEFAULT_BETA),
        alpha: float(p, "alpha", warn)?.unwrap_or(DEFAULT_ALPHA_DEG),
        ..HairMaterial::default()
    })
}
