//! `hairtrace report --quick` as the test suite runs it: the report and every plot it
//! links are written, each section is there, and every number in it is finite.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

const SECTIONS: [&str; 6] = ["BSDF", "Render", "Gallery", "Scale", "Real grooms", "Peers"];

/// Every link target `](file)` in a Markdown text.
fn links(text: &str) -> Vec<&str> {
    text.split("](")
        .skip(1)
        .filter_map(|rest| rest.split_once(')').map(|(target, _)| target))
        .collect()
}

/// Every word that reads as a number, or as a float that is not one.
fn numbers(text: &str) -> Vec<&str> {
    text.split(|c: char| c.is_whitespace() || "|(),;:*`[]x".contains(c))
        .map(|w| w.trim_end_matches(['.', '%']))
        .filter(|w| {
            let lower = w.to_ascii_lowercase();
            w.parse::<f64>().is_ok() || ["nan", "inf", "-inf", "infinity"].contains(&lower.as_str())
        })
        .collect()
}

/// The quick report's folder and its REPORT.md, run once for the tests that read it (the
/// first to ask runs it; the others wait).
fn quick_report() -> &'static (PathBuf, String) {
    static REPORT: OnceLock<(PathBuf, String)> = OnceLock::new();
    REPORT.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report_quick");
        let _ = std::fs::remove_dir_all(&out);
        // A peer run as bench/peer.py writes it: hairtrace at half Cycles' RMSE in the
        // same time reaches Cycles' RMSE in a quarter of the time, a speedup of 4.
        let peers = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report_quick_peers.json");
        std::fs::write(
            &peers,
            r#"[{"scene": "fur_ball", "spp": 16,
                 "renderers": {"hairtrace": {"seconds": 2.0, "rmse": 0.01},
                               "Cycles": {"seconds": 2.0, "rmse": 0.02}},
                 "converged": {"rmse_between_references": 0.003, "expected_from_noise": 0.004}}]"#,
        )
        .unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_hairtrace"))
            .args(["report", "--quick", "-o"])
            .arg(&out)
            .arg("--scenes")
            .arg(root.join("bench/scenes"))
            .arg("--peers")
            .arg(&peers)
            .env_remove("HT_BENCH_VENV")
            .output()
            .expect("run hairtrace report");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(out.join("REPORT.md")).expect("REPORT.md written");
        (out, text)
    })
}

/// The cells of the table row that starts with `start`, in the part of `text` from `from`.
fn row<'a>(text: &'a str, from: &str, start: &str) -> Vec<&'a str> {
    let part = &text[text.find(from).unwrap_or_else(|| panic!("no {from:?}"))..];
    let line = (part.lines())
        .find(|l| l.starts_with(start))
        .unwrap_or_else(|| panic!("no row {start:?} after {from:?}"));
    line.split('|').map(str::trim).collect()
}

fn finite(cell: &str) -> f64 {
    let v: f64 = cell.parse().unwrap_or(f64::NAN);
    assert!(v.is_finite(), "{cell:?} is not a finite number");
    v
}

#[test]
fn quick_report_is_complete_and_finite() {
    let (out, text) = quick_report();
    // The peers section was not measured in this run, and the header says so.
    let header = text.lines().nth(2).unwrap();
    assert!(
        header.contains("earlier peer benchmark") && header.contains("report_quick_peers.json"),
        "{header}"
    );
    for (i, s) in SECTIONS.iter().enumerate() {
        assert!(
            text.contains(&format!("## {}. {s}", i + 1)),
            "no section {s}:\n{text}"
        );
    }
    let plots = links(text);
    for name in [
        "bsdf_pareto.png",
        "bsdf_huang.png",
        "render_fur_ball.png",
        "render_huang_fur_ball.png",
        "render_huang_oval_fur_ball.png",
        "gallery.png",
        "scale_build.png",
    ] {
        assert!(plots.contains(&name), "{name} not linked: {plots:?}");
    }
    for name in &plots {
        let path = out.join(name);
        let img = image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            img.width() >= 100 && img.height() >= 100,
            "{name}: {}x{}",
            img.width(),
            img.height()
        );
        // A plot or sheet has more than one colour.
        let rgb = img.to_rgb8();
        let first = rgb.get_pixel(0, 0);
        assert!(rgb.pixels().any(|p| p != first), "{name} is blank");
    }
    let nums = numbers(text);
    assert!(nums.len() > 50, "too few numbers: {nums:?}");
    for n in nums {
        let v: f64 = n.parse().unwrap_or(f64::NAN);
        assert!(v.is_finite(), "non-finite number {n:?} in REPORT.md");
    }
    let cells = row(text, ". Peers", "| fur_ball");
    assert_eq!(cells[7..9], ["0.500", "4.00"], "{cells:?}");
}

