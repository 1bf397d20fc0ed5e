//! The BSDF entry points from C: every bad argument gets its status and message
//! (`c/bsdf_args.c`), every per-direction entry point gives the Rust API's bits on random
//! inputs (`c/bsdf_bits.c`), the Huang model's through `hairtrace.hpp` and C too
//! (`c/huang_bits.cpp`), and the benchmark's plain float port agrees with the model
//! (`bench/c_bsdf`).

use crate::c_examples::build_and_run_file;
use glam::{Vec2, Vec3};
use hairtrace::{BsdfSample, HairBsdf, HairParams, HuangBsdf, HuangParams};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::fmt::Write as _;
use std::path::Path;

/// Runs the argument table and checks it ran every row and none failed (a failing row
/// fails the run, and `build_and_run_file` shows its stderr).
fn check_argument_table(compiler: &str, flags: &[&str]) {
    let out = build_and_run_file(Path::new("tests/c_abi/c/bsdf_args.c"), compiler, flags, &[]);
    let last = out.lines().last().unwrap_or_default();
    let words: Vec<&str> = last.split_whitespace().collect();
    assert_eq!(words.first(), Some(&"checks"), "{out}");
    let checks: u32 = words[1].parse().expect("a count");
    assert!(checks >= 100, "only {checks} rows ran:\n{out}");
    assert_eq!(words[3], "0", "{out}");
}

#[test]
fn bad_arguments_get_their_status_and_message_in_c99() {
    check_argument_table("gcc", &["-std=c99", "-pedantic"]);
}

#[test]
fn bad_arguments_get_their_status_and_message_in_cpp() {
    check_argument_table("g++", &["-x", "c++", "-std=c++17"]);
}

fn unit(rng: &mut Pcg64) -> [f32; 3] {
    let z: f32 = rng.random_range(-1.0..1.0);
    let phi: f32 = rng.random_range(0.0..std::f32::consts::TAU);
    let r = (1.0 - z * z).max(0.0).sqrt();
    [z, r * phi.cos(), r * phi.sin()]
}

/// One input of every entry point: parameters, h, wo, wi, u.
type Case = (HairParams, f32, [f32; 3], [f32; 3], [f32; 3]);

/// Random in-range inputs: parameters over their whole ranges, h, wo, wi, u.
fn cases(n: usize) -> Vec<Case> {
    let mut rng = Pcg64::seed_from_u64(11);
    (0..n)
        .map(|_| {
            let params = HairParams {
                sigma_a: [0; 3].map(|_| rng.random_range(0.0..6.0)),
                eta: rng.random_range(1.01..3.0),
                beta_m: rng.random_range(0.01..1.0),
                beta_n: rng.random_range(0.01..1.0),
                alpha: rng.random_range(-20.0..20.0),
            };
            let h = rng.random_range(-1.0..=1.0);
            let u = [0; 3].map(|_| rng.random::<f32>());
            (params, h, unit(&mut rng), unit(&mut rng), u)
        })
        .collect()
}

/// What a C sample call writes of a Rust sample: wi, f |cos|, the weight f |cos| / pdf and
/// the pdf (zeros without a direction or a finite weight).
fn sampled(s: Option<BsdfSample>) -> [f32; 10] {
    s.map(|s| (s.wi, s.f * s.wi.z.abs(), s.pdf))
        .filter(|(_, fc, p)| (*fc / *p).is_finite())
        .map_or([0.0; 10], |(d, fc, p)| {
            let w = fc / p;
            [d.x, d.y, d.z, fc.x, fc.y, fc.z, w.x, w.y, w.z, p]
        })
}

#[test]
fn every_c_entry_point_gives_the_rust_bits() {
    let cases = cases(3000);
    let mut input = String::new();
    for (p, h, wo, wi, u) in &cases {
        let s = p.sigma_a;
        let words = [s[0], s[1], s[2], p.eta, p.beta_m, p.beta_n, p.alpha, *h]
            .into_iter()
            .chain(*wo)
            .chain(*wi)
            .chain(*u);
        for w in words {
            write!(input, "{:08x} ", w.to_bits()).unwrap();
        }
        input.push('\n');
    }
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bsdf_bits_input.txt");
    std::fs::write(&path, input).unwrap();
    let out = build_and_run_file(
        Path::new("tests/c_abi/c/bsdf_bits.c"),
        "gcc",
        &["-std=c99", "-pedantic"],
        &[path.as_os_str()],
    );
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), cases.len());
    for (i, ((p, h, wo, wi, u), line)) in cases.iter().zip(lines).enumerate() {
        let got: Vec<u32> = line
            .split_whitespace()
            .map(|w| u32::from_str_radix(w, 16).expect("hex"))
            .collect();
        let bsdf = HairBsdf::new(p).unwrap();
        let point = bsdf.at(*h, Vec3::from_array(*wo));
        let wi = Vec3::from_array(*wi);
        // f |cos| and pdf; a sample's wi, f |cos|, weight f |cos| / pdf and pdf (zeros
        // without a direction or a finite weight); each lane's f |cos|, then their pdfs.
        let e = point.eval(wi);
        let cos = e.f * wi.z.abs();
        let eval = [cos.x, cos.y, cos.z, e.pdf];
        let sample = sampled(point.sample(*u));
        let lanes = point.eval_across(wi).expect("the point's lanes");
        let across = (lanes.f.iter().flat_map(|f| (*f * wi.z.abs()).to_array())).chain(lanes.pdf);
        let want: Vec<u32> = (eval.into_iter().chain(sample).chain(across))
            .map(|v| v.to_bits())
            .collect();
        assert_eq!(got, want, "case {i}: {p:?} h {h} wo {wo:?} wi {wi} u {u:?}");
    }
}

