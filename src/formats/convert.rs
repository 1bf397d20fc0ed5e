//! `hairtrace convert`: grooms between Cem Yuksel's `.hair` and USD BasisCurves, so that a
//! procedural groom can go to a DCC and come back (docs/formats.md, "Converting").
//!
//! Nothing is lost either way. A `.hair` file that this module writes carries, in its
//! header's text ([`HairTag`]), the USD layout its points are the authored points of and the
//! stage's up axis and unit; so a USD prim of any basis and wrap goes to `.hair` and back
//! to the bit, and a tagged `.hair` file goes to USD as what it says. An untagged `.hair`
//! file holds polylines and says nothing of the curve drawn through them: its reader must
//! name a basis (`--basis`), and the stage gets the layout that draws hairtrace's curve of
//! that basis through them ([`Layout::of_polylines`]).
//!
//! Several prims go into one `.hair` file only when they share their layout and units;
//! `--basis linear` samples cubic curves into polylines of
//! [`ConvertOptions::samples_per_segment`] segments per curve segment, the one lossy way,
//! which a note names.

use std::path::Path;

use super::hair::{HairTag, Thickness, write_tagged_hair_file};
use super::units::StageUnits;
use super::usd::{CurvesToWrite, Layout, UsdCurves, is_usd_path, read_usd_file, write_usd_file};
use crate::description::{
    GroomDesc, GroomSource, GroomStrands, SceneDescription, StrandCurves, demo, has_extension,
};
use crate::embree::CurveBasis;
use crate::error::{Error, Result, invalid_arg};
use crate::scene::Strands;

/// Where the grooms come from.
#[derive(Debug, Clone, Copy)]
pub enum ConvertSource<'a> {
    /// A `.hair` file, a USD file or a scene file (`.toml`, its grooms in world space).
    File(&'a Path),
    /// A built-in scene (see [`DEMOS`](crate::description::DEMOS)): its procedural groom.
    Demo(&'a str),
}

/// How `.hair` files are read and written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConvertOptions {
    /// The basis drawn through a `.hair` file's points: needed for a file that does not say
    /// its own. For a USD input, `linear` samples cubic curves into polylines; another basis
    /// must be the prims' own.
    pub basis: Option<CurveBasis>,
    pub thickness: Thickness,
    /// Polyline segments per curve segment when a cubic USD curve is written as linear
    /// `.hair` strands (the sampled points lie on the curve); at least 1.
    pub samples_per_segment: u32,
}

/// The default of [`ConvertOptions::samples_per_segment`]: chords within about 1/500 of a
/// segment's length of the curve for hair-like bends.
const SAMPLES_PER_SEGMENT: u32 = 8;

impl Default for ConvertOptions {
    fn default() -> Self {
        ConvertOptions {
            basis: None,
            thickness: Thickness::Diameter,
            samples_per_segment: SAMPLES_PER_SEGMENT,
        }
    }
}

/// What a conversion wrote, and what it had to say about it.
#[derive(Debug, Clone, PartialEq)]
pub struct Converted {
    /// BasisCurves prims written (USD) or read (into a `.hair` file).
    pub prims: usize,
    pub strands: usize,
    pub points: usize,
    /// Lines for the user: curves sampled, primvars a `.hair` file cannot hold.
    pub notes: Vec<String>,
}

/// A groom on its way: its points, the curve they draw and their units, named for the
/// stage.
struct Groom {
    name: String,
    set: GroomStrands,
}

