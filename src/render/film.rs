//! The film: per-pixel averages of camera samples in a crop window of the full frame,
//! with optional AOVs (albedo, depth, strand id) for compositing and denoising.
//!
//! Pixels are addressed by full-frame coordinates everywhere, so a crop renders exactly
//! the values the same pixels have in a full render: a render farm can split a frame and
//! assemble the pieces bit for bit.

use glam::Vec3;

use crate::Result;
use crate::error::invalid_arg;

/// A rectangle of pixels `[x0, x1) x [y0, y1)` in full-frame coordinates: a crop window
/// or a tile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Window {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Window {
    /// The whole of a `width` x `height` frame.
    pub fn full(width: u32, height: u32) -> Self {
        Self {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    pub fn width(&self) -> u32 {
        self.x1.saturating_sub(self.x0)
    }

    pub fn height(&self) -> u32 {
        self.y1.saturating_sub(self.y0)
    }

    pub fn pixel_count(&self) -> u64 {
        u64::from(self.width()) * u64::from(self.height())
    }

    /// Full-frame coordinates of the window's pixels, row by row from the top.
    pub fn pixels(&self) -> impl Iterator<Item = (u32, u32)> + use<> {
        let Window { x0, y0, x1, y1 } = *self;
        (y0..y1).flat_map(move |y| (x0..x1).map(move |x| (x, y)))
    }
}

/// Which AOVs a film keeps besides colour.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Aovs {
    pub albedo: bool,
    pub depth: bool,
    pub strand_id: bool,
}

impl Aovs {
    /// Whether any AOV is asked for: without one, first hits need not be described.
    pub fn any(&self) -> bool {
        self.albedo || self.depth || self.strand_id
    }
}

/// What the first camera-ray hit of a sample reports for the AOVs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FirstHit {
    /// Reflectance colour of the surface (hair colour, diffuse albedo), in [0, 1].
    pub albedo: Vec3,
    /// Distance from the camera along the ray.
    pub depth: f32,
    /// Strand index for hair, `None` for meshes.
    pub strand: Option<u32>,
}

/// What a camera sample's single ray met first: what `camera_rays = auto` reads of the
/// pilot (`super::camera_rays::Choice`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Seen {
    /// It escaped.
    Nothing,
    /// A surface.
    Surface,
    /// A strand this many pixels wide there.
    Strand(f32),
    /// The sample was several rays.
    Split,
}

/// A pixel's samples as [`Seen`] sums them: those whose ray escaped and their summed
/// radiance, and those that met a strand first and the strands' summed width in pixels.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Coverage {
    pub escaped: u32,
    pub escaped_rgb: [f32; 3],
    pub strands: u32,
    pub strand_width: f32,
}

/// How a pixel's samples map to positions: each sample's offset from the pixel centre
/// is drawn from the filter (filter importance sampling), so every sample has weight 1
/// and belongs to exactly one pixel, which keeps pixels independent of each other (and of
/// tiles and crops). A wider filter trades sharpness for less aliasing of thin strands.
///
/// The default is a tent of radius 1 pixel: strands thinner than a pixel alias into
/// stair-steps and crawling highlights under a box, and the tent's overlap between
/// neighbours removes most of that for the price of a slightly softer image. The box is
/// there for comparisons with renderers that use it, and for exact pixel coverage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelFilter {
    /// Half-width of a tent in pixels; 0 is the one-pixel box.
    tent_radius: f32,
}

impl Default for PixelFilter {
    fn default() -> Self {
        PixelFilter { tent_radius: 1.0 }
    }
}

impl PixelFilter {
    /// The one-pixel box filter.
    pub const BOX: PixelFilter = PixelFilter { tent_radius: 0.0 };

