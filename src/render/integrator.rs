//! Unidirectional path tracing with next-event estimation and multiple importance
//! sampling (power heuristic) between light sampling and BSDF sampling.
//!
//! Light hair keeps energy through very many bounces, so the depth cap is high and paths
//! end mostly by Russian roulette on their throughput, which is unbiased. Which rays are
//! traced where was chosen by measurement (docs/measurements.md, "Render efficiency").

use glam::Vec3;

use super::camera_rays::MAX_CAMERA_RAYS;
use super::film::{FirstHit, Seen};
use super::sampler::PixelSampler;
use super::settings::{LightOffsets, PathSettings, Roulette, Strategy};
use super::survival::{Recorder, Survival};
use crate::bsdf::absorption::color_from_sigma_a;
use crate::bsdf::diffuse::Diffuse;
use crate::bsdf::{
    ACROSS, DiffusePoint, HairBsdf, HairPoint, HuangBsdf, HuangField, HuangPoint, Lobes, LocalBsdf,
};
use crate::embree::Ray;
use crate::error::{Result, invalid_arg};
use crate::math::sampling::{Distribution1D, power_heuristic};
use crate::math::{Frame, hashed_pair, luminance};
use crate::scene::hit::{HairHit, Hit, SurfaceHit};
use crate::scene::light::{Light, LightEval};
use crate::scene::material::Material;
use crate::scene::tracer::{SpawnedRay, Tracer};

impl Roulette {
    /// The probability that a path goes on when it is decided at a hit, before the
    /// vertex is shaded (where no light is sampled: `World::radiance`): the square of
    /// [`Self::survival`], which also stands in for the attenuation of the vertex it has
    /// not seen (measured cheaper than the rule after the vertex at the same error:
    /// docs/measurements.md, "Render efficiency"), times the depth's learned `factor`
    /// (`render::survival`), at most 1.
    pub fn survival_at_hit(self, beta: Vec3, factor: f32) -> f32 {
        let s = self.survival(beta);
        (s * s * factor).min(1.0)
    }

    /// The probability that a path with throughput `beta` goes on.
    pub fn survival(self, beta: Vec3) -> f32 {
        let m = beta.max_element();
        let p = match self {
            Roulette::SqrtThroughput => m.sqrt(),
            Roulette::Throughput => m,
        };
        // NaN (a degenerate weight) ends the path.
        if p.is_nan() { 0.0 } else { p.min(1.0) }
    }
}

/// The least probability with which shadow-ray roulette traces a shadow ray.
const MIN_SHADOW_SURVIVAL: f32 = 1.0 / 1_048_576.0;

impl PathSettings {
    /// The hair lobes a vertex evaluates after `events` scattering events.
    fn lobes(&self, events: u32) -> Lobes {
        if self.deep_bounce_depth.is_some_and(|n| events >= n) {
            Lobes::Merged
        } else if self.lobe_cull > 0.0 {
            Lobes::Culled(self.lobe_cull)
        } else {
            Lobes::All
        }
    }
}

/// Everything a path needs: geometry, one material per geometry id, lights.
pub struct World {
    pub tracer: Tracer,
    materials: Vec<Material>,
    lights: Vec<Light>,
    /// Light selection proportional to power, and each light's probability under it.
    light_choice: Option<Distribution1D>,
    light_prob: Vec<f32>,
}

impl World {
    /// `materials[g]` shades geometry id g of the tracer.
    pub fn new(tracer: Tracer, materials: Vec<Material>, lights: Vec<Light>) -> Result<Self> {
        let geometries = tracer.scene().geometries().len();
        if materials.len() != geometries {
            return Err(invalid_arg!(
                "{} materials for {geometries} geometries",
                materials.len()
            ));
        }
        let mut world = World {
            tracer,
            materials,
            lights: Vec::new(),
            light_choice: None,
            light_prob: Vec::new(),
        };
        world.set_lights(lights)?;
        Ok(world)
    }

    /// Replaces the material of geometry `geometry` (hair on curves, diffuse on meshes),
    /// keeping the build: a world shades by reading its materials at each hit, so the
    /// next render is the one a world built with this material would give.
    pub fn set_material(&mut self, geometry: u32, material: Material) -> Result<()> {
        let slot = self.materials.get_mut(geometry as usize).ok_or_else(|| {
            invalid_arg!(
                "geometry {geometry}: the world has {} geometries",
                self.tracer.scene().geometries().len()
            )
        })?;
        let on_curves = self.tracer.strands(geometry).is_some();
        material.check_suits(&format!("the material for geometry {geometry}"), on_curves)?;
        *slot = material;
        Ok(())
    }

