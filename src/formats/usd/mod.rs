//! USD grooms: every `BasisCurves` prim of a composed stage (.usda, .usdc or .usdz, read by
//! the pure-Rust `openusd` crate), each as its own curve geometry in world space, laid out
//! for Embree (see [`Layout`] for the basis and wrap conversions), turned and scaled from the
//! stage's `upAxis` and `metersPerUnit` into hairtrace's +y up metres ([`StageUnits`]); and,
//! read apart ([`Prims`]), its `Mesh` prims ([`UsdMesh`]) and `Camera` prims
//! ([`UsdCamera`]). See docs/formats.md for what is read, the primvar names and what is
//! refused.

mod camera;
mod crate_check;
mod layout;
mod mesh;
mod prim;
mod resolver;
mod text_arrays;
mod time;
mod write;

use std::fmt::Write as _;
use std::io::Read as _;
use std::path::Path;

use openusd::usd::{PrimPredicate, Stage};

use super::units::{StageUnits, UpAxis};
use crate::embree::{CurveBasis, CurveShape};
use crate::error::{Error, Result, invalid_arg};
use crate::scene::Strands;
use crate::scene::curves::{Curves, placed};
use crate::scene::framing::Framing;

pub use camera::UsdCamera;
pub use layout::{Interpolation, Layout, Wrap};
pub use mesh::UsdMesh;
use time::ReadAt;
pub use time::{Animation, Clock};
pub use write::{CurvesToWrite, ROOT_PRIM, write_usd_file};

/// Bytes a USD file may have: the reader keeps the whole stage in memory.
const MAX_FILE_BYTES: u64 = 1 << 32;

/// Which prims of a stage a read converts; the others it lists as ignored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Prims {
    Curves,
    Meshes,
    Cameras,
}

/// A stage's grooms (or meshes, or cameras: [`Prims`]) and what the reader made of the
/// rest.
#[derive(Debug, Clone, PartialEq)]
pub struct UsdGrooms {
    /// The stage's `upAxis` and `metersPerUnit` (USD's fallbacks, Y and 0.01, where not
    /// authored): every prim's curves are turned and scaled by them into the world.
    pub units: StageUnits,
    pub clock: Clock,
    pub curves: Vec<UsdCurves>,
    pub meshes: Vec<UsdMesh>,
    pub cameras: Vec<UsdCamera>,
    /// Paths and types of the prims that were not read (nor plain Xforms or Scopes).
    pub ignored: Vec<String>,
}

impl UsdGrooms {
    /// What of each prim read moves.
    fn animations(&self) -> impl Iterator<Item = &Animation> {
        (self.curves.iter().map(|c| &c.animation))
            .chain(self.meshes.iter().map(|m| &m.animation))
            .chain(self.cameras.iter().map(|c| &c.animation))
    }

    /// How many time codes strictly between `open` and `close` any prim's animated
    /// attributes have samples at.
    pub fn samples_between(&self, open: f64, close: f64) -> usize {
        let mut times: Vec<f64> = (self.animations())
            .flat_map(|a| a.times.iter().copied())
            .filter(|&t| open < t && t < close)
            .collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        times.len()
    }

    /// The animation's time codes: the stage's `startTimeCode` to `endTimeCode` where both
    /// are authored, else the span of the prims' samples; None for a still.
    pub fn time_range(&self) -> Option<(f64, f64)> {
        let animated = self.animations().any(|a| !a.attributes.is_empty());
        let span = (self.animations().filter_map(|a| a.span))
            .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)));
        match self.clock.authored_range {
            Some(range) if animated => Some(range),
            _ if animated => span,
            _ => None,
        }
    }
}

