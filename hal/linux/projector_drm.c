/* HDMI projector on DRM/KMS through libdrm: dumb buffers, a mode set once, page flips with
 * events (the libdrm "modeset" pattern: drmModeGetResources, a connected connector's mode, its
 * encoder's CRTC, DRM_IOCTL_MODE_CREATE_DUMB / MAP_DUMB, drmModeAddFB, drmModeSetCrtc, then
 * drmModePageFlip with DRM_MODE_PAGE_FLIP_EVENT and drmHandleEvent). */
#define _GNU_SOURCE
#include "projector_drm.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include <xf86drm.h>
#include <xf86drmMode.h>

static int fail(struct projector_drm *p, int rc, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->error, sizeof(p->error), fmt, ap);
    va_end(ap);
    return rc;
}

static int create_buffer(struct projector_drm *p, struct projector_drm_buffer *b)
{
    struct drm_mode_create_dumb create = {.width = p->width, .height = p->height, .bpp = 32};
    if (drmIoctl(p->fd, DRM_IOCTL_MODE_CREATE_DUMB, &create) != 0)
        return fail(p, -errno, "DRM_IOCTL_MODE_CREATE_DUMB: %s", strerror(errno));
    b->handle = create.handle;
    b->pitch = create.pitch;
    b->size = create.size;
    if (drmModeAddFB(p->fd, p->width, p->height, 24, 32, b->pitch, b->handle, &b->fb_id) != 0)
        return fail(p, -errno, "drmModeAddFB: %s", strerror(errno));
    struct drm_mode_map_dumb map = {.handle = b->handle};
    if (drmIoctl(p->fd, DRM_IOCTL_MODE_MAP_DUMB, &map) != 0)
        return fail(p, -errno, "DRM_IOCTL_MODE_MAP_DUMB: %s", strerror(errno));
    void *m =
        mmap(NULL, (size_t)b->size, PROT_READ | PROT_WRITE, MAP_SHARED, p->fd, (off_t)map.offset);
    if (m == MAP_FAILED)
        return fail(p, -errno, "mmap of a dumb buffer: %s", strerror(errno));
    b->map = m;
    return 0;
}

static void destroy_buffer(struct projector_drm *p, struct projector_drm_buffer *b)
{
    if (b->map != NULL)
        munmap(b->map, (size_t)b->size);
    if (b->fb_id != 0)
        drmModeRmFB(p->fd, b->fb_id);
    if (b->handle != 0) {
        struct drm_mode_destroy_dumb destroy = {.handle = b->handle};
        drmIoctl(p->fd, DRM_IOCTL_MODE_DESTROY_DUMB, &destroy);
    }
    memset(b, 0, sizeof(*b));
}

/* A CRTC that can drive @p conn: its encoder's, else the first any of its encoders can use. */
static uint32_t find_crtc(int fd, const drmModeRes *res, const drmModeConnector *conn)
{
    drmModeEncoder *enc = conn->encoder_id ? drmModeGetEncoder(fd, conn->encoder_id) : NULL;
    uint32_t crtc = enc != NULL ? enc->crtc_id : 0;
    drmModeFreeEncoder(enc);
    for (int e = 0; crtc == 0 && e < conn->count_encoders; e++) {
        enc = drmModeGetEncoder(fd, conn->encoders[e]);
        for (int c = 0; enc != NULL && crtc == 0 && c < res->count_crtcs; c++)
            if (enc->possible_crtcs & (1u << c))
                crtc = res->crtcs[c];
        drmModeFreeEncoder(enc);
    }
    return crtc;
}

/* The connected connector with a width x height mode (the preferred one of that size first). */
static int find_output(struct projector_drm *p, char *err, size_t err_len)
{
    drmModeRes *res = drmModeGetResources(p->fd);
    if (res == NULL)
        return fail(p, -ENODEV, "drmModeGetResources: %s (not a KMS device?)", strerror(errno));
    int rc = -ENODEV;
    size_t said = 0;
    err[0] = '\0';
    for (int i = 0; i < res->count_connectors && rc != 0; i++) {
        drmModeConnector *conn = drmModeGetConnector(p->fd, res->connectors[i]);
        if (conn == NULL || conn->connection != DRM_MODE_CONNECTED || conn->count_modes == 0) {
            drmModeFreeConnector(conn);
            continue;
        }
        int best = -1;
        for (int m = 0; m < conn->count_modes; m++) {
            const drmModeModeInfo *mi = &conn->modes[m];
            if (mi->hdisplay == p->width && mi->vdisplay == p->height &&
                (best < 0 || (mi->type & DRM_MODE_TYPE_PREFERRED)))
                best = m;
            if (said + 16 < err_len)
                said += (size_t)snprintf(err + said, err_len - said, "%s%ux%u", said ? " " : "",
                                         (unsigned)mi->hdisplay, (unsigned)mi->vdisplay);
        }
        uint32_t crtc = best >= 0 ? find_crtc(p->fd, res, conn) : 0;
        if (best >= 0 && crtc != 0) {
            p->mode = malloc(sizeof(drmModeModeInfo)); /* at open: the HAL may allocate here */
            if (p->mode == NULL) {
                drmModeFreeConnector(conn);
                rc = -ENOMEM;
                break;
            }
            memcpy(p->mode, &conn->modes[best], sizeof(drmModeModeInfo));
            p->conn_id = conn->connector_id;
            p->crtc_id = crtc;
            rc = 0;
        } else {
            rc = best >= 0 ? -ENODEV : -EINVAL;
        }
        drmModeFreeConnector(conn);
    }
    drmModeFreeResources(res);
    if (rc == -EINVAL)
        return fail(p, rc, "no %ux%u mode on the display (it has: %s)", (unsigned)p->width,
                    (unsigned)p->height, err);
    if (rc != 0)
        return fail(p, rc, "no connected display with a CRTC");
    return 0;
}