    /// Replaces the lights, keeping the build, and weighs them again for next-event
    /// estimation (by power over the scene's bounds, as [`World::new`] does).
    pub fn set_lights(&mut self, lights: Vec<Light>) -> Result<()> {
        let (lo, hi) = self.tracer.scene().bounds();
        let radius = 0.5 * (Vec3::from_array(hi) - Vec3::from_array(lo)).length();
        let radius = if radius.is_finite() && radius > 0.0 {
            radius
        } else {
            1.0
        };
        // Lights that BSDF sampling serves as well on its own get no shadow rays: they
        // are left out of the choice, so their MIS weight on BSDF-sampled rays is 1.
        let power: Vec<f32> = lights
            .iter()
            .map(|l| {
                if l.needs_light_sampling() {
                    l.power(radius)
                } else {
                    0.0
                }
            })
            .collect();
        let total: f32 = power.iter().sum();
        (self.light_choice, self.light_prob) = if total > 0.0 && total.is_finite() {
            (
                Some(Distribution1D::new(&power)?),
                power.iter().map(|p| p / total).collect(),
            )
        } else {
            (None, vec![0.0; lights.len()])
        };
        self.lights = lights;
        Ok(())
    }

    /// Whether next-event estimation samples a light at each vertex: not where no light
    /// needs it (a uniform sky alone) or when only the BSDF is sampled.
    pub fn samples_lights(&self, settings: &PathSettings) -> bool {
        settings.strategy != Strategy::BsdfOnly && self.light_choice.is_some()
    }

    /// One camera sample traced as `rays`, spread over its pixel (`super::camera_rays`):
    /// the rays that escape add what they see, and the path goes on from the ray that
    /// `choice` (in [0, 1)) picks among those that hit, weighted by their number. Its first
    /// hit, for the AOVs, is the first ray's. Where no light is sampled, `survival` scales
    /// the roulette, and `record`, when given, records the path's decisions.
    #[allow(clippy::too_many_arguments)]
    pub fn camera_sample(
        &self,
        rays: &[Ray],
        choice: f32,
        settings: &PathSettings,
        aovs: bool,
        pixel_spread: f32,
        sampler: &mut PixelSampler,
        ending: (&Survival, Option<&mut Recorder>),
    ) -> CameraSample {
        if let [ray] = rays {
            return self.radiance(*ray, settings, aovs, pixel_spread, sampler, ending);
        }
        let mut seen = Vec3::ZERO;
        let mut hit = [0; MAX_CAMERA_RAYS];
        let mut hits = 0;
        for (i, ray) in rays.iter().enumerate() {
            // Which rays hit is all a split needs of most of them: occlusion queries.
            if self.tracer.occluded_spawned(&SpawnedRay::from(*ray)) {
                hit[hits] = i;
                hits += 1;
            } else {
                seen += self.emission(
                    ray.org,
                    ray.dir,
                    f32::INFINITY,
                    Came::Camera,
                    settings.strategy,
                );
            }
        }
        let count = rays.len() as f32;
        let mut sample = CameraSample {
            radiance: seen / count,
            first: None,
            rays: rays.len() as u32,
            seen: Seen::Split,
        };
        if hits == 0 {
            return sample;
        }
        let picked = hit[((choice * hits as f32) as usize).min(hits - 1)];
        let path = self.radiance(rays[picked], settings, aovs, pixel_spread, sampler, ending);
        sample.radiance += path.radiance * (hits as f32 / count);
        sample.rays += path.rays;
        sample.first = match picked {
            0 => path.first,
            _ if aovs && hit[0] == 0 => self.first_hit_of(rays[0]),
            _ => None,
        };
        sample
    }

