/* Bad input through every scene, render and image entry point: NULLs, NaN and infinity,
 * huge and "negative" (wrapped) sizes, strands of no length, zero radii, misaligned and
 * overlapping buffers. Each row of the table below names a call, the status it must
 * return and words its ht_last_error() message must hold. Then a tiny valid scene still
 * renders. Prints one line per failed row and "checks N failed F"; exits non-zero on any
 * failure. Compiles as C99 and as C++; tests/c_abi runs it, also under valgrind and ASan. */
#include "hairtrace.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

static int checks = 0, failures = 0;

/* One row of the table: `s` is the status `call` returned. */
static void expect(const char *call, HtStatus s, HtStatus want, const char *words) {
    const char *msg = s == HT_OK ? "" : ht_last_error();
    checks++;
    if (s != want || strstr(msg, words) == NULL) {
        failures++;
        printf("FAIL %s: got %s \"%s\", want %s with \"%s\"\n", call, ht_status_str((int32_t)s),
               msg, ht_status_str((int32_t)want), words);
    }
}

#define ROW(call, want, words) expect(#call, call, want, words)
#define NUL HT_ERR_NULL_ARG
#define BAD HT_ERR_INVALID_ARG

/* Float storage aligned to 16 bytes, so that misaligned views of it are known exactly. */
typedef union Aligned {
    float f[64];
    double align[32];
    long double align16;
} Aligned;

static bool cancel_at_once(uint64_t done, uint64_t total, void *user) {
    (void)done;
    (void)total;
    (void)user;
    return false;
}

