/* The BSDF through every C entry point, for inputs the Rust test writes to the file named
 * by argv[1], one case a line as 17 hexadecimal float bit patterns: sigma_a[3], eta,
 * beta_m, beta_n, alpha, h, wo[3], wi[3], u[3]. Prints one line a case with the bit
 * patterns of: ht_hair_point_eval (f, pdf), ht_hair_point_pdf, ht_hair_point_sample (wi,
 * f, pdf), ht_hair_eval, ht_hair_sample, ht_hair_points_eval, ht_hair_points_sample,
 * ht_hair_eval_batch (one material per case), ht_hair_point_eval_cos (f_cos, pdf) and
 * ht_hair_point_sample_cos (wi, weight, pdf), so that the test compares them with Rust. */
#include "hairtrace.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct Case {
    HtHairParams params;
    float h, wo[3], wi[3], u[3];
} Case;

static float from_bits(uint32_t b) {
    float f;
    memcpy(&f, &b, sizeof f);
    return f;
}

static void put(const float *v, int n) {
    for (int k = 0; k < n; ++k) {
        uint32_t b;
        memcpy(&b, &v[k], sizeof b);
        printf(" %08x", (unsigned)b);
    }
}

static void ok(HtStatus s, const char *what, size_t i) {
    if (s != HT_OK) {
        const char *why = ht_last_error();
        fprintf(stderr, "case %zu: %s: %s\n", i, what, why);
        exit(1);
    }
}

int main(int argc, char **argv) {
    FILE *in = argc > 1 ? fopen(argv[1], "r") : NULL;
    if (in == NULL) {
        fprintf(stderr, "usage: bsdf_bits INPUT\n");
        return 1;
    }
    size_t n = 0, cap = 0;
    Case *cases = NULL;
    for (;;) {
        uint32_t w[17];
        int got = 0;
        for (int k = 0; k < 17; ++k) got += fscanf(in, "%x", &w[k]);
        if (got != 17) break;
        if (n == cap) {
            cap = cap ? 2 * cap : 256;
            cases = (Case *)realloc(cases, cap * sizeof *cases);
        }
        Case *c = &cases[n++];
        float v[17];
        for (int k = 0; k < 17; ++k) v[k] = from_bits(w[k]);
        memcpy(c->params.sigma_a, v, 3 * sizeof(float));
        c->params.eta = v[3];
        c->params.beta_m = v[4];
        c->params.beta_n = v[5];
        c->params.alpha = v[6];
        c->h = v[7];
        memcpy(c->wo, v + 8, sizeof c->wo);
        memcpy(c->wi, v + 11, sizeof c->wi);
        memcpy(c->u, v + 14, sizeof c->u);
    }
    fclose(in);

    /* malloc aligns to 16 on 64-bit platforms, as HtHairPoint needs. */
    HtHairPoint *points = (HtHairPoint *)malloc(n * sizeof *points);
    float *wi = (float *)malloc(n * 3 * sizeof(float)), *u = (float *)malloc(n * 3 * sizeof(float));
    float *bf = (float *)malloc(n * 3 * sizeof(float)), *bp = (float *)malloc(n * sizeof(float));
    float *sw = (float *)malloc(n * 3 * sizeof(float)), *sf = (float *)malloc(n * 3 * sizeof(float));
    float *sp = (float *)malloc(n * sizeof(float));
    for (size_t i = 0; i < n; ++i) {
        HtHairPrepared *prepared;
        ok(ht_hair_prepare(&cases[i].params, &prepared), "prepare", i);
        ok(ht_hair_point_init(prepared, cases[i].h, cases[i].wo, &points[i]), "init", i);
        ok(ht_hair_prepared_free(prepared), "free", i); /* the point outlives it */
        memcpy(wi + 3 * i, cases[i].wi, sizeof cases[i].wi);
        memcpy(u + 3 * i, cases[i].u, sizeof cases[i].u);
    }
    ok(ht_hair_points_eval(points, n, wi, bf, bp), "points_eval", 0);
    ok(ht_hair_points_sample(points, n, u, sw, sf, sp), "points_sample", 0);

    for (size_t i = 0; i < n; ++i) {
        const Case *c = &cases[i];
        float f[3], pdf, pdf_only, s[7], e[4], t[7], b[4], ec[4], sc[7];
        ok(ht_hair_point_eval(&points[i], c->wi, f, &pdf), "point_eval", i);
        ok(ht_hair_point_pdf(&points[i], c->wi, &pdf_only), "point_pdf", i);
        ok(ht_hair_point_sample(&points[i], c->u, s, s + 3, s + 6), "point_sample", i);
        ok(ht_hair_eval(&c->params, c->h, c->wo, c->wi, e, e + 3), "eval", i);
        ok(ht_hair_sample(&c->params, c->h, c->wo, c->u, t, t + 3, t + 6), "sample", i);
        ok(ht_hair_eval_batch(&c->params, 1, &c->h, c->wo, c->wi, b, b + 3), "eval_batch", i);
        ok(ht_hair_point_eval_cos(&points[i], c->wi, ec, ec + 3), "point_eval_cos", i);
        ok(ht_hair_point_sample_cos(&points[i], c->u, sc, sc + 3, sc + 6), "point_sample_cos", i);
        put(f, 3);
        put(&pdf, 1);
        put(&pdf_only, 1);
        put(s, 7);
        put(e, 4);
        put(t, 7);
        put(bf + 3 * i, 3);
        put(bp + i, 1);
        put(sw + 3 * i, 3);
        put(sf + 3 * i, 3);
        put(sp + i, 1);
        put(b, 4);
        put(ec, 4);
        put(sc, 7);
        printf("\n");
    }
    free(points);
    free(wi);
    free(u);
    free(bf);
    free(bp);
    free(sw);
    free(sf);
    free(sp);
    free(cases);
    return 0;
}