    /// Radiance arriving along the camera ray `camera_ray` (at its time, a fraction of the
    /// shutter, which every ray of the path keeps), what its first hit reports for
    /// the AOVs (None when it escapes or when `aovs` is false), and the number of rays
    /// traced. `pixel_spread` is the side of the ray's pixel per unit distance from the eye
    /// (`Camera::pixel_spread`; the ray's direction is a unit vector).
    ///
    /// A path of at most `max_depth` scattering events traces up to `max_depth + 1`
    /// closest-hit rays: the last one only looks for emission, so that BSDF sampling
    /// reaches exactly as deep as next-event estimation and MIS stays unbiased at the cap.
    fn radiance(
        &self,
        camera_ray: Ray,
        settings: &PathSettings,
        aovs: bool,
        pixel_spread: f32,
        sampler: &mut PixelSampler,
        (survival, mut record): (&Survival, Option<&mut Recorder>),
    ) -> CameraSample {
        let mut first = None;
        let mut seen = Seen::Nothing;
        let mut rays = 0;
        let mut l = Vec3::ZERO;
        let mut beta = Vec3::ONE;
        let mut ray = SpawnedRay::from(camera_ray);
        // How `ray` was made, for MIS on the emission it finds.
        let mut came = Came::Camera;
        // `events` scattering events precede the ray traced in this iteration.
        let sample_light = self.samples_lights(settings);
        // Without next-event estimation a vertex's only product is the path's continuation,
        // so roulette decides at the hit, before the hit record and the BSDF are built.
        let roulette_at_hit = !sample_light;
        for events in 0..=settings.max_depth {
            let found = self.tracer.find_spawned(&ray);
            rays += 1;
            let t_hit = found.as_ref().map_or(f32::INFINITY, |h| h.t);
            let (org, t_hit) = ray.start(t_hit);
            let contribution = self.emission(org, ray.ray.dir, t_hit, came, settings.strategy);
            l += clamp(beta * contribution, events, settings);
            let Some(found) = found else { break };
            // A fixed number of requests per bounce keeps the sample sequence aligned;
            // the light's are skipped when no light is sampled.
            let [lx, ly, choice, u_shadow] = if sample_light {
                sampler.next_4d()
            } else {
                sampler.skip();
                [0.0; 4]
            };
            // The direction takes the best stratified pair, the lobe and roulette the rest.
            let [dx, dy, u_lobe, u_rr] = sampler.next_4d();
            if roulette_at_hit && events > 0 && events + 1 >= settings.rr_depth {
                let survive = settings
                    .roulette
                    .survival_at_hit(beta, survival.factor(events));
                if u_rr >= survive {
                    break;
                }
                if let Some(r) = record.as_deref_mut() {
                    r.survived(events, survive, beta, l, rays);
                }
                beta /= survive;
            }
            if events == 0 {
                seen = Seen::Surface;
            }
            let Some(hit) = self.tracer.record_spawned(&ray, &found) else {
                break;
            };
            if events == 0 {
                if let Hit::Hair(h) = &hit {
                    // Not finite where the spread is 0: `PixelAccumulator::add_seen`
                    // leaves that out.
                    seen = Seen::Strand(2.0 * h.radius / (pixel_spread * h.t));
                }
                if aovs {
                    first = Some(self.first_hit(&hit));
                }
            }
            if events == settings.max_depth {
                break;
            }
            let wo_world = -ray.ray.dir.normalize();
            let u_light = LightU {
                choice,
                point: [lx, ly],
                roulette: u_shadow,
            };
            // A varied hair material builds its BSDF per hit; the shading point borrows it.
            let varied_bsdf;
            let shading = match (&hit, self.materials.get(hit.geom_id() as usize)) {
                (Hit::Hair(h), Some(Material::Hair(m))) => {
                    // The strand narrower than its pixel, or seen by a bounce: the BSDF
                    // averaged across the fibre serves.
                    let thin = events > 0 || 2.0 * h.radius <= pixel_spread * h.t;
                    if let Some(b) = m.huang_at(h.strand.id, h.s, h.absorption) {
                        let field = huang_field(thin, sample_light);
                        Shading::huang(h, &b, wo_world, field, jitter(u_rr, u_lobe, events))
                    } else {
                        varied_bsdf = m.bsdf_at(h.strand.id, h.s, h.absorption);
                        let across = settings.light_offsets == LightOffsets::Across && thin;
                        Shading::hair(h, &varied_bsdf, wo_world, settings.lobes(events), across)
                    }
                }
                (Hit::Surface(s), Some(Material::Diffuse(d))) => Shading::diffuse(s, *d, wo_world),
                _ => break,
            };
            if sample_light {
                let (direct, shadow_rays) = self.direct(&hit, &shading, beta, u_light, settings);
                rays += shadow_rays;
                l += clamp(direct, events + 1, settings);
            }
            let Some(s) = shading.sample([u_lobe, dx, dy]) else {
                break;
            };
            beta *= s.weight;
            if !roulette_at_hit && events + 1 >= settings.rr_depth {
                let survive = settings.roulette.survival(beta);
                if u_rr >= survive {
                    break;
                }
                beta /= survive;
            }
            ray = self.tracer.spawn(&hit, s.wi, f32::INFINITY);
            // The BSDF's pdf costs a whole evaluation of its lobes: it is computed only
            // for a ray that may find a light next-event estimation also samples.
            let mis = settings.strategy == Strategy::Mis
                && self.sampled_light_along(ray.start(0.0).0, ray.ray.dir);
            came = Came::Bsdf {
                pdf: if mis { shading.pdf(s.local) } else { 0.0 },
            };
        }
        if let Some(r) = record {
            r.finish(l, rays);
        }
        CameraSample {
            radiance: l,
            first,
            rays,
            seen,
        }
    }

