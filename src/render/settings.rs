//! Every render setting, declared once: name, type, default, range and doc in one line of
//! `settings!` below. The TOML `[render]` table, the command line (`--NAME VALUE` and
//! `--set NAME=VALUE`) and the C ABI (`ht_settings_set(settings, "NAME", "VALUE")`) all read
//! settings by name through [`RenderSettings::set`], so a new setting is one line here plus
//! its use, and never changes the C ABI's layout.
//!
//! Every surface speaks text: `set` parses it with the setting's type ([`Value`]) and checks
//! the declared [`Range`], and errors name the key and the range.

use std::fmt;

use super::camera_rays::MAX_CAMERA_RAYS;
use super::film::PixelFilter;
use crate::embree::{Device, Isa, MAX_TIME_STEPS};
use crate::error::{Error, Result, invalid_arg};
use crate::scene::lod::DEFAULT_LOD_PIXELS;

/// A value a setting can hold, read from and written as text.
pub trait Value: Sized {
    /// What the text must be, for help and errors ("an integer", "sqrt or throughput").
    fn kind() -> String;
    fn parse(text: &str) -> Option<Self>;
    fn show(&self) -> String;
    /// The number a [`Range`] checks; None where there is none (a name, unset).
    fn number(&self) -> Option<f64> {
        None
    }
}

macro_rules! numeric_value {
    ($($t:ty => $kind:literal),*) => {$(
        impl Value for $t {
            fn kind() -> String {
                $kind.into()
            }
            fn parse(text: &str) -> Option<Self> {
                text.trim().parse().ok()
            }
            fn show(&self) -> String {
                self.to_string()
            }
            fn number(&self) -> Option<f64> {
                Some(*self as f64)
            }
        }
    )*};
}
numeric_value!(u32 => "an integer", u64 => "an integer", usize => "an integer");

impl Value for f32 {
    fn kind() -> String {
        "a number".into()
    }
    fn parse(text: &str) -> Option<Self> {
        // NaN and infinities are never a setting.
        text.trim().parse().ok().filter(|v: &f32| v.is_finite())
    }
    fn show(&self) -> String {
        self.to_string()
    }
    fn number(&self) -> Option<f64> {
        Some(f64::from(*self))
    }
}

/// Unset is written `none`.
impl<T: Value> Value for Option<T> {
    fn kind() -> String {
        format!("{} or none", T::kind())
    }
    fn parse(text: &str) -> Option<Self> {
        match text.trim() {
            "none" => Some(None),
            t => T::parse(t).map(Some),
        }
    }
    fn show(&self) -> String {
        self.as_ref().map_or("none".into(), T::show)
    }
    fn number(&self) -> Option<f64> {
        self.as_ref().and_then(T::number)
    }
}

/// A pixel window `x0,y0,x1,y1`.
impl Value for [u32; 4] {
    fn kind() -> String {
        "x0,y0,x1,y1".into()
    }
    fn parse(text: &str) -> Option<Self> {
        let v: Vec<u32> = text
            .split(',')
            .map(|x| x.trim().parse().ok())
            .collect::<Option<_>>()?;
        v.try_into().ok()
    }
    fn show(&self) -> String {
        self.map(|v| v.to_string()).join(",")
    }
}

/// A setting's choices, each by its name.
macro_rules! named_value {
    ($t:ty { $($variant:ident = $name:literal),* $(,)? }) => {
        impl Value for $t {
            fn kind() -> String {
                [$($name),*].join(" | ")
            }
            fn parse(text: &str) -> Option<Self> {
                match text.trim() {
                    $($name => Some(<$t>::$variant),)*
                    _ => None,
                }
            }
            fn show(&self) -> String {
                match self {
                    $(<$t>::$variant => $name.into(),)*
                }
            }
        }
    };
}
named_value!(Roulette { SqrtThroughput = "sqrt", Throughput = "throughput" });
named_value!(RouletteScale { Auto = "auto", Off = "off" });
named_value!(Strategy { Mis = "mis", LightOnly = "light", BsdfOnly = "bsdf" });
named_value!(Filter { Tent = "tent", Box = "box" });
named_value!(Allocation { Uniform = "uniform", Noise = "noise" });
named_value!(LightOffsets { Across = "across", Hit = "hit" });
named_value!(CurveParts { Auto = "auto", On = "on", Off = "off" });

