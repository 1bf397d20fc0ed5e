/*
 * hairtrace.hpp: a C++17 layer over the C ABI of hairtrace.h, header-only.
 *
 * - Every handle has an owner that releases it: `Material` (HtHairPrepared), `HuangMaterial`
 *   (HtHuangPrepared), and with the full library `Device`, `Scene`, `Settings`. `get()`
 *   gives the C handle, for the C calls this layer does not wrap. `Scene` wraps the calls
 *   of motion and animation: strands and meshes at several time steps, files read at a
 *   frame.
 * - The host's own vectors go in and out as they are: anything with `x, y, z` members or
 *   an `operator[]` (glm, Eigen, a `float[3]`, a std::array), converted to float.
 * - Two forms of every per-vertex call. The value form throws `hairtrace::Error` (the
 *   status and `ht_last_error()`'s message): for set-up and for hosts that catch per
 *   frame. The status form is `noexcept`, writes its result to an out-parameter and
 *   returns the `HtStatus` (`HT_OK`, or read `ht_last_error()` on this thread): for a
 *   renderer's worker threads, where an escaped exception would end the render and a
 *   try/catch around every vertex is not wanted. "No direction" is a sample with pdf 0,
 *   not an error, in both forms.
 *
 * The hot path is three calls per path vertex: `Point::set_at_hit` (a hit to a point with
 * its frame), `eval_world` (f |cos| and pdf toward a light), `sample_world` (a direction,
 * f |cos|, the weight f |cos| / pdf and the pdf). `Point` and `Frame` are
 * default-constructible, so a host's vertex struct holds them. They give the bits of the C
 * calls they wrap. `HuangPoint` is the same vertex for the Huang model of elliptical
 * fibres, whose calls also take the section's major axis, the jitter and the field.
 */
#ifndef HT_HAIRTRACE_HPP
#define HT_HAIRTRACE_HPP

#include "hairtrace.h"

#include <array>
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace hairtrace {

/** A status other than HT_OK, with the library's message for it. */
class Error : public std::runtime_error {
public:
    Error(HtStatus status, const std::string &message)
        : std::runtime_error(message), status_(status) {}
    /** The C status (`HT_ERR_INVALID_ARG`, ...). */
    HtStatus status() const noexcept { return status_; }

private:
    HtStatus status_;
};

/** Throws `Error` for any status but HT_OK, with `ht_last_error()`'s message. */
inline void check(HtStatus status) {
    if (status != HT_OK) {
        throw Error(status, std::string(ht_status_str(static_cast<int32_t>(status))) + ": " +
                                ht_last_error());
    }
}

/** The vectors of this layer: three floats, as the C ABI takes them. */
using Vec3 = std::array<float, 3>;

namespace detail {
template <class V, class = void> struct HasXyz : std::false_type {};
template <class V>
struct HasXyz<V, std::void_t<decltype(std::declval<const V &>().x),
                             decltype(std::declval<const V &>().y),
                             decltype(std::declval<const V &>().z)>> : std::true_type {};
} // namespace detail

/** A host vector as three floats: its `x, y, z` if it has them, else `v[0], v[1], v[2]`. */
template <class V> Vec3 vec3(const V &v) {
    if constexpr (detail::HasXyz<V>::value) {
        return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
    } else {
        return {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2])};
    }
}

/** Three floats as a host vector type `V`, built as `V{x, y, z}`. */
template <class V> V as(const Vec3 &v) {
    return V{v[0], v[1], v[2]};
}

/** f |cos| (RGB, the fraction scattered per unit solid angle) and pdf toward a direction. */
struct Eval {
    Vec3 f_cos;
    float pdf;
};

/** `Eval` at each of the `HT_ACROSS` offsets across the fibre, the point's own first. */
using Across = std::array<Eval, HT_ACROSS>;

/** A sampled direction, f |cos| toward it, its weight f |cos| / pdf and its pdf; pdf 0: no
 * direction. */
struct Sample {
    Vec3 wi;
    Vec3 f_cos;
    Vec3 weight;
    float pdf;
    explicit operator bool() const noexcept { return pdf > 0.0f; }
};

/** `HtHairParams` with the library's defaults (brown hair); fields as in hairtrace.h. */
inline HtHairParams default_params() { return ht_hair_params_default(); }

/** `HtHuangParams` with the library's defaults (brown, round); fields as in hairtrace.h. */
inline HtHuangParams default_huang_params() { return ht_huang_params_default(); }

/** The two numbers a Huang point draws its microfacet normals from, each in [0, 1). */
using Jitter = std::array<float, 2>;

