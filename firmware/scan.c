/* One view: projector pattern sequence, capture with bounded retries, decode, triangulate. */
#include "scan.h"

#include "frames.h"
#include "fusion.h"
#include "gray.h"
#include "mem.h"
#include "colour.h"
#include "ply.h"
#include "refine.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

/* The pixels of a frame of @p p. */
static size_t frame_pixels(const struct scan_params *p)
{
    return (size_t)p->width * p->height;
}

int scan_check(const struct scan_params *p, const struct scan_calib *c, char *msg, size_t len)
{
    if (p->width > HAL_MAX_WIDTH || p->height > HAL_MAX_HEIGHT) {
        snprintf(msg, len, "camera %ux%u exceeds the compiled limit %ux%u", (unsigned)p->width,
                 (unsigned)p->height, HAL_MAX_WIDTH, HAL_MAX_HEIGHT);
        return -EINVAL;
    }
    if (c->cam_width != p->width || c->cam_height != p->height) {
        snprintf(msg, len,
                 "calibration is for a %ux%u camera but the camera is set to %ux%u ([camera] "
                 "width and height: set them to %ux%u, or calibrate the camera at %ux%u with "
                 "'scanner calibrate')",
                 (unsigned)c->cam_width, (unsigned)c->cam_height, (unsigned)p->width,
                 (unsigned)p->height, (unsigned)c->cam_width, (unsigned)c->cam_height,
                 (unsigned)p->width, (unsigned)p->height);
        return -EINVAL;
    }
    if (c->proj_width == 0 || c->proj_width > HAL_MAX_PROJECTOR_WIDTH) {
        snprintf(msg, len, "projector width %u outside 1..%u", (unsigned)c->proj_width,
                 HAL_MAX_PROJECTOR_WIDTH);
        return -EINVAL;
    }
    if (c->light_count > HAL_MAX_LIGHTS) {
        snprintf(msg, len, "%u lights exceed the compiled limit %u", (unsigned)c->light_count,
                 HAL_MAX_LIGHTS);
        return -EINVAL;
    }
    if (p->colour.method != COLOUR_NONE && p->colour.bracket > 1 &&
        c->light_count > COLOUR_MAX_BRACKETED) {
        snprintf(msg, len,
                 "[colour] bracket: %u lights, but this build can bracket %u "
                 "(COLOUR_MAX_BRACKETED; a LIMITS=small build has no room for the frames): set "
                 "bracket = 0",
                 (unsigned)c->light_count, COLOUR_MAX_BRACKETED);
        return -EINVAL;
    }
    /* the colour frames a view may take: the lights' exposure, when the scan is to choose it,
     * counted as one of its own (a dark frame more) */
    struct colour_params most = p->colour;
    if (most.light_exposure_us == 0)
        most.light_exposure_us = most.exposure_us + 1u;
    struct colour_layout lay;
    colour_layout(&most, c->light_count, &lay);
    if ((uint64_t)lay.count * p->width * p->height >
        (uint64_t)COLOUR_POOL_FRAMES * HAL_MAX_PIXELS) {
        snprintf(msg, len,
                 "[colour]: %u colour frames a view of %ux%u (%u lights%s) are more than this "
                 "build keeps (%u of %ux%u, COLOUR_POOL_FRAMES): fewer lights, bracket = 0, or "
                 "[camera] binning",
                 (unsigned)lay.count, (unsigned)p->width, (unsigned)p->height,
                 (unsigned)c->light_count, lay.long_of[COLOUR_FRAME_LIGHT0] ? ", bracketed" : "",
                 COLOUR_POOL_FRAMES, HAL_MAX_WIDTH, HAL_MAX_HEIGHT);
        return -EINVAL;
    }
    return 0;
}

int scan_open(const struct hal *hal, const struct hal_camera_config *cam_cfg)
{
    int rc = hal->gpio.ops->safe_state(hal->gpio.priv);
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR, "gpio: cannot switch lights and projector off: %s", strerror(-rc));
        return rc;
    }
    rc = hal_cam_open(&hal->camera, cam_cfg);
    if (rc != 0)
        hal->log(HAL_LOG_ERROR, "camera: cannot open '%s' at %ux%u: %s", cam_cfg->device,
                 (unsigned)cam_cfg->width, (unsigned)cam_cfg->height, strerror(-rc));
    return rc;
}

/* Wait for a light or pattern change to take effect, and remember when it had. */
static int settle(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p)
{
    int rc = hal_clock_sleep_us(&hal->clock, p->pattern_settle_us);
    if (rc == 0 && hal_clock_now_us(&hal->clock, &s->settled_us) != 0)
        s->settled_us = 0;
    return rc;
}

/* A frame whose exposure began before the change had settled shows the old pattern or lights
 * (a camera delivering a frame it had in flight): it is discarded like a corrupt one. */
static int check_fresh(struct scan_ctx *s, const struct hal *hal, const struct hal_image *img,
                       uint32_t pattern)
{
    if (img->start_us == 0 || s->settled_us == 0 || img->start_us >= s->settled_us)
        return 0;
    hal->log(HAL_LOG_WARN,
             "camera: frame %llu for pattern %u began %llu us before the change had settled "
             "(a stale frame); discarded",
             (unsigned long long)img->sequence, (unsigned)pattern,
             (unsigned long long)(s->settled_us - img->start_us));
    return -EAGAIN;
}