/// One BasisCurves prim, in world space.
#[derive(Debug, Clone, PartialEq)]
pub struct UsdCurves {
    pub path: String,
    pub animation: Animation,
    /// The stage's units: `control` and `bounds` are in them, [`UsdCurves::curves`] and
    /// [`UsdCurves::frame`] bring them into the world.
    pub units: StageUnits,
    pub layout: Layout,
    /// `curveVertexCounts` as authored.
    pub authored_counts: Vec<u32>,
    /// Segments of all curves.
    pub segments: usize,
    /// Bounds of the authored points under the prim's transform, in the stage's units.
    pub bounds: ([f32; 3], [f32; 3]),
    /// Smallest and largest radius the widths give (widths / 2 times the transform's
    /// scale), in the stage's units.
    pub radius_range: (f32, f32),
    /// Control points (x, y, z, radius) for Embree, curve after curve, under the prim's
    /// transform and in the stage's units.
    pub control: Vec<[f32; 4]>,
    /// Control points of each curve in `control`.
    pub control_counts: Vec<u32>,
    /// `primvars:displayColor` at every segment end (segments + 1 per curve), if authored.
    pub colors: Option<Vec<[f32; 3]>>,
    /// `primvars:displayColor` at every authored point, if authored with `constant`,
    /// `uniform` or `vertex` interpolation (what a `.hair` file holds per point).
    pub point_colors: Option<Vec<[f32; 3]>>,
    /// `primvars:melanin`: the eumelanin concentration of each curve, if authored.
    pub melanin: Option<Vec<f32>>,
    /// The curves' normals at every segment end (segments + 1 per curve), turned by the
    /// prim's transform, if authored (`read_normals` in `prim.rs` says which names).
    pub normals: Option<Vec<[f32; 3]>>,
}

impl UsdCurves {
    /// The Embree curves of this prim in the world, radii multiplied by `radius_scale` and
    /// every point mapped by `point` (a scene's placement of the groom). Colours and melanin
    /// go with the strands as authored: the material converts them at each hit.
    pub fn curves(
        &self,
        shape: CurveShape,
        radius_scale: f32,
        point: impl Fn([f32; 3]) -> [f32; 3],
    ) -> Result<Curves> {
        let units = self.units;
        let curves = Curves::from_control_points(
            placed(
                &self.control,
                |p| point(units.to_world(p)),
                radius_scale * units.scale(),
            ),
            &self.control_counts,
            self.colors.clone(),
            self.layout.basis,
            shape,
        );
        let curves = match &self.melanin {
            // The primvar is eumelanin alone.
            Some(m) => curves.and_then(|c| c.with_melanin(m.iter().map(|&e| [e, 0.0]).collect())),
            None => curves,
        };
        let curves = match &self.normals {
            // The placement is affine: its linear part turns a direction.
            Some(n) => curves.and_then(|c| {
                let origin = point(units.to_world([0.0; 3]));
                let turn = |v: [f32; 3]| {
                    let a = point(units.to_world(v));
                    std::array::from_fn(|k| a[k] - origin[k])
                };
                c.with_normals(n.iter().map(|&v| turn(v)).collect())
            }),
            None => curves,
        };
        curves.map_err(|e| e.context(&self.path))
    }

    pub fn basis(&self) -> CurveBasis {
        self.layout.basis
    }

    /// The prim's authored points and radii, curve after curve, under its transform and in
    /// the stage's units: the control points without the ones the wrap adds. Colours are
    /// the authored ones where they were given per point (else none).
    pub fn authored(&self) -> Strands {
        let lead = self.layout.lead();
        let mut s = Strands {
            colors: self.point_colors.clone(),
            ..Strands::default()
        };
        let mut start = 0;
        for (&m, &n) in self.control_counts.iter().zip(&self.authored_counts) {
            for p in &self.control[start + lead..start + lead + n as usize] {
                s.points.push([p[0], p[1], p[2]]);
                s.radii.push(p[3]);
            }
            s.counts.push(n);
            start += m as usize;
        }
        s
    }

    /// Adds the prim to `framing` as a scene frames it: the corners of its bounds in the
    /// world, mapped by `point`, each widened by its largest radius times `radius_scale`.
    pub fn frame(
        &self,
        framing: &mut Framing,
        radius_scale: f32,
        point: impl Fn([f32; 3]) -> [f32; 3],
    ) {
        let r = self.radius_range.1 * radius_scale * self.units.scale();
        for p in self.world_corners() {
            framing.add_hair_point(point(p).into(), r);
        }
    }