/// Converts the grooms of `source` into `output`, whose extension picks the format: `.hair`
/// or `.usda` (USD text; crate files are refused, see [`write_usd_file`]). Errors name the
/// file at fault.
pub fn convert(source: ConvertSource, output: &Path, opts: &ConvertOptions) -> Result<Converted> {
    if opts.samples_per_segment == 0 {
        return Err(invalid_arg!("samples per segment: must be at least 1"));
    }
    let to_usd = is_usd_path(output);
    if !to_usd && !has_extension(output, "hair") {
        return Err(invalid_arg!(
            "{}: unknown output extension: give .hair or .usda",
            output.display()
        ));
    }
    if to_usd && !has_extension(output, "usda") {
        return Err(invalid_arg!(
            "{}: write .usda: Pixar's USD library cannot read the crate files (.usdc, .usd, \
             .usdz) that openusd 0.6 writes; Pixar's `usdcat` turns a .usda into one",
            output.display()
        ));
    }
    let folder = output.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(dir) = folder.filter(|d| !d.is_dir()) {
        return Err(invalid_arg!(
            "{}: the folder {} does not exist",
            output.display(),
            dir.display()
        ));
    }
    let mut notes = Vec::new();
    let grooms = read_grooms(source, output, opts, &mut notes)?;
    let mut converted = Converted {
        prims: grooms.len(),
        strands: grooms.iter().map(|g| g.set.strands.strand_count()).sum(),
        points: grooms.iter().map(|g| g.set.strands.point_count()).sum(),
        notes,
    };
    let units = shared_units(&grooms)?;
    if to_usd {
        let prims = grooms
            .iter()
            .map(curves_to_write)
            .collect::<Result<Vec<_>>>()?;
        write_usd_file(output, &prims, &units)?;
    } else {
        let (strands, layout) = joined(grooms, &mut converted.notes)?;
        let tag = HairTag { layout, units };
        write_tagged_hair_file(output, &strands, opts.thickness, Some(&tag))?;
    }
    Ok(converted)
}

/// The grooms `source` holds, read for `output` (a USD input is for a `.hair` output and the
/// other way round).
fn read_grooms(
    source: ConvertSource,
    output: &Path,
    opts: &ConvertOptions,
    notes: &mut Vec<String>,
) -> Result<Vec<Groom>> {
    Ok(match source {
        ConvertSource::Demo(name) => scene_grooms(&demo(name)?)?,
        ConvertSource::File(path) => {
            std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
            if is_usd_path(path) {
                if is_usd_path(output) {
                    return Err(invalid_arg!(
                        "{} and {} are both USD: nothing to convert",
                        path.display(),
                        output.display()
                    ));
                }
                let stage = read_usd_file(path)?;
                (stage.curves.iter())
                    .map(|c| usd_groom(c, opts, notes))
                    .collect::<Result<_>>()
                    .map_err(|e| e.context(path.display()))?
            } else if has_extension(path, "hair") {
                if !is_usd_path(output) {
                    return Err(invalid_arg!(
                        "{} and {} are both .hair: nothing to convert",
                        path.display(),
                        output.display()
                    ));
                }
                let file = GroomSource::File {
                    path: path.to_path_buf(),
                    thickness: opts.thickness,
                    frame: None,
                };
                let groom = GroomDesc {
                    basis: opts.basis,
                    ..GroomDesc::new(file, "")
                };
                (groom.authored_strands()?.into_iter())
                    .map(|set| Groom {
                        name: "groom0".into(),
                        set,
                    })
                    .collect()
            } else if has_extension(path, "toml") {
                scene_grooms(&SceneDescription::from_file(path)?)?
            } else {
                return Err(invalid_arg!(
                    "{}: unknown input extension: give .hair, a USD file (.usda, .usdc, .usd, \
                     .usdz) or a scene file (.toml)",
                    path.display()
                ));
            }
        }
    })
}

/// The strand grooms of a scene, placed in the world, each with its curve.
fn scene_grooms(scene: &SceneDescription) -> Result<Vec<Groom>> {
    let mut grooms = Vec::new();
    for (i, g) in scene.grooms.iter().enumerate() {
        let sets = (g.placed_strands())
            .map_err(|e| e.context(format_args!("{}: groom[{i}]", scene.origin)))?;
        let many = sets.len() > 1;
        for (k, set) in sets.into_iter().enumerate() {
            let name = match many {
                true => format!("groom{i}_{k}"),
                false => format!("groom{i}"),
            };
            grooms.push(Groom { name, set });
        }
    }
    Ok(grooms)
}

