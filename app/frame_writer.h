/* The storage thread: keeps a view's frames on disk while the scan goes on, from the
 * firmware's static frame buffers or its own copies of them (nothing allocated during a scan). */
#ifndef FRAME_WRITER_H
#define FRAME_WRITER_H

#include "hal.h"
#include "scan_dir.h"

#include <stddef.h>
#include <stdint.h>

/** Frames waiting to be written at most: a whole view's, so that a capture never waits. */
#define FRAME_WRITER_SLOTS SCAN_DIR_MAX_FRAMES
/** Grey frames copied and waiting at most: a capture waits only when the writer is this many
 *  frames behind (a pattern frame takes two frame periods, a grey zstd frame less). */
#define FRAME_WRITER_COPIES 8u

/** Start the thread that writes into @p storage. @retval 0 @retval -errno (the thread could not
 *  be made) */
int frame_writer_start(const struct hal_storage *storage);

/** Queue frame @p frame of view @p view of scan directory @p dir for writing. Waits while every
 *  slot (or, to copy, every copy) is taken.
 *  @param copy  0: @p pixels must stay as they are until frame_writer_flush returns (the colour
 *  frames stay in the firmware's buffers until the next view); 1: they are copied first (a grey
 *  frame of at most HAL_MAX_PIXELS: the decoder's frames last only until the next)
 *  @retval 0 @retval -errno a write queued earlier failed (and nothing is queued): @p failed
 *  names its file @retval -EINVAL a frame too large to copy */
int frame_writer_put(const char *dir, uint32_t view, uint32_t frame, const uint8_t *pixels,
                     uint32_t width, uint32_t height, uint32_t channels,
                     enum scan_frame_format format, int copy, char *failed, size_t failed_len);

/** Wait until every queued frame is on disk (written, fsynced, renamed).
 *  @retval 0 @retval -errno the first write that failed since the last flush, whose file
 *  @p failed names (the error is then cleared) */
int frame_writer_flush(char *failed, size_t failed_len);

/** Flush and end the thread; safe when it was not started. */
void frame_writer_stop(void);

/** CPU time the thread has spent, in seconds (make bench splits the scan's CPU with it). */
double frame_writer_cpu_s(void);

#endif
