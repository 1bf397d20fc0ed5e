/* Single-thread cost of the hair BSDF as a C host calls it: the per-call entry point, the
 * prepared per-vertex point (eval, pdf, sample, the combined and world-space calls), whole
 * path vertices as a host makes them, the batches, and a plain float port of the model
 * (port.c), timed in interleaved rounds over the same random inputs; medians of ns per
 * call. `bench --check` instead compares the port with hairtrace's values. vertex.rs times
 * the Rust vertex on the same inputs. Build and run: bench/c_bsdf/run (bench/README.md). */
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
/* A world frame per input (h[i] its h) and wo, wi in world space: the local inputs turned. */
static HtHairFrame frames[N];
static float wo_w[N][3], wi_w[N][3];
static HtHairPoint points[N], framed[N];
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
static void run_init_world(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_init_world(prepared[i & 1], &frames[i], wo_w[i], &framed[i])); }
static void run_eval_cos(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_eval_cos(&points[i], wi[i], f[i], &pdf[i])); }
static void run_sample_cos(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_sample_cos(&points[i], u[i], wis[i], f[i], &pdf[i])); }
static void run_eval_world(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_eval_world(&framed[i], wi_w[i], f[i], &pdf[i])); }
static void run_sample_world(void) { for (int i = 0; i < N; ++i) OK(ht_hair_point_sample_world(&framed[i], u[i], wis[i], f[i], &pdf[i])); }
static void run_to_local(void) { for (int i = 0; i < N; ++i) OK(ht_hair_frame_to_local(&frames[i], wo_w[i], wis[i])); }
/* A whole path vertex: the point, light evaluation with its MIS pdf, and a sampled
 * direction. As a host with a split sample/eval/pdf material API calls the ABI-6 entry
 * points (7 calls: wo and the light direction to the local frame, init, eval, pdf,
 * sample, the sample back to world space); with the combined local calls (3); with the
 * world-space calls (3). The point is a local variable, as a path tracer keeps it for the
 * vertex (and as the Rust vertex does). */
static void run_vertex_split(void) {
    for (int i = 0; i < N; ++i) {
        float l[3], w[3], light[3], fl[3], pl, ps, ws[3];
        HtHairPoint p;
        OK(ht_hair_frame_to_local(&frames[i], wo_w[i], l));
        OK(ht_hair_point_init(prepared[i & 1], frames[i].h, l, &p));
        OK(ht_hair_frame_to_local(&frames[i], wi_w[i], light));
        OK(ht_hair_point_eval(&p, light, fl, &pl));
        OK(ht_hair_point_pdf(&p, light, &pl));
        OK(ht_hair_point_sample(&p, u[i], w, f[i], &ps));
        OK(ht_hair_frame_to_world(&frames[i], w, ws));
        pdf[i] = pl + ps + fl[0] + ws[0];
    }
}
static void run_vertex_local(void) {
    for (int i = 0; i < N; ++i) {
        float fl[3], pl, ps;
        HtHairPoint p;
        OK(ht_hair_point_init(prepared[i & 1], h[i], wo[i], &p));
        OK(ht_hair_point_eval_cos(&p, wi[i], fl, &pl));
        OK(ht_hair_point_sample_cos(&p, u[i], wis[i], f[i], &ps));
        pdf[i] = pl + ps + fl[0];
    }
}
static void run_vertex_world(void) {
    for (int i = 0; i < N; ++i) {
        float fl[3], pl, ps;
        HtHairPoint p;
        OK(ht_hair_point_init_world(prepared[i & 1], &frames[i], wo_w[i], &p));
        OK(ht_hair_point_eval_world(&p, wi_w[i], fl, &pl));
        OK(ht_hair_point_sample_world(&p, u[i], wis[i], f[i], &ps));
        pdf[i] = pl + ps + fl[0];
    }
}
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
    {"ht_hair_point_init_world", run_init_world, {0}},
    {"ht_hair_point_eval_cos", run_eval_cos, {0}},
    {"ht_hair_point_sample_cos", run_sample_cos, {0}},
    {"ht_hair_point_eval_world", run_eval_world, {0}},
    {"ht_hair_point_sample_world", run_sample_world, {0}},
    {"ht_hair_frame_to_local", run_to_local, {0}},
    {"vertex, split calls (7, ABI 6)", run_vertex_split, {0}},
    {"vertex, combined local calls (3)", run_vertex_local, {0}},
    {"vertex, world-space calls (3)", run_vertex_world, {0}},
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
        OK(ht_hair_frame_to_world(fr, wo[i], wo_w[i]));
        OK(ht_hair_frame_to_world(fr, wi[i], wi_w[i]));
    }
    run_init();
    run_init_world();
    if (argc > 1 && strcmp(argv[1], "--check") == 0) return check();

    for (int r = 0; r < ROUNDS; ++r)
        for (int k = 0; k < METHODS; ++k) {
            double t0 = now();
            methods[k].run();
            methods[k].ns[r] = (now() - t0) / N;
            sink += f[N / 2][0] + pdf[N / 3];
        }
    double point = median(methods[3].ns), port_ns = median(methods[18].ns);
    printf("%-44s %8s\n", "ns per call (median of interleaved rounds)", "ns");
    for (int k = 0; k < METHODS; ++k) printf("%-44s %8.1f\n", methods[k].name, median(methods[k].ns));
    printf("port / ht_hair_point_eval: %.2fx\n", port_ns / point);
    for (int m = 0; m < 2; ++m) OK(ht_hair_prepared_free(prepared[m]));
    return check();
}
