/* An HDMI projector on DRM/KMS (libdrm): each pattern full screen at the display's native mode,
 * one vblank-synchronised page flip per pattern, shown only once the flip event says so. */
#ifndef PROJECTOR_DRM_H
#define PROJECTOR_DRM_H

#include <stddef.h>
#include <stdint.h>

/** Draws pattern @p pattern into an XRGB8888 buffer of @p width x @p height, rows @p pitch
 *  bytes apart (the board knows the sequence; the HAL does not). @retval 0 or -errno */
typedef int (*projector_render_fn)(void *ctx, uint32_t pattern, uint8_t *xrgb, uint32_t width,
                                   uint32_t height, uint32_t pitch);

/** Pattern number that projector_drm_show draws all black (the projector "off"). */
#define PROJECTOR_DRM_BLACK 0xFFFFFFFFu

struct projector_drm_buffer {
    uint32_t handle, fb_id, pitch;
    uint64_t size;
    uint8_t *map;
};

struct projector_drm {
    int fd; /* -1 when closed */
    uint32_t conn_id, crtc_id;
    uint32_t width, height;
    void *mode;       /* drmModeModeInfo of the native mode (kept opaque here) */
    void *saved_crtc; /* drmModeCrtc as it was before: put back on close */
    struct projector_drm_buffer buf[2];
    int front;        /* the buffer on screen */
    int flip_pending; /* a flip asked for, its event not yet read */
    uint64_t flip_us; /* when the last flip reached the screen, CLOCK_MONOTONIC */
    projector_render_fn render;
    void *render_ctx;
    char error[256];
};

/** Take the display: the first connected connector with a mode of @p width x @p height (the
 *  projector's native one, the calibration's size), a CRTC that drives it, two dumb buffers;
 *  shows black. @param device  "/dev/dri/card0"
 *  @retval 0 ok @retval -ENODEV no such device or no connected display
 *  @retval -EINVAL no mode of that size (@p err lists the display's) @retval -errno */
int projector_drm_open(struct projector_drm *p, const char *device, uint32_t width, uint32_t height,
                       projector_render_fn render, void *render_ctx, char *err, size_t err_len);

/** Draw @p pattern (PROJECTOR_DRM_BLACK: black) into the hidden buffer, flip to it at the next
 *  vertical blank and wait, up to @p timeout_ms, for the flip event: when this returns 0 the
 *  pattern is on screen, since flip_us. @retval 0 @retval -ETIMEDOUT no flip event @retval -errno
 */
int projector_drm_show(struct projector_drm *p, uint32_t pattern, uint32_t timeout_ms);

/** Black, the display given back as it was, buffers freed. Safe on a closed projector. */
void projector_drm_close(struct projector_drm *p);

#endif
