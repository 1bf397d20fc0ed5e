/* The Chiang 2016 hair model written the direct way, in float with libm: longitudinal Mp
 * of d'Eon 2011 (with I0 from the Abramowitz-Stegun fits), azimuthal Np a logistic
 * trimmed to [-pi, pi], attenuation Ap from Fresnel and absorption for R, TT, TRT and a
 * residual lobe, cuticle tilt alpha. Everything that depends on (h, wo, wi) is computed
 * per call, as a renderer's f() does; only the per-material constants are prepared. */
#include "port.h"

#include <math.h>

#define PI_F 3.14159265358979f

PortHair port_prepare(const float sigma_a[3], float eta, float beta_m, float beta_n,
                      float alpha_deg) {
    PortHair m;
    for (int c = 0; c < 3; ++c) m.sigma_a[c] = sigma_a[c];
    m.eta = eta;
    float r = 0.726f * beta_m + 0.812f * beta_m * beta_m + 3.7f * powf(beta_m, 20.0f);
    m.v[0] = r * r;
    m.v[1] = 0.25f * m.v[0];
    m.v[2] = 4.0f * m.v[0];
    m.v[3] = m.v[2];
    float q = 0.265f * beta_n + 1.194f * beta_n * beta_n + 5.372f * powf(beta_n, 22.0f);
    m.s = sqrtf(PI_F / 8.0f) * q;
    float alpha = alpha_deg * PI_F / 180.0f;
    const float shift[3] = {-2.0f * alpha, alpha, 4.0f * alpha};
    for (int p = 0; p < 3; ++p) {
        m.sin_tilt[p] = sinf(shift[p]);
        m.cos_tilt[p] = cosf(shift[p]);
    }
    return m;
}

/* e^-x I0(x) for x >= 0 (Abramowitz and Stegun 9.8.1 and 9.8.2). */
static float scaled_i0(float x) {
    if (x < 3.75f) {
        float t = x / 3.75f;
        t *= t;
        float i0 = 1.0f + t * (3.5156229f + t * (3.0899424f + t * (1.2067492f +
                   t * (0.2659732f + t * (0.0360768f + t * 0.0045813f)))));
        return expf(-x) * i0;
    }
    float t = 3.75f / x;
    float p = 0.39894228f + t * (0.01328592f + t * (0.00225319f + t * (-0.00157565f +
              t * (0.00916281f + t * (-0.02057706f + t * (0.02635537f +
              t * (-0.01647633f + t * 0.00392377f)))))));
    return p / sqrtf(x);
}

/* d'Eon's Mp = exp(-sin ti sin to / v) I0(cos ti cos to / v) / (2 v sinh(1/v)), with the
 * exponentials combined so that small v does not overflow. */
static float mp(float sin_ti, float cos_ti, float sin_to, float cos_to, float v) {
    float a = cos_ti * cos_to / v;
    float b = sin_ti * sin_to / v;
    float norm = 1.0f / (v * (1.0f - expf(-2.0f / v)));
    return norm * expf(a - b - 1.0f / v) * scaled_i0(a);
}

static float logistic(float x, float s) {
    x = fabsf(x);
    float e = expf(-x / s);
    return e / (s * (1.0f + e) * (1.0f + e));
}

static float logistic_cdf(float x, float s) { return 1.0f / (1.0f + expf(-x / s)); }

static float np(float phi, int p, float gamma_o, float gamma_t, float s) {
    float dphi = phi - (2.0f * p * gamma_t - 2.0f * gamma_o + p * PI_F);
    while (dphi > PI_F) dphi -= 2.0f * PI_F;
    while (dphi < -PI_F) dphi += 2.0f * PI_F;
    return logistic(dphi, s) / (logistic_cdf(PI_F, s) - logistic_cdf(-PI_F, s));
}

static float fresnel(float cos_i, float eta) {
    float sin_t = sqrtf(fmaxf(0.0f, 1.0f - cos_i * cos_i)) / eta;
    float cos_t = sqrtf(fmaxf(0.0f, 1.0f - sin_t * sin_t));
    float par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5f * (par * par + perp * perp);
}

void port_eval(const PortHair *m, float h, const float wo[3], const float wi[3], float f[3],
               float *pdf) {
    float sin_to = wo[0], cos_to = sqrtf(fmaxf(0.0f, 1.0f - sin_to * sin_to));
    float sin_ti = wi[0], cos_ti = sqrtf(fmaxf(0.0f, 1.0f - sin_ti * sin_ti));
    float phi = atan2f(wi[2], wi[1]) - atan2f(wo[2], wo[1]);

    float sin_tt = sin_to / m->eta, cos_tt = sqrtf(fmaxf(0.0f, 1.0f - sin_tt * sin_tt));
    float etap = sqrtf(m->eta * m->eta - sin_to * sin_to) / cos_to;
    float sin_gt = h / etap, cos_gt = sqrtf(fmaxf(0.0f, 1.0f - sin_gt * sin_gt));
    float gamma_o = asinf(h), gamma_t = asinf(sin_gt);

    /* Attenuation of each lobe and channel. */
    float fr = fresnel(cos_to * sqrtf(fmaxf(0.0f, 1.0f - h * h)), m->eta);
    float ap[4][3];
    for (int c = 0; c < 3; ++c) {
        float t = expf(-m->sigma_a[c] * (2.0f * cos_gt / cos_tt));
        ap[0][c] = fr;
        ap[1][c] = (1.0f - fr) * (1.0f - fr) * t;
        ap[2][c] = ap[1][c] * t * fr;
        float denom = 1.0f - t * fr;
        ap[3][c] = denom > 0.0f ? ap[2][c] * fr * t / denom : 0.0f;
    }
    float mean[4], total = 0.0f;
    for (int p = 0; p < 4; ++p) {
        mean[p] = (ap[p][0] + ap[p][1] + ap[p][2]) / 3.0f;
        total += mean[p];
    }

    float sum[3] = {0.0f, 0.0f, 0.0f}, density = 0.0f;
    for (int p = 0; p < 4; ++p) {
        float w;
        if (p < 3) {
            float s_op = sin_to * m->cos_tilt[p] + cos_to * m->sin_tilt[p];
            float c_op = fabsf(cos_to * m->cos_tilt[p] - sin_to * m->sin_tilt[p]);
            w = mp(sin_ti, cos_ti, s_op, c_op, m->v[p]) * np(phi, p, gamma_o, gamma_t, m->s);
        } else {
            w = mp(sin_ti, cos_ti, sin_to, cos_to, m->v[3]) / (2.0f * PI_F);
        }
        for (int c = 0; c < 3; ++c) sum[c] += w * ap[p][c];
        density += w * mean[p] / total;
    }
    float cos_wi = fabsf(wi[2]);
    float inv = cos_wi > 0.0f ? 1.0f / cos_wi : 1.0f;
    for (int c = 0; c < 3; ++c) f[c] = sum[c] * inv;
    *pdf = density;
}
