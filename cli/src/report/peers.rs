//! Peers section: the peer benchmark (bench/peer.py: hairtrace and Blender Cycles on the
//! bench scenes, same machine, same run) when Blender's Python module is installed, turned
//! into time to the same RMSE and the converged difference. Without it the section says
//! why it was not run.

use super::Context;
use super::markdown::{num, table};
use hairtrace::{Error, Result};
use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;

/// The environment variable naming the peer benchmark's virtual environment.
const VENV: &str = "HT_BENCH_VENV";

pub fn steps(_: &Context) -> u64 {
    1
}

/// The venv's python if Blender's module imports there, else why not.
fn blender_python() -> std::result::Result<PathBuf, String> {
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
}

pub fn section(ctx: &Context) -> Result<String> {
    ctx.step("peers: Blender Cycles");
    let python = match (ctx.quick, blender_python()) {
        (true, _) => Err("`--quick` leaves it out (Blender's renders take minutes)".to_owned()),
        (false, r) => r,
    };
    let text = match python {
        Err(why) => format!(
            "**Not run:** {why}. The peer benchmark needs Blender as a Python module: \
             `bench/peer` installs it (see bench/README.md), then \
             `{VENV}=bench/.venv hairtrace report` includes this section.\n"
        ),
        Ok(python) => run_peer(ctx, &python)?,
    };
    ctx.done();
    Ok(text)
}

fn run_peer(ctx: &Context, python: &PathBuf) -> Result<String> {
    let bench = ctx.scenes.join("..");
    let json = ctx.path("peers.json");
    let shim = bench.join("../target/bench-peer/count_rays.so");
    let mut cmd = Command::new(python);
    cmd.arg(bench.join("peer.py"))
        .args(["--quick", "--repeats", "1", "--json"])
        .arg(&json);
    if shim.exists() {
        cmd.arg("--shim").arg(&shim);
    }
    let out = cmd
        .output()
        .map_err(|e| Error::io(&bench.join("peer.py"), e))?;
    if !out.status.success() {
        return Err(Error::InvalidArg(format!(
            "bench/peer.py failed: {}",
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
        )));
    }
    let text = std::fs::read_to_string(&json).map_err(|e| Error::io(&json, e))?;
    let results: Vec<Value> = serde_json::from_str(&text)
        .map_err(|e| Error::InvalidArg(format!("{}: {e}", json.display())))?;
    let f = |v: &Value, path: &[&str]| {
        path.iter()
            .try_fold(v, |v, k| v.get(k))
            .and_then(Value::as_f64)
            .unwrap_or(f64::NAN)
    };
    let rows: Vec<Vec<String>> = results
        .iter()
        .map(|r| {
            let (hs, hr) = (
                f(r, &["renderers", "hairtrace", "seconds"]),
                f(r, &["renderers", "hairtrace", "rmse"]),
            );
            let (cs, cr) = (
                f(r, &["renderers", "Cycles", "seconds"]),
                f(r, &["renderers", "Cycles", "rmse"]),
            );
            // Noise falls as 1 / sqrt(time): hairtrace's time to Cycles' RMSE.
            let to_same = hs * (hr / cr).powi(2);
            vec![
                r.get("scene")
                    .and_then(Value::as_str)
                    .unwrap_or("?")
                    .to_owned(),
                num(f(r, &["spp"]), 3),
                num(hs, 3),
                num(cs, 3),
                num(hr, 3),
                num(cr, 3),
                num(to_same, 3),
                num(cs / to_same, 3),
                num(f(r, &["converged", "rmse_between_references"]), 3),
                num(f(r, &["converged", "expected_from_noise"]), 3),
            ]
        })
        .collect();
    Ok(format!(
        "`bench/peer.py --quick --repeats 1` (a quarter of each scene's spp, one timed run \
         each; bench/README.md says how it matches the two renderers) on {}, {} threads, \
         seed 1, references at 16x spp with seed 1000003. Time to the same RMSE is \
         hairtrace's path-tracing time scaled to Cycles' RMSE (noise falls as one over the \
         square root of time); the converged difference is the RMSE between the two \
         references, next to what their own noise alone would give.\n\n{}",
        ctx.machine.cpu,
        ctx.machine.threads,
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
                "expected from noise"
            ],
            &rows
        )
    ))
}
