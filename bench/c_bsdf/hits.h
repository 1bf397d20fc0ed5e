/* The path vertices of bench/c_bsdf as a renderer has them: hits on fibres (the curve's
 * tangent, the ray, the axis point and radius) with a light direction and three uniform
 * numbers each, drawn by their own generator so that bench.c, vertex.cpp and vertex.rs
 * (which draws the same hits in Rust) share them exactly. */
#ifndef HT_BENCH_HITS_H
#define HT_BENCH_HITS_H

#include <math.h>
#include <stdint.h>

typedef struct BenchHit {
    float tangent[3], org[3], dir[3], axis[3], radius, light[3], u[3];
} BenchHit;

/* xorshift64*, 24 bits in [0, 1). */
static inline float bench_uniform(uint64_t *state) {
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    return (float)((*state * 0x2545f4914f6cdd1dull) >> 40) / 16777216.0f;
}

/* A direction uniform on the sphere. */
static inline void bench_unit(uint64_t *state, float *w) {
    float z = 2.0f * bench_uniform(state) - 1.0f, phi = 6.2831853f * bench_uniform(state);
    float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    w[0] = z;
    w[1] = r * cosf(phi);
    w[2] = r * sinf(phi);
}

/* Hit k of the sequence from `state`: a random tangent and ray passing an axis point of a
 * fibre of radius 0.03 at a uniform offset h, a random light direction and u. A ray along
 * the tangent (no side to be offset to) passes through the axis. */
static inline BenchHit bench_hit(uint64_t *state) {
    BenchHit k;
    bench_unit(state, k.tangent);
    bench_unit(state, k.dir);
    bench_unit(state, k.light);
    for (int c = 0; c < 3; ++c) k.u[c] = bench_uniform(state);
    float h = 2.0f * bench_uniform(state) - 1.0f;
    const float *t = k.tangent, *d = k.dir;
    float y[3] = {t[1] * d[2] - t[2] * d[1], t[2] * d[0] - t[0] * d[2], t[0] * d[1] - t[1] * d[0]};
    float n = sqrtf(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    if (n < 1e-3f) h = 0.0f;
    k.radius = 0.03f;
    const float axis[3] = {0.5f, -0.25f, 1.0f}, s = n < 1e-3f ? 0.0f : h * k.radius / n;
    for (int c = 0; c < 3; ++c) {
        k.axis[c] = axis[c];
        k.org[c] = axis[c] + y[c] * s - 4.0f * d[c];
    }
    return k;
}

#endif