    /// What the camera ray `ray` reports for the AOVs: its first hit's, None if it
    /// escapes.
    fn first_hit_of(&self, ray: Ray) -> Option<FirstHit> {
        Some(self.first_hit(&self.tracer.intersect(&ray)?))
    }

    fn first_hit(&self, hit: &Hit) -> FirstHit {
        let (albedo, strand) = match (hit, self.materials.get(hit.geom_id() as usize)) {
            (Hit::Hair(h), Some(Material::Hair(m))) => {
                let p = m.params_at(h.strand.id, h.s, h.absorption);
                (
                    Vec3::from_array(color_from_sigma_a(p.sigma_a, p.beta_n)),
                    Some(h.strand.id),
                )
            }
            (Hit::Surface(_), Some(Material::Diffuse(d))) => (d.albedo(), None),
            _ => (Vec3::ZERO, None),
        };
        FirstHit {
            albedo,
            depth: hit.t(),
            strand,
        }
    }

    /// Emission met by a ray: lights at infinity when it escapes, rect lights nearer than
    /// its hit.
    fn emission(&self, org: Vec3, dir: Vec3, t_hit: f32, came: Came, strategy: Strategy) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for (i, light) in self.lights.iter().enumerate() {
            let Some(e) = emitted(light, org, dir, t_hit) else {
                continue;
            };
            // A light never chosen for next-event estimation is found only this way.
            let light_pdf = self.choice_pdf(i) * e.pdf;
            let weight = match (came, strategy) {
                (Came::Camera, _) | (_, Strategy::BsdfOnly) => 1.0,
                _ if light_pdf == 0.0 => 1.0,
                (_, Strategy::LightOnly) => 0.0,
                // `sampled_light_along` saw this light, so the pdf is there.
                (Came::Bsdf { pdf }, Strategy::Mis) if pdf > 0.0 => {
                    power_heuristic(1.0, pdf, 1.0, light_pdf)
                }
                (Came::Bsdf { .. }, Strategy::Mis) => 1.0,
            };
            sum += e.radiance * weight;
        }
        sum
    }

    /// Whether the ray (org, dir) may meet, at any distance, a light that next-event
    /// estimation samples: the cases where [`Self::emission`] needs the BSDF's pdf.
    fn sampled_light_along(&self, org: Vec3, dir: Vec3) -> bool {
        self.light_choice.is_some()
            && self.lights.iter().enumerate().any(|(i, light)| {
                self.choice_pdf(i) > 0.0
                    && emitted(light, org, dir, f32::INFINITY).is_some_and(|e| e.pdf > 0.0)
            })
    }

    fn choice_pdf(&self, light: usize) -> f32 {
        self.light_prob[light]
    }

    /// Next-event estimation: one light, chosen by power, one direction toward it.
    /// Returns the contribution to the pixel of the path of throughput `beta`, and the
    /// number of shadow rays traced (0 or 1).
    fn direct(
        &self,
        hit: &Hit,
        shading: &Shading,
        beta: Vec3,
        u: LightU,
        settings: &PathSettings,
    ) -> (Vec3, u32) {
        let none = (Vec3::ZERO, 0);
        let Some(choice) = &self.light_choice else {
            return none;
        };
        let (_, _, index) = choice.sample(u.choice);
        let (Some(light), choice_pdf) = (self.lights.get(index), self.choice_pdf(index)) else {
            return none;
        };
        let Some(ls) = light.sample_li(hit.p(), u.point) else {
            return none;
        };
        if ls.pdf.is_nan() || ls.pdf <= 0.0 || ls.radiance == Vec3::ZERO {
            return none;
        }
        let light_pdf = ls.pdf * choice_pdf;
        let weight = |bsdf_pdf: f32| {
            if ls.is_delta || settings.strategy == Strategy::LightOnly {
                1.0
            } else {
                power_heuristic(1.0, light_pdf, 1.0, bsdf_pdf)
            }
        };
        // Across the fibre each offset takes its own MIS weight: the BSDF-sampled ray
        // that pairs with it comes from the hit's offset, which is any of them alike.
        let f_cos = shading.light_eval(ls.wi, weight);
        if f_cos == Vec3::ZERO {
            return none;
        }
        let mut contribution = beta * f_cos * ls.radiance / light_pdf;
        let largest = contribution.max_element();
        // A degenerate (NaN) contribution traces nothing, as a zero one.
        if largest.is_nan() || largest <= 0.0 {
            return none;
        }
        if largest < settings.light_threshold {
            // A survivor's largest channel becomes the threshold: no fireflies. The floor
            // keeps the survival probability one that `u` (a multiple of 2^-24) can draw.
            let survive = (largest / settings.light_threshold).max(MIN_SHADOW_SURVIVAL);
            if u.roulette >= survive {
                return none;
            }
            contribution /= survive;
        }
        let tfar = if ls.distance.is_finite() {
            ls.distance * (1.0 - 1e-4)
        } else {
            f32::INFINITY
        };
        if self
            .tracer
            .occluded_spawned(&self.tracer.spawn(hit, ls.wi, tfar))
        {
            return (Vec3::ZERO, 1);
        }
        (contribution, 1)
    }
}

