//! What each entry of a description becomes: grooms read and converted into curves,
//! meshes read and placed, materials and lights checked, the camera placed
//! ([`crate::Scene::from_description`] drives them).

use std::path::{Path, PathBuf};

use glam::{Affine3A, EulerRot, Quat, Vec3};

use super::assembly::scene_options;
use super::{
    CameraDesc, EnvironmentSource, GroomDesc, GroomSource, GroomStrands, LightDesc, MaterialDesc,
    MeshDesc, MeshSource, PoseDesc, SceneDescription, StrandCurves, Transform,
};
use crate::bsdf::diffuse::Diffuse;
use crate::embree::CurveBasis;
use crate::error::{Error, Result, invalid_arg};
use crate::render::Aovs;
use crate::render::renderer::film_bytes_and_uniform;
use crate::render::settings::RenderSettings;
use crate::scene::GroomShape;
use crate::scene::Strands;
use crate::scene::camera::Camera;
use crate::scene::curves::{Curves, placed};
use crate::scene::envmap::Environment;
use crate::scene::footprint::{self, CurvesSize};
use crate::scene::framing::Framing;
use crate::scene::light::Light;
use crate::scene::material::{Material, check_kind};
use crate::scene::mesh::Mesh;
use crate::scene::shapes;
use crate::scene::stages::{Stage, StageRunner};
use crate::validate::{self, positive};

use crate::embree::MAX_TIME_STEPS;
use crate::farm::frame_path;
use crate::formats::hair::{HairTag, Thickness, read_hair_file, read_hair_tag};
use crate::formats::mesh::read_mesh_file;
use crate::formats::units::StageUnits;
use crate::formats::usd::{
    Layout, Prims, UsdGrooms, Wrap, is_usd_path, read_usd_file_at, read_usd_prims_at,
    read_usd_prims_near,
};

impl SceneDescription {
    /// Renders frame `frame` of the shot: every groom file is read at it (see
    /// [`GroomSource::File`]). Refused outside the `[animation]` table's `frames`; a USD
    /// stage refuses a frame outside its own animation when it is read.
    pub fn at_frame(&mut self, frame: f64) -> Result<()> {
        if !frame.is_finite() {
            return Err(invalid_arg!(
                "{}: frame {frame}: must be finite",
                self.origin
            ));
        }
        if let Some((first, last)) = self.frames
            && !(first as f64..=last as f64).contains(&frame)
        {
            return Err(invalid_arg!(
                "{}: frame {frame} is outside the shot's frames {first} to {last}",
                self.origin
            ));
        }
        for g in &mut self.grooms {
            if let GroomSource::File { frame: f, .. } = &mut g.source {
                *f = Some(frame);
            }
        }
        for m in &mut self.meshes {
            if let MeshSource::Usd { frame: f, .. } = &mut m.source {
                *f = Some(frame);
            }
        }
        if self.camera.usd.is_some() {
            self.camera.frame = Some(frame);
        }
        Ok(())
    }

    /// Refuses the description when its render's film, or its procedural grooms (whose
    /// sizes are known before anything is made) with the film, would need more than
    /// `available` bytes at their peak (see [`footprint`]); grooms from files are checked
    /// once read, before the BVH build. The film is counted without AOVs and as one in
    /// passes (the larger), as a render chooses those (and checks again).
    pub(crate) fn check_memory(&self, available: Option<u64>) -> Result<()> {
        let (film, uniform) = film_bytes_and_uniform(&self.render, Aovs::default(), true);
        footprint::check_film_fits(film, uniform, available)
            .map_err(|e| e.context(&self.origin))?;
        let options = scene_options(&self.render);
        let (mut sizes, mut conversion) = (Vec::new(), 0);
        for g in &self.grooms {
            let (strands, segments) = match &g.source {
                GroomSource::FurBall(f) => (f.strands, f.segments),
                GroomSource::Scalp(s) => (s.strands, s.segments),
                _ => continue,
            };
            let (strands, segments) = (strands as u64, u64::from(segments));
            let basis = g.strand_curves()?.basis();
            let size = CurvesSize::polylines(strands, segments, basis, g.shape.built(), &options);
            let points = strands.saturating_mul(segments + 1);
            conversion = conversion.max(footprint::conversion_bytes(points, strands, &size));
            sizes.push(size);
        }
        if sizes.is_empty() {
            return Ok(());
        }
        // The film comes after the build, beside what the build keeps (at most its peak).
        let needed = footprint::build_bytes(&sizes, &options)
            .saturating_add(film)
            .max(conversion);
        footprint::check_fits(&sizes, needed, "at their peak", available)
            .map_err(|e| e.context(&self.origin))
    }
}

impl MaterialDesc {
    /// Whether the material suits curves (`on_curves`: hair) or meshes (diffuse), without
    /// preparing it; `what` names it in the error.
    pub fn check_suits(&self, what: &str, on_curves: bool) -> Result<()> {
        check_kind(what, matches!(self, MaterialDesc::Hair(_)), on_curves)
    }

