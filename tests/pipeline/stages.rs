//! The stages of a scene build: reported in order, each monotone up to completion, timed,
//! and cancellable in the middle of Embree's BVH build.

use std::sync::{Arc, Mutex};

use hairtrace::description::{GroomSource, SceneDescription, Transform, demo};
use hairtrace::embree::{Device, is_cancelled};
use hairtrace::scene::{Stage, StageProgress};

/// Records every call; cancels at the first call that `cancel_at` picks.
struct Recorder {
    calls: Mutex<Vec<(Stage, f64)>>,
    cancel_at: fn(Stage, f64) -> bool,
}

impl Recorder {
    fn new(cancel_at: fn(Stage, f64) -> bool) -> Self {
        Recorder {
            calls: Mutex::new(Vec::new()),
            cancel_at,
        }
    }

    fn calls(&self) -> Vec<(Stage, f64)> {
        self.calls.lock().unwrap().clone()
    }
}

impl StageProgress for Recorder {
    fn update(&self, stage: Stage, fraction: f64) -> bool {
        // `try_lock`: two calls at once would be a broken promise, and fail here.
        self.calls
            .try_lock()
            .expect("one call at a time")
            .push((stage, fraction));
        !(self.cancel_at)(stage, fraction)
    }
}

/// The scalp demo (a groom and a head) with `strands` strands of 16 segments.
fn scalp(strands: usize) -> SceneDescription {
    let mut desc = demo("scalp").unwrap();
    let GroomSource::Scalp(s) = &mut desc.grooms[0].source else {
        panic!("the scalp demo has a scalp groom");
    };
    s.strands = strands;
    s.segments = 16;
    desc
}

fn device() -> Arc<Device> {
    Arc::new(Device::new(Some(2)).unwrap())
}

/// Every stage's fractions never decrease and end at 1; the BVH comes after every read
/// and conversion; each groom's conversion follows its read.
fn check_sequence(calls: &[(Stage, f64)]) {
    for stage in Stage::ALL {
        let fractions: Vec<f64> = calls.iter().filter(|c| c.0 == stage).map(|c| c.1).collect();
        assert!(!fractions.is_empty(), "{stage:?} never reported: {calls:?}");
        assert!(
            fractions.windows(2).all(|w| w[0] <= w[1]),
            "{stage:?} went backwards: {fractions:?}"
        );
        assert_eq!(fractions.last(), Some(&1.0), "{stage:?} did not finish");
        assert!(fractions.iter().all(|f| (0.0..=1.0).contains(f)));
    }
    let first_bvh = calls.iter().position(|c| c.0 == Stage::Bvh).unwrap();
    assert!(calls[first_bvh..].iter().all(|c| c.0 == Stage::Bvh));
    assert_eq!(calls[0], (Stage::Read, 0.0));
    assert_eq!(calls[first_bvh], (Stage::Bvh, 0.0));
}

#[test]
fn stages_come_in_order_and_finish() {
    let recorder = Recorder::new(|_, _| false);
    let built = scalp(20_000).build_with(device(), &recorder).unwrap();
    let calls = recorder.calls();
    check_sequence(&calls);
    // One groom then one mesh: read half, convert all, read the rest, build.
    let stages: Vec<Stage> = calls.iter().map(|c| c.0).collect();
    let mut runs = stages.clone();
    runs.dedup();
    assert_eq!(
        runs,
        [Stage::Read, Stage::Curves, Stage::Read, Stage::Bvh],
        "{calls:?}"
    );
    assert!(calls.contains(&(Stage::Read, 0.5)));
    // Embree reports the BVH build's progress in between.
    assert!(
        calls
            .iter()
            .any(|&(s, f)| s == Stage::Bvh && f > 0.0 && f < 1.0),
        "no progress inside the BVH build: {calls:?}"
    );
    let times = built.stages();
    assert!(Stage::ALL.iter().all(|&s| times.get(s) >= 0.0));
    assert!(times.bvh > 0.0 && times.read > 0.0 && times.curves > 0.0);
}

#[test]
fn two_grooms_keep_each_stage_monotone() {
    let mut desc = scalp(500);
    let mut second = desc.grooms[0].clone();
    second.transform = Transform::Trs {
        translate: [0.0, 1.0, 0.0],
        rotate_deg: [0.0; 3],
        scale: 1.0,
    };
    desc.grooms.push(second);
    let recorder = Recorder::new(|_, _| false);
    desc.build_with(device(), &recorder).unwrap();
    let calls = recorder.calls();
    check_sequence(&calls);
    // Two grooms and a mesh: each read is a third of the reading.
    for f in [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0] {
        assert!(calls.contains(&(Stage::Read, f)), "{calls:?}");
    }
    assert!(calls.contains(&(Stage::Curves, 0.5)), "{calls:?}");
}

#[test]
fn cancelling_stops_the_build() {
    // Inside Embree's BVH build, and between the stages before it.
    let inside_bvh: fn(Stage, f64) -> bool = |s, f| s == Stage::Bvh && f > 0.0;
    let at_curves: fn(Stage, f64) -> bool = |s, _| s == Stage::Curves;
    for cancel_at in [inside_bvh, at_curves] {
        let recorder = Recorder::new(cancel_at);
        let err = scalp(20_000)
            .build_with(device(), &recorder)
            .err()
            .expect("a cancelled build fails");
        assert!(is_cancelled(&err), "{err}");
        let calls = recorder.calls();
        let last = *calls.last().unwrap();
        assert!(
            cancel_at(last.0, last.1),
            "went on after cancelling: {calls:?}"
        );
        assert_eq!(calls.iter().filter(|c| cancel_at(c.0, c.1)).count(), 1);
    }
}
