//! One BasisCurves prim: its attributes read and checked, its composed world transform
//! applied, its curves laid out for Embree.

use openusd::gf::Matrix4d;
use openusd::schemas::geom::{BasisCurves, Xform, Xformable};
use openusd::sdf::{self, Value};
use openusd::usd::{Attribute, Prim, Stage};

use super::UsdCurves;
use super::layout::{Interpolation, Layout, clamp_colors};
use super::time::{self, Animation, Clock, Motion, ReadAt, failed};
use crate::error::{Result, invalid_arg};
use crate::formats::units::StageUnits;
use crate::validate;

pub(super) fn wrong_type(what: &str, expected: &str, v: &Value) -> crate::Error {
    let actual: &'static str = v.into();
    invalid_arg!("{what}: expected {expected}, found {actual}")
}

fn token(value: Option<Value>, what: &str, fallback: &str) -> Result<String> {
    match value {
        None => Ok(fallback.to_string()),
        Some(Value::Token(t)) => Ok(t.as_str().to_string()),
        Some(Value::String(s)) => Ok(s),
        Some(v) => Err(wrong_type(what, "a token", &v)),
    }
}

fn floats(value: Option<Value>, what: &str) -> Result<Option<Vec<f32>>> {
    match value {
        None => Ok(None),
        Some(Value::FloatVec(v)) => Ok(Some(v)),
        Some(Value::DoubleVec(v)) => Ok(Some(v.into_iter().map(|x| x as f32).collect())),
        Some(v) => Err(wrong_type(what, "float[]", &v)),
    }
}

pub(super) fn vec3s(value: Option<Value>, what: &str) -> Result<Option<Vec<[f32; 3]>>> {
    match value {
        None => Ok(None),
        Some(Value::Vec3fVec(v)) => Ok(Some(v.into_iter().map(Into::into).collect())),
        Some(Value::Vec3dVec(v)) => Ok(Some(
            v.into_iter()
                .map(|p| {
                    let p: [f64; 3] = p.into();
                    p.map(|x| x as f32)
                })
                .collect(),
        )),
        Some(v) => Err(wrong_type(what, "point3f[] or color3f[]", &v)),
    }
}

/// The `interpolation` metadata of a primvar (or `widths`), `fallback` when not authored.
fn interpolation(attr: &Attribute, what: &str, fallback: Interpolation) -> Result<Interpolation> {
    let v = attr
        .get_metadata::<Value>("interpolation")
        .map_err(|e| invalid_arg!("{what}: {e:#}"))?;
    match v {
        None => Ok(fallback),
        Some(Value::Token(t)) => Interpolation::named(t.as_str())
            .ok_or_else(|| invalid_arg!("{what}: unknown interpolation \"{}\"", t.as_str())),
        Some(v) => Err(wrong_type(what, "an interpolation token", &v)),
    }
}

/// The prim's local-to-world matrix (row vectors, as USD writes them): its own xformOps
/// and every ancestor's, stopping at a `!resetXformStack!`.
pub(super) fn world_transform(
    stage: &Stage,
    path: &sdf::Path,
    prim: &impl Xformable,
    when: ReadAt,
) -> Result<Matrix4d> {
    let err = failed;
    let mut m = prim
        .local_to_parent_transform(when.transform_time())
        .map_err(|e| err(path, e))?;
    let mut reset = prim.resets_xform_stack().map_err(|e| err(path, e))?;
    let mut at = path.parent();
    while let Some(p) = at.filter(|p| *p != sdf::Path::abs_root() && !reset) {
        let ancestor = stage.prim(p.clone());
        let order = ancestor.attribute("xformOpOrder");
        match Xform::get(stage, p.clone()).map_err(|e| err(&p, e))? {
            Some(x) => {
                m = m * x
                    .local_to_parent_transform(when.transform_time())
                    .map_err(|e| err(&p, e))?;
                reset = x.resets_xform_stack().map_err(|e| err(&p, e))?;
            }
            None if when.value(&order)?.is_some() => {
                return Err(invalid_arg!(
                    "ancestor {} has xformOps but is not an Xform: this reader follows the \
                     transforms of Xform ancestors only",
                    p.as_str()
                ));
            }
            None => {}
        }
        at = p.parent();
    }
    Ok(m)
}