    /// The material, every value checked: a host that edits a scene checks an edit with
    /// it before there is a build to take it.
    pub fn prepare(&self) -> Result<Material> {
        Ok(match self {
            MaterialDesc::Hair(h) => Material::Hair(Box::new(h.prepare()?)),
            MaterialDesc::Diffuse { albedo } => {
                Material::Diffuse(Diffuse::new(Vec3::from_array(*albedo))?)
            }
        })
    }
}

impl Transform {
    /// The transform as an affine map and the factor radii follow, once every field is
    /// checked.
    fn affine(&self) -> Result<(Affine3A, f32)> {
        match *self {
            Transform::Trs {
                translate,
                rotate_deg,
                scale,
            } => {
                let finite = |what: &str, v: [f32; 3]| match v.iter().all(|x| x.is_finite()) {
                    true => Ok(()),
                    false => Err(invalid_arg!("{what} = {v:?}: must be finite")),
                };
                finite("translate", translate)?;
                finite("rotate", rotate_deg)?;
                positive("scale", scale)?;
                let [x, y, z] = rotate_deg.map(f32::to_radians);
                let turn = Quat::from_euler(EulerRot::ZYX, z, y, x);
                let affine = Affine3A::from_scale_rotation_translation(
                    Vec3::splat(scale),
                    turn,
                    Vec3::from_array(translate),
                );
                Ok((affine, scale))
            }
            Transform::Matrix(rows) => {
                if !rows.iter().flatten().all(|v| v.is_finite()) || rows[3] != [0.0, 0.0, 0.0, 1.0]
                {
                    return Err(invalid_arg!(
                        "matrix = {rows:?}: must be finite, its last row 0 0 0 1"
                    ));
                }
                let column = |j: usize| Vec3::new(rows[0][j], rows[1][j], rows[2][j]);
                let affine = Affine3A::from_cols(
                    column(0).into(),
                    column(1).into(),
                    column(2).into(),
                    column(3).into(),
                );
                let axes = [0, 1, 2].map(|j| column(j).as_dvec3().to_array());
                let scale = validate::uniform_scale(&format!("matrix = {rows:?}"), axes)?;
                Ok((affine, scale as f32))
            }
        }
    }
}

impl GroomDesc {
    /// A groom with the defaults of a `[[groom]]` entry: the source's own basis
    /// ([`GroomDesc::strand_curves`]), the default shape, no transform.
    pub fn new(source: GroomSource, material: &str) -> Self {
        GroomDesc {
            source,
            basis: None,
            shape: GroomShape::default(),
            radius_scale: 1.0,
            transform: Transform::default(),
            material: material.to_string(),
        }
    }

    /// The curve the groom's strands draw: the entry's basis through them as polylines;
    /// else what the source says (a `.hair` file's tag, B-spline for a procedural groom).
    /// A `.hair` file that says nothing, with no basis given, is refused: its points could
    /// be any curve's.
    pub fn strand_curves(&self) -> Result<StrandCurves> {
        let tag = match &self.source {
            GroomSource::File { path, frame, .. } if self.basis.is_none() && !is_usd_path(path) => {
                read_hair_tag(&frame_file(path, *frame)?)?
            }
            _ => None,
        };
        self.curves_with_tag(tag)
    }

    /// [`GroomDesc::strand_curves`], with the tag of a `.hair` source read already.
    fn curves_with_tag(&self, tag: Option<HairTag>) -> Result<StrandCurves> {
        if let Some(basis) = self.basis {
            return Ok(StrandCurves::Polylines(basis));
        }
        match &self.source {
            GroomSource::File { path, .. } if !is_usd_path(path) => {
                let tag = tag.ok_or_else(|| {
                    invalid_arg!(
                        "{}: a .hair file does not say which curve its points draw: give its \
                         basis (linear, bezier, bspline or catmull_rom)",
                        path.display()
                    )
                })?;
                Ok(match tag.layout {
                    l if l == Layout::of_polylines(l.basis) => StrandCurves::Polylines(l.basis),
                    l => StrandCurves::Authored(l),
                })
            }
            GroomSource::FurBall(_) | GroomSource::Scalp(_) | GroomSource::Strands(_) => {
                Ok(StrandCurves::Polylines(CurveBasis::BSpline))
            }
            GroomSource::File { path, .. } => Err(invalid_arg!(
                "{}: a USD groom draws each prim with its own basis",
                path.display()
            )),
            GroomSource::ControlPoints { basis, .. } => Ok(StrandCurves::Authored(Layout {
                basis: *basis,
                wrap: Wrap::Nonperiodic,
            })),
        }
    }

