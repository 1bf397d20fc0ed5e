/* A host of the installed library (tests/packaging): compiled as C99 and as C++, linked
 * through pkg-config or CMake, shared or static, full or BSDF-only. It prints the versions
 * it was compiled and linked against, one BSDF evaluation (f |cos| and pdf), what the process costs after
 * start-up (threads, resident memory, mapped shared objects) and, with the full library,
 * that a render device can be made, and, given a path, which image shim writing an image
 * there maps, and the shared objects after it. */
#include <hairtrace.h>
#include <stdio.h>
#include <string.h>

/* Prints the value of a "Key:" line of /proc/self/status. */
static void print_status(const char *key) {
    char line[256];
    FILE *f = fopen("/proc/self/status", "r");
    size_t n = strlen(key);
    if (!f) return;
    while (fgets(line, sizeof line, f))
        if (strncmp(line, key, n) == 0) printf("%s", line);
    fclose(f);
}

/* Counts the distinct shared objects mapped into the process, and those whose path holds
 * `a` or `b`, on a line headed `heading`; with `shim` also prints the path of each one
 * whose path holds it, as "image shim <path>". */
static void print_maps(const char *heading, const char *a, const char *b, const char *shim) {
    char line[4096], last[4096] = "";
    int objects = 0, found_a = 0, found_b = 0;
    FILE *f = fopen("/proc/self/maps", "r");
    if (!f) return;
    while (fgets(line, sizeof line, f)) {
        const char *path = strchr(line, '/');
        if (!path || !strstr(path, ".so") || strcmp(path, last) == 0) continue;
        strncpy(last, path, sizeof last - 1);
        objects++;
        found_a += strstr(path, a) != NULL;
        found_b += strstr(path, b) != NULL;
        if (shim && strstr(path, shim)) printf("image shim %s", path);
    }
    fclose(f);
    printf("%s %d objects, %d %s, %d %s\n", heading, objects, found_a, a, found_b, b);
}

int main(int argc, char **argv) {
    HtHairParams p = ht_hair_params_default();
    /* The worked example of docs/conventions.md at the local frame: f |cos| and pdf. */
    const HtHairFrame local = {{1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, 0.5f};
    const float wo[3] = {0.0f, 0.0f, 1.0f}, wi[3] = {0.0f, 0.8660254f, 0.5f};
    float f[3], pdf;
    HtHairPrepared *prepared = NULL;
    HtHairPoint point;
    if (ht_hair_prepare(&p, &prepared) != HT_OK ||
        ht_hair_point_init_world(prepared, &local, wo, &point) != HT_OK ||
        ht_hair_point_eval_world(&point, wi, f, &pdf) != HT_OK) {
        fprintf(stderr, "the BSDF: %s\n", ht_last_error());
        return 1;
    }
    ht_hair_prepared_free(prepared);
    printf("header %d.%d.%d abi %d\n", HT_VERSION_MAJOR, HT_VERSION_MINOR, HT_VERSION_PATCH,
           HT_ABI_VERSION);
    printf("library %s abi %u\n", ht_version(), ht_abi_version());
    printf("eval %.9g %.9g %.9g %.9g\n", f[0], f[1], f[2], pdf);
    print_status("Threads:");
    print_status("VmRSS:");
    print_maps("maps", "libembree", "libOpenImageIO", NULL);
#ifdef HT_RENDER
    {
        HtDevice *device = NULL;
        if (ht_device_new(1, &device) != HT_OK) {
            fprintf(stderr, "ht_device_new: %s\n", ht_last_error());
            return 1;
        }
        ht_device_free(device);
        printf("device ok\n");
    }
    if (argc > 1) {
        const float pixel[3] = {0.25f, 0.5f, 1.0f};
        if (ht_image_write(argv[1], 1, 1, 3, pixel, 3) != HT_OK) {
            fprintf(stderr, "ht_image_write: %s\n", ht_last_error());
            return 1;
        }
        print_maps("image maps", "libembree", "libOpenImageIO", "libhairtrace-oiio");
    }
#else
    (void)argc;
    (void)argv;
#endif
    return 0;
}