/// The uniform scale of a transform's linear part (its rows are the images of the axes),
/// or an error when it scales the axes differently (round fibres cannot follow).
fn uniform_scale(m: &Matrix4d) -> Result<f64> {
    let row = |i: usize| [m.0[4 * i], m.0[4 * i + 1], m.0[4 * i + 2]];
    validate::uniform_scale("the world transform", [row(0), row(1), row(2)])
}

pub(super) fn transform_point(m: &Matrix4d, p: [f32; 3]) -> [f32; 3] {
    let p = p.map(f64::from);
    std::array::from_fn(|j| {
        (p[0] * m.0[j] + p[1] * m.0[4 + j] + p[2] * m.0[8 + j] + m.0[12 + j]) as f32
    })
}

/// How many values a primvar of `interp` has for curves of `counts` points and `segs`
/// segments; refused for `varying` if a curve has none (a pinned curve of two points).
fn expected_len(
    interp: Interpolation,
    layout: Layout,
    counts: &[usize],
    segs: &[usize],
) -> Result<usize> {
    Ok(match interp {
        Interpolation::Constant => 1,
        Interpolation::Uniform => counts.len(),
        Interpolation::Vertex => counts.iter().sum(),
        Interpolation::Varying => {
            if let Some(i) = segs.iter().position(|&s| layout.varying_count(s) == 0) {
                return Err(invalid_arg!(
                    "curve {i}: a pinned curve of 2 points has no varying values (usd-core \
                     counts its points - 2); author its values per vertex"
                ));
            }
            segs.iter().map(|&s| layout.varying_count(s)).sum()
        }
    })
}

/// Splits `values` of `interp` into the values of curve `i` (start offsets precomputed).
fn per_curve<T: Copy>(
    values: &[T],
    interp: Interpolation,
    i: usize,
    vertex_start: usize,
    varying_start: usize,
    n: usize,
    varying_n: usize,
) -> Vec<T> {
    match interp {
        Interpolation::Constant => vec![values[0]; n],
        Interpolation::Uniform => vec![values[i]; n],
        Interpolation::Vertex => values[vertex_start..vertex_start + n].to_vec(),
        Interpolation::Varying => values[varying_start..varying_start + varying_n].to_vec(),
    }
}

/// A vec3 primvar of `interp` at every segment end of the curves (segments + 1 per curve,
/// as the curve evaluates it between its points), and per authored point unless it is
/// `varying` (which holds no value per point). `phantom` gives the value at a wrap's extra
/// point from the one the wrap reflects and the end's own.
fn segment_end_values(
    values: &[[f32; 3]],
    interp: Interpolation,
    layout: Layout,
    (counts, segs): (&[usize], &[usize]),
    phantom: impl Fn([f32; 3], [f32; 3]) -> [f32; 3] + Copy,
) -> (Vec<[f32; 3]>, Option<Vec<[f32; 3]>>) {
    let mut ends = Vec::new();
    let mut points = (interp != Interpolation::Varying).then(Vec::new);
    let (mut vertex_start, mut varying_start) = (0, 0);
    for (i, (&n, &s)) in counts.iter().zip(segs).enumerate() {
        let varying_n = layout.varying_count(s);
        let v = per_curve(values, interp, i, vertex_start, varying_start, n, varying_n);
        match interp {
            Interpolation::Varying => {
                let v = layout.varying_ends(&v);
                ends.extend_from_slice(&v);
                if v.len() == s {
                    ends.push(v[0]);
                }
            }
            _ => {
                if let Some(p) = &mut points {
                    p.extend_from_slice(&v);
                }
                let mut ext = Vec::new();
                layout.extend(&v, &mut ext, phantom);
                layout.segment_ends(&ext, s, &mut ends);
            }
        }
        vertex_start += n;
        varying_start += varying_n;
    }
    (ends, points)
}