/** sigma_a for melanin concentrations (`ht_hair_sigma_a_from_melanin`). */
inline Vec3 sigma_a_from_melanin(float eumelanin, float pheomelanin) {
    Vec3 out;
    check(ht_hair_sigma_a_from_melanin(eumelanin, pheomelanin, out.data()));
    return out;
}

/** sigma_a that looks like the linear RGB `color` at `beta_n` (`ht_hair_sigma_a_from_color`). */
template <class V> Vec3 sigma_a_from_color(const V &color, float beta_n) {
    const Vec3 c = vec3(color);
    Vec3 out;
    check(ht_hair_sigma_a_from_color(c.data(), beta_n, out.data()));
    return out;
}

/** sigma_a of a named preset (`ht_hair_sigma_a_preset`). */
inline Vec3 sigma_a_preset(const char *name) {
    Vec3 out;
    check(ht_hair_sigma_a_preset(name, out.data()));
    return out;
}

/**
 * The shading frame and h of a hair hit (`HtHairFrame`, `ht_hair_frame`): the convention
 * every call assumes, built from the hit instead of by hand. Default-constructed, it is no
 * frame (zero axes): a point refuses it until it is set.
 */
class Frame {
public:
    Frame() noexcept : frame_() {}
    /** A frame the host built itself; checked where it is used. */
    explicit Frame(const HtHairFrame &frame) noexcept : frame_(frame) {}

    /** From the curve's tangent, the ray, the axis point at the hit and the radius there. */
    template <class T, class O, class D, class A>
    static Frame at_hit(const T &tangent, const O &ray_org, const D &ray_dir, const A &axis,
                        float radius) {
        Frame f;
        check(f.set_at_hit(tangent, ray_org, ray_dir, axis, radius));
        return f;
    }
    /** `at_hit` into this frame, with a status instead of a throw (unchanged on error). */
    template <class T, class O, class D, class A>
    HtStatus set_at_hit(const T &tangent, const O &ray_org, const D &ray_dir, const A &axis,
                        float radius) noexcept {
        const Vec3 t = vec3(tangent), o = vec3(ray_org), d = vec3(ray_dir), a = vec3(axis);
        return ht_hair_frame(t.data(), o.data(), d.data(), a.data(), radius, &frame_);
    }

    /** The offset across the fibre, in radii. */
    float h() const noexcept { return frame_.h; }
    const HtHairFrame &c() const noexcept { return frame_; }

private:
    HtHairFrame frame_;
};

namespace detail {
/** A model prepared for one parameter set by `Prepare`, released by `Free` with its last
 * copy. */
template <class Handle, class Params, HtStatus (*Prepare)(const Params *, Handle **),
          HtStatus (*Free)(Handle *)>
class Prepared {
public:
    explicit Prepared(const Params &params) {
        Handle *handle = nullptr;
        check(Prepare(&params, &handle));
        handle_.reset(handle, [](Handle *p) { Free(p); });
    }
    const Handle *get() const noexcept { return handle_.get(); }

private:
    std::shared_ptr<Handle> handle_;
};

/** A model's point `C` in the host's memory, with its world calls `EvalFn` and `SampleFn`:
 * default-constructed it is unfilled (zero bytes). */
template <class C, HtStatus (*EvalFn)(const C *, const float *, float *, float *),
          HtStatus (*SampleFn)(const C *, const float *, float *, float *, float *, float *)>
class WorldPoint {
public:
    WorldPoint() noexcept : point_() {}

    /** f |cos| and pdf toward the world `wi` (`ht_*_point_eval_world`). */
    template <class V> Eval eval_world(const V &wi) const {
        Eval e;
        check(eval_world(wi, e));
        return e;
    }
    /** `eval_world` into `out`, with a status instead of a throw. */
    template <class V> HtStatus eval_world(const V &wi, Eval &out) const noexcept {
        const Vec3 w = vec3(wi);
        return EvalFn(&point_, w.data(), out.f_cos.data(), &out.pdf);
    }
    /** A world direction from `u` in [0, 1)^3 (`ht_*_point_sample_world`). */
    Sample sample_world(const Vec3 &u) const {
        Sample s;
        check(sample_world(u, s));
        return s;
    }
    /** `sample_world` into `out`, with a status instead of a throw. */
    HtStatus sample_world(const Vec3 &u, Sample &out) const noexcept {
        return SampleFn(&point_, u.data(), out.wi.data(), out.f_cos.data(), out.weight.data(),
                        &out.pdf);
    }
    const C &c() const noexcept { return point_; }

protected:
    C point_;
};
} // namespace detail

