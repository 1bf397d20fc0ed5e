/* Renders a small curly fur ball, groomed here in C, around a white sphere, through the C
 * header only, and writes it to the EXR path given as the first argument.
 * Compiles as C99 and as C++ with -Wall -Wextra -Werror; tests/c_abi/c_examples.rs runs it and
 * checks what it prints and the image it writes. */
#include "hairtrace.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STRANDS 500
#define SEGMENTS 16
#define POINTS_PER_STRAND (SEGMENTS + 1)
#define WIDTH 64
#define HEIGHT 48
/* A window of the frame, rendered again on its own. */
#define CROP_X0 20
#define CROP_Y0 10
#define CROP_W 24
#define CROP_H 20

static const float PI = 3.14159265f;

static int check(HtStatus s, const char *what) {
    if (s != HT_OK) {
        fprintf(stderr, "%s failed: %s: %s\n", what, ht_status_str((int32_t)s), ht_last_error());
        return 1;
    }
    return 0;
}

static void cross(const float a[3], const float b[3], float out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void normalize(float v[3]) {
    float len = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    v[0] /= len;
    v[1] /= len;
    v[2] /= len;
}

/* Curly strands on the unit sphere: roots on a Fibonacci lattice, each strand a helix of
 * two turns around its outward normal, radius tapering from root to tip. Writes
 * STRANDS * POINTS_PER_STRAND points (xyz) and radii. */
static void groom(float *points, float *radii) {
    const float golden_angle = PI * (3.0f - sqrtf(5.0f));
    const float length = 0.5f, curl = 0.06f, turns = 2.0f;
    for (int s = 0; s < STRANDS; s++) {
        float n[3], t1[3], t2[3];
        n[1] = 1.0f - 2.0f * ((float)s + 0.5f) / (float)STRANDS;
        float ring = sqrtf(1.0f - n[1] * n[1]), phi = golden_angle * (float)s;
        n[0] = ring * cosf(phi);
        n[2] = ring * sinf(phi);
        const float any[3] = {0.6f, 0.0f, 0.8f}; /* never parallel to every normal */
        cross(n, any, t1);
        if (t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2] < 1e-4f) {
            const float other[3] = {0.0f, 1.0f, 0.0f};
            cross(n, other, t1);
        }
        normalize(t1);
        cross(n, t1, t2);
        for (int k = 0; k < POINTS_PER_STRAND; k++) {
            float u = (float)k / (float)SEGMENTS, angle = 2.0f * PI * turns * u;
            /* The helix starts at the root: offset (cos - 1, sin) in the tangent plane. */
            float a = curl * (cosf(angle) - 1.0f), b = curl * sinf(angle);
            float *p = points + 3 * (s * POINTS_PER_STRAND + k);
            for (int c = 0; c < 3; c++) p[c] = n[c] * (1.0f + length * u) + a * t1[c] + b * t2[c];
            radii[s * POINTS_PER_STRAND + k] = 0.006f * (1.0f - 0.6f * u);
        }
    }
}

/* A UV sphere of radius r: (rings + 1) * (sectors + 1) vertices with outward normals,
 * 2 * rings * sectors triangles, counter-clockwise seen from outside. */
static void sphere(float r, int rings, int sectors, float *positions, float *normals,
                   uint32_t *indices) {
    for (int i = 0; i <= rings; i++) {
        float theta = PI * (float)i / (float)rings;
        for (int j = 0; j <= sectors; j++) {
            float phi = 2.0f * PI * (float)j / (float)sectors;
            float *nv = normals + 3 * (i * (sectors + 1) + j);
            nv[0] = sinf(theta) * cosf(phi);
            nv[1] = cosf(theta);
            nv[2] = -sinf(theta) * sinf(phi);
            for (int c = 0; c < 3; c++) positions[3 * (i * (sectors + 1) + j) + c] = r * nv[c];
        }
    }
    for (int i = 0; i < rings; i++) {
        for (int j = 0; j < sectors; j++) {
            uint32_t a = (uint32_t)(i * (sectors + 1) + j), b = a + (uint32_t)sectors + 1;
            uint32_t tri[6] = {a, b, a + 1, a + 1, b, b + 1};
            for (int c = 0; c < 6; c++) indices[6 * (i * sectors + j) + c] = tri[c];
        }
    }
}

/* What the progress callback saw. The renderer never runs two calls at once, so plain
 * fields are safe. */
typedef struct Progress {
    unsigned calls;
    uint64_t done, total;
} Progress;

