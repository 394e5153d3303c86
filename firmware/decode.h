/* Structured-light decoding: per-pixel projector column and a reason code for every rejected pixel.
 */
#ifndef DECODE_H
#define DECODE_H

#include "scan_types.h"

#include <stddef.h>
#include <stdint.h>

/** Why a pixel has no depth; SCAN_VALID means it has one. */
enum scan_reason {
    SCAN_VALID = 0,
    SCAN_SHADOW,       /**< the projector does not reach it (white ~ black) */
    SCAN_DARK,         /**< lit, but too dark a surface to decode reliably */
    SCAN_LOW_CONTRAST, /**< some bit's |I - I_inverse| is within the noise */
    SCAN_SATURATED,    /**< a channel clipped in some frame */
    SCAN_INCONSISTENT, /**< decodes outside the projector or disagrees with its neighbours */
    SCAN_REASON_COUNT
};

/** Read-only view of the decoder's static maps (row-major, width * height). */
struct decode_maps {
    const uint16_t *column; /**< projector column, meaningful where reason == SCAN_VALID */
    uint8_t *reason;        /**< enum scan_reason per pixel; later stages add their own */
    uint32_t width, height;
};

/** Short name of a reason code, for logs and reports. */
const char *scan_reason_name(unsigned reason);

/** Grey level that marks a pixel saturated in some channel; real grey levels stop at 254. */
#define DECODE_SATURATED 255u

/** Convert an RGB24 frame to the decoder's grey frame (ITU-R BT.601 weights, integer): a pixel
 *  with a channel at or above @p saturation_dn becomes DECODE_SATURATED. The live scan and the
 *  offline re-processing both decode exactly such frames, so they agree to the bit. */
void decode_rgb_to_grey(const uint8_t *rgb, uint8_t *grey, size_t n, uint32_t saturation_dn);

/** Start a view. @retval 0 ok @retval -EINVAL size above the compiled limits */
int decode_begin(const struct scan_params *params, uint32_t proj_width);
/** Feed the grey frame (see decode_rgb_to_grey) of stored pattern @p pattern_index, in order.
 *  @retval 0 ok @retval -EINVAL out of order */
int decode_frame(uint32_t pattern_index, const uint8_t *grey);
/** Gray to binary, range and neighbour checks. @retval 0 ok @retval -EINVAL frames missing */
int decode_finish(void);
/** The maps of the last finished view. */
const struct decode_maps *decode_get_maps(void);

#endif