/**
 * A hair material: the BSDF prepared for one parameter set (`ht_hair_prepare`). Copies share
 * the one immutable handle, which any number of threads may use at once; the last copy
 * releases it. Made once per material, at set-up: it throws.
 */
class Material : public detail::Prepared<HtHairPrepared, HtHairParams, ht_hair_prepare,
                                         ht_hair_prepared_free> {
public:
    using Prepared::Prepared;
};

/** A material of the Huang model (`ht_huang_prepare`), shared and released as `Material`. */
class HuangMaterial : public detail::Prepared<HtHuangPrepared, HtHuangParams, ht_huang_prepare,
                                              ht_huang_prepared_free> {
public:
    using Prepared::Prepared;
};

/**
 * The BSDF at one path vertex (`HtHairPoint`): plain bytes in the host's memory, filled once
 * and then evaluated and sampled any number of times, by any number of threads, in world
 * space. Copyable, no release, independent of the `Material` it came from.
 * Default-constructed it is unfilled (zero bytes): every call on it returns
 * `HT_ERR_INVALID_ARG` (or throws, in the value form) until a `set_*` fills it.
 */
class Point : public detail::WorldPoint<HtHairPoint, ht_hair_point_eval_world,
                                        ht_hair_point_sample_world> {
public:

    /** A renderer's hit to a point, frame included (`ht_hair_point_at_hit`): the curve's
     * tangent, the ray, the axis point at the hit and the radius there; wo is -ray_dir. */
    template <class T, class O, class D, class A>
    static Point at_hit(const Material &material, const T &tangent, const O &ray_org,
                        const D &ray_dir, const A &axis, float radius) {
        Point p;
        check(p.set_at_hit(material, tangent, ray_org, ray_dir, axis, radius));
        return p;
    }
    /** `at_hit` into this point, with a status instead of a throw (unchanged on error). */
    template <class T, class O, class D, class A>
    HtStatus set_at_hit(const Material &material, const T &tangent, const O &ray_org,
                        const D &ray_dir, const A &axis, float radius) noexcept {
        const Vec3 t = vec3(tangent), o = vec3(ray_org), d = vec3(ray_dir), a = vec3(axis);
        return ht_hair_point_at_hit(material.get(), t.data(), o.data(), d.data(), a.data(),
                                    radius, &point_);
    }
    /** At a frame, `wo` in world space (`ht_hair_point_init_world`). */
    template <class V> static Point world(const Material &material, const Frame &frame, const V &wo) {
        Point p;
        check(p.set_world(material, frame, wo));
        return p;
    }
    /** `world` into this point, with a status instead of a throw (unchanged on error). */
    template <class V>
    HtStatus set_world(const Material &material, const Frame &frame, const V &wo) noexcept {
        const Vec3 w = vec3(wo);
        return ht_hair_point_init_world(material.get(), &frame.c(), w.data(), &point_);
    }

#if defined(HT_RENDER)
    /** At strand `strand`, position `s`, of a groom varied as `variation` says, with the
     * strand's colour `color` (NULL: none), at a frame with `wo` in world space:
     * `ht_hair_point_init_strand`. */
    template <class V>
    static Point strand(const Material &material, const HtHairVariation &variation,
                        uint32_t strand, float s, const float *color, const Frame &frame,
                        const V &wo) {
        const Vec3 w = vec3(wo);
        Point p;
        check(ht_hair_point_init_strand(material.get(), &variation, strand, s, color, &frame.c(),
                                        w.data(), &p.point_));
        return p;
    }
#endif

    /** f |cos| and pdf toward the world `wi` at `HT_ACROSS` offsets across the fibre, the
     * point's own first (`ht_hair_point_eval_across_world`): next-event estimation weighs a
     * light by the lanes' mean, each lane with its own MIS weight (docs/c-abi.md). */
    template <class V> Across eval_across_world(const V &wi) const {
        Across lanes;
        check(eval_across_world(wi, lanes));
        return lanes;
    }
    /** `eval_across_world` into `out`, with a status instead of a throw. */
    template <class V> HtStatus eval_across_world(const V &wi, Across &out) const noexcept {
        const Vec3 w = vec3(wi);
        std::array<float, 3 * HT_ACROSS> f_cos;
        std::array<float, HT_ACROSS> pdf;
        const HtStatus status = ht_hair_point_eval_across_world(&point_, w.data(), f_cos.data(),
                                                                pdf.data());
        if (status == HT_OK) {
            for (std::size_t k = 0; k < HT_ACROSS; ++k) {
                out[k] = Eval{{f_cos[3 * k], f_cos[3 * k + 1], f_cos[3 * k + 2]}, pdf[k]};
            }
        }
        return status;
    }
};

