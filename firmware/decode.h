/* Structured-light decoding: per-pixel projector column (and row) and a reason code for every
 * rejected pixel. Each frame is read into the pixels' bits as it is handed over (a bit's stripes
 * when their inverse comes), so the decoder keeps a few bytes a pixel, not the view's frames. */
#ifndef DECODE_H
#define DECODE_H

#include "gray.h"
#include "hal_thread.h"
#include "scan_types.h"

#include <stddef.h>
#include <stdint.h>

/** Why a pixel has no depth; SCAN_VALID means it has one. */
enum scan_reason {
    SCAN_VALID = 0,
    SCAN_SHADOW,       /**< the projector does not reach it (white ~ black) */
    SCAN_DARK,         /**< lit, but too dark a surface to decode reliably */
    SCAN_LOW_CONTRAST, /**< too many bits' |I - I_inverse| within the noise */
    SCAN_SATURATED,    /**< a channel clipped in some frame */
    SCAN_INCONSISTENT, /**< decodes outside the projector or disagrees with its neighbours */
    SCAN_REASON_COUNT
};

/** The decoded maps of a view, read-only (row-major, width * height): the decoder's columns and
 *  rows, and the view's reason map as the stages after decoding left it. */
struct decode_maps {
    const uint16_t *column; /**< projector column, meaningful where reason == SCAN_VALID */
    const uint16_t *row;    /**< projector row, or NULL when rows are not coded */
    const uint8_t *reason;  /**< enum scan_reason per pixel */
    uint32_t width, height;
};

/* Patterns a view can have: DECODE_MAX_PATTERNS (hal_limits.h). */

/** Pixels converted together by decode_pixels, a block a thread at a time. */
#define DECODE_BLOCK 4096u

/** The planes a view's decoder works in until decode_finish has run (about 19 bytes a pixel):
 *  apart from struct decode_ctx so that their owner may give their memory to what comes after
 *  the decoding (struct scan_ctx: the range image). Fields are the decoder's own. */
struct decode_work {
    /* Frames being handed over: a bit's stripes wait in stage[0] for their inverse, which (like
     * a bit projected without inverse) comes into stage[1]. */
    uint8_t stage[2][HAL_MAX_PIXELS];
    uint8_t threshold[HAL_MAX_PIXELS];      /* of a bit with its inverse, by the contrast */
    uint8_t mean[HAL_MAX_PIXELS];           /* (white + black) / 2: read against by the bits */
    uint8_t mean_threshold[HAL_MAX_PIXELS]; /* without inverse, and their threshold */
    uint8_t sat[HAL_MAX_PIXELS];            /* some pair had both frames saturated */
    /* The bits read so far, first high: the Gray word and which bits were unclear, of the
     * columns [0] and rows [1], in byte planes (bits 0-7, then the rest) so that reading a bit
     * is 8-bit arithmetic on one plane. */
    uint8_t word_hi[2][HAL_MAX_PIXELS], word_lo[2][HAL_MAX_PIXELS];
    uint8_t unclear_hi[2][HAL_MAX_PIXELS], unclear_lo[2][HAL_MAX_PIXELS];
    uint16_t unclear_col[HAL_MAX_PIXELS]; /* bit k: Gray bit k of the column was unclear */
    uint16_t unclear_row[HAL_MAX_PIXELS];
    uint8_t scratch[HAL_MAX_PIXELS]; /* the neighbourhood stages' verdicts, applied after */
};

/** One view's decoder (several MB at the compiled limits: kept static by its owner, a struct
 *  scan_ctx, never on the stack). It keeps what it needs of each pixel, not the frames: white
 *  and black, the thresholds they give, and the bits read so far (in its working planes,
 *  struct decode_work), so its size does not grow with the patterns. What a finished view is
 *  described by stays here: white, black and the maps. Fields are the decoder's own. */
struct decode_ctx {
    uint8_t white[HAL_MAX_PIXELS], black[HAL_MAX_PIXELS]; /* patterns 0 and 1, kept */
    uint16_t column_map[HAL_MAX_PIXELS];
    uint16_t row_map[HAL_MAX_PIXELS];
    struct decode_work *work; /* the owner's, given to decode_begin */
    struct scan_params params;
    struct gray_layout layout;
    uint32_t proj_width, proj_height;
    uint32_t next_pattern;
    uint8_t bit_threshold[256];     /* |I - I_inverse| at or below this is unclear, per contrast */
    uint8_t mean_threshold_of[256]; /* |I - (white + black) / 2| likewise, a bit without inverse */
    uint32_t xor_col, xor_row;      /* gray_code_xor_mask of the columns and rows */
};

