//! `hairtrace convert`: grooms between Cem Yuksel's `.hair` and USD BasisCurves, so that a
//! procedural groom can go to a DCC and come back (docs/formats.md, "Converting").
//!
//! A `.hair` file holds polylines and says nothing of the curve drawn through them; hairtrace
//! reads its points with a groom's `basis` (B-spline by default), as
//! the scene layer's `Curves::from_strands` lays them out. The
//! conversion keeps that curve exactly, in both directions:
//! - linear: a `linear` (`nonperiodic`) prim of the same points;
//! - B-spline: a `cubic` `bspline` prim with `pinned` wrap, whose phantom end points
//!   (`2 p0 - p1`) are the ones hairtrace adds;
//! - Catmull-Rom and Bezier (the Catmull-Rom curve in Bezier form): `cubic` `catmullRom`,
//!   `pinned`.
//!
//! USD prims become `.hair` strands in world space when their curves are one of those forms
//! for the chosen basis; with the linear basis, every cubic curve is sampled into a polyline
//! of [`ConvertOptions::samples_per_segment`] segments per curve segment. Any other prim is
//! refused with the way out named, never approximated silently.

use std::path::Path;

use super::hair::{Thickness, read_hair_file, write_hair_file};
use super::usd::{
    CurvesToWrite, Layout, StageUnits, UsdCurves, Wrap, is_usd_path, read_usd_file, write_usd_file,
};
use crate::description::{SceneDescription, demo, has_extension};
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
    /// The basis a `.hair` file's points are read with (hairtrace's default for a bare
    /// `.hair` and a `[[groom]]` entry: B-spline).
    pub basis: CurveBasis,
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
            basis: CurveBasis::BSpline,
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

/// A groom on its way: polylines and the basis that draws its curve.
struct Groom {
    name: String,
    strands: Strands,
    basis: CurveBasis,
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
        strands: grooms.iter().map(|g| g.strands.strand_count()).sum(),
        points: grooms.iter().map(|g| g.strands.point_count()).sum(),
        notes,
    };
    if to_usd {
        let prims = grooms
            .iter()
            .map(curves_to_write)
            .collect::<Result<Vec<_>>>()?;
        // A .hair file has no units or axes: hairtrace's +y up, and USD's own fallback unit.
        let units = StageUnits {
            up_axis: "Y".into(),
            meters_per_unit: 0.01,
        };
        write_usd_file(output, &prims, &units)?;
    } else {
        let strands = joined(grooms, opts.basis, &mut converted.notes)?;
        write_hair_file(output, &strands, opts.thickness)?;
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
                if stage.up_axis != "Y" {
                    notes.push(format!(
                        "{}: the stage is {}-up; a .hair file has no up axis, and the points \
                         are kept as authored",
                        path.display(),
                        stage.up_axis
                    ));
                }
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
                vec![Groom {
                    name: "groom0".into(),
                    strands: read_hair_file(path, opts.thickness)?,
                    basis: opts.basis,
                }]
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

/// The strand grooms of a scene, placed in world space, each with its basis.
fn scene_grooms(scene: &SceneDescription) -> Result<Vec<Groom>> {
    (scene.grooms.iter().enumerate())
        .map(|(i, g)| {
            Ok(Groom {
                name: format!("groom{i}"),
                strands: g
                    .strands()
                    .map_err(|e| e.context(format_args!("{}: groom[{i}]", scene.origin)))?,
                basis: g.basis,
            })
        })
        .collect()
}

/// The USD layout that draws exactly the curve hairtrace draws through polylines read with
/// `basis`.
fn usd_layout(basis: CurveBasis) -> Layout {
    match basis {
        CurveBasis::Linear => Layout {
            basis,
            wrap: Wrap::Nonperiodic,
        },
        CurveBasis::BSpline => Layout {
            basis,
            wrap: Wrap::Pinned,
        },
        CurveBasis::CatmullRom | CurveBasis::Bezier => Layout {
            basis: CurveBasis::CatmullRom,
            wrap: Wrap::Pinned,
        },
    }
}

fn curves_to_write(g: &Groom) -> Result<CurvesToWrite> {
    let s = &g.strands;
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
        layout: usd_layout(g.basis),
        points: s.points.clone(),
        counts: s.counts.clone(),
        widths,
        colors: s.colors.clone(),
    })
}

/// All grooms as one `.hair` groom, when each is drawn with `basis` as a `.hair` file will be.
/// When only some have colours, none are written (a note says so).
fn joined(grooms: Vec<Groom>, basis: CurveBasis, notes: &mut Vec<String>) -> Result<Strands> {
    let coloured = grooms.iter().filter(|g| g.strands.colors.is_some()).count();
    if coloured != 0 && coloured != grooms.len() {
        notes.push(format!(
            "colours not written: {coloured} of {} grooms have them, and a .hair file has a \
             colour for every point or for none",
            grooms.len()
        ));
    }
    let mut all = Strands {
        colors: (coloured == grooms.len() && coloured != 0).then(Vec::new),
        ..Strands::default()
    };
    for g in grooms {
        if usd_layout(g.basis) != usd_layout(basis) {
            return Err(invalid_arg!(
                "{}: its basis is {:?}, but the .hair file's points will be read as {:?}: \
                 convert it with --basis {}",
                g.name,
                g.basis,
                basis,
                basis_name(g.basis)
            ));
        }
        all.points.extend(g.strands.points);
        all.radii.extend(g.strands.radii);
        all.counts.extend(g.strands.counts);
        if let (Some(out), Some(c)) = (&mut all.colors, g.strands.colors) {
            out.extend(c);
        }
    }
    Ok(all)
}

