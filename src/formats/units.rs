//! The up axis and length unit a groom's file is written in, and the turn and scale that
//! bring its points into hairtrace's world: +y up, in metres (docs/conventions.md, "World
//! space"). USD stages state both (`upAxis`, `metersPerUnit`); a `.hair` file written by
//! `hairtrace convert` carries them in its header text; other files have neither and are
//! taken as they are.

use crate::error::{Result, invalid_arg};

/// A file's up axis. USD allows these two only.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UpAxis {
    Y,
    Z,
}

impl UpAxis {
    /// The axis USD spells `name` ("Y" or "Z").
    pub fn named(name: &str) -> Result<UpAxis> {
        match name {
            "Y" => Ok(UpAxis::Y),
            "Z" => Ok(UpAxis::Z),
            other => Err(invalid_arg!(
                "upAxis \"{other}\": USD allows \"Y\" and \"Z\""
            )),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            UpAxis::Y => "Y",
            UpAxis::Z => "Z",
        }
    }
}

/// A file's orientation and unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StageUnits {
    pub up_axis: UpAxis,
    pub meters_per_unit: f64,
}

impl StageUnits {
    /// hairtrace's world: +y up, metres. A file in these units is used as authored.
    pub const WORLD: StageUnits = StageUnits {
        up_axis: UpAxis::Y,
        meters_per_unit: 1.0,
    };

    /// USD's fallbacks for a stage that authors neither: `upAxis` Y, `metersPerUnit` 0.01.
    pub const USD_FALLBACK: StageUnits = StageUnits {
        up_axis: UpAxis::Y,
        meters_per_unit: 0.01,
    };

    /// Checked units: `meters_per_unit` finite and > 0, and small and large enough that a
    /// point keeps its precision once scaled.
    pub fn new(up_axis: UpAxis, meters_per_unit: f64) -> Result<StageUnits> {
        if !(meters_per_unit.is_finite() && (1e-9..=1e9).contains(&meters_per_unit)) {
            return Err(invalid_arg!(
                "metersPerUnit = {meters_per_unit}: must be finite, in [1e-9, 1e9]"
            ));
        }
        Ok(StageUnits {
            up_axis,
            meters_per_unit,
        })
    }

    /// The factor from the file's unit to metres, which radii follow.
    pub fn scale(self) -> f32 {
        self.meters_per_unit as f32
    }

    /// A point of the file in the world: a Z-up file turned so that its +z is +y and its +y
    /// is -z (`(x, y, z)` to `(x, z, -y)`, the turn Blender's exporters make into a Y-up
    /// format), then scaled into metres. The turn is exact, and so is the scale of a metre
    /// file.
    pub fn to_world(self, [x, y, z]: [f32; 3]) -> [f32; 3] {
        let p = match self.up_axis {
            UpAxis::Y => [x, y, z],
            UpAxis::Z => [x, z, -y],
        };
        match self.meters_per_unit {
            1.0 => p,
            _ => p.map(|v| v * self.scale()),
        }
    }

    /// How `hairtrace info` says what was applied.
    pub fn describe(self) -> String {
        let turn = match self.up_axis {
            UpAxis::Y => "+y up as hairtrace",
            UpAxis::Z => "Z-up, turned to +y up",
        };
        format!(
            "upAxis {}, metersPerUnit {} ({turn}, scaled by {} into metres)",
            self.up_axis.name(),
            self.meters_per_unit,
            self.meters_per_unit
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn z_up_turns_as_blender_exports_and_units_scale_into_metres() {
        let z = StageUnits::new(UpAxis::Z, 1.0).unwrap();
        // Blender's +z (up) is +y, its +y (back) is -z, its +x stays.
        assert_eq!(z.to_world([0.0, 0.0, 1.0]), [0.0, 1.0, 0.0]);
        assert_eq!(z.to_world([0.0, 1.0, 0.0]), [0.0, 0.0, -1.0]);
        assert_eq!(z.to_world([1.0, 0.0, 0.0]), [1.0, 0.0, 0.0]);
        let cm = StageUnits::new(UpAxis::Y, 0.01).unwrap();
        assert_eq!(cm.to_world([100.0, 0.0, -50.0]), [1.0, 0.0, -0.5]);
        assert_eq!(StageUnits::WORLD.to_world([1.5, 2.5, 3.5]), [1.5, 2.5, 3.5]);
    }

    #[test]
    fn bad_units_are_refused() {
        assert!(
            UpAxis::named("X")
                .unwrap_err()
                .to_string()
                .contains("upAxis \"X\"")
        );
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e-12] {
            let e = StageUnits::new(UpAxis::Y, bad).unwrap_err().to_string();
            assert!(e.contains("metersPerUnit"), "{e}");
        }
    }
}