    /// The Embree curves of the groom, `part` = (index, grooms, files to read) of the
    /// build's stages: one geometry, or one per BasisCurves prim of a USD file (laid out by
    /// the prim's own basis and wrap, placed by the entry's transform). A USD file read at
    /// a frame, with `shutter` (open, close, in frames from it) open, gives curves in
    /// motion over it ([`usd_steps`]). Adds the groom, at every time step, to `framing`.
    pub(crate) fn curves(
        &self,
        stages: &mut StageRunner,
        (i, grooms, reads): (usize, usize, usize),
        framing: &mut Framing,
        shutter: Shutter,
    ) -> Result<Vec<Curves>> {
        let (affine, scale) = self.transform.affine()?;
        positive("radius_scale", self.radius_scale)?;
        let radius_factor = scale * self.radius_scale;
        let place = |p: [f32; 3]| affine.transform_point3(Vec3::from_array(p)).to_array();
        let shape = self.shape.built();
        match &self.source {
            GroomSource::File { path, frame, .. } if is_usd_path(path) => {
                let steps = stages.run(Stage::Read, (i, reads), |_| {
                    usd_steps(&frame_file(path, *frame)?, *frame, shutter, Prims::Curves)
                })?;
                for c in steps.iter().flat_map(|s| &s.curves) {
                    c.frame(framing, radius_factor, place);
                }
                stages.run(Stage::Curves, (i, grooms), |_| {
                    (0..steps[0].curves.len())
                        .map(|prim| {
                            let at = (steps.iter())
                                .map(|s| s.curves[prim].curves(shape, radius_factor, place))
                                .collect::<Result<Vec<_>>>()?;
                            in_motion(at).map_err(|e| e.context(&steps[0].curves[prim].path))
                        })
                        .collect()
                })
            }
            // Control points (a pbrt file's) were read with their file: there is only the
            // conversion to do.
            GroomSource::ControlPoints {
                points,
                counts,
                basis,
            } => {
                let curves = stages.run(Stage::Curves, (i, grooms), |_| {
                    Curves::from_control_points(
                        placed(points, place, radius_factor),
                        counts,
                        None,
                        *basis,
                        shape,
                    )
                })?;
                framing.add_control_points(curves.vertices());
                Ok(vec![curves])
            }
            _ => {
                // A file that is not USD, or a procedural groom, is one set of strands at
                // each time step (one step but for a `.hair` sequence blurred).
                let steps = stages.run(Stage::Read, (i, reads), |_| self.placed_steps(shutter))?;
                for step in &steps {
                    framing.add_strands(&step.strands);
                }
                let curves = stages.run(Stage::Curves, (i, grooms), |_| {
                    let at = (steps.iter())
                        .map(
                            |GroomStrands {
                                 strands, curves, ..
                             }| match *curves {
                                StrandCurves::Polylines(basis) => {
                                    Curves::from_strands(strands, basis, shape)
                                }
                                StrandCurves::Authored(layout) => {
                                    let (control, counts, colors) =
                                        layout.control_points(strands)?;
                                    Curves::from_control_points(
                                        control,
                                        &counts,
                                        colors,
                                        layout.basis,
                                        shape,
                                    )
                                }
                            },
                        )
                        .collect::<Result<Vec<_>>>()?;
                    in_motion(at)
                })?;
                Ok(vec![curves])
            }
        }
    }

    /// The groom's strands as its source authors them, with the curve each set draws and
    /// its units: one set for a `.hair` file (in the units its tag says) or a procedural
    /// groom, one per BasisCurves prim of a USD stage (its points under its own transform,
    /// in the stage's units).
    pub fn authored_strands(&self) -> Result<Vec<GroomStrands>> {
        let one = |strands| Ok(vec![self.strand_set(strands, None)?]);
        match &self.source {
            GroomSource::File { path, frame, .. } if is_usd_path(path) => {
                let file = read_usd_file_at(&frame_file(path, *frame)?, *frame)?;
                Ok((file.curves.iter())
                    .map(|c| GroomStrands {
                        prim: Some(c.path.clone()),
                        strands: c.authored(),
                        curves: StrandCurves::Authored(c.layout),
                        units: file.units,
                        normals: c.normals.clone(),
                    })
                    .collect())
            }
            GroomSource::File {
                path,
                thickness,
                frame,
            } => self.hair_steps(path, *thickness, *frame, Shutter::default()),
            GroomSource::FurBall(f) => one(f.build()?),
            GroomSource::Scalp(s) => one(s.build()?),
            GroomSource::Strands(s) => one(s.clone()),
            GroomSource::ControlPoints { .. } => Err(invalid_arg!(
                "a groom of control points (from a pbrt file) has no polyline strands"
            )),
        }
    }

    /// [`GroomDesc::authored_strands`] in the world: brought from their units, then placed
    /// by the entry's transform, radii scaled.
    pub fn placed_strands(&self) -> Result<Vec<GroomStrands>> {
        self.placed(self.authored_strands()?)
    }