/// The Huang model through `hairtrace.hpp` (value and status forms) and the C calls under
/// it, and a strand's point without variation: the four agree bit for bit, and give the
/// bits of the Rust `HuangPoint` in each field (`c/huang_bits.cpp`); a bad aspect and a
/// strand's point at s = 1.5 throw, a major axis along the fibre and an unfilled point get
/// their status and message.
#[test]
fn the_huang_model_through_cpp_gives_the_rust_bits() {
    let mut rng = Pcg64::seed_from_u64(12);
    let mut input = String::new();
    let mut cases = Vec::new();
    for _ in 0..400 {
        let params = HuangParams {
            sigma_a: [0; 3].map(|_| rng.random_range(0.0..6.0)),
            eta: rng.random_range(1.01..3.0),
            roughness: rng.random_range(0.01..1.0),
            aspect: rng.random_range(0.05..=1.0),
            alpha: rng.random_range(-20.0..20.0),
        };
        let h: f32 = rng.random_range(-1.0..=1.0);
        let (wo, wi) = (unit(&mut rng), unit(&mut rng));
        let u = [0; 3].map(|_| rng.random::<f32>());
        let major = [0.0, rng.random_range(-1.0..1.0), rng.random_range(0.1..1.0)];
        let jitter = [0; 2].map(|_| rng.random::<f32>());
        // 0 near, 1 far, 2 far for lit points (huang_bits.cpp's thresholds).
        let field: usize = rng.random_range(0..3);
        let p = &params;
        let words = (p.sigma_a.into_iter())
            .chain([p.eta, p.roughness, p.aspect, p.alpha, h])
            .chain(wo)
            .chain(wi)
            .chain(u)
            .chain(major)
            .chain(jitter)
            .chain([[0.0, 0.5, 1.0][field]]);
        for w in words {
            write!(input, "{:08x} ", w.to_bits()).unwrap();
        }
        input.push('\n');
        cases.push((params, h, wo, wi, u, major, jitter, field));
    }
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("huang_bits_input.txt");
    std::fs::write(&path, input).unwrap();
    let out = build_and_run_file(
        Path::new("tests/c_abi/c/huang_bits.cpp"),
        "g++",
        &["-x", "c++", "-std=c++17", "-pedantic"],
        &[path.as_os_str()],
    );
    let lines: Vec<&str> = out.lines().collect();
    for (i, (p, h, wo, wi, u, major, jitter, field)) in cases.iter().enumerate() {
        let got: Vec<u32> = (lines[i].split_whitespace())
            .map(|w| u32::from_str_radix(w, 16).expect("hex"))
            .collect();
        let bsdf = HuangBsdf::new(p).unwrap();
        let (wo, wi) = (Vec3::from_array(*wo), Vec3::from_array(*wi));
        let yz = Vec2::new(major[1], major[2]);
        let at = [HuangBsdf::near, HuangBsdf::far, HuangBsdf::far_lit][*field];
        let point = at(&bsdf, *h, wo, yz, *jitter);
        let e = point.eval(wi);
        let cos = e.f * wi.z.abs();
        let sample = sampled(point.sample(*u));
        let want: Vec<u32> = ([cos.x, cos.y, cos.z, e.pdf].into_iter().chain(sample))
            .map(f32::to_bits)
            .collect();
        assert_eq!(got, want, "case {i}: {p:?} h {h} wo {wo} wi {wi} u {u:?}");
    }
    let rest = &lines[cases.len()..].join("\n");
    assert!(rest.contains("mismatches 0"), "{rest}");
    assert!(
        rest.contains("throws invalid argument: aspect = 1.5: must be in [0.05, 1]"),
        "{rest}"
    );
    assert!(
        rest.contains("major invalid argument: major = [3, 0, 0]: lies along the fibre"),
        "{rest}"
    );
    assert!(
        rest.contains("unfilled invalid argument: point was not filled by ht_huang_point_at_hit"),
        "{rest}"
    );
    assert!(
        rest.contains("strand throws invalid argument: s = 1.5: must be in [0, 1]"),
        "{rest}"
    );
}

#[test]
fn the_benchmarks_plain_port_agrees_with_the_model() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let port = root.join("bench/c_bsdf/port.c");
    let out = build_and_run_file(
        Path::new("bench/c_bsdf/bench.c"),
        "gcc",
        &["-std=c99", port.to_str().expect("UTF-8 path")],
        &["--check".as_ref()],
    );
    assert!(out.starts_with("check "), "{out}");
}
