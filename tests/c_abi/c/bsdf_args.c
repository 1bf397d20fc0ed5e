/* Every BSDF entry point of the C ABI given bad arguments: NULLs, NaN and infinities, values
 * out of range, misaligned and overlapping buffers. Each row names the call, the
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
    float wo[3] = {0.0f, 0.0f, 1.0f};
    float zero3[3] = {0.0f, 0.0f, 0.0f}, long3[3] = {0.0f, 0.0f, 1.01f}, nan3[3] = {nan, 0, 1};
    float u[3] = {0.2f, 0.4f, 0.6f}, u_one[3] = {1.0f, 0.5f, 0.5f}, u_neg[3] = {0.5f, -0.1f, 0.5f};
    float u_nan[3] = {0.5f, 0.5f, nan};
    float f[8], pdf, out[8];
    float *odd = (float *)((char *)store.f + 2); /* 2 mod 4 bytes: misaligned for float */
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

    /* Prepared handle. */
    HtHairPrepared *prep = NULL, *untouched = (HtHairPrepared *)&store;
    ROW(NUL, "params is NULL", ht_hair_prepare(NULL, &prep));
    ROW(NUL, "out is NULL", ht_hair_prepare(&p, NULL));
    ROW(NUL, "params is NULL", ht_hair_prepare(NULL, NULL));
    ROW(BAD, "eta = inf", ht_hair_prepare(&bad_eta, &untouched));
    ROW(BAD, "beta_m = 2", ht_hair_prepare(&bad_beta, &untouched));
    ROW(BAD, "alpha = 30", ht_hair_prepare(&bad_alpha, &untouched));
    ROW(BAD, "sigma_a[1] = inf", ht_hair_prepare(&inf_sigma, &untouched));
    ROW(BAD, "params|not aligned", ht_hair_prepare((const HtHairParams *)(const void *)odd, &prep));
    if (untouched != (HtHairPrepared *)&store) { ++failed; fprintf(stderr, "FAIL: out written\n"); }
    ROW(OK, NULL, ht_hair_prepared_free(NULL));
    ROW(OK, NULL, ht_hair_prepare(&p, &prep));

    /* The frame of a hit. */
    float x[3] = {1, 0, 0}, org[3] = {0, 0.5f, 5}, d[3] = {0, 0, -1}, axis[3] = {0, 0, 0};
    float far_org[3] = {0, 2.0f, 5}, along[3] = {-5, 0, 0};
    HtHairFrame fr, keep;
    memset(&keep, 0, sizeof keep);
    fr = keep;
    ROW(NUL, "tangent is NULL", ht_hair_frame(NULL, org, d, axis, nan, &fr));
    ROW(NUL, "ray_org is NULL", ht_hair_frame(x, NULL, d, axis, 1.0f, &fr));
    ROW(NUL, "ray_dir is NULL", ht_hair_frame(x, org, NULL, axis, 1.0f, &fr));
    ROW(NUL, "axis is NULL", ht_hair_frame(x, org, d, NULL, 1.0f, &fr));
    ROW(NUL, "frame is NULL", ht_hair_frame(x, org, d, axis, 1.0f, NULL));
    ROW(BAD, "tangent is zero", ht_hair_frame(zero3, org, d, axis, 1.0f, &fr));
    ROW(BAD, "ray_dir is zero", ht_hair_frame(x, org, zero3, axis, 1.0f, &fr));
    ROW(BAD, "axis = [NaN", ht_hair_frame(x, org, d, nan3, 1.0f, &fr));
    ROW(BAD, "ray_org = [NaN", ht_hair_frame(x, nan3, d, axis, 1.0f, &fr));
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
    HtHairFrame mirrored = fr, bad_h = fr, long_axis = fr;
    mirrored.z[2] = -1.0f;
    bad_h.h = 1.5f;
    long_axis.x[0] = 1.01f;

    /* A hit to a point: the frame's checks, then the point's. */
    HtHairPoint pt, zeroed;
    memset(&zeroed, 0, sizeof zeroed);
    pt = zeroed;
    HtHairPoint *odd_point = (HtHairPoint *)((char *)store.p + 4);
    ROW(NUL, "prepared is NULL", ht_hair_point_at_hit(NULL, x, org, d, axis, nan, &pt));
    ROW(NUL, "tangent is NULL", ht_hair_point_at_hit(prep, NULL, org, d, axis, 1.0f, &pt));
    ROW(NUL, "ray_org is NULL", ht_hair_point_at_hit(prep, x, NULL, d, axis, 1.0f, &pt));
    ROW(NUL, "ray_dir is NULL", ht_hair_point_at_hit(prep, x, org, NULL, axis, 1.0f, &pt));
    ROW(NUL, "axis is NULL", ht_hair_point_at_hit(prep, x, org, d, NULL, 1.0f, &pt));
    ROW(NUL, "point is NULL", ht_hair_point_at_hit(prep, x, org, d, axis, 1.0f, NULL));
    ROW(BAD, "tangent is zero", ht_hair_point_at_hit(prep, zero3, org, d, axis, 1.0f, &pt));
    ROW(BAD, "ray_dir is zero", ht_hair_point_at_hit(prep, x, org, zero3, axis, 1.0f, &pt));
    ROW(BAD, "axis = [NaN", ht_hair_point_at_hit(prep, x, org, d, nan3, 1.0f, &pt));
    ROW(BAD, "radius = 0", ht_hair_point_at_hit(prep, x, org, d, axis, 0.0f, &pt));
    ROW(BAD, "radius = NaN", ht_hair_point_at_hit(prep, x, org, d, axis, nan, &pt));
    ROW(BAD, "2 radii away", ht_hair_point_at_hit(prep, x, far_org, d, axis, 1.0f, &pt));
    ROW(BAD, "not aligned to 4", ht_hair_point_at_hit(prep, odd, org, d, axis, 1.0f, &pt));
    ROW(BAD, "not aligned to 16", ht_hair_point_at_hit(prep, x, org, d, axis, 1.0f, odd_point));
    memcpy(store.p[1].opaque, x, sizeof x);
    ROW(BAD, "point and tangent overlap",
        ht_hair_point_at_hit(prep, (const float *)store.p[1].opaque, org, d, axis, 1.0f, &store.p[1]));
    if (memcmp(&pt, &zeroed, sizeof pt) != 0) { ++failed; fprintf(stderr, "FAIL: point written\n"); }
    ROW(OK, NULL, ht_hair_point_at_hit(prep, x, along, x, axis, 1.0f, &pt)); /* end-on */
    ROW(OK, NULL, ht_hair_point_at_hit(prep, x, org, d, axis, 1.0f, &pt));

    /* A point at a frame. */
    HtHairPoint framed;
    float wo_world[3] = {0, 0, 1}, wi_world[3] = {0, 0.6f, 0.8f};
    ROW(NUL, "prepared is NULL", ht_hair_point_init_world(NULL, &fr, nan3, &framed));
    ROW(NUL, "frame is NULL", ht_hair_point_init_world(prep, NULL, wo_world, &framed));
    ROW(NUL, "wo is NULL", ht_hair_point_init_world(prep, &fr, NULL, &framed));
    ROW(NUL, "point is NULL", ht_hair_point_init_world(prep, &fr, wo_world, NULL));
    ROW(BAD, "right-handed orthonormal", ht_hair_point_init_world(prep, &mirrored, wo_world, &framed));
    ROW(BAD, "right-handed orthonormal", ht_hair_point_init_world(prep, &long_axis, wo_world, &framed));
    ROW(BAD, "right-handed orthonormal", ht_hair_point_init_world(prep, &keep, wo_world, &framed));
    ROW(BAD, "h = 1.5", ht_hair_point_init_world(prep, &bad_h, wo_world, &framed));
    ROW(BAD, "wo = [0, 0, 0]", ht_hair_point_init_world(prep, &fr, zero3, &framed));
    ROW(BAD, "wo = [0, 0, 1.01]", ht_hair_point_init_world(prep, &fr, long3, &framed));
    ROW(BAD, "wo = [NaN", ht_hair_point_init_world(prep, &fr, nan3, &framed));
    ROW(BAD, "not aligned to 16", ht_hair_point_init_world(prep, &fr, wo_world, odd_point));
    ROW(BAD, "not aligned to 4", ht_hair_point_init_world(prep, &fr, odd, &framed));
    memcpy(store.p[1].opaque, wo, sizeof wo);
    ROW(BAD, "point and wo overlap",
        ht_hair_point_init_world(prep, &fr, (const float *)store.p[1].opaque, &store.p[1]));
    ROW(BAD, "point and frame overlap",
        ht_hair_point_init_world(prep, (const HtHairFrame *)store.p[1].opaque, wo_world, &store.p[1]));
    ROW(OK, NULL, ht_hair_point_init_world(prep, &fr, wo_world, &framed));
    ROW(OK, NULL, ht_hair_prepared_free(prep)); /* the points keep their own copy */

    /* Light toward a direction. */
    ROW(NUL, "point is NULL", ht_hair_point_eval_world(NULL, nan3, f, &pdf));
    ROW(NUL, "wi is NULL", ht_hair_point_eval_world(&framed, NULL, f, &pdf));
    ROW(NUL, "f_cos is NULL", ht_hair_point_eval_world(&pt, wi_world, NULL, &pdf));
    ROW(NUL, "pdf is NULL", ht_hair_point_eval_world(&pt, wi_world, f, NULL));
    ROW(BAD, "not filled by ht_hair_point_at_hit", ht_hair_point_eval_world(&zeroed, wi_world, f, &pdf));
    ROW(BAD, "not aligned to 16", ht_hair_point_eval_world(odd_point, wi_world, f, &pdf));
    ROW(BAD, "wi (in the point's frame) = [0, 0, 0]", ht_hair_point_eval_world(&framed, zero3, f, &pdf));
    ROW(BAD, "wi (in the point's frame) = [0, 0, 1.01]", ht_hair_point_eval_world(&framed, long3, f, &pdf));
    ROW(BAD, "wi (in the point's frame) = [NaN", ht_hair_point_eval_world(&pt, nan3, f, &pdf));
    ROW(BAD, "not aligned to 4", ht_hair_point_eval_world(&pt, wi_world, odd, &pdf));
    ROW(BAD, "f_cos and pdf overlap", ht_hair_point_eval_world(&pt, wi_world, f, f + 1));
    ROW(BAD, "f_cos and wi overlap", ht_hair_point_eval_world(&pt, f + 1, f, &pdf));
    ROW(BAD, "f_cos and point overlap",
        ht_hair_point_eval_world(&framed, wi_world, (float *)framed.opaque, &pdf));
    UNTOUCHED(f, 8);
    ROW(OK, NULL, ht_hair_point_eval_world(&framed, wi_world, f, &pdf));

    /* A sampled direction. */
    float ws[3] = {7, 7, 7}, fc[3] = {7, 7, 7};
    for (int k = 0; k < 8; ++k) f[k] = 7.0f;
    ROW(NUL, "point is NULL", ht_hair_point_sample_world(NULL, u_nan, ws, fc, f, &pdf));
    ROW(NUL, "u is NULL", ht_hair_point_sample_world(&pt, NULL, ws, fc, f, &pdf));
    ROW(NUL, "wi is NULL", ht_hair_point_sample_world(&pt, u, NULL, fc, f, &pdf));
    ROW(NUL, "f_cos is NULL", ht_hair_point_sample_world(&pt, u, ws, NULL, f, &pdf));
    ROW(NUL, "weight is NULL", ht_hair_point_sample_world(&pt, u, ws, fc, NULL, &pdf));
    ROW(NUL, "pdf is NULL", ht_hair_point_sample_world(&pt, u, ws, fc, f, NULL));
    ROW(BAD, "not filled by ht_hair_point_at_hit", ht_hair_point_sample_world(&zeroed, u, ws, fc, f, &pdf));
    ROW(BAD, "u[0] = 1", ht_hair_point_sample_world(&pt, u_one, ws, fc, f, &pdf));
    ROW(BAD, "u[1] = -0.1", ht_hair_point_sample_world(&pt, u_neg, ws, fc, f, &pdf));
    ROW(BAD, "u[2] = NaN", ht_hair_point_sample_world(&framed, u_nan, ws, fc, f, &pdf));
    ROW(BAD, "not aligned to 4", ht_hair_point_sample_world(&pt, u, odd, fc, f, &pdf));
    ROW(BAD, "wi and f_cos overlap", ht_hair_point_sample_world(&pt, u, f, f + 2, fc, &pdf));
    ROW(BAD, "f_cos and weight overlap", ht_hair_point_sample_world(&pt, u, ws, f, f + 1, &pdf));
    ROW(BAD, "weight and pdf overlap", ht_hair_point_sample_world(&framed, u, ws, fc, f, f + 2));
    ROW(BAD, "wi and u overlap", ht_hair_point_sample_world(&pt, f, f + 1, fc, ws, &pdf));
    UNTOUCHED(f, 8);
    UNTOUCHED(ws, 3);
    UNTOUCHED(fc, 3);
    ROW(OK, NULL, ht_hair_point_sample_world(&framed, u, ws, fc, f, &pdf));

    /* Light across the fibre. */
    float fa[3 * HT_ACROSS], pa[HT_ACROSS];
    for (size_t k = 0; k < 3 * HT_ACROSS; ++k) fa[k] = 7.0f;
    for (size_t k = 0; k < HT_ACROSS; ++k) pa[k] = 7.0f;
    ROW(NUL, "point is NULL", ht_hair_point_eval_across_world(NULL, wi_world, fa, pa));
    ROW(NUL, "wi is NULL", ht_hair_point_eval_across_world(&framed, NULL, fa, pa));
    ROW(NUL, "f_cos is NULL", ht_hair_point_eval_across_world(&framed, wi_world, NULL, pa));
    ROW(NUL, "pdf is NULL", ht_hair_point_eval_across_world(&framed, wi_world, fa, NULL));
    ROW(BAD, "not filled by ht_hair_point_at_hit", ht_hair_point_eval_across_world(&zeroed, wi_world, fa, pa));
    ROW(BAD, "not aligned to 16", ht_hair_point_eval_across_world(odd_point, wi_world, fa, pa));
    ROW(BAD, "wi (in the point's frame) = [0, 0, 0]",
        ht_hair_point_eval_across_world(&framed, zero3, fa, pa));
    ROW(BAD, "f_cos and pdf overlap", ht_hair_point_eval_across_world(&framed, wi_world, fa, fa + 5));
    ROW(BAD, "f_cos and point overlap",
        ht_hair_point_eval_across_world(&framed, wi_world, (float *)framed.opaque, pa));
    ROW(BAD, "pdf and point overlap",
        ht_hair_point_eval_across_world(&pt, wi_world, fa, (float *)pt.opaque + 4));
    UNTOUCHED(fa, 3 * HT_ACROSS);
    UNTOUCHED(pa, HT_ACROSS);
    ROW(OK, NULL, ht_hair_point_eval_across_world(&framed, wi_world, fa, pa));

    /* The Huang model: its parameters, a point's section, jitter and field, its points. */
    HtHuangParams hp = ht_huang_params_default(), flat = hp, oval = hp, nan_aspect = hp;
    flat.aspect = 0.0f;
    oval.aspect = 1.5f;
    nan_aspect.aspect = nan;
    HtHuangPrepared *huang = NULL, *kept = (HtHuangPrepared *)&store;
    ROW(NUL, "params is NULL", ht_huang_prepare(NULL, &huang));
    ROW(NUL, "out is NULL", ht_huang_prepare(&hp, NULL));
    ROW(BAD, "aspect = 0: must be in [0.05, 1]", ht_huang_prepare(&flat, &kept));
    ROW(BAD, "aspect = 1.5", ht_huang_prepare(&oval, &kept));
    ROW(BAD, "aspect = NaN", ht_huang_prepare(&nan_aspect, &kept));
    if (kept != (HtHuangPrepared *)&store) { ++failed; fprintf(stderr, "FAIL: huang out written\n"); }
    ROW(OK, NULL, ht_huang_prepared_free(NULL));
    ROW(OK, NULL, ht_huang_prepare(&hp, &huang));
    static HtHuangPoint hpt, hzero;
    float up[3] = {0, 1, 0}, jit[2] = {0.5f, 0.5f}, jit_one[2] = {0.5f, 1.0f};
    ROW(NUL, "prepared is NULL", ht_huang_point_at_hit(NULL, x, org, d, axis, nan, up, jit, 0, &hpt));
    ROW(NUL, "major is NULL", ht_huang_point_at_hit(huang, x, org, d, axis, 1.0f, NULL, jit, 0, &hpt));
    ROW(NUL, "jitter is NULL", ht_huang_point_at_hit(huang, x, org, d, axis, 1.0f, up, NULL, 9, &hpt));
    ROW(NUL, "point is NULL", ht_huang_point_at_hit(huang, x, org, d, axis, 1.0f, up, jit, 0, NULL));
    ROW(BAD, "radius = 0", ht_huang_point_at_hit(huang, x, org, d, axis, 0.0f, up, jit, 0, &hpt));
    ROW(BAD, "2 radii away", ht_huang_point_at_hit(huang, x, far_org, d, axis, 1.0f, up, jit, 0, &hpt));
    ROW(BAD, "major = [1, 0, 0]: lies along the fibre", ht_huang_point_at_hit(huang, x, org, d, axis, 1.0f, x, jit, 0, &hpt));
    ROW(BAD, "major = [0, 0, 0]: lies along", ht_huang_point_at_hit(huang, x, org, d, axis, 1.0f, zero3, jit, 0, &hpt));
    ROW(BAD, "major = [NaN, 0, 1]: must be finite", ht_huang_point_at_hit(huang, x, org, d, axis, 1.0f, nan3, jit, 0, &hpt));
    ROW(BAD, "jitter[1] = 1: must be in [0, 1)", ht_huang_point_at_hit(huang, x, org, d, axis, 1.0f, up, jit_one, 0, &hpt));
    ROW(BAD, "field = 3: must be HT_HUANG_NEAR (0), HT_HUANG_FAR (1) or HT_HUANG_FAR_LIT (2)",
        ht_huang_point_at_hit(huang, x, org, d, axis, 1.0f, up, jit, 3, &hpt));
    ROW(BAD, "not aligned to 4", ht_huang_point_at_hit(huang, x, org, d, axis, 1.0f, odd, jit, 0, &hpt));
    ROW(BAD, "point and major overlap",
        ht_huang_point_at_hit(huang, x, org, d, axis, 1.0f, (const float *)hpt.opaque, jit, 0, &hpt));
    ROW(NUL, "frame is NULL", ht_huang_point_init_world(huang, NULL, wo_world, up, jit, 0, &hpt));
    ROW(BAD, "h = 1.5", ht_huang_point_init_world(huang, &bad_h, wo_world, up, jit, 0, &hpt));
    ROW(BAD, "wo = [0, 0, 1.01]", ht_huang_point_init_world(huang, &fr, long3, up, jit, 0, &hpt));
    ROW(BAD, "major = [1, 0, 0]: lies along the fibre", ht_huang_point_init_world(huang, &fr, wo_world, x, jit, 1, &hpt));
    if (memcmp(&hpt, &hzero, sizeof hpt) != 0) { ++failed; fprintf(stderr, "FAIL: huang point written\n"); }
    ROW(BAD, "not filled by ht_huang_point_at_hit", ht_huang_point_eval_world(&hzero, wi_world, f, &pdf));
    ROW(OK, NULL, ht_huang_point_at_hit(huang, x, org, d, axis, 1.0f, up, jit, HT_HUANG_FAR, &hpt));
    ROW(OK, NULL, ht_huang_prepared_free(huang)); /* the point keeps its own copy */
    for (int k = 0; k < 8; ++k) f[k] = 7.0f;
    ROW(NUL, "wi is NULL", ht_huang_point_eval_world(&hpt, NULL, f, &pdf));
    ROW(BAD, "wi (in the point's frame) = [0, 0, 0]", ht_huang_point_eval_world(&hpt, zero3, f, &pdf));
    ROW(BAD, "f_cos and pdf overlap", ht_huang_point_eval_world(&hpt, wi_world, f, f + 1));
    ROW(BAD, "u[0] = 1", ht_huang_point_sample_world(&hpt, u_one, ws, fc, f, &pdf));
    ROW(BAD, "wi and f_cos overlap", ht_huang_point_sample_world(&hpt, u, f, f + 2, fc, &pdf));
    UNTOUCHED(f, 8);
    ROW(OK, NULL, ht_huang_point_eval_world(&hpt, wi_world, f, &pdf));
    ROW(OK, NULL, ht_huang_point_sample_world(&hpt, u, ws, fc, f, &pdf));

    printf("checks %d failed %d\n", checks, failed);
    return failed ? 1 : 0;
}
