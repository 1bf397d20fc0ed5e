/* The hair BSDF from C++ through hairtrace.hpp: a white furnace over random hits, each
 * shaded as a path vertex is (the frame of the hit, a point, a sampled direction and its
 * weight, the pdf of light from that direction, and the BSDF toward it across the fibre),
 * next to the same vertex made with the C calls a host used before the combined ones (the
 * frame conversions, ht_hair_point_init, _sample and _pdf, the weight computed by the
 * host). With no absorption the mean weight is 1; the two paths must agree bit for bit.
 * Prints "furnace MEAN", "mismatches M of N" and "error STATUS: MESSAGE". */
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

bool same_bits(const float *a, const float *b, size_t n) {
    return std::memcmp(a, b, n * sizeof(float)) == 0;
}

/* The C path: the vertex as the ABI-6 calls make it. Returns false if a call fails. */
bool c_vertex(const HtHairPrepared *prepared, const float tangent[3], const float org[3],
              const float dir[3], const float u[3], float wi[3], float weight[3], float *pdf,
              float *light_pdf) {
    const float axis[3] = {0.0f, 0.0f, 0.0f}, wo[3] = {-dir[0], -dir[1], -dir[2]};
    HtHairFrame frame;
    float wo_local[3], wi_local[3], f[3];
    HtHairPoint point;
    if (ht_hair_frame(tangent, org, dir, axis, 1.0f, &frame) != HT_OK ||
        ht_hair_frame_to_local(&frame, wo, wo_local) != HT_OK ||
        ht_hair_point_init(prepared, frame.h, wo_local, &point) != HT_OK ||
        ht_hair_point_sample(&point, u, wi_local, f, pdf) != HT_OK) {
        return false;
    }
    float w[3] = {0.0f, 0.0f, 0.0f}, d[3] = {0.0f, 0.0f, 0.0f};
    bool finite = true;
    for (int c = 0; c < 3; ++c) {
        w[c] = *pdf > 0.0f ? f[c] * std::fabs(wi_local[2]) / *pdf : 0.0f;
        finite = finite && std::isfinite(w[c]);
    }
    if (*pdf > 0.0f && finite) {
        if (ht_hair_frame_to_world(&frame, wi_local, d) != HT_OK) return false;
    } else {
        w[0] = w[1] = w[2] = 0.0f;
        *pdf = 0.0f;
    }
    std::memcpy(wi, d, sizeof d);
    std::memcpy(weight, w, sizeof w);
    /* The pdf of light arriving from the sampled direction (for MIS), given in world
     * space as a light gives it. */
    *light_pdf = 0.0f;
    float back[3];
    return *pdf == 0.0f || (ht_hair_frame_to_local(&frame, d, back) == HT_OK &&
                            ht_hair_point_pdf(&point, back, light_pdf) == HT_OK);
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

            const auto frame =
                hairtrace::Frame::at_hit(tangent, org, dir, HostVec{0.0f, 0.0f, 0.0f}, 1.0f);
            const auto point =
                hairtrace::Point::world(material, frame, HostVec{-dir.x, -dir.y, -dir.z});
            const hairtrace::Sample s = point.sample_world(u);
            float light_pdf = 0.0f;
            bool across_agrees = true;
            if (s) {
                const hairtrace::Eval e = point.eval_world(hairtrace::as<HostVec>(s.wi));
                light_pdf = e.pdf;
                sum += s.weight[1];
                /* Across the fibre: the world lanes are the local point's lanes through the
                 * frame, and lane 0, the point's own offset, is the plain evaluation. */
                const hairtrace::Across world = point.eval_across_world(hairtrace::as<HostVec>(s.wi));
                const hairtrace::Point local(material, frame.h(),
                                             frame.to_local(HostVec{-dir.x, -dir.y, -dir.z}));
                const hairtrace::Across lanes = local.eval_across(frame.to_local(s.wi));
                for (size_t k = 0; k < HT_ACROSS; ++k) {
                    across_agrees = across_agrees &&
                                    same_bits(world[k].f_cos.data(), lanes[k].f_cos.data(), 3) &&
                                    same_bits(&world[k].pdf, &lanes[k].pdf, 1);
                }
                across_agrees = across_agrees && same_bits(world[0].f_cos.data(), e.f_cos.data(), 3) &&
                                same_bits(&world[0].pdf, &e.pdf, 1);
            }

            const float t[3] = {tangent.x, tangent.y, tangent.z}, d[3] = {dir.x, dir.y, dir.z};
            float c_wi[3], c_weight[3], c_pdf, c_light_pdf;
            if (!c_vertex(prepared, t, org, d, u.data(), c_wi, c_weight, &c_pdf, &c_light_pdf)) {
                hairtrace::check(HT_ERR_INVALID_ARG);
            }
            if (!same_bits(s.wi.data(), c_wi, 3) || !same_bits(s.weight.data(), c_weight, 3) ||
                !same_bits(&s.pdf, &c_pdf, 1) || !same_bits(&light_pdf, &c_light_pdf, 1) ||
                !across_agrees) {
                ++mismatches;
            }
        }
        ht_hair_prepared_free(prepared);
        std::printf("furnace %.6f\n", sum / shaded);
        std::printf("mismatches %d of %d\n", mismatches, shaded);

        /* A broken contract is an exception with the library's message. */
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
