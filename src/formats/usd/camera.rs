//! One Camera prim: its pose under its composed world transform, its lens, turned into a
//! hairtrace camera. UsdGeomCamera measures `focalLength` and the apertures in tenths of a
//! scene unit (millimetres on a centimetre stage) and `focusDistance` in scene units; the
//! camera looks down its own -z with +y up.

use glam::{DVec3, Vec3};
use openusd::schemas::geom::Camera as CameraPrim;
use openusd::sdf::{self, Value};
use openusd::usd::Stage;

use super::prim::{animation, world_transform, wrong_type};
use super::time::{Animation, ReadAt};
use crate::error::{Result, invalid_arg};
use crate::formats::units::StageUnits;
use crate::scene::Camera;

/// One Camera prim at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct UsdCamera {
    pub path: String,
    pub animation: Animation,
    pub units: StageUnits,
    /// The eye, view and up directions under the prim's transform, in the stage's units
    /// and axes.
    pub eye: [f64; 3],
    pub view: [f64; 3],
    pub up: [f64; 3],
    /// `focalLength`, `verticalAperture` and `horizontalAperture`, in tenths of a scene
    /// unit.
    pub focal_length: f64,
    pub vertical_aperture: f64,
    pub horizontal_aperture: f64,
    /// `fStop` (0: a pinhole) and `focusDistance`, in scene units.
    pub f_stop: f64,
    pub focus_distance: f64,
}

/// A tenth of a scene unit, the unit of the lens and filmback.
const LENS_UNIT: f64 = 0.1;

impl UsdCamera {
    /// The vertical field of view, in degrees: the vertical aperture seen from the focal
    /// length.
    pub fn fov_y_deg(&self) -> f64 {
        (2.0 * (0.5 * self.vertical_aperture / self.focal_length).atan()).to_degrees()
    }

    /// The camera in hairtrace's world for an image of `aspect`: the vertical aperture
    /// gives the field of view, the image's aspect its width; an `fStop` above 0 makes a
    /// thin lens of radius focal length / (2 fStop), focused at `focusDistance`.
    pub fn camera(&self, aspect: f32) -> Result<Camera> {
        let units = self.units;
        let world = |p: [f64; 3]| Vec3::from_array(units.to_world(p.map(|x| x as f32)));
        let eye = world(self.eye);
        // Directions take the turn alone: the scale does not change where they point.
        let turn = StageUnits {
            meters_per_unit: 1.0,
            ..units
        };
        let dir = |d: [f64; 3]| {
            let d = DVec3::from_array(d).normalize_or_zero().as_vec3();
            Vec3::from_array(turn.to_world(d.to_array()))
        };
        let camera = Camera::new(
            eye,
            eye + dir(self.view),
            dir(self.up),
            self.fov_y_deg() as f32,
            aspect,
        )?;
        if self.f_stop == 0.0 {
            return Ok(camera);
        }
        let metres = units.meters_per_unit;
        let radius = self.focal_length * LENS_UNIT / (2.0 * self.f_stop) * metres;
        if self.focus_distance <= 0.0 {
            return Err(invalid_arg!(
                "focusDistance = {}: fStop {} makes a thin lens, which needs a focus distance > 0",
                self.focus_distance,
                self.f_stop
            ));
        }
        camera.with_thin_lens(radius as f32, (self.focus_distance * metres) as f32)
    }
}

fn number(value: Option<Value>, what: &str, fallback: f64) -> Result<f64> {
    let v = match value {
        None => fallback,
        Some(Value::Float(v)) => f64::from(v),
        Some(Value::Double(v)) => v,
        // A text layer's time samples keep the type their numbers were written in.
        Some(Value::Int(v)) => f64::from(v),
        Some(Value::Int64(v)) => v as f64,
        Some(v) => return Err(wrong_type(what, "float", &v)),
    };
    match v.is_finite() {
        true => Ok(v),
        false => Err(invalid_arg!("{what} = {v}: must be finite")),
    }
}

/// Reads the Camera prim at `path`.
pub(super) fn read_camera(
    stage: &Stage,
    path: &sdf::Path,
    units: StageUnits,
    at: ReadAt,
) -> Result<UsdCamera> {
    let camera = CameraPrim::get(stage, path.clone())
        .map_err(|e| invalid_arg!("{e:#}"))?
        .ok_or_else(|| invalid_arg!("not a Camera prim"))?;
    let prim = stage.prim(path.clone());
    let value =
        |name: &str, fallback: f64| number(at.value(&prim.attribute(name))?, name, fallback);
    match at.value(&prim.attribute("projection"))? {
        None => {}
        Some(Value::Token(t)) if t.as_str() == "perspective" => {}
        Some(v) => {
            return Err(invalid_arg!(
                "projection: {v:?}: only perspective cameras are read"
            ));
        }
    }
    // UsdGeomCamera's fallbacks: a 50 mm lens on a 35 mm filmback.
    let read = UsdCamera {
        path: path.as_str().to_string(),
        animation: animation(stage, path)?,
        units,
        eye: [0.0; 3],
        view: [0.0; 3],
        up: [0.0; 3],
        focal_length: value("focalLength", 50.0)?,
        vertical_aperture: value("verticalAperture", 15.2908)?,
        horizontal_aperture: value("horizontalAperture", 20.955)?,
        f_stop: value("fStop", 0.0)?,
        focus_distance: value("focusDistance", 0.0)?,
    };
    for (what, v) in [
        ("focalLength", read.focal_length),
        ("verticalAperture", read.vertical_aperture),
        ("horizontalAperture", read.horizontal_aperture),
    ] {
        if v <= 0.0 {
            return Err(invalid_arg!("{what} = {v}: must be > 0"));
        }
    }
    if read.f_stop < 0.0 {
        return Err(invalid_arg!("fStop = {}: must be >= 0", read.f_stop));
    }
    let m = world_transform(stage, path, &camera, at)?;
    // Row vectors, as USD writes them: a point is p M, a direction d M without the
    // translation.
    let apply = |d: [f64; 3], w: f64| -> [f64; 3] {
        std::array::from_fn(|j| {
            d[0] * m.0[j] + d[1] * m.0[4 + j] + d[2] * m.0[8 + j] + w * m.0[12 + j]
        })
    };
    let finite = |v: [f64; 3]| v.iter().all(|x| x.is_finite());
    let (eye, view, up) = (
        apply([0.0; 3], 1.0),
        apply([0.0, 0.0, -1.0], 0.0),
        apply([0.0, 1.0, 0.0], 0.0),
    );
    if !(finite(eye) && finite(view) && finite(up)) {
        return Err(invalid_arg!("the camera's world transform is not finite"));
    }
    Ok(UsdCamera {
        eye,
        view,
        up,
        ..read
    })
}