/// What one camera sample brings its pixel.
#[derive(Debug, Clone, Copy)]
pub struct CameraSample {
    pub radiance: Vec3,
    /// What its first hit reports for the AOVs (None where it escaped, or where no AOV is
    /// asked for).
    pub first: Option<FirstHit>,
    /// Rays traced.
    pub rays: u32,
    /// What its ray met first ([`Seen::Split`] for a sample of several).
    pub seen: Seen,
}

/// The numbers of one light sample: which light, where on it, and the shadow-ray
/// roulette.
struct LightU {
    choice: f32,
    point: [f32; 2],
    roulette: f32,
}

/// How the ray a path traces was made.
#[derive(Debug, Clone, Copy)]
enum Came {
    /// From the camera: emission is seen with full weight.
    Camera,
    /// By BSDF sampling. `pdf` is its density, for MIS, where the ray may meet a light
    /// that next-event estimation samples; 0 elsewhere (a sampled direction's density is
    /// never 0). A plain number rather than an Option, whose unset payload memcheck sees
    /// as read when the compiler merges the match's branches.
    Bsdf { pdf: f32 },
}

/// What `light` emits toward `org` along `dir` if the ray reaches it: a light at infinity
/// when the ray's hit is at infinity, a rect when it is nearer.
fn emitted(light: &Light, org: Vec3, dir: Vec3, t_hit: f32) -> Option<LightEval> {
    let reached = if light.is_infinite() {
        t_hit == f32::INFINITY
    } else {
        light.intersect(org, dir).is_some_and(|t| t < t_hit)
    };
    reached
        .then(|| light.eval_li(org, dir.normalize()))
        .flatten()
}

/// A direction drawn at a vertex: in world and local frames, with its path weight.
struct VertexSample {
    wi: Vec3,
    local: Vec3,
    weight: Vec3,
}

/// A BSDF at a path vertex with its local frame: world directions go through the frame
/// once, here, whatever the material.
struct Shading<'a> {
    frame: Frame,
    point: Point<'a>,
    /// Next-event estimation weighs a light by the hair BSDF across the fibre
    /// (`HairPoint::eval_across`).
    across: bool,
}

/// The BSDF at the vertex, its (h, wo) work done once and shared by next-event estimation
/// and BSDF sampling.
enum Point<'a> {
    Hair(HairPoint<'a>),
    /// Boxed: a far-field point holds the paths of several offsets.
    Huang(Box<HuangPoint>),
    Diffuse(DiffusePoint),
}

