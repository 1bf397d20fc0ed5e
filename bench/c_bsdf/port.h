/* A plain float port of the Chiang et al. 2016 hair BSDF with libm: the comparison point
 * of bench/c_bsdf (what a host would write from the paper without hairtrace). Same frame,
 * parameters and f convention as hairtrace (docs/conventions.md). */
#ifndef HT_BENCH_PORT_H
#define HT_BENCH_PORT_H

typedef struct PortHair {
    float sigma_a[3], eta;
    /* Longitudinal variance of R, TT, TRT and the residual; logistic scale. */
    float v[4], s;
    /* sin and cos of the cuticle shift of theta_o for R, TT, TRT: -2 alpha, alpha, 4 alpha. */
    float sin_tilt[3], cos_tilt[3];
} PortHair;

/* The per-material constants from sigma_a, eta, beta_m, beta_n, alpha (degrees). */
PortHair port_prepare(const float sigma_a[3], float eta, float beta_m, float beta_n,
                      float alpha_deg);

/* f (RGB, includes 1/|wi.z|) and pdf for unit wo, wi in the local frame at offset h. */
void port_eval(const PortHair *m, float h, const float wo[3], const float wi[3], float f[3],
               float *pdf);

#endif
