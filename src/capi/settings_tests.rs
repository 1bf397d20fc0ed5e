//! Tests of settings by name through the C ABI.

use super::HtStatus;
use super::render::*;
use super::render_tests::{bits, fur_scene, render_aovs_c, settings};
use super::scene::HtScene;
use super::scene_tests::{fails, last_error};
use super::settings::*;
use crate::render::settings::{Filter, PathSettings, RenderSettings};
use std::ffi::{CStr, CString, c_char};
use std::ptr::{null, null_mut};

/// Settings from `ht_settings_new`, freed on drop.
pub(super) struct Named(pub(super) *mut HtSettings);

impl Named {
    pub(super) fn new(pairs: &[(&str, &str)]) -> Named {
        let mut s = null_mut();
        assert_eq!(unsafe { ht_settings_new(&mut s) }, HtStatus::HT_OK);
        let named = Named(s);
        for (k, v) in pairs {
            assert_eq!(named.set(k, v), HtStatus::HT_OK, "{}", last_error());
        }
        named
    }

    fn set(&self, key: &str, value: &str) -> HtStatus {
        let (k, v) = (CString::new(key).unwrap(), CString::new(value).unwrap());
        unsafe { ht_settings_set(self.0, k.as_ptr(), v.as_ptr()) }
    }

    /// Renders `scene` with these settings into a fresh RGB buffer of `pixels`.
    pub(super) fn render_rgb(&self, scene: *mut HtScene, pixels: usize) -> (HtStatus, Vec<f32>) {
        self.render_reporting(scene, pixels, None, null_mut())
    }

    /// As [`Self::render_rgb`], telling `progress` with `user`.
    fn render_reporting(
        &self,
        scene: *mut HtScene,
        pixels: usize,
        progress: HtProgressFn,
        user: *mut std::ffi::c_void,
    ) -> (HtStatus, Vec<f32>) {
        let mut rgb = vec![-1.0f32; 3 * pixels];
        let status = unsafe {
            ht_render_with(
                scene,
                self.0,
                progress,
                user,
                rgb.as_mut_ptr(),
                rgb.len(),
                null_mut(),
                null_mut(),
                null_mut(),
                pixels,
            )
        };
        (status, rgb)
    }

    fn get(&self, key: &str) -> String {
        let k = CString::new(key).unwrap();
        let mut buf = [0 as c_char; 64];
        let mut len = 0;
        let s =
            unsafe { ht_settings_get(self.0, k.as_ptr(), buf.as_mut_ptr(), buf.len(), &mut len) };
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        let text = unsafe { CStr::from_ptr(buf.as_ptr()) }
            .to_str()
            .unwrap()
            .to_owned();
        assert_eq!(text.len(), len);
        text
    }
}

impl Drop for Named {
    fn drop(&mut self) {
        assert_eq!(unsafe { ht_settings_free(self.0) }, HtStatus::HT_OK);
    }
}

#[test]
fn settings_by_name_render_what_the_rust_settings_render_bit_for_bit() {
    let h = fur_scene(true);
    let s = RenderSettings {
        filter: Filter::Box,
        crop: Some([4, 2, 20, 18]),
        path: PathSettings {
            light_threshold: 0.0,
            max_depth: 12,
            ..PathSettings::default()
        },
        ..settings(24)
    };
    let by_struct = render_aovs_c(&h, &s);
    let named = Named::new(&[
        ("width", "24"),
        ("height", "24"),
        ("spp", "4"),
        ("seed", "7"),
        ("threads", "2"),
        ("filter", "box"),
        ("crop", "4,2,20,18"),
        ("light_threshold", "0"),
        ("max_depth", "12"),
    ]);
    let pixels = 16 * 16;
    let mut out = [3, 3, 1, 1].map(|c| vec![-2.0f32; c * pixels]);
    let [rgb, albedo, depth, strand_id] = &mut out;
    let status = unsafe {
        ht_render_with(
            h.scene,
            named.0,
            None,
            null_mut(),
            rgb.as_mut_ptr(),
            rgb.len(),
            albedo.as_mut_ptr(),
            depth.as_mut_ptr(),
            strand_id.as_mut_ptr(),
            pixels,
        )
    };
    assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
    for (a, b) in out.iter().zip(&by_struct) {
        assert_eq!(bits(a), bits(b));
    }
    // A build with the same settings leaves nothing for the render to build.
    let build = unsafe { ht_scene_build_with(h.scene, named.0, None, null_mut()) };
    assert_eq!(build, HtStatus::HT_OK, "{}", last_error());
}

