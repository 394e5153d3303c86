/* Whether the disk has room for a scan's frames (disk_room.h). */
#include "disk_room.h"

#include "hal_limits.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/statvfs.h>

/* Bytes a view keeps per camera pixel, measured on the simulator's bunny at 1280 x 960 with
 * [colour] method multi (2026-12-04, the simulator's truth files left out): every frame 21.9,
 * the colour frames 13.8, none 4.6 (range.bin and cloud.ply); the object filling more of the
 * picture, or noisier frames compressing less, keep more: half again as margin. */
uint64_t disk_room_view_bytes(const struct app_config *cfg)
{
    const double per_pixel = cfg->keep_frames == KEEP_FRAMES_ALL      ? 21.9
                             : cfg->keep_frames == KEEP_FRAMES_COLOUR ? 13.8
                                                                      : 4.6;
    return (uint64_t)(1.5 * per_pixel * cfg->camera.width * cfg->camera.height);
}

/* statvfs of @p dir, or of the nearest parent that exists ("scans/sim" before the first scan
 * makes it). @retval 0 ok, else -errno */
static int free_bytes_at(const char *dir, double *free_bytes)
{
    char at[HAL_MAX_PATH];
    struct statvfs fs;
    if (snprintf(at, sizeof(at), "%s", dir[0] != '\0' ? dir : ".") >= (int)sizeof(at))
        return -ENAMETOOLONG;
    while (statvfs(at, &fs) != 0) {
        if (errno != ENOENT || strcmp(at, ".") == 0 || strcmp(at, "/") == 0)
            return -errno;
        char *slash = strrchr(at, '/');
        if (slash == NULL) /* a relative path's first part: the working directory */
            snprintf(at, sizeof(at), ".");
        else if (slash == at) /* "/x": the root */
            at[1] = '\0';
        else
            *slash = '\0';
    }
    /* what a person may use: the blocks free to them, not those kept for root */
    *free_bytes = (double)fs.f_bavail * (double)fs.f_frsize;
    return 0;
}

int disk_room_check(const struct app_config *cfg, const char *dir, uint32_t views, char *why,
                    size_t why_len)
{
    double free_bytes;
    if (free_bytes_at(dir, &free_bytes) != 0)
        return 0;
    const double view_bytes = (double)disk_room_view_bytes(cfg);
    const double need = (double)views * view_bytes;
    if (need <= free_bytes)
        return 0;
    snprintf(why, why_len,
             "the disk holds %.0f MB free; this scan needs about %.0f MB (%u views of about %.0f "
             "MB, [output] keep_frames = %s): delete a scan, or keep fewer frames",
             free_bytes / 1e6, need / 1e6, (unsigned)views, view_bytes / 1e6,
             cfg->keep_frames_name);
    return -ENOSPC;
}
