/* The simulator's photographic paint read from its file ([sim] albedo_image). */
#ifndef BOARD_ALBEDO_H
#define BOARD_ALBEDO_H

#include "sim_config.h"

#include <stddef.h>

/** [sim] albedo_pattern = image: read albedo_image (relative to @p dir) with the project's PNG
 *  reader (a FIFO, a directory, a 16-bit or alpha PNG refused with the reason) and hand it to the
 *  simulator (sim_albedo_image_set), once per path; nothing to do for another pattern.
 *  @retval 0 @retval -EINVAL not given, not such a PNG, larger than BOARD_ALBEDO_MAX_SIDE a side
 *  (@p err says which) @retval -ENOMEM */
int board_albedo_image_load(const struct sim_config *cfg, const char *dir, char *err, size_t len);

#define BOARD_ALBEDO_MAX_SIDE 4096u

#endif