/// `auto` or a count.
impl Value for CameraRays {
    fn kind() -> String {
        "auto or an integer".into()
    }
    fn parse(text: &str) -> Option<Self> {
        match text.trim() {
            "auto" => Some(CameraRays::Auto),
            t => t.parse().ok().map(CameraRays::Fixed),
        }
    }
    fn show(&self) -> String {
        match self {
            CameraRays::Auto => "auto".into(),
            CameraRays::Fixed(n) => n.to_string(),
        }
    }
    fn number(&self) -> Option<f64> {
        match self {
            CameraRays::Auto => None,
            CameraRays::Fixed(n) => Some(f64::from(*n)),
        }
    }
}

/// By the names `Isa` itself gives Embree.
impl Value for Isa {
    fn kind() -> String {
        Isa::ALL.map(Isa::name).join(" | ")
    }
    fn parse(text: &str) -> Option<Self> {
        Isa::named(text.trim()).ok()
    }
    fn show(&self) -> String {
        self.name().into()
    }
}

/// The values a numeric setting may take.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Range {
    Any,
    /// `>= a`
    AtLeast(f64),
    /// `> a`
    Above(f64),
    /// `[a, b]`
    Closed(f64, f64),
    /// `[a, b)`
    ClosedOpen(f64, f64),
    /// `(a, b]`
    OpenClosed(f64, f64),
}

impl Range {
    fn holds(self, x: f64) -> bool {
        match self {
            Range::Any => true,
            Range::AtLeast(a) => x >= a,
            Range::Above(a) => x > a,
            Range::Closed(a, b) => (a..=b).contains(&x),
            Range::ClosedOpen(a, b) => (a..b).contains(&x),
            Range::OpenClosed(a, b) => x > a && x <= b,
        }
    }
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Range::Any => write!(f, "any"),
            Range::AtLeast(a) => write!(f, ">= {a}"),
            Range::Above(a) => write!(f, "> {a}"),
            Range::Closed(a, b) => write!(f, "[{a}, {b}]"),
            Range::ClosedOpen(a, b) => write!(f, "[{a}, {b})"),
            Range::OpenClosed(a, b) => write!(f, "({a}, {b}]"),
        }
    }
}

/// One setting of the schema: what help, docs and the C ABI list.
pub struct Setting {
    pub name: &'static str,
    /// The doc comment's lines.
    doc: &'static [&'static str],
    pub range: Range,
    /// Whether a render with another value needs a build of its own.
    pub needs: Needs,
    kind: fn() -> String,
    default: fn() -> String,
    get: fn(&RenderSettings) -> String,
    set: fn(&mut RenderSettings, &str) -> std::result::Result<(), String>,
    check: fn(&RenderSettings) -> std::result::Result<(), String>,
}

impl Setting {
    /// The doc comment as one paragraph.
    pub fn doc(&self) -> String {
        self.doc
            .iter()
            .map(|l| l.trim())
            .collect::<Vec<_>>()
            .join(" ")
    }
    /// What its text must be: "an integer", "sqrt | throughput", ...
    pub fn kind(&self) -> String {
        (self.kind)()
    }
    /// The default, as text.
    pub fn default_text(&self) -> String {
        (self.default)()
    }
    /// Where `range` says more than `kind`: "an integer, >= 1".
    pub fn allowed(&self) -> String {
        match self.range {
            Range::Any => self.kind(),
            r => format!("{}, {r}", self.kind()),
        }
    }
}

/// `value` parsed as a `T` within `range`, or what is wrong with it.
fn parsed<T: Value>(text: &str, range: Range) -> std::result::Result<T, String> {
    let v = T::parse(text).ok_or_else(|| format!("must be {}", T::kind()))?;
    within(&v, range)?;
    Ok(v)
}