/// The curves' normals, if authored: USD's `primvars:normals` or `normals`, or Blender's
/// `primvars:custom_normal` (Blender 5.0 writes a curve's normals, those of its Free
/// normal mode, under that name and no other). Checked for length and finite values.
fn read_normals(
    prim: &Prim,
    at: ReadAt,
    layout: Layout,
    (counts, segs): (&[usize], &[usize]),
) -> Result<Option<(Vec<[f32; 3]>, Interpolation)>> {
    for name in ["primvars:normals", "normals", "primvars:custom_normal"] {
        let attr = prim.attribute(name);
        let Some(v) = vec3s(at.value(&attr)?, name)? else {
            continue;
        };
        let interp = interpolation(&attr, name, Interpolation::Vertex)?;
        let want = expected_len(interp, layout, counts, segs)?;
        if v.len() != want {
            return Err(invalid_arg!(
                "{name} has {} values for {interp:?} interpolation: {want} expected",
                v.len()
            ));
        }
        if let Some(i) = v.iter().position(|n| !n.iter().all(|x| x.is_finite())) {
            return Err(invalid_arg!("{name}[{i}] = {:?}: must be finite", v[i]));
        }
        return Ok(Some((v, interp)));
    }
    Ok(None)
}

/// Reads the BasisCurves prim at `path`. `file_bytes` bounds the counts: no curve table may
/// ask for more points than the file could hold.
pub(super) fn read_basis_curves(
    stage: &Stage,
    path: &sdf::Path,
    file_bytes: u64,
    (units, clock): (StageUnits, &Clock),
    at: ReadAt,
) -> Result<UsdCurves> {
    let curves = BasisCurves::get(stage, path.clone())
        .map_err(|e| invalid_arg!("{e:#}"))?
        .ok_or_else(|| invalid_arg!("not a BasisCurves prim"))?;
    let prim = stage.prim(path.clone());
    let attr = |name: &str| prim.attribute(name);
    let value = |name: &str| at.value(&attr(name));
    let kind = token(value("type")?, "type", "cubic")?;
    let basis = token(value("basis")?, "basis", "bezier")?;
    let layout = Layout::named(
        &kind,
        &basis,
        &token(value("wrap")?, "wrap", "nonperiodic")?,
    )?;
    let points = points_at(&prim, at, clock)?.ok_or_else(|| invalid_arg!("no points"))?;
    let raw_counts = match value("curveVertexCounts")? {
        Some(Value::IntVec(v)) => v,
        Some(v) => return Err(wrong_type("curveVertexCounts", "int[]", &v)),
        None => return Err(invalid_arg!("no curveVertexCounts")),
    };
    if raw_counts.len() as u64 > file_bytes {
        return Err(invalid_arg!(
            "{} curves: more than the file could hold",
            raw_counts.len()
        ));
    }
    let mut counts = Vec::with_capacity(raw_counts.len());
    let mut segs = Vec::with_capacity(raw_counts.len());
    for (i, &c) in raw_counts.iter().enumerate() {
        let n = usize::try_from(c)
            .map_err(|_| invalid_arg!("curveVertexCounts[{i}] = {c}: negative"))?;
        let s = layout.segments(n).ok_or_else(|| {
            let (kind, basis, wrap) = layout.tokens();
            invalid_arg!(
                "curveVertexCounts[{i}] = {n}: {kind} {basis} {wrap} curves have {} points",
                layout.count_rule()
            )
        })?;
        counts.push(n);
        segs.push(s);
    }
    let total: u64 = counts.iter().map(|&n| n as u64).sum();
    if total != points.len() as u64 {
        return Err(invalid_arg!(
            "curveVertexCounts add up to {total} points but points has {}",
            points.len()
        ));
    }
    validate::positions("point", &points)?;

    let widths_attr = attr("widths");
    let widths = floats(at.value(&widths_attr)?, "widths")?
        .ok_or_else(|| invalid_arg!("no widths: the fibres' diameters must be authored"))?;
    let widths_interp = interpolation(&widths_attr, "widths", Interpolation::Vertex)?;
    let want = expected_len(widths_interp, layout, &counts, &segs)?;
    if widths.len() != want {
        return Err(invalid_arg!(
            "widths has {} values for {widths_interp:?} interpolation: {want} expected",
            widths.len()
        ));
    }
    if let Some(i) = widths.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(invalid_arg!(
            "widths[{i}] = {}: must be finite and > 0",
            widths[i]
        ));
    }

    let color_attr = attr("primvars:displayColor");
    let colors = vec3s(at.value(&color_attr)?, "primvars:displayColor")?;
    let color_interp = interpolation(
        &color_attr,
        "primvars:displayColor",
        Interpolation::Constant,
    )?;
    if let Some(c) = &colors {
        let want = expected_len(color_interp, layout, &counts, &segs)?;
        if c.len() != want {
            return Err(invalid_arg!(
                "{} displayColor values for {color_interp:?} interpolation: {want} expected",
                c.len()
            ));
        }
        if let Some(i) = c
            .iter()
            .position(|v| !v.iter().all(|x| (0.0..=1.0).contains(x)))
        {
            return Err(invalid_arg!(
                "displayColor[{i}] = {:?}: must be in [0, 1]",
                c[i]
            ));
        }
    }

    let melanin = read_melanin(at, &attr("primvars:melanin"), counts.len())?;
    if melanin.is_some() && colors.is_some() {
        return Err(invalid_arg!(
            "both primvars:displayColor and primvars:melanin are authored: give one"
        ));
    }

    let m = world_transform(stage, path, &curves, at)?;
    let scale = uniform_scale(&m)?;
    let world: Vec<[f32; 3]> = points.iter().map(|&p| transform_point(&m, p)).collect();
    validate::positions("point (in world space)", &world)?;
    let radius_of = |w: f32| (f64::from(w) * 0.5 * scale) as f32;
    let (lo, hi) = widths
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &w| {
            (lo.min(radius_of(w)), hi.max(radius_of(w)))
        });
    let bounds = world.iter().fold(
        ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                std::array::from_fn(|k| lo[k].min(p[k])),
                std::array::from_fn(|k| hi[k].max(p[k])),
            )
        },
    );

    let control_total: usize = counts.iter().map(|&n| layout.embree_count(n)).sum();
    let mut control = Vec::with_capacity(control_total);
    let mut control_counts = Vec::with_capacity(counts.len());
    let (mut vertex_start, mut varying_start) = (0, 0);
    let mut pos = Vec::new();
    let mut radii = Vec::new();
    for (i, (&n, &s)) in counts.iter().zip(&segs).enumerate() {
        let varying_n = layout.varying_count(s);
        let w = per_curve(
            &widths,
            widths_interp,
            i,
            vertex_start,
            varying_start,
            n,
            varying_n,
        );
        let r: Vec<[f32; 1]> = match widths_interp {
            Interpolation::Varying => layout.varying_to_points(&w, n),
            _ => w.iter().map(|&x| [x]).collect(),
        };
        pos.clear();
        layout.extend(&world[vertex_start..vertex_start + n], &mut pos, |p, _| p);
        radii.clear();
        layout.extend(&r, &mut radii, |r, end| if r[0] > 0.0 { r } else { end });
        control.extend(
            pos.iter()
                .zip(&radii)
                .map(|(p, r)| [p[0], p[1], p[2], radius_of(r[0])]),
        );
        control_counts.push(pos.len() as u32);
        vertex_start += n;
        varying_start += varying_n;
    }
    // A pinned wrap's phantom end points lie beyond the authored ones, and a transform's
    // scale can push radii past f32: what Embree gets is checked here, where the file is named.
    validate::positions("control point (the wrap's end points included)", &control)?;
    if let Some(i) = control.iter().position(|p| !p[3].is_finite()) {
        return Err(invalid_arg!(
            "control point {i}: radius {} in world space is not finite",
            control[i][3]
        ));
    }
    let (colors, point_colors) = match &colors {
        Some(c) => {
            let clamped = |c: [f32; 3], _| c.map(|x| x.clamp(0.0, 1.0));
            let (mut ends, points) =
                segment_end_values(c, color_interp, layout, (&counts, &segs), clamped);
            clamp_colors(&mut ends);
            (Some(ends), points)
        }
        None => (None, None),
    };
    // Normals are directions: the transform's linear part turns them.
    let turn = |n: [f32; 3]| {
        let (a, o) = (transform_point(&m, n), transform_point(&m, [0.0; 3]));
        std::array::from_fn(|k| a[k] - o[k])
    };
    let normals = read_normals(&prim, at, layout, (&counts, &segs))?.map(|(v, interp)| {
        let world: Vec<[f32; 3]> = v.into_iter().map(turn).collect();
        segment_end_values(&world, interp, layout, (&counts, &segs), |_, end| end).0
    });
    let animation = animation(stage, path)?;
    Ok(UsdCurves {
        path: path.as_str().to_string(),
        animation,
        units,
        layout,
        authored_counts: counts.iter().map(|&n| n as u32).collect(),
        segments: segs.iter().sum(),
        bounds,
        radius_range: (lo, hi),
        control,
        control_counts,
        colors,
        point_colors,
        normals,
        melanin,
    })
}

