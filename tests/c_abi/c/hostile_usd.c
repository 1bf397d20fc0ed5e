/* A C host reading a hostile USD file (argv[1]) into a scene: the library must return the
 * error and its message, and print nothing to the host's stderr, though the USD reader
 * panics inside. Prints "status STATUS" and "message MESSAGE". */
#include "hairtrace.h"

#include <stdio.h>

int main(int argc, char **argv) {
    if (argc < 2) return 2;
    HtDevice *device = NULL;
    HtScene *scene = NULL;
    uint32_t material, first = 0, count = 0;
    const HtHairParams params = ht_hair_params_default();
    if (ht_device_new(1, &device) != HT_OK || ht_scene_new(device, &scene) != HT_OK ||
        ht_scene_add_hair_material(scene, &params, &material) != HT_OK) {
        printf("setup failed: %s\n", ht_last_error());
        return 1;
    }
    HtStatus s = ht_scene_add_usd_file(scene, argv[1], HT_CURVE_ROUND, material, &first, &count);
    printf("status %s\nmessage %s\n", ht_status_str((int32_t)s), ht_last_error());
    ht_scene_free(scene);
    ht_device_free(device);
    return 0;
}
