//! `hairtrace report --quick` as the test suite runs it: the report and every plot it
//! links are written, each section is there, and every number in it is finite.

use std::path::Path;
use std::process::Command;

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

#[test]
fn quick_report_is_complete_and_finite() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report_quick");
    let _ = std::fs::remove_dir_all(&out);
    // A peer run as bench/peer.py writes it: hairtrace at half Cycles' RMSE in the same
    // time reaches Cycles' RMSE in a quarter of the time, a speedup of 4.
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
    let plots = links(&text);
    for name in [
        "bsdf_pareto.png",
        "render_fur_ball.png",
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
    let nums = numbers(&text);
    assert!(nums.len() > 50, "too few numbers: {nums:?}");
    for n in nums {
        let v: f64 = n.parse().unwrap_or(f64::NAN);
        assert!(v.is_finite(), "non-finite number {n:?} in REPORT.md");
    }
    let peers = &text[text.find(". Peers").expect("the peers section")..];
    let row = peers.lines().find(|l| l.starts_with("| fur_ball")).unwrap();
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    assert_eq!(cells[7..9], ["0.500", "4.00"], "{row}");
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