    /// The filter named `name` ("box" or "tent"); `radius` is the tent's half-width in
    /// pixels (default 1) and must not be given for the box.
    pub fn named(name: &str, radius: Option<f32>) -> Result<Self> {
        match (name, radius) {
            ("box", None) => Ok(Self::BOX),
            ("box", Some(r)) => Err(invalid_arg!(
                "filter_radius = {r} applies to the tent filter, not the box (always one pixel)"
            )),
            ("tent", r) => Self::tent(r.unwrap_or(1.0)),
            _ => Err(invalid_arg!(
                "unknown pixel filter {name:?} (choose box or tent)"
            )),
        }
    }

    /// The filter's name, as [`Self::named`] takes it, and the tent's radius.
    pub fn name(&self) -> (&'static str, Option<f32>) {
        if self.tent_radius == 0.0 {
            ("box", None)
        } else {
            ("tent", Some(self.tent_radius))
        }
    }

    /// A separable tent (triangle) of half-width `radius` pixels, in (0, 8].
    pub fn tent(radius: f32) -> Result<Self> {
        if !(radius > 0.0 && radius <= 8.0) {
            return Err(invalid_arg!(
                "tent filter radius {radius} must be in (0, 8] pixels"
            ));
        }
        Ok(Self {
            tent_radius: radius,
        })
    }

    /// Offset from the pixel centre, in pixels, for `u` in [0, 1)^2.
    pub fn sample(&self, u: [f32; 2]) -> [f32; 2] {
        let r = self.tent_radius;
        if r == 0.0 {
            return [u[0] - 0.5, u[1] - 0.5];
        }
        // Inverse CDF of the triangle on [-r, r], one half at a time.
        let tent = |u: f32| {
            if u < 0.5 {
                r * ((2.0 * u).sqrt() - 1.0)
            } else {
                r * (1.0 - (2.0 - 2.0 * u).sqrt())
            }
        };
        [tent(u[0]), tent(u[1])]
    }
}

/// Depth AOV of a pixel no sample hit. Zero, because a file must stay finite (and half
/// floats overflow past 65504); no real hit is at distance 0.
pub const NO_HIT_DEPTH: f32 = 0.0;
/// Strand-id AOV of a pixel whose nearest hit is not hair (or nothing).
pub const NO_STRAND: f32 = -1.0;

/// Sums one pixel's samples, over a render's passes, keeping the sums at the last two
/// power-of-two pass counts: the two halves that estimate the noise of the mean. The tiles
/// take one from the film for each pixel they render, hand it to the per-pixel function and
/// store it back; the film keeps of it only what its [`Keep`] says.
#[derive(Debug, Clone)]
pub struct PixelAccumulator {
    rgb: [f64; 3],
    /// Sums of squares of the samples, for their variance.
    rgb_sq: [f64; 3],
    /// Rays the samples traced: their cost.
    rays: u64,
    albedo: [f64; 3],
    samples: u32,
    rejected: u32,
    nearest: f32,
    strand: f32,
    /// Passes ended ([`Self::end_pass`]).
    passes: u32,
    /// The sums and sample counts when `passes` was last a power of two, and the time
    /// before (half as many passes); f32, as they only estimate the noise.
    last_power: ([f32; 3], u32),
    half_power: ([f32; 3], u32),
    coverage: Coverage,
}

impl Default for PixelAccumulator {
    fn default() -> Self {
        Self {
            rgb: [0.0; 3],
            rgb_sq: [0.0; 3],
            rays: 0,
            albedo: [0.0; 3],
            samples: 0,
            rejected: 0,
            nearest: f32::INFINITY,
            strand: NO_STRAND,
            passes: 0,
            last_power: ([0.0; 3], 0),
            half_power: ([0.0; 3], 0),
            coverage: Coverage::default(),
        }
    }
}