    /// The corners of the prim's bounds in the world (turned and scaled from the stage's
    /// units).
    fn world_corners(&self) -> impl Iterator<Item = [f32; 3]> + '_ {
        let (lo, hi) = self.bounds;
        (0..8).map(move |corner| {
            let p = std::array::from_fn(|k| if corner >> k & 1 == 1 { hi[k] } else { lo[k] });
            self.units.to_world(p)
        })
    }
}

/// Reads and composes the stage at `path` and converts each BasisCurves prim, each
/// attribute's default value (else its earliest sample). Errors name the file (and the prim
/// when one is at fault).
pub fn read_usd_file(path: &Path) -> Result<UsdGrooms> {
    read_usd_file_at(path, None)
}

/// [`read_usd_file`] at frame `frame` of the stage's animation (see `time`), or as a still
/// when None. A frame outside the animation's time range is refused; any frame of a stage
/// that has no time samples reads its one still.
pub fn read_usd_file_at(path: &Path, frame: Option<f64>) -> Result<UsdGrooms> {
    read_usd_prims_at(path, frame, Prims::Curves)
}

/// [`read_usd_file_at`] of the prims `prims` names.
pub fn read_usd_prims_at(path: &Path, frame: Option<f64>, prims: Prims) -> Result<UsdGrooms> {
    let grooms = read_usd_prims_near(path, frame, prims)?;
    if let (Some(f), Some((start, end))) = (frame, grooms.time_range()) {
        let t = grooms.clock.time_code(f);
        if !(start..=end).contains(&t) {
            return Err(invalid_arg!(
                "{}: frame {f} (time code {t}) is outside the animation: time codes {start} \
                 to {end}, frames {} to {}",
                path.display(),
                grooms.clock.frame(start),
                grooms.clock.frame(end)
            ));
        }
    }
    Ok(grooms)
}

/// [`read_usd_file_at`] at a frame that may lie outside the animation, where values hold
/// at its first or last samples: a time step of a shutter that opens before the first
/// frame or closes after the last.
pub fn read_usd_file_near(path: &Path, frame: Option<f64>) -> Result<UsdGrooms> {
    read_usd_prims_near(path, frame, Prims::Curves)
}

/// [`read_usd_file_near`] of the prims `prims` names.
pub fn read_usd_prims_near(path: &Path, frame: Option<f64>, prims: Prims) -> Result<UsdGrooms> {
    let at = |e: Error| e.context(path.display());
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.len() > MAX_FILE_BYTES {
        return Err(at(invalid_arg!(
            "{} bytes: larger than the {MAX_FILE_BYTES} this reader accepts",
            meta.len()
        )));
    }
    let name = path
        .to_str()
        .ok_or_else(|| at(invalid_arg!("the path is not valid UTF-8")))?;
    // Every layer passes the crate check on its way in (see `resolver`). openusd 0.6 still
    // indexes some tables of a corrupt .usdc without checking them, and panics: the panic
    // is caught here and becomes this file's error (the stage is dropped with it).
    let read = std::panic::catch_unwind(|| {
        // A text stage goes through the fast path for its arrays first; whatever that
        // cannot read cleanly is read again as openusd reads it, so that errors and panics
        // are openusd's own (and the fast path's panic, quiet, is not printed twice).
        let fast = if is_text_layer(path) {
            std::panic::catch_unwind(|| {
                let _quiet = crate::quiet_panic::Quiet::enter();
                read_lifting(name, meta.len(), frame, prims)
            })
            .unwrap_or(Ok(None))?
        } else {
            None
        };
        match fast {
            Some(grooms) => Ok(grooms),
            None => read_stage(
                &open(name, resolver::CheckingResolver::default())?,
                meta.len(),
                frame,
                prims,
            ),
        }
    });
    match read {
        Ok(result) => result.map_err(at),
        Err(panic) => {
            let why = (panic.downcast_ref::<String>().map(String::as_str))
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("no message");
            Err(at(invalid_arg!(
                "not a readable USD stage (the USD library failed: {why})"
            )))
        }
    }
}

