//! Writes grooms as a USD stage of BasisCurves prims, through `openusd`'s own authoring API
//! and layer writers (the format by the extension). Use `.usda`: the crate files openusd 0.6
//! writes (`.usdc`, `.usd`, `.usdz`) read back here but Pixar's library cannot read them
//! (usd-core 26.11 refuses nested prims, "Invalid children found in primChildren field", and
//! reads root prims as none), so [`convert`](crate::formats::convert) writes text only.
//!
//! Every prim is authored with what the UsdGeom schema needs to be read anywhere: `type`,
//! `basis` and `wrap` (uniform tokens), `points`, `curveVertexCounts`, `widths` as
//! **diameters** (`constant` when every width is the same, else `vertex`), and, when there are
//! colours, `primvars:displayColor` with `vertex` interpolation (not `varying`: `vertex`
//! keeps each point's colour as the `.hair` file has it, and a pinned curve of two points
//! has no `varying` values in usd-core's count).
//! The writer prints floats through f64, so every f32 reads back bit for bit (a negative zero
//! as 0: integral values are printed as integers).

use std::path::Path;

use openusd::sdf::{self, Value, Variability};
use openusd::tf::Token;
use openusd::usd::{Prim, Stage};

use super::layout::Layout;
use crate::error::{Result, invalid_arg};
use crate::formats::units::StageUnits;

/// The root Xform every written prim sits under (and the stage's default prim).
pub const ROOT_PRIM: &str = "Groom";

/// One BasisCurves prim to write: authored points, curve after curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvesToWrite {
    /// The prim's name under [`ROOT_PRIM`] (a USD identifier).
    pub name: String,
    pub layout: Layout,
    pub points: Vec<[f32; 3]>,
    pub counts: Vec<u32>,
    /// Diameters, one per point.
    pub widths: Vec<f32>,
    /// One colour per point, if any.
    pub colors: Option<Vec<[f32; 3]>>,
}

/// Writes `prims` to `path` (format by extension) under `/Groom`, with `units` as stage
/// metadata. Errors name the path.
pub fn write_usd_file(path: &Path, prims: &[CurvesToWrite], units: &StageUnits) -> Result<()> {
    let at = |e: String| invalid_arg!("{}: {e}", path.display());
    let name = path
        .to_str()
        .ok_or_else(|| at("the path is not valid UTF-8".into()))?;
    let stage = author(prims, units).map_err(|e| e.context(path.display()))?;
    stage
        .root_layer()
        .export(name)
        .map_err(|e| at(format!("cannot write the USD file: {e:#}")))
}

/// An error of the USD library, its causes included.
fn failed(e: impl std::fmt::Display) -> crate::Error {
    invalid_arg!("{e:#}")
}

fn author(prims: &[CurvesToWrite], units: &StageUnits) -> Result<Stage> {
    let stage = Stage::builder().in_memory("groom.usda").map_err(failed)?;
    stage.set_default_prim(ROOT_PRIM).map_err(failed)?;
    let id = stage.root_layer().identifier().to_string();
    stage
        .batch_edit(&[&id], |layers| {
            let mut root = layers[0].pseudo_root_mut()?;
            root.set("upAxis", Value::Token(Token::from(units.up_axis.name())));
            root.set("metersPerUnit", Value::Double(units.meters_per_unit));
            Ok(())
        })
        .map_err(failed)?;
    let define = |path: &str, kind: &str| -> Result<Prim> {
        let path = sdf::path(path).map_err(failed)?;
        let prim = stage.define_prim(path).map_err(failed)?;
        prim.set_type_name(kind).map_err(failed)
    };
    define(&format!("/{ROOT_PRIM}"), "Xform")?;
    for p in prims {
        let prim = define(&format!("/{ROOT_PRIM}/{}", p.name), "BasisCurves")?;
        // Schema attributes (custom = false), with an interpolation when given one.
        let attr = |name: &str, ty: &str, v: Value, interp: Option<&'static str>| {
            let a = prim
                .create_attribute(Token::from(name), ty)
                .map_err(failed)?;
            let a = a.set_custom(false).and_then(|a| a.set(v)).map_err(failed)?;
            match interp {
                Some(i) => a
                    .set_metadata("interpolation", Value::Token(Token::new(i)))
                    .map_err(failed),
                None => Ok(a),
            }
        };
        let (kind, basis, wrap) = p.layout.tokens();
        for (name, token) in [("type", kind), ("basis", basis), ("wrap", wrap)] {
            attr(name, "token", Value::Token(Token::new(token)), None)?
                .set_variability(Variability::Uniform)
                .map_err(failed)?;
        }
        let counts = (p.counts.iter())
            .map(|&c| i32::try_from(c).map_err(failed))
            .collect::<Result<Vec<_>>>()?;
        attr("curveVertexCounts", "int[]", Value::IntVec(counts), None)?;
        let vec3 = |v: &[[f32; 3]]| Value::Vec3fVec(v.iter().map(|&p| p.into()).collect());
        attr("points", "point3f[]", vec3(&p.points), None)?;
        let constant = p
            .widths
            .windows(2)
            .all(|w| w[0].to_bits() == w[1].to_bits());
        let (widths, interp) = match p.widths.first() {
            Some(&w) if constant => (vec![w], "constant"),
            _ => (p.widths.clone(), "vertex"),
        };
        attr("widths", "float[]", Value::FloatVec(widths), Some(interp))?;
        if let Some(c) = &p.colors {
            attr(
                "primvars:displayColor",
                "color3f[]",
                vec3(c),
                Some("vertex"),
            )?;
        }
    }
    Ok(stage)
}