impl PixelAccumulator {
    /// Adds a camera sample's radiance and what its first hit reports (`None` for a ray
    /// that escaped).
    ///
    /// A sample with any NaN or infinite value (a numerical accident somewhere along the
    /// path) counts as a black sample that hit nothing, and is counted in
    /// [`Film::rejected_samples`]: one bad path darkens its pixel by 1/spp instead of
    /// poisoning it, and the count tells the accident happened.
    pub fn add(&mut self, radiance: Vec3, hit: Option<&FirstHit>) {
        self.samples += 1;
        let hit_ok = hit.is_none_or(|h| h.albedo.is_finite() && h.depth.is_finite());
        if !(radiance.is_finite() && hit_ok) {
            self.rejected += 1;
            return;
        }
        for (c, v) in radiance.to_array().into_iter().enumerate() {
            let v = f64::from(v);
            self.rgb[c] += v;
            self.rgb_sq[c] += v * v;
        }
        if let Some(h) = hit {
            for (sum, v) in self.albedo.iter_mut().zip(h.albedo.to_array()) {
                *sum += f64::from(v);
            }
            // Depth and strand come from the nearest hit: an average of ids is no id,
            // and an average depth across a silhouette is a depth of nothing.
            if h.depth < self.nearest {
                self.nearest = h.depth;
                self.strand = h.strand.map_or(NO_STRAND, |s| s as f32);
            }
        }
    }

    fn mean(&self, sum: [f64; 3]) -> [f32; 3] {
        let n = f64::from(self.samples.max(1));
        sum.map(|s| (s / n) as f32)
    }

    /// Adds what a sample's single camera ray met first ([`Self::coverage`]); a radiance
    /// [`Self::add`] rejects is left out here too.
    pub fn add_seen(&mut self, seen: Seen, radiance: Vec3) {
        if !radiance.is_finite() {
            return;
        }
        let c = &mut self.coverage;
        match seen {
            Seen::Nothing => {
                c.escaped += 1;
                for (sum, v) in c.escaped_rgb.iter_mut().zip(radiance.to_array()) {
                    *sum += v;
                }
            }
            Seen::Strand(width) if width.is_finite() => {
                c.strands += 1;
                c.strand_width += width;
            }
            _ => {}
        }
    }

    /// What [`Self::add_seen`] summed.
    pub fn coverage(&self) -> Coverage {
        self.coverage
    }

    /// Counts the rays a sample traced.
    pub fn add_rays(&mut self, rays: u32) {
        self.rays += u64::from(rays);
    }

    /// Rays traced so far.
    pub fn rays(&self) -> u64 {
        self.rays
    }

    /// Samples so far.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// The variance of one sample, per channel (the unbiased estimate; 0 below two samples).
    pub fn sample_variance(&self) -> [f64; 3] {
        if self.samples < 2 {
            return [0.0; 3];
        }
        let n = f64::from(self.samples);
        std::array::from_fn(|c| {
            ((self.rgb_sq[c] - self.rgb[c] * self.rgb[c] / n) / (n - 1.0)).max(0.0)
        })
    }

    /// Each channel's mean, in f64.
    pub fn mean_rgb(&self) -> [f64; 3] {
        let n = f64::from(self.samples.max(1));
        self.rgb.map(|s| s / n)
    }

    /// Ends a pass of the render over this pixel.
    pub fn end_pass(&mut self) {
        self.passes += 1;
        if self.passes.is_power_of_two() {
            self.half_power = self.last_power;
            self.last_power = (self.rgb.map(|v| v as f32), self.samples);
        }
    }

    /// The variance of each channel's mean, from the difference between two halves: the
    /// samples of the first h passes, h the largest power of two at most half the passes,
    /// against the rest; None before two passes. The first half is a power-of-two block of
    /// the Sobol sequence and the second nearly one, each stratified in itself, so the
    /// estimate keeps the sampler's stratification within halves (a per-sample variance,
    /// or the spread of the passes' means, would miss most of it and overstate the noise);
    /// it misses only the gain of joining the two.
    pub fn variance_of_mean(&self) -> Option<[f64; 3]> {
        let (first, n_first) = self.half_power;
        let n_rest = self.samples.checked_sub(n_first)?;
        if self.passes < 2 || n_first == 0 || n_rest == 0 {
            return None;
        }
        let (a, b, n) = (
            f64::from(n_first),
            f64::from(n_rest),
            f64::from(self.samples),
        );
        Some(std::array::from_fn(|c| {
            let first = f64::from(first[c]);
            let d = first / a - (self.rgb[c] - first) / b;
            // E[d^2] = sigma^2 (1/a + 1/b) for independent samples of variance sigma^2.
            d * d / (1.0 / a + 1.0 / b) / n
        }))
    }
}