/** Short name of a reason code, for logs and reports. */
const char *scan_reason_name(unsigned reason);

/** Grey level that marks a pixel saturated in some channel; real grey levels stop at 254. */
#define DECODE_SATURATED 255u

/** Convert an RGB24 frame to the decoder's grey frame (ITU-R BT.601 weights, integer): a pixel
 *  with a channel at or above @p saturation_dn becomes DECODE_SATURATED. The live scan and the
 *  offline re-processing both decode exactly such frames, so they agree to the bit. */
void decode_rgb_to_grey(const uint8_t *rgb, uint8_t *grey, size_t n, uint32_t saturation_dn);

/** The pixel's bit threshold: |I - I_inverse| at or below it leaves the bit unclear. From the
 *  camera's noise model, bit_noise_sigmas standard deviations of the difference of two frames
 *  at this white-minus-black contrast, and never below min_bit_diff_dn. */
uint32_t decode_bit_threshold(const struct scan_params *params, uint32_t contrast_dn);

/** The threshold of a bit projected without its inverse (gray_layout's inverse_bits), read
 *  against the mean of white and black: |I - mean| at or below it leaves the bit unclear. A
 *  quarter of decode_bit_threshold, rounded up (measured: decode.c says why). */
uint32_t decode_mean_threshold(const struct scan_params *params, uint32_t contrast_dn);

/** Give back the memory of @p d's own per-pixel planes (mem_release; not its working planes,
 *  whose memory is their owner's) until the next decode_begin: their contents are not read
 *  again before a view writes them (zeros if they are). */
void decode_release(struct decode_ctx *d);

/** Start a view of a @p proj_width x @p proj_height projector coded as @p layout in @p d.
 *  @param work  the planes it works in until decode_finish (read again by nothing after it: the
 *               owner may use their memory then, and decode_finish runs once a view)
 *  @retval 0 ok @retval -EINVAL size or pattern count above the compiled limits */
int decode_begin(struct decode_ctx *d, struct decode_work *work, const struct scan_params *params,
                 const struct gray_layout *layout, uint32_t proj_width, uint32_t proj_height);
/** Where frame @p pattern is handed over: a capture may write its grey frame there directly.
 *  It holds the frame until the next frame after it is handed over (white and black: until
 *  the next view begins). @retval NULL when @p pattern is outside the layout */
uint8_t *decode_frame_slot(struct decode_ctx *d, uint32_t pattern);
/** Whether pattern @p next's frame may be written into its slot before pattern @p pattern is
 *  handed over (a reader of kept frames reads two at once): its slot is neither @p pattern's
 *  nor one the hand-over of @p pattern reads (an inverse is read against its stripes' frame).
 *  @retval 1 it may @retval 0 it may not, or either is outside the layout */
int decode_slot_free_before(struct decode_ctx *d, uint32_t pattern, uint32_t next);
/** Hand over the grey frame of pattern @p pattern, in sequence order (copied into its slot
 *  unless it already is the slot), and read its bit into every pixel.
 *  @retval 0 ok @retval -EINVAL out of order */
int decode_frame(struct decode_ctx *d, uint32_t pattern, const uint8_t *grey);
/** Decode every pixel from the bits read (decode_pixels); then pixels with several unclear
 *  bits take the reading their neighbourhood agrees with; then the neighbour check.
 *  @param threads  the cores to split the pixels across (NULL: this thread alone); the result
 *  is the same to the byte however many
 *  @param reason  out: enum scan_reason per pixel (width * height, the caller's buffer)
 *  @param maps    out: the decoder's column and row maps, and @p reason
 *  @retval 0 ok @retval -EINVAL frames missing */
int decode_finish(struct decode_ctx *d, const struct hal_thread *threads, uint8_t *reason,
                  struct decode_maps *maps);
/** The per-pixel stage of decode_finish alone (for tests and benchmarks; it may run again, the
 *  bits read are kept until the next view begins); same parameters. */
int decode_pixels(struct decode_ctx *d, const struct hal_thread *threads, uint8_t *reason,
                  struct decode_maps *maps);

/** The plain per-pixel reference the blocked decoder must match (tests compare them): decode
 *  @p n pixels of @p frames (one pointer per pattern of @p layout) into @p column, @p row
 *  (may be NULL when the layout has no rows) and @p reason. */
void decode_reference(const struct scan_params *params, const struct gray_layout *layout,
                      uint32_t proj_width, uint32_t proj_height, const uint8_t *const *frames,
                      size_t n, uint16_t *column, uint16_t *row, uint8_t *reason);

#endif
