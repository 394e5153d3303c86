/* Camera backend on the V4L2 ioctls: fixed exposure, mmap streaming, frames as RGB24.
 * Errors are translated here, once: every message names the device and the ioctl. */
#define _POSIX_C_SOURCE 200809L
#include "camera_v4l2.h"

#include "v4l2_frame.h"

#include <errno.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

/* ioctl, again after a signal. @retval 0 or -errno */
static int xioctl(int fd, unsigned long request, void *arg)
{
    int r;
    do
        r = ioctl(fd, request, arg);
    while (r == -1 && errno == EINTR);
    return r == -1 ? -errno : 0;
}

/* Record and log what failed; @retval @p rc */
static int fail(struct camera_v4l2 *cam, int rc, const char *what, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int fail(struct camera_v4l2 *cam, int rc, const char *what, const char *fmt, ...)
{
    char detail[160] = "";
    if (fmt != NULL) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(detail, sizeof(detail), fmt, ap);
        va_end(ap);
    }
    snprintf(cam->error, sizeof(cam->error), "camera %s: %s: %s", cam->cfg.device, what,
             detail[0] ? detail : strerror(-rc));
    if (cam->log != NULL)
        cam->log(HAL_LOG_ERROR, "%s", cam->error);
    return rc;
}

static int set_controls(struct camera_v4l2 *cam, uint32_t exposure_us, uint32_t gain_milli)
{
    const uint32_t *ids;
    size_t n = v4l2_plan_ids(&ids), count;
    struct v4l2_ctrl_info info[V4L2_PLAN_MAX];
    struct v4l2_ctrl_value plan[V4L2_PLAN_MAX];
    char why[160];
    for (size_t k = 0; k < n && k < V4L2_PLAN_MAX; k++) {
        struct v4l2_queryctrl q = {.id = ids[k]};
        int rc = xioctl(cam->fd, VIDIOC_QUERYCTRL, &q);
        info[k].id = ids[k];
        info[k].present = rc == 0 && !(q.flags & V4L2_CTRL_FLAG_DISABLED);
        info[k].minimum = q.minimum;
        info[k].maximum = q.maximum;
        info[k].step = q.step;
        info[k].default_value = q.default_value;
    }
    int fixed;
    int rc = v4l2_plan_controls(info, n, exposure_us, gain_milli, plan, &count, &fixed, why,
                                sizeof(why));
    if (rc != 0)
        return fail(cam, rc, "controls", "%s", why);
    if (fixed && !cam->exposure_fixed && cam->log != NULL)
        cam->log(HAL_LOG_WARN,
                 "camera %s: no exposure control; its own fixed exposure is used, exposure_us "
                 "is not applied (and HDR or colour frames at other exposures cannot be taken)",
                 cam->cfg.device);
    cam->exposure_fixed = fixed;
    for (size_t k = 0; k < count; k++) {
        struct v4l2_control c = {.id = plan[k].id, .value = plan[k].value};
        rc = xioctl(cam->fd, VIDIOC_S_CTRL, &c);
        if (rc != 0)
            return fail(cam, rc, "VIDIOC_S_CTRL", "%s = %d: %s", plan[k].name, (int)plan[k].value,
                        strerror(-rc));
    }
    return 0;
}

/* [camera] binning, 0 (unset) read as 1. */
static uint32_t binning_of(const struct hal_camera_config *cfg)
{
    return cfg->binning > 1 ? cfg->binning : 1u;
}

static int set_format(struct camera_v4l2 *cam)
{
    char want[5], got[5];
    struct v4l2_format f = {.type = V4L2_BUF_TYPE_VIDEO_CAPTURE};
    const uint32_t w = cam->cfg.width * binning_of(&cam->cfg),
                   h = cam->cfg.height * binning_of(&cam->cfg);
    f.fmt.pix.width = w; /* the sensor's mode: the frame's size times the binning */
    f.fmt.pix.height = h;
    f.fmt.pix.pixelformat = v4l2_fourcc_of(cam->cfg.pixel_format);
    f.fmt.pix.field = V4L2_FIELD_NONE;
    int rc = xioctl(cam->fd, VIDIOC_S_FMT, &f);
    if (rc != 0)
        return fail(cam, rc, "VIDIOC_S_FMT", NULL);
    /* Drivers adjust what they cannot do instead of failing: check what we got. */
    if (f.fmt.pix.width != w || f.fmt.pix.height != h ||
        f.fmt.pix.pixelformat != v4l2_fourcc_of(cam->cfg.pixel_format))
        return fail(cam, -EINVAL, "VIDIOC_S_FMT", "asked for %ux%u %s, the device offers %ux%u %s",
                    (unsigned)w, (unsigned)h,
                    v4l2_fourcc_text(v4l2_fourcc_of(cam->cfg.pixel_format), want),
                    (unsigned)f.fmt.pix.width, (unsigned)f.fmt.pix.height,
                    v4l2_fourcc_text(f.fmt.pix.pixelformat, got));
    cam->fourcc = f.fmt.pix.pixelformat;
    cam->bytes_per_line = f.fmt.pix.bytesperline;
    return 0;
}