/// What a film keeps of each pixel's samples besides its image: only what the render that
/// fills it reads, since at 4K each byte per pixel is 8 MB.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Keep {
    /// The image alone: a render into the film replaces its pixels. For a render that takes
    /// all its samples of a pixel at once.
    Image,
    /// Also each pixel's sums, so that a further render into the film adds to them: a
    /// render in passes.
    #[default]
    Sums,
    /// The sums and the two halves of `PixelAccumulator::variance_of_mean`: a render in
    /// passes that estimates its noise.
    Halves,
    /// The sums, the squares and the rays of each pixel: its variance and cost per sample
    /// (the noise allocation's pilot).
    Spread,
}

/// The two halves a [`Keep::Halves`] film keeps of a pixel.
#[derive(Debug, Clone, Copy, Default)]
struct Halves {
    passes: u32,
    last_power: ([f32; 3], u32),
    half_power: ([f32; 3], u32),
}

impl Keep {
    /// The bytes a film of `aovs` keeping this takes per pixel: its image and AOVs, and the
    /// running sums kept besides.
    pub fn bytes_per_pixel(self, aovs: Aovs) -> u64 {
        let f32s = |n: usize| (n * size_of::<f32>()) as u64;
        let mut bytes = f32s(3)
            + f32s(3) * u64::from(aovs.albedo)
            + f32s(1) * u64::from(aovs.depth)
            + f32s(1) * u64::from(aovs.strand_id);
        if self != Keep::Image {
            bytes += (size_of::<[f64; 3]>() + size_of::<u32>()) as u64;
            bytes += size_of::<[f64; 3]>() as u64 * u64::from(aovs.albedo);
            bytes += f32s(1) * u64::from(aovs.depth || aovs.strand_id);
        }
        bytes
            + match self {
                Keep::Halves => size_of::<Halves>() as u64,
                Keep::Spread => (size_of::<[f64; 3]>() + size_of::<u64>()) as u64,
                Keep::Image | Keep::Sums => 0,
            }
    }
}

/// The camera's [0, 1]^2 image point of a sample at `offset` pixels (from a
/// [`PixelFilter`]) from the centre of the full-frame `pixel` of a `width` x `height` frame.
pub fn ndc(width: u32, height: u32, pixel: (u32, u32), offset: [f32; 2]) -> [f32; 2] {
    [
        (pixel.0 as f32 + 0.5 + offset[0]) / width as f32,
        (pixel.1 as f32 + 0.5 + offset[1]) / height as f32,
    ]
}

/// Float RGB (and AOV) pixels of a crop window of a `width` x `height` frame, and what
/// its [`Keep`] says of each pixel's samples.
#[derive(Debug, Clone)]
pub struct Film {
    width: u32,
    height: u32,
    crop: Window,
    keep: Keep,
    rgb: Vec<f32>,
    albedo: Option<Vec<f32>>,
    depth: Option<Vec<f32>>,
    strand_id: Option<Vec<f32>>,
    /// Each pixel's kept sums; empty where the [`Keep`] or the AOVs do not ask for them.
    sums: Vec<[f64; 3]>,
    samples: Vec<u32>,
    albedo_sums: Vec<[f64; 3]>,
    nearest: Vec<f32>,
    halves: Vec<Halves>,
    squares: Vec<[f64; 3]>,
    rays: Vec<u64>,
    /// Over the whole film: samples taken, rejected (`PixelAccumulator::add`) and rays
    /// traced by the samples of the pixels as stored.
    totals: Totals,
}