/* Capture into @p buf, retrying faults that a second try can cure (timeout, corrupt or stale
 * frame). */
static int capture(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p,
                   uint8_t *buf, uint32_t pattern, struct scan_view_info *info)
{
    struct hal_image img = {.rgb = buf, .capacity = sizeof(s->phase.taking.frame_rgb)};
    int rc = -EIO;
    for (uint32_t attempt = 0; attempt <= p->capture_retries; attempt++) {
        if (attempt > 0)
            info->capture_retries++;
        rc = hal_cam_capture(&hal->camera, &img);
        if (rc == 0 && (img.width != p->width || img.height != p->height))
            rc = -EIO; /* a frame of the wrong size is as bad as a corrupt one */
        if (rc == 0)
            rc = check_fresh(s, hal, &img, pattern);
        if (rc == 0)
            return 0;
        if (rc != -EAGAIN)
            hal->log(HAL_LOG_WARN, "camera: capture of pattern %u failed (%s), try %u of %u",
                     (unsigned)pattern, strerror(-rc), (unsigned)attempt + 1,
                     (unsigned)p->capture_retries + 1);
        if (rc != -ETIMEDOUT && rc != -EIO && rc != -EAGAIN)
            break;
    }
    if (rc == -EAGAIN) {
        hal->log(HAL_LOG_ERROR,
                 "camera: giving up on pattern %u: every frame began before the change had "
                 "settled (raise [camera] drop_frames or [projector] settle_us)",
                 (unsigned)pattern);
        return -EIO;
    }
    hal->log(HAL_LOG_ERROR, "camera: giving up on pattern %u: %s", (unsigned)pattern,
             strerror(-rc));
    return rc;
}

static int lights_off(const struct hal *hal, uint32_t light_count)
{
    int rc = 0;
    for (uint32_t i = 0; i < light_count && rc == 0; i++)
        rc = hal_gpio_set(&hal->gpio, (enum hal_gpio_line)(HAL_GPIO_LIGHT_0 + i), 0);
    return rc;
}

/* Show pattern 0 (white) with only the projector lighting the object. */
static int projector_start(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p,
                           uint32_t lights)
{
    int rc = lights_off(hal, lights);
    if (rc == 0)
        rc = hal_gpio_set(&hal->gpio, HAL_GPIO_PROJECTOR_ENABLE, 1);
    if (rc == 0)
        rc = hal_gpio_pulse(&hal->gpio, &hal->clock, HAL_GPIO_PROJECTOR_RESET, p->trigger_pulse_us);
    if (rc == 0)
        rc = settle(s, hal, p);
    return rc;
}

void scan_layout(const struct scan_params *p, const struct scan_calib *c, struct gray_layout *l)
{
    gray_layout_for(c->proj_width, c->proj_height, (int)p->decode_rows, l);
    l->code = p->code;
    l->inverse_bits = p->inverse_bits;
}

/* Colour frame @p k of a view of @p n pixels, where the frames' memory keeps it (one after the
 * other at their size), or NULL: no memory (lent, app/job.c), or not that much of it. */
static uint8_t *light_frame(const struct scan_ctx *s, uint32_t k, size_t n)
{
    if (s->light == NULL || ((size_t)k + 1u) * n * 3u > sizeof(s->light->rgb))
        return NULL;
    return s->light->rgb + (size_t)k * n * 3u;
}

/* The pixel buffers a view of @p n pixels writes whole (its colour and reasons), mapped ahead
 * (mem.h). */
static void prefault_colour(struct scan_ctx *s, size_t n)
{
    mem_prefault(s->phase.colour.rgb, n * 3);
    mem_prefault(s->phase.colour.confidence, n * sizeof(s->phase.colour.confidence[0]));
    mem_prefault(s->view_reason, n);
}

/* ... and the colour frames its method reads (of layout @p lay), with the white frame kept as
 * its colour. */
static void prefault_colour_frames(struct scan_ctx *s, const struct scan_params *p,
                                   const struct colour_layout *lay)
{
    size_t n = frame_pixels(p);
    mem_prefault(s->colour_rgb, n * 3);
    for (uint32_t k = 0; k < lay->count && k < COLOUR_MAX_FRAMES; k++)
        if (colour_needs_frame(&p->colour, lay, k))
            mem_prefault(light_frame(s, k, n), n * 3);
}

/* The points' buffers (written only where a pixel decoded), mapped ahead from the first row
 * with a decoded pixel to the last: the rows of background above and below stay unmapped. */
static void prefault_points(struct scan_ctx *s, const struct decode_maps *m)
{
    size_t w = m->width, first = m->height, last = 0;
    for (size_t y = 0; y < m->height; y++)
        if (memchr(m->reason + y * w, SCAN_VALID, w) != NULL)
            first = first < y ? first : y, last = y;
    if (first > last)
        return;
    size_t i = first * w, n = (last + 1 - first) * w;
    mem_prefault(s->phase.column + i, n * sizeof(s->phase.column[0]));
    mem_prefault(s->planes.tri.xyz_mm + 3 * i, 3 * n * sizeof(s->planes.tri.xyz_mm[0]));
    mem_prefault(s->planes.tri.normal + 3 * i, 3 * n * sizeof(s->planes.tri.normal[0]));
}

