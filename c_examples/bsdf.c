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

    /* How a renderer shades a hair hit: the material prepared once, then per path vertex
     * one call from its own hit (the curve's tangent, the ray, the axis point at the hit's
     * curve parameter and the radius there) to a point with its frame, in the host's own
     * storage, shared by light evaluation and BSDF sampling in world space. The fibre runs
     * along +x, the ray comes down -z passing the axis half a radius along +y: the worked
     * example of docs/conventions.md, with its R highlight toward the light. */
    HtHairPrepared *brown;
    if (check(ht_hair_prepare(&hair, &brown), "ht_hair_prepare")) return 1;
    const float tangent[3] = {2.0f, 0.0f, 0.0f}, org[3] = {0.0f, 0.5f, 5.0f};
    const float dir[3] = {0.0f, 0.0f, -1.0f}, axis[3] = {0.0f, 0.0f, 0.0f};
    HtHairPoint point; /* HT_HAIR_POINT_SIZE bytes, 16-byte aligned by its type */
    if (check(ht_hair_point_at_hit(brown, tangent, org, dir, axis, 1.0f, &point), "at_hit"))
        return 1;
    const float to_light[3] = {0.0f, 0.8660254f, 0.5f};
    float f_cos[3], pdf;
    if (check(ht_hair_point_eval_world(&point, to_light, f_cos, &pdf), "eval")) return 1;
    printf("point %.9g %.9g %.9g pdf %.9g\n", f_cos[0], f_cos[1], f_cos[2], pdf);
    const float u0[3] = {0.25f, 0.5f, 0.5f};
    float ws[3], weight[3];
    if (check(ht_hair_point_sample_world(&point, u0, ws, f_cos, weight, &pdf), "sample"))
        return 1;
    printf("sampled world %.6f %.6f %.6f pdf %.6g\n", ws[0], ws[1], ws[2], pdf);

    /* The frame alone (its h, to check a host's own), and a point at a frame: here the
     * local frame, whose world directions are the local ones. */
    HtHairFrame frame;
    if (check(ht_hair_frame(tangent, org, dir, axis, 1.0f, &frame), "ht_hair_frame")) return 1;
    printf("frame h %.9g\n", frame.h);
    const HtHairFrame local = {{1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, 0.5f};
    const float wo[3] = {0.0f, 0.0f, 1.0f};
    if (check(ht_hair_point_init_world(brown, &local, wo, &point), "init")) return 1;
    ht_hair_prepared_free(brown); /* the points keep what they need */
    if (check(ht_hair_point_eval_world(&point, to_light, f_cos, &pdf), "eval")) return 1;
    printf("local %.9g %.9g %.9g pdf %.9g\n", f_cos[0], f_cos[1], f_cos[2], pdf);

    /* White furnace by importance sampling: with no absorption every sample weight
     * f |cos| / pdf is 1, so the mean is 1. */
    HtHairParams white = hair;
    white.sigma_a[0] = white.sigma_a[1] = white.sigma_a[2] = 0.0f;
    HtHairPrepared *prepared_white;
    if (check(ht_hair_prepare(&white, &prepared_white), "ht_hair_prepare")) return 1;
    uint32_t rng = 12345u;
    double sum = 0.0;
    const int n = 10000;
    for (int i = 0; i < n; i++) {
        float u[3] = {next_uniform(&rng), next_uniform(&rng), next_uniform(&rng)};
        HtHairFrame at = local;
        at.h = 2.0f * next_uniform(&rng) - 1.0f;
        if (check(ht_hair_point_init_world(prepared_white, &at, wo, &point), "init")) return 1;
        if (check(ht_hair_point_sample_world(&point, u, ws, f_cos, weight, &pdf), "sample"))
            return 1;
        sum += weight[1]; /* 0 when no direction was sampled */
    }
    ht_hair_prepared_free(prepared_white);
    printf("furnace %.6f\n", sum / n);

    /* Errors come back as statuses with a message, never as a crash. */
    HtStatus s = ht_hair_point_eval_world(&point, NULL, f_cos, &pdf);
    printf("null %s\n", ht_status_str((int32_t)s));
    HtHairParams rough = hair;
    rough.beta_m = 2.0f;
    HtHairPrepared *never;
    s = ht_hair_prepare(&rough, &never);
    printf("invalid %s: %s\n", ht_status_str((int32_t)s), ht_last_error());

    float sigma[3];
    const float color[3] = {0.8f, 0.5f, 0.3f};
    if (check(ht_hair_sigma_a_from_color(color, 0.3f, sigma), "ht_hair_sigma_a_from_color")) return 1;
    printf("from_color %.6g %.6g %.6g\n", sigma[0], sigma[1], sigma[2]);
    if (check(ht_hair_sigma_a_from_melanin(8.0f, 0.0f, sigma), "ht_hair_sigma_a_from_melanin")) return 1;
    printf("from_melanin %.6g %.6g %.6g\n", sigma[0], sigma[1], sigma[2]);
    return 0;
}
