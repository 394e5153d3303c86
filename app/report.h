/* The scan report: report.html, one self-contained page per scan directory, and the pictures it
 * and the web page show (thumbnails of each view, the model seen from around). */
#ifndef REPORT_H
#define REPORT_H

#include "hal.h"

#include <stddef.h>
#include <stdint.h>

/** Width of a view's thumbnail, pixels (its height keeps the camera's aspect). */
#define REPORT_THUMB_WIDTH 240u

/** What a view's thumbnail shows. */
enum report_thumb {
    REPORT_THUMB_RAW,       /**< the camera's colour frame, as captured (before compensation) */
    REPORT_THUMB_INTRINSIC, /**< the view's colour as the model takes it (after compensation) */
    REPORT_THUMB_REASONS,   /**< each pixel's reason code (valid, shadow, dark ...): legend */
};

/** A view's thumbnail as a PNG in memory, made from what its directory keeps (range.bin; the
 *  colour frame for REPORT_THUMB_RAW). Reentrant: threads may ask at once.
 *  @param png  out: the PNG, the caller's to free()
 *  @retval 0 @retval -ENOENT the view has no such data (yet) @retval -EINVAL damaged
 *  @retval -ENOMEM */
int report_thumb_png(const char *dir, uint32_t view, enum report_thumb kind, uint8_t **png,
                     size_t *png_len);

/** The colour a reason code has in the reason map, "#rrggbb" (@p reason < SCAN_REASON_COUNT). */
const char *report_reason_colour(unsigned reason);

/** Write @p dir/report.html from what the scan directory holds now: the views taken, each with
 *  its thumbnails, reason map, valid points and registration; the model seen from four sides
 *  and from above; timings per stage and peak memory (summary.ini). A scan that stopped early
 *  gets a report of what it has.
 *  @param err  out: what failed, naming the file
 *  @retval 0 @retval -errno */
int report_write(const struct hal_storage *st, const char *dir, char *err, size_t err_len);

#endif