/// The units every groom is in: a file holds one stage's.
fn shared_units(grooms: &[Groom]) -> Result<StageUnits> {
    let units = grooms.first().map_or(StageUnits::WORLD, |g| g.set.units);
    match grooms.iter().find(|g| g.set.units != units) {
        Some(g) => Err(invalid_arg!(
            "{}: in {} where the first groom is in {}: one file holds one stage's units",
            g.name,
            g.set.units.describe(),
            units.describe()
        )),
        None => Ok(units),
    }
}

fn curves_to_write(g: &Groom) -> Result<CurvesToWrite> {
    let s = &g.set.strands;
    s.validate().map_err(|e| e.context(&g.name))?;
    let widths: Vec<f32> = s.radii.iter().map(|r| r * 2.0).collect();
    if let Some(i) = widths.iter().position(|w| !w.is_finite()) {
        return Err(invalid_arg!(
            "{}: radius {i} = {}: its diameter is not a finite f32",
            g.name,
            s.radii[i]
        ));
    }
    Ok(CurvesToWrite {
        name: g.name.clone(),
        layout: g.set.curves.layout(),
        points: s.points.clone(),
        counts: s.counts.clone(),
        widths,
        colors: s.colors.clone(),
    })
}

/// All grooms as one `.hair` groom, when they share one layout, and that layout.
/// When only some have colours, none are written (a note says so).
fn joined(grooms: Vec<Groom>, notes: &mut Vec<String>) -> Result<(Strands, Layout)> {
    let coloured = grooms
        .iter()
        .filter(|g| g.set.strands.colors.is_some())
        .count();
    if coloured != 0 && coloured != grooms.len() {
        notes.push(format!(
            "colours not written: {coloured} of {} grooms have them, and a .hair file has a \
             colour for every point or for none",
            grooms.len()
        ));
    }
    let layout = grooms
        .first()
        .map_or(Layout::of_polylines(CurveBasis::Linear), |g| {
            g.set.curves.layout()
        });
    let mut all = Strands {
        colors: (coloured == grooms.len() && coloured != 0).then(Vec::new),
        ..Strands::default()
    };
    for g in grooms {
        let own = g.set.curves.layout();
        if own != layout {
            let (kind, basis, wrap) = own.tokens();
            let (first_kind, first_basis, first_wrap) = layout.tokens();
            return Err(invalid_arg!(
                "{}: its curves are {kind} {basis} {wrap}, the first groom's {first_kind} \
                 {first_basis} {first_wrap}: a .hair file holds one layout (convert each \
                 alone, or sample all with --basis linear)",
                g.name
            ));
        }
        all.points.extend(g.set.strands.points);
        all.radii.extend(g.set.strands.radii);
        all.counts.extend(g.set.strands.counts);
        if let (Some(out), Some(c)) = (&mut all.colors, g.set.strands.colors) {
            out.extend(c);
        }
    }
    Ok((all, layout))
}

/// Names of the bases, as `--basis` and a `[[groom]]`'s `basis` spell them.
const BASIS_NAMES: [(&str, CurveBasis); 4] = [
    ("linear", CurveBasis::Linear),
    ("bezier", CurveBasis::Bezier),
    ("bspline", CurveBasis::BSpline),
    ("catmull_rom", CurveBasis::CatmullRom),
];

/// The basis called `name` (linear, bezier, bspline, catmull_rom).
pub fn basis_named(name: &str) -> Result<CurveBasis> {
    (BASIS_NAMES.iter().find(|(n, _)| *n == name))
        .map(|&(_, b)| b)
        .ok_or_else(|| {
            invalid_arg!("unknown basis {name:?} (linear, bezier, bspline, catmull_rom)")
        })
}

