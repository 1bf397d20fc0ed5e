//! The Huang model in the renderer: its exact pdf lets MIS, light sampling and BSDF
//! sampling estimate the same image, near and far field (a thick and a thin fur ball),
//! and its non-absorbing fur in a white furnace stays finite and below 1 by the model's
//! own loss.

use super::render::{
    assert_quadrants_agree, camera, fur_world, lit_lights, mean, quadrant_means_over,
    quadrant_settings,
};
use crate::render::renderer::render;
use crate::render::settings::{PathSettings, RenderSettings, Strategy};
use crate::render::{Aovs, NoProgress};
use crate::scene::envmap::Environment;
use crate::scene::light::Light;
use crate::scene::material::{HairColor, HairMaterial, HairModel};
use glam::Vec3;

fn huang(sigma_a: [f32; 3]) -> HairMaterial {
    HairMaterial {
        color: HairColor::SigmaA(sigma_a),
        model: HairModel::Huang {
            roughness: 0.3,
            aspect: 0.65,
        },
        ..HairMaterial::default()
    }
}

/// Light-only, BSDF-only and MIS agree quadrant by quadrant (4 standard errors), which
/// they do only if the pdf MIS weighs with is the sampler's.
#[test]
fn huang_mis_agrees_with_light_and_bsdf_sampling() {
    let world = fur_world(
        huang(HairMaterial::default().color.sigma_a(0.3).unwrap()),
        lit_lights(),
        2000,
    );
    let means = |strategy| {
        quadrant_means_over(
            &world,
            quadrant_settings(PathSettings {
                strategy,
                max_depth: 3,
                ..PathSettings::default()
            }),
            32,
        )
    };
    let mis = means(Strategy::Mis);
    for other in [Strategy::LightOnly, Strategy::BsdfOnly] {
        assert_quadrants_agree(&format!("huang, MIS vs {other:?}"), &mis, &means(other));
    }
}

#[test]
fn huang_white_fur_in_a_white_furnace() {
    let env = Light::Environment(Environment::uniform(Vec3::ONE).unwrap());
    let world = fur_world(huang([0.0; 3]), vec![env], 2000);
    let settings = RenderSettings {
        width: 32,
        height: 32,
        spp: 16,
        ..RenderSettings::default()
    };
    let out = render(&world, &camera(), &settings, Aovs::default(), &NoProgress).unwrap();
    let rgb = out.film.rgb();
    assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0));
    let m = mean(rgb);
    println!("huang white fur ball in a white furnace: mean {m:.4}");
    assert!(m > 0.3 && m < 1.01, "{m}");
}

/// The field each vertex takes (`integrator::huang_field`): far with the lit offsets at
/// every thin vertex where lights are sampled, near wherever none is (one offset drawn per
/// sample: the far field's draw) and on strands wider than their pixel. Fails if the rule
/// the measurements chose changes.
#[test]
fn each_vertex_takes_the_field_the_measurements_chose() {
    use crate::bsdf::{HuangBsdf, HuangParams};
    use crate::render::integrator::huang_field;
    let bsdf = HuangBsdf::new(&HuangParams::default()).unwrap();
    let (h, wo, major, jitter) = (
        0.3,
        Vec3::new(0.2, 0.5, 0.8).normalize(),
        glam::Vec2::X,
        [0.4, 0.7],
    );
    let point =
        |field: crate::bsdf::HuangField| format!("{:?}", field(&bsdf, h, wo, major, jitter));
    let (near, lit) = (point(HuangBsdf::near), point(HuangBsdf::far_lit));
    assert!(near != lit);
    for (thin, lights, expected) in [
        (true, true, &lit),
        (true, false, &near),
        (false, true, &near),
        (false, false, &near),
    ] {
        let got = point(huang_field(thin, lights));
        assert_eq!(&got, expected, "thin {thin}, lights sampled {lights}");
    }
}
