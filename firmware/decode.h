/* Structured-light decoding: per-pixel projector column and a reason code for every rejected pixel.
 */
#ifndef DECODE_H
#define DECODE_H

#include "scan_types.h"

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

/** Grey value of one RGB pixel (ITU-R BT.601 weights, integer). */
static inline uint8_t decode_grey(const uint8_t *rgb)
{
    return (uint8_t)((77u * rgb[0] + 150u * rgb[1] + 29u * rgb[2]) >> 8);
}

/** Start a view. @retval 0 ok @retval -EINVAL size above the compiled limits */
int decode_begin(const struct scan_params *params, uint32_t proj_width);
/** Feed the frame of stored pattern @p pattern_index (in sequence order), RGB24.
 *  @retval 0 ok @retval -EINVAL out of order */
int decode_frame(uint32_t pattern_index, const uint8_t *rgb);
/** Gray to binary, range and neighbour checks. @retval 0 ok @retval -EINVAL frames missing */
int decode_finish(void);
/** The maps of the last finished view. */
const struct decode_maps *decode_get_maps(void);

#endif
