// Camera backend on libcamera (0.0.3, Debian 12): the one C++ file, behind camera_libcamera.h.
// Still frames with auto exposure and auto white balance off: a fixed exposure time, analogue
// gain and colour gains from the config; each capture queues one request and waits for it.
#include "camera_libcamera.h"

#include "v4l2_frame.h"

#include <libcamera/libcamera.h>

#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <linux/videodev2.h>
#include <memory>
#include <mutex>
#include <optional>
#include <sys/mman.h>

using namespace libcamera;

namespace
{

struct lc_state {
    std::unique_ptr<CameraManager> manager;
    std::shared_ptr<Camera> camera;
    std::unique_ptr<CameraConfiguration> config;
    std::unique_ptr<FrameBufferAllocator> allocator;
    std::unique_ptr<Request> request;
    Stream *stream = nullptr;
    void *map = MAP_FAILED;
    size_t map_len = 0;
    bool acquired = false, started = false;
    hal_camera_config cfg{};
    uint32_t before_us = 0;     // the exposure until the last change (cfg's: none since)
    uint32_t said_other_us = 0; // the exposure asked for whose frames came out another, said
    uint32_t fourcc = 0, stride = 0;
    std::mutex lock; // libcamera completes requests on its own thread
    std::condition_variable completed;
    bool done = false;

