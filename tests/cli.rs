//! The command line as a user meets it: the main job prints its table, `info` describes
//! a groom, and every error is one line on stderr with a non-zero exit.

use hairtrace::scene::{FurBall, Thickness, write_hair_file};
use std::process::{Command, Output};

fn hairtrace(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hairtrace"))
        .args(args)
        .output()
        .expect("run hairtrace")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn assert_one_line_error(o: &Output, needle: &str) {
    assert!(!o.status.success(), "expected a failure");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "error must be one line: {err:?}"
    );
    assert!(err.contains(needle), "{err:?} should mention {needle:?}");
}

#[test]
fn lobes_prints_energies_that_add_up() {
    let o = hairtrace(&["lobes", "--color", "1,1,1"]);
    assert!(o.status.success(), "{o:?}");
    let out = stdout(&o);
    // White fibres lose nothing: every row's total is 1 in each channel.
    let rows: Vec<_> = out.lines().filter(|l| l.contains('°')).collect();
    assert_eq!(rows.len(), 7, "{out}");
    for row in rows {
        let totals: Vec<f32> = row
            .split_whitespace()
            .rev()
            .take(3)
            .map(|v| v.parse().unwrap())
            .collect();
        assert!(totals.iter().all(|t| (t - 1.0).abs() < 2e-3), "{row}");
    }
}

#[test]
fn lobes_refuses_bad_parameters() {
    assert_one_line_error(&hairtrace(&["lobes", "--beta-m", "5"]), "beta_m");
    assert_one_line_error(&hairtrace(&["lobes", "--eumelanin", "nan"]), "eumelanin");
}

#[test]
fn info_describes_a_groom() {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_info.hair");
    let groom = FurBall {
        strands: 100,
        segments: 8,
        ..FurBall::default()
    }
    .build()
    .unwrap();
    write_hair_file(&path, &groom, Thickness::Diameter).unwrap();
    let o = hairtrace(&["info", path.to_str().unwrap()]);
    assert!(o.status.success(), "{o:?}");
    let out = stdout(&o);
    for want in [
        "strands:  100",
        "points:   900",
        "segments: 800",
        "bounds:",
        "radius:",
    ] {
        assert!(out.contains(want), "{want:?} missing from:\n{out}");
    }
}

#[test]
fn info_errors_are_one_line() {
    assert_one_line_error(
        &hairtrace(&["info", "/nonexistent/groom.hair"]),
        "/nonexistent/groom.hair",
    );
    let bad = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_bad.hair");
    std::fs::write(&bad, b"HAIR but far too short").unwrap();
    let o = hairtrace(&["info", bad.to_str().unwrap()]);
    assert!(!o.status.success());
}
