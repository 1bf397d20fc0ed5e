/* The BSDF through every per-direction C entry point, for inputs the Rust test writes to
 * the file named by argv[1], one case a line as 17 hexadecimal float bit patterns:
 * sigma_a[3], eta, beta_m, beta_n, alpha, h, wo[3], wi[3], u[3]. Each point is filled at
 * the local frame (axes x, y, z), where world directions are the local ones. Prints one
 * line a case with the bit patterns of: ht_hair_point_eval_world (f_cos, pdf),
 * ht_hair_point_sample_world (wi, f_cos, weight, pdf) and ht_hair_point_eval_across_world
 * (f_cos and pdf of each lane), so that the test compares them with Rust. */
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

    for (size_t i = 0; i < n; ++i) {
        const Case *c = &cases[i];
        const HtHairFrame local = {{1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, c->h};
        HtHairPrepared *prepared;
        HtHairPoint point;
        float e[4], s[10], across[4 * HT_ACROSS];
        ok(ht_hair_prepare(&c->params, &prepared), "prepare", i);
        ok(ht_hair_point_init_world(prepared, &local, c->wo, &point), "init", i);
        ok(ht_hair_prepared_free(prepared), "free", i); /* the point outlives it */
        ok(ht_hair_point_eval_world(&point, c->wi, e, e + 3), "eval", i);
        ok(ht_hair_point_sample_world(&point, c->u, s, s + 3, s + 6, s + 9), "sample", i);
        ok(ht_hair_point_eval_across_world(&point, c->wi, across, across + 3 * HT_ACROSS),
           "across", i);
        put(e, 4);
        put(s, 10);
        put(across, 4 * HT_ACROSS);
        printf("\n");
    }
    free(cases);
    return 0;
}