#[derive(Debug, Clone, Copy, Default)]
struct Totals {
    samples: u64,
    rejected: u64,
    rays: u64,
}

impl Film {
    /// A black film of the full frame, or of `crop` (non-empty, inside the frame), that
    /// keeps each pixel's sums ([`Keep::Sums`]).
    pub fn new(width: u32, height: u32, crop: Option<Window>, aovs: Aovs) -> Result<Self> {
        Self::keeping(width, height, crop, aovs, Keep::Sums)
    }

    /// A black film as [`Self::new`] makes, keeping `keep` of each pixel's samples.
    pub fn keeping(
        width: u32,
        height: u32,
        crop: Option<Window>,
        aovs: Aovs,
        keep: Keep,
    ) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(invalid_arg!(
                "film size {width} x {height} must be at least 1 x 1"
            ));
        }
        let crop = crop.unwrap_or(Window::full(width, height));
        if !(crop.x0 < crop.x1 && crop.y0 < crop.y1 && crop.x1 <= width && crop.y1 <= height) {
            return Err(invalid_arg!(
                "crop window x [{}, {}) y [{}, {}) must be non-empty and inside the \
                 {width} x {height} frame",
                crop.x0,
                crop.x1,
                crop.y0,
                crop.y1
            ));
        }
        let pixels = usize::try_from(crop.pixel_count())
            .map_err(|_| invalid_arg!("film of {width} x {height} is too large"))?;
        let values = |channels: usize| {
            pixels
                .checked_mul(channels)
                .ok_or_else(|| invalid_arg!("film of {width} x {height} is too large"))
        };
        let aov = |on: bool, channels, fill| -> Result<Option<Vec<f32>>> {
            on.then(|| filled(values(channels)?, fill)).transpose()
        };
        let sums = keep != Keep::Image;
        let kept = |on: bool| if on { pixels } else { 0 };
        Ok(Self {
            width,
            height,
            crop,
            keep,
            rgb: filled(values(3)?, 0.0)?,
            albedo: aov(aovs.albedo, 3, 0.0)?,
            depth: aov(aovs.depth, 1, NO_HIT_DEPTH)?,
            strand_id: aov(aovs.strand_id, 1, NO_STRAND)?,
            sums: filled(kept(sums), [0.0; 3])?,
            samples: filled(kept(sums), 0)?,
            albedo_sums: filled(kept(sums && aovs.albedo), [0.0; 3])?,
            nearest: filled(kept(sums && (aovs.depth || aovs.strand_id)), f32::INFINITY)?,
            halves: filled(kept(keep == Keep::Halves), Halves::default())?,
            squares: filled(kept(keep == Keep::Spread), [0.0; 3])?,
            rays: filled(kept(keep == Keep::Spread), 0)?,
            totals: Totals::default(),
        })
    }

    /// Full frame width.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Full frame height.
    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn crop(&self) -> Window {
        self.crop
    }

    /// What the film keeps of each pixel's samples.
    pub fn keep(&self) -> Keep {
        self.keep
    }

    /// The bytes the film's pixels take: its image, AOVs and kept sums.
    pub fn bytes(&self) -> u64 {
        fn of<T>(v: &[T]) -> u64 {
            size_of_val(v) as u64
        }
        let aovs = [&self.albedo, &self.depth, &self.strand_id];
        of(&self.rgb)
            + aovs.iter().map(|a| a.as_deref().map_or(0, of)).sum::<u64>()
            + of(&self.sums)
            + of(&self.samples)
            + of(&self.albedo_sums)
            + of(&self.nearest)
            + of(&self.halves)
            + of(&self.squares)
            + of(&self.rays)
    }

    /// The camera's [0, 1]^2 image point of a sample; see `render::film::ndc`.
    pub fn ndc(&self, pixel: (u32, u32), offset: [f32; 2]) -> [f32; 2] {
        ndc(self.width, self.height, pixel, offset)
    }

    /// Interleaved RGB of the crop window, rows from the top: what `write_image` takes,
    /// with the crop's width and height.
    pub fn rgb(&self) -> &[f32] {
        &self.rgb
    }

    /// Interleaved mean albedo RGB of the first hits (0 where rays escaped).
    pub fn albedo(&self) -> Option<&[f32]> {
        self.albedo.as_deref()
    }

    /// Distance to the nearest first hit of each pixel ([`NO_HIT_DEPTH`] for none).
    pub fn depth(&self) -> Option<&[f32]> {
        self.depth.as_deref()
    }

    /// Strand index of each pixel's nearest first hit as f32 ([`NO_STRAND`] for none);
    /// exact up to 2^24 strands.
    pub fn strand_id(&self) -> Option<&[f32]> {
        self.strand_id.as_deref()
    }

    /// Samples whose values were NaN or infinite, counted as black (see
    /// `PixelAccumulator::add`).
    pub fn rejected_samples(&self) -> u64 {
        self.totals.rejected
    }

    /// The estimated noise of the image: the RMSE of its pixels' means (over pixels and
    /// channels, as `hairtrace compare` measures it) relative to the image's mean, from
    /// `PixelAccumulator::variance_of_mean`. None before two passes, for a film that
    /// does not keep the halves ([`Keep::Halves`]), or for an image whose mean is not
    /// positive while it has noise.
    pub fn noise(&self) -> Option<f32> {
        if self.halves.is_empty() {
            return None;
        }
        let mut pixels = Vec::with_capacity(self.halves.len());
        for p in self.crop.pixels() {
            let acc = self.accumulator(p);
            pixels.push((acc.mean_rgb(), acc.variance_of_mean()?));
        }
        relative_rmse(pixels)
    }

    /// Camera samples taken so far.
    pub fn samples(&self) -> u64 {
        self.totals.samples
    }

    /// Rays traced by the samples so far.
    pub fn rays(&self) -> u64 {
        self.totals.rays
    }

    fn index(&self, pixel: (u32, u32)) -> usize {
        ((pixel.1 - self.crop.y0) as usize) * self.crop.width() as usize
            + (pixel.0 - self.crop.x0) as usize
    }

    /// The samples so far of a pixel (full-frame coordinates, inside the crop), as far as
    /// the film keeps them: none of an [`Keep::Image`] film's, and its rejected samples
    /// and (but for [`Keep::Spread`]) rays counted in the film's totals instead.
    pub(super) fn accumulator(&self, pixel: (u32, u32)) -> PixelAccumulator {
        let i = self.index(pixel);
        let mut acc = PixelAccumulator::default();
        if let (Some(&rgb), Some(&samples)) = (self.sums.get(i), self.samples.get(i)) {
            (acc.rgb, acc.samples) = (rgb, samples);
        }
        if let Some(&albedo) = self.albedo_sums.get(i) {
            acc.albedo = albedo;
        }
        if let Some(&nearest) = self.nearest.get(i) {
            acc.nearest = nearest;
            acc.strand = self.strand_id.as_ref().map_or(NO_STRAND, |s| s[i]);
        }
        if let Some(h) = self.halves.get(i) {
            (acc.passes, acc.last_power, acc.half_power) = (h.passes, h.last_power, h.half_power);
        }
        if let (Some(&squares), Some(&rays)) = (self.squares.get(i), self.rays.get(i)) {
            (acc.rgb_sq, acc.rays) = (squares, rays);
        }
        acc
    }

    /// Stores a pixel's samples so far, given in full-frame coordinates inside the crop:
    /// `acc` grew from [`Self::accumulator`]'s.
    pub(super) fn store(&mut self, pixel: (u32, u32), acc: &PixelAccumulator) {
        let i = self.index(pixel);
        let kept = self.accumulator(pixel);
        // What `acc` adds to the kept counts (the totals hold those, so never go negative).
        let t = &mut self.totals;
        t.samples = t.samples + u64::from(acc.samples) - u64::from(kept.samples);
        t.rejected = t.rejected + u64::from(acc.rejected) - u64::from(kept.rejected);
        t.rays = t.rays + acc.rays - kept.rays;
        if let (Some(rgb), Some(samples)) = (self.sums.get_mut(i), self.samples.get_mut(i)) {
            (*rgb, *samples) = (acc.rgb, acc.samples);
        }
        if let Some(albedo) = self.albedo_sums.get_mut(i) {
            *albedo = acc.albedo;
        }
        if let Some(nearest) = self.nearest.get_mut(i) {
            *nearest = acc.nearest;
        }
        if let Some(h) = self.halves.get_mut(i) {
            *h = Halves {
                passes: acc.passes,
                last_power: acc.last_power,
                half_power: acc.half_power,
            };
        }
        if let (Some(squares), Some(rays)) = (self.squares.get_mut(i), self.rays.get_mut(i)) {
            (*squares, *rays) = (acc.rgb_sq, acc.rays);
        }
        self.write(i, acc.mean(acc.rgb), acc.mean(acc.albedo), acc);
    }

    /// Makes a pixel's values `pilot_weight` x the pilot's means + the rest x its own
    /// (its depth and strand those of the nearer of the two's nearest hits). Its samples
    /// stay its own.
    pub(super) fn store_blend(
        &mut self,
        pixel: (u32, u32),
        pilot: &PixelAccumulator,
        pilot_weight: f64,
    ) {
        let i = self.index(pixel);
        let own = self.accumulator(pixel);
        let blend = |p: [f32; 3], o: [f32; 3]| {
            std::array::from_fn(|c| {
                (pilot_weight * f64::from(p[c]) + (1.0 - pilot_weight) * f64::from(o[c])) as f32
            })
        };
        let rgb = blend(pilot.mean(pilot.rgb), own.mean(own.rgb));
        let albedo = blend(pilot.mean(pilot.albedo), own.mean(own.albedo));
        let nearest = if pilot.nearest < own.nearest {
            pilot
        } else {
            &own
        };
        self.write(i, rgb, albedo, nearest);
    }

    /// Writes pixel `i`'s colour, albedo, and the depth and strand of `nearest`'s hit.
    fn write(&mut self, i: usize, rgb: [f32; 3], albedo: [f32; 3], nearest: &PixelAccumulator) {
        self.rgb[3 * i..3 * i + 3].copy_from_slice(&rgb);
        if let Some(a) = &mut self.albedo {
            a[3 * i..3 * i + 3].copy_from_slice(&albedo);
        }
        if let Some(depth) = &mut self.depth {
            depth[i] = if nearest.nearest.is_finite() {
                nearest.nearest
            } else {
                NO_HIT_DEPTH
            };
        }
        if let Some(strand) = &mut self.strand_id {
            strand[i] = nearest.strand;
        }
    }
}

/// The RMSE of pixels given as (mean, variance of the mean) per channel, over pixels and
/// channels, relative to their mean: a film's estimated noise. Zero without variance, None
/// for noise on a mean that is not positive.
pub(super) fn relative_rmse(pixels: Vec<([f64; 3], [f64; 3])>) -> Option<f32> {
    let values = 3.0 * pixels.len() as f64;
    let (variance, sum) = pixels.iter().fold((0.0, 0.0), |(v, s), (m, var)| {
        (v + var.iter().sum::<f64>(), s + m.iter().sum::<f64>())
    });
    match (variance, sum) {
        (0.0, _) => Some(0.0),
        (v, s) if s > 0.0 => Some(((v / values).sqrt() / (s / values)) as f32),
        _ => None,
    }
}

/// A buffer of `n` copies of `fill`, or an error rather than an abort when memory runs
/// out.
fn filled<T: Copy>(n: usize, fill: T) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| invalid_arg!("cannot allocate a film of {n} values"))?;
    v.resize(n, fill);
    Ok(v)
}
