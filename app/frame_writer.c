/* The storage thread: a ring of frames to keep, queued by the scan, written by one thread
 * through scan_dir_write_frame (so each frame stays an atomic, durable write). The colour frames
 * are not copied: they stay in the firmware's static buffers, which the next view overwrites only
 * after frame_writer_flush (the caller's promise); the pattern frames, which the decoder reads
 * and lets go, are copied into a ring of its own. view.ini is written after the flush, so its
 * presence still means every frame is on disk. The thread keeps one zstd compressor for all its
 * frames: writing a zstd or PGM/PPM frame allocates nothing (libpng allocates for png). */
#define _POSIX_C_SOURCE 200809L
#include "frame_writer.h"

#include "clock_posix.h"
#include "hal_limits.h"
#include "image_io.h"
#include "mem.h"
#include "thread_posix.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#define FRAME_WRITER_STACK (512u * 1024u)

struct slot {
    char dir[HAL_MAX_PATH];
    const uint8_t *pixels; /* the caller's, unchanged until the flush, or one of copies[] */
    int copied;
    uint32_t view, frame, width, height, channels;
    enum scan_frame_format format;
};

static struct slot slots[FRAME_WRITER_SLOTS];
/* Grey frames copied, used in turn: slots are written in order, so copies are freed in order. */
static uint8_t copies[FRAME_WRITER_COPIES][HAL_MAX_PIXELS];

static struct {
    pthread_mutex_t lock;
    pthread_cond_t changed; /* a slot was queued or emptied, or the thread is asked to end */
    pthread_t thread;
    const struct hal_storage *storage;
    uint32_t head, count; /* the oldest queued slot (being written), and how many are queued */
    uint32_t copy_next, copies_queued; /* the copy the next copied frame takes; those in use */
    int stopping, running;
    int error;                      /* the first failed write since the last flush */
    char failed[SCAN_DIR_PATH_MAX]; /* its file */
    double cpu_s;
} w = {.lock = PTHREAD_MUTEX_INITIALIZER, .changed = PTHREAD_COND_INITIALIZER};

static void *writer(void *arg)
{
    (void)arg;
    int kept = image_zstd_keep(); /* without it, each frame makes its own compressor */
    pthread_mutex_lock(&w.lock);
    for (;;) {
        while (w.count == 0 && !w.stopping)
            pthread_cond_wait(&w.changed, &w.lock);
        if (w.count == 0)
            break;
        uint32_t k = w.head;
        pthread_mutex_unlock(&w.lock);
        /* outside the lock: the scan queues the next frames meanwhile */
        const struct slot *s = &slots[k];
        int rc = scan_dir_write_frame(w.storage, s->dir, s->view, s->frame, s->pixels, s->width,
                                      s->height, s->channels, s->format);
        pthread_mutex_lock(&w.lock);
        if (rc != 0 && w.error == 0) {
            w.error = rc;
            scan_dir_frame_path(w.failed, sizeof(w.failed), s->dir, s->view, s->frame, s->format,
                                s->channels);
        }
        w.head = (w.head + 1) % FRAME_WRITER_SLOTS;
        w.count--;
        w.copies_queued -= s->copied ? 1u : 0u;
        w.cpu_s = clock_posix_thread_cpu_s();
        pthread_cond_broadcast(&w.changed);
    }
    pthread_mutex_unlock(&w.lock);
    if (kept == 0)
        image_zstd_release();
    return NULL;
}

int frame_writer_start(const struct hal_storage *storage)
{
    if (w.running)
        return 0;
    w.storage = storage;
    w.head = w.count = 0;
    w.copy_next = w.copies_queued = 0;
    w.stopping = w.error = 0;
    w.cpu_s = 0.0;
    /* A small stack: the encoders keep their state on the heap, and a board with 512 MB has no
     * address space to spare for the default 8 MiB (make LIMITS=small under ulimit -v). */
    int rc = thread_posix_start(&w.thread, FRAME_WRITER_STACK, writer, NULL);
    if (rc != 0)
        return rc;
    w.running = 1;
    return 0;
}

/* Take the error to report (with the lock held): it is reported once. */
static int take_error(char *failed, size_t failed_len)
{
    int rc = w.error;
    if (rc != 0)
        snprintf(failed, failed_len, "%s", w.failed);
    w.error = 0;
    return rc;
}

int frame_writer_put(const char *dir, uint32_t view, uint32_t frame, const uint8_t *pixels,
                     uint32_t width, uint32_t height, uint32_t channels,
                     enum scan_frame_format format, int copy, char *failed, size_t failed_len)
{
    if (!w.running)
        return -EPIPE;
    if (strlen(dir) >= sizeof(slots[0].dir))
        return -E2BIG;
    if (copy && (size_t)width * height * channels > sizeof(copies[0]))
        return -EINVAL;
    pthread_mutex_lock(&w.lock);
    while ((w.count == FRAME_WRITER_SLOTS || (copy && w.copies_queued == FRAME_WRITER_COPIES)) &&
           w.error == 0)
        pthread_cond_wait(&w.changed, &w.lock);
    int rc = take_error(failed, failed_len);
    if (rc == 0) {
        /* the slot after the queued ones is free (the writer only touches queued slots), and so
         * is the next copy */
        uint32_t k = (w.head + w.count) % FRAME_WRITER_SLOTS, c = w.copy_next;
        if (copy) {
            w.copy_next = (c + 1u) % FRAME_WRITER_COPIES;
            w.copies_queued++;
        }
        pthread_mutex_unlock(&w.lock);
        if (copy) {
            memcpy(copies[c], pixels, (size_t)width * height * channels);
            pixels = copies[c];
        }
        slots[k] = (struct slot){.pixels = pixels,
                                 .copied = copy,
                                 .view = view,
                                 .frame = frame,
                                 .width = width,
                                 .height = height,
                                 .channels = channels,
                                 .format = format};
        snprintf(slots[k].dir, sizeof(slots[k].dir), "%s", dir);
        pthread_mutex_lock(&w.lock);
        w.count++;
        pthread_cond_broadcast(&w.changed);
    }
    pthread_mutex_unlock(&w.lock);
    return rc;
}

int frame_writer_flush(char *failed, size_t failed_len)
{
    if (!w.running)
        return 0;
    pthread_mutex_lock(&w.lock);
    while (w.count > 0)
        pthread_cond_wait(&w.changed, &w.lock);
    int rc = take_error(failed, failed_len);
    pthread_mutex_unlock(&w.lock);
    return rc;
}

void frame_writer_stop(void)
{
    if (!w.running)
        return;
    pthread_mutex_lock(&w.lock);
    w.stopping = 1;
    pthread_cond_broadcast(&w.changed);
    pthread_mutex_unlock(&w.lock);
    pthread_join(w.thread, NULL);
    w.running = 0;
    mem_release(copies, sizeof(copies)); /* every copy written: not read again */
}

double frame_writer_cpu_s(void)
{
    pthread_mutex_lock(&w.lock);
    double s = w.cpu_s;
    pthread_mutex_unlock(&w.lock);
    return s;
}
