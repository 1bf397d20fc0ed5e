//! Materials a hair scene needs: the hair BSDF with its colour source and per-strand
//! variation, and a diffuse surface for scalps, heads and floors.

use crate::bsdf::diffuse::Diffuse;
use crate::bsdf::{
    HairBsdf, HairParams, HuangBsdf, HuangParams, sigma_a_from_color, sigma_a_from_melanin,
};
use crate::error::{Result, invalid_arg};
use crate::math::mix64;
use crate::validate::positive;

/// What a geometry is made of. A hair material holds its prepared BSDF, hence the box.
#[derive(Debug, Clone)]
pub enum Material {
    Hair(Box<PreparedHair>),
    Diffuse(Diffuse),
}

impl Material {
    /// Checks that the material suits the geometry: hair on curves (`on_curves`), diffuse
    /// on meshes. `what` names the material in the error.
    pub fn check_suits(&self, what: &str, on_curves: bool) -> Result<()> {
        check_kind(what, matches!(self, Material::Hair(_)), on_curves)
    }
}

/// Whether a material of its kind (`hair` or diffuse) suits curves (`on_curves`) or meshes:
/// [`Material::check_suits`] for a material not prepared yet.
pub(crate) fn check_kind(what: &str, hair: bool, on_curves: bool) -> Result<()> {
    match (hair, on_curves) {
        (true, true) | (false, false) => Ok(()),
        (false, true) => Err(invalid_arg!(
            "{what} is a diffuse material; curves need a hair material"
        )),
        (true, false) => Err(invalid_arg!(
            "{what} is a hair material; meshes need a diffuse material"
        )),
    }
}

/// Where a hair material's absorption comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HairColor {
    /// Absorption per unit fiber radius, linear RGB.
    SigmaA([f32; 3]),
    /// Eumelanin and pheomelanin concentrations.
    Melanin { eumelanin: f32, pheomelanin: f32 },
    /// A reflectance colour, inverted through beta_n (Chiang et al. 2016).
    Color([f32; 3]),
}

impl HairColor {
    /// The absorption it says, for a fibre of azimuthal roughness `beta_n` (which only a
    /// colour needs).
    pub fn sigma_a(self, beta_n: f32) -> Result<[f32; 3]> {
        match self {
            HairColor::SigmaA(s) => Ok(s),
            HairColor::Melanin {
                eumelanin,
                pheomelanin,
            } => sigma_a_from_melanin(eumelanin, pheomelanin),
            HairColor::Color(c) => sigma_a_from_color(c, beta_n),
        }
    }
}

/// Which hair model a material scatters with (docs/conventions.md, sections 4 and 4b).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum HairModel {
    /// Chiang et al. 2016, round fibres: `beta_m` and `beta_n` are its roughnesses.
    #[default]
    Chiang,
    /// Huang et al. 2022, elliptical fibres of GGX roughness `roughness` and minor over
    /// major axis `aspect`; `beta_m` is unused and `beta_n` only inverts a `color`.
    Huang { roughness: f32, aspect: f32 },
}

/// A hair material: the BSDF parameters plus how they vary over the groom. Variation is
/// deterministic: it depends only on the seed, the strand id and the position along it.
#[derive(Debug, Clone, PartialEq)]
pub struct HairMaterial {
    pub color: HairColor,
    pub eta: f32,
    pub beta_m: f32,
    pub beta_n: f32,
    /// Cuticle tilt, degrees.
    pub alpha: f32,
    /// Relative per-strand spread of the absorption (melanin), in [0, 1]: each strand's
    /// sigma_a is scaled by a factor drawn uniformly from [1 - x, 1 + x].
    pub absorption_variation: f32,
    /// Relative per-strand spread of both roughnesses, in [0, 1] (results are kept in
    /// the valid range [0.01, 1]).
    pub roughness_variation: f32,
    /// Absorption at the tip relative to the root, > 0 (below 1: lighter tips), varied
    /// linearly along the strand.
    pub tip_absorption: f32,
    /// Take the absorption from the groom where it gives one, in place of `color`: its
    /// per-point colours (inverted at `beta_n`) or its per-strand melanin (as it is).
    pub use_vertex_colors: bool,
    pub seed: u64,
    pub model: HairModel,
}

