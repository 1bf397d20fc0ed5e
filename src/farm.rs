//! What a render farm needs of hairtrace beyond `crop`: one rule that splits a frame into
//! tiles (tile I of N is the same window on every machine), the header that says what
//! rendered an image, and the assembly of a frame from its tiles, which refuses tiles that
//! do not belong together rather than pasting a frame no single render would give.
//!
//! A tile is an EXR whose data window is its crop of the full frame and whose header holds
//! [`header`](crate::farm::header)'s `hairtrace:*` attributes. Assembly checks that every
//! tile is there, holds the window the rule gives it, and agrees with the others on every
//! attribute but the window, so that the frame it writes is bit for bit the whole-frame
//! render (docs/farm.md).

use std::path::{Path, PathBuf};

use crate::embree::Isa;
use crate::error::{Result, invalid_arg};
use crate::image::{self, Image, Placement, WriteOptions};
use crate::render::settings::RenderSettings;

/// The prefix of the header attributes hairtrace writes.
pub const PREFIX: &str = "hairtrace:";

/// Attributes that differ between the tiles of one frame: the window and the tile number.
const PER_TILE: [&str; 2] = ["crop", "tile"];

/// The window `[x0, y0, x1, y1)` of tile `index` (from 1) of `count` tiles of a `width` x
/// `height` frame: a grid of rows x columns, rows the largest divisor of `count` not above
/// its square root, numbered along rows from the top left. Every tile has at least one
/// pixel, and the tiles cover the frame once.
pub fn tile_window(width: u32, height: u32, index: u32, count: u32) -> Result<[u32; 4]> {
    if count == 0 || index == 0 || index > count {
        return Err(invalid_arg!(
            "tile {index} of {count}: the tiles are numbered from 1 to their count"
        ));
    }
    let rows = (1..=count)
        .take_while(|r| r * r <= count)
        .filter(|r| count % r == 0)
        .last()
        .unwrap_or(1);
    let cols = count / rows;
    if cols > width || rows > height {
        return Err(invalid_arg!(
            "{count} tiles ({cols} x {rows}) do not fit a {width}x{height} frame"
        ));
    }
    let (row, col) = ((index - 1) / cols, (index - 1) % cols);
    let cut =
        |size: u32, parts: u32, i: u32| (u64::from(size) * u64::from(i) / u64::from(parts)) as u32;
    Ok([
        cut(width, cols, col),
        cut(height, rows, row),
        cut(width, cols, col + 1),
        cut(height, rows, row + 1),
    ])
}

/// `path` with `.TAG` before its extension: `frame.exr` -> `frame.TAG.exr`.
pub fn tagged_path(path: &Path, tag: &str) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let name = match path.extension() {
        Some(ext) => format!("{stem}.{tag}.{}", ext.to_string_lossy()),
        None => format!("{stem}.{tag}"),
    };
    path.with_file_name(name)
}

/// Where tile `index` of `count` of the frame `frame` is written: `frame.tile-2-of-4.exr`.
pub fn tile_path(frame: &Path, index: u32, count: u32) -> PathBuf {
    tagged_path(frame, &format!("tile-{index}-of-{count}"))
}

/// `pattern` with the run of `#` in its file name replaced by `frame`, zero-padded to the
/// run's length: `out/frame.####.exr` and 7 give `out/frame.0007.exr`.
pub fn frame_path(pattern: &Path, frame: u32) -> Result<PathBuf> {
    let name = pattern.file_name().unwrap_or_default().to_string_lossy();
    let start = name.find('#');
    let end = start.map(|s| s + name[s..].find(|c| c != '#').unwrap_or(name.len() - s));
    match (start, end) {
        (Some(s), Some(e)) if !name[e..].contains('#') => Ok(pattern.with_file_name(format!(
            "{}{frame:0width$}{}",
            &name[..s],
            &name[e..],
            width = e - s
        ))),
        _ => Err(invalid_arg!(
            "{}: a frame's path needs one run of # in its file name for the frame number \
             (frame.####.exr)",
            pattern.display()
        )),
    }
}