void scan_use_light_frames(struct scan_ctx *s, struct scan_light_frames *frames)
{
    s->light = frames;
}

int scan_begin_colour(struct scan_ctx *s, const struct scan_params *p, const struct scan_calib *c)
{
    struct gray_layout layout;
    struct colour_layout lay;
    if (p->width == 0 || p->height == 0 || p->width > HAL_MAX_WIDTH || p->height > HAL_MAX_HEIGHT)
        return -EINVAL;
    colour_layout(&p->colour, c->light_count, &lay);
    if (lay.count > 0 && light_frame(s, lay.count - 1u, frame_pixels(p)) == NULL)
        return -EINVAL; /* no memory for them, or not enough (scan_check) */
    s->params = *p;
    memset(s->light_present, 0, sizeof(s->light_present));
    scan_layout(p, c, &layout);
    s->patterns = gray_layout_count(&layout);
    s->lights = lay.count; /* scan_light_frame_count */
    prefault_colour_frames(s, p, &lay);
    return 0;
}

int scan_begin_view(struct scan_ctx *s, const struct scan_params *p, const struct scan_calib *c)
{
    struct gray_layout layout;
    scan_layout(p, c, &layout);
    int rc =
        decode_begin(&s->decode, &s->planes.decoding, p, &layout, c->proj_width, c->proj_height);
    if (rc == 0)
        rc = scan_begin_colour(s, p, c);
    if (rc != 0)
        return rc;
    size_t n = frame_pixels(p);
    prefault_colour(s, n); /* (the decoder's buffers are its own: decode_begin) */
    if (p->exposure_count > 0) {
        mem_prefault(s->phase.taking.hdr_choice, n);
        mem_prefault(s->phase.taking.hdr_grey, n);
    }
    return 0;
}

void scan_release_frames(struct scan_ctx *s)
{
    decode_release(&s->decode);
    mem_release(&s->planes, sizeof(s->planes)); /* the decoder's working planes, the range image */
    mem_release(s->colour_rgb, sizeof(s->colour_rgb));
    if (s->light != NULL)
        mem_release(s->light, sizeof(*s->light));
    memset(s->light_present, 0, sizeof(s->light_present));
    /* not s->phase: the view's colour is in it */
}

int scan_feed_frame(struct scan_ctx *s, uint32_t pattern, const uint8_t *pixels, uint32_t channels,
                    const struct scan_frame_sink *sink)
{
    size_t n = frame_pixels(&s->params);
    const uint8_t *grey = pixels;
    uint8_t *slot = decode_frame_slot(&s->decode, pattern);
    if (slot == NULL)
        return -EINVAL;
    int colour = channels == 3 && pattern == GRAY_PATTERN_WHITE;
    if (channels == 3) {
        if (colour && pixels != s->colour_rgb)
            memcpy(s->colour_rgb, pixels, n * 3); /* the view's colour */
        decode_rgb_to_grey(pixels, slot, n, s->params.saturation_dn);
        grey = slot; /* converted straight into the decoder's store */
    }
    int rc = decode_frame(&s->decode, pattern, grey);
    /* The white frame is kept in colour (its grey is derived again offline); the others are
     * kept exactly as the decoder saw them. */
    if (rc == 0 && sink != NULL && sink->save != NULL)
        rc = colour ? sink->save(sink->priv, pattern, s->colour_rgb, s->params.width,
                                 s->params.height, 3)
                    : sink->save(sink->priv, pattern, grey, s->params.width, s->params.height, 1);
    return rc;
}

uint32_t scan_frame_channels(const struct scan_params *p, const struct scan_calib *c,
                             uint32_t frame)
{
    struct gray_layout layout;
    scan_layout(p, c, &layout);
    uint32_t count = gray_layout_count(&layout);
    int hdr = p->exposure_count > 0; /* the patterns merged grey, the colour after the lights */
    if (frame >= count + scan_light_frame_count(p, c) + (hdr ? 1u : 0u))
        return 0;
    return (frame == GRAY_PATTERN_WHITE && !hdr) || frame >= count ? 3u : 1u;
}

uint8_t *scan_frame_buffer(struct scan_ctx *s, uint32_t frame)
{
    uint32_t count = s->patterns, lights = s->lights;
    int hdr = s->params.exposure_count > 0;
    if (frame < count)
        return frame == GRAY_PATTERN_WHITE && !hdr ? s->colour_rgb
                                                   : decode_frame_slot(&s->decode, frame);
    if (frame < count + lights)
        return light_frame(s, frame - count, frame_pixels(&s->params));
    return hdr && frame == count + lights ? s->colour_rgb : NULL;
}

int scan_frame_read_ahead(struct scan_ctx *s, uint32_t frame, uint32_t next)
{
    /* a pattern's buffer is its decoder slot but the white frame's, the view's colour, which
     * is no slot: the decoder's answer is the whole answer */
    return decode_slot_free_before(&s->decode, frame, next);
}

