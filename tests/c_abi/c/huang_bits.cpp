/* The Huang model through hairtrace.hpp and the C calls under it, for inputs the Rust test
 * writes to the file named by argv[1], one case a line as 23 hexadecimal float bit
 * patterns: sigma_a[3], eta, roughness, aspect, alpha, h, wo[3], wi[3], u[3], major[3],
 * jitter[2], field (0 near, 1 far). Each point is filled at the local frame, where world
 * directions are the local ones, four ways: the value form, the noexcept status form into
 * a default-constructed point, the C calls, and a strand's point without variation
 * (`HuangPoint::strand`); they must agree bit for bit. Prints one line a case with the bit
 * patterns of eval (f_cos, pdf) and sample (wi, f_cos, weight, pdf), then "mismatches M"
 * and the refusals: "throws STATUS: MESSAGE" for a bad aspect, "major STATUS: MESSAGE" for
 * a major axis along the fibre, "unfilled STATUS: MESSAGE", "strand throws STATUS:
 * MESSAGE" for a strand's point at s = 1.5. */
#include "hairtrace.hpp"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace {

float from_bits(uint32_t b) {
    float f;
    std::memcpy(&f, &b, sizeof f);
    return f;
}

void put(const float *v, int n) {
    for (int k = 0; k < n; ++k) {
        uint32_t b;
        std::memcpy(&b, &v[k], sizeof b);
        std::printf(" %08x", static_cast<unsigned>(b));
    }
}

template <class T> bool same_bits(const T &a, const T &b) {
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}

bool same(const hairtrace::Eval &a, const hairtrace::Eval &b) {
    return same_bits(a.f_cos, b.f_cos) && same_bits(a.pdf, b.pdf);
}

bool same(const hairtrace::Sample &a, const hairtrace::Sample &b) {
    return same_bits(a.wi, b.wi) && same_bits(a.f_cos, b.f_cos) &&
           same_bits(a.weight, b.weight) && same_bits(a.pdf, b.pdf);
}

void report(const char *what, HtStatus status) {
    std::printf("%s %s: %s\n", what, ht_status_str(static_cast<int32_t>(status)), ht_last_error());
}

} // namespace

int main(int argc, char **argv) {
    std::FILE *in = argc > 1 ? std::fopen(argv[1], "r") : nullptr;
    if (in == nullptr) {
        std::fprintf(stderr, "usage: huang_bits INPUT\n");
        return 1;
    }
    std::vector<float> v;
    for (uint32_t w; std::fscanf(in, "%x", &w) == 1;) v.push_back(from_bits(w));
    std::fclose(in);
    int mismatches = 0;
    for (std::size_t at = 0; at + 23 <= v.size(); at += 23) {
        const float *c = &v[at];
        HtHuangParams params = hairtrace::default_huang_params();
        std::memcpy(params.sigma_a, c, 3 * sizeof(float));
        params.eta = c[3];
        params.roughness = c[4];
        params.aspect = c[5];
        params.alpha = c[6];
        const hairtrace::Frame frame(
            HtHairFrame{{1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, c[7]});
        const float *wo = c + 8, *wi = c + 11, *major = c + 17;
        const hairtrace::Vec3 u{c[14], c[15], c[16]};
        const hairtrace::Jitter jitter{c[20], c[21]};
        const HtHuangField field = c[22] > 0.67f ? HT_HUANG_FAR_LIT : c[22] > 0.33f ? HT_HUANG_FAR : HT_HUANG_NEAR;
        const hairtrace::HuangMaterial material(params);
        const hairtrace::HuangPoint point =
            hairtrace::HuangPoint::world(material, frame, wo, major, jitter, field);
        const hairtrace::Eval e = point.eval_world(wi);
        const hairtrace::Sample s = point.sample_world(u);

        hairtrace::HuangPoint status_point;
        hairtrace::Eval e2{};
        hairtrace::Sample s2{};
        const bool status_ok =
            status_point.set_world(material, frame, wo, major, jitter, field) == HT_OK &&
            status_point.eval_world(wi, e2) == HT_OK && status_point.sample_world(u, s2) == HT_OK;

        HtHuangPoint c_point;
        hairtrace::Eval e3{};
        hairtrace::Sample s3{};
        const bool c_ok =
            ht_huang_point_init_world(material.get(), &frame.c(), wo, major, jitter.data(), field,
                                      &c_point) == HT_OK &&
            ht_huang_point_eval_world(&c_point, wi, e3.f_cos.data(), &e3.pdf) == HT_OK &&
            ht_huang_point_sample_world(&c_point, u.data(), s3.wi.data(), s3.f_cos.data(),
                                        s3.weight.data(), &s3.pdf) == HT_OK;
        const hairtrace::HuangPoint strand_point = hairtrace::HuangPoint::strand(
            material, ht_hair_variation_default(), static_cast<uint32_t>(at / 23), 0.5f, nullptr,
            frame, wo, major, jitter, field);
        const hairtrace::Eval e4 = strand_point.eval_world(wi);
        const hairtrace::Sample s4 = strand_point.sample_world(u);
        if (!status_ok || !c_ok || !same(e, e2) || !same(e, e3) || !same(s, s2) || !same(s, s3) ||
            !same(e, e4) || !same(s, s4)) {
            ++mismatches;
        }
        put(e.f_cos.data(), 3);
        put(&e.pdf, 1);
        put(s.wi.data(), 3);
        put(s.f_cos.data(), 3);
        put(s.weight.data(), 3);
        put(&s.pdf, 1);
        std::printf("\n");
    }
    std::printf("mismatches %d\n", mismatches);

    HtHuangParams oval = hairtrace::default_huang_params();
    oval.aspect = 1.5f;
    try {
        const hairtrace::HuangMaterial refused(oval);
        std::printf("throws nothing\n");
    } catch (const hairtrace::Error &e) {
        std::printf("throws %s\n", e.what());
    }
    const hairtrace::HuangMaterial circle(hairtrace::default_huang_params());
    hairtrace::HuangPoint unfilled;
    const hairtrace::Frame local(
        HtHairFrame{{1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, 0.0f});
    const float wo[3] = {0.0f, 0.0f, 1.0f}, along[3] = {3.0f, 0.0f, 0.0f};
    report("major", unfilled.set_world(circle, local, wo, along, hairtrace::Jitter{0.5f, 0.5f},
                                       HT_HUANG_NEAR));
    hairtrace::Eval light{};
    report("unfilled", unfilled.eval_world(wo, light));
    try {
        const float across[3] = {0.0f, 1.0f, 0.0f};
        const hairtrace::HuangPoint refused =
            hairtrace::HuangPoint::strand(circle, ht_hair_variation_default(), 0, 1.5f, nullptr,
                                          local, wo, across, hairtrace::Jitter{0.5f, 0.5f},
                                          HT_HUANG_NEAR);
        static_cast<void>(refused);
        std::printf("strand throws nothing\n");
    } catch (const hairtrace::Error &e) {
        std::printf("strand throws %s\n", e.what());
    }
    return 0;
}