/// One USD prim for a `.hair` file: its authored points as they are (in the stage's units),
/// or, with `--basis linear`, its curves sampled into polylines. Another basis must be the
/// prim's own.
fn usd_groom(c: &UsdCurves, opts: &ConvertOptions, notes: &mut Vec<String>) -> Result<Groom> {
    let layout = c.layout;
    for (lost, what) in [
        (
            c.melanin.is_some(),
            "primvars:melanin is not written: a .hair file has no melanin",
        ),
        (
            c.normals.is_some(),
            "curve normals are not written: a .hair file has none",
        ),
    ] {
        if lost {
            notes.push(format!("{}: {what}", c.path));
        }
    }
    let linear = Layout::of_polylines(CurveBasis::Linear);
    let sample = opts.basis == Some(CurveBasis::Linear) && layout != linear;
    if let Some(basis) = opts.basis.filter(|_| !sample) {
        if Layout::of_polylines(basis).basis != layout.basis {
            let (kind, name, wrap) = layout.tokens();
            return Err(invalid_arg!(
                "{}: its curves are {kind} {name} {wrap}, not {basis:?}: leave --basis out to \
                 keep them as they are, or sample them with --basis linear",
                c.path
            ));
        }
    }
    let named = |strands, curves| Groom {
        name: c.path.clone(),
        set: GroomStrands {
            prim: Some(c.path.clone()),
            strands,
            curves,
            units: c.units,
            normals: None,
        },
    };
    if !sample {
        return Ok(named(c.authored(), StrandCurves::Authored(layout)));
    }
    notes.push(match layout.basis {
        CurveBasis::Linear => format!("{}: closed polylines written open", c.path),
        _ => format!(
            "{}: {:?} {:?} curves sampled into polylines, {} segments per curve segment",
            c.path, layout.basis, layout.wrap, opts.samples_per_segment
        ),
    });
    let mut s = Strands {
        colors: c.colors.as_ref().map(|_| Vec::new()),
        ..Strands::default()
    };
    let (mut start, mut ends_start) = (0, 0);
    for &m in &c.control_counts {
        let ctl = &c.control[start..start + m as usize];
        let segments = layout.basis.segments_for(ctl.len()).unwrap_or(0);
        let ends = c
            .colors
            .as_ref()
            .map(|e| &e[ends_start..ends_start + segments + 1]);
        let before = s.points.len();
        if layout.basis == CurveBasis::Linear {
            // A closed polyline: its control points repeat the first at the end.
            for p in ctl {
                s.points.push([p[0], p[1], p[2]]);
                s.radii.push(p[3]);
            }
            if let (Some(out), Some(e)) = (&mut s.colors, ends) {
                out.extend_from_slice(e);
            }
        } else {
            sample_curve(
                layout.basis,
                ctl,
                segments,
                opts.samples_per_segment,
                ends,
                &mut s,
            );
        }
        s.counts.push((s.points.len() - before) as u32);
        start += m as usize;
        ends_start += segments + 1;
    }
    Ok(named(s, StrandCurves::Polylines(CurveBasis::Linear)))
}

/// Appends one cubic curve of Embree control points `ctl` to `out` as a polyline through
/// the curve at `steps` steps per segment; colours (given at segment ends) are blended
/// linearly, as the renderer blends them. A radius the basis takes to <= 0 (a
/// Catmull-Rom overshoot) becomes the segment's smallest control radius.
fn sample_curve(
    basis: CurveBasis,
    ctl: &[[f32; 4]],
    segments: usize,
    steps: u32,
    ends: Option<&[[f32; 3]]>,
    out: &mut Strands,
) {
    let steps = steps as usize;
    let stride = basis.segment_stride();
    for seg in 0..segments {
        let cp = &ctl[seg * stride..seg * stride + 4];
        let last = seg + 1 == segments;
        for k in 0..steps + usize::from(last) {
            let t = k as f64 / steps as f64;
            let w = basis.weights(t);
            let v: [f32; 4] = std::array::from_fn(|c| {
                (0..4).map(|j| w[j] * f64::from(cp[j][c])).sum::<f64>() as f32
            });
            let floor = cp.iter().map(|p| p[3]).fold(f32::INFINITY, f32::min);
            out.points.push([v[0], v[1], v[2]]);
            out.radii.push(if v[3] > 0.0 { v[3] } else { floor });
            if let (Some(c), Some(e)) = (&mut out.colors, ends) {
                let (a, b) = (e[seg], e[seg + 1]);
                c.push(std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t as f32));
            }
        }
    }
}
