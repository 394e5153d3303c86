/* View sequencing: drive projector and camera through the pattern set, then decode and triangulate.
 */
#ifndef SCAN_H
#define SCAN_H

#include "colour.h"
#include "decode.h"
#include "hal.h"
#include "scan_types.h"
#include "frames.h"
#include "reg.h"
#include "tri.h"

struct fusion_volume;

/** The memory of a view's colour frames (colour.h order: dark, all lights, each light alone,
 *  the bracketed ones, their dark frames), RGB24, one after the other at the frames' size:
 *  COLOUR_POOL_FRAMES frames at the compiled frame limit, more of smaller ones (scan_check
 *  refuses a config whose frames do not fit). A view's largest buffer; apart from struct
 *  scan_ctx so that its owner may give it to what comes after the views (the job: the fusion
 *  volume, app/job.c); given to the context by scan_use_light_frames. */
struct scan_light_frames {
    uint8_t rgb[(size_t)COLOUR_POOL_FRAMES * HAL_MAX_PIXELS * 3u];
};

/** One view's buffers and state, from its first frame to its range image and colour: what
 *  scan_begin_view (or scan_capture_view) starts and scan_finish_view completes; the views it
 *  hands out point into it. Tens of MB at the compiled limits: its owner (the job, the
 *  calibration, a command) keeps it static and passes it by pointer, so there is no allocation;
 *  two contexts are two independent views. Its fields are the firmware's own. */
struct scan_ctx {
    struct decode_ctx decode; /* the pattern frames, decoded */
    /* The decoder works in these planes until decode_finish; the range image is made after it
     * in the same memory (tri_range_image), for the frames' bits are not read again: a view is
     * finished once. Why: the two are a view's largest buffers after the frames (19 and 24
     * bytes a pixel), and never needed at once. */
    union {
        struct decode_work decoding;
        struct tri_maps tri; /* the range image */
    } planes;
    /* A view uses these in three phases, one after the other, never two at once: while its
     * frames come (every frame but the white one in RGB, HDR's choice and grey), from its
     * decoding to its range image (the continuous column), and from its colour until the next
     * view's frames come (what the stages after it read). Why: 16 bytes a pixel in buffers of
     * their own, 7 in one memory (scan_release_frames keeps it: the colour stays). */
    union {
        struct {
            uint8_t frame_rgb[HAL_MAX_PIXELS * 3]; /* every other frame, consumed at once */
            uint8_t hdr_choice[HAL_MAX_PIXELS];    /* HDR: the exposure each pixel is read at */
            uint8_t hdr_grey[HAL_MAX_PIXELS]; /* HDR: one exposure of the pattern being merged */
        } taking;
        float column[HAL_MAX_PIXELS]; /* continuous projector column (refine.h) */
        struct {
            uint8_t rgb[HAL_MAX_PIXELS * 3]; /* the view's colour: compensated, or raw */
            float confidence[HAL_MAX_PIXELS];
        } colour;
    } phase;
    uint8_t colour_rgb[HAL_MAX_PIXELS * 3]; /* projector-white frame, kept as the view's colour */
    struct scan_light_frames *light; /* the owner's (scan_use_light_frames); NULL: none yet */
    int light_present[COLOUR_MAX_FRAMES];
    uint8_t view_reason[HAL_MAX_PIXELS]; /* decoded, then refined by each later stage */
    struct scan_params params;           /* of the view being fed */
    uint32_t patterns, lights;           /* its pattern and colour frames */
    uint64_t settled_us; /* when the last light or pattern change had settled (HAL clock; 0: the
                            clock cannot tell) */
};

/** What one view produced. */
struct scan_view_info {
    int32_t angle_mdeg;                       /**< turntable angle of the view */
    uint32_t frames_captured;                 /**< frames taken, retries not counted */
    uint32_t capture_retries;                 /**< captures that had to be repeated */
    uint32_t valid_points;                    /**< pixels with depth and normal */
    uint32_t reason_count[SCAN_REASON_COUNT]; /**< pixels per reason code */
    uint32_t dark_contrast_dn; /**< the median white minus black of the pixels lit but too dark
                                    to decode (SCAN_DARK), grey levels; 0: none */
};

/** One processed view, as a value: what scan_finish_view hands to the stages after it
 *  (registration, cloud, fusion, recolouring), each of which takes it as an argument. Its
 *  pointers lead into the struct scan_ctx it came from: valid until that context's next view
 *  begins. */