int scan_feed_white_colour(struct scan_ctx *s, const uint8_t *rgb)
{
    if (rgb != s->colour_rgb)
        memcpy(s->colour_rgb, rgb, frame_pixels(&s->params) * 3);
    return 0;
}

uint32_t scan_light_frame_count(const struct scan_params *p, const struct scan_calib *c)
{
    struct colour_layout lay;
    colour_layout(&p->colour, c->light_count, &lay);
    return lay.count;
}

int scan_needs_light_frame(const struct scan_params *p, const struct scan_calib *c, uint32_t k)
{
    struct colour_layout lay;
    colour_layout(&p->colour, c->light_count, &lay);
    return colour_needs_frame(&p->colour, &lay, k);
}

int scan_feed_light_frame(struct scan_ctx *s, uint32_t k, const uint8_t *rgb)
{
    uint8_t *frame = light_frame(s, k, frame_pixels(&s->params));
    if (k >= COLOUR_MAX_FRAMES || frame == NULL)
        return -EINVAL;
    if (rgb != frame)
        memcpy(frame, rgb, frame_pixels(&s->params) * 3);
    s->light_present[k] = 1;
    return 0;
}

/* The grey level at or under which @p percent of a histogram's @p total pixels lie (50: the
 * median; 0: no pixels). */
static uint32_t hist_percentile(const uint32_t hist[256], uint32_t total, uint32_t percent)
{
    for (uint32_t v = 0, seen = 0; v < 256 && total > 0; v++) {
        seen += hist[v];
        if (100u * (uint64_t)seen >= (uint64_t)percent * total)
            return v;
    }
    return 0;
}

/* A view's pixels per reason and the contrast of its dark ones, counted by parts of the image
 * (integers: the same counts on any number of threads). */
struct reason_parts {
    const struct scan_ctx *s;
    size_t pixels;
    unsigned parts;
    uint32_t count[HAL_MAX_PARTS][SCAN_REASON_COUNT];
    uint32_t dark_hist[HAL_MAX_PARTS][256];
};

static void reason_part(void *arg, unsigned k)
{
    struct reason_parts *p = arg;
    const struct scan_ctx *s = p->s;
    /* counted on the stack: the compiler cannot tell the reason bytes from counts in memory */
    uint32_t count[SCAN_REASON_COUNT] = {0}, dark_hist[256] = {0};
    for (size_t i = p->pixels * k / p->parts; i < p->pixels * (k + 1u) / p->parts; i++) {
        count[s->view_reason[i]]++;
        if (s->view_reason[i] == SCAN_DARK && s->decode.white[i] > s->decode.black[i])
            dark_hist[s->decode.white[i] - s->decode.black[i]]++;
    }
    memcpy(p->count[k], count, sizeof(count));
    memcpy(p->dark_hist[k], dark_hist, sizeof(dark_hist));
}

static void count_reasons(const struct scan_ctx *s, const struct hal_thread *cores,
                          struct scan_view_info *info)
{
    static struct reason_parts p; /* 34 KiB of counts: one view is finished at a time */
    p.s = s;
    p.pixels = frame_pixels(&s->params);
    p.parts = hal_thread_parts(cores, HAL_MAX_PARTS);
    hal_thread_run(cores, p.parts, reason_part, &p);
    uint32_t dark_hist[256] = {0}, dark_n = 0;
    memset(info->reason_count, 0, sizeof(info->reason_count));
    for (unsigned k = 0; k < p.parts; k++) {
        for (unsigned r = 0; r < SCAN_REASON_COUNT; r++)
            info->reason_count[r] += p.count[k][r];
        for (unsigned v = 0; v < 256; v++)
            dark_hist[v] += p.dark_hist[k][v], dark_n += p.dark_hist[k][v];
    }
    info->valid_points = info->reason_count[SCAN_VALID];
    info->dark_contrast_dn = hist_percentile(dark_hist, dark_n, 50);
}

int scan_finish_view(struct scan_ctx *s, const struct hal_thread *threads,
                     const struct scan_calib *c, int32_t angle_mdeg, struct scan_view *view,
                     struct scan_view_info *info)
{
    struct hal_thread cores = scan_cores(threads, &s->params);
    memset(view, 0, sizeof(*view));
    view->width = s->params.width;
    view->height = s->params.height;
    view->angle_mdeg = angle_mdeg;
    view->white_rgb = s->colour_rgb;
    for (uint32_t k = 0; k < COLOUR_MAX_FRAMES; k++)
        view->lights[k] = s->light_present[k] ? light_frame(s, k, frame_pixels(&s->params)) : NULL;
    view->rgb = s->phase.colour.rgb;
    view->confidence = s->phase.colour.confidence;
    int rc = decode_finish(&s->decode, &cores, s->view_reason, &view->maps);
    if (rc == 0)
        prefault_points(s, &view->maps);
    if (rc == 0)
        rc = refine_columns(&view->maps, &cores, (int)s->params.refine, s->phase.column);
    if (rc == 0) /* the column's last use: the colour made next takes its memory */
        rc = tri_range_image(c, &cores, &s->planes.tri, view->width, view->height, s->phase.column,
                             s->view_reason, &view->range);
    if (rc == 0)
        rc = tri_normals(&s->planes.tri, &cores, &view->range, s->view_reason,
                         s->params.normal_radius_px, s->params.max_depth_jump_mm);
    if (rc == 0)
        rc = scan_recolour(&s->params.colour, &cores, c, view, NULL); /* fit: multi's, until the
                                                                   job's model colours it */
    if (rc != 0)
        return rc;
    info->angle_mdeg = angle_mdeg;
    count_reasons(s, &cores, info);
    return 0;
}