    /// [`GroomDesc::placed_strands`] of a groom that is not USD at each time step of
    /// `shutter` (open, close, in frames from the frame): one set a step, more than one for
    /// a `.hair` sequence read at a frame with the shutter open ([`hair_sequence_steps`]).
    fn placed_steps(&self, shutter: Shutter) -> Result<Vec<GroomStrands>> {
        match &self.source {
            GroomSource::File {
                path,
                thickness,
                frame,
            } if !is_usd_path(path) => {
                self.placed(self.hair_steps(path, *thickness, *frame, shutter)?)
            }
            _ => self.placed_strands(),
        }
    }

    /// The strands of the `.hair` groom at `path` at each time step of `shutter`, with the
    /// curve they draw and the units of the frame's file.
    fn hair_steps(
        &self,
        path: &Path,
        thickness: Thickness,
        frame: Option<f64>,
        shutter: Shutter,
    ) -> Result<Vec<GroomStrands>> {
        let tag = read_hair_tag(&frame_file(path, frame)?)?;
        (hair_sequence_steps(path, thickness, frame, shutter)?.into_iter())
            .map(|strands| self.strand_set(strands, tag))
            .collect()
    }

    /// `strands` of this groom as one set, with the curve they draw and their units, from
    /// the tag of the `.hair` file they were read from, if any.
    fn strand_set(&self, strands: Strands, tag: Option<HairTag>) -> Result<GroomStrands> {
        Ok(GroomStrands {
            prim: None,
            strands,
            curves: self.curves_with_tag(tag)?,
            units: tag.map_or(StageUnits::WORLD, |t| t.units),
            normals: None,
        })
    }

    /// `sets` in the world: brought from their units, then placed by the entry's
    /// transform, radii scaled.
    fn placed(&self, mut sets: Vec<GroomStrands>) -> Result<Vec<GroomStrands>> {
        let (affine, scale) = self.transform.affine()?;
        positive("radius_scale", self.radius_scale)?;
        let placed = self.transform != Transform::default();
        for set in &mut sets {
            let units = std::mem::replace(&mut set.units, StageUnits::WORLD);
            if placed || units != StageUnits::WORLD {
                for p in &mut set.strands.points {
                    let world = Vec3::from_array(units.to_world(*p));
                    *p = affine.transform_point3(world).to_array();
                }
                // The turn and the placement are linear on directions.
                for n in set.normals.iter_mut().flatten() {
                    let world = Vec3::from_array(units.to_world(*n));
                    *n = affine.transform_vector3(world).to_array();
                }
            }
            let radius_factor = scale * self.radius_scale * units.scale();
            if radius_factor != 1.0 {
                for r in &mut set.strands.radii {
                    *r *= radius_factor;
                }
            }
        }
        Ok(sets)
    }
}

/// The `prims` of the USD stage at `path` at `frame`, or, with `shutter` open at a frame
/// of an animated stage, at the time steps of its motion: where the shutter opens, where
/// it closes and evenly between, as many as take in every time sample inside it (Embree's
/// steps are even), at most Embree's most. The steps may reach past the animation's first
/// or last frame, where its values hold.
fn usd_steps(
    path: &Path,
    frame: Option<f64>,
    shutter: Shutter,
    prims: Prims,
) -> Result<Vec<UsdGrooms>> {
    let still = read_usd_prims_at(path, frame, prims)?;
    let Some(f) = frame.filter(|_| shutter.is_open() && still.time_range().is_some()) else {
        return Ok(vec![still]);
    };
    let clock = still.clock;
    let code = |k, steps| clock.time_code(shutter_frame(f, shutter, k, steps));
    let count = shutter.steps(still.samples_between(code(0, 2), code(1, 2)));
    let mut still = Some(still);
    (0..count)
        .map(|k| {
            let at = shutter_frame(f, shutter, k, count);
            // A shutter that opens at the frame starts with the read already made.
            match still.take_if(|_| at == f) {
                Some(read) => Ok(read),
                None => read_usd_prims_near(path, Some(at), prims),
            }
        })
        .collect()
}

/// The frame of time step `k` of `steps` over `shutter` (open, close, in frames from
/// `frame`), spread evenly from the opening to the closing.
fn shutter_frame(frame: f64, Shutter { open, close, .. }: Shutter, k: usize, steps: usize) -> f64 {
    let (open, close) = (frame + f64::from(open), frame + f64::from(close));
    match steps {
        1 => open,
        _ => open + (close - open) * k as f64 / (steps - 1) as f64,
    }
}

/// The shutter a scene is read over: when it opens and closes, in frames from the frame,
/// and the fewest time steps an animated file gives a geometry over it when it is open
/// (the settings `shutter_open`, `shutter_close` and `motion_steps`). The default is closed:
/// one time step, at the frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Shutter {
    pub open: f32,
    pub close: f32,
    pub least_steps: usize,
}

impl Shutter {
    /// The shutter of a render with `settings`.
    pub fn of(settings: &RenderSettings) -> Shutter {
        Shutter {
            open: settings.shutter_open,
            close: settings.shutter_close,
            least_steps: settings.motion_steps as usize,
        }
    }

    fn is_open(self) -> bool {
        self.close > self.open
    }