static void on_flip(int fd, unsigned int frame, unsigned int sec, unsigned int usec, void *data)
{
    (void)fd;
    (void)frame;
    struct projector_drm *p = data;
    p->flip_us = (uint64_t)sec * 1000000u + usec; /* the vblank the new buffer went up at */
    p->flip_pending = 0;
}

/* Read the flip event, waiting up to @p timeout_ms. */
static int wait_flip(struct projector_drm *p, uint32_t timeout_ms)
{
    drmEventContext ev = {.version = 2, .page_flip_handler = on_flip};
    while (p->flip_pending) {
        struct pollfd pfd = {.fd = p->fd, .events = POLLIN};
        int r = poll(&pfd, 1, (int)timeout_ms);
        if (r < 0 && errno == EINTR)
            continue;
        if (r < 0)
            return fail(p, -errno, "poll: %s", strerror(errno));
        if (r == 0)
            return fail(p, -ETIMEDOUT, "no page-flip event in %u ms", (unsigned)timeout_ms);
        if (drmHandleEvent(p->fd, &ev) != 0)
            return fail(p, -EIO, "drmHandleEvent failed");
    }
    return 0;
}

static int draw(struct projector_drm *p, struct projector_drm_buffer *b, uint32_t pattern)
{
    if (pattern == PROJECTOR_DRM_BLACK || p->render == NULL) {
        memset(b->map, 0, (size_t)b->size);
        return 0;
    }
    return p->render(p->render_ctx, pattern, b->map, p->width, p->height, b->pitch);
}

int projector_drm_open(struct projector_drm *p, const char *device, uint32_t width, uint32_t height,
                       projector_render_fn render, void *render_ctx, char *err, size_t err_len)
{
    memset(p, 0, sizeof(*p));
    p->width = width;
    p->height = height;
    p->render = render;
    p->render_ctx = render_ctx;
    p->fd = open(device, O_RDWR | O_CLOEXEC);
    int rc = 0;
    if (p->fd < 0) {
        rc = fail(p, errno == ENOENT ? -ENODEV : -errno, "%s: %s", device, strerror(errno));
        goto out;
    }
    if ((rc = find_output(p, err, err_len)) != 0)
        goto out_close;
    p->saved_crtc = drmModeGetCrtc(p->fd, p->crtc_id);
    for (int k = 0; k < 2 && rc == 0; k++)
        rc = create_buffer(p, &p->buf[k]);
    if (rc == 0 && (rc = draw(p, &p->buf[0], PROJECTOR_DRM_BLACK)) == 0 &&
        drmModeSetCrtc(p->fd, p->crtc_id, p->buf[0].fb_id, 0, 0, &p->conn_id, 1, p->mode) != 0)
        rc = fail(p, -errno, "drmModeSetCrtc (is another program showing on it?): %s",
                  strerror(errno));
    if (rc != 0)
        goto out_close;
    p->front = 0;
    return 0;
out_close:
    snprintf(err, err_len, "%s: %s", device, p->error);
    projector_drm_close(p);
    return rc;
out:
    snprintf(err, err_len, "%s", p->error);
    p->fd = -1;
    return rc;
}

int projector_drm_show(struct projector_drm *p, uint32_t pattern, uint32_t timeout_ms)
{
    if (p->fd < 0)
        return fail(p, -ENODEV, "projector not open");
    struct projector_drm_buffer *back = &p->buf[1 - p->front];
    int rc = draw(p, back, pattern);
    if (rc != 0)
        return fail(p, rc, "drawing pattern %u: %s", (unsigned)pattern, strerror(-rc));
    if (drmModePageFlip(p->fd, p->crtc_id, back->fb_id, DRM_MODE_PAGE_FLIP_EVENT, p) != 0)
        return fail(p, -errno, "drmModePageFlip: %s", strerror(errno));
    p->flip_pending = 1;
    if ((rc = wait_flip(p, timeout_ms)) != 0)
        return rc;
    p->front = 1 - p->front;
    return 0;
}

void projector_drm_close(struct projector_drm *p)
{
    if (p->fd < 0)
        return;
    if (p->flip_pending)
        wait_flip(p, 100); /* a buffer must not go while the display scans it out */
    drmModeCrtc *saved = p->saved_crtc;
    if (saved != NULL && saved->mode_valid) /* the console (or whatever was there) back */
        drmModeSetCrtc(p->fd, saved->crtc_id, saved->buffer_id, saved->x, saved->y, &p->conn_id, 1,
                       &saved->mode);
    drmModeFreeCrtc(saved);
    for (int k = 0; k < 2; k++)
        destroy_buffer(p, &p->buf[k]);
    free(p->mode);
    close(p->fd);
    p->fd = -1;
    p->saved_crtc = NULL;
    p->mode = NULL;
}
