/* Every BSDF entry point of the C ABI given bad arguments: NULLs, NaN and infinities, huge
 * and "negative" sizes, misaligned and overlapping buffers. Each row names the call, the
 * status it must return and pieces of its message (in order, split at "|"); outputs must
 * be left untouched.
 * Prints one line per failed row and "checks N failed M"; exits 1 if any failed. */
#include "hairtrace.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

static int checks, failed;

/* Whether msg holds the pieces of `parts` (separated by '|') in this order. */
static int holds(const char *msg, const char *parts) {
    char piece[128];
    while (parts != NULL && *parts) {
        const char *bar = strchr(parts, '|');
        size_t n = bar ? (size_t)(bar - parts) : strlen(parts);
        memcpy(piece, parts, n);
        piece[n] = '\0';
        msg = strstr(msg, piece);
        if (msg == NULL) return 0;
        msg += n;
        parts = bar ? bar + 1 : NULL;
    }
    return 1;
}

static void check(int line, const char *call, HtStatus got, HtStatus want, const char *part) {
    const char *msg = got == HT_OK ? "" : ht_last_error();
    ++checks;
    if (got != want || !holds(msg, part)) {
        ++failed;
        fprintf(stderr, "FAIL line %d: %s\n  got %s \"%s\", want %s \"%s\"\n", line, call,
               ht_status_str((int32_t)got), msg, ht_status_str((int32_t)want),
               part ? part : "");
    }
}
#define ROW(want, part, call) check(__LINE__, #call, (call), (want), (part))
#define UNTOUCHED(buf, n) \
    do { for (size_t k_ = 0; k_ < (n); ++k_) if ((buf)[k_] != 7.0f) { ++failed; \
        fprintf(stderr, "FAIL line %d: %s[%zu] was written\n", __LINE__, #buf, k_); } } while (0)

#define NUL HT_ERR_NULL_ARG
#define BAD HT_ERR_INVALID_ARG
#define OK HT_OK

/* Storage with room for misaligned views. */
static union { float f[64]; HtHairPoint p[4]; } store;

int main(void) {
    const float nan = NAN, inf = INFINITY;
    HtHairParams p = ht_hair_params_default();
    HtHairParams bad_eta = p, bad_beta = p, bad_alpha = p, inf_sigma = p;
    bad_eta.eta = inf;
    bad_beta.beta_m = 2.0f;
    bad_alpha.alpha = 30.0f;
    inf_sigma.sigma_a[1] = inf;
    float wo[3] = {0.0f, 0.0f, 1.0f}, wi[3] = {0.0f, 0.6f, 0.8f};
    float zero3[3] = {0.0f, 0.0f, 0.0f}, long3[3] = {0.0f, 0.0f, 1.01f}, nan3[3] = {nan, 0, 1};
    float u[3] = {0.2f, 0.4f, 0.6f}, u_one[3] = {1.0f, 0.5f, 0.5f}, u_neg[3] = {0.5f, -0.1f, 0.5f};
    float u_nan[3] = {0.5f, 0.5f, nan};
    float f[8], pdf, out[8];
    float *odd = (float *)((char *)store.f + 2); /* 2 mod 4 bytes: misaligned for float */
    const size_t huge = SIZE_MAX / 2, negative = (size_t)-1;
    for (int k = 0; k < 8; ++k) f[k] = out[k] = 7.0f;

    /* sigma_a from melanin and colour. */
    ROW(NUL, "sigma_a is NULL", ht_hair_sigma_a_from_melanin(1.0f, 0.0f, NULL));
    ROW(NUL, "sigma_a is NULL", ht_hair_sigma_a_from_melanin(nan, 0.0f, NULL));
    ROW(BAD, "eumelanin = NaN", ht_hair_sigma_a_from_melanin(nan, 0.0f, out));
    ROW(BAD, "pheomelanin = -1", ht_hair_sigma_a_from_melanin(1.0f, -1.0f, out));
    ROW(BAD, "overflows", ht_hair_sigma_a_from_melanin(FLT_MAX, FLT_MAX, out));
    ROW(BAD, "eumelanin = inf", ht_hair_sigma_a_from_melanin(inf, 0.0f, out));
    ROW(BAD, "not aligned", ht_hair_sigma_a_from_melanin(1.0f, 0.0f, odd));
    /* sigma_a presets by name: an unknown name lists the known ones. */
    ROW(BAD, "known: red_brown, light_brown", ht_hair_sigma_a_preset("auburn", out));
    ROW(BAD, "name is empty", ht_hair_sigma_a_preset("", out));
    ROW(NUL, "name is NULL", ht_hair_sigma_a_preset(NULL, out));
    ROW(NUL, "sigma_a is NULL", ht_hair_sigma_a_preset("auburn", NULL));
    ROW(BAD, "not aligned", ht_hair_sigma_a_preset("black", odd));
    UNTOUCHED(out, 8);
    float grey[3] = {0.5f, 0.5f, 0.5f}, bright[3] = {0.5f, 1.5f, 0.5f}, black[3] = {0.5f, 0.0f, 0.5f};
    ROW(NUL, "color is NULL", ht_hair_sigma_a_from_color(NULL, nan, out));
    ROW(NUL, "sigma_a is NULL", ht_hair_sigma_a_from_color(grey, 0.3f, NULL));
    ROW(BAD, "more than it receives", ht_hair_sigma_a_from_color(bright, 0.3f, out));
    ROW(BAD, "infinite absorption", ht_hair_sigma_a_from_color(black, 0.3f, out));
    ROW(BAD, "color[0] = NaN", ht_hair_sigma_a_from_color(nan3, 0.3f, out));
    ROW(BAD, "beta_n = NaN", ht_hair_sigma_a_from_color(grey, nan, out));
    ROW(BAD, "sigma_a and color overlap", ht_hair_sigma_a_from_color(out, 0.3f, out + 1));
    ROW(BAD, "not aligned", ht_hair_sigma_a_from_color(odd, 0.3f, out));
    UNTOUCHED(out, 8);

    /* ht_hair_eval: NULLs first, whatever else is wrong. */
    ROW(NUL, "params is NULL", ht_hair_eval(NULL, nan, wo, wi, f, &pdf));
    ROW(NUL, "wo is NULL", ht_hair_eval(&p, 0.0f, NULL, wi, f, &pdf));
    ROW(NUL, "wi is NULL", ht_hair_eval(&bad_eta, nan, wo, NULL, f, &pdf));
    ROW(NUL, "f is NULL", ht_hair_eval(&p, 0.0f, wo, wi, NULL, &pdf));
    ROW(NUL, "pdf is NULL", ht_hair_eval(&p, 0.0f, wo, wi, f, NULL));
    ROW(BAD, "h = NaN", ht_hair_eval(&p, nan, wo, wi, f, &pdf));
    ROW(BAD, "h = inf", ht_hair_eval(&p, inf, wo, wi, f, &pdf));
    ROW(BAD, "h = 1.5", ht_hair_eval(&p, 1.5f, wo, wi, f, &pdf));
    ROW(BAD, "wo = [0, 0, 1.01]", ht_hair_eval(&p, 0.0f, long3, wi, f, &pdf));
    ROW(BAD, "wi = [0, 0, 0]", ht_hair_eval(&p, 0.0f, wo, zero3, f, &pdf));
    ROW(BAD, "wo = [NaN", ht_hair_eval(&p, 0.0f, nan3, wi, f, &pdf));
    ROW(BAD, "eta = inf", ht_hair_eval(&bad_eta, 0.0f, wo, wi, f, &pdf));
    ROW(BAD, "beta_m = 2", ht_hair_eval(&bad_beta, 0.0f, wo, wi, f, &pdf));
    ROW(BAD, "alpha = 30", ht_hair_eval(&bad_alpha, 0.0f, wo, wi, f, &pdf));
    ROW(BAD, "sigma_a[1] = inf", ht_hair_eval(&inf_sigma, 0.0f, wo, wi, f, &pdf));
    ROW(BAD, "f = ", ht_hair_eval(&p, 0.0f, wo, wi, odd, &pdf));
    ROW(BAD, "f and pdf overlap", ht_hair_eval(&p, 0.0f, wo, wi, f, &f[2]));
    ROW(BAD, "f and wi overlap", ht_hair_eval(&p, 0.0f, wo, f, f, &pdf));
    UNTOUCHED(f, 8);

    /* ht_hair_sample */
    float ws[3] = {7, 7, 7};
    ROW(NUL, "u is NULL", ht_hair_sample(&p, nan, wo, NULL, ws, f, &pdf));
    ROW(NUL, "wi is NULL", ht_hair_sample(&p, 0.0f, wo, u, NULL, f, &pdf));
    ROW(BAD, "u[0] = 1", ht_hair_sample(&p, 0.0f, wo, u_one, ws, f, &pdf));
    ROW(BAD, "u[1] = -0.1", ht_hair_sample(&p, 0.0f, wo, u_neg, ws, f, &pdf));
    ROW(BAD, "u[2] = NaN", ht_hair_sample(&p, 0.0f, wo, u_nan, ws, f, &pdf));
    ROW(BAD, "wi and f overlap", ht_hair_sample(&p, 0.0f, wo, u, f, f + 1, &pdf));
    ROW(BAD, "not aligned", ht_hair_sample(&p, 0.0f, wo, u, odd, f, &pdf));
    UNTOUCHED(f, 8);
    UNTOUCHED(ws, 3);

    /* ht_hair_eval_batch */
    float hs[2] = {0.1f, 0.2f}, wos[6] = {0, 0, 1, 0, 0, 1}, wis[6] = {0, 0.6f, 0.8f, 0, 0, 2};
    ROW(BAD, "do not fit in memory", ht_hair_eval_batch(&p, huge, hs, wos, wis, f, &pdf));
    ROW(BAD, "do not fit in memory", ht_hair_eval_batch(&p, negative, hs, wos, wis, f, &pdf));
    ROW(NUL, "params is NULL", ht_hair_eval_batch(NULL, 0, NULL, NULL, NULL, NULL, NULL));
    ROW(BAD, "beta_m = 2", ht_hair_eval_batch(&bad_beta, 0, NULL, NULL, NULL, NULL, NULL));
    ROW(OK, NULL, ht_hair_eval_batch(&p, 0, NULL, NULL, NULL, NULL, NULL));
    ROW(NUL, "h is NULL", ht_hair_eval_batch(&p, 2, NULL, wos, wis, f, out));
    ROW(NUL, "pdf is NULL", ht_hair_eval_batch(&p, 2, hs, wos, wis, f, NULL));
    ROW(BAD, "element 1: ", ht_hair_eval_batch(&p, 2, hs, wos, wis, f, out));
    ROW(BAD, "wo = ", ht_hair_eval_batch(&p, 2, hs, odd, wis, f, out));
    ROW(BAD, "f and pdf overlap", ht_hair_eval_batch(&p, 2, hs, wos, wos, f, f + 5));
    ROW(BAD, "f and wi overlap", ht_hair_eval_batch(&p, 2, hs, wos, f, f, out));
    UNTOUCHED(f, 8);
    UNTOUCHED(out, 8);

    /* Prepared handle and points. */
    HtHairPrepared *prep = NULL, *untouched = (HtHairPrepared *)&store;
    ROW(NUL, "params is NULL", ht_hair_prepare(NULL, &prep));
    ROW(NUL, "out is NULL", ht_hair_prepare(&p, NULL));
    ROW(BAD, "beta_m = 2", ht_hair_prepare(&bad_beta, &untouched));
    if (untouched != (HtHairPrepared *)&store) { ++failed; fprintf(stderr, "FAIL: out written\n"); }
    ROW(OK, NULL, ht_hair_prepared_free(NULL));
    ROW(OK, NULL, ht_hair_prepare(&p, &prep));
    HtHairPoint pt, zeroed;
    memset(&zeroed, 0, sizeof zeroed);
    HtHairPoint *odd_point = (HtHairPoint *)((char *)store.p + 4);
    ROW(NUL, "prepared is NULL", ht_hair_point_init(NULL, nan, wo, &pt));
    ROW(NUL, "wo is NULL", ht_hair_point_init(prep, 0.0f, NULL, &pt));
    ROW(NUL, "point is NULL", ht_hair_point_init(prep, 0.0f, wo, NULL));
    ROW(BAD, "h = NaN", ht_hair_point_init(prep, nan, wo, &pt));
    ROW(BAD, "wo = [0, 0, 0]", ht_hair_point_init(prep, 0.0f, zero3, &pt));
    ROW(BAD, "not aligned to 16", ht_hair_point_init(prep, 0.0f, wo, odd_point));
    memcpy(store.p[1].opaque, wo, sizeof wo);
    ROW(BAD, "point and wo overlap",
        ht_hair_point_init(prep, 0.0f, (const float *)store.p[1].opaque, &store.p[1]));
    ROW(OK, NULL, ht_hair_point_init(prep, 0.3f, wo, &pt));
    ROW(OK, NULL, ht_hair_prepared_free(prep)); /* the point keeps its own copy */

    ROW(NUL, "point is NULL", ht_hair_point_eval(NULL, nan3, f, &pdf));
    ROW(NUL, "wi is NULL", ht_hair_point_eval(&pt, NULL, f, &pdf));
    ROW(NUL, "f is NULL", ht_hair_point_eval(&pt, wi, NULL, &pdf));
    ROW(BAD, "not filled by ht_hair_point_init", ht_hair_point_eval(&zeroed, wi, f, &pdf));
    ROW(BAD, "not aligned to 16", ht_hair_point_eval(odd_point, wi, f, &pdf));
    ROW(BAD, "wi = [NaN", ht_hair_point_eval(&pt, nan3, f, &pdf));
    ROW(BAD, "wi = [0, 0, 1.01]", ht_hair_point_eval(&pt, long3, f, &pdf));
    ROW(BAD, "not aligned to 4", ht_hair_point_eval(&pt, wi, odd, &pdf));
    ROW(BAD, "f and pdf overlap", ht_hair_point_eval(&pt, wi, f, f + 1));
    ROW(BAD, "f and point overlap", ht_hair_point_eval(&pt, wi, (float *)pt.opaque, &pdf));
    ROW(NUL, "pdf is NULL", ht_hair_point_pdf(&pt, wi, NULL));
    ROW(BAD, "wi = [0, 0, 0]", ht_hair_point_pdf(&pt, zero3, &pdf));
    ROW(BAD, "pdf and wi overlap", ht_hair_point_pdf(&pt, f, f + 2));
    float fa[3 * HT_ACROSS], pa[HT_ACROSS];
    for (size_t k = 0; k < 3 * HT_ACROSS; ++k) fa[k] = 7.0f;
    for (size_t k = 0; k < HT_ACROSS; ++k) pa[k] = 7.0f;
    ROW(NUL, "f_cos is NULL", ht_hair_point_eval_across(&pt, wi, NULL, pa));
    ROW(NUL, "pdf is NULL", ht_hair_point_eval_across(&pt, wi, fa, NULL));
    ROW(BAD, "not filled by ht_hair_point_init", ht_hair_point_eval_across(&zeroed, wi, fa, pa));
    ROW(BAD, "not aligned to 16", ht_hair_point_eval_across(odd_point, wi, fa, pa));
    ROW(BAD, "wi = [0, 0, 1.01]", ht_hair_point_eval_across(&pt, long3, fa, pa));
    ROW(BAD, "f_cos and pdf overlap", ht_hair_point_eval_across(&pt, wi, fa, fa + 3));
    ROW(BAD, "pdf and point overlap",
        ht_hair_point_eval_across(&pt, wi, fa, (float *)pt.opaque + 4));
    UNTOUCHED(fa, 3 * HT_ACROSS);
    UNTOUCHED(pa, HT_ACROSS);
    ROW(OK, NULL, ht_hair_point_eval_across(&pt, wi, fa, pa));
    ROW(NUL, "u is NULL", ht_hair_point_sample(&pt, NULL, ws, f, &pdf));
    ROW(BAD, "u[0] = 1", ht_hair_point_sample(&pt, u_one, ws, f, &pdf));
    ROW(BAD, "u[2] = NaN", ht_hair_point_sample(&pt, u_nan, ws, f, &pdf));
    ROW(BAD, "wi and f overlap", ht_hair_point_sample(&pt, u, f, f + 2, &pdf));
    UNTOUCHED(f, 8);
    UNTOUCHED(ws, 3);

    HtHairPoint two[2];
    two[0] = pt;
    two[1] = zeroed;
    float wi2[6] = {0, 0.6f, 0.8f, 0, 0, 1}, u2[6] = {0.1f, 0.2f, 0.3f, 0.5f, 0.5f, 1.0f};
    ROW(BAD, "do not fit in memory", ht_hair_points_eval(two, huge, wi2, f, out));
    ROW(BAD, "do not fit in memory", ht_hair_points_eval(two, negative, wi2, f, out));
    ROW(OK, NULL, ht_hair_points_eval(NULL, 0, NULL, NULL, NULL));
    ROW(NUL, "points is NULL", ht_hair_points_eval(NULL, 2, wi2, f, out));
    ROW(BAD, "element 1: |point was not filled", ht_hair_points_eval(two, 2, wi2, f, out));
    two[1] = pt;
    ROW(BAD, "element 1: |wi = [0, 0, 2]", ht_hair_points_eval(two, 2, wis, f, out));
    ROW(BAD, "not aligned to 16", ht_hair_points_eval(odd_point, 2, wi2, f, out));
    ROW(BAD, "f and points overlap", ht_hair_points_eval(two, 2, wi2, (float *)two[1].opaque, out));
    ROW(BAD, "do not fit in memory", ht_hair_points_sample(two, huge, u2, ws, f, out));
    ROW(BAD, "element 1: |u[2] = 1", ht_hair_points_sample(two, 2, u2, f, f + 6, out));
    ROW(BAD, "wi and f overlap", ht_hair_points_sample(two, 2, u, f, f + 3, out));
    UNTOUCHED(f, 8);
    UNTOUCHED(out, 8);

    /* The frame helper and conversions. */
    float x[3] = {1, 0, 0}, org[3] = {0, 0.5f, 5}, d[3] = {0, 0, -1}, axis[3] = {0, 0, 0};
    float far_org[3] = {0, 2.0f, 5}, along[3] = {-5, 0, 0};
    HtHairFrame fr, keep;
    memset(&keep, 0, sizeof keep);
    fr = keep;
    ROW(NUL, "tangent is NULL", ht_hair_frame(NULL, org, d, axis, nan, &fr));
    ROW(NUL, "ray_org is NULL", ht_hair_frame(x, NULL, d, axis, 1.0f, &fr));
    ROW(NUL, "frame is NULL", ht_hair_frame(x, org, d, axis, 1.0f, NULL));
    ROW(BAD, "tangent is zero", ht_hair_frame(zero3, org, d, axis, 1.0f, &fr));
    ROW(BAD, "ray_dir is zero", ht_hair_frame(x, org, zero3, axis, 1.0f, &fr));
    ROW(BAD, "axis = [NaN", ht_hair_frame(x, org, d, nan3, 1.0f, &fr));
    ROW(BAD, "radius = 0", ht_hair_frame(x, org, d, axis, 0.0f, &fr));
    ROW(BAD, "radius = -1", ht_hair_frame(x, org, d, axis, -1.0f, &fr));
    ROW(BAD, "radius = inf", ht_hair_frame(x, org, d, axis, inf, &fr));
    ROW(BAD, "radius = NaN", ht_hair_frame(x, org, d, axis, nan, &fr));
    ROW(BAD, "2 radii away", ht_hair_frame(x, far_org, d, axis, 1.0f, &fr));
    ROW(BAD, "not aligned", ht_hair_frame(odd, org, d, axis, 1.0f, &fr));
    ROW(BAD, "frame and tangent overlap", ht_hair_frame(fr.y, org, d, axis, 1.0f, &fr));
    if (memcmp(&fr, &keep, sizeof fr) != 0) { ++failed; fprintf(stderr, "FAIL: frame written\n"); }
    ROW(OK, NULL, ht_hair_frame(x, along, x, axis, 1.0f, &fr)); /* ray along the tangent */
    ROW(OK, NULL, ht_hair_frame(x, org, d, axis, 1.0f, &fr));
    if (!(fr.h == 0.5f && fr.y[1] == 1.0f && fr.z[2] == 1.0f)) { ++failed; fprintf(stderr, "FAIL: worked example\n"); }
    HtHairFrame mirrored = fr;
    mirrored.z[2] = -1.0f;
    ROW(NUL, "frame is NULL", ht_hair_frame_to_local(NULL, nan3, out));
    ROW(NUL, "w is NULL", ht_hair_frame_to_local(&fr, NULL, out));
    ROW(NUL, "out is NULL", ht_hair_frame_to_world(&fr, wo, NULL));
    ROW(BAD, "right-handed orthonormal", ht_hair_frame_to_local(&mirrored, wo, out));
    ROW(BAD, "w = [NaN", ht_hair_frame_to_world(&fr, nan3, out));
    ROW(BAD, "out and w overlap", ht_hair_frame_to_local(&fr, out, out));
    ROW(BAD, "out and frame overlap", ht_hair_frame_to_world(&fr, wo, fr.x));
    UNTOUCHED(out, 8);

    /* The combined and world-space point calls. */
    HtHairPoint framed;
    float wo_world[3] = {0, 0, 1}, wi_world[3] = {0, 0.6f, 0.8f};
    HtHairFrame bad_h = fr;
    bad_h.h = 1.5f;
    ROW(OK, NULL, ht_hair_prepare(&p, &prep));
    ROW(NUL, "prepared is NULL", ht_hair_point_init_world(NULL, &fr, wo_world, &framed));
    ROW(NUL, "frame is NULL", ht_hair_point_init_world(prep, NULL, wo_world, &framed));
    ROW(NUL, "wo is NULL", ht_hair_point_init_world(prep, &fr, NULL, &framed));
    ROW(NUL, "point is NULL", ht_hair_point_init_world(prep, &fr, wo_world, NULL));
    ROW(BAD, "right-handed orthonormal", ht_hair_point_init_world(prep, &mirrored, wo_world, &framed));
    ROW(BAD, "h = 1.5", ht_hair_point_init_world(prep, &bad_h, wo_world, &framed));
    ROW(BAD, "wo = [0, 0, 0]", ht_hair_point_init_world(prep, &fr, zero3, &framed));
    ROW(BAD, "not aligned to 16", ht_hair_point_init_world(prep, &fr, wo_world, odd_point));
    ROW(BAD, "point and frame overlap",
        ht_hair_point_init_world(prep, (const HtHairFrame *)store.p[1].opaque, wo_world, &store.p[1]));
    ROW(OK, NULL, ht_hair_point_init_world(prep, &fr, wo_world, &framed));
    ROW(OK, NULL, ht_hair_prepared_free(prep));
    ROW(NUL, "f_cos is NULL", ht_hair_point_eval_cos(&pt, wi, NULL, &pdf));
    ROW(BAD, "wi = [0, 0, 1.01]", ht_hair_point_eval_cos(&pt, long3, f, &pdf));
    ROW(BAD, "f_cos and pdf overlap", ht_hair_point_eval_cos(&pt, wi, f, f + 1));
    ROW(NUL, "weight is NULL", ht_hair_point_sample_cos(&pt, u, ws, NULL, &pdf));
    ROW(BAD, "u[0] = 1", ht_hair_point_sample_cos(&pt, u_one, ws, f, &pdf));
    ROW(BAD, "wi and weight overlap", ht_hair_point_sample_cos(&pt, u, f, f + 2, &pdf));
    ROW(BAD, "not filled by ht_hair_point_init", ht_hair_point_eval_world(&zeroed, wi_world, f, &pdf));
    ROW(BAD, "without a frame", ht_hair_point_eval_world(&pt, wi_world, f, &pdf));
    ROW(BAD, "without a frame", ht_hair_point_sample_world(&pt, u, ws, f, &pdf));
    ROW(NUL, "wi is NULL", ht_hair_point_eval_world(&framed, NULL, f, &pdf));
    ROW(BAD, "wi (in the point's frame) = [0, 0, 0]", ht_hair_point_eval_world(&framed, zero3, f, &pdf));
    ROW(BAD, "f_cos and point overlap",
        ht_hair_point_eval_world(&framed, wi_world, (float *)framed.opaque, &pdf));
    ROW(BAD, "u[2] = NaN", ht_hair_point_sample_world(&framed, u_nan, ws, f, &pdf));
    ROW(BAD, "weight and pdf overlap", ht_hair_point_sample_world(&framed, u, ws, f, f + 2));
    UNTOUCHED(f, 8);
    UNTOUCHED(ws, 3);
    ROW(OK, NULL, ht_hair_point_eval_world(&framed, wi_world, f, &pdf));
    ROW(OK, NULL, ht_hair_point_sample_world(&framed, u, ws, f, &pdf));
    for (size_t k = 0; k < 3 * HT_ACROSS; ++k) fa[k] = 7.0f;
    for (size_t k = 0; k < HT_ACROSS; ++k) pa[k] = 7.0f;
    ROW(NUL, "point is NULL", ht_hair_point_eval_across_world(NULL, wi_world, fa, pa));
    ROW(NUL, "wi is NULL", ht_hair_point_eval_across_world(&framed, NULL, fa, pa));
    ROW(BAD, "without a frame", ht_hair_point_eval_across_world(&pt, wi_world, fa, pa));
    ROW(BAD, "not filled by ht_hair_point_init", ht_hair_point_eval_across_world(&zeroed, wi_world, fa, pa));
    ROW(BAD, "wi (in the point's frame) = [0, 0, 0]",
        ht_hair_point_eval_across_world(&framed, zero3, fa, pa));
    ROW(BAD, "f_cos and pdf overlap", ht_hair_point_eval_across_world(&framed, wi_world, fa, fa + 5));
    ROW(BAD, "f_cos and point overlap",
        ht_hair_point_eval_across_world(&framed, wi_world, (float *)framed.opaque, pa));
    UNTOUCHED(fa, 3 * HT_ACROSS);
    UNTOUCHED(pa, HT_ACROSS);
    ROW(OK, NULL, ht_hair_point_eval_across_world(&framed, wi_world, fa, pa));

    printf("checks %d failed %d\n", checks, failed);
    return failed ? 1 : 0;
}