    /// Time steps over the open shutter for a file with `inside` time samples (or whole
    /// frames) inside it: one at each end and evenly between, enough to take in every
    /// sample (Embree's steps are even), at least `least_steps`, at most Embree's most.
    fn steps(self, inside: usize) -> usize {
        (inside + 2).max(self.least_steps).min(MAX_TIME_STEPS)
    }
}

/// Curves made at each time step as one geometry: moving over the shutter when there is
/// more than one step.
fn in_motion(mut at: Vec<Curves>) -> Result<Curves> {
    match at.len() {
        1 => Ok(at.remove(0)),
        _ => Curves::in_motion(at),
    }
}

/// The strands of the `.hair` file at `path` read at `frame` ([`frame_file`]), or, for a
/// sequence of per-frame files read at a frame with `shutter` open, at the time steps of
/// its motion, chosen as [`usd_steps`] chooses a stage's with each file a time sample:
/// where the shutter opens, where it closes and evenly between, as many as take in every
/// whole frame inside. A step between two frames blends their files' points and radii
/// linearly, as USD interpolates its samples (colours are the earlier file's). Every file
/// a step reads must exist and hold the strands of the frame's file, point for point.
fn hair_sequence_steps(
    path: &Path,
    thickness: Thickness,
    frame: Option<f64>,
    shutter: Shutter,
) -> Result<Vec<Strands>> {
    let file = frame_file(path, frame)?;
    let still = read_hair_file(&file, thickness)?;
    let Some(f) = frame.filter(|_| shutter.is_open() && is_sequence(path)) else {
        return Ok(vec![still]);
    };
    let (open, close) = (f + f64::from(shutter.open), f + f64::from(shutter.close));
    let span = |e: Error| {
        e.context(format!(
            "the shutter of frame {f} spans frames {open} to {close}"
        ))
    };
    let count = shutter.steps((close.ceil() - open.floor() - 1.0).max(0.0) as usize);
    // Each file read once: the frame's, then those the steps reach.
    let mut files = vec![(f, file, still)];
    type Read = (f64, PathBuf, Strands);
    let read = |files: &mut Vec<Read>, n: f64| -> Result<usize> {
        if let Some(i) = files.iter().position(|(m, ..)| *m == n) {
            return Ok(i);
        }
        let file = frame_file(path, Some(n)).map_err(span)?;
        let strands = read_hair_file(&file, thickness)?;
        let (first, ours) = (&files[0], &strands);
        if ours.counts != first.2.counts {
            return Err(invalid_arg!(
                "{} ({} strands, {} points) and {} ({} strands, {} points) differ: the files \
                 a shutter spans hold the same strands, point for point",
                file.display(),
                ours.counts.len(),
                ours.points.len(),
                first.1.display(),
                first.2.counts.len(),
                first.2.points.len()
            ));
        }
        files.push((n, file, strands));
        Ok(files.len() - 1)
    };
    let mut steps = Vec::with_capacity(count);
    for k in 0..count {
        let at = open + (close - open) * k as f64 / (count - 1) as f64;
        let below = at.floor();
        let earlier = read(&mut files, below)?;
        let t = (at - below) as f32;
        if t == 0.0 {
            steps.push(files[earlier].2.clone());
            continue;
        }
        let later = read(&mut files, below + 1.0)?;
        steps.push(blend(&files[earlier].2, &files[later].2, t));
    }
    Ok(steps)
}

/// The strands `t` of the way from `a` to `b` (the same strands): points and radii
/// linearly between, the colours of `a`.
fn blend(a: &Strands, b: &Strands, t: f32) -> Strands {
    let lerp = |x: f32, y: f32| x + (y - x) * t;
    Strands {
        points: (a.points.iter().zip(&b.points))
            .map(|(p, q)| [0, 1, 2].map(|i| lerp(p[i], q[i])))
            .collect(),
        radii: (a.radii.iter().zip(&b.radii))
            .map(|(&r, &s)| lerp(r, s))
            .collect(),
        counts: a.counts.clone(),
        colors: a.colors.clone(),
    }
}

/// Whether `path` names a sequence of per-frame files: a run of # in its file name.
pub fn is_sequence(path: &Path) -> bool {
    path.file_name()
        .is_some_and(|n| n.to_string_lossy().contains('#'))
}

/// The file a groom reads at `frame`: `path` itself, or for a sequence of per-frame files
/// (a run of # in its file name) the file of that frame, which must exist.
fn frame_file(path: &Path, frame: Option<f64>) -> Result<PathBuf> {
    if !is_sequence(path) {
        return Ok(path.to_path_buf());
    }
    let at = |why: String| invalid_arg!("{}: {why}", path.display());
    let frame = frame.ok_or_else(|| {
        at(
            "a sequence of per-frame files: give the frame to render (`render --frame F`, \
            or `frame` in the scene's [animation] table)"
                .into(),
        )
    })?;
    if !(frame >= 0.0 && frame.fract() == 0.0 && frame <= f64::from(u32::MAX)) {
        return Err(at(format!(
            "frame {frame}: a sequence's files are numbered by whole frames >= 0"
        )));
    }
    let file = frame_path(path, frame as u32)?;
    if !file.is_file() {
        return Err(at(format!(
            "frame {frame}: {} does not exist (the sequence has no file for that frame)",
            file.display()
        )));
    }
    Ok(file)
}

