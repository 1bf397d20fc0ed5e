//! Real grooms' bias: on every real-groom bench scene (grooms made with Blender's hair
//! tools, written on demand by bench/real_grooms.py), the default curves (`auto`, with its
//! level of detail and parts) against full-detail round tubes, as block means against the
//! noise of two seeds a side (`hairtrace::image::block_bias`, what `hairtrace bias` runs).

use super::markdown::{num, table};
use super::render::{Built, Variant};
use super::{Context, all_scene_names, bench_scene};
use hairtrace::Result;
use hairtrace::description::{GroomSource, MeshSource, SceneDescription};
use hairtrace::image::{BlockBias, block_bias};
use hairtrace::scene::GroomShape;

/// Seeds of each side; none is a timed render's or a reference's.
const SEEDS: [u64; 2] = [2_000_003, 2_000_004];

/// Side of a block, in pixels.
const BLOCK: usize = 8;

/// Frames smaller than this many pixels (the close-ups) render at four times their scene's
/// spp: they are cheap, and more samples sharpen the blocks' test. Larger ones (the 1080p
/// frames) render at a quarter of it, as their round tubes take minutes a render.
const SMALL_FRAME: u32 = 100_000;

/// The real-groom scenes whose files are made, and those that are not.
fn scenes(ctx: &Context) -> Result<(Vec<String>, Vec<String>)> {
    let (mut made, mut missing) = (Vec::new(), Vec::new());
    for name in all_scene_names(ctx)?
        .into_iter()
        .filter(|n| n.starts_with("real_"))
    {
        if files_exist(&bench_scene(ctx, &name)?) {
            made.push(name);
        } else {
            missing.push(name);
        }
    }
    // Quick: one close-up, which shows the section works.
    if ctx.quick {
        made.retain(|n| n.contains("_close_"));
        made.truncate(1);
    }
    Ok((made, missing))
}

fn files_exist(desc: &SceneDescription) -> bool {
    let grooms = desc.grooms.iter().all(|g| match &g.source {
        GroomSource::File { path, .. } => path.is_file(),
        _ => true,
    });
    let meshes = desc.meshes.iter().all(|m| match &m.source {
        MeshSource::File(path) => path.is_file(),
        _ => true,
    });
    grooms && meshes
}

pub fn steps(ctx: &Context) -> u64 {
    scenes(ctx).map_or(1, |(made, _)| (made.len() * 2 * SEEDS.len()) as u64)
}

/// `desc` at its measured size: quick, an eighth of each side at 2 spp.
fn sized(ctx: &Context, mut desc: SceneDescription) -> SceneDescription {
    let r = &mut desc.render;
    if ctx.quick {
        r.width = (r.width / 8).max(16);
        r.height = (r.height / 8).max(16);
        r.spp = 2;
    } else if r.width * r.height < SMALL_FRAME {
        r.spp *= 4;
    } else {
        r.spp = (r.spp / 4).max(1);
    }
    desc
}

/// Two seeds of `desc` with every groom of `shape`.
fn renders(
    ctx: &Context,
    name: &str,
    desc: &SceneDescription,
    shape: GroomShape,
) -> Result<Vec<hairtrace::image::Image>> {
    let mut desc = desc.clone();
    desc.grooms.iter_mut().for_each(|g| g.shape = shape);
    let spp = desc.render.spp;
    let mut built = Built::new(&Variant { desc })?;
    SEEDS
        .iter()
        .map(|&seed| {
            ctx.step(format!("real grooms: {name}, {shape:?}, seed {seed}"));
            let (image, ..) = built.render(spp, seed)?;
            ctx.done();
            Ok(image)
        })
        .collect()
}

fn row(name: &str, desc: &SceneDescription, b: &BlockBias) -> Vec<String> {
    vec![
        name.to_string(),
        format!(
            "{}x{} x {} spp",
            desc.render.width, desc.render.height, desc.render.spp
        ),
        b.blocks.to_string(),
        num(b.z_rms, 3),
        format!("{:.1}%", 100.0 * b.over_two),
        num(b.z_max, 3),
        format!(
            "{:+.3}% ± {:.3}%",
            100.0 * b.mean_difference,
            100.0 * b.mean_difference_sigma
        ),
        if b.within_noise() { "yes" } else { "**no**" }.to_string(),
    ]
}

pub fn section(ctx: &Context) -> Result<String> {
    let (made, missing) = scenes(ctx)?;
    let mut text = format!(
        "The default curves (`auto`: ribbons where a strand is under a pixel, its level of \
         detail, lazy parts) against full-detail round tubes on the grooms made with \
         Blender's hair tools (bench/README.md, \"Real grooms\"), each scene as written \
         (close-ups at 4x its spp, 1080p frames at a quarter), {} seeds a side that no \
         other render uses. Each {BLOCK}x{BLOCK} block's mean difference is divided by its noise (the seeds' \
         per-pixel variances summed over the block, calibrated once per frame by the \
         blocks' own seed-to-seed scatter, so that a filter's correlation between pixels \
         is counted): without bias the z-scores' rms is about 1 (below it where the noise \
         is heavy-tailed, as fireflies make it) and 4.6% of blocks are over 2. Within \
         noise: at most that share plus three binomial deviations over 2, and the frame's \
         mean within three of its deviations.\n\n",
        SEEDS.len()
    );
    if made.is_empty() {
        text += "Not measured: the real grooms are not made on this machine \
                 (`bench/real_grooms.py` writes them with Blender's `bpy`; `bench/peer` \
                 makes them on its first run).\n";
        return Ok(text);
    }
    let mut rows = Vec::new();
    for name in &made {
        let desc = sized(ctx, bench_scene(ctx, name)?);
        let auto = renders(ctx, name, &desc, GroomShape::Auto)?;
        let round = renders(ctx, name, &desc, GroomShape::Round)?;
        rows.push(row(name, &desc, &block_bias(&auto, &round, BLOCK)?));
    }
    text += &table(
        &[
            "scene",
            "size",
            "blocks",
            "z rms",
            "over 2",
            "z max",
            "frame mean, auto vs round",
            "within noise",
        ],
        &rows,
    );
    if !missing.is_empty() {
        text += &format!("\nNot made on this machine: {}.\n", missing.join(", "));
    }
    Ok(text)
}
