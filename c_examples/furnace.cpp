/* The hair BSDF from C++ through hairtrace.hpp: a white furnace over random hits, each
 * shaded as a renderer's worker thread shades a path vertex, with the noexcept status
 * forms and a default-constructed vertex (a point from the hit, frame included, a sampled
 * direction with f |cos|, its weight and pdf, the pdf of light from that direction, and
 * the BSDF toward it across the fibre). Each vertex is made again with the throwing value
 * forms, with the frame and the point in two steps, and with the C calls; all must agree
 * bit for bit. With no absorption the mean weight is 1.
 * Prints "furnace MEAN", "mismatches M of N", "unfilled STATUS: MESSAGE" and
 * "error STATUS: MESSAGE". */
#include "hairtrace.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace {

/* A host's own vector type: the layer reads x, y, z and builds it as V{x, y, z}. */
struct HostVec {
    float x, y, z;
};

/* What a host's path vertex holds: default-constructed, filled by the status forms. */
struct Vertex {
    hairtrace::Point point;
    hairtrace::Sample sample{};
    hairtrace::Eval light{};
    hairtrace::Across across{};
};

uint32_t state = 12345u;
float uniform() {
    state = state * 1664525u + 1013904223u;
    return static_cast<float>(state >> 8) * (1.0f / 16777216.0f);
}

HostVec random_unit() {
    const float z = 2.0f * uniform() - 1.0f, phi = 6.2831853f * uniform();
    const float r = std::sqrt(std::fmax(0.0f, 1.0f - z * z));
    return HostVec{r * std::cos(phi), r * std::sin(phi), z};
}

template <class T> bool same_bits(const T &a, const T &b) {
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}

bool same(const hairtrace::Sample &a, const hairtrace::Sample &b) {
    return same_bits(a.wi, b.wi) && same_bits(a.f_cos, b.f_cos) &&
           same_bits(a.weight, b.weight) && same_bits(a.pdf, b.pdf);
}

bool same(const hairtrace::Eval &a, const hairtrace::Eval &b) {
    return same_bits(a.f_cos, b.f_cos) && same_bits(a.pdf, b.pdf);
}

/* The worker's vertex: status forms only, no exception can leave it. */
HtStatus shade(const hairtrace::Material &material, const HostVec &tangent, const float org[3],
               const HostVec &dir, const hairtrace::Vec3 &u, Vertex &v) noexcept {
    HtStatus s = v.point.set_at_hit(material, tangent, org, dir, HostVec{0.0f, 0.0f, 0.0f}, 1.0f);
    if (s == HT_OK) s = v.point.sample_world(u, v.sample);
    if (s == HT_OK && v.sample) s = v.point.eval_world(v.sample.wi, v.light);
    if (s == HT_OK && v.sample) s = v.point.eval_across_world(v.sample.wi, v.across);
    return s;
}

/* The same vertex with the C calls. */
bool c_agrees(const HtHairPrepared *prepared, const HostVec &tangent, const float org[3],
              const HostVec &dir, const hairtrace::Vec3 &u, const Vertex &v) {
    const float t[3] = {tangent.x, tangent.y, tangent.z}, d[3] = {dir.x, dir.y, dir.z};
    const float axis[3] = {0.0f, 0.0f, 0.0f};
    HtHairPoint point;
    hairtrace::Sample s;
    hairtrace::Eval e{};
    if (ht_hair_point_at_hit(prepared, t, org, d, axis, 1.0f, &point) != HT_OK ||
        ht_hair_point_sample_world(&point, u.data(), s.wi.data(), s.f_cos.data(), s.weight.data(),
                                   &s.pdf) != HT_OK ||
        (s && ht_hair_point_eval_world(&point, s.wi.data(), e.f_cos.data(), &e.pdf) != HT_OK)) {
        return false;
    }
    return same(s, v.sample) && same(e, v.light);
}

} // namespace

int main() {
    try {
        HtHairParams white = hairtrace::default_params();
        white.sigma_a[0] = white.sigma_a[1] = white.sigma_a[2] = 0.0f;
        const hairtrace::Material material(white);
        HtHairPrepared *prepared = nullptr;
        hairtrace::check(ht_hair_prepare(&white, &prepared));

        const int n = 20000;
        double sum = 0.0;
        int shaded = 0, mismatches = 0;
        for (int i = 0; i < n; ++i) {
            /* A ray past a fibre of radius 1 along a random tangent, at a random h. */
            const HostVec tangent = random_unit(), dir = random_unit();
            HostVec across{tangent.y * dir.z - tangent.z * dir.y,
                           tangent.z * dir.x - tangent.x * dir.z,
                           tangent.x * dir.y - tangent.y * dir.x};
            const float len = std::sqrt(across.x * across.x + across.y * across.y +
                                        across.z * across.z);
            if (len < 1e-3f) continue; /* the ray runs along the fibre */
            const float h = 0.999f * (2.0f * uniform() - 1.0f);
            const float org[3] = {across.x / len * h - 3.0f * dir.x,
                                  across.y / len * h - 3.0f * dir.y,
                                  across.z / len * h - 3.0f * dir.z};
            const hairtrace::Vec3 u = {uniform(), uniform(), uniform()};
            ++shaded;

            Vertex v;
            hairtrace::check(shade(material, tangent, org, dir, u, v));
            if (v.sample) sum += v.sample.weight[1];
            /* The value forms, and the frame then the point, give the same bits. */
            const auto point = hairtrace::Point::at_hit(material, tangent, org, dir,
                                                        HostVec{0.0f, 0.0f, 0.0f}, 1.0f);
            const auto frame =
                hairtrace::Frame::at_hit(tangent, org, dir, HostVec{0.0f, 0.0f, 0.0f}, 1.0f);
            /* wo = -ray_dir normalised, as the point at the hit takes it. */
            const float r = 1.0f / std::sqrt(dir.x * dir.x + dir.y * dir.y + dir.z * dir.z);
            const auto framed =
                hairtrace::Point::world(material, frame, HostVec{-dir.x * r, -dir.y * r, -dir.z * r});
            bool agrees = same(point.sample_world(u), v.sample) &&
                          same(framed.sample_world(u), v.sample) &&
                          c_agrees(prepared, tangent, org, dir, u, v);
            if (v.sample) {
                const hairtrace::Across lanes = point.eval_across_world(hairtrace::as<HostVec>(v.sample.wi));
                agrees = agrees && same(point.eval_world(v.sample.wi), v.light) &&
                         same(framed.eval_world(v.sample.wi), v.light) && same(v.across[0], v.light);
                for (size_t k = 0; k < HT_ACROSS; ++k) agrees = agrees && same(lanes[k], v.across[k]);
            }
            mismatches += !agrees;
        }
        ht_hair_prepared_free(prepared);
        std::printf("furnace %.6f\n", sum / shaded);
        std::printf("mismatches %d of %d\n", mismatches, shaded);

        /* A status form on a vertex that was never filled: a status and the message, no
         * throw. */
        const Vertex unfilled;
        hairtrace::Eval e{};
        const HtStatus s = unfilled.point.eval_world(HostVec{0.0f, 0.0f, 1.0f}, e);
        std::printf("unfilled %s: %s\n", ht_status_str(static_cast<int32_t>(s)), ht_last_error());

        /* A broken contract in a value form is an exception with the library's message. */
        HtHairParams rough = white;
        rough.beta_m = 2.0f;
        try {
            const hairtrace::Material bad(rough);
            std::printf("error none\n");
        } catch (const hairtrace::Error &e) {
            std::printf("error %s\n", e.what());
        }
    } catch (const hairtrace::Error &e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}