/**
 * The Huang model at one path vertex (`HtHuangPoint`): as `Point`, and its fills also take
 * the section's major axis (world space, any length, across the fibre), the `Jitter` (fresh
 * uniform numbers per hit for an unbiased render) and the field (`HT_HUANG_NEAR` at the
 * hit's h, `HT_HUANG_FAR` across the fibre, or `HT_HUANG_FAR_LIT` across it at more offsets
 * for a vertex that also samples lights). Default-constructed it is unfilled.
 */
class HuangPoint : public detail::WorldPoint<HtHuangPoint, ht_huang_point_eval_world,
                                             ht_huang_point_sample_world> {
public:
    /** A renderer's hit to a point, frame included (`ht_huang_point_at_hit`). */
    template <class T, class O, class D, class A, class M>
    static HuangPoint at_hit(const HuangMaterial &material, const T &tangent, const O &ray_org,
                             const D &ray_dir, const A &axis, float radius, const M &major,
                             const Jitter &jitter, HtHuangField field) {
        HuangPoint p;
        check(p.set_at_hit(material, tangent, ray_org, ray_dir, axis, radius, major, jitter,
                           field));
        return p;
    }
    /** `at_hit` into this point, with a status instead of a throw (unchanged on error). */
    template <class T, class O, class D, class A, class M>
    HtStatus set_at_hit(const HuangMaterial &material, const T &tangent, const O &ray_org,
                        const D &ray_dir, const A &axis, float radius, const M &major,
                        const Jitter &jitter, HtHuangField field) noexcept {
        const Vec3 t = vec3(tangent), o = vec3(ray_org), d = vec3(ray_dir), a = vec3(axis);
        const Vec3 m = vec3(major);
        return ht_huang_point_at_hit(material.get(), t.data(), o.data(), d.data(), a.data(),
                                     radius, m.data(), jitter.data(), field, &point_);
    }
    /** At a frame, `wo` in world space (`ht_huang_point_init_world`). */
    template <class V, class M>
    static HuangPoint world(const HuangMaterial &material, const Frame &frame, const V &wo,
                            const M &major, const Jitter &jitter, HtHuangField field) {
        HuangPoint p;
        check(p.set_world(material, frame, wo, major, jitter, field));
        return p;
    }
    /** `world` into this point, with a status instead of a throw (unchanged on error). */
    template <class V, class M>
    HtStatus set_world(const HuangMaterial &material, const Frame &frame, const V &wo,
                       const M &major, const Jitter &jitter, HtHuangField field) noexcept {
        const Vec3 w = vec3(wo), m = vec3(major);
        return ht_huang_point_init_world(material.get(), &frame.c(), w.data(), m.data(),
                                         jitter.data(), field, &point_);
    }

#if defined(HT_RENDER)
    /** At strand `strand`, position `s`, of a groom varied as `variation` says, with the
     * strand's colour `color` (NULL: none), at a frame with `wo` in world space:
     * `ht_huang_point_init_strand`. */
    template <class V, class M>
    static HuangPoint strand(const HuangMaterial &material, const HtHairVariation &variation,
                             uint32_t strand, float s, const float *color, const Frame &frame,
                             const V &wo, const M &major, const Jitter &jitter,
                             HtHuangField field) {
        const Vec3 w = vec3(wo), m = vec3(major);
        HuangPoint p;
        check(ht_huang_point_init_strand(material.get(), &variation, strand, s, color,
                                         &frame.c(), w.data(), m.data(), jitter.data(), field,
                                         &p.point_));
        return p;
    }
#endif
};

