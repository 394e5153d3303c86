/* Whether the disk has room for the frames a scan (or the rest of a resumed one) will keep:
 * asked before a scan touches the rig, by the command line and the web server alike. */
#ifndef DISK_ROOM_H
#define DISK_ROOM_H

#include "config.h"

#include <stddef.h>
#include <stdint.h>

/** About how many bytes a view of @p cfg keeps on disk (frames as [output] keep_frames says,
 *  range.bin, cloud.ply): measured per camera pixel, with half again as margin. */
uint64_t disk_room_view_bytes(const struct app_config *cfg);

/** Whether the file system of @p dir (or, while it does not exist yet, of its nearest existing
 *  parent) has room for @p views more views of @p cfg.
 *  @param why  out: when short, what is free, what the scan needs and what to do
 *  @retval 0 room, or the free space cannot be read (the writes will say what is wrong)
 *  @retval -ENOSPC not room for them */
int disk_room_check(const struct app_config *cfg, const char *dir, uint32_t views, char *why,
                    size_t why_len);

#endif
