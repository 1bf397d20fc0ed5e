/* A path vertex from a hit to a sampled direction, frame included, as a renderer's worker
 * thread makes it: through hairtrace.hpp with the noexcept status forms and a
 * default-constructed vertex struct, and with the three C calls it wraps
 * (ht_hair_point_at_hit, _eval_world, _sample_world). Both on the hits of hits.h, two
 * materials alternating, timed as bench.c times (41 interleaved rounds over 4096 hits,
 * medians of ns per vertex); vertex.rs times the Rust vertex on the same hits. Built and
 * run by bench/c_bsdf/run. */
#include "hairtrace.hpp"

extern "C" {
#include "hits.h"
}

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

constexpr int N = 4096, ROUNDS = 41;
BenchHit hits[N];
volatile float sink;

/* What a host's vertex holds. */
struct Vertex {
    hairtrace::Point point;
    hairtrace::Eval light{};
    hairtrace::Sample sample{};
};

[[noreturn]] void die(const char *what, HtStatus s) {
    std::fprintf(stderr, "%s: %s: %s\n", what, ht_status_str(static_cast<int32_t>(s)),
                 ht_last_error());
    std::exit(1);
}

void run_cpp(const hairtrace::Material *materials) {
    for (int i = 0; i < N; ++i) {
        const BenchHit &k = hits[i];
        Vertex v;
        HtStatus s = v.point.set_at_hit(materials[i & 1], k.tangent, k.org, k.dir, k.axis, k.radius);
        if (s == HT_OK) s = v.point.eval_world(k.light, v.light);
        if (s == HT_OK) s = v.point.sample_world({k.u[0], k.u[1], k.u[2]}, v.sample);
        if (s != HT_OK) die("C++ vertex", s);
        sink = sink + v.light.pdf + v.sample.weight[0];
    }
}

void run_c(HtHairPrepared *const *prepared) {
    for (int i = 0; i < N; ++i) {
        const BenchHit &k = hits[i];
        HtHairPoint p;
        float fl[3], pl, wi[3], fc[3], w[3], ps;
        HtStatus s = ht_hair_point_at_hit(prepared[i & 1], k.tangent, k.org, k.dir, k.axis,
                                          k.radius, &p);
        if (s == HT_OK) s = ht_hair_point_eval_world(&p, k.light, fl, &pl);
        if (s == HT_OK) s = ht_hair_point_sample_world(&p, k.u, wi, fc, w, &ps);
        if (s != HT_OK) die("C vertex", s);
        sink = sink + pl + w[0];
    }
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

} // namespace

int main() {
    HtHairParams params[2] = {ht_hair_params_default(), ht_hair_params_default()};
    params[1].beta_m = 0.12f;
    params[1].alpha = -3.0f;
    const hairtrace::Vec3 blond = hairtrace::sigma_a_from_melanin(0.3f, 0.2f);
    std::copy(blond.begin(), blond.end(), params[1].sigma_a);
    const hairtrace::Material materials[2] = {hairtrace::Material(params[0]),
                                              hairtrace::Material(params[1])};
    HtHairPrepared *prepared[2];
    for (int m = 0; m < 2; ++m) {
        if (HtStatus s = ht_hair_prepare(&params[m], &prepared[m]); s != HT_OK) die("prepare", s);
    }
    uint64_t state = 0x51ed2701f3a5c7b9ull;
    for (BenchHit &k : hits) k = bench_hit(&state);

    std::vector<double> cpp, c;
    for (int r = 0; r < ROUNDS; ++r) {
        for (int which = 0; which < 2; ++which) {
            const auto t0 = std::chrono::steady_clock::now();
            which == 0 ? run_cpp(materials) : run_c(prepared);
            const std::chrono::duration<double, std::nano> dt = std::chrono::steady_clock::now() - t0;
            (which == 0 ? cpp : c).push_back(dt.count() / N);
        }
    }
    std::printf("%-44s %8.1f\n", "C++ vertex from a hit (hairtrace.hpp)", median(cpp));
    std::printf("%-44s %8.1f\n", "C vertex from a hit (3 calls)", median(c));
    for (HtHairPrepared *p : prepared) ht_hair_prepared_free(p);
    return 0;
}