impl Default for HairMaterial {
    /// The default brown hair, with no variation.
    fn default() -> Self {
        let p = HairParams::default();
        HairMaterial {
            color: HairColor::SigmaA(p.sigma_a),
            eta: p.eta,
            beta_m: p.beta_m,
            beta_n: p.beta_n,
            alpha: p.alpha,
            absorption_variation: 0.0,
            roughness_variation: 0.0,
            tip_absorption: 1.0,
            use_vertex_colors: false,
            seed: 0,
            model: HairModel::Chiang,
        }
    }
}

/// The hair BSDFs of a material: one shared when nothing varies, else built per hit.
#[derive(Debug, Clone)]
pub struct PreparedHair {
    material: HairMaterial,
    base: HairParams,
    uniform: Option<HairBsdf>,
    /// The Huang model's BSDF when nothing varies (with [`HairModel::Huang`]).
    uniform_huang: Option<HuangBsdf>,
}

impl HairMaterial {
    /// The parameters every strand starts from ([`Self::varied`]'s `base`): the colour's
    /// absorption with the material's other values. Checked.
    pub(crate) fn base_params(&self) -> Result<HairParams> {
        let params = HairParams {
            sigma_a: self.color.sigma_a(self.beta_n)?,
            eta: self.eta,
            beta_m: self.beta_m,
            beta_n: self.beta_n,
            alpha: self.alpha,
        };
        params.validate()?;
        Ok(params)
    }

    /// Validates everything and precomputes what does not vary.
    pub fn prepare(&self) -> Result<PreparedHair> {
        let base = self.base_params()?;
        self.check_variation()?;
        let varies = self.absorption_variation > 0.0
            || self.roughness_variation > 0.0
            || self.tip_absorption != 1.0
            || self.use_vertex_colors;
        let uniform = if varies {
            None
        } else {
            Some(HairBsdf::new(&base)?)
        };
        let huang = self.huang_params(base, 1.0)?;
        let uniform_huang = match huang {
            Some(p) if !varies => Some(HuangBsdf::new(&p)?),
            _ => None,
        };
        Ok(PreparedHair {
            material: self.clone(),
            base,
            uniform,
            uniform_huang,
        })
    }

    /// The Huang model's parameters from (possibly varied) `p`, its roughness scaled by
    /// `roughness_factor` and kept in range; None for the Chiang model. Checked.
    fn huang_params(&self, p: HairParams, roughness_factor: f32) -> Result<Option<HuangParams>> {
        let HairModel::Huang { roughness, aspect } = self.model else {
            return Ok(None);
        };
        let params = HuangParams {
            sigma_a: p.sigma_a,
            eta: p.eta,
            roughness: if roughness_factor == 1.0 {
                roughness
            } else {
                (roughness * roughness_factor).clamp(0.01, 1.0)
            },
            aspect,
            alpha: p.alpha,
        };
        params.validate()?;
        Ok(Some(params))
    }
}