struct scan_view {
    uint32_t width, height;   /**< frame size */
    int32_t angle_mdeg;       /**< turntable angle it was taken at */
    struct decode_maps maps;  /**< projector columns (rows), reason per pixel */
    struct tri_range range;   /**< points and normals, camera frame, mm */
    const uint8_t *white_rgb; /**< projector-white frame, RGB24 */
    const uint8_t
        *lights[COLOUR_MAX_FRAMES]; /**< colour frames (colour.h order); NULL: not taken */
    uint8_t *rgb;           /**< the view's colour as saved and fused: compensated, else raw */
    float *confidence;      /**< colour confidence per pixel (COLOUR_NO_ESTIMATE: none) */
    uint32_t colour_method; /**< enum colour_method the colour was made with */
};

/** Where a view restored from its kept range image goes (scan_restore_view): the context's
 *  buffers, to be filled by the caller. */
struct scan_view_fill {
    uint8_t *reason; /**< width * height reason codes */
    float *xyz_mm;   /**< 3 per pixel (valid pixels) */
    float *normal;   /**< 3 per pixel (valid pixels) */
    uint8_t *rgb;    /**< 3 per pixel */
    float *confidence;
};

/** A view as the stages after decoding take it (registration, cloud, fusion), from a range
 *  image kept earlier instead of from frames: @p view points into @p s's buffers, which
 *  @p fill gives to the caller to fill. No colour frames (recolouring needs frames).
 *  @retval 0 @retval -E2BIG larger than the compiled limits */
int scan_restore_view(struct scan_ctx *s, uint32_t width, uint32_t height, int32_t angle_mdeg,
                      uint32_t valid_count, uint32_t colour_method, struct scan_view *view,
                      struct scan_view_fill *fill);

/** Check parameters and calibration against each other and the compiled limits.
 *  @param msg  out: a sentence saying what is wrong
 *  @retval 0 ok @retval -EINVAL */
int scan_check(const struct scan_params *params, const struct scan_calib *calib, char *msg,
               size_t msg_len);

/** Put the rig in its idle state and open the camera. @retval 0 ok @retval what the camera said */
int scan_open(const struct hal *hal, const struct hal_camera_config *cam_cfg);

/** Where the frames of a view go to be kept (the scan directory); optional. */
struct scan_frame_sink {
    /** Keep frame @p pattern: RGB24 (channels 3: the white frame, the colour frames; they stay
     *  as they are until the next view begins) or the decoder's grey (channels 1: valid only
     *  during the call, the decoder reads each frame and lets it go).
     *  @retval 0 ok @retval -errno, which stops the view */
    int (*save)(void *priv, uint32_t pattern, const uint8_t *pixels, uint32_t width,
                uint32_t height, uint32_t channels);
    void *priv;
};

/** What the camera sees of the projector's light at one exposure, from a white and a black
 *  frame: how much of the object it lights, and how much of that is too dark to decode. */
struct scan_contrast {
    uint32_t lit;            /**< pixels whose white minus black is over shadow_contrast_dn */
    uint32_t dark;           /**< of them, under min_contrast_dn: too dark to decode */
    uint32_t dark_median_dn; /**< the median white minus black of the dark ones (0: none) */
};

/** A white and a black projector frame at @p exposure_us (the camera back at the colour
 *  exposure after), without turning the table, measured as the decoder would read them
 *  (decode_rgb_to_grey; a saturated pixel is not dark); projector off again when it returns.
 *  @param out  what they show
 *  @retval 0 ok @retval -EINTR stop requested @retval the camera's or GPIO's error (-ENOSYS: the
 *  camera cannot change its exposure) */
int scan_probe_contrast(struct scan_ctx *s, const struct hal *hal, const struct scan_params *params,
                        const struct scan_calib *calib, uint32_t exposure_us,
                        struct scan_contrast *out);

/** What the white lights show at the camera's exposure, one at a time over a dark frame: how
 *  near the brightest of them brings the object to saturation. */
struct scan_light_probe {
    uint32_t lit;      /**< pixels the brightest light lifts over [colour] shadow_dn (0: none) */
    uint32_t level_dn; /**< their 95th percentile, brightest channel (DECODE_SATURATED: reached
                            saturation_dn) */
    uint32_t dark_dn;  /**< the dark frame's median there, in the same channel */
    uint32_t light;    /**< the brightest light: the one with the highest level_dn */
};