/// Names of the bases, as `--basis` and a `[[groom]]`'s `basis` spell them.
const BASIS_NAMES: [(&str, CurveBasis); 4] = [
    ("linear", CurveBasis::Linear),
    ("bezier", CurveBasis::Bezier),
    ("bspline", CurveBasis::BSpline),
    ("catmull_rom", CurveBasis::CatmullRom),
];

fn basis_name(basis: CurveBasis) -> &'static str {
    BASIS_NAMES
        .iter()
        .find(|(_, b)| *b == basis)
        .map_or("", |(n, _)| n)
}

/// The basis called `name` (linear, bezier, bspline, catmull_rom).
pub fn basis_named(name: &str) -> Result<CurveBasis> {
    (BASIS_NAMES.iter().find(|(n, _)| *n == name))
        .map(|&(_, b)| b)
        .ok_or_else(|| {
            invalid_arg!("unknown basis {name:?} (linear, bezier, bspline, catmull_rom)")
        })
}

/// One USD prim as polylines for `basis`: its own points when its curves are what `basis`
/// draws through them, sampled curves when `basis` is linear, else an error.
fn usd_groom(c: &UsdCurves, opts: &ConvertOptions, notes: &mut Vec<String>) -> Result<Groom> {
    let (layout, basis) = (c.layout, opts.basis);
    let exact = usd_layout(basis) == layout
        || (basis == CurveBasis::Linear && layout.basis == CurveBasis::Linear);
    if !exact && basis != CurveBasis::Linear {
        return Err(invalid_arg!(
            "{}: {:?} {:?} curves are not what a .hair file read as {:?} draws: convert with \
             --basis linear ({})",
            c.path,
            layout.basis,
            layout.wrap,
            basis,
            if layout.basis == CurveBasis::Linear {
                "exact"
            } else {
                "the curves are sampled into polylines"
            }
        ));
    }
    if !exact {
        notes.push(format!(
            "{}: {:?} {:?} curves sampled into polylines, {} segments per curve segment",
            c.path, layout.basis, layout.wrap, opts.samples_per_segment
        ));
    }
    if c.melanin.is_some() {
        notes.push(format!(
            "{}: primvars:melanin is not written: a .hair file has no melanin",
            c.path
        ));
    }
    // Pinned cubic curves carry a phantom point at each end that is not a strand point.
    let trim =
        usize::from(exact && layout.wrap == Wrap::Pinned && layout.basis != CurveBasis::Linear);
    let mut s = Strands {
        colors: c.colors.as_ref().map(|_| Vec::new()),
        ..Strands::default()
    };
    let (mut start, mut ends_start, mut authored) = (0, 0, 0);
    for (curve, &m) in c.control_counts.iter().enumerate() {
        let ctl = &c.control[start..start + m as usize];
        let n = c.authored_counts[curve] as usize;
        let segments = layout.basis.segments_for(ctl.len()).unwrap_or(0);
        let ends = c
            .colors
            .as_ref()
            .map(|e| &e[ends_start..ends_start + segments + 1]);
        let before = s.points.len();
        if exact {
            for p in &ctl[trim..ctl.len() - trim] {
                s.points.push([p[0], p[1], p[2]]);
                s.radii.push(p[3]);
            }
            // A pinned cubic curve's point colours are what the .hair file holds per point;
            // elsewhere (linear, or `varying` colours) the segment ends are the points.
            let points = c.point_colors.as_ref().filter(|_| trim == 1);
            match (&mut s.colors, points, ends) {
                (Some(out), Some(p), _) => out.extend_from_slice(&p[authored..authored + n]),
                (Some(out), None, Some(e)) => out.extend_from_slice(e),
                _ => {}
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
        authored += n;
    }
    Ok(Groom {
        name: c.path.clone(),
        strands: s,
        basis,
    })
}

/// The weights of a cubic segment's four control points at parameter t.
fn cubic_weights(basis: CurveBasis, t: f64) -> [f64; 4] {
    let (t2, t3, u) = (t * t, t * t * t, 1.0 - t);
    match basis {
        CurveBasis::Bezier => [u * u * u, 3.0 * t * u * u, 3.0 * t2 * u, t3],
        CurveBasis::BSpline => [
            u * u * u / 6.0,
            (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
            (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
            t3 / 6.0,
        ],
        CurveBasis::CatmullRom => [
            0.5 * (-t3 + 2.0 * t2 - t),
            0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
            0.5 * (-3.0 * t3 + 4.0 * t2 + t),
            0.5 * (t3 - t2),
        ],
        CurveBasis::Linear => [u, t, 0.0, 0.0],
    }
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
            let w = cubic_weights(basis, t);
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