/// The Huang model's field at a hair vertex: far where lights are sampled, at
/// `LIT_SHIFTS` offsets (each light sample's value is the point's estimate of the BSDF);
/// near on a strand wider than its pixel (`thin` false), whose highlights the image
/// resolves. A thin vertex that samples no light scatters by the far field too, but its
/// only use is one drawn direction weighted by the offset and lobe that drew it
/// (`HuangPoint::sample_weight`): that is the far field sampled at one offset drawn
/// uniformly, and the hit's own h, uniform across the fibre, is such an offset, so the near
/// point at h is that draw without the other offsets' cost (docs/measurements.md, "The
/// Huang model").
pub(crate) fn huang_field(thin: bool, sample_light: bool) -> HuangField {
    match (thin, sample_light) {
        (true, true) => HuangBsdf::far_lit,
        _ => HuangBsdf::near,
    }
}

/// The Huang model's jitter at a hit (`HuangBsdf::near`): two numbers hashed from the
/// bounce's own, so that the pixel sampler's sequence keeps its layout for every model.
fn jitter(u_rr: f32, u_lobe: f32, events: u32) -> [f32; 2] {
    hashed_pair([u_rr, u_lobe], u64::from(events))
}

impl<'a> Shading<'a> {
    fn hair(h: &HairHit, bsdf: &'a HairBsdf, wo_world: Vec3, lobes: Lobes, across: bool) -> Self {
        Shading {
            frame: h.frame,
            point: Point::Hair(bsdf.at_lobes(h.h, h.frame.to_local(wo_world), lobes)),
            across,
        }
    }

    /// The Huang model at a hair hit, in `field`.
    fn huang(
        h: &HairHit,
        bsdf: &HuangBsdf,
        wo_world: Vec3,
        field: HuangField,
        jitter: [f32; 2],
    ) -> Self {
        let wo = h.frame.to_local(wo_world);
        let major = h.major_axis();
        let point = field(bsdf, h.h, wo, major, jitter);
        Shading {
            frame: h.frame,
            point: Point::Huang(Box::new(point)),
            across: false,
        }
    }

    fn diffuse(s: &SurfaceHit, bsdf: Diffuse, wo_world: Vec3) -> Self {
        let frame = Frame::from_z(s.ns);
        Shading {
            frame,
            point: Point::Diffuse(bsdf.at(frame.to_local(wo_world))),
            across: false,
        }
    }

    fn local(&self) -> &dyn LocalBsdf {
        match &self.point {
            Point::Hair(p) => p,
            Point::Huang(p) => p.as_ref(),
            Point::Diffuse(p) => p,
        }
    }

    /// f * |cos| toward the world direction wi of a light sample, each evaluation
    /// weighted by `mis` of its pdf: across the fibre where the shading point says so (the
    /// mean of the offsets' weighted values), at the hit's offset elsewhere.
    fn light_eval(&self, wi: Vec3, mis: impl Fn(f32) -> f32) -> Vec3 {
        let local = self.frame.to_local(wi);
        let across = match &self.point {
            Point::Hair(p) if self.across => p.eval_across(local),
            _ => None,
        };
        let f = match across {
            Some(a) => {
                let sum =
                    (a.f.iter().zip(a.pdf)).fold(Vec3::ZERO, |sum, (&f, pdf)| sum + f * mis(pdf));
                sum / ACROSS as f32
            }
            None => {
                let e = self.local().eval(local);
                e.f * mis(e.pdf)
            }
        };
        f * local.z.abs()
    }

    /// A direction and its path weight ([`LocalBsdf::sample_weight`]).
    fn sample(&self, u: [f32; 3]) -> Option<VertexSample> {
        let s = self.local().sample_weight(u)?;
        Some(VertexSample {
            wi: self.frame.to_world(s.wi),
            local: s.wi,
            weight: s.weight,
        })
    }

    /// The BSDF pdf of the local direction `local`.
    fn pdf(&self, local: Vec3) -> f32 {
        self.local().eval(local).pdf
    }
}

/// Applies the indirect clamp to a contribution that reached the camera after `events`
/// scattering events: 0 is light seen directly, 1 direct lighting (by either strategy),
/// 2 and more indirect light, the only kind clamped.
fn clamp(c: Vec3, events: u32, settings: &PathSettings) -> Vec3 {
    match settings.clamp_indirect {
        Some(max) if events > 1 => {
            let y = luminance(c);
            if y > max { c * (max / y) } else { c }
        }
        _ => c,
    }
}