/** A dark frame and each light alone at the camera's exposure, projector off, without turning
 *  the table ([colour] light_exposure_us chosen by the scan: app/job_live.c); lights off again
 *  when it returns, the rig safe on every failure. @param out  what the brightest light shows
 *  @retval 0 ok @retval -EINTR stop requested @retval -EINVAL no memory for the dark frame
 *  (scan_use_light_frames) @retval the camera's or GPIO's error */
int scan_probe_lights(struct scan_ctx *s, const struct hal *hal, const struct scan_params *params,
                      const struct scan_calib *calib, struct scan_light_probe *out);

/** One picture of what the camera sees lit by the projector's white (the web page's live view),
 *  without turning the table; the projector is off again when it returns. Like the probes above
 *  it takes the memory of the last view's colour (scan_ctx.phase): call it once that view has
 *  been saved, as between views.
 *  @param rgb  out: the RGB24 frame (params' width x height), valid until the next capture
 *  @retval 0 ok @retval capture error */
int scan_snapshot(struct scan_ctx *s, const struct hal *hal, const struct scan_params *params,
                  const struct scan_calib *calib, const uint8_t **rgb);

/** Capture one view at the current turntable angle into @p s, without processing it: the
 *  frames wait there for scan_finish_view (which may run while the table turns to the
 *  next view; nothing else may use @p s meanwhile). On any failure the projector and
 *  lights are off when it returns. @param sink  keeps every frame (NULL: not kept)
 *  @param info  out: frames and retries counted
 *  @retval 0 ok @retval -EINTR stop requested @retval capture error */
int scan_capture_view(struct scan_ctx *s, const struct hal *hal, const struct scan_params *params,
                      const struct scan_calib *calib, int32_t angle_mdeg,
                      const struct scan_frame_sink *sink, struct scan_view_info *info);

/** Capture and process one view at the current turntable angle. On any failure the projector
 *  and lights are off when it returns.
 *  @param sink  keeps every frame as captured (NULL: frames are not kept)
 *  @param view  out: the processed view
 *  @retval 0 ok @retval -EINTR stop requested @retval capture or processing error */
int scan_take_view(struct scan_ctx *s, const struct hal *hal, const struct scan_params *params,
                   const struct scan_calib *calib, int32_t angle_mdeg,
                   const struct scan_frame_sink *sink, struct scan_view *view,
                   struct scan_view_info *info);

/** The same processing without a rig, from kept frames (scanner process): begin, feed every
 *  pattern in order (the white frame as RGB, channels 3; the others grey, channels 1, or RGB),
 *  then finish with the parameters given to begin. The live scan runs exactly this path.
 *  @retval 0 or -EINVAL */
int scan_begin_view(struct scan_ctx *s, const struct scan_params *params,
                    const struct scan_calib *calib);
/** Give @p s the memory its colour frames are kept in (its owner's, kept as long as @p s is
 *  used; NULL: none). A view whose method takes colour frames cannot begin without it. */
void scan_use_light_frames(struct scan_ctx *s, struct scan_light_frames *frames);
/** Begin a view's colour only, its range image restored (scan_restore_view): the colour frames
 *  and the white frame are then read into scan_frame_buffer and fed (scan_feed_light_frame),
 *  and scan_attach_colour hands them to the view. The decoder is left as it is.
 *  @retval 0 @retval -EINVAL a frame size beyond the compiled limits, or colour frames to take
 *  and no memory for them (scan_use_light_frames) */
int scan_begin_colour(struct scan_ctx *s, const struct scan_params *params,
                      const struct scan_calib *calib);
/** The frames, the decoder's planes, the projector columns and the range image of the views
 *  taken are not needed again until the next view begins or is restored (scan_begin_view,
 *  scan_begin_colour, scan_restore_view): their memory is given back (mem_release), so that
 *  the stages after the views (the fusion grid, the mesh, the texture) do not add to it. The
 *  view's colour and its reasons stay. */
void scan_release_frames(struct scan_ctx *s);
/** The pattern sequence of a view (columns, and rows when params->decode_rows). */
void scan_layout(const struct scan_params *params, const struct scan_calib *calib,
                 struct gray_layout *layout);
int scan_feed_frame(struct scan_ctx *s, uint32_t pattern, const uint8_t *pixels, uint32_t channels,
                    const struct scan_frame_sink *sink);