fn within<T: Value>(v: &T, range: Range) -> std::result::Result<(), String> {
    match v.number() {
        // Fields set directly (the Rust API, the C struct) may hold NaN or infinities.
        Some(x) if !x.is_finite() => Err(format!("must be finite, {range}")),
        Some(x) if !range.holds(x) => Err(format!("must be {range}")),
        _ => Ok(()),
    }
}

macro_rules! settings {
    (
        $(#[$rmeta:meta])*
        pub struct RenderSettings {
            $( $(#[doc = $rdoc:literal])* $rname:ident : $rty:ty = $rdefault:expr, $rrange:expr, $rneeds:ident; )*
        }
        $(#[$pmeta:meta])*
        pub struct PathSettings {
            $( $(#[doc = $pdoc:literal])* $pname:ident : $pty:ty = $pdefault:expr, $prange:expr, $pneeds:ident; )*
        }
    ) => {
        $(#[$rmeta])*
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub struct RenderSettings {
            $( $(#[doc = $rdoc])* pub $rname: $rty, )*
            /// How paths are traced.
            pub path: PathSettings,
        }

        $(#[$pmeta])*
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub struct PathSettings {
            $( $(#[doc = $pdoc])* pub $pname: $pty, )*
        }

        impl Default for RenderSettings {
            fn default() -> Self {
                RenderSettings { $($rname: $rdefault,)* path: PathSettings::default() }
            }
        }

        impl Default for PathSettings {
            fn default() -> Self {
                PathSettings { $($pname: $pdefault,)* }
            }
        }

        /// The schema, in declaration order.
        static SETTINGS: &[Setting] = &[
            $(Setting {
                name: stringify!($rname),
                doc: &[$($rdoc),*],
                range: $rrange,
                needs: Needs::$rneeds,
                kind: <$rty as Value>::kind,
                default: || Value::show(&RenderSettings::default().$rname),
                get: |s| Value::show(&s.$rname),
                set: |s, t| Ok(s.$rname = parsed(t, $rrange)?),
                check: |s| within(&s.$rname, $rrange),
            },)*
            $(Setting {
                name: stringify!($pname),
                doc: &[$($pdoc),*],
                range: $prange,
                needs: Needs::$pneeds,
                kind: <$pty as Value>::kind,
                default: || Value::show(&PathSettings::default().$pname),
                get: |s| Value::show(&s.path.$pname),
                set: |s, t| Ok(s.path.$pname = parsed(t, $prange)?),
                check: |s| within(&s.path.$pname, $prange),
            },)*
        ];
    };
}

settings! {
    /// Settings of one render. The image depends only on these and the scene: never on the
    /// thread count or the order tiles finish in. Read and written by name with
    /// [`RenderSettings::set`] and [`RenderSettings::get`]; [`RenderSettings::schema`] lists
    /// them.
    pub struct RenderSettings {
        /// Image width in pixels.
        width: u32 = 640, Range::Closed(1.0, MAX_SIDE as f64), Render;
        /// Image height in pixels.
        height: u32 = 480, Range::Closed(1.0, MAX_SIDE as f64), Render;
        /// Samples per pixel; with a noise target or a time budget, the most.
        spp: u32 = 16, Range::AtLeast(1.0), Render;
        /// Stop once the estimated noise (RMSE relative to the image's mean) is at most this;
        /// none: render all spp.
        noise_target: Option<f32> = None, Range::Above(0.0), Render;
        /// Stop before a pass that would end past this many seconds of rendering; none: no
        /// limit.
        time_budget: Option<f32> = None, Range::Above(0.0), Render;
        /// Where samples go: noise (a pilot pass of 8 spp, then, where the pilot says it
        /// pays, each pixel's share in proportion to its noise over the square root of its
        /// cost, unbiased; the same number of samples over each 32 x 32 block; taken from 9
        /// to 2^22 spp, uniform outside) or uniform (spp in every pixel).
        allocation: Allocation = Allocation::Noise, Range::Any, Render;
        /// The image depends only on the scene, the settings and this seed.
        seed: u64 = 0, Range::Any, Render;
        /// Worker threads; none: one per hardware thread.
        threads: Option<usize> = None, Range::AtLeast(1.0), Render;
        /// Pin Embree's kernels to one instruction set, so that crops rendered on different
        /// CPUs assemble bit for bit (docs/farm.md); none: the widest this CPU runs. A scene's
        /// device holds the pin (`Device::pinned`, `ht_device_new_pinned`): a render asking
        /// another is refused.
        isa: Option<Isa> = None, Range::Any, Build;
        /// Render only the pixels [x0, x1) x [y0, y1) of the full frame, exactly as the full
        /// render has them; none: the full frame.
        crop: Option<[u32; 4]> = None, Range::Any, Render;
        /// Rays per camera sample, spread over its pixel: those that escape add what they
        /// see (the sky) exactly, and the path goes on from one of the others, picked at
        /// random and weighted by their number. The same image in expectation; less noise
        /// where thin strands show a bright sky between them, more cost elsewhere. auto:
        /// chosen for each 32 x 32 block from a survey of the frame before the image, 1 to 8
        /// where strands far under a pixel wide, or moving under an open shutter, against a
        /// bright background make most of the noise, else 1 (and 1 in renders without the
        /// noise allocation's pilot); a count: that many everywhere (docs/measurements.md,
        /// "Camera rays").
        camera_rays: CameraRays = CameraRays::Auto, Range::Closed(1.0, MAX_CAMERA_RAYS as f64), Render;
        /// Pixel filter: tent (thin strands alias under a box) or box (one pixel, as
        /// renderers that use it).
        filter: Filter = Filter::Tent, Range::Any, Render;
        /// The tent's half-width in pixels (the box ignores it).
        filter_radius: f32 = 1.0, Range::OpenClosed(0.0, 8.0), Render;
        /// Level of detail of `auto` grooms: the largest distance, in pixels, between a thin
        /// strand's curve and the linear ribbons traced in its place, or the quads Embree
        /// intersects a cubic ribbon as; 0: no polylines (the quads keep the default's).
        lod_pixels: f32 = DEFAULT_LOD_PIXELS, Range::AtLeast(0.0), Build;
        /// Whether a groom of 2^18 segments or more is built as parts of 2^10, each a BVH
        /// of its own built when a ray first reaches it: auto (from 2^20 segments, for a
        /// render of fewer than 3 camera samples per segment, where the faster build
        /// outweighs the slower rays: docs/large-grooms.md), on or off.
        curve_parts: CurveParts = CurveParts::Auto, Range::Any, Build;
        /// When the shutter opens, in frames from the frame's time (negative: before it).
        /// Curves, meshes and the camera in motion hold their time steps spread evenly from
        /// the opening to the closing, and each camera sample, with every ray of its path, is traced at a time
        /// of its own in between (motion blur); equal to shutter_close: no blur, every ray
        /// at the opening.
        shutter_open: f32 = 0.0, Range::Any, Render;
        /// When the shutter closes, in frames from the frame's time: at least shutter_open.
        shutter_close: f32 = 0.0, Range::Any, Render;
        /// The fewest time steps an animated file (USD, a `.hair` sequence) gives a groom, a
        /// mesh or the camera over an open shutter: 0, as many as take in every time sample
        /// inside it; more follow motion that curves between samples (velocities,
        /// accelerations, a fast turn) more closely, each step read from the file.
        motion_steps: u32 = 0, Range::Closed(0.0, MAX_TIME_STEPS as f64), Render;
    }

    /// How paths are traced and ended, and the hair BSDF's fidelity knobs.
    pub struct PathSettings {
        /// Longest path, in scattering events. 256 keeps a white fur ball's furnace above
        /// 0.9999 (white fibres scatter for hundreds of bounces); Russian roulette ends most
        /// paths far earlier.
        max_depth: u32 = 256, Range::AtLeast(1.0), Render;
        /// Russian roulette may end a path after this many events. 2 always traces the ray
        /// that leaves the first hit: 1.2-1.25x more efficient than 1 or 3 on the bench
        /// scenes.
        rr_depth: u32 = 2, Range::AtLeast(1.0), Render;
        /// Russian roulette's survival: sqrt (of the path throughput's largest channel:
        /// keeps long chains through light hair) or throughput (pbrt's rule).
        roulette: Roulette = Roulette::SqrtThroughput, Range::Any, Render;
        /// Where no light is sampled (a uniform sky alone), roulette's survival at each
        /// depth times a factor learned from a survey of the frame before the image: auto
        /// (at least 1, raised where light the path may still gather outweighs the rays it
        /// costs, to first order: light hair; the rule alone in renders without the noise
        /// allocation's pilot) or off
        /// (docs/measurements.md, "Roulette from the pilot").
        roulette_scale: RouletteScale = RouletteScale::Auto, Range::Any, Render;
        /// Upper bound on the luminance of one contribution of indirect light (biased, cuts
        /// fireflies); none: no clamping.
        clamp_indirect: Option<f32> = None, Range::Above(0.0), Render;
        /// How light is gathered: mis (the renderer), light or bsdf (one strategy alone,
        /// which tests use to show that MIS is unbiased).
        strategy: Strategy = Strategy::Mis, Range::Any, Render;
        /// Past this many scattering events a hair BSDF is one merged lobe (the same
        /// energy, no azimuthal highlights: less noise on light hair, at a bias); none: the
        /// exact model at every event. At most max_depth.
        deep_bounce_depth: Option<u32> = None, Range::AtLeast(1.0), Render;
        /// Hair lobes whose attenuation is below this fraction of the total are dropped;
        /// 0: every lobe. Measured to save no time on the bench scenes.
        lobe_cull: f32 = 0.0, Range::ClosedOpen(0.0, 1.0), Render;
        /// Shadow-ray roulette: a light sample contributing less than this to the pixel
        /// (largest channel) traces its shadow ray with probability contribution /
        /// threshold, reweighted (unbiased); 0: every shadow ray.
        light_threshold: f32 = 0.03, Range::AtLeast(0.0), Render;
        /// Where next-event estimation evaluates a hair BSDF across the fibre: across (the
        /// mean over eight offsets, the hit's among them: the same image in expectation,
        /// 1.5-2.5x less variance per sample under small lights; not at a camera ray's hit on
        /// a strand wider than its pixel, whose highlights the image resolves) or hit (the
        /// hit's offset alone).
        light_offsets: LightOffsets = LightOffsets::Across, Range::Any, Render;
    }
}

/// Where next-event estimation evaluates a hair BSDF across the fibre
/// (`HairPoint::eval_across`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LightOffsets {
    /// Eight offsets spread across the fibre, the hit's among them.
    Across,
    /// The hit's offset alone.
    Hit,
}

/// Whether Russian roulette where no light is sampled scales its survival per depth by
/// what the noise allocation's pilot measured (`super::survival`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RouletteScale {
    /// Learned from the pilot, never below the rule's survival; the rule's alone without a
    /// pilot.
    Auto,
    /// The rule's survival alone.
    Off,
}

/// How Russian roulette turns a path's throughput into its chance to go on. Both are
/// unbiased (a surviving path is reweighted by 1 / survival); they differ in where they
/// spend rays.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Roulette {
    /// Survival = min(1, sqrt(max channel of the throughput)): a dim path lives longer
    /// than its throughput alone says, which keeps long chains through light hair.
    SqrtThroughput,
    /// Survival = min(1, max channel of the throughput) (pbrt's rule): fewer rays per
    /// sample, more variance per ray.
    Throughput,
}

/// How a path's light is gathered. `Mis` is the renderer; the two others exist so that
/// tests can show MIS is unbiased (all three converge to the same image).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Strategy {
    Mis,
    /// Next-event estimation only: emission found by BSDF sampling is ignored, except
    /// what the camera sees directly and lights that next-event estimation never samples
    /// (a uniform environment: see `Light::needs_light_sampling`).
    LightOnly,
    /// BSDF sampling only: no shadow rays.
    BsdfOnly,
}

/// How a render shares its samples among pixels (`super::allocation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Allocation {
    /// `spp` samples in every pixel.
    Uniform,
    /// A pilot pass, then samples in proportion to each pixel's estimated noise.
    Noise,
}

/// How many rays a camera sample is traced as (`super::camera_rays`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraRays {
    /// Chosen per block of pixels from the noise allocation's pilot
    /// (`camera_rays::Choice`).
    Auto,
    /// This many everywhere.
    Fixed(u32),
}

/// When a large groom is built in parts (`crate::embree::PartsRule`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurveParts {
    /// For a render of few camera samples per segment.
    Auto,
    On,
    Off,
}

/// The pixel filter's kind (its radius is `filter_radius`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Filter {
    Tent,
    Box,
}

/// What a change of a setting costs: another render, or a build first (Embree's kernels,
/// the curves' level of detail and parts). The image's size is `Render`: the camera is
/// placed at each render, and the view check (`renderer::serves`) builds again for pixels
/// smaller than the `auto` curves were shaped for. `Scene` reads this alone.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Needs {
    Render,
    Build,
}

/// Largest accepted image side, so that a typo cannot ask for terabytes.
pub(crate) const MAX_SIDE: u32 = 1 << 15;

impl RenderSettings {
    /// Every setting, in declaration order.
    pub fn schema() -> &'static [Setting] {
        SETTINGS
    }

    fn setting(key: &str) -> Result<&'static Setting> {
        SETTINGS.iter().find(|s| s.name == key).ok_or_else(|| {
            invalid_arg!(
                "{key}: not a render setting (the settings: {})",
                SETTINGS
                    .iter()
                    .map(|s| s.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
    }

    /// Sets `key` from its text (`"16"`, `"box"`, `"none"`, `"0,0,64,48"`), checked against
    /// the setting's type and range; an error names the key and what it allows. Checks
    /// across settings (a crop inside the frame) wait for [`Self::validate`].
    ///
    /// ```
    /// let mut settings = hairtrace::RenderSettings::default();
    /// settings.set("spp", "256")?;
    /// settings.set("noise_target", "0.02")?;
    /// assert_eq!(settings.spp, 256);
    /// let e = settings.set("spp", "0").unwrap_err();
    /// assert!(e.to_string().contains("spp"), "{e}");
    /// # Ok::<(), hairtrace::Error>(())
    /// ```
    pub fn set(&mut self, key: &str, value: &str) -> Result<()> {
        let s = Self::setting(key)?;
        (s.set)(self, value).map_err(|why| Error::InvalidArg(format!("{key} = {value}: {why}")))
    }

    /// The value of `key`, as [`Self::set`] reads it.
    pub fn get(&self, key: &str) -> Result<String> {
        Ok((Self::setting(key)?.get)(self))
    }

    /// Checks every setting's range and the rules between settings.
    pub fn validate(&self) -> Result<()> {
        for s in SETTINGS {
            (s.check)(self).map_err(|why| {
                Error::InvalidArg(format!("{} = {}: {why}", s.name, (s.get)(self)))
            })?;
        }
        if let Some([x0, y0, x1, y1]) = self.crop {
            if !(x0 < x1 && y0 < y1 && x1 <= self.width && y1 <= self.height) {
                return Err(invalid_arg!(
                    "crop = {x0},{y0},{x1},{y1}: must satisfy x0 < x1 <= width ({}) and y0 < y1 \
                     <= height ({})",
                    self.width,
                    self.height
                ));
            }
        }
        if self.shutter_close < self.shutter_open {
            return Err(invalid_arg!(
                "shutter_close = {}: the shutter closes before it opens (shutter_open = {})",
                self.shutter_close,
                self.shutter_open
            ));
        }
        if let Some(n) = self.path.deep_bounce_depth {
            if n > self.path.max_depth {
                return Err(invalid_arg!(
                    "deep_bounce_depth = {n}: must be at most max_depth = {} (none: the exact \
                     BSDF at every event)",
                    self.path.max_depth
                ));
            }
        }
        Ok(())
    }

    /// The first setting that [needs a build](Needs::Build) whose value differs from
    /// `built`'s (the settings a scene was built for): None when a render with these
    /// settings can use that build.
    pub(crate) fn build_change(&self, built: &RenderSettings) -> Option<&'static str> {
        (SETTINGS.iter())
            .find(|s| s.needs == Needs::Build && (s.get)(self) != (s.get)(built))
            .map(|s| s.name)
    }

    /// Whether the shutter stays open for a while: each camera sample then has a time of
    /// its own.
    pub fn motion_blur(&self) -> bool {
        self.shutter_close > self.shutter_open
    }

    /// The crop window, or the full frame.
    pub fn window(&self) -> [u32; 4] {
        self.crop.unwrap_or([0, 0, self.width, self.height])
    }

    /// Where in and around its pixel each sample lands.
    pub fn pixel_filter(&self) -> Result<PixelFilter> {
        match self.filter {
            Filter::Tent => PixelFilter::tent(self.filter_radius),
            Filter::Box => Ok(PixelFilter::BOX),
        }
    }

    /// The Embree device these settings ask for: their thread count and pinned ISA.
    pub fn device(&self) -> Result<Device> {
        Device::pinned(self.threads, self.isa)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_setting_round_trips_its_default_through_text() {
        let d = RenderSettings::default();
        for s in RenderSettings::schema() {
            let mut r = RenderSettings::default();
            r.set(s.name, &s.default_text()).unwrap();
            assert_eq!(r, d, "{}", s.name);
            assert_eq!(r.get(s.name).unwrap(), s.default_text());
            assert!(!s.doc().is_empty(), "{} has no doc", s.name);
        }
        d.validate().unwrap();
    }

    #[test]
    fn set_reaches_the_field_and_refuses_what_the_schema_refuses() {
        let mut r = RenderSettings::default();
        r.set("spp", "64").unwrap();
        r.set("roulette", "throughput").unwrap();
        r.set("crop", "0,0,32,16").unwrap();
        r.set("clamp_indirect", "10").unwrap();
        r.set("isa", "sse2").unwrap();
        assert_eq!(
            (r.spp, r.path.roulette, r.crop, r.path.clamp_indirect, r.isa),
            (
                64,
                Roulette::Throughput,
                Some([0, 0, 32, 16]),
                Some(10.0),
                Some(Isa::Sse2)
            )
        );
        for (key, value, says) in [
            ("spp", "0", "spp = 0: must be >= 1"),
            ("spp", "1.5", "must be an integer"),
            ("width", "40000", "must be [1, 32768]"),
            ("lobe_cull", "1", "must be [0, 1)"),
            ("light_threshold", "NaN", "must be a number"),
            ("light_threshold", "inf", "must be a number"),
            ("clamp_indirect", "0", "must be > 0"),
            ("roulette", "cube", "must be sqrt | throughput"),
            ("filter_radius", "0", "must be (0, 8]"),
            ("camera_rays", "0", "must be [1, 16]"),
            ("camera_rays", "17", "must be [1, 16]"),
            ("sp", "4", "sp: not a render setting"),
        ] {
            let before = r;
            let e = r.set(key, value).unwrap_err().to_string();
            assert!(e.contains(says), "{key} = {value}: {e}");
            assert_eq!(r, before, "a refused value must change nothing");
        }
    }

    #[test]
    fn validate_checks_ranges_of_fields_set_directly_and_rules_between_settings() {
        let mut r = RenderSettings::default();
        r.path.lobe_cull = 1.0;
        assert!(
            r.validate()
                .unwrap_err()
                .to_string()
                .contains("lobe_cull = 1")
        );
        let r = RenderSettings {
            crop: Some([0, 0, 641, 10]),
            ..RenderSettings::default()
        };
        assert!(r.validate().unwrap_err().to_string().contains("crop"));
        let mut r = RenderSettings::default();
        r.path.max_depth = 4;
        r.path.deep_bounce_depth = Some(5);
        assert!(
            r.validate()
                .unwrap_err()
                .to_string()
                .contains("at most max_depth")
        );
        r.path.deep_bounce_depth = Some(4);
        r.validate().unwrap();
        // Sample indices are u32s, and every spp is valid: past 2^22 the noise allocation
        // gives way to uniform sampling (`renderer::allocation_taken`).
        RenderSettings {
            spp: u32::MAX,
            ..RenderSettings::default()
        }
        .validate()
        .unwrap();
    }
}