static bool count_progress(uint64_t done, uint64_t total, void *user) {
    Progress *p = (Progress *)user;
    p->calls += 1;
    p->done = done;
    p->total = total;
    return true;
}

#define RINGS 16
#define SECTORS 32
#define VERTICES ((RINGS + 1) * (SECTORS + 1))
#define TRIANGLES (2 * RINGS * SECTORS)

/* The host's arrays: the groom, the sphere mesh and the image. */
typedef struct Buffers {
    float *points, *radii, *positions, *normals, *rgb;
    uint32_t *counts, *indices;
} Buffers;

/* Builds the scene and renders it into b->rgb, then writes it to `out`. */
static int render_fur(HtScene *scene, const Buffers *b, const char *out) {
    /* Materials first: light brown hair whose melanin varies a little from strand to
     * strand, and a white diffuse sphere. */
    HtHairParams hair = ht_hair_params_default();
    if (check(ht_hair_sigma_a_from_melanin(0.6f, 0.2f, hair.sigma_a), "sigma_a")) return 1;
    HtHairVariation variation = ht_hair_variation_default();
    variation.absorption_variation = 0.2f;
    variation.seed = 7;
    uint32_t hair_id, white_id, fur_geom, sphere_geom;
    if (check(ht_scene_add_hair_material_varied(scene, &hair, &variation, &hair_id), "hair"))
        return 1;
    const float white[3] = {0.8f, 0.8f, 0.8f};
    if (check(ht_scene_add_diffuse_material(scene, white, &white_id), "diffuse")) return 1;

    /* The groom is copied: the host's arrays could be freed right after this call. */
    HtCurves fur;
    fur.strand_count = STRANDS;
    fur.point_counts = b->counts;
    fur.point_count = (size_t)STRANDS * POINTS_PER_STRAND;
    fur.points = b->points;
    fur.radii = b->radii;
    fur.radius = 0.0f;
    fur.colors = NULL;
    fur.basis = HT_CURVE_BSPLINE;
    fur.shape = HT_CURVE_ROUND;
    if (check(ht_scene_add_curves(scene, &fur, hair_id, &fur_geom), "ht_scene_add_curves"))
        return 1;
    if (check(ht_scene_add_mesh(scene, VERTICES, b->positions, b->normals, TRIANGLES,
                                b->indices, white_id, &sphere_geom),
              "ht_scene_add_mesh"))
        return 1;
    printf("geometry %u %u\n", fur_geom, sphere_geom);

    /* A mistake is reported, and leaves the scene as it was. */
    HtStatus s = ht_scene_add_curves(scene, &fur, white_id, &fur_geom);
    printf("mismatch %s: %s\n", ht_status_str((int32_t)s), ht_last_error());

    const float sky[3] = {0.25f, 0.28f, 0.32f};
    const float sun_dir[3] = {1.0f, 1.5f, 1.0f}, sun[3] = {3.0f, 2.9f, 2.7f};
    if (check(ht_scene_add_environment(scene, sky), "environment")) return 1;
    if (check(ht_scene_add_distant_light(scene, sun_dir, sun, 3.0f), "distant light")) return 1;
    const float eye[3] = {0.0f, 0.8f, 6.0f}, target[3] = {0.0f, 0.0f, 0.0f};
    const float up[3] = {0.0f, 1.0f, 0.0f};
    if (check(ht_scene_set_camera(scene, eye, target, up, 35.0f), "camera")) return 1;

    Progress progress = {0, 0, 0};
    HtSettings *settings = NULL;
    if (check(ht_settings_new(&settings), "settings")) return 1;
    char size[2][16];
    snprintf(size[0], sizeof size[0], "%d", WIDTH);
    snprintf(size[1], sizeof size[1], "%d", HEIGHT);
    if (check(ht_settings_set(settings, "width", size[0]), "width") ||
        check(ht_settings_set(settings, "height", size[1]), "height") ||
        check(ht_settings_set(settings, "spp", "4"), "spp") ||
        check(ht_settings_set(settings, "seed", "1"), "seed"))
        return 1;
    if (check(ht_render_with(scene, settings, count_progress, &progress, b->rgb,
                             WIDTH * HEIGHT * 3, NULL, NULL, NULL, WIDTH * HEIGHT),
              "ht_render_with"))
        return 1;

    double sum = 0.0;
    for (int i = 0; i < WIDTH * HEIGHT * 3; i++) sum += b->rgb[i];
    printf("image %d %d\n", WIDTH, HEIGHT);
    printf("mean %.6f\n", sum / (WIDTH * HEIGHT * 3));
    printf("progress %u calls, done %llu of %llu\n", progress.calls,
           (unsigned long long)progress.done, (unsigned long long)progress.total);

    /* A crop renders exactly the full frame's pixels there, so a farm can split a frame;
     * this one also asks for the depth AOV (the other AOVs are not wanted: NULL). */
    float crop[CROP_W * CROP_H * 3], depth[CROP_W * CROP_H];
    char window[64];
    snprintf(window, sizeof window, "%d,%d,%d,%d", CROP_X0, CROP_Y0, CROP_X0 + CROP_W,
             CROP_Y0 + CROP_H);
    if (check(ht_settings_set(settings, "crop", window), "crop")) return 1;
    if (check(ht_render_with(scene, settings, NULL, NULL, crop, CROP_W * CROP_H * 3, NULL, depth,
                             NULL, CROP_W * CROP_H),
              "ht_render_with"))
        return 1;
    int same = 1, hits = 0;
    for (int y = 0; y < CROP_H; y++) {
        const float *full = b->rgb + ((y + CROP_Y0) * WIDTH + CROP_X0) * 3;
        same &= memcmp(crop + y * CROP_W * 3, full, CROP_W * 3 * sizeof(float)) == 0;
    }
    for (int i = 0; i < CROP_W * CROP_H; i++) hits += depth[i] > 0.0f;
    printf("crop %d %d same %d hits %d\n", CROP_W, CROP_H, same, hits);
    if (check(ht_image_write(out, WIDTH, HEIGHT, 3, b->rgb, WIDTH * HEIGHT * 3), "ht_image_write")) return 1;
    printf("wrote %s\n", out);

    /* Darker hair on the built scene: no new build, the next render uses it at once. */
    if (check(ht_hair_sigma_a_from_melanin(3.0f, 0.2f, hair.sigma_a), "sigma_a")) return 1;
    if (check(ht_scene_set_hair_material(scene, hair_id, &hair, &variation), "set hair"))
        return 1;
    float darker[CROP_W * CROP_H * 3];
    if (check(ht_render_with(scene, settings, NULL, NULL, darker, CROP_W * CROP_H * 3, NULL, NULL,
                             NULL, CROP_W * CROP_H),
              "ht_render_with"))
        return 1;
    if (check(ht_settings_free(settings), "free settings")) return 1;
    double before = 0.0, after = 0.0;
    for (int i = 0; i < CROP_W * CROP_H * 3; i++) {
        before += crop[i];
        after += darker[i];
    }
    printf("darker hair %d\n", after < before);
    return 0;
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s OUT.exr\n", argv[0]);
        return 2;
    }
    const size_t points = (size_t)STRANDS * POINTS_PER_STRAND;
    Buffers b;
    b.points = (float *)malloc(3 * points * sizeof(float));
    b.radii = (float *)malloc(points * sizeof(float));
    b.counts = (uint32_t *)malloc(STRANDS * sizeof(uint32_t));
    b.positions = (float *)malloc(3 * VERTICES * sizeof(float));
    b.normals = (float *)malloc(3 * VERTICES * sizeof(float));
    b.indices = (uint32_t *)malloc(3 * TRIANGLES * sizeof(uint32_t));
    b.rgb = (float *)malloc(WIDTH * HEIGHT * 3 * sizeof(float));
    HtDevice *device = NULL;
    HtScene *scene = NULL;
    int failed = 1;
    if (!b.points || !b.radii || !b.counts || !b.positions || !b.normals || !b.indices ||
        !b.rgb) {
        fprintf(stderr, "out of memory\n");
    } else if (!check(ht_device_new(0, &device), "ht_device_new") &&
               !check(ht_scene_new(device, &scene), "ht_scene_new")) {
        groom(b.points, b.radii);
        for (int s = 0; s < STRANDS; s++) b.counts[s] = POINTS_PER_STRAND;
        sphere(0.98f, RINGS, SECTORS, b.positions, b.normals, b.indices);
        failed = render_fur(scene, &b, argv[1]);
    }
    /* Both frees accept NULL. The scene keeps the device alive, so the order is free. */
    ht_scene_free(scene);
    ht_device_free(device);
    /* Every handle is freed: join the worker threads Embree kept (optional at exit). */
    if (check(ht_shutdown(), "ht_shutdown")) failed = 1;
    free(b.points);
    free(b.radii);
    free(b.counts);
    free(b.positions);
    free(b.normals);
    free(b.indices);
    free(b.rgb);
    return failed;
}