impl MeshDesc {
    pub fn new(source: MeshSource, material: &str) -> Self {
        MeshDesc {
            source,
            transform: Transform::default(),
            material: material.to_string(),
        }
    }

    /// The mesh, transformed; a USD stage's every Mesh prim, deforming over `shutter`
    /// (open, close, in frames from its frame) where its points move.
    pub fn mesh(&self, shutter: Shutter) -> Result<Mesh> {
        let (affine, _) = self.transform.affine()?;
        let mut mesh = match &self.source {
            MeshSource::File(path) => read_mesh_file(path)?,
            MeshSource::Usd { path, frame } => usd_mesh(path, *frame, shutter)?,
            MeshSource::Sphere { centre, radius } => shapes::sphere(
                Vec3::from_array(*centre),
                *radius,
                shapes::SPHERE_SUBDIVISIONS,
            )?,
            MeshSource::Ground { y, half_size } => shapes::ground(*y, *half_size)?,
            MeshSource::Triangles(mesh) => {
                mesh.validate()?;
                mesh.clone()
            }
        };
        if self.transform != Transform::default() {
            let steps = std::iter::once(&mut mesh.positions).chain(&mut mesh.later_positions);
            for p in steps.flatten() {
                *p = affine.transform_point3(Vec3::from_array(*p)).to_array();
            }
            // The scale is uniform, so the linear part maps normals to normals.
            for n in mesh.normals.iter_mut().flatten() {
                *n = affine
                    .transform_vector3(Vec3::from_array(*n))
                    .normalize_or_zero()
                    .to_array();
            }
        }
        Ok(mesh)
    }
}

/// Every Mesh prim of the stage at `path` as one mesh (in the world, before the entry's
/// transform), read at `frame`, at the time steps of [`usd_steps`] over `shutter`: a mesh
/// that deforms has its points at each. Refused where a prim's faces or point count
/// change between two steps, naming the prim, the attribute and the step's frame.
fn usd_mesh(path: &Path, frame: Option<f64>, shutter: Shutter) -> Result<Mesh> {
    let steps = usd_steps(path, frame, shutter, Prims::Meshes)?;
    let first = &steps[0];
    if first.meshes.is_empty() {
        return Err(invalid_arg!("{}: no Mesh prims", path.display()));
    }
    let at = |e: crate::Error| e.context(path.display());
    let mut mesh = Mesh::default();
    for (m, prim) in first.meshes.iter().enumerate() {
        let base = u32::try_from(mesh.positions.len())
            .map_err(|_| at(invalid_arg!("more than 2^32 points in all")))?;
        mesh.positions.extend(prim.world_points(|p| p));
        (mesh.triangles).extend(prim.triangles.iter().map(|t| t.map(|v| v + base)));
        for (k, step) in steps.iter().enumerate().skip(1) {
            let later = &step.meshes[m];
            let when = || {
                let f = shutter_frame(frame.unwrap_or(0.0), shutter, k, steps.len());
                format!("{} at frame {f}", prim.path)
            };
            if later.points.len() != prim.points.len() {
                return Err(at(invalid_arg!(
                    "{}: points: {} points, {} at the shutter's opening: a mesh's points                      cannot change in number inside the shutter",
                    when(),
                    later.points.len(),
                    prim.points.len()
                )));
            }
            if later.triangles != prim.triangles {
                return Err(at(invalid_arg!(
                    "{}: faceVertexCounts or faceVertexIndices differ from the shutter's                      opening: a mesh's faces cannot change inside the shutter",
                    when()
                )));
            }
            if mesh.later_positions.len() < k {
                mesh.later_positions.push(Vec::new());
            }
            mesh.later_positions[k - 1].extend(later.world_points(|p| p));
        }
    }
    if mesh.later_positions.iter().all(|p| *p == mesh.positions) {
        mesh.later_positions.clear();
    }
    mesh.validate().map_err(at)?;
    Ok(mesh)
}

impl LightDesc {
    pub fn build(&self) -> Result<Light> {
        let v = Vec3::from_array;
        match self {
            LightDesc::Environment {
                source,
                rotation_deg,
                scale,
            } => {
                let env = match source {
                    EnvironmentSource::Uniform(radiance) => Environment::uniform(v(*radiance))?,
                    EnvironmentSource::Map(path) => Environment::from_file(path)?,
                    EnvironmentSource::LatLong { width, height, rgb } => {
                        Environment::from_pixels(*width, *height, 3, rgb)?
                    }
                };
                Ok(Light::Environment(
                    env.with_rotation(*rotation_deg)?.with_scale(*scale)?,
                ))
            }
            LightDesc::Distant {
                direction,
                irradiance,
                angular_radius_deg,
            } => Light::distant(v(*direction), v(*irradiance), *angular_radius_deg),
            LightDesc::Rect {
                corner,
                edge_u,
                edge_v,
                radiance,
                two_sided,
            } => Light::rect(v(*corner), v(*edge_u), v(*edge_v), v(*radiance), *two_sided),
        }
    }
}

