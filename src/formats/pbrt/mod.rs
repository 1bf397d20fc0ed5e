//! A subset of pbrt-v4's scene format, enough for pbrt's hair scenes, read into a
//! [`SceneDescription`]. The subset and the warning rule are listed in `docs/pbrt.md`; in
//! short:
//!
//! - **Read**: Camera "perspective" (fov, lensradius, focaldistance, shutter), Film
//!   (xresolution, yresolution, filename, iso), Sampler's pixelsamples, Integrator's
//!   maxdepth, LookAt, Transform, ConcatTransform, Translate, Rotate, Scale, Identity,
//!   CoordinateSystem, CoordSysTransform, AttributeBegin/End, TransformBegin/End,
//!   Include/Import (gzipped too), WorldBegin, LightSource "infinite" (rgb L, or an
//!   equal-area image resampled to lat-long) and "distant", Shape "curve",
//!   "trianglemesh", "plymesh" and "sphere", Material / MakeNamedMaterial "hair" and
//!   "diffuse", NamedMaterial.
//! - **Warned and ignored** (each warning names the file and line): statements and
//!   parameters that hairtrace replaces by its own (PixelFilter, the sampler and
//!   integrator beyond the two values read) or that do not apply to it, and texture
//!   references, which get pbrt's default value.
//! - **Refused** with an error naming the file and line: whatever would leave the image
//!   wrong or incomplete: other shapes, lights and cameras, a shape whose material is not
//!   hair (curves) or diffuse (meshes), area lights, instancing, non-RGB spectra, and
//!   malformed input.
//!
//! Curves are gathered into one groom per (material, shape, basis), whatever the number of
//! Shape statements. pbrt's camera is left-handed; the scene is mirrored through x = 0
//! when needed so that the image is pbrt's (see `reader.rs`).

mod envmap;
mod lexer;
mod materials;
mod params;
mod reader;
mod shapes;

use std::fmt::Write;
use std::path::{Path, PathBuf};

use crate::description::{EnvironmentSource, GroomSource, LightDesc, MeshSource, SceneDescription};
use crate::error::Result;
use reader::Reader;

/// A pbrt scene as hairtrace reads it.
#[derive(Debug, Clone, PartialEq)]
pub struct PbrtScene {
    pub description: SceneDescription,
    /// What was ignored or approximated, one line each, `file:line: statement: why`;
    /// repeats of one message are counted on its first line.
    pub warnings: Vec<String>,
    /// Film's `filename`, if given. The CLI writes to its `-o` instead.
    pub film_filename: Option<PathBuf>,
}

impl PbrtScene {
    /// Reads a `.pbrt` file and the files it includes.
    pub fn from_file(path: &Path) -> Result<Self> {
        let mut reader = Reader::new();
        reader.read_file(path)?;
        Self::finish(reader, &path.display().to_string())
    }

    /// Reads pbrt text; includes and PLY files are looked for in `dir`, and `origin`
    /// names the text in messages.
    pub fn from_text(text: &str, dir: &Path, origin: &str) -> Result<Self> {
        let mut reader = Reader::new();
        reader.read_text(text, dir, origin)?;
        Self::finish(reader, origin)
    }

    fn finish(mut reader: Reader, origin: &str) -> Result<Self> {
        let warnings = count_repeats(std::mem::take(&mut reader.warnings));
        let film_filename = reader.film_filename.take();
        Ok(PbrtScene {
            description: reader.finish(origin)?,
            warnings,
            film_filename,
        })
    }

    /// What `hairtrace info` prints: per groom its strands, points, segments, bounds and
    /// radius range; meshes, lights, the camera and the film; then the warnings.
    pub fn info_report(&self) -> String {
        let d = &self.description;
        let mut s = String::new();
        for (i, g) in d.grooms.iter().enumerate() {
            let GroomSource::ControlPoints {
                points,
                counts,
                basis,
            } = &g.source
            else {
                continue;
            };
            let segments: usize = counts
                .iter()
                .filter_map(|&n| basis.segments_for(n as usize))
                .sum();
            let (lo, hi) = points.iter().fold(
                ([f32::INFINITY; 4], [f32::NEG_INFINITY; 4]),
                |(lo, hi), p| {
                    (
                        std::array::from_fn(|c| lo[c].min(p[c])),
                        std::array::from_fn(|c| hi[c].max(p[c])),
                    )
                },
            );
            let _ = writeln!(
                s,
                "groom[{i}]: material {:?}, {:?} {:?} curves: {} strands, {} control points, \
                 {segments} segments",
                g.material,
                g.shape,
                basis,
                counts.len(),
                points.len()
            );
            let _ = writeln!(
                s,
                "  bounds min ({}, {}, {}), max ({}, {}, {}); radius {} to {}",
                lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], lo[3], hi[3]
            );
        }
        for (i, m) in d.meshes.iter().enumerate() {
            if let MeshSource::Triangles(mesh) = &m.source {
                let _ = writeln!(
                    s,
                    "mesh[{i}]: material {:?}: {} triangles, {} vertices",
                    m.material,
                    mesh.triangles.len(),
                    mesh.positions.len()
                );
            }
        }
        for (i, l) in d.lights.iter().enumerate() {
            let _ = match l {
                LightDesc::Environment {
                    source: EnvironmentSource::LatLong { width, height, .. },
                    scale,
                    ..
                } => writeln!(
                    s,
                    "light[{i}]: environment map resampled to {width} x {height} lat-long, \
                     scale {scale}"
                ),
                other => writeln!(s, "light[{i}]: {other:?}"),
            };
        }
        let c = &d.camera;
        let _ = writeln!(
            s,
            "camera: eye {:?}, target {:?}, up {:?}, vertical fov {} deg",
            c.eye.unwrap_or_default(),
            c.target.unwrap_or_default(),
            c.up,
            c.fov_deg
        );
        let _ = writeln!(
            s,
            "film: {} x {}, {} spp, max depth {}",
            d.render.width, d.render.height, d.render.spp, d.render.path.max_depth
        );
        for w in &self.warnings {
            let _ = writeln!(s, "warning: {w}");
        }
        s
    }
}

/// `loc: text` lines, a repeated text kept once at its first place with its count.
fn count_repeats(warnings: Vec<(String, String)>) -> Vec<String> {
    let mut order: Vec<(String, String, usize)> = Vec::new();
    let mut index: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for (loc, text) in warnings {
        match index.get(&text) {
            Some(&i) => order[i].2 += 1,
            None => {
                index.insert(text.clone(), order.len());
                order.push((loc, text, 0));
            }
        }
    }
    order
        .into_iter()
        .map(|(loc, text, more)| match more {
            0 => format!("{loc}: {text}"),
            n => format!("{loc}: {text} (and {n} more like it)"),
        })
        .collect()
}