/** How frame @p frame of a view (kept-frame order: patterns, lights, HDR colour) is fed and
 *  kept: @retval 3 RGB (the white pattern, the colour frames) @retval 1 grey (the other
 *  patterns, HDR's merged white among them) @retval 0 no such frame */
uint32_t scan_frame_channels(const struct scan_params *params, const struct scan_calib *calib,
                             uint32_t frame);
/** Where frame @p frame of the view begun (kept-frame order: patterns, lights, HDR colour) is
 *  kept once fed: reading a kept frame straight into it spares a copy. @retval the buffer, of
 *  HAL_MAX_PIXELS RGB pixels for the white and colour frames, HAL_MAX_PIXELS grey ones for the
 *  other patterns @retval NULL no such frame */
uint8_t *scan_frame_buffer(struct scan_ctx *s, uint32_t frame);
/** Whether pattern frame @p next may be read into its scan_frame_buffer before pattern frame
 *  @p frame is fed (decode_slot_free_before). @retval 1 it may @retval 0 it may not */
int scan_frame_read_ahead(struct scan_ctx *s, uint32_t frame, uint32_t next);
/** Decode, refine, triangulate, take normals and colour of the frames fed since
 *  scan_begin_view: once (the range image is made where the decoder worked; finishing the same
 *  frames again needs them fed again). @param threads  the cores the per-pixel stages may
 *  split across (NULL: this thread; at most [scan] threads of them): the view the same to the
 *  byte however many
 *  @param view  out @param info  out: reasons counted, valid points */
int scan_finish_view(struct scan_ctx *s, const struct hal_thread *threads,
                     const struct scan_calib *calib, int32_t angle_mdeg, struct scan_view *view,
                     struct scan_view_info *info);

/** Keep samples of @p view as view @p index of the joint registration @p reg (reg_begin
 *  first). */
int scan_keep_for_registration(struct reg_ctx *reg, uint32_t index, const struct scan_view *view);

/** Fuse @p view into the volume @p vol (fusion_begin first) seen through @p obj_from_cam, its
 *  voxels split across @p cores (scan_cores; NULL: this thread). */
int scan_fuse_view(struct fusion_volume *vol, const struct hal_thread *cores,
                   const struct scan_calib *calib, const struct scan_view *view,
                   const struct frame_xform *obj_from_cam);

/** The cores a view's stages may split across: the platform's @p threads (NULL: one), as many
 *  as [scan] threads in @p p allows (0: all of them). */
struct hal_thread scan_cores(const struct hal_thread *threads, const struct scan_params *p);

/** Write @p view's point cloud as binary PLY, through @p obj_from_cam into the object frame.
 *  @retval 0 ok @retval -errno from storage */
int scan_save_cloud(const struct hal *hal, const struct scan_view *view,
                    const struct frame_xform *obj_from_cam, const char *path);

/** Recompute @p view's colour and confidence with other colour parameters (same frames, same
 *  geometry): the white calibration compares the methods on one view; method fit colours with
 *  @p pool (colour_compute; NULL: none). @retval 0 or -EINVAL */
int scan_recolour(const struct colour_params *colour, const struct hal_thread *cores,
                  const struct scan_calib *calib, struct scan_view *view,
                  struct reflect_pool *pool);

/** Point @p view (restored from its range image) at the colour frames fed since
 *  scan_begin_view (scan_feed_light_frame, and the white colour read into scan_frame_buffer),
 *  so that scan_recolour can colour it again. */
void scan_attach_colour(struct scan_ctx *s, struct scan_view *view);

/** Offline, HDR: hand over the view's colour (the white pattern at the camera's exposure; the
 *  white fed to scan_feed_frame is then the merged grey). @retval 0 */
int scan_feed_white_colour(struct scan_ctx *s, const uint8_t *rgb);

/** Colour frames a view takes after its patterns (0 when [colour] method = none). */
uint32_t scan_light_frame_count(const struct scan_params *params, const struct scan_calib *calib);
/** Whether [colour] method reads colour frame @p k (colour_needs_frame): offline, a frame it
 *  does not read is not read back either. @retval 1 @retval 0 */
int scan_needs_light_frame(const struct scan_params *params, const struct scan_calib *calib,
                           uint32_t k);
/** Offline: hand over colour frame @p k (colour.h numbering), RGB24. @retval 0 or -EINVAL */
int scan_feed_light_frame(struct scan_ctx *s, uint32_t k, const uint8_t *rgb);

/** Close the camera and put every device in its safe state. */
void scan_close(const struct hal *hal);

#endif
