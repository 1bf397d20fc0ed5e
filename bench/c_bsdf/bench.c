/* Single-thread cost of the hair BSDF as a C host calls it: each entry point of a path
 * vertex (the frame, the point from a hit or at a frame, eval, sample, the lanes across the
 * fibre), a vertex at a frame, and a plain float port of the model (port.c), timed in
 * interleaved rounds over the same random inputs; medians of ns per call. `bench --check`
 * instead compares the port with hairtrace's values. vertex.cpp times the whole vertex from
 * a hit through hairtrace.hpp and the C calls, vertex.rs the Rust vertex on the same inputs.
 * Build and run: bench/c_bsdf/run (bench/README.md). */
#define _POSIX_C_SOURCE 199309L
#include "hairtrace.h"
#include "hits.h"
#include "port.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { N = 4096, ROUNDS = 41 };

/* The local inputs' generator: vertex.rs draws the same h, wo, wi and u from it. */
static uint64_t rng = 0x9e3779b97f4a7c15ull;
static float uniform(void) { return bench_uniform(&rng); }
static void unit(float *w) { bench_unit(&rng, w); }

static float h[N], wo[N][3], wi[N][3], u[N][3], f[N][3], pdf[N], wis[N][3], weight[N][3];
static float across_f[3 * HT_ACROSS], across_pdf[HT_ACROSS];
/* A world frame per input (h[i] its h) and wo, wi in world space: the local inputs turned. */
static HtHairFrame frames[N];
static float wo_w[N][3], wi_w[N][3];
static HtHairPoint framed[N], hit_points[N];
static BenchHit hits[N];
static HtHairParams params[2];
static HtHairPrepared *prepared[2];
static PortHair port[2];
static volatile float sink;

static void die(const char *what, HtStatus s) {
    const char *why = ht_last_error();
    fprintf(stderr, "%s: %s: %s\n", what, ht_status_str((int32_t)s), why);
    exit(1);
}
#define OK(call) do { HtStatus s_ = (call); if (s_ != HT_OK) die(#call, s_); } while (0)

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

/* One pass of each method over the N inputs. */
static void run_frame(void) {
    for (int i = 0; i < N; ++i) {
        const BenchHit *k = &hits[i];
        HtHairFrame fr;
        OK(ht_hair_frame(k->tangent, k->org, k->dir, k->axis, k->radius, &fr));
        pdf[i] = fr.h;
    }
}
static void run_at_hit(void) {
    for (int i = 0; i < N; ++i) {
        const BenchHit *k = &hits[i];
        OK(ht_hair_point_at_hit(prepared[i & 1], k->tangent, k->org, k->dir, k->axis, k->radius,
                                &hit_points[i]));
    }
}
static void run_init_world(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_init_world(prepared[i & 1], &frames[i], wo_w[i], &framed[i])); }
static void run_eval_world(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_eval_world(&framed[i], wi_w[i], f[i], &pdf[i])); }
static void run_sample_world(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_sample_world(&framed[i], u[i], wis[i], f[i], weight[i], &pdf[i])); }
static void run_across(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_eval_across_world(&framed[i], wi_w[i], across_f, across_pdf)); }
/* A whole path vertex at a frame the host has: the point, light evaluation with its MIS
 * pdf, and a sampled direction; the point a local variable, as a path tracer keeps it. */
static void run_vertex_world(void) {
    for (int i = 0; i < N; ++i) {
        float fl[3], pl, ps;
        HtHairPoint p;
        OK(ht_hair_point_init_world(prepared[i & 1], &frames[i], wo_w[i], &p));
        OK(ht_hair_point_eval_world(&p, wi_w[i], fl, &pl));
        OK(ht_hair_point_sample_world(&p, u[i], wis[i], f[i], weight[i], &ps));
        pdf[i] = pl + ps + fl[0];
    }
}
static void run_port(void) { for (int i = 0; i < N; ++i) port_eval(&port[0], h[i], wo[i], wi[i], f[i], &pdf[i]); }
static void run_port_alt(void) { for (int i = 0; i < N; ++i) port_eval(&port[i & 1], h[i], wo[i], wi[i], f[i], &pdf[i]); }

typedef struct { const char *name; void (*run)(void); double ns[ROUNDS]; } Method;
static Method methods[] = {
    {"ht_hair_frame", run_frame, {0}},
    {"ht_hair_point_at_hit", run_at_hit, {0}},
    {"ht_hair_point_init_world", run_init_world, {0}},
    {"ht_hair_point_eval_world", run_eval_world, {0}},
    {"ht_hair_point_sample_world", run_sample_world, {0}},
    {"ht_hair_point_eval_across_world (8 lanes)", run_across, {0}},
    {"vertex at a frame (init, eval, sample)", run_vertex_world, {0}},
    {"plain float port eval (one material)", run_port, {0}},
    {"plain float port eval (two materials)", run_port_alt, {0}},
};
enum { METHODS = sizeof methods / sizeof methods[0] };

static int by_value(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}
static double median(const double *v) {
    double s[ROUNDS];
    memcpy(s, v, sizeof s);
    qsort(s, ROUNDS, sizeof s[0], by_value);
    return s[ROUNDS / 2];
}