int scan_restore_view(struct scan_ctx *s, uint32_t width, uint32_t height, int32_t angle_mdeg,
                      uint32_t valid_count, uint32_t colour_method, struct scan_view *view,
                      struct scan_view_fill *fill)
{
    memset(view, 0, sizeof(*view));
    int rc = tri_restore(&s->planes.tri, width, height, valid_count, &view->range);
    if (rc != 0)
        return rc;
    prefault_colour(s, (size_t)width * height);
    fill->xyz_mm = s->planes.tri.xyz_mm;
    fill->normal = s->planes.tri.normal;
    view->width = width;
    view->height = height;
    view->angle_mdeg = angle_mdeg;
    view->maps = (struct decode_maps){.reason = s->view_reason, .width = width, .height = height};
    view->rgb = fill->rgb = s->phase.colour.rgb;
    view->confidence = fill->confidence = s->phase.colour.confidence;
    view->colour_method = colour_method;
    fill->reason = s->view_reason;
    return 0;
}

/* HDR: pattern @p i at every exposure, merged in the decoder's slot before it is fed: each
 * pixel at the exposure s->phase.taking.hdr_choice holds, chosen on the white pattern as the
 * longest whose white is not saturated (the brightest unsaturated). The pixel's patterns, inverses,
 * white and black are then all read at one exposure, so the decoder's comparisons stay within it
 * and need no scaling. The white at the camera's own exposure is kept as the view's colour.
 * @p exposure_us  in/out: the camera's exposure now */
static int capture_hdr(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p,
                       uint32_t i, uint32_t *exposure_us, struct scan_view_info *info)
{
    const size_t n = frame_pixels(p);
    uint8_t *slot = decode_frame_slot(&s->decode, i);
    int rc = 0;
    for (uint32_t e = 0; e < p->exposure_count && rc == 0; e++) {
        if (p->exposures_us[e] != *exposure_us) {
            rc = hal_cam_set_exposure(&hal->camera, p->exposures_us[e], p->colour.gain_milli);
            *exposure_us = p->exposures_us[e];
        }
        int colour = i == GRAY_PATTERN_WHITE && p->exposures_us[e] == p->colour.exposure_us;
        uint8_t *buf = colour ? s->colour_rgb : s->phase.taking.frame_rgb;
        if (rc == 0)
            rc = capture(s, hal, p, buf, i, info);
        if (rc != 0)
            break;
        info->frames_captured++;
        decode_rgb_to_grey(buf, s->phase.taking.hdr_grey, n, p->saturation_dn);
        if (i == GRAY_PATTERN_WHITE) /* ascending: a longer unsaturated exposure wins */
            for (size_t k = 0; k < n; k++)
                if (e == 0 || s->phase.taking.hdr_grey[k] != DECODE_SATURATED)
                    s->phase.taking.hdr_choice[k] = (uint8_t)e;
        for (size_t k = 0; k < n; k++)
            if (s->phase.taking.hdr_choice[k] == e)
                slot[k] = s->phase.taking.hdr_grey[k];
    }
    return rc;
}

/* One pattern as the decoder takes it: RGB at the camera's exposure, or merged HDR grey. */
static int capture_pattern(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p,
                           uint32_t i, const struct scan_frame_sink *sink, uint32_t *exposure_us,
                           struct scan_view_info *info)
{
    if (p->exposure_count > 0) {
        int rc = capture_hdr(s, hal, p, i, exposure_us, info);
        return rc != 0 ? rc : scan_feed_frame(s, i, decode_frame_slot(&s->decode, i), 1, sink);
    }
    uint8_t *buf = i == GRAY_PATTERN_WHITE ? s->colour_rgb : s->phase.taking.frame_rgb;
    int rc = capture(s, hal, p, buf, i, info);
    if (rc != 0)
        return rc;
    info->frames_captured++;
    return scan_feed_frame(s, i, buf, 3, sink);
}

static int capture_sequence(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p,
                            uint32_t count, const struct scan_frame_sink *sink,
                            uint32_t *exposure_us, struct scan_view_info *info)
{
    for (uint32_t i = 0; i < count; i++) {
        if (hal_should_stop(hal))
            return -EINTR;
        int rc = capture_pattern(s, hal, p, i, sink, exposure_us, info);
        if (rc != 0)
            return rc;
        if (i + 1 == count)
            break;
        rc = hal_gpio_pulse(&hal->gpio, &hal->clock, HAL_GPIO_PROJECTOR_TRIGGER,
                            p->trigger_pulse_us);
        if (rc == 0)
            rc = settle(s, hal, p);
        if (rc != 0)
            return rc;
    }
    return 0;
}