int main(void) {
    const float nan = NAN, inf = INFINITY;
    const float eye[3] = {0.0f, 0.0f, 4.0f}, origin[3] = {0.0f, 0.0f, 0.0f};
    const float up[3] = {0.0f, 1.0f, 0.0f}, one[3] = {1.0f, 1.0f, 1.0f};
    const float nan3[3] = {nan, 0.0f, 0.0f}, far3[3] = {1e19f, 0.0f, 0.0f};
    const float zero3[3] = {0.0f, 0.0f, 0.0f}, edge_u[3] = {1.0f, 0.0f, 0.0f};
    HtDevice *device = NULL;
    HtScene *scene = NULL, *other = NULL;
    uint32_t hair = 0, white = 0, id = 0, ids[2] = {0, 0};
    uint32_t *odd_id = (uint32_t *)(void *)((char *)ids + 1);

    ROW(ht_device_new(0, NULL), NUL, "out is NULL");
    if (ht_device_new(1, &device) != HT_OK || ht_scene_new(device, &scene) != HT_OK) {
        printf("cannot create a scene: %s\n", ht_last_error());
        return 1;
    }
    ROW(ht_scene_new(NULL, &other), NUL, "device is NULL");
    ROW(ht_scene_new(device, NULL), NUL, "out is NULL");

    /* Materials. */
    HtHairParams params = ht_hair_params_default();
    HtHairVariation variation = ht_hair_variation_default();
    ROW(ht_scene_add_hair_material(NULL, &params, &hair), NUL, "scene is NULL");
    ROW(ht_scene_add_hair_material(scene, NULL, &hair), NUL, "params is NULL");
    ROW(ht_scene_add_hair_material(scene, &params, NULL), NUL, "material_id is NULL");
    ROW(ht_scene_add_hair_material(scene, &params, odd_id), BAD, "not aligned to 4 bytes");
    ROW(ht_scene_add_hair_material_varied(scene, &params, NULL, &hair), NUL, "variation is NULL");
    variation.use_vertex_colors = 2;
    ROW(ht_scene_add_hair_material_varied(scene, &params, &variation, &hair), BAD,
        "use_vertex_colors = 2: must be 0 or 1");
    variation = ht_hair_variation_default();
    params.beta_m = nan;
    ROW(ht_scene_add_hair_material(scene, &params, &hair), BAD, "beta_m = NaN");
    params = ht_hair_params_default();
    ROW(ht_scene_add_diffuse_material(scene, NULL, &white), NUL, "albedo is NULL");
    ROW(ht_scene_add_diffuse_material(scene, nan3, &white), BAD, "albedo");
    ROW(ht_scene_add_hair_material(scene, &params, &hair), HT_OK, "");
    ROW(ht_scene_add_diffuse_material(scene, one, &white), HT_OK, "");

    /* Polyline curves: one strand of two points. */
    Aligned buf;
    memset(&buf, 0, sizeof buf);
    float *pts = buf.f;
    pts[4] = 0.5f; /* from (0, 0, 0) to (0, 0.5, 0) */
    uint32_t two[1] = {2}, zero_pts[1] = {0}, one_pt[1] = {1};
    const float radii[2] = {0.05f, 0.0f};
    HtCurves c;
    c.strand_count = 1;
    c.point_counts = two;
    c.point_count = 2;
    c.points = pts;
    c.radii = NULL;
    c.radius = 0.05f;
    c.colors = NULL;
    c.basis = HT_CURVE_LINEAR;
    c.shape = HT_CURVE_ROUND;
    HtCurves bad = c;
    ROW(ht_scene_add_curves(NULL, &c, hair, &id), NUL, "scene is NULL");
    ROW(ht_scene_add_curves(scene, NULL, hair, &id), NUL, "desc is NULL");
    ROW(ht_scene_add_curves(scene, &c, hair, NULL), NUL, "geom_id is NULL");
    ROW(ht_scene_add_curves(scene, &c, hair, odd_id), BAD, "geom_id");
    unsigned char bytes[2 * sizeof(HtCurves)];
    memcpy(bytes + 1, &c, sizeof c);
    ROW(ht_scene_add_curves(scene, (const HtCurves *)(const void *)(bytes + 1), hair, &id), BAD,
        "desc = ");
    bad.points = NULL;
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), NUL, "desc->points is NULL");
    bad = c;
    bad.point_counts = NULL;
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), NUL, "desc->point_counts is NULL");
    bad = c;
    bad.strand_count = 0;
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), BAD, "at least one strand");
    bad = c;
    bad.point_counts = zero_pts;
    bad.point_count = 0;
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), BAD, "strand 0 has 0 control points");
    bad = c;
    bad.point_counts = one_pt;
    bad.point_count = 1;
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), BAD, "at least 2 are needed");
    bad = c;
    bad.strand_count = (size_t)-1;
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), BAD, "do not fit in memory");
    bad = c;
    bad.point_count = SIZE_MAX / 2;
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), BAD, "do not fit in memory");
    bad = c;
    bad.radius = 0.0f;
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), BAD, "desc->radius = 0");
    bad.radius = nan;
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), BAD, "desc->radius = NaN");
    bad = c;
    bad.radii = radii;
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), BAD, "radius 1 = 0");
    bad = c;
    bad.points = (const float *)(const void *)((const char *)pts + 1);
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), BAD, "not aligned to 4 bytes");
    bad = c;
    bad.basis = 7;
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), BAD, "basis = 7");
    bad = c;
    bad.shape = 9;
    ROW(ht_scene_add_curves(scene, &bad, hair, &id), BAD, "shape = 9");
    pts[0] = inf;
    ROW(ht_scene_add_curves(scene, &c, hair, &id), BAD, "point 0 = ");
    pts[0] = 1e19f;
    ROW(ht_scene_add_curves(scene, &c, hair, &id), BAD, "within +-1e15");
    pts[0] = 0.0f;
    ROW(ht_scene_add_curves(scene, &c, white, &id), BAD, "material_id = 1");

    /* float4 control points, copied or shared. */
    Aligned x;
    memset(&x, 0, sizeof x);
    x.f[3] = 0.05f;
    x.f[5] = 0.5f;
    x.f[7] = 0.0f; /* a zero radius is allowed for xyzr points */
    HtCurvesXyzr xc;
    xc.strand_count = 1;
    xc.point_counts = two;
    xc.point_count = 2;
    xc.points = x.f;
    xc.colors = NULL;
    xc.basis = HT_CURVE_LINEAR;
    xc.shape = HT_CURVE_ROUND;
    HtCurvesXyzr xbad = xc;
    xbad.points = x.f + 1;
    ROW(ht_scene_add_curves_xyzr_shared(scene, &xbad, hair, &id), BAD,
        "not aligned to 16 bytes");
    xbad.points = x.f + 2;
    ROW(ht_scene_add_curves_xyzr_shared(scene, &xbad, hair, &id), BAD,
        "not aligned to 16 bytes");
    xbad = xc;
    xbad.point_counts = one_pt;
    xbad.point_count = 1;
    ROW(ht_scene_add_curves_xyzr(scene, &xbad, hair, &id), BAD, "not a whole number");
    xbad = xc;
    xbad.point_count = (size_t)-1;
    ROW(ht_scene_add_curves_xyzr(scene, &xbad, hair, &id), BAD, "do not fit in memory");
    x.f[3] = -1.0f;
    ROW(ht_scene_add_curves_xyzr(scene, &xc, hair, &id), BAD, "radius >= 0");
    x.f[3] = 0.05f;
    ROW(ht_scene_add_hair_file(scene, NULL, false, 0, 0, hair, &id), NUL, "path is NULL");
    ROW(ht_scene_add_hair_file(scene, "", false, 0, 0, hair, &id), BAD, "path is empty");
    ROW(ht_scene_add_hair_file(scene, "/nonexistent/a.hair", false, 0, 0, hair, &id), HT_ERR_IO,
        "/nonexistent/a.hair");
    uint32_t count = 0;
    ROW(ht_scene_add_usd_file(scene, NULL, 0, hair, &id, &count), NUL, "path is NULL");
    ROW(ht_scene_add_usd_file(scene, "a.usda", 0, hair, &id, NULL), NUL, "geom_count is NULL");
    ROW(ht_scene_add_usd_file(scene, "/nonexistent/a.usda", 0, hair, &id, &count), HT_ERR_IO,
        "/nonexistent/a.usda");

    /* Meshes. */
    const float tri[9] = {0.0f, 0.0f, -1.0f, 1.0f, 0.0f, -1.0f, 0.0f, 1.0f, -1.0f};
    const uint32_t idx[3] = {0, 1, 2}, idx_out[3] = {0, 1, 3};
    ROW(ht_scene_add_mesh(scene, 3, NULL, NULL, 1, idx, white, &id), NUL, "positions is NULL");
    ROW(ht_scene_add_mesh(scene, 3, tri, NULL, 1, NULL, white, &id), NUL, "indices is NULL");
    ROW(ht_scene_add_mesh(scene, 3, tri, NULL, 0, idx, white, &id), BAD, "at least one triangle");
    ROW(ht_scene_add_mesh(scene, (size_t)-1, tri, NULL, 1, idx, white, &id), BAD,
        "do not fit in memory");
    ROW(ht_scene_add_mesh(scene, 3, tri, NULL, 1, idx_out, white, &id), BAD, "triangle 0");
    const float nan_normals[9] = {0.0f, 0.0f, 1.0f, nan, 0.0f, 1.0f, 0.0f, 0.0f, 1.0f};
    ROW(ht_scene_add_mesh(scene, 3, tri, nan_normals, 1, idx, white, &id), BAD, "normal 1");
    ROW(ht_scene_add_mesh(scene, 3, tri, NULL, 1, idx, hair, &id), BAD, "material_id = 0");
    ROW(ht_scene_add_mesh_file(scene, NULL, white, &id), NUL, "path is NULL");
    ROW(ht_scene_add_mesh_file(scene, "/nonexistent/m.obj", white, &id), HT_ERR_IO, "m.obj");
    ROW(ht_scene_add_mesh_file(scene, "/nonexistent/m.ply", white, &id), HT_ERR_IO, "m.ply");
    ROW(ht_scene_add_mesh_file(scene, "m.stl", white, &id), BAD, "unknown mesh format");

    /* Lights and camera. */
    const float huge_dir[3] = {1e30f, 1e30f, 0.0f};
    ROW(ht_scene_add_environment(NULL, one), NUL, "scene is NULL");
    ROW(ht_scene_add_environment(scene, NULL), NUL, "radiance is NULL");
    ROW(ht_scene_add_environment(scene, nan3), BAD, "radiance");
    ROW(ht_scene_add_environment_map(scene, NULL, 0.0f, 1.0f), NUL, "path is NULL");
    ROW(ht_scene_add_environment_map(scene, "/nonexistent/e.exr", 0.0f, 1.0f), HT_ERR_IO,
        "e.exr");
    ROW(ht_scene_add_distant_light(scene, NULL, one, 1.0f), NUL, "direction is NULL");
    ROW(ht_scene_add_distant_light(scene, zero3, one, 1.0f), BAD, "not zero");
    ROW(ht_scene_add_distant_light(scene, up, one, nan), BAD, "NaN degrees");
    ROW(ht_scene_add_distant_light(scene, up, one, 90.0f), BAD, "90 degrees must be in [0, 90)");
    ROW(ht_scene_add_distant_light(scene, huge_dir, one, 1.0f), HT_OK, "");
    ROW(ht_scene_add_rect_light(scene, far3, edge_u, up, one, false), BAD, "rect light corner");
    ROW(ht_scene_add_rect_light(scene, origin, edge_u, edge_u, one, false), BAD, "parallel");
    ROW(ht_scene_add_rect_light(scene, origin, edge_u, up, NULL, false), NUL, "radiance is NULL");
    ROW(ht_scene_set_camera(scene, NULL, origin, up, 40.0f), NUL, "eye is NULL");
    ROW(ht_scene_set_camera(scene, nan3, origin, up, 40.0f), BAD, "eye");
    ROW(ht_scene_set_camera(scene, far3, origin, up, 40.0f), BAD, "within +-1e15");
    ROW(ht_scene_set_camera(scene, eye, eye, up, 40.0f), BAD, "distinct");
    ROW(ht_scene_set_camera(scene, eye, origin, up, inf), BAD, "fov");
    ROW(ht_scene_set_thin_lens(NULL, 0.0f, 1.0f), NUL, "scene is NULL");
    ROW(ht_scene_set_thin_lens(scene, nan, 1.0f), BAD, "aperture_radius = NaN");
    ROW(ht_scene_set_thin_lens(scene, 2e18f, 1.0f), BAD, "aperture_radius");
    ROW(ht_scene_set_thin_lens(scene, 0.0f, -1.0f), BAD, "focus_distance = -1");

    /* Rendering: a 2 x 2 image, settings by name. Nothing above was added but the lights. */
    HtSettings *s = NULL;
    ROW(ht_settings_new(NULL), NUL, "out is NULL");
    ROW(ht_settings_new(&s), HT_OK, "");
    ROW(ht_settings_set(s, "width", "2"), HT_OK, "");
    ROW(ht_settings_set(s, "height", "2"), HT_OK, "");
    ROW(ht_settings_set(s, "spp", "1"), HT_OK, "");
    ROW(ht_settings_set(s, "threads", "1"), HT_OK, "");
    ROW(ht_settings_set(NULL, "spp", "1"), NUL, "settings is NULL");
    ROW(ht_settings_set(s, NULL, "1"), NUL, "key is NULL");
    ROW(ht_settings_set(s, "spp", "0"), BAD, "spp = 0: must be >= 1");
    ROW(ht_settings_set(s, "sp", "4"), BAD, "sp: not a render setting");
    ROW(ht_settings_set(s, "filter_radius", "nan"), BAD, "filter_radius = nan");
    Aligned out;
    float *rgb = out.f, *odd_rgb = (float *)(void *)((char *)out.f + 2);
    ROW(ht_render_with(NULL, s, NULL, NULL, rgb, 12, NULL, NULL, NULL, 4), NUL, "scene is NULL");
    ROW(ht_render_with(scene, NULL, NULL, NULL, rgb, 12, NULL, NULL, NULL, 4), NUL,
        "settings is NULL");
    ROW(ht_render_with(scene, s, NULL, NULL, NULL, 12, NULL, NULL, NULL, 4), NUL, "rgb is NULL");
    ROW(ht_render_with(scene, s, NULL, NULL, rgb, (size_t)-1, NULL, NULL, NULL, 4), BAD,
        "rgb_len = ");
    ROW(ht_render_with(scene, s, NULL, NULL, odd_rgb, 12, NULL, NULL, NULL, 4), BAD,
        "not aligned to 4 bytes");
    ROW(ht_render_with(scene, s, NULL, NULL, rgb, 12, NULL, rgb, NULL, 4), BAD,
        "rgb and depth overlap");
    ROW(ht_render_with(scene, s, NULL, NULL, rgb, 12, rgb + 16, NULL, rgb + 20, 4), BAD,
        "albedo and strand_id overlap");
    ROW(ht_render_with(scene, s, NULL, NULL, rgb, 12, NULL, NULL, NULL, SIZE_MAX), BAD,
        "pixel_count");
    ROW(ht_scene_build_with(NULL, s, NULL, NULL), NUL, "scene is NULL");
    ROW(ht_scene_build_with(scene, NULL, NULL, NULL), NUL, "settings is NULL");
    /* Rules between settings are checked where the settings are used. */
    ROW(ht_settings_set(s, "crop", "0,0,3,2"), HT_OK, "");
    ROW(ht_scene_build_with(scene, s, NULL, NULL), BAD, "crop = 0,0,3,2");
    ROW(ht_render_with(scene, s, NULL, NULL, rgb, 18, NULL, NULL, NULL, 6), BAD, "crop = 0,0,3,2");
    ROW(ht_settings_set(s, "crop", "none"), HT_OK, "");
    /* No geometry and no camera: nothing to frame. */
    ROW(ht_render_with(scene, s, NULL, NULL, rgb, 12, NULL, NULL, NULL, 4), BAD,
        "no geometry to frame");

    /* Images. */
    const float px[12] = {0};
    ROW(ht_image_write(NULL, 2, 2, 3, px, 12), NUL, "path is NULL");
    ROW(ht_image_write("/tmp/x.exr", 2, 2, 3, NULL, 12), NUL, "pixels is NULL");
    ROW(ht_image_write("/tmp/x.exr", 100000, 100000, 3, px, 12), BAD, "pixels_len = 12");
    const float nan_px[12] = {0.0f, nan, 0.0f};
    ROW(ht_image_write("/tmp/x.exr", 2, 2, 3, nan_px, 12), BAD, "channel 1 is NaN");
    ROW(ht_image_write("/tmp/x.exr", UINT32_MAX, UINT32_MAX, UINT32_MAX, px, 12), BAD,
        "overflows");
    ROW(ht_image_write("/tmp/x.exr", 2, 2, 3, (const float *)(const void *)((const char *)px + 1),
                       12),
        BAD, "not aligned");

    /* Freeing NULL is fine; unknown statuses have a name. */
    ROW(ht_scene_free(NULL), HT_OK, "");
    ROW(ht_device_free(NULL), HT_OK, "");
    checks++;
    if (strcmp(ht_status_str(-1), "unknown status") != 0) {
        failures++;
        printf("FAIL ht_status_str(-1) = %s\n", ht_status_str(-1));
    }

    /* After all of that, a valid strand renders, and a callback can cancel it. */
    ROW(ht_scene_add_curves(scene, &c, hair, &id), HT_OK, "");
    ROW(ht_scene_set_camera(scene, eye, origin, up, 20.0f), HT_OK, "");
    ROW(ht_render_with(scene, s, NULL, NULL, rgb, 12, NULL, NULL, NULL, 4), HT_OK, "");
    ROW(ht_settings_set(s, "spp", "4000000000"), HT_OK, "");
    ROW(ht_render_with(scene, s, cancel_at_once, NULL, rgb, 12, NULL, NULL, NULL, 4),
        HT_ERR_CANCELLED, "cancelled");
    ROW(ht_settings_free(s), HT_OK, "");
    ROW(ht_settings_free(NULL), HT_OK, "");

    ROW(ht_shutdown(), BAD, "still in use");
    ht_scene_free(scene);
    ht_device_free(device);
    /* Joins Embree's (TBB's) worker threads, so that leak checkers see none running. */
    ROW(ht_shutdown(), HT_OK, "");
    printf("checks %d failed %d\n", checks, failures);
    return failures != 0;
}