/* The port against hairtrace on every input: the largest difference of f |cos| relative to
 * the largest channel, and of pdf, over inputs away from the tangent (where f32 input
 * rounding alone moves the model by more; README "Accuracy"). Each point at the local frame,
 * whose world directions are the local ones. */
static int check(void) {
    double worst_f = 0.0, worst_pdf = 0.0;
    int compared = 0;
    for (int m = 0; m < 2; ++m)
        for (int i = 0; i < N; ++i) {
            if (fabsf(wo[i][0]) > 0.99f || fabsf(wi[i][0]) > 0.99f) continue;
            const HtHairFrame local = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, h[i]};
            HtHairPoint p;
            float fo[3], po, fp[3], pp;
            OK(ht_hair_point_init_world(prepared[m], &local, wo[i], &p));
            OK(ht_hair_point_eval_world(&p, wi[i], fo, &po));
            port_eval(&port[m], h[i], wo[i], wi[i], fp, &pp);
            float big = fmaxf(fo[0], fmaxf(fo[1], fo[2]));
            if (!(big > 0.0f)) continue; /* wi in the fibre's normal plane: no f |cos| */
            for (int c = 0; c < 3; ++c) {
                double d = fabs((double)fp[c] * fabsf(wi[i][2]) - fo[c]) / big;
                if (d > worst_f) worst_f = d;
            }
            double d = fabs((double)pp - po) / po;
            if (d > worst_pdf) worst_pdf = d;
            ++compared;
        }
    printf("check %d inputs: port vs hairtrace, max |df| / max(f) %.3g, max |dpdf| / pdf %.3g\n",
           compared, worst_f, worst_pdf);
    return compared > N && worst_f < 2e-3 && worst_pdf < 2e-3 ? 0 : 1;
}

int main(int argc, char **argv) {
    if (ht_abi_version() != HT_ABI_VERSION) {
        fprintf(stderr, "header and library disagree on the ABI version\n");
        return 1;
    }
    params[0] = ht_hair_params_default();
    params[1] = params[0];
    params[1].beta_m = 0.12f;
    params[1].alpha = -3.0f;
    OK(ht_hair_sigma_a_from_melanin(0.3f, 0.2f, params[1].sigma_a));
    for (int m = 0; m < 2; ++m) {
        OK(ht_hair_prepare(&params[m], &prepared[m]));
        port[m] = port_prepare(params[m].sigma_a, params[m].eta, params[m].beta_m,
                               params[m].beta_n, params[m].alpha);
    }
    for (int i = 0; i < N; ++i) {
        h[i] = 2.0f * uniform() - 1.0f;
        unit(wo[i]);
        unit(wi[i]);
        for (int k = 0; k < 3; ++k) u[i][k] = uniform();
    }
    /* Random right-handed frames (after the local inputs, so that vertex.rs draws those
     * alike), each with h[i], and wo, wi taken to world space. */
    for (int i = 0; i < N; ++i) {
        float x[3], r[3], y[3];
        unit(x);
        unit(r);
        y[0] = x[1] * r[2] - x[2] * r[1];
        y[1] = x[2] * r[0] - x[0] * r[2];
        y[2] = x[0] * r[1] - x[1] * r[0];
        float n = sqrtf(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
        HtHairFrame *fr = &frames[i];
        for (int k = 0; k < 3; ++k) {
            fr->x[k] = x[k];
            fr->y[k] = y[k] / n;
        }
        fr->z[0] = fr->x[1] * fr->y[2] - fr->x[2] * fr->y[1];
        fr->z[1] = fr->x[2] * fr->y[0] - fr->x[0] * fr->y[2];
        fr->z[2] = fr->x[0] * fr->y[1] - fr->x[1] * fr->y[0];
        fr->h = h[i];
        for (int k = 0; k < 3; ++k) {
            wo_w[i][k] = fr->x[k] * wo[i][0] + fr->y[k] * wo[i][1] + fr->z[k] * wo[i][2];
            wi_w[i][k] = fr->x[k] * wi[i][0] + fr->y[k] * wi[i][1] + fr->z[k] * wi[i][2];
        }
    }
    uint64_t hit_state = 0x51ed2701f3a5c7b9ull; /* vertex.cpp's and vertex.rs's */
    for (int i = 0; i < N; ++i) hits[i] = bench_hit(&hit_state);
    run_init_world();
    if (argc > 1 && strcmp(argv[1], "--check") == 0) return check();

    for (int r = 0; r < ROUNDS; ++r)
        for (int k = 0; k < METHODS; ++k) {
            double t0 = now();
            methods[k].run();
            methods[k].ns[r] = (now() - t0) / N;
            sink += f[N / 2][0] + pdf[N / 3];
        }
    double point = median(methods[3].ns), port_ns = median(methods[7].ns);
    printf("%-44s %8s\n", "ns per call (median of interleaved rounds)", "ns");
    for (int k = 0; k < METHODS; ++k) printf("%-44s %8.1f\n", methods[k].name, median(methods[k].ns));
    printf("port / ht_hair_point_eval_world: %.2fx\n", port_ns / point);
    for (int m = 0; m < 2; ++m) OK(ht_hair_prepared_free(prepared[m]));
    return check();
}
