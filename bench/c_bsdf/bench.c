/* Single-thread cost of the hair BSDF as a C host calls it: the per-call entry point, the
 * prepared per-vertex point (eval, pdf, sample), the batches, and a plain float port of
 * the model (port.c), timed in interleaved rounds over the same random inputs; medians of
 * ns per call. `bench --check` instead compares the port with hairtrace's values.
 * Build and run: bench/c_bsdf/run (see bench/README.md). */
#define _POSIX_C_SOURCE 199309L
#include "hairtrace.h"
#include "port.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { N = 4096, ROUNDS = 41 };

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static float uniform(void) { /* xorshift64*, 24 bits in [0, 1) */
    rng ^= rng >> 12;
    rng ^= rng << 25;
    rng ^= rng >> 27;
    return (float)((rng * 0x2545f4914f6cdd1dull) >> 40) / 16777216.0f;
}
static void unit(float *w) {
    float z = 2.0f * uniform() - 1.0f, phi = 6.2831853f * uniform();
    float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    w[0] = z;
    w[1] = r * cosf(phi);
    w[2] = r * sinf(phi);
}

static float h[N], wo[N][3], wi[N][3], u[N][3], f[N][3], pdf[N], wis[N][3];
static HtHairPoint points[N];
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
static void run_eval(void) { for (int i = 0; i < N; ++i) OK(ht_hair_eval(&params[0], h[i], wo[i], wi[i], f[i], &pdf[i])); }
static void run_eval_alt(void) { for (int i = 0; i < N; ++i) OK(ht_hair_eval(&params[i & 1], h[i], wo[i], wi[i], f[i], &pdf[i])); }
static void run_init(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_init(prepared[i & 1], h[i], wo[i], &points[i])); }
static void run_point_eval(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_eval(&points[i], wi[i], f[i], &pdf[i])); }
static void run_point_pdf(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_pdf(&points[i], wi[i], &pdf[i])); }
static void run_point_sample(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_sample(&points[i], u[i], wis[i], f[i], &pdf[i])); }
static void run_points_eval(void) { OK(ht_hair_points_eval(points, N, wi[0], f[0], pdf)); }
static void run_points_sample(void) { OK(ht_hair_points_sample(points, N, u[0], wis[0], f[0], pdf)); }
static void run_eval_batch(void) { OK(ht_hair_eval_batch(&params[0], N, h, wo[0], wi[0], f[0], pdf)); }
static void run_port(void) { for (int i = 0; i < N; ++i) port_eval(&port[0], h[i], wo[i], wi[i], f[i], &pdf[i]); }
static void run_port_alt(void) { for (int i = 0; i < N; ++i) port_eval(&port[i & 1], h[i], wo[i], wi[i], f[i], &pdf[i]); }

typedef struct { const char *name; void (*run)(void); double ns[ROUNDS]; } Method;
static Method methods[] = {
    {"ht_hair_eval (one material)", run_eval, {0}},
    {"ht_hair_eval (two materials alternating)", run_eval_alt, {0}},
    {"ht_hair_point_init", run_init, {0}},
    {"ht_hair_point_eval", run_point_eval, {0}},
    {"ht_hair_point_pdf", run_point_pdf, {0}},
    {"ht_hair_point_sample", run_point_sample, {0}},
    {"ht_hair_points_eval, per element", run_points_eval, {0}},
    {"ht_hair_points_sample, per element", run_points_sample, {0}},
    {"ht_hair_eval_batch, per element", run_eval_batch, {0}},
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

/* The port against hairtrace on every input: the largest difference of f relative to the
 * largest channel, and of pdf, over inputs away from the tangent (where f32 input rounding
 * alone moves the model by more; README "Accuracy"). */
static int check(void) {
    double worst_f = 0.0, worst_pdf = 0.0;
    int compared = 0;
    for (int m = 0; m < 2; ++m)
        for (int i = 0; i < N; ++i) {
            if (fabsf(wo[i][0]) > 0.99f || fabsf(wi[i][0]) > 0.99f) continue;
            float fo[3], po, fp[3], pp;
            OK(ht_hair_eval(&params[m], h[i], wo[i], wi[i], fo, &po));
            port_eval(&port[m], h[i], wo[i], wi[i], fp, &pp);
            float big = fmaxf(fo[0], fmaxf(fo[1], fo[2]));
            for (int c = 0; c < 3; ++c) {
                double d = fabs((double)fp[c] - fo[c]) / big;
                if (d > worst_f) worst_f = d;
            }
            double d = fabs((double)pp - po) / po;
            if (d > worst_pdf) worst_pdf = d;
            ++compared;
        }
    printf("check %d inputs: port vs hairtrace, max |df| / max(f) %.3g, max |dpdf| / pdf %.3g\n",
           compared, worst_f, worst_pdf);
    return worst_f < 2e-3 && worst_pdf < 2e-3 ? 0 : 1;
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
    run_init();
    if (argc > 1 && strcmp(argv[1], "--check") == 0) return check();

    for (int r = 0; r < ROUNDS; ++r)
        for (int k = 0; k < METHODS; ++k) {
            double t0 = now();
            methods[k].run();
            methods[k].ns[r] = (now() - t0) / N;
            sink += f[N / 2][0] + pdf[N / 3];
        }
    double point = median(methods[3].ns), port_ns = median(methods[9].ns);
    printf("%-44s %8s\n", "ns per call (median of interleaved rounds)", "ns");
    for (int k = 0; k < METHODS; ++k) printf("%-44s %8.1f\n", methods[k].name, median(methods[k].ns));
    printf("port / ht_hair_point_eval: %.2fx\n", port_ns / point);
    for (int m = 0; m < 2; ++m) OK(ht_hair_prepared_free(prepared[m]));
    return check();
}
