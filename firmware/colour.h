/* Intrinsic colour of a view (Jost, Schutz and Hugli): the camera sees reflected light; knowing
 * the geometry and the lights, invert the reflectance model. Ca (ambient + black offset) comes
 * from a dark frame. Methods:
 *   single  - projector as the only light, Cd = (C - Ca) / cos(theta)            (eq. 4)
 *   uniform - all lights on (near-uniform diffuse light), Cd = C - Ca             (method 2)
 *   multi   - each light alone, Cd = sum (Ci - Ca) wi' / sum cos(theta_i) wi',
 *             wi' = (1 - cos(alpha_i)^ke)^ko, 0 where light i is shadowed         (eq. 6)
 * with the inverse-square falloff from each calibrated source position, and a per-channel white
 * scale so that a white surface comes out as 1. */
#ifndef COLOUR_H
#define COLOUR_H

#include "decode.h"
#include "tri.h"

struct reflect_pool;

/** Light frames after the Gray-code patterns: dark, all lights, then each light alone. */
#define COLOUR_FRAME_DARK 0u
#define COLOUR_FRAME_ALL 1u
#define COLOUR_FRAME_LIGHT0 2u
/* At most COLOUR_MAX_FRAMES (hal_limits.h): dark, all lights, every light, the bracketed ones
 * again, and a dark frame for each other exposure (all lights', single lights', bracketed). */
HAL_STATIC_ASSERT(COLOUR_MAX_FRAMES == COLOUR_FRAME_LIGHT0 + HAL_MAX_LIGHTS + 2u +
                                           (COLOUR_MAX_BRACKETED ? COLOUR_MAX_BRACKETED + 1u : 0u),
                  "COLOUR_MAX_FRAMES counts the frames colour_layout() can ask for");

/** What each colour frame shows: its lights, its exposure and the dark frame (Ca) taken at the
 *  same exposure. Frames: dark, all lights, each light alone, with [colour] bracket each light
 *  alone again at the longer exposure, then a dark frame for each other exposure. */
struct colour_layout {
    uint32_t count;
    uint32_t lights_mask[COLOUR_MAX_FRAMES];
    uint32_t exposure_us[COLOUR_MAX_FRAMES];
    uint32_t dark_of[COLOUR_MAX_FRAMES]; /**< index of the frame's dark frame */
    uint32_t long_of[COLOUR_MAX_FRAMES]; /**< the same light at the longer exposure (0: none) */
};

/** The colour frames of @p p with @p light_count lights (none when the method is none). */
void colour_layout(const struct colour_params *p, uint32_t light_count, struct colour_layout *out);

/** Whether method @p p reads colour frame @p k of layout @p l (single: the dark frame; uniform:
 *  the all-lights frame and its dark; multi and fit: each light alone, its longer frame and
 *  their dark frames; none: no frame). A scan takes them all, so that one scan serves every
 *  method; the others need not be read back. @retval 1 needed @retval 0 not */
int colour_needs_frame(const struct colour_params *p, const struct colour_layout *l, uint32_t k);

/** Confidence of a pixel with no colour estimate at all (every light shadowed or too dark for
 *  its frames): its colour is 0 and the fusion leaves it out. */
#define COLOUR_NO_ESTIMATE (-1.0f)

/** Compute albedo (0..1 scaled to 0..255) and a confidence (0..1) for every valid pixel.
 *  @param white  projector-white frame (RGB24); @param lights  light frames (RGB24) in
 *  colour_layout() order, NULL entries allowed when the method does not need them. A pixel
 *  with only a weak estimate (grazing or saturated light) gets it with confidence 0 (used where
 *  no view has better); one with none gets colour 0 and COLOUR_NO_ESTIMATE.
 *  @param pool  method fit: the reflectance (its model, once fitted, is taken off each light;
 *  while it collects, the last pass adds samples to it); NULL: none (fit gives multi's estimate)
 *  @param threads  the cores the pixels are split across (NULL: this thread; fit, which keeps
 *  samples in order, takes one): every pixel its own, the same colours however many
 *  @retval 0 @retval -EINVAL a needed frame missing */
int colour_compute(const struct colour_params *p, const struct hal_thread *threads,
                   const struct scan_calib *calib, const struct decode_maps *maps,
                   const struct tri_range *range, const uint8_t *white,
                   const uint8_t *const *lights, uint8_t *albedo_rgb, float *confidence,
                   struct reflect_pool *pool);

#endif