/* One frame interval, for the start of exposure of end-of-frame timestamps; optional. */
static uint32_t frame_interval_us(struct camera_v4l2 *cam)
{
    struct v4l2_streamparm parm = {.type = V4L2_BUF_TYPE_VIDEO_CAPTURE};
    if (xioctl(cam->fd, VIDIOC_G_PARM, &parm) != 0)
        return 0;
    const struct v4l2_fract *f = &parm.parm.capture.timeperframe;
    return f->denominator ? (uint32_t)((uint64_t)f->numerator * 1000000u / f->denominator) : 0;
}

static int map_buffers(struct camera_v4l2 *cam)
{
    struct v4l2_requestbuffers req = {
        .count = CAMERA_V4L2_RING, .type = V4L2_BUF_TYPE_VIDEO_CAPTURE, .memory = V4L2_MEMORY_MMAP};
    int rc = xioctl(cam->fd, VIDIOC_REQBUFS, &req);
    if (rc != 0)
        return fail(cam, rc, "VIDIOC_REQBUFS", NULL);
    if (req.count < 2)
        return fail(cam, -ENOMEM, "VIDIOC_REQBUFS", "the driver gave %u buffers, 2 needed",
                    (unsigned)req.count);
    for (uint32_t k = 0; k < req.count && k < CAMERA_V4L2_RING; k++) {
        struct v4l2_buffer b = {
            .type = V4L2_BUF_TYPE_VIDEO_CAPTURE, .memory = V4L2_MEMORY_MMAP, .index = k};
        if ((rc = xioctl(cam->fd, VIDIOC_QUERYBUF, &b)) != 0)
            return fail(cam, rc, "VIDIOC_QUERYBUF", NULL);
        void *p = mmap(NULL, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, cam->fd, b.m.offset);
        if (p == MAP_FAILED)
            return fail(cam, -errno, "mmap", NULL);
        cam->buf[k] = p;
        cam->buf_len[k] = b.length;
        cam->buf_count = k + 1;
        if ((rc = xioctl(cam->fd, VIDIOC_QBUF, &b)) != 0)
            return fail(cam, rc, "VIDIOC_QBUF", NULL);
    }
    return 0;
}

static int v4l2_close(void *priv);

static int v4l2_open(void *priv, const struct hal_camera_config *cfg)
{
    struct camera_v4l2 *cam = priv;
    struct v4l2_capability cap;
    int rc;
    v4l2_close(cam);
    cam->cfg = *cfg;
    cam->fd = open(cfg->device, O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (cam->fd < 0)
        return fail(cam, errno == ENOENT ? -ENODEV : -errno, "open", NULL);
    memset(&cap, 0, sizeof(cap));
    if ((rc = xioctl(cam->fd, VIDIOC_QUERYCAP, &cap)) != 0) {
        rc = fail(cam, -ENODEV, "VIDIOC_QUERYCAP", "not a V4L2 device (%s)", strerror(-rc));
        goto out_close;
    }
    uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE) || !(caps & V4L2_CAP_STREAMING)) {
        rc = fail(cam, -ENODEV, "VIDIOC_QUERYCAP", "%s (%s) cannot stream video capture",
                  (const char *)cap.card, (const char *)cap.driver);
        goto out_close;
    }
    if ((rc = set_format(cam)) != 0 ||
        (rc = set_controls(cam, cfg->exposure_us, cfg->gain_milli)) != 0 ||
        (rc = map_buffers(cam)) != 0)
        goto out_close;
    cam->frame_us = frame_interval_us(cam);
    enum v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if ((rc = xioctl(cam->fd, VIDIOC_STREAMON, &type)) != 0) {
        fail(cam, rc, "VIDIOC_STREAMON", NULL);
        goto out_close;
    }
    cam->streaming = 1;
    return 0;
out_close:
    v4l2_close(cam);
    return rc;
}

/* Wait up to the frame timeout (0: do not wait) and dequeue one filled buffer.
 * @retval 0 @retval -EAGAIN none ready (timeout 0) @retval -ETIMEDOUT @retval -errno */
static int dequeue(struct camera_v4l2 *cam, uint32_t timeout_ms, struct v4l2_buffer *b)
{
    struct pollfd p = {.fd = cam->fd, .events = POLLIN};
    int r;
    do
        r = poll(&p, 1, (int)timeout_ms);
    while (r < 0 && errno == EINTR);
    if (r < 0)
        return fail(cam, -errno, "poll", NULL);
    if (r == 0)
        return timeout_ms
                   ? fail(cam, -ETIMEDOUT, "capture", "no frame in %u ms", (unsigned)timeout_ms)
                   : -EAGAIN;
    memset(b, 0, sizeof(*b));
    b->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b->memory = V4L2_MEMORY_MMAP;
    int rc = xioctl(cam->fd, VIDIOC_DQBUF, b);
    if (rc == -EAGAIN && timeout_ms == 0)
        return rc;
    return rc != 0 ? fail(cam, rc, "VIDIOC_DQBUF", NULL) : 0;
}