/// The prim's points at `at`: moved by their velocities from the sample before, where
/// those are authored there (UsdGeomPointBased's rule), else as [`ReadAt::value`] gives
/// them; refused between two samples of different counts with no velocities.
pub(super) fn points_at(prim: &Prim, at: ReadAt, clock: &Clock) -> Result<Option<Vec<[f32; 3]>>> {
    let points = prim.attribute("points");
    let read = |t: ReadAt| vec3s(t.value(&points)?, "points");
    let ReadAt::Code(t) = at else {
        return read(at);
    };
    let Some((lo, hi)) = time::between(&time::sample_times(&points)?, t) else {
        return read(at);
    };
    let velocities = prim.attribute("velocities");
    if time::sample_times(&velocities)?.contains(&lo) {
        let before = read(ReadAt::Code(lo))?.unwrap_or_default();
        let at_lo = |name: &str| vec3s(ReadAt::Code(lo).value(&prim.attribute(name))?, name);
        let motion = Motion {
            velocities: at_lo("velocities")?.unwrap_or_default(),
            accelerations: at_lo("accelerations")?,
        };
        let counts = [Some(&motion.velocities), motion.accelerations.as_ref()];
        if let Some(n) = counts
            .into_iter()
            .flatten()
            .find(|v| v.len() != before.len())
        {
            return Err(invalid_arg!(
                "velocities or accelerations at time code {lo}: {} values for {} points",
                n.len(),
                before.len()
            ));
        }
        return Ok(Some(
            motion.moved(&before, (t - lo) / clock.codes_per_second),
        ));
    }
    // Between samples of different counts USD holds the earlier one, so the value at `t`
    // has the count of the sample before: a count unlike the sample after's is the change.
    let points_at_t = read(at)?.unwrap_or_default();
    let after = read(ReadAt::Code(hi))?.unwrap_or_default();
    if points_at_t.len() != after.len() {
        return Err(invalid_arg!(
            "points: the samples at time codes {lo} ({} points) and {hi} ({} points) differ \
             in count and no velocities are authored at {lo}: the points between them are \
             undefined",
            points_at_t.len(),
            after.len()
        ));
    }
    Ok(Some(points_at_t))
}