/// The header of an image rendered with `settings` from `scene` (a name for the scene,
/// the same on every machine): every setting that changes pixels (all but `threads`), the
/// Embree kernels the render ran (the pinned ISA, or the widest this CPU offers), the scene
/// and the hairtrace version, each as `hairtrace:NAME`. Tiles that agree on all of them
/// but the window assemble bit for bit.
pub fn header(settings: &RenderSettings, scene: &str) -> Vec<(String, String)> {
    let kernels = settings.isa.or_else(Isa::widest_here);
    let mut out: Vec<(String, String)> = RenderSettings::schema()
        .iter()
        .filter(|s| s.name != "threads")
        .filter_map(|s| Some((s.name.to_owned(), settings.get(s.name).ok()?)))
        .collect();
    out.extend([
        (
            "kernels".to_owned(),
            kernels.map_or("none", Isa::name).to_owned(),
        ),
        ("scene".to_owned(), scene.to_owned()),
        ("version".to_owned(), crate::VERSION.to_owned()),
    ]);
    out.into_iter()
        .map(|(name, value)| (format!("{PREFIX}{name}"), value))
        .collect()
}

/// An assembled frame's size and tile count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Assembled {
    pub width: u32,
    pub height: u32,
    pub tiles: u32,
}

/// Reads the `count` tiles of `frame` (at [`tile_path`]), checks that they make one frame,
/// and writes it to `frame` (under a temporary name, then renamed), with the tiles' header
/// and `crop` = none: the header of the whole-frame render. A missing tile, one holding
/// another window, or one whose header disagrees with the first tile's is refused, and the
/// error names the tile and the attribute.
pub fn assemble(frame: &Path, count: u32) -> Result<Assembled> {
    if !frame
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        return Err(invalid_arg!(
            "{}: a frame assembled from tiles is an EXR (float pixels, and the header that \
             says what rendered them)",
            frame.display()
        ));
    }
    image::check_output_path(frame)?;
    let mut first: Option<(PathBuf, Vec<(String, String)>)> = None;
    let mut pixels = Vec::new();
    let mut size = (0, 0, 0);
    for index in 1..=count.max(1) {
        let path = tile_path(frame, index, count);
        let tile = image::read_image(&path)
            .map_err(|e| e.context(format_args!("tile {index} of {count}")))?;
        let own = identity(&tile);
        if own.is_empty() {
            return Err(invalid_arg!(
                "tile {index} of {count}: {} has no {PREFIX}* attributes: it is not a tile \
                 hairtrace rendered",
                path.display()
            ));
        }
        let (first_path, reference) = first.get_or_insert_with(|| (path.clone(), own.clone()));
        if let Some(why) = disagreement(reference, &own) {
            return Err(invalid_arg!(
                "tile {index} of {count}: {} {why} {}: the tiles of a frame must come from \
                 one render (scene, settings, seed, ISA, hairtrace version)",
                path.display(),
                first_path.display()
            ));
        }
        let mut settings = RenderSettings::default();
        for key in ["width", "height"] {
            let value = tile.attribute(&format!("{PREFIX}{key}")).unwrap_or("");
            settings.set(key, value).map_err(|e| {
                e.context(format_args!("tile {index} of {count}: {}", path.display()))
            })?;
        }
        let (w, h) = (settings.width, settings.height);
        let want = tile_window(w, h, index, count)?;
        let p = tile.placement;
        let holds = [p.x, p.y, p.x + tile.width, p.y + tile.height].map(|v| v as u64);
        if holds != want.map(u64::from) || (p.full_width, p.full_height) != (w as usize, h as usize)
        {
            return Err(invalid_arg!(
                "tile {index} of {count}: {} holds the window {} of a {}x{} frame, but tile \
                 {index} of {count} of the {w}x{h} frame is {}",
                path.display(),
                holds.map(|v| v.to_string()).join(","),
                p.full_width,
                p.full_height,
                want.map(|v| v.to_string()).join(",")
            ));
        }
        if index == 1 {
            size = (w as usize, h as usize, tile.channels);
            pixels = vec![0.0f32; size.0 * size.1 * size.2];
        } else if tile.channels != size.2 {
            return Err(invalid_arg!(
                "tile {index} of {count}: {} has {} channels, tile 1 has {}",
                path.display(),
                tile.channels,
                size.2
            ));
        }
        paste(&mut pixels, size.0, &tile);
    }
    let (_, reference) = first.expect("at least one tile was read");
    let mut attributes: Vec<(String, String)> = reference
        .into_iter()
        .map(|(name, value)| (format!("{PREFIX}{name}"), value))
        .collect();
    attributes.push((format!("{PREFIX}crop"), "none".to_owned()));
    attributes.sort();
    let opts = WriteOptions {
        attributes,
        ..WriteOptions::default()
    };
    image::write_image(frame, size.0, size.1, size.2, &pixels, &opts)?;
    Ok(Assembled {
        width: size.0 as u32,
        height: size.1 as u32,
        tiles: count,
    })
}