/* Back to the camera's own exposure from @p exposure_us (the HDR patterns' or the colour
 * frames' last). @retval 0 or the camera's error */
static int camera_exposure_back(const struct hal *hal, const struct scan_params *p,
                                uint32_t exposure_us)
{
    if (exposure_us == p->colour.exposure_us)
        return 0;
    return hal_cam_set_exposure(&hal->camera, p->colour.exposure_us, p->colour.gain_milli);
}

/* Every pattern of the sequence, the camera back at its own exposure after (also on failure). */
static int capture_patterns(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p,
                            uint32_t count, const struct scan_frame_sink *sink,
                            struct scan_view_info *info)
{
    uint32_t exposure_us = p->colour.exposure_us;
    int rc = capture_sequence(s, hal, p, count, sink, &exposure_us, info);
    int rc_exp = camera_exposure_back(hal, p, exposure_us);
    rc = rc != 0 ? rc : rc_exp;
    if (rc == -ENOSYS)
        hal->log(HAL_LOG_ERROR, "camera: cannot change the exposure for HDR patterns; leave "
                                "[scan] exposures_us empty");
    return rc;
}

/* The colour frames (colour_layout): projector off, each with its lights and exposure; lights off
 * and the camera back at its own exposure after, also on failure. */
static int capture_lights(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p,
                          const struct scan_calib *c, uint32_t first_index,
                          const struct scan_frame_sink *sink, struct scan_view_info *info)
{
    int rc = 0;
    struct colour_layout lay;
    colour_layout(&p->colour, c->light_count, &lay);
    uint32_t exposure_us = p->colour.exposure_us;
    for (uint32_t k = 0; k < lay.count && rc == 0; k++) {
        for (uint32_t l = 0; l < c->light_count && rc == 0; l++)
            rc = hal_gpio_set(&hal->gpio, (enum hal_gpio_line)(HAL_GPIO_LIGHT_0 + l),
                              (lay.lights_mask[k] >> l) & 1u);
        if (rc == 0 && lay.exposure_us[k] != exposure_us) {
            rc = hal_cam_set_exposure(&hal->camera, lay.exposure_us[k], p->colour.gain_milli);
            exposure_us = lay.exposure_us[k];
        }
        if (rc == 0)
            rc = settle(s, hal, p);
        if (rc == 0 && hal_should_stop(hal))
            rc = -EINTR;
        uint8_t *frame = light_frame(s, k, frame_pixels(p)); /* scan_begin_view: it fits */
        if (rc == 0)
            rc = capture(s, hal, p, frame, first_index + k, info);
        if (rc == 0) {
            info->frames_captured++;
            rc = scan_feed_light_frame(s, k, frame);
        }
        if (rc == 0 && sink != NULL && sink->save != NULL)
            rc = sink->save(sink->priv, first_index + k, frame, p->width, p->height, 3);
    }
    int rc_off = lights_off(hal, c->light_count);
    int rc_exp = camera_exposure_back(hal, p, exposure_us);
    rc_off = rc_off != 0 ? rc_off : rc_exp;
    if (rc == -ENOSYS)
        hal->log(HAL_LOG_ERROR, "camera: cannot change the exposure for the colour frames; set "
                                "[colour] all_lights_exposure_us and light_exposure_us to 0");
    return rc != 0 ? rc : rc_off;
}

int scan_snapshot(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p,
                  const struct scan_calib *c, const uint8_t **rgb)
{
    struct scan_view_info info;
    memset(&info, 0, sizeof(info));
    int rc = projector_start(s, hal, p, c->light_count);
    if (rc == 0)
        rc = capture(s, hal, p, s->phase.taking.frame_rgb, 0, &info);
    /* the projector off again at once, and the rig safe on every failure */
    int rc_off = hal_gpio_set(&hal->gpio, HAL_GPIO_PROJECTOR_ENABLE, 0);
    if (rc != 0 || rc_off != 0)
        hal->gpio.ops->safe_state(hal->gpio.priv);
    *rgb = s->phase.taking.frame_rgb;
    return rc != 0 ? rc : rc_off;
}

/* The white (in s->colour_rgb) and black (in s->phase.taking.frame_rgb) projector frames at @p
 * exposure_us, the camera back at the colour exposure after. */
static int capture_white_black(struct scan_ctx *s, const struct hal *hal,
                               const struct scan_params *p, const struct scan_calib *c,
                               uint32_t exposure_us, struct scan_view_info *info)
{
    int rc = exposure_us == p->colour.exposure_us
                 ? 0
                 : hal_cam_set_exposure(&hal->camera, exposure_us, p->colour.gain_milli);
    if (rc == 0)
        rc = projector_start(s, hal, p, c->light_count); /* it shows the white pattern */
    if (rc == 0 && hal_should_stop(hal))
        rc = -EINTR;
    if (rc == 0)
        rc = capture(s, hal, p, s->colour_rgb, GRAY_PATTERN_WHITE, info);
    if (rc == 0)
        rc = hal_gpio_pulse(&hal->gpio, &hal->clock, HAL_GPIO_PROJECTOR_TRIGGER,
                            p->trigger_pulse_us);
    if (rc == 0)
        rc = settle(s, hal, p);
    if (rc == 0)
        rc = capture(s, hal, p, s->phase.taking.frame_rgb, GRAY_PATTERN_BLACK, info);
    int rc_exp = camera_exposure_back(hal, p, exposure_us);
    return rc != 0 ? rc : rc_exp;
}