impl HairMaterial {
    /// Checks the variation's ranges (the parameters are checked with the base).
    pub(crate) fn check_variation(&self) -> Result<()> {
        for (name, v) in [
            ("absorption_variation", self.absorption_variation),
            ("roughness_variation", self.roughness_variation),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(invalid_arg!("{name} = {v}: must be in [0, 1]"));
            }
        }
        positive("tip_absorption", self.tip_absorption)
    }

    /// `base` (this material's valid parameters) varied as this material says at position
    /// s (root 0, tip 1) of `strand`, with the groom's absorption at the hit when it gives
    /// one ([`crate::scene::curves::StrandIndex::absorption`]). Always valid: the varied
    /// values are clamped into range.
    pub(crate) fn varied(
        &self,
        base: HairParams,
        strand: u32,
        s: f32,
        groom: Option<HairColor>,
    ) -> HairParams {
        let mut p = base;
        if let (true, Some(a)) = (self.use_vertex_colors, groom) {
            let a = match a {
                // Colours are validated into [0, 1]; black, which no finite absorption
                // makes, is taken as 1e-4 (documented with the colours of the C ABI and
                // scene files).
                HairColor::Color(c) => HairColor::Color(c.map(|v| v.max(1e-4))),
                other => other,
            };
            // The groom's values were validated with it: the fallback is never taken.
            p.sigma_a = a.sigma_a(p.beta_n).unwrap_or(p.sigma_a);
        }
        let [ua, ur] = strand_uniforms(self.seed, strand);
        let absorption = (1.0 + self.absorption_variation * (2.0 * ua - 1.0))
            * (1.0 + (self.tip_absorption - 1.0) * s.clamp(0.0, 1.0));
        p.sigma_a = p.sigma_a.map(|v| (v * absorption).min(f32::MAX));
        let roughness = self.roughness_factor(ur);
        p.beta_m = (p.beta_m * roughness).clamp(0.01, 1.0);
        p.beta_n = (p.beta_n * roughness).clamp(0.01, 1.0);
        p
    }

    /// The Huang model's parameters at position s (root 0, tip 1) of `strand`: `base` (this
    /// material's valid parameters, [`Self::base_params`]) varied as [`Self::varied`] varies
    /// them, the strand's roughness factor applied to the model's roughness. None for the
    /// Chiang model. The renderer's hits ([`PreparedHair::huang_at`]) and the C ABI's
    /// strand points both take their parameters from here.
    pub(crate) fn huang_varied(
        &self,
        base: HairParams,
        strand: u32,
        s: f32,
        groom: Option<HairColor>,
    ) -> Result<Option<HuangParams>> {
        let varied = self.varied(base, strand, s, groom);
        let [_, ur] = strand_uniforms(self.seed, strand);
        self.huang_params(varied, self.roughness_factor(ur))
    }

    /// The factor a strand's roughnesses are scaled by, from its uniform number `ur`.
    fn roughness_factor(&self, ur: f32) -> f32 {
        1.0 + self.roughness_variation * (2.0 * ur - 1.0)
    }
}

impl PreparedHair {
    /// Every hit shares one BSDF: nothing varies per strand, along strands or by the
    /// groom's absorption.
    pub fn is_uniform(&self) -> bool {
        self.uniform.is_some()
    }

    /// The parameters at position s (root 0, tip 1) of `strand`, with the groom's
    /// absorption at the hit when it gives one ([`crate::scene::curves::StrandIndex::absorption`]).
    pub fn params_at(&self, strand: u32, s: f32, groom: Option<HairColor>) -> HairParams {
        self.material.varied(self.base, strand, s, groom)
    }

    /// The BSDF at a hit: shared when the material is uniform.
    pub(crate) fn bsdf_at(
        &self,
        strand: u32,
        s: f32,
        groom: Option<HairColor>,
    ) -> std::borrow::Cow<'_, HairBsdf> {
        match &self.uniform {
            Some(b) => std::borrow::Cow::Borrowed(b),
            // The parameters are valid by construction (clamped into range).
            None => std::borrow::Cow::Owned(
                HairBsdf::new(&self.params_at(strand, s, groom))
                    .expect("varied parameters stay in range"),
            ),
        }
    }
}

impl PreparedHair {
    /// The Huang model's BSDF at a hit ([`Self::bsdf_at`]'s variation); None for a material
    /// of the Chiang model.
    pub(crate) fn huang_at(
        &self,
        strand: u32,
        s: f32,
        groom: Option<HairColor>,
    ) -> Option<HuangBsdf> {
        if let Some(b) = self.uniform_huang {
            return Some(b);
        }
        // Valid by construction: the base was checked, the variation is clamped into range.
        let p = self
            .material
            .huang_varied(self.base, strand, s, groom)
            .ok()??;
        HuangBsdf::new(&p).ok()
    }
}