#if defined(HT_RENDER)
namespace detail {
/** An owner of a C handle released by `Free`; move-only. */
template <class T, HtStatus (*Free)(T *)> class Owned {
public:
    Owned() = default;
    explicit Owned(T *handle) noexcept : handle_(handle) {}
    Owned(Owned &&other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
    Owned &operator=(Owned &&other) noexcept {
        std::swap(handle_, other.handle_);
        return *this;
    }
    Owned(const Owned &) = delete;
    Owned &operator=(const Owned &) = delete;
    ~Owned() { Free(handle_); }
    T *get() const noexcept { return handle_; }

private:
    T *handle_ = nullptr;
};
} // namespace detail

/** An Embree device (`ht_device_new`); 0 threads: every core. */
class Device : public detail::Owned<HtDevice, ht_device_free> {
public:
    explicit Device(uint32_t threads = 0) : Owned(make(threads)) {}

private:
    static HtDevice *make(uint32_t threads) {
        HtDevice *d = nullptr;
        check(ht_device_new(threads, &d));
        return d;
    }
};

/** Render settings by name (`ht_settings_new`, `ht_settings_set`, `ht_settings_get`). */
class Settings : public detail::Owned<HtSettings, ht_settings_free> {
public:
    Settings() : Owned(make()) {}
    Settings &set(const char *key, const std::string &value) {
        check(ht_settings_set(get(), key, value.c_str()));
        return *this;
    }
    std::string value(const char *key) const {
        size_t len = 0;
        check(ht_settings_get(get(), key, nullptr, 0, &len));
        std::string text(len + 1, '\0');
        check(ht_settings_get(get(), key, &text[0], text.size(), &len));
        text.resize(len);
        return text;
    }

private:
    static HtSettings *make() {
        HtSettings *s = nullptr;
        check(ht_settings_new(&s));
        return s;
    }
};

/**
 * A scene on a device (`ht_scene_new`). Motion and animation have wrappers here, which
 * throw `Error`; fill the rest with the `ht_scene_*` calls on `get()`.
 */
class Scene : public detail::Owned<HtScene, ht_scene_free> {
public:
    explicit Scene(const Device &device) : Owned(make(device)) {}

    /**
     * Strands of float4 control points moving over the shutter
     * (`ht_scene_add_curves_xyzr_motion`): `desc.points` at the first time step, `later[k]`
     * (`4 * desc.point_count` floats each) at step k + 1. Returns the geometry id.
     */
    uint32_t add_curves_xyzr_motion(const HtCurvesXyzr &desc,
                                    const std::vector<const float *> &later,
                                    uint32_t material_id) {
        uint32_t id = 0;
        check(ht_scene_add_curves_xyzr_motion(get(), &desc, later.data(), later.size(),
                                              material_id, &id));
        return id;
    }

    /**
     * A triangle mesh deforming over the shutter (`ht_scene_add_mesh_motion`):
     * `positions[k]` holds the `3 * vertex_count` floats of the vertices at time step k (one
     * pointer: a mesh that stays put), `indices` 3 per triangle. Returns the geometry id.
     */
    uint32_t add_mesh_motion(size_t vertex_count, const std::vector<const float *> &positions,
                             const std::vector<uint32_t> &indices, uint32_t material_id) {
        uint32_t id = 0;
        const float *first = positions.empty() ? nullptr : positions[0];
        size_t later = positions.empty() ? 0 : positions.size() - 1;
        check(ht_scene_add_mesh_motion(get(), vertex_count, first,
                                       later ? positions.data() + 1 : nullptr, later,
                                       indices.size() / 3, indices.data(), material_id, &id));
        return id;
    }

    /** The first geometry id of a USD stage's prims, and how many. */
    struct Geometries {
        uint32_t first;
        uint32_t count;
    };

    /**
     * A USD stage's BasisCurves read at frame `frame` (`ht_scene_add_usd_file_at`), moving
     * over the shutter of `settings` where it is open (nullptr: closed).
     */
    Geometries add_usd_file_at(const std::string &path, double frame, HtCurveShape shape,
                               uint32_t material_id, const Settings *settings = nullptr) {
        Geometries ids{0, 0};
        check(ht_scene_add_usd_file_at(get(), path.c_str(), frame, settings_of(settings), shape,
                                       material_id, &ids.first, &ids.count));
        return ids;
    }

    /**
     * A `.hair` file, or the file of frame `frame` of a sequence (`groom.####.hair`), read
     * by `ht_scene_add_hair_file_at`: a sequence moves over the shutter of `settings` where
     * it is open (nullptr: closed). Returns the geometry id.
     */
    uint32_t add_hair_file_at(const std::string &path, double frame, bool thickness_is_radius,
                              HtCurveBasis basis, HtCurveShape shape, uint32_t material_id,
                              const Settings *settings = nullptr) {
        uint32_t id = 0;
        check(ht_scene_add_hair_file_at(get(), path.c_str(), frame, settings_of(settings),
                                        thickness_is_radius, basis, shape, material_id, &id));
        return id;
    }

private:
    static HtScene *make(const Device &device) {
        HtScene *s = nullptr;
        check(ht_scene_new(device.get(), &s));
        return s;
    }
    static const HtSettings *settings_of(const Settings *settings) noexcept {
        return settings ? settings->get() : nullptr;
    }
};
#endif

} // namespace hairtrace

#endif