#[test]
fn set_names_the_key_and_range_and_get_reads_back() {
    let named = Named::new(&[("spp", "64"), ("roulette", "throughput")]);
    assert_eq!(named.get("spp"), "64");
    assert_eq!(named.get("roulette"), "throughput");
    assert_eq!(named.get("threads"), "none");
    fails(
        named.set("spp", "0"),
        HtStatus::HT_ERR_INVALID_ARG,
        "spp = 0: must be >= 1",
    );
    fails(
        named.set("lobe_cull", "nan"),
        HtStatus::HT_ERR_INVALID_ARG,
        "lobe_cull = nan",
    );
    fails(
        named.set("sp", "4"),
        HtStatus::HT_ERR_INVALID_ARG,
        "sp: not a render setting",
    );
    assert_eq!(named.get("spp"), "64", "a refused value changes nothing");
    unsafe {
        let key = c"spp";
        fails(
            ht_settings_set(null_mut(), key.as_ptr(), c"1".as_ptr()),
            HtStatus::HT_ERR_NULL_ARG,
            "settings",
        );
        fails(
            ht_settings_set(named.0, null(), c"1".as_ptr()),
            HtStatus::HT_ERR_NULL_ARG,
            "key",
        );
        fails(
            ht_settings_set(named.0, key.as_ptr(), null()),
            HtStatus::HT_ERR_NULL_ARG,
            "value",
        );
        // Sizing first, then a buffer too small for "64" and its NUL.
        let mut len = 0;
        assert_eq!(
            ht_settings_get(named.0, key.as_ptr(), null_mut(), 0, &mut len),
            HtStatus::HT_OK
        );
        assert_eq!(len, 2);
        let mut small = [0 as c_char; 2];
        fails(
            ht_settings_get(named.0, key.as_ptr(), small.as_mut_ptr(), 2, &mut len),
            HtStatus::HT_ERR_INVALID_ARG,
            "needs 3 bytes",
        );
        assert_eq!(small, [0, 0], "nothing written");
        fails(
            ht_settings_get(named.0, key.as_ptr(), null_mut(), 0, null_mut()),
            HtStatus::HT_ERR_NULL_ARG,
            "nowhere",
        );
    }
    // Rules between settings are checked when they are used.
    let h = fur_scene(true);
    let crop = Named::new(&[("width", "8"), ("height", "8"), ("crop", "0,0,9,8")]);
    let (status, _) = crop.render_rgb(h.scene, 64);
    fails(status, HtStatus::HT_ERR_INVALID_ARG, "crop = 0,0,9,8");
}

#[test]
fn every_setting_is_listed_by_key() {
    let names: Vec<&str> = (0..)
        .map(|i| ht_settings_key(i))
        .take_while(|k| !k.is_null())
        .map(|k| unsafe { CStr::from_ptr(k) }.to_str().unwrap())
        .collect();
    let schema: Vec<&str> = RenderSettings::schema().iter().map(|s| s.name).collect();
    assert_eq!(names, schema);
    let named = Named::new(&[]);
    for s in RenderSettings::schema() {
        assert_eq!(named.get(s.name), s.default_text());
    }
}

/// Each noise a progress callback reads through `ht_progress_noise`, as f32 bits.
extern "C" fn record_noise(_done: u64, _total: u64, user: *mut std::ffi::c_void) -> bool {
    // SAFETY: the test's vector, alive until the render returns; calls never overlap.
    let seen = unsafe { &*user.cast::<std::sync::Mutex<Vec<f32>>>() };
    seen.lock().unwrap().push(ht_progress_noise());
    true
}

/// A progress callback of a render with a noise target reads the estimated noise: -1
/// until two passes have finished, then finite and positive, the last one read above the
/// target the render then reached. Outside a callback, and in a render without a target
/// or a time budget (which estimates none), it reads -1.
#[test]
fn a_progress_callback_reads_the_estimated_noise() {
    let h = fur_scene(true);
    let run = |pairs: &[(&str, &str)]| {
        let seen = std::sync::Mutex::new(Vec::new());
        let user = std::ptr::from_ref(&seen).cast_mut().cast();
        let (status, _) =
            Named::new(pairs).render_reporting(h.scene, 24 * 24, Some(record_noise), user);
        assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
        seen.into_inner().unwrap()
    };
    let size = [("width", "24"), ("height", "24"), ("threads", "2")];
    let target = 0.02;
    let seen = run(&[size.as_slice(), &[("spp", "512"), ("noise_target", "0.02")]].concat());
    let estimates: Vec<f32> = seen.iter().copied().filter(|&n| n != -1.0).collect();
    assert!(seen[0] == -1.0, "{seen:?}");
    assert!(
        estimates.len() > 2 && estimates.iter().all(|n| n.is_finite() && *n > 0.0),
        "{seen:?}"
    );
    assert!(*estimates.last().unwrap() > target, "{estimates:?}");
    let plain = run(&[size.as_slice(), &[("spp", "32")]].concat());
    assert!(
        !plain.is_empty() && plain.iter().all(|&n| n == -1.0),
        "{plain:?}"
    );
    assert_eq!(ht_progress_noise(), -1.0);
}