impl CameraDesc {
    /// Checks a camera placed by `eye` and `target` (or given one of them alone), or read
    /// from a USD stage, before there is anything to frame; an automatic camera is checked
    /// when the build frames it.
    pub fn validate(&self) -> Result<()> {
        match (self.eye, self.target, &self.usd) {
            (None, None, None) => self.check_placed_if_moving(),
            _ => self
                .build(&Framing::default(), 1.0, Shutter::default())
                .map(|_| ()),
        }
    }

    /// An automatic camera does not move.
    fn check_placed_if_moving(&self) -> Result<()> {
        match (self.shutter_close, self.eye, self.target) {
            (Some(_), None, None) => Err(invalid_arg!(
                "shutter_close: an automatic camera does not move: give `eye` and `target`"
            )),
            _ => Ok(()),
        }
    }

    /// The camera for an image of `aspect`, framing `framing` when no eye and target are
    /// given, moving over `shutter` (open, close, in frames from the frame) when it is
    /// open and the camera has a pose at its closing (or a USD camera moves). The pose at
    /// the closing is checked whether the shutter is open or not.
    pub(crate) fn build(&self, framing: &Framing, aspect: f32, shutter: Shutter) -> Result<Camera> {
        if let Some(path) = &self.usd {
            return self.usd_camera(path, aspect, shutter);
        }
        self.check_placed_if_moving()?;
        let open = self.pose(framing, aspect, PoseDesc::default())?;
        let Some(close) = self.shutter_close else {
            return Ok(open);
        };
        let close = (self.pose(framing, aspect, close)).map_err(|e| e.context("shutter_close"))?;
        match shutter.is_open() {
            true => Camera::in_motion(vec![open, close]),
            false => Ok(open),
        }
    }

    /// The still camera of this table's pose with `over`'s keys in place of its own.
    fn pose(&self, framing: &Framing, aspect: f32, over: PoseDesc) -> Result<Camera> {
        let fov = over.fov_deg.unwrap_or(self.fov_deg);
        let (camera, target) = match (over.eye.or(self.eye), over.target.or(self.target)) {
            (Some(eye), Some(target)) => {
                let (eye, target) = (Vec3::from_array(eye), Vec3::from_array(target));
                let up = Vec3::from_array(over.up.unwrap_or(self.up));
                (Camera::new(eye, target, up, fov, aspect)?, target)
            }
            (None, None) => {
                let camera = framing.camera(aspect, fov).ok_or_else(|| {
                    invalid_arg!(
                        "nothing to frame (no groom and no mesh but ground quads): give                          `eye` and `target`"
                    )
                })??;
                let (lo, hi) = framing.bounds().expect("framed above");
                (camera, (lo + hi) / 2.0)
            }
            _ => {
                return Err(invalid_arg!(
                    "give both `eye` and `target`, or neither for an automatic camera"
                ));
            }
        };
        let focus = self
            .focus_distance
            .unwrap_or_else(|| camera.eye().distance(target));
        camera.with_thin_lens(self.aperture_radius, focus)
    }

