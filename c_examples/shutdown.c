/* ht_shutdown joins the worker threads hairtrace started: counts this process's threads
 * (/proc/self/task, Linux) before a render, after it, after the handles are freed and after
 * ht_shutdown, which must leave the main thread alone; then shows that shutdown refuses
 * while a scene lives and that the library works again afterwards. Compiles as C99 and
 * C++; tests/c_abi/c_examples.rs runs it, also under valgrind and ASan. */
#include "hairtrace.h"

#include <dirent.h>
#include <stdio.h>
#include <time.h>

/* Threads of this process, or -1 if /proc cannot be read. */
static int thread_count(void) {
    DIR *dir = opendir("/proc/self/task");
    if (dir == NULL) return -1;
    int n = 0;
    for (struct dirent *e = readdir(dir); e != NULL; e = readdir(dir)) n += e->d_name[0] != '.';
    closedir(dir);
    return n;
}

/* The thread count once it is down to `target`, or after a second of waiting: a joined
 * thread has finished its work but may still be on its way out of the kernel's list. */
static int settled_thread_count(int target) {
    const struct timespec tick = {0, 10 * 1000 * 1000};
    int n = thread_count();
    for (int i = 0; i < 100 && n > target; i++) {
        nanosleep(&tick, NULL);
        n = thread_count();
    }
    return n;
}

/* One strand under a sky, rendered at 4 x 4 on 2 threads into a fresh device and scene. */
static int render_once(HtDevice **device, HtScene **scene) {
    const float pts[6] = {0.0f, 0.0f, 0.0f, 0.0f, 0.5f, 0.0f}, sky[3] = {1.0f, 1.0f, 1.0f};
    const float eye[3] = {0.0f, 0.0f, 4.0f}, target[3] = {0.0f, 0.2f, 0.0f};
    const float up[3] = {0.0f, 1.0f, 0.0f};
    const uint32_t counts[1] = {2};
    uint32_t hair, geom;
    HtHairParams params = ht_hair_params_default();
    HtCurves c;
    c.strand_count = 1;
    c.point_counts = counts;
    c.point_count = 2;
    c.points = pts;
    c.radii = NULL;
    c.radius = 0.05f;
    c.colors = NULL;
    c.basis = HT_CURVE_LINEAR;
    c.shape = HT_CURVE_ROUND;
    HtSettings *s = NULL;
    float rgb[48];
    if (ht_settings_new(&s) != HT_OK || ht_settings_set(s, "width", "4") != HT_OK ||
        ht_settings_set(s, "height", "4") != HT_OK || ht_settings_set(s, "spp", "2") != HT_OK ||
        ht_settings_set(s, "threads", "2") != HT_OK || ht_device_new(2, device) != HT_OK ||
        ht_scene_new(*device, scene) != HT_OK ||
        ht_scene_add_hair_material(*scene, &params, &hair) != HT_OK ||
        ht_scene_add_curves(*scene, &c, hair, &geom) != HT_OK ||
        ht_scene_add_environment(*scene, sky) != HT_OK ||
        ht_scene_set_camera(*scene, eye, target, up, 30.0f) != HT_OK ||
        ht_render_with(*scene, s, NULL, NULL, rgb, 48, NULL, NULL, NULL, 16) != HT_OK) {
        printf("render failed: %s\n", ht_last_error());
        ht_settings_free(s);
        return 1;
    }
    return ht_settings_free(s) != HT_OK;
}

int main(void) {
    HtDevice *device = NULL;
    HtScene *scene = NULL;
    const int start = thread_count();
    printf("threads start %d\n", start);
    if (ht_shutdown() != HT_OK) return 1; /* nothing started yet: nothing to join */
    if (render_once(&device, &scene)) return 1;
    printf("threads rendered %d\n", thread_count());
    HtStatus s = ht_shutdown();
    printf("refused %s: %s\n", ht_status_str((int32_t)s), ht_last_error());
    ht_scene_free(scene);
    ht_device_free(device);
    printf("threads freed %d\n", thread_count());
    s = ht_shutdown();
    printf("shutdown %s threads %d\n", ht_status_str((int32_t)s), settled_thread_count(start));
    /* The library starts again on demand. */
    if (render_once(&device, &scene)) return 1;
    ht_scene_free(scene);
    ht_device_free(device);
    s = ht_shutdown();
    printf("again %s threads %d\n", ht_status_str((int32_t)s), settled_thread_count(start));
    return 0;
}
