//! `hairtrace farm`: a shot's frames x tiles as the jobs schedulers run. An Open Job
//! Description template (what AWS Deadline Cloud and `openjd run` take) and a Slurm
//! job-array script hold the same split: one task per tile runs `hairtrace render --tile
//! I/N` with the ISA pinned, then one task per frame runs `hairtrace assemble`, after every
//! tile has succeeded. Frame F is rendered with seed F, so that noise changes from frame
//! to frame as in an animation.

use std::path::{Path, PathBuf};

use hairtrace::embree::Isa;
use hairtrace::farm::{frame_path, tile_window};
use hairtrace::render::settings::RenderSettings;
use hairtrace::{Error, Result};

use crate::settings::SettingArgs;

/// The scene a job renders.
pub enum Scene {
    /// A file, by its absolute path.
    File(PathBuf),
    /// A built-in scene, by name.
    Demo(String),
}

/// Settings that are the job's parameters, or its tasks' own (seed, window), and so are not
/// fixed in the commands.
const NOT_FIXED: [&str; 5] = ["spp", "isa", "threads", "seed", "crop"];

/// One job: what every task renders, and how it is split.
pub struct Job {
    scene: Scene,
    /// `--set NAME=VALUE` of the settings given on the command line, for every task.
    fixed: Vec<(String, String)>,
    first: u32,
    last: u32,
    tiles: u32,
    output: PathBuf,
    hairtrace: String,
    spp: u32,
    isa: Isa,
    threads: usize,
}

impl Job {
    /// Checks what the tasks would refuse or get wrong before anything is submitted: an ISA
    /// left to each CPU, a crop, more tiles than pixels, an output without a frame number.
    pub fn new(
        scene: Scene,
        render: &RenderSettings,
        given: &SettingArgs,
        frames: &str,
        tiles: u32,
        output: PathBuf,
        hairtrace: String,
    ) -> Result<Job> {
        render.validate()?;
        let isa = render.isa.ok_or_else(|| {
            Error::InvalidArg(
                "farm: pin the ISA (--isa sse2|avx|avx2|avx512, the widest every worker runs): \
                 tiles rendered with different kernels do not assemble (docs/farm.md)"
                    .into(),
            )
        })?;
        if render.crop.is_some() {
            return Err(Error::InvalidArg(
                "farm: the job splits the frame into tiles itself; remove crop".into(),
            ));
        }
        tile_window(render.width, render.height, 1, tiles)?;
        let (first, last) = parse_frames(frames)?;
        if !output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
        {
            return Err(Error::InvalidArg(format!(
                "farm: --output {} must be an .exr (tiles and frames keep their float pixels \
                 and their header)",
                output.display()
            )));
        }
        frame_path(&output, first)?;
        let fixed = given
            .values
            .iter()
            .filter(|(k, _)| !NOT_FIXED.contains(&k.as_str()))
            .cloned()
            .collect();
        let threads = render.threads.unwrap_or_else(|| {
            std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
        });
        Ok(Job {
            scene,
            fixed,
            first,
            last,
            tiles,
            output,
            hairtrace,
            spp: render.spp,
            isa,
            threads,
        })
    }

    /// "2 frames x 4 tiles, sse2".
    pub fn summary(&self) -> String {
        format!(
            "{} frames x {} tiles, {} spp, isa {}",
            self.last - self.first + 1,
            self.tiles,
            self.spp,
            self.isa
        )
    }

    /// The render command's arguments after `render`, up to the per-task ones.
    fn scene_args(&self, scene_param: &str) -> Vec<String> {
        let mut args = match &self.scene {
            Scene::File(_) => vec![scene_param.to_owned()],
            Scene::Demo(name) => vec!["--demo".to_owned(), name.clone()],
        };
        for (k, v) in &self.fixed {
            args.extend(["--set".to_owned(), format!("{k}={v}")]);
        }
        args
    }

