//! Gallery section: the classic parameter sweeps of the hair model on the fur ball, small
//! renders composed into one labelled contact sheet.

use super::markdown::figure;
use super::render::{Built, Variant, fewer_strands};
use super::{Context, bench_scene};
use hairtrace::bsdf::sigma_a_preset;
use hairtrace::description::MaterialDesc;
use hairtrace::image::{Image, srgb_encode};
use hairtrace::scene::{HairColor, HairMaterial};
use hairtrace::{Error, Result};
use plotters::prelude::*;

/// What one tile changes in the fur ball's hair (brown, melanin 1.3, beta_m = beta_n =
/// 0.3, tilt 2 degrees).
#[derive(Clone, Copy)]
enum Look {
    Roughness {
        beta_m: f32,
        beta_n: f32,
    },
    Preset(&'static str),
    /// A reflectance colour, inverted to sigma_a through beta_n (Chiang et al.).
    Color(f32),
    BetaN(f32),
    Alpha(f32),
    Melanin(f32),
}

/// The sheet, one row per sweep.
const ROWS: [&[Look]; 5] = [
    &[
        Look::Roughness {
            beta_m: 0.1,
            beta_n: 0.5,
        },
        Look::Roughness {
            beta_m: 0.6,
            beta_n: 0.5,
        },
    ],
    &[
        Look::Preset("red_brown"),
        Look::Preset("light_brown"),
        Look::Preset("dark_brown"),
        Look::Preset("black"),
        Look::Preset("white"),
        Look::Color(0.7),
    ],
    &[
        Look::BetaN(0.3),
        Look::BetaN(0.35),
        Look::BetaN(0.4),
        Look::BetaN(0.9),
    ],
    &[Look::Alpha(0.0), Look::Alpha(2.0), Look::Alpha(10.0)],
    &[Look::Melanin(0.3), Look::Melanin(1.3), Look::Melanin(8.0)],
];

impl Look {
    fn label(self) -> String {
        match self {
            Look::Roughness { beta_m, beta_n } => format!("beta_m {beta_m}, beta_n {beta_n}"),
            Look::Preset(name) => name.to_owned(),
            Look::Color(c) => format!("colour {c}"),
            Look::BetaN(b) => format!("beta_n {b}"),
            Look::Alpha(a) => format!("tilt {a} deg"),
            Look::Melanin(m) => format!("melanin {m}"),
        }
    }

    fn apply(self, m: &mut HairMaterial) -> Result<()> {
        match self {
            Look::Roughness { beta_m, beta_n } => (m.beta_m, m.beta_n) = (beta_m, beta_n),
            Look::Preset(name) => m.color = HairColor::SigmaA(sigma_a_preset(name)?),
            Look::Color(c) => m.color = HairColor::Color([c; 3]),
            Look::BetaN(b) => m.beta_n = b,
            Look::Alpha(a) => m.alpha = a,
            Look::Melanin(e) => {
                m.color = HairColor::Melanin {
                    eumelanin: e,
                    pheomelanin: 0.0,
                };
            }
        }
        Ok(())
    }
}

/// Tile size and samples.
fn tile(ctx: &Context) -> (u32, u32, u32) {
    if ctx.quick {
        (128, 96, 4)
    } else {
        (160, 120, 32)
    }
}

const LABEL_HEIGHT: u32 = 18;

pub fn steps(_: &Context) -> u64 {
    ROWS.iter().map(|r| r.len() as u64).sum::<u64>() + 1
}

/// One tile as 8-bit sRGB.
fn render_tile(ctx: &Context, look: Look) -> Result<Image> {
    let (w, h, spp) = tile(ctx);
    let mut desc = bench_scene(ctx, "demo_fur_ball")?;
    desc.render.width = w;
    desc.render.height = h;
    // Closer than the bench scene's framing: the ball fills the tile.
    desc.camera.fov_deg = 24.0;
    if ctx.quick {
        fewer_strands(&mut desc, 4);
    }
    for m in desc.materials.values_mut() {
        if let MaterialDesc::Hair(hair) = m {
            look.apply(hair)?;
        }
    }
    let (image, _, _) = Built::new(&Variant { desc })?.render(spp, 1)?;
    Ok(image)
}

pub fn section(ctx: &Context) -> Result<String> {
    let (w, h, spp) = tile(ctx);
    let columns = ROWS.iter().map(|r| r.len()).max().unwrap_or(1) as u32;
    let (sheet_w, sheet_h) = (columns * w, ROWS.len() as u32 * (h + LABEL_HEIGHT));
    let mut pixels = vec![255u8; (sheet_w * sheet_h * 3) as usize];
    let mut labels = Vec::new();
    for (row, looks) in ROWS.iter().enumerate() {
        for (col, &look) in looks.iter().enumerate() {
            ctx.step(format!("gallery: {}", look.label()));
            let image = render_tile(ctx, look)?;
            let (x0, y0) = (
                col as u32 * w,
                row as u32 * (h + LABEL_HEIGHT) + LABEL_HEIGHT,
            );
            for (i, rgb) in image.pixels.chunks_exact(3).enumerate() {
                let (x, y) = (x0 + i as u32 % w, y0 + i as u32 / w);
                let at = ((y * sheet_w + x) * 3) as usize;
                for (c, v) in rgb.iter().enumerate() {
                    pixels[at + c] = (srgb_encode(v.clamp(0.0, 1.0)) * 255.0).round() as u8;
                }
            }
            labels.push((look.label(), x0 + 4, y0 - LABEL_HEIGHT + 3));
            ctx.done();
        }
    }
    let file = "gallery.png";
    let path = ctx.path(file);
    let fail = |e: &dyn std::fmt::Display| Error::image(&path, e);
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (sheet_w, sheet_h)).into_drawing_area();
        for (text, x, y) in &labels {
            root.draw_text(
                text,
                &("sans-serif", 12).into_font().color(&BLACK),
                (*x as i32, *y as i32),
            )
            .map_err(|e| fail(&e))?;
        }
        root.present().map_err(|e| fail(&e))?;
    }
    crate::files::write_png(&path, &pixels, (sheet_w, sheet_h))?;
    ctx.step("gallery: sheet");
    ctx.done();
    let caption = ctx.machine.caption(
        ctx.machine.threads,
        &format!("demo_fur_ball bench scene, {w}x{h} per tile, {spp} spp, seed 1, box filter"),
    );
    Ok(format!(
        "The fur ball (the `demo_fur_ball` bench scene: 20k brown strands, melanin 1.3, \
         beta_m = beta_n = 0.3, tilt 2 degrees, a sky and a key light) with one hair \
         parameter changed per tile. Rows: longitudinal roughness beta_m 0.1 and 0.6 at \
         beta_n 0.5; the absorption presets, beside hair of reflectance colour 0.7 (the \
         library's curves take hair materials only, so a diffuse fur ball of albedo 0.7 is \
         shown as hair whose colour inverts to 0.7); azimuthal roughness beta_n; cuticle \
         tilt; eumelanin concentration.\n\n{}",
        figure(file, "gallery of hair parameters", &caption)
    ))
}
