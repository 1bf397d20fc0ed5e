//! Peers section: the peer benchmark (bench/peer.py: hairtrace and Blender Cycles on the
//! bench scenes, same machine, same run) when Blender's Python module is installed, or the
//! results of an earlier `bench/peer --json` run, turned into time to the same RMSE and
//! the converged difference. Without either the section says why it was not run.

use super::Context;
use super::markdown::{num, table};
use super::render::scene_names;
use hairtrace::{Error, Result};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The environment variable naming the peer benchmark's virtual environment.
const VENV: &str = "HT_BENCH_VENV";

pub fn steps(_: &Context) -> u64 {
    1
}

/// The venv's python if Blender's module imports there, else why not: asked once per
/// process (the import takes seconds, and three sections ask).
pub(super) fn blender_python() -> std::result::Result<PathBuf, String> {
    static FOUND: OnceLock<std::result::Result<PathBuf, String>> = OnceLock::new();
    FOUND
        .get_or_init(|| {
            let venv = std::env::var_os(VENV).ok_or_else(|| format!("{VENV} is not set"))?;
            let python = PathBuf::from(venv).join("bin/python");
            let ok = Command::new(&python)
                .args(["-c", "import bpy"])
                .output()
                .is_ok_and(|o| o.status.success());
            if ok {
                Ok(python)
            } else {
                Err(format!("{} cannot import bpy", python.display()))
            }
        })
        .clone()
}

pub fn section(ctx: &Context) -> Result<String> {
    ctx.step("peers: Blender Cycles");
    let text = if let Some(json) = &ctx.peers {
        format!(
            "From an earlier run of the peer benchmark (`{}`, not measured by this report).\n\n{}",
            json.display(),
            peer_table(&read_json(json)?)?
        )
    } else {
        let python = match (ctx.quick, blender_python()) {
            (true, _) => Err("`--quick` leaves it out (Blender's renders take minutes)".into()),
            (false, r) => r,
        };
        match python {
            Err(why) => format!(
                "**Not run:** {why}. The peer benchmark needs Blender as a Python module: \
                 `bench/peer` installs it (see bench/README.md), then \
                 `{VENV}=bench/.venv hairtrace report` includes this section, or \
                 `hairtrace report --peers FILE` takes an earlier `bench/peer --json FILE` \
                 run.\n"
            ),
            Ok(python) => run_peer(ctx, &python)?,
        }
    };
    ctx.done();
    Ok(text)
}

/// Refuses a `--peers` file that is not a peer benchmark's results, before the report's
/// minutes of work.
pub fn check_file(path: &Path) -> Result<()> {
    peer_table(&read_json(path)?)
        .map(drop)
        .map_err(|e| e.context(format!("--peers {}", path.display())))
}

fn read_json(path: &Path) -> Result<Value> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    serde_json::from_str(&text).map_err(|e| Error::InvalidArg(format!("{}: {e}", path.display())))
}

fn run_peer(ctx: &Context, python: &Path) -> Result<String> {
    let bench = ctx.scenes.join("..");
    let script = bench.join("peer.py");
    let json = ctx.path("peers.json");
    let shim = bench.join("../target/bench-peer/count_rays.so");
    let mut cmd = Command::new(python);
    cmd.env("HT_HAIRTRACE", &ctx.hairtrace)
        .arg(&script)
        .args(["--quick", "--repeats", "1", "--scenes"])
        .arg(scene_names(ctx)?.join(","))
        .arg("--threads")
        .arg(ctx.machine.threads.to_string())
        .arg("--json")
        .arg(&json);
    if shim.exists() {
        cmd.arg("--shim").arg(&shim);
    }
    let out = cmd.output().map_err(|e| Error::io(&script, e))?;
    if !out.status.success() {
        return Err(Error::InvalidArg(format!(
            "{} failed: {}",
            script.display(),
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
        )));
    }
    Ok(format!(
        "`bench/peer.py --quick --repeats 1` in this run (a quarter of each scene's spp, one \
         timed render each; bench/README.md says how it matches the two renderers), {} \
         threads, seed 1, references at 16x those samples with seed 1000003. Its full results: \
         `peers.json`.\n\n{}",
        ctx.machine.threads,
        peer_table(&read_json(&json)?)?
    ))
}

/// The table of a peer benchmark's JSON results (a list of scenes as bench/peer.py
/// writes them). Time to the same RMSE is hairtrace's path-tracing time scaled to
/// Cycles' RMSE (noise falls as one over the square root of time).
fn peer_table(results: &Value) -> Result<String> {
    let scenes = results
        .as_array()
        .ok_or_else(|| Error::InvalidArg("peer results: not a list of scenes".into()))?;
    let f = |v: &Value, path: &[&str]| {
        path.iter()
            .try_fold(v, |v, k| v.get(k))
            .and_then(Value::as_f64)
            .unwrap_or(f64::NAN)
    };
    let rows: Vec<Vec<String>> = scenes
        .iter()
        .map(|r| {
            let ht = |k| f(r, &["renderers", "hairtrace", k]);
            let cy = |k| f(r, &["renderers", "Cycles", k]);
            let to_same = ht("seconds") * (ht("rmse") / cy("rmse")).powi(2);
            vec![
                r.get("scene")
                    .and_then(Value::as_str)
                    .unwrap_or("?")
                    .to_owned(),
                num(f(r, &["spp"]), 3),
                num(ht("seconds"), 3),
                num(cy("seconds"), 3),
                num(ht("rmse"), 3),
                num(cy("rmse"), 3),
                num(to_same, 3),
                num(cy("seconds") / to_same, 3),
                num(f(r, &["converged", "rmse_between_references"]), 3),
                num(f(r, &["converged", "expected_from_noise"]), 3),
            ]
        })
        .collect();
    Ok(format!(
        "Time to Cycles' RMSE: hairtrace's path-tracing seconds scaled by (its RMSE / \
         Cycles')^2, since noise falls as one over the square root of time; speedup is \
         Cycles' seconds over that. Converged difference: the RMSE between the two \
         renderers' references, next to what their own noise alone would give (well \
         above it is a systematic difference).\n\n{}",
        table(
            &[
                "scene",
                "spp",
                "hairtrace s",
                "Cycles s",
                "hairtrace RMSE",
                "Cycles RMSE",
                "hairtrace s to Cycles' RMSE",
                "speedup",
                "converged difference",
                "expected from noise",
            ],
            &rows
        )
    ))
}