/// What of the prim at `path` moves.
pub(super) fn animation(stage: &Stage, path: &sdf::Path) -> Result<Animation> {
    let mut a = Animation::default();
    let mut at = Some(path.clone());
    while let Some(p) = at.filter(|p| *p != sdf::Path::abs_root()) {
        let prim = stage.prim(p.clone());
        for attr in prim.attributes().map_err(|e| failed(&p, e))? {
            let times = time::sample_times(&attr)?;
            if let (Some(&first), Some(&last)) = (times.first(), times.last()) {
                let (lo, hi) = a.span.unwrap_or((first, last));
                a.span = Some((lo.min(first), hi.max(last)));
            }
            if times.len() > 1 {
                a.attributes.push(attr.path().as_str().to_string());
                a.times.extend(&times);
            }
        }
        at = p.parent();
    }
    a.times.sort_by(f64::total_cmp);
    a.times.dedup();
    Ok(a)
}

/// `primvars:melanin`, eumelanin per curve (constant or uniform), if authored.
fn read_melanin(at: ReadAt, attr: &Attribute, curves: usize) -> Result<Option<Vec<f32>>> {
    const WHAT: &str = "primvars:melanin";
    let Some(values) = floats(at.value(attr)?, WHAT)? else {
        return Ok(None);
    };
    let per_curve = match interpolation(attr, WHAT, Interpolation::Constant)? {
        Interpolation::Constant if values.len() == 1 => vec![values[0]; curves],
        Interpolation::Uniform if values.len() == curves => values,
        interp => {
            return Err(invalid_arg!(
                "{WHAT}: {} values for {interp:?} interpolation: one (constant) or one per \
                 curve (uniform) expected",
                values.len()
            ));
        }
    };
    if let Some(i) = per_curve.iter().position(|m| !(m.is_finite() && *m >= 0.0)) {
        return Err(invalid_arg!(
            "{WHAT}[{i}] = {}: must be finite and >= 0",
            per_curve[i]
        ));
    }
    Ok(Some(per_curve))
}