/// A tile's `hairtrace:*` attributes but the per-tile ones, without the prefix, sorted.
fn identity(tile: &Image) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = tile
        .attributes
        .iter()
        .filter_map(|(n, v)| Some((n.strip_prefix(PREFIX)?.to_owned(), v.clone())))
        .filter(|(n, _)| !PER_TILE.contains(&n.as_str()))
        .collect();
    out.sort();
    out
}

/// How `own` differs from `reference`, as "has spp = 8, where 4 is in": the first
/// attribute (by name) that one lacks or that differs.
fn disagreement(reference: &[(String, String)], own: &[(String, String)]) -> Option<String> {
    let value = |list: &[(String, String)], name: &str| {
        list.iter().find(|(n, _)| n == name).map(|(_, v)| v.clone())
    };
    let mut names: Vec<&String> = reference.iter().chain(own).map(|(n, _)| n).collect();
    names.sort();
    names.dedup();
    names.into_iter().find_map(|name| {
        let (mine, theirs) = (value(own, name), value(reference, name));
        let show = |v: Option<String>| v.unwrap_or_else(|| "(absent)".into());
        (mine != theirs).then(|| {
            format!(
                "has {name} = {}, where {name} = {} is in",
                show(mine),
                show(theirs)
            )
        })
    })
}

/// Copies `tile`'s pixels into the frame `pixels` (rows of `width` pixels) at its place.
fn paste(pixels: &mut [f32], width: usize, tile: &Image) {
    let c = tile.channels;
    let Placement { x, y, .. } = tile.placement;
    for (row, line) in tile.pixels.chunks_exact(tile.width * c).enumerate() {
        let start = ((y + row) * width + x) * c;
        pixels[start..start + line.len()].copy_from_slice(line);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_frame_once_in_a_grid() {
        for (w, h, n) in [
            (96, 72, 4),
            (97, 73, 6),
            (7, 3, 7),
            (1, 1, 1),
            (640, 480, 12),
        ] {
            let mut seen = vec![0u8; (w * h) as usize];
            for i in 1..=n {
                let [x0, y0, x1, y1] = tile_window(w, h, i, n).unwrap();
                assert!(x0 < x1 && y0 < y1, "tile {i} of {n} of {w}x{h} is empty");
                for y in y0..y1 {
                    for x in x0..x1 {
                        seen[(y * w + x) as usize] += 1;
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "{w}x{h} in {n}");
        }
        assert_eq!(tile_window(96, 72, 2, 4).unwrap(), [48, 0, 96, 36]);
        assert_eq!(tile_window(96, 72, 3, 6).unwrap(), [64, 0, 96, 36]);
        for (i, n) in [(0, 4), (5, 4), (1, 0)] {
            assert!(tile_window(96, 72, i, n).is_err(), "{i} of {n}");
        }
        assert!(
            tile_window(4, 4, 1, 5)
                .unwrap_err()
                .to_string()
                .contains("do not fit")
        );
    }

    #[test]
    fn tile_paths_keep_the_extension() {
        assert_eq!(
            tile_path(Path::new("out/frame.0001.exr"), 2, 4),
            Path::new("out/frame.0001.tile-2-of-4.exr")
        );
        assert_eq!(tagged_path(Path::new("a"), "albedo"), Path::new("a.albedo"));
        let frame = |p: &str, f| frame_path(Path::new(p), f).map_err(|e| e.to_string());
        assert_eq!(frame("o/f.####.exr", 7).unwrap(), Path::new("o/f.0007.exr"));
        assert_eq!(frame("#.exr", 12345).unwrap(), Path::new("12345.exr"));
        assert!(frame("o#/f.exr", 1).unwrap_err().contains("one run of #"));
        assert!(frame("f.#.#.exr", 1).unwrap_err().contains("one run of #"));
    }

    #[test]
    fn the_header_names_what_changes_pixels_and_not_the_thread_count() {
        let s = RenderSettings {
            isa: Some(Isa::Sse2),
            threads: Some(3),
            ..RenderSettings::default()
        };
        let h = header(&s, "demo:furball");
        let get = |k: &str| h.iter().find(|(n, _)| n == k).map(|(_, v)| v.as_str());
        assert_eq!(get("hairtrace:spp"), Some("16"));
        assert_eq!(get("hairtrace:isa"), Some("sse2"));
        assert_eq!(get("hairtrace:kernels"), Some("sse2"));
        assert_eq!(get("hairtrace:scene"), Some("demo:furball"));
        assert_eq!(get("hairtrace:version"), Some(crate::VERSION));
        assert_eq!(get("hairtrace:threads"), None);
    }
}
