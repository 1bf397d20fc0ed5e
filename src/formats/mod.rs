//! Every file format hairtrace reads or writes, one module each: TOML scene files
//! (`toml_scene`), pbrt-v4 scenes (`pbrt`), USD grooms (`usd`), Cem Yuksel's `.hair`
//! (`hair`), OBJ and PLY meshes (`mesh`), the conversion between `.hair` and USD
//! (`convert`), and the up axes and units files are written in (`units`). [`SceneDescription::load`] picks the reader for a path, so that every
//! front end opens a file the same way.

pub mod convert;
pub mod hair;
pub mod mesh;
pub mod pbrt;
mod toml_scene;
pub mod units;
pub mod usd;

use std::io::Read;
use std::path::Path;

use crate::description::{SceneDescription, has_extension, quick_look};
use crate::error::{Error, Result, invalid_arg};

/// The kinds of file [`SceneDescription::load`] opens.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SceneFormat {
    /// A TOML scene file (`[render]`, `[camera]`, `[[groom]]`, ...).
    Toml,
    /// A pbrt-v4 scene.
    Pbrt,
    /// A USD stage of `BasisCurves` grooms (.usda, .usdc, .usdz), rendered as a quick look.
    Usd,
    /// A bare `.hair` groom, rendered as a quick look.
    Hair,
}

impl SceneFormat {
    /// The format of the file at `path`: by the file's signature where it has one (`.hair`'s
    /// `HAIR`, USD's `PXR-USDC` and `#usda`), which a misnamed file cannot hide (a USD stage
    /// must still carry a USD extension, which its reader needs); else by the extension
    /// (`.toml`, `.pbrt`, `.usd*`, `.hair`); else, for a text file with another name, TOML
    /// when a line opens a `[table]` or sets a `key =`, pbrt when its first word is a
    /// capitalised directive.
    pub fn of(path: &Path) -> Result<SceneFormat> {
        let mut head = Vec::with_capacity(4096);
        std::fs::File::open(path)
            .and_then(|f| f.take(4096).read_to_end(&mut head))
            .map_err(|e| Error::io(path, e))?;
        if head.starts_with(b"HAIR") {
            return Ok(SceneFormat::Hair);
        }
        let usd_name = usd::is_usd_path(path);
        if head.starts_with(b"PXR-USDC") || head.starts_with(b"#usda") {
            // The USD library picks its file format by the extension alone.
            return match usd_name {
                true => Ok(SceneFormat::Usd),
                false => Err(invalid_arg!(
                    "{}: a USD stage (by its first bytes): name it .usd, .usda or .usdc, as \
                     the USD reader needs",
                    path.display()
                )),
            };
        }
        if usd_name {
            return Ok(SceneFormat::Usd);
        }
        for (ext, format) in [
            ("toml", SceneFormat::Toml),
            ("pbrt", SceneFormat::Pbrt),
            ("hair", SceneFormat::Hair),
        ] {
            if has_extension(path, ext) {
                return Ok(format);
            }
        }
        Self::of_text(&String::from_utf8_lossy(&head)).ok_or_else(|| {
            invalid_arg!(
                "{}: cannot tell the file's format: name it .toml, .pbrt, .usd, .usda, .usdc, \
                 .usdz or .hair",
                path.display()
            )
        })
    }

    /// TOML or pbrt, from the first line that is neither blank nor a comment.
    fn of_text(text: &str) -> Option<SceneFormat> {
        let line = text
            .lines()
            .map(str::trim)
            .find(|l| !l.is_empty() && !l.starts_with('#'))?;
        let word: String = line.chars().take_while(|c| c.is_alphanumeric()).collect();
        if line.starts_with('[') || line.split_once('=').is_some_and(|(k, _)| !k.contains('"')) {
            Some(SceneFormat::Toml)
        } else if word.starts_with(|c: char| c.is_ascii_uppercase()) {
            Some(SceneFormat::Pbrt)
        } else {
            None
        }
    }
}

impl SceneDescription {
    /// Reads the scene at `path` with the reader for its format ([`SceneFormat::of`]): a
    /// TOML or pbrt scene as it is written, a bare `.hair` or USD groom as a quick look (an
    /// automatic camera, a sky and a key light). What a reader could not carry over is in
    /// [`SceneDescription::notes`].
    ///
    /// ```no_run
    /// # fn main() -> hairtrace::Result<()> {
    /// let scene = hairtrace::SceneDescription::load("groom.usdc".as_ref())?;
    /// for note in &scene.notes {
    ///     eprintln!("warning: {note}");
    /// }
    /// # Ok(()) }
    /// ```
    pub fn load(path: &Path) -> Result<SceneDescription> {
        match SceneFormat::of(path)? {
            SceneFormat::Toml => SceneDescription::from_file(path),
            SceneFormat::Pbrt => {
                let pbrt = pbrt::PbrtScene::from_file(path)?;
                let mut description = pbrt.description;
                description.notes = pbrt.warnings.iter().map(ToString::to_string).collect();
                if let Some(name) = &pbrt.film_filename {
                    description.notes.push(format!(
                        "the file's Film filename {} is not used: the caller names the image",
                        name.display()
                    ));
                }
                Ok(description)
            }
            SceneFormat::Usd | SceneFormat::Hair => quick_look(path),
        }
    }
}

#[cfg(test)]
mod tests;