/// The BSDF section times and judges the Huang model's near and far points beside a
/// Chiang point: every call's row holds a time, every eval and sample row its errors
/// against the f64 reference, small, and the text gives the cost ratio to Chiang.
#[test]
fn quick_report_has_the_huang_bsdf_rows() {
    let (_, text) = quick_report();
    let from = "### The Huang model beside Chiang";
    for (model, [build, eval, sample]) in [
        (
            "Chiang",
            ["HairBsdf::at", "HairPoint::eval", "HairPoint::sample"],
        ),
        (
            "Huang near",
            ["HuangBsdf::near", "HuangPoint::eval", "HuangPoint::sample"],
        ),
        (
            "Huang far",
            ["HuangBsdf::far", "HuangPoint::eval", "HuangPoint::sample"],
        ),
        (
            "Huang far, lit",
            [
                "HuangBsdf::far_lit",
                "HuangPoint::eval",
                "HuangPoint::sample",
            ],
        ),
    ] {
        let cells = |call: &str| row(text, from, &format!("| {model} | `{call}`"));
        assert!(finite(cells(build)[3]) > 0.0);
        for call in [eval, sample] {
            let cells = cells(call);
            assert!(finite(cells[3]) > 0.0, "{cells:?}");
            // Max and RMS relative error of f |wi.z|, then of the pdf.
            for pair in cells[4..8].chunks(2) {
                let (max, rms) = (finite(pair[0]), finite(pair[1]));
                assert!(rms <= max && rms < 1e-2 && max < 1.0, "{cells:?}");
            }
        }
    }
    let ratios = text
        .split("a Huang point's eval costs ")
        .nth(1)
        .expect("the cost ratio to Chiang");
    for r in ratios.split("x").take(3) {
        let r = r.rsplit(' ').next().unwrap();
        assert!(finite(r) > 0.0, "{ratios}");
    }
}

/// The render section measures the two Huang bench scenes, says their hair is the Huang
/// model, and leaves out the knobs that model does not read.
#[test]
fn quick_report_renders_the_huang_scenes() {
    let (_, text) = quick_report();
    assert!(
        text.contains("### fur_ball\n\nHair: Chiang model."),
        "{text}"
    );
    for scene in ["huang_fur_ball", "huang_oval_fur_ball"] {
        let heading = format!("### {scene}\n");
        let part = &text[text.find(&heading).unwrap_or_else(|| panic!("no {scene}"))..];
        assert!(
            part[heading.len()..].starts_with("\nHair: Huang model"),
            "{part}"
        );
        let cells = row(part, &heading, "| `reference settings`");
        for c in &cells[2..cells.len() - 1] {
            finite(c);
        }
        let skipped = part
            .lines()
            .find(|l| l.starts_with("Not measured here"))
            .unwrap();
        assert!(
            skipped.contains("`lobe_cull 0.1` (not applicable"),
            "{skipped}"
        );
    }
}

/// A `--peers` file that is not a peer benchmark's results is refused at once, named, before
/// any work and without writing anything.
#[test]
fn report_refuses_a_bad_peers_file_at_once() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let out = dir.join("report_bad_peers");
    let _ = std::fs::remove_dir_all(&out);
    let peers = dir.join("bad_peers.json");
    std::fs::write(&peers, r#"{"scene": 1}"#).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_hairtrace"))
        .args(["report", "--quick", "--peers"])
        .arg(&peers)
        .arg("--scenes")
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("../bench/scenes"))
        .arg("-o")
        .arg(&out)
        .output()
        .expect("run hairtrace report");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("bad_peers.json"), "{err}");
    assert!(err.contains("not a list of scenes"), "{err}");
    assert!(!out.exists(), "wrote {}", out.display());
}

/// Without the bench scenes the report stops at once, in one line that says what to do,
/// and writes nothing.
#[test]
fn report_without_the_bench_scenes_says_where_they_are() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report_no_scenes");
    let _ = std::fs::remove_dir_all(&out);
    let o = Command::new(env!("CARGO_BIN_EXE_hairtrace"))
        .args(["report", "--quick", "--scenes", "/nonexistent/scenes", "-o"])
        .arg(&out)
        .output()
        .expect("run hairtrace report");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("--scenes"), "{err}");
    assert!(!out.exists(), "wrote {}", out.display());
}

/// A report killed while it writes a plot (here by the file-size limit, SIGXFSZ, after
/// 4 kB) leaves no half-written file under a name of the report's: each is written under a
/// temporary name and renamed once whole.
#[test]
fn a_report_killed_while_writing_leaves_no_partial_file() {
    use std::os::unix::process::ExitStatusExt;
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report_killed");
    let _ = std::fs::remove_dir_all(&out);
    let o = Command::new("sh")
        .args(["-c", "ulimit -f 8 && exec \"$0\" \"$@\""])
        .arg(env!("CARGO_BIN_EXE_hairtrace"))
        .args(["report", "--quick", "--scenes"])
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("../bench/scenes"))
        .arg("-o")
        .arg(&out)
        .env_remove("HT_BENCH_VENV")
        .output()
        .expect("run hairtrace report");
    assert_eq!(o.status.signal(), Some(25), "SIGXFSZ: {o:?}");
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert!(
        names.iter().any(|n| n.starts_with('.')),
        "killed before writing: {names:?}"
    );
    for name in names.iter().filter(|n| !n.starts_with('.')) {
        assert_ne!(name, "REPORT.md");
        image::open(out.join(name)).unwrap_or_else(|e| panic!("{name} left partial: {e}"));
    }
}