int scan_probe_contrast(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p,
                        const struct scan_calib *c, uint32_t exposure_us, struct scan_contrast *out)
{
    struct scan_view_info info;
    memset(&info, 0, sizeof(info));
    memset(out, 0, sizeof(*out));
    int rc = capture_white_black(s, hal, p, c, exposure_us, &info);
    /* the projector off again at once, and the rig safe on every failure */
    int rc_off = hal_gpio_set(&hal->gpio, HAL_GPIO_PROJECTOR_ENABLE, 0);
    if (rc != 0 || rc_off != 0) {
        hal->gpio.ops->safe_state(hal->gpio.priv);
        return rc != 0 ? rc : rc_off;
    }
    const size_t n = frame_pixels(p);
    uint8_t *white = s->phase.taking.hdr_grey,
            *black = s->phase.taking.hdr_choice; /* both free once a view is saved */
    decode_rgb_to_grey(s->colour_rgb, white, n, p->saturation_dn);
    decode_rgb_to_grey(s->phase.taking.frame_rgb, black, n, p->saturation_dn);
    uint32_t hist[256] = {0};
    for (size_t i = 0; i < n; i++) {
        if (white[i] == DECODE_SATURATED || white[i] <= black[i] ||
            (uint32_t)(white[i] - black[i]) <= p->shadow_contrast_dn)
            continue;
        uint32_t contrast = (uint32_t)(white[i] - black[i]);
        out->lit++;
        if (contrast < p->min_contrast_dn)
            out->dark++, hist[contrast]++;
    }
    out->dark_median_dn = hist_percentile(hist, out->dark, 50);
    return 0;
}

/* What light frame @p lit shows over @p dark (both RGB24, @p n pixels): of the pixels it lifts
 * over @p shadow_dn in some channel, the brightest channel's level (DECODE_SATURATED where a
 * channel reaches @p saturation_dn) and the dark frame's in that channel, counted. */
static void light_levels(const uint8_t *lit, const uint8_t *dark, size_t n, double shadow_dn,
                         uint32_t saturation_dn, uint32_t level_hist[256], uint32_t dark_hist[256],
                         uint32_t *count)
{
    memset(level_hist, 0, 256 * sizeof(uint32_t));
    memset(dark_hist, 0, 256 * sizeof(uint32_t));
    *count = 0;
    for (size_t i = 0; i < n; i++) {
        const uint8_t *l = lit + 3 * i, *d = dark + 3 * i;
        unsigned top = 0, lift = 0, sat = 0;
        for (unsigned ch = 0; ch < 3; ch++) {
            unsigned up = l[ch] > d[ch] ? (unsigned)(l[ch] - d[ch]) : 0u;
            if (l[ch] > l[top])
                top = ch;
            lift = up > lift ? up : lift;
            sat |= l[ch] >= saturation_dn;
        }
        if ((double)lift <= shadow_dn)
            continue;
        level_hist[sat ? DECODE_SATURATED : l[top]]++;
        dark_hist[d[top]]++;
        (*count)++;
    }
}

int scan_probe_lights(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p,
                      const struct scan_calib *c, struct scan_light_probe *out)
{
    static uint32_t level_hist[256], dark_hist[256]; /* one probe at a time, as one view */
    struct scan_view_info info;
    memset(&info, 0, sizeof(info));
    memset(out, 0, sizeof(*out));
    const size_t n = frame_pixels(p);
    uint8_t *dark = light_frame(s, COLOUR_FRAME_DARK, n); /* free between views */
    if (dark == NULL || n > HAL_MAX_PIXELS)
        return -EINVAL;
    int rc = hal_gpio_set(&hal->gpio, HAL_GPIO_PROJECTOR_ENABLE, 0);
    for (uint32_t l = 0; l <= c->light_count && rc == 0; l++) { /* dark, then each light */
        rc = lights_off(hal, c->light_count);
        if (rc == 0 && l > 0)
            rc = hal_gpio_set(&hal->gpio, (enum hal_gpio_line)(HAL_GPIO_LIGHT_0 + l - 1), 1);
        if (rc == 0)
            rc = settle(s, hal, p);
        if (rc == 0 && hal_should_stop(hal))
            rc = -EINTR;
        if (rc == 0)
            rc = capture(s, hal, p, l == 0 ? dark : s->phase.taking.frame_rgb,
                         l == 0 ? COLOUR_FRAME_DARK : COLOUR_FRAME_LIGHT0 + l - 1, &info);
        if (rc != 0 || l == 0)
            continue;
        uint32_t count;
        light_levels(s->phase.taking.frame_rgb, dark, n, p->colour.shadow_dn, p->saturation_dn,
                     level_hist, dark_hist, &count);
        uint32_t level = hist_percentile(level_hist, count, 95);
        if (count > 0 && (out->lit == 0 || level > out->level_dn))
            *out = (struct scan_light_probe){.lit = count,
                                             .level_dn = level,
                                             .dark_dn = hist_percentile(dark_hist, count, 50),
                                             .light = l - 1};
    }
    /* the lights off again at once, and the rig safe on every failure */
    int rc_off = lights_off(hal, c->light_count);
    if (rc != 0 || rc_off != 0) {
        hal->gpio.ops->safe_state(hal->gpio.priv);
        return rc != 0 ? rc : rc_off;
    }
    return 0;
}