static int requeue(struct camera_v4l2 *cam, struct v4l2_buffer *b)
{
    int rc = xioctl(cam->fd, VIDIOC_QBUF, b);
    return rc != 0 ? fail(cam, rc, "VIDIOC_QBUF", NULL) : 0;
}

static int v4l2_capture(void *priv, struct hal_image *img)
{
    struct camera_v4l2 *cam = priv;
    struct v4l2_buffer b;
    int rc;
    if (!cam->streaming)
        return fail(cam, -ENODEV, "capture", "camera not open");
    /* Frames already filled were exposed before the light or pattern changed: give them back,
     * then let drop_frames more go by (a frame being exposed during the change). */
    while ((rc = dequeue(cam, 0, &b)) == 0)
        if ((rc = requeue(cam, &b)) != 0)
            return rc;
    if (rc != -EAGAIN)
        return rc;
    for (uint32_t k = 0; k <= cam->cfg.drop_frames; k++) {
        if ((rc = dequeue(cam, cam->cfg.frame_timeout_ms, &b)) != 0)
            return rc;
        if (k < cam->cfg.drop_frames && (rc = requeue(cam, &b)) != 0)
            return rc;
    }
    if (b.flags & V4L2_BUF_FLAG_ERROR)
        rc = fail(cam, -EIO, "capture", "the driver flagged frame %u as corrupt",
                  (unsigned)b.sequence);
    else if (b.index >= cam->buf_count)
        rc = fail(cam, -EIO, "VIDIOC_DQBUF", "buffer index %u out of range", (unsigned)b.index);
    else if ((rc = v4l2_to_rgb(cam->fourcc, cam->buf[b.index], b.bytesused, cam->bytes_per_line,
                               cam->cfg.width, cam->cfg.height, binning_of(&cam->cfg), img->rgb,
                               img->capacity)) == -EIO)
        fail(cam, rc, "capture", "short frame %u: %u bytes", (unsigned)b.sequence,
             (unsigned)b.bytesused);
    else if (rc != 0)
        fail(cam, rc, "capture", "cannot convert to RGB into %zu bytes", img->capacity);
    img->width = cam->cfg.width;
    img->height = cam->cfg.height;
    img->sequence = b.sequence;
    img->start_us =
        v4l2_frame_start_us(b.flags, (int64_t)b.timestamp.tv_sec, (int64_t)b.timestamp.tv_usec,
                            cam->cfg.exposure_us, cam->frame_us);
    int rq = requeue(cam, &b);
    return rc != 0 ? rc : rq;
}

static int v4l2_set_exposure(void *priv, uint32_t exposure_us, uint32_t gain_milli)
{
    struct camera_v4l2 *cam = priv;
    if (cam->fd < 0)
        return fail(cam, -ENODEV, "set_exposure", "camera not open");
    if (cam->exposure_fixed && exposure_us != cam->cfg.exposure_us)
        return fail(cam, -ENOSYS, "set_exposure", "the device has no exposure control");
    int rc = set_controls(cam, exposure_us, gain_milli);
    if (rc == 0) { /* the start of exposure of the frames that follow depends on it */
        cam->cfg.exposure_us = exposure_us;
        cam->cfg.gain_milli = gain_milli;
    }
    return rc;
}

static int v4l2_safe_state(void *priv)
{
    struct camera_v4l2 *cam = priv;
    enum v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (cam->fd >= 0 && cam->streaming)
        xioctl(cam->fd, VIDIOC_STREAMOFF, &type);
    cam->streaming = 0;
    return 0;
}

static int v4l2_close(void *priv)
{
    struct camera_v4l2 *cam = priv;
    v4l2_safe_state(cam);
    for (uint32_t k = 0; k < cam->buf_count; k++)
        munmap(cam->buf[k], cam->buf_len[k]);
    cam->buf_count = 0;
    if (cam->fd >= 0) {
        struct v4l2_requestbuffers req = {
            .count = 0, .type = V4L2_BUF_TYPE_VIDEO_CAPTURE, .memory = V4L2_MEMORY_MMAP};
        xioctl(cam->fd, VIDIOC_REQBUFS, &req); /* frees the driver's buffers; may be refused */
        close(cam->fd);
    }
    cam->fd = -1;
    return 0;
}

static const struct hal_camera_ops v4l2_ops = {
    .open = v4l2_open,
    .capture = v4l2_capture,
    .set_exposure = v4l2_set_exposure,
    .close = v4l2_close,
    .safe_state = v4l2_safe_state,
};

void camera_v4l2_init(struct camera_v4l2 *cam,
                      void (*log)(enum hal_log_level level, const char *fmt, ...),
                      struct hal_camera *out)
{
    memset(cam, 0, sizeof(*cam));
    cam->fd = -1;
    cam->log = log;
    out->ops = &v4l2_ops;
    out->priv = cam;
}