    /// The Open Job Description template (jobtemplate-2023-09), as JSON, to be written in
    /// `folder`, and the path parameters left without a default: the specification takes
    /// a path's default only relative to the template's folder and inside it, so a path
    /// elsewhere is given at submission (`-p Scene=...`).
    pub fn openjd(&self, folder: &Path) -> (String, Vec<&'static str>) {
        let mut undefaulted = Vec::new();
        let mut path_param = |name: &'static str, path: &Path, flow: &str, about: &str| {
            let mut param = serde_json::json!({
                "name": name, "type": "PATH", "objectType": "FILE", "dataFlow": flow,
                "description": about,
            });
            match pathdiff::diff_paths(path, folder).filter(|p| !p.starts_with("..")) {
                Some(inside) => param["default"] = inside.display().to_string().into(),
                None => undefaulted.push(name),
            }
            param
        };
        let mut params = Vec::new();
        if let Scene::File(path) = &self.scene {
            params.push(path_param(
                "Scene",
                path,
                "IN",
                "The scene file every task renders.",
            ));
        }
        params.push(path_param(
            "Output",
            &self.output,
            "OUT",
            "The frames (.exr), with a run of # for the frame number; the tiles are written \
             beside them.",
        ));
        params.extend([
            serde_json::json!({
                "name": "Frames", "type": "STRING",
                "default": format!("{}-{}", self.first, self.last),
                "description": "The frames to render (frame F with seed F).",
            }),
            serde_json::json!({
                "name": "Tiles", "type": "INT", "default": self.tiles, "minValue": 1,
                "description": "Tiles per frame: one render task each.",
            }),
            serde_json::json!({
                "name": "Spp", "type": "INT", "default": self.spp, "minValue": 1,
                "description": "Samples per pixel.",
            }),
            serde_json::json!({
                "name": "Isa", "type": "STRING", "default": self.isa.name(),
                "allowedValues": Isa::ALL.map(Isa::name),
                "description": "The instruction set Embree's kernels are pinned to, on every \
                                worker: the widest they all run.",
            }),
            serde_json::json!({
                "name": "Threads", "type": "INT", "default": self.threads, "minValue": 1,
                "description": "Render threads per task.",
            }),
            serde_json::json!({
                "name": "Hairtrace", "type": "STRING", "default": self.hairtrace,
                "description": "The hairtrace binary on the workers.",
            }),
        ]);
        let mut render = vec!["render".to_owned()];
        render.extend(self.scene_args("{{Param.Scene}}"));
        render.extend(
            [
                "--spp",
                "{{Param.Spp}}",
                "--isa",
                "{{Param.Isa}}",
                "--threads",
                "{{Param.Threads}}",
                "--seed",
                "{{Task.Param.Frame}}",
                "--frame",
                "{{Task.Param.Frame}}",
                "--tile",
                "{{Task.Param.Tile}}/{{Param.Tiles}}",
                "-o",
                "{{Param.Output}}",
            ]
            .map(String::from),
        );
        let frame = serde_json::json!({
            "name": "Frame", "type": "INT", "range": "{{Param.Frames}}",
        });
        let template = serde_json::json!({
            "specificationVersion": "jobtemplate-2023-09",
            "name": "hairtrace",
            "description": format!(
                "Written by hairtrace farm {}: every tile of every frame rendered with the ISA \
                 pinned, then each frame assembled from its tiles and checked (docs/farm.md).",
                hairtrace::VERSION
            ),
            "parameterDefinitions": params,
            "steps": [
                {
                    "name": "Render",
                    "parameterSpace": {
                        "taskParameterDefinitions": [
                            frame,
                            {"name": "Tile", "type": "INT", "range": "1-{{Param.Tiles}}"},
                        ],
                    },
                    "script": {
                        "actions": {"onRun": {"command": "{{Param.Hairtrace}}", "args": render}},
                    },
                },
                {
                    "name": "Assemble",
                    "dependencies": [{"dependsOn": "Render"}],
                    "parameterSpace": {"taskParameterDefinitions": [frame]},
                    "script": {
                        "actions": {"onRun": {
                            "command": "{{Param.Hairtrace}}",
                            "args": [
                                "assemble", "--frame", "{{Task.Param.Frame}}",
                                "--tiles", "{{Param.Tiles}}", "{{Param.Output}}",
                            ],
                        }},
                    },
                },
            ],
        });
        let mut text = serde_json::to_string_pretty(&template).expect("JSON values serialise");
        text.push('\n');
        (text, undefaulted)
    }

    /// The Slurm script: run with bash, it submits itself as a job array of render tasks
    /// and an array of assemble tasks that waits for it (`--dependency=afterok`).
    pub fn slurm(&self) -> String {
        let var = |name: &str, value: &str| format!("{name}=${{{name}:-{}}}", quote(value));
        let mut vars = vec![var("HAIRTRACE", &self.hairtrace)];
        if let Scene::File(path) = &self.scene {
            vars.push(var("SCENE", &path.display().to_string()));
        }
        let scene = self
            .scene_args("$SCENE")
            .iter()
            .map(|a| match a.as_str() {
                "$SCENE" => "\"$SCENE\"".to_owned(),
                _ => quote(a),
            })
            .collect::<Vec<_>>()
            .join(" ");
        vars.extend([
            var("OUTPUT", &self.output.display().to_string()),
            var("FIRST_FRAME", &self.first.to_string()),
            var("LAST_FRAME", &self.last.to_string()),
            var("TILES", &self.tiles.to_string()),
            var("SPP", &self.spp.to_string()),
            var("ISA", self.isa.name()),
            var("THREADS", &self.threads.to_string()),
        ]);
        let vars = vars.join("\n");
        format!(
            r#"#!/usr/bin/env bash
# A hairtrace render job for Slurm, written by hairtrace farm {version}. Submit it with
#   bash THIS_FILE [sbatch options, e.g. --partition=render]
# (not with sbatch): it submits itself twice, as an array of one render task per tile of
# every frame (the ISA pinned), then as an array of one assemble task per frame that
# starts once every render task has succeeded (--dependency=afterok). A failed tile is
# rerun alone: sbatch --array=ID THIS_FILE render. The variables below are the job's
# parameters: override any at submission, e.g. SPP=64 bash THIS_FILE.
set -euo pipefail
{vars}
frames=$((LAST_FRAME - FIRST_FRAME + 1))
case "${{1:-}}" in
  render)
    # Task ID = (frame - FIRST_FRAME) * TILES + tile - 1.
    frame=$((FIRST_FRAME + SLURM_ARRAY_TASK_ID / TILES))
    tile=$((SLURM_ARRAY_TASK_ID % TILES + 1))
    exec "$HAIRTRACE" render {scene} --spp "$SPP" --isa "$ISA" \
      --threads "$THREADS" --seed "$frame" --frame "$frame" --tile "$tile/$TILES" -o "$OUTPUT"
    ;;
  assemble)
    exec "$HAIRTRACE" assemble --frame $((FIRST_FRAME + SLURM_ARRAY_TASK_ID)) \
      --tiles "$TILES" "$OUTPUT"
    ;;
  *)
    render=$(sbatch --parsable "$@" --job-name=hairtrace-render \
      --array=0-$((frames * TILES - 1)) --cpus-per-task="$THREADS" "$0" render)
    render=${{render%%;*}}
    assemble=$(sbatch --parsable "$@" --job-name=hairtrace-assemble \
      --dependency=afterok:"$render" --array=0-$((frames - 1)) "$0" assemble)
    echo "render job ${{render}}, assemble job ${{assemble%%;*}}"
    ;;
esac
"#,
            version = hairtrace::VERSION,
        )
    }
}

/// "F" or "FIRST-LAST".
pub fn parse_frames(text: &str) -> Result<(u32, u32)> {
    let bad = || {
        Error::InvalidArg(format!(
            "--frames {text:?}: must be F or FIRST-LAST (whole numbers, FIRST <= LAST)"
        ))
    };
    let number = |t: &str| t.trim().parse::<u32>().map_err(|_| bad());
    let (first, last) = match text.split_once('-') {
        Some((a, b)) => (number(a)?, number(b)?),
        None => (number(text)?, number(text)?),
    };
    if first > last {
        return Err(bad());
    }
    Ok((first, last))
}

/// `text` as one shell word.
fn quote(text: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "/._-=+:,@%".contains(c);
    if !text.is_empty() && text.chars().all(plain) {
        text.to_owned()
    } else {
        format!("'{}'", text.replace('\'', r"'\''"))
    }
}