/// Whether the file starts as a text layer does.
fn is_text_layer(path: &Path) -> bool {
    let mut head = [0; 5];
    let read = std::fs::File::open(path).and_then(|mut f| f.read_exact(&mut head));
    read.is_ok() && &head == b"#usda"
}

fn open(name: &str, resolver: resolver::CheckingResolver) -> Result<Stage> {
    Stage::builder()
        .resolver(resolver)
        .open(name)
        .map_err(|e| invalid_arg!("not a readable USD stage: {e:#}"))
}

/// The grooms with the numeric arrays of text layers lifted out before openusd parses
/// them and put back after (see `text_arrays`); `None` when anything went otherwise, an
/// error for a malformed tuple, which openusd would read without a word.
fn read_lifting(
    name: &str,
    file_bytes: u64,
    frame: Option<f64>,
    prims: Prims,
) -> Result<Option<UsdGrooms>> {
    let lifted = resolver::Lifted::default();
    let Ok(stage) = open(name, resolver::CheckingResolver::lifting(lifted.clone())) else {
        return Ok(None);
    };
    // Layers load as composition reaches them: a traversal reaches every one the
    // reader's own traversal will.
    if stage.traverse(PrimPredicate::DEFAULT, |_| {}).is_err() {
        return Ok(None);
    }
    let layers = std::mem::take(&mut *resolver::lock(&lifted));
    for (id, arrays) in &layers {
        let Some(mut layer) = stage.layer_mut(id) else {
            return Ok(None);
        };
        if text_arrays::restore(&mut layer, arrays)?.is_none() {
            return Ok(None);
        }
    }
    let grooms = read_stage(&stage, file_bytes, frame, prims).ok();
    // A text layer opened after the arrays were put back would hold placeholders.
    Ok(grooms.filter(|_| resolver::lock(&lifted).is_empty()))
}

/// The grooms of a composed stage, at `frame` or as a still. `file_bytes` bounds what any
/// count may ask for. Composition is lazy: its errors (cycles, missing layers) are known
/// once every prim has been visited.
fn read_stage(
    stage: &Stage,
    file_bytes: u64,
    frame: Option<f64>,
    prims: Prims,
) -> Result<UsdGrooms> {
    let units = stage_units(stage)?;
    let clock = Clock::of(stage)?;
    let (at, when) = match frame {
        None => (ReadAt::Still, String::new()),
        Some(f) => {
            let t = clock.time_code(f);
            (ReadAt::Code(t), format!(" at frame {f} (time code {t})"))
        }
    };
    let mut paths = Vec::new();
    stage
        .traverse(PrimPredicate::DEFAULT, |p| paths.push(p.clone()))
        .map_err(|e| invalid_arg!("traversal failed: {e:#}"))?;
    let (mut curves, mut meshes, mut cameras) = (Vec::new(), Vec::new(), Vec::new());
    let mut ignored = Vec::new();
    for p in &paths {
        let prim = stage.prim(p.clone());
        let kind = prim
            .type_name()
            .map_err(|e| invalid_arg!("{}: {e:#}", p.as_str()))?
            .map(|t| t.as_str().to_string())
            .unwrap_or_default();
        let named = |e: Error| e.context(format!("{}{when}", p.as_str()));
        match (kind.as_str(), prims) {
            ("BasisCurves", Prims::Curves) => curves.push(
                prim::read_basis_curves(stage, p, file_bytes, (units, &clock), at)
                    .map_err(named)?,
            ),
            ("Mesh", Prims::Meshes) => meshes
                .push(mesh::read_mesh(stage, p, file_bytes, (units, &clock), at).map_err(named)?),
            ("Camera", Prims::Cameras) => {
                cameras.push(camera::read_camera(stage, p, units, at).map_err(named)?)
            }
            ("" | "Xform" | "Scope", _) => {}
            (other, _) => ignored.push(format!("{} ({other})", p.as_str())),
        }
    }
    if let Some(e) = stage.composition_errors().first() {
        return Err(invalid_arg!("composition failed: {e}"));
    }
    Ok(UsdGrooms {
        units,
        clock,
        curves,
        meshes,
        cameras,
        ignored,
    })
}