/// Two uniform numbers in [0, 1) for a strand, from a 64-bit mix of (seed, strand).
fn strand_uniforms(seed: u64, strand: u32) -> [f32; 2] {
    let x = mix64(seed ^ (u64::from(strand).wrapping_mul(0x9E37_79B9_7F4A_7C15)));
    [
        (x >> 40) as f32 / (1u64 << 24) as f32,
        ((x >> 16) & 0xFF_FFFF) as f32 / (1u64 << 24) as f32,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_material_shares_one_bsdf() {
        let p = HairMaterial::default().prepare().unwrap();
        assert!(matches!(
            p.bsdf_at(3, 0.5, None),
            std::borrow::Cow::Borrowed(_)
        ));
        assert_eq!(p.params_at(7, 0.9, None), HairParams::default());
    }

    #[test]
    fn variation_is_deterministic_bounded_and_per_strand() {
        let m = HairMaterial {
            absorption_variation: 0.5,
            roughness_variation: 0.5,
            tip_absorption: 0.25,
            seed: 9,
            ..HairMaterial::default()
        };
        let p = m.prepare().unwrap();
        let base = HairParams::default();
        let a = p.params_at(1, 0.0, None);
        assert_eq!(a, p.params_at(1, 0.0, None));
        assert_ne!(a, p.params_at(2, 0.0, None));
        for strand in 0..1000 {
            let q = p.params_at(strand, 0.0, None);
            q.validate().unwrap();
            let k = q.sigma_a[0] / base.sigma_a[0];
            assert!((0.5 - 1e-6..=1.5 + 1e-6).contains(&k), "{k}");
            // Tips absorb a quarter of the root's.
            let tip = p.params_at(strand, 1.0, None);
            assert!((tip.sigma_a[2] / q.sigma_a[2] - 0.25).abs() < 1e-5);
        }
    }

    /// A groom's melanin is its absorption exactly, whatever beta_n, even for black hair
    /// (eumelanin 8), which no colour above 1e-4 can say; a colour is inverted at beta_n.
    /// Without `use_vertex_colors` the material's own absorption stays.
    #[test]
    fn groom_melanin_is_its_absorption_exactly() {
        let black = HairColor::Melanin {
            eumelanin: 8.0,
            pheomelanin: 0.0,
        };
        let want = sigma_a_from_melanin(8.0, 0.0).unwrap();
        for beta_n in [0.1, 0.3, 0.9] {
            let m = HairMaterial {
                beta_n,
                use_vertex_colors: true,
                ..HairMaterial::default()
            };
            let p = m.prepare().unwrap();
            assert_eq!(p.params_at(4, 0.6, Some(black)).sigma_a, want);
            let c = [0.2, 0.3, 0.4];
            assert_eq!(
                p.params_at(4, 0.6, Some(HairColor::Color(c))).sigma_a,
                sigma_a_from_color(c, beta_n).unwrap()
            );
            let own = HairMaterial {
                use_vertex_colors: false,
                ..m
            };
            let own = own.prepare().unwrap();
            assert_eq!(
                own.params_at(4, 0.6, Some(black)),
                p.params_at(4, 0.6, None)
            );
        }
    }

    #[test]
    fn vertex_colours_and_bad_values() {
        let m = HairMaterial {
            use_vertex_colors: true,
            ..HairMaterial::default()
        };
        let p = m.prepare().unwrap();
        let white = p.params_at(0, 0.3, Some(HairColor::Color([1.0; 3])));
        assert_eq!(white.sigma_a, [0.0; 3]);
        assert_eq!(
            p.params_at(0, 0.3, None).sigma_a,
            HairParams::default().sigma_a
        );
        let bad = HairMaterial {
            roughness_variation: 1.5,
            ..HairMaterial::default()
        };
        assert!(
            bad.prepare()
                .unwrap_err()
                .to_string()
                .contains("roughness_variation")
        );
        let bad = HairMaterial {
            tip_absorption: 0.0,
            ..HairMaterial::default()
        };
        assert!(
            bad.prepare()
                .unwrap_err()
                .to_string()
                .contains("tip_absorption")
        );
        let bad = HairMaterial {
            beta_m: 0.0,
            ..HairMaterial::default()
        };
        assert!(bad.prepare().unwrap_err().to_string().contains("beta_m"));
    }
}