    /// The UsdGeomCamera of the stage at `path` (the prim `prim`, else the only one), at
    /// the frame and over the shutter's time steps ([`usd_steps`]).
    fn usd_camera(&self, path: &Path, aspect: f32, shutter: Shutter) -> Result<Camera> {
        let defaults = CameraDesc::default();
        let alone = CameraDesc {
            usd: None,
            prim: None,
            frame: None,
            ..self.clone()
        };
        if alone != defaults {
            return Err(invalid_arg!(
                "usd: a camera read from a USD stage takes no other key but `prim`"
            ));
        }
        let at = |e: crate::Error| e.context(path.display());
        let steps = usd_steps(path, self.frame, shutter, Prims::Cameras)?;
        let cameras = &steps[0].cameras;
        let index = match &self.prim {
            Some(prim) => cameras
                .iter()
                .position(|c| c.path == *prim)
                .ok_or_else(|| at(invalid_arg!("no Camera prim at {prim}")))?,
            None if cameras.len() == 1 => 0,
            None => {
                let paths: Vec<&str> = cameras.iter().map(|c| c.path.as_str()).collect();
                return Err(at(invalid_arg!(
                    "{} Camera prims ({}): give the one to use as `prim`",
                    cameras.len(),
                    if paths.is_empty() {
                        "none".into()
                    } else {
                        paths.join(", ")
                    }
                )));
            }
        };
        let poses = (steps.iter().enumerate())
            .map(|(k, s)| {
                let c = &s.cameras[index];
                c.camera(aspect).map_err(|e| {
                    let f = shutter_frame(self.frame.unwrap_or(0.0), shutter, k, steps.len());
                    at(e.context(format!("{} at frame {f}", c.path)))
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Camera::in_motion(poses).map_err(at)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// A scalp of `strands` x 16 segments of `basis`, shape `shape`.
    fn scalp(strands: usize, basis: &str, shape: &str) -> SceneDescription {
        let text = format!(
            "[materials.h]\ntype = \"hair\"\nmelanin = [0.5, 0]\n[[groom]]\nprocedural = \"scalp\"\nmaterial = \"h\"\n\
             basis = \"{basis}\"\nshape = \"{shape}\"\n[groom.params]\nstrands = {strands}\n\
             segments = 16\n[[light]]\ntype = \"environment\"\nradiance = [1, 1, 1]\n"
        );
        SceneDescription::from_toml(&text, Path::new("."), "scalp.toml").unwrap()
    }

    const GIB: u64 = 1 << 30;

    #[test]
    fn a_groom_past_the_available_memory_is_refused_with_its_size() {
        let big = scalp(10_000_000, "catmull_rom", "round");
        let e = big.check_memory(Some(4 * GIB)).unwrap_err();
        let message = e.to_string();
        for part in [
            "scalp.toml",
            "10000000 strands x 16 segments, catmull_rom round",
            "4.0 GiB are available",
        ] {
            assert!(message.contains(part), "{message:?} lacks {part:?}");
        }
        // The figure it names is the estimate's.
        let options = scene_options(&big.render);
        let needed = footprint::build_bytes(
            &[CurvesSize::polylines(
                10_000_000,
                16,
                CurveBasis::CatmullRom,
                crate::embree::CurveShape::Round,
                &options,
            )],
            &options,
        );
        let gib = format!("{:.1} GiB of memory", needed as f64 / GIB as f64);
        assert!(message.contains(&gib), "{message:?} lacks {gib:?}");
        // The same groom fits where there is room, and so does a small one here.
        big.check_memory(Some(needed + GIB)).unwrap();
        scalp(1000, "catmull_rom", "round")
            .check_memory(Some(4 * GIB))
            .unwrap();
        // Without a figure for the available memory, nothing is refused.
        big.check_memory(None).unwrap();
    }

    #[test]
    fn a_film_past_the_available_memory_is_refused_before_the_build() {
        let mut big = scalp(1000, "catmull_rom", "round");
        (big.render.width, big.render.height) = (32768, 32768);
        let message = big.check_memory(Some(4 * GIB)).unwrap_err().to_string();
        for part in [
            "scalp.toml",
            // 32768^2 pixels of the noise allocation's sums and pilot (the layout
            // `Keep::bytes_per_pixel` gives, which `a_film_keeps_only_what_its_render_reads`
            // pins).
            "film needs about 114688 MiB",
            "4096 MiB are available",
        ] {
            assert!(message.contains(part), "{message:?} lacks {part:?}");
        }
        // Sampled uniformly, the sums alone (40 bytes a pixel) do not fit either: not offered.
        assert!(!message.contains("allocation = uniform"), "{message}");
        // Where they fit, the refusal offers them.
        let message = big.check_memory(Some(48 * GIB)).unwrap_err().to_string();
        let offer = "or sample uniformly (allocation = uniform: about 40960 MiB)";
        assert!(message.contains(offer), "{message:?} lacks {offer:?}");
        big.render.allocation = crate::render::settings::Allocation::Uniform;
        big.check_memory(Some(48 * GIB)).unwrap();
        big.render.allocation = crate::render::settings::Allocation::Noise;
        // A crop of the frame keeps a film of its own pixels only.
        big.render.crop = Some([0, 0, 1024, 1024]);
        big.check_memory(Some(4 * GIB)).unwrap();
    }

    #[test]
    fn the_estimate_grows_with_the_basis_and_not_with_the_copies() {
        let at = |basis, shape| {
            scalp(10_000_000, basis, shape)
                .check_memory(Some(GIB))
                .unwrap_err()
                .to_string()
        };
        let gib = |m: String| -> f64 {
            let i = m.find(" GiB of memory").unwrap();
            let start = m[..i].rfind(' ').unwrap() + 1;
            m[start..i].parse().unwrap()
        };
        let linear = gib(at("linear", "round"));
        let cubic = gib(at("catmull_rom", "round"));
        let bezier = gib(at("bezier", "round"));
        assert!(
            linear < cubic && cubic < bezier,
            "{linear} {cubic} {bezier}"
        );
        assert!(at("bspline", "auto").contains("bspline round"));
        // The copies into spatial order and into an `auto` groom's parts come after the
        // polylines are freed, below the BVH build's peak: they add nothing.
        assert_eq!(gib(at("bspline", "auto")), gib(at("bspline", "round")));
    }
}