/// The stage's `upAxis` and `metersPerUnit`, USD's fallback for each one not authored.
fn stage_units(stage: &Stage) -> Result<StageUnits> {
    let meta = |key: &str| stage.stage_metadata(key).ok().flatten();
    let fallback = StageUnits::USD_FALLBACK;
    let up_axis = match meta("upAxis") {
        None => fallback.up_axis,
        Some(v) => match v.clone().try_as_token() {
            Some(t) => UpAxis::named(t.as_str())?,
            None => return Err(invalid_arg!("upAxis is not a token: {v:?}")),
        },
    };
    let meters_per_unit = match meta("metersPerUnit") {
        None => fallback.meters_per_unit,
        Some(v) => (v.clone().try_as_double())
            .ok_or_else(|| invalid_arg!("metersPerUnit is not a number: {v:?}"))?,
    };
    StageUnits::new(up_axis, meters_per_unit)
}

/// Whether `path` names a USD file by its extension (.usd, .usda, .usdc, .usdz).
pub fn is_usd_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| ["usd", "usda", "usdc", "usdz"].contains(&e.to_ascii_lowercase().as_str()))
}

/// `hairtrace info` for a USD stage: per prim, curve, point and segment counts, world bounds
/// and radius range; then the stage's units and the prims that were ignored.
pub fn info_report(grooms: &UsdGrooms) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "stage:    {}", grooms.units.describe());
    let clock = &grooms.clock;
    match grooms.time_range() {
        Some((start, end)) => {
            let _ = writeln!(
                s,
                "time:     time codes {start} to {end} (frames {} to {}), {} time codes and {} \
                 frames per second",
                clock.frame(start),
                clock.frame(end),
                clock.codes_per_second,
                clock.frames_per_second
            );
        }
        None => {
            let _ = writeln!(s, "time:     a still (no attribute has two time samples)");
        }
    }
    for c in &grooms.curves {
        let (lo, hi) = c.world_corners().fold(
            ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
            |(lo, hi), p| {
                (
                    std::array::from_fn(|k| lo[k].min(p[k])),
                    std::array::from_fn(|k| hi[k].max(p[k])),
                )
            },
        );
        let _ = writeln!(
            s,
            "prim {} ({:?}, {:?})",
            c.path, c.layout.basis, c.layout.wrap
        );
        let _ = writeln!(s, "  strands:  {}", c.authored_counts.len());
        let points: u64 = c.authored_counts.iter().map(|&n| u64::from(n)).sum();
        let _ = writeln!(s, "  points:   {points}");
        let _ = writeln!(s, "  segments: {}", c.segments);
        let _ = writeln!(
            s,
            "  bounds:   min ({}, {}, {}), max ({}, {}, {})",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        );
        let scale = c.units.scale();
        let _ = writeln!(
            s,
            "  radius:   min {}, max {}",
            c.radius_range.0 * scale,
            c.radius_range.1 * scale
        );
        let _ = writeln!(
            s,
            "  colours:  {}",
            if c.colors.is_some() { "yes" } else { "no" }
        );
        if !c.animation.attributes.is_empty() {
            let _ = writeln!(s, "  animated: {}", c.animation.attributes.join(", "));
        }
    }
    if grooms.curves.is_empty() {
        let _ = writeln!(s, "no BasisCurves prims");
    }
    if !grooms.ignored.is_empty() {
        let _ = writeln!(s, "ignored:  {}", grooms.ignored.join(", "));
    }
    s
}