    void on_request(Request *r)
    {
        std::lock_guard<std::mutex> guard(lock);
        done = r == request.get();
        completed.notify_all();
    }
};

int fail(camera_libcamera *cam, int rc, const char *what, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
int fail(camera_libcamera *cam, int rc, const char *what, const char *fmt, ...)
{
    char detail[160] = "";
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(detail, sizeof(detail), fmt, ap);
    va_end(ap);
    const lc_state *s = static_cast<const lc_state *>(cam->impl);
    snprintf(cam->error, sizeof(cam->error), "camera libcamera '%s': %s: %s", s->cfg.device, what,
             detail);
    if (cam->log != nullptr)
        cam->log(HAL_LOG_ERROR, "%s", cam->error);
    return rc;
}

// The controls every request carries: nothing automatic.
void set_controls(lc_state *s, ControlList &c)
{
    c.set(controls::AeEnable, false);
    c.set(controls::AwbEnable, false);
    c.set(controls::ExposureTime, static_cast<int32_t>(s->cfg.exposure_us));
    c.set(controls::AnalogueGain, s->cfg.gain_milli / 1000.0f);
    const float gains[2] = {s->cfg.red_gain_milli / 1000.0f, s->cfg.blue_gain_milli / 1000.0f};
    c.set(controls::ColourGains, Span<const float, 2>(gains));
}

int lc_close(void *priv);

int configure(camera_libcamera *cam, lc_state *s)
{
    // libcamera names formats as DRM does: BGR888 is R, G, B in memory (V4L2's RGB24).
    PixelFormat want = s->cfg.pixel_format == HAL_PIX_YUYV   ? formats::YUYV
                       : s->cfg.pixel_format == HAL_PIX_GREY ? formats::R8
                                                             : formats::BGR888;
    s->config = s->camera->generateConfiguration({StreamRole::StillCapture});
    if (!s->config)
        return fail(cam, -EINVAL, "generateConfiguration", "no still capture configuration");
    StreamConfiguration &sc = s->config->at(0);
    sc.pixelFormat = want;
    const unsigned binning = s->cfg.binning > 1 ? s->cfg.binning : 1u;
    const Size sensor(s->cfg.width * binning, s->cfg.height * binning); /* binned in software */
    sc.size = sensor;
    sc.bufferCount = 1;
    if (s->config->validate() == CameraConfiguration::Invalid || sc.pixelFormat != want ||
        sc.size != sensor)
        return fail(cam, -EINVAL, "configure", "asked for %ux%u %s, the camera offers %s",
                    (unsigned)sensor.width, (unsigned)sensor.height, want.toString().c_str(),
                    sc.toString().c_str());
    int rc = s->camera->configure(s->config.get());
    if (rc < 0)
        return fail(cam, rc, "configure", "%s", strerror(-rc));
    s->stream = sc.stream();
    s->stride = sc.stride;
    s->fourcc = v4l2_fourcc_of(s->cfg.pixel_format);
    return 0;
}

int allocate(camera_libcamera *cam, lc_state *s)
{
    s->allocator = std::make_unique<FrameBufferAllocator>(s->camera);
    int rc = s->allocator->allocate(s->stream);
    if (rc < 0)
        return fail(cam, rc, "FrameBufferAllocator", "%s", strerror(-rc));
    const std::unique_ptr<FrameBuffer> &fb = s->allocator->buffers(s->stream).at(0);
    const FrameBuffer::Plane &plane = fb->planes().at(0); // packed formats have one plane
    s->map_len = plane.offset + plane.length;
    s->map = mmap(nullptr, s->map_len, PROT_READ, MAP_SHARED, plane.fd.get(), 0);
    if (s->map == MAP_FAILED)
        return fail(cam, -errno, "mmap", "%s", strerror(errno));
    s->request = s->camera->createRequest();
    if (!s->request || s->request->addBuffer(s->stream, fb.get()) < 0)
        return fail(cam, -ENOMEM, "createRequest", "cannot attach the frame buffer");
    return 0;
}

int lc_open(void *priv, const hal_camera_config *cfg)
{
    camera_libcamera *cam = static_cast<camera_libcamera *>(priv);
    lc_state *s = static_cast<lc_state *>(cam->impl);
    lc_close(priv);
    s->cfg = *cfg;
    s->before_us = cfg->exposure_us;
    s->said_other_us = 0;
    setenv("LIBCAMERA_LOG_LEVELS", "*:ERROR", 0); // its INFO lines are noise in a scan log
    s->manager = std::make_unique<CameraManager>();
    int rc = s->manager->start();
    if (rc < 0)
        return fail(cam, rc, "CameraManager::start", "%s", strerror(-rc));
    if (cfg->device[0] == '\0' || strcmp(cfg->device, "auto") == 0) {
        if (!s->manager->cameras().empty())
            s->camera = s->manager->cameras().front();
    } else {
        s->camera = s->manager->get(cfg->device);
    }
    if (!s->camera) {
        rc = fail(cam, -ENODEV, "CameraManager::get", "no such camera (%zu found)",
                  s->manager->cameras().size());
        goto out_close;
    }
    if ((rc = s->camera->acquire()) < 0) {
        fail(cam, rc, "acquire", "%s", strerror(-rc));
        goto out_close;
    }
    s->acquired = true;
    if ((rc = configure(cam, s)) != 0 || (rc = allocate(cam, s)) != 0)
        goto out_close;
    s->camera->requestCompleted.connect(s, &lc_state::on_request);
    {
        ControlList start_controls(controls::controls);
        set_controls(s, start_controls);
        if ((rc = s->camera->start(&start_controls)) < 0) {
            fail(cam, rc, "start", "%s", strerror(-rc));
            goto out_close;
        }
    }
    s->started = true;
    return 0;
out_close:
    lc_close(priv);
    return rc;
}

// Queue the request and wait for it. @retval 0, -ETIMEDOUT or -EIO
int one_frame(camera_libcamera *cam, lc_state *s)
{
    s->request->reuse(Request::ReuseBuffers);
    set_controls(s, s->request->controls());
    {
        std::lock_guard<std::mutex> guard(s->lock);
        s->done = false;
    }
    int rc = s->camera->queueRequest(s->request.get());
    if (rc < 0)
        return fail(cam, rc, "queueRequest", "%s", strerror(-rc));
    std::unique_lock<std::mutex> guard(s->lock);
    if (!s->completed.wait_for(guard, std::chrono::milliseconds(s->cfg.frame_timeout_ms),
                               [s] { return s->done; }))
        return fail(cam, -ETIMEDOUT, "capture", "no frame in %u ms",
                    (unsigned)s->cfg.frame_timeout_ms);
    if (s->request->status() != Request::RequestComplete)
        return fail(cam, -EIO, "capture", "request cancelled");
    return 0;
}

// The exposure the frame's metadata say it had (where the pipeline says): one of the exposure
// before a change is taken again, as a stale frame is (-EAGAIN: the scan retries it, within
// [camera] capture_retries; more [camera] drop_frames let the sensor apply the change first);
// one of another exposure is kept and said once for each exposure asked for.
int check_exposure(camera_libcamera *cam, lc_state *s, unsigned sequence)
{
    const std::optional<int32_t> actual = s->request->metadata().get(controls::ExposureTime);
    if (!actual || *actual <= 0)
        return 0;
    const uint32_t got = static_cast<uint32_t>(*actual), want = s->cfg.exposure_us;
    switch (v4l2_frame_exposure(want, s->before_us, got)) {
    case V4L2_EXPOSURE_AS_ASKED:
        s->before_us = want; // applied: the change is behind
        return 0;
    case V4L2_EXPOSURE_BEFORE:
        if (cam->log != nullptr)
            cam->log(HAL_LOG_WARN,
                     "camera libcamera '%s': frame %u was exposed %u us, the exposure before "
                     "the change to %u us (the sensor had not applied it yet): taken again",
                     s->cfg.device, sequence, (unsigned)got, (unsigned)want);
        return -EAGAIN;
    case V4L2_EXPOSURE_OTHER:
        if (s->said_other_us != want && cam->log != nullptr)
            cam->log(HAL_LOG_WARN,
                     "camera libcamera '%s': frames asked for at %u us come out at %u us (the "
                     "sensor's limits at its frame rate?): kept",
                     s->cfg.device, (unsigned)want, (unsigned)got);
        s->said_other_us = want;
        return 0;
    }
    return 0;
}

int lc_capture(void *priv, hal_image *img)
{
    camera_libcamera *cam = static_cast<camera_libcamera *>(priv);
    lc_state *s = static_cast<lc_state *>(cam->impl);
    if (!s->started)
        return fail(cam, -ENODEV, "capture", "camera not open");
    int rc = 0;
    for (uint32_t k = 0; k <= s->cfg.drop_frames && rc == 0; k++) // frames during the change
        rc = one_frame(cam, s);
    if (rc != 0)
        return rc;
    FrameBuffer *fb = s->request->buffers().begin()->second;
    const FrameMetadata &md = fb->metadata();
    if (md.status != FrameMetadata::FrameSuccess)
        return fail(cam, -EIO, "capture", "frame %u flagged corrupt", md.sequence);
    if ((rc = check_exposure(cam, s, md.sequence)) != 0)
        return rc;
    const FrameBuffer::Plane &plane = fb->planes().at(0);
    const uint8_t *pixels = static_cast<const uint8_t *>(s->map) + plane.offset;
    rc = v4l2_to_rgb(s->fourcc, pixels, md.planes()[0].bytesused, s->stride, s->cfg.width,
                     s->cfg.height, s->cfg.binning > 1 ? s->cfg.binning : 1u, img->rgb,
                     img->capacity);
    if (rc != 0)
        return fail(cam, rc, "capture", "frame %u: %s", md.sequence,
                    rc == -EIO ? "short frame" : "cannot convert to RGB");
    img->width = s->cfg.width;
    img->height = s->cfg.height;
    img->sequence = md.sequence;
    // FrameMetadata::timestamp is the kernel's buffer stamp in ns of CLOCK_MONOTONIC (the HAL
    // clock), taken at the start of the frame's readout by the Raspberry Pi's unicam: the
    // exposure began up to one exposure before it.
    uint64_t stamp_us = md.timestamp / 1000u;
    img->start_us = stamp_us > s->cfg.exposure_us ? stamp_us - s->cfg.exposure_us : 0;
    return 0;
}

int lc_set_exposure(void *priv, uint32_t exposure_us, uint32_t gain_milli)
{
    camera_libcamera *cam = static_cast<camera_libcamera *>(priv);
    lc_state *s = static_cast<lc_state *>(cam->impl);
    if (exposure_us != s->cfg.exposure_us)
        s->before_us = s->cfg.exposure_us; // until a frame shows the new one (check_exposure)
    s->cfg.exposure_us = exposure_us;      // every request carries the controls
    s->cfg.gain_milli = gain_milli;
    return 0;
}

int lc_safe_state(void *priv)
{
    lc_state *s = static_cast<lc_state *>(static_cast<camera_libcamera *>(priv)->impl);
    if (s->started)
        s->camera->stop();
    s->started = false;
    return 0;
}

int lc_close(void *priv)
{
    lc_state *s = static_cast<lc_state *>(static_cast<camera_libcamera *>(priv)->impl);
    lc_safe_state(priv);
    if (s->camera)
        s->camera->requestCompleted.disconnect(s);
    s->request.reset();
    if (s->map != MAP_FAILED)
        munmap(s->map, s->map_len);
    s->map = MAP_FAILED;
    s->allocator.reset();
    s->config.reset();
    if (s->acquired)
        s->camera->release();
    s->acquired = false;
    s->camera.reset();
    if (s->manager)
        s->manager->stop();
    s->manager.reset();
    return 0;
}

const hal_camera_ops lc_ops = {
    lc_open, lc_capture, lc_set_exposure, lc_close, lc_safe_state,
};

} // namespace

extern "C" int camera_libcamera_init(struct camera_libcamera *cam,
                                     void (*log)(enum hal_log_level level, const char *fmt, ...),
                                     struct hal_camera *out)
{
    memset(cam, 0, sizeof(*cam));
    cam->log = log;
    cam->impl = new (std::nothrow) lc_state;
    if (cam->impl == nullptr)
        return -ENOMEM;
    out->ops = &lc_ops;
    out->priv = cam;
    return 0;
}

extern "C" void camera_libcamera_free(struct camera_libcamera *cam)
{
    if (cam->impl == nullptr)
        return;
    lc_close(cam);
    delete static_cast<lc_state *>(cam->impl);
    cam->impl = nullptr;
}
