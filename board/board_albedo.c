/* The simulator's photographic paint read from its file (board_albedo.h). */
#include "board_albedo.h"

#include "image_io.h"
#include "sim_rig.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int board_albedo_image_load(const struct sim_config *cfg, const char *dir, char *err, size_t len)
{
    if (strcmp(cfg->albedo_pattern, "image") != 0)
        return 0;
    char path[HAL_MAX_PATH * 2 + 2], why[256];
    const char *name = cfg->albedo_image;
    int n = name[0] == '/' ? snprintf(path, sizeof(path), "%s", name)
                           : snprintf(path, sizeof(path), "%s/%s", dir, name);
    if (name[0] == '\0' || n < 0 || (size_t)n >= sizeof(path)) {
        snprintf(err, len, "[sim] albedo_image: %s", name[0] ? "path too long" : "not given");
        return -EINVAL;
    }
    if (sim_albedo_image_is(path))
        return 0;
    const size_t capacity = (size_t)BOARD_ALBEDO_MAX_SIDE * BOARD_ALBEDO_MAX_SIDE * 3;
    uint8_t *rgb = malloc(capacity);
    uint32_t w = 0, h = 0;
    if (rgb == NULL)
        return -ENOMEM;
    int rc = image_read_png(path, rgb, capacity, &w, &h, 3, why, sizeof(why));
    if (rc == 0)
        rc = sim_albedo_image_set(path, rgb, w, h);
    else
        snprintf(err, len, "[sim] albedo_image: %s: %s", path,
                 rc == -ENOENT ? strerror(ENOENT) : why);
    free(rgb);
    return rc;
}
