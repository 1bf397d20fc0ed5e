/* Evaluates and samples the default (brown) hair through the C header only.
 * Compiles as C99 and as C++ with -Wall -Wextra -Werror; tests/c_abi/c_examples.rs runs it
 * and checks what it prints. */
#include "hairtrace.h"

#include <math.h>
#include <stdio.h>

static int check(HtStatus s, const char *what) {
    if (s != HT_OK) {
        fprintf(stderr, "%s failed: %s: %s\n", what, ht_status_str((int32_t)s), ht_last_error());
        return 1;
    }
    return 0;
}

/* A small deterministic generator for the sample numbers (xorshift32, in [0, 1)). */
static float next_uniform(uint32_t *state) {
    *state ^= *state << 13;
    *state ^= *state >> 17;
    *state ^= *state << 5;
    return (float)(*state >> 8) * (1.0f / 16777216.0f);
}

int main(void) {
    if (ht_abi_version() != HT_ABI_VERSION) {
        fprintf(stderr, "header ABI %d, library ABI %u\n", HT_ABI_VERSION, ht_abi_version());
        return 1;
    }
    printf("version %s abi %u\n", ht_version(), ht_abi_version());

    HtHairParams hair = ht_hair_params_default();
    printf("sigma_a %.9g %.9g %.9g\n", hair.sigma_a[0], hair.sigma_a[1], hair.sigma_a[2]);

    /* Viewer along +z, light from above: the R highlight of the worked example in
       docs/conventions.md. */
    const float h = 0.5f;
    const float wo[3] = {0.0f, 0.0f, 1.0f};
    const float wi[3] = {0.0f, 0.8660254f, 0.5f};
    float f[3], pdf;
    if (check(ht_hair_eval(&hair, h, wo, wi, f, &pdf), "ht_hair_eval")) return 1;
    printf("eval %.9g %.9g %.9g pdf %.9g\n", f[0], f[1], f[2], pdf);

    /* Batch evaluation of the same pair twice. */
    float hb[2] = {h, h}, wob[6], wib[6], fb[6], pdfb[2];
    for (int i = 0; i < 6; i++) {
        wob[i] = wo[i % 3];
        wib[i] = wi[i % 3];
    }
    if (check(ht_hair_eval_batch(&hair, 2, hb, wob, wib, fb, pdfb), "ht_hair_eval_batch")) return 1;
    printf("batch %.9g %.9g %.9g pdf %.9g\n", fb[3], fb[4], fb[5], pdfb[1]);

    /* How a renderer shades a hair hit: the frame and h from its own ray and curve
     * (never from a ribbon's v coordinate, which runs the other way), the material
     * prepared once, and a point per path vertex, in the host's own storage, shared by
     * light evaluation and BSDF sampling. Same fibre and ray as above, in world space. */
    const float tangent[3] = {2.0f, 0.0f, 0.0f}, org[3] = {0.0f, 0.5f, 5.0f};
    const float dir[3] = {0.0f, 0.0f, -1.0f}, axis[3] = {0.0f, 0.0f, 0.0f};
    HtHairFrame frame;
    if (check(ht_hair_frame(tangent, org, dir, axis, 1.0f, &frame), "ht_hair_frame")) return 1;
    const float to_viewer[3] = {-dir[0], -dir[1], -dir[2]};
    const float to_light[3] = {0.0f, 0.8660254f, 0.5f};
    float wo_local[3], wi_local[3];
    if (check(ht_hair_frame_to_local(&frame, to_viewer, wo_local), "to_local")) return 1;
    if (check(ht_hair_frame_to_local(&frame, to_light, wi_local), "to_local")) return 1;
    printf("frame h %.9g\n", frame.h);
    HtHairPrepared *brown;
    if (check(ht_hair_prepare(&hair, &brown), "ht_hair_prepare")) return 1;
    HtHairPoint point; /* HT_HAIR_POINT_SIZE bytes, 16-byte aligned by its type */
    HtStatus init = ht_hair_point_init(brown, frame.h, wo_local, &point);
    ht_hair_prepared_free(brown); /* the point keeps what it needs */
    if (check(init, "ht_hair_point_init")) return 1;
    if (check(ht_hair_point_eval(&point, wi_local, f, &pdf), "ht_hair_point_eval")) return 1;
    printf("point %.9g %.9g %.9g pdf %.9g\n", f[0], f[1], f[2], pdf);
    const float u0[3] = {0.25f, 0.5f, 0.5f};
    float ws[3], wworld[3];
    if (check(ht_hair_point_sample(&point, u0, ws, f, &pdf), "ht_hair_point_sample")) return 1;
    if (check(ht_hair_frame_to_world(&frame, ws, wworld), "to_world")) return 1;
    printf("sampled world %.6f %.6f %.6f pdf %.6g\n", wworld[0], wworld[1], wworld[2], pdf);

    /* White furnace by importance sampling: with no absorption every sample weight
     * f |wi.z| / pdf is 1, so the mean is 1. */
    HtHairParams white = hair;
    white.sigma_a[0] = white.sigma_a[1] = white.sigma_a[2] = 0.0f;
    uint32_t rng = 12345u;
    double sum = 0.0;
    const int n = 10000;
    for (int i = 0; i < n; i++) {
        float u[3] = {next_uniform(&rng), next_uniform(&rng), next_uniform(&rng)};
        float hs = 2.0f * next_uniform(&rng) - 1.0f;
        float ws[3], fs[3], ps;
        if (check(ht_hair_sample(&white, hs, wo, u, ws, fs, &ps), "ht_hair_sample")) return 1;
        if (ps > 0.0f) sum += fs[1] * fabsf(ws[2]) / ps;
    }
    printf("furnace %.6f\n", sum / n);

    /* Errors come back as statuses with a message, never as a crash. */
    HtStatus s = ht_hair_eval(&hair, h, NULL, wi, f, &pdf);
    printf("null %s\n", ht_status_str((int32_t)s));
    HtHairParams rough = hair;
    rough.beta_m = 2.0f;
    s = ht_hair_eval(&rough, h, wo, wi, f, &pdf);
    printf("invalid %s: %s\n", ht_status_str((int32_t)s), ht_last_error());

    float sigma[3];
    const float color[3] = {0.8f, 0.5f, 0.3f};
    if (check(ht_hair_sigma_a_from_color(color, 0.3f, sigma), "ht_hair_sigma_a_from_color")) return 1;
    printf("from_color %.6g %.6g %.6g\n", sigma[0], sigma[1], sigma[2]);
    if (check(ht_hair_sigma_a_from_melanin(8.0f, 0.0f, sigma), "ht_hair_sigma_a_from_melanin")) return 1;
    printf("from_melanin %.6g %.6g %.6g\n", sigma[0], sigma[1], sigma[2]);
    return 0;
}