int scan_capture_view(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p,
                      const struct scan_calib *c, int32_t angle_mdeg,
                      const struct scan_frame_sink *sink, struct scan_view_info *info)
{
    memset(info, 0, sizeof(*info));
    info->angle_mdeg = angle_mdeg;
    int rc = scan_begin_view(s, p, c);
    if (rc != 0)
        return rc;
    struct gray_layout layout;
    scan_layout(p, c, &layout);
    uint32_t count = gray_layout_count(&layout);
    rc = projector_start(s, hal, p, c->light_count);
    if (rc == 0)
        rc = capture_patterns(s, hal, p, count, sink, info);
    /* Projector off as soon as the last frame is in, and on every failure. */
    int rc_off = hal_gpio_set(&hal->gpio, HAL_GPIO_PROJECTOR_ENABLE, 0);
    if (rc == 0 && rc_off == 0)
        rc = capture_lights(s, hal, p, c, count, sink, info);
    /* HDR: the pattern frames are merged grey; the view's colour is kept after the lights. */
    if (rc == 0 && rc_off == 0 && p->exposure_count > 0 && sink != NULL && sink->save != NULL)
        rc = sink->save(sink->priv, count + scan_light_frame_count(p, c), s->colour_rgb, p->width,
                        p->height, 3);
    if (rc != 0 || rc_off != 0)
        goto out_safe;
    return 0;
out_safe:
    hal->gpio.ops->safe_state(hal->gpio.priv);
    return rc != 0 ? rc : rc_off;
}

int scan_take_view(struct scan_ctx *s, const struct hal *hal, const struct scan_params *p,
                   const struct scan_calib *c, int32_t angle_mdeg,
                   const struct scan_frame_sink *sink, struct scan_view *view,
                   struct scan_view_info *info)
{
    int rc = scan_capture_view(s, hal, p, c, angle_mdeg, sink, info);
    return rc != 0 ? rc : scan_finish_view(s, &hal->thread, c, angle_mdeg, view, info);
}

int scan_keep_for_registration(struct reg_ctx *reg, uint32_t index, const struct scan_view *view)
{
    return reg_add_view(reg, index, view->angle_mdeg, &view->maps, &view->range, view->rgb,
                        view->confidence);
}

struct hal_thread scan_cores(const struct hal_thread *threads, const struct scan_params *p)
{
    struct hal_thread cores = {0};
    if (threads != NULL)
        cores = *threads;
    if (p->threads > 0 && p->threads < cores.threads)
        cores.threads = p->threads;
    return cores;
}

int scan_fuse_view(struct fusion_volume *vol, const struct hal_thread *cores,
                   const struct scan_calib *calib, const struct scan_view *view,
                   const struct frame_xform *obj_from_cam)
{
    return fusion_integrate(vol, cores, calib, obj_from_cam, &view->maps, &view->range, view->rgb,
                            view->confidence);
}

int scan_save_cloud(const struct hal *hal, const struct scan_view *view,
                    const struct frame_xform *obj_from_cam, const char *path)
{
    uint32_t written = 0;
    int rc = ply_write_cloud(&hal->storage, path, &view->maps, &view->range, view->rgb,
                             view->confidence, obj_from_cam, &written);
    if (rc != 0)
        hal->log(HAL_LOG_ERROR, "storage: cannot write %s: %s", path, strerror(-rc));
    else
        hal->log(HAL_LOG_DEBUG, "wrote %u points to %s", (unsigned)written, path);
    return rc;
}

void scan_attach_colour(struct scan_ctx *s, struct scan_view *view)
{
    view->white_rgb = s->colour_rgb;
    for (uint32_t k = 0; k < COLOUR_MAX_FRAMES; k++)
        view->lights[k] = s->light_present[k] ? light_frame(s, k, frame_pixels(&s->params)) : NULL;
}

int scan_recolour(const struct colour_params *colour, const struct hal_thread *cores,
                  const struct scan_calib *c, struct scan_view *view, struct reflect_pool *pool)
{
    view->colour_method = colour->method;
    return colour_compute(colour, cores, c, &view->maps, &view->range, view->white_rgb,
                          view->lights, view->rgb, view->confidence, pool);
}

void scan_close(const struct hal *hal)
{
    hal_cam_close(&hal->camera);
    int rc = hal_safe_state(hal);
    if (rc != 0)
        hal->log(HAL_LOG_ERROR, "safe state: a device did not answer (%s); check the rig",
                 strerror(-rc));
    else
        hal->log(HAL_LOG_INFO, "safe state: lights and projector off, camera closed");
}
