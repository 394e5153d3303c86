/* Image files: PNG through libpng, PGM/PPM raw or zstd-compressed, PFM (portable float map) for
 * range and normal images. */
#ifndef IMAGE_IO_H
#define IMAGE_IO_H

#include "hal.h"

#include <stddef.h>
#include <stdint.h>

/** Encode an 8-bit PNG (channels 1 or 3) in memory: *@p png_data is the caller's to free.
 *  @retval 0 ok @retval -ENOMEM @retval -EIO */
int image_encode_png(const uint8_t *pixels, uint32_t width, uint32_t height, int channels,
                     uint8_t **png_data, size_t *png_len);
/** Write an 8-bit PNG (channels 1 or 3) atomically. @retval 0 ok @retval -errno */
int image_write_png(const struct hal_storage *st, const char *path, const uint8_t *pixels,
                    uint32_t width, uint32_t height, int channels);
/** Read an 8-bit PNG without alpha into @p pixels (capacity bytes), converting to @p channels
 *  (1 or 3). A 16-bit PNG or one with alpha is refused, not converted: a frame never changes
 *  what it says on the way in.
 *  @param why  out: what is wrong, in libpng's words for a damaged file
 *  @retval 0 ok @retval -ENOENT no such file @retval -EINVAL not such a PNG, or too large */
int image_read_png(const char *path, uint8_t *pixels, size_t capacity, uint32_t *width,
                   uint32_t *height, int channels, char *why, size_t why_len);
/** Write an 8-bit PGM (channels 1) or PPM (channels 3) atomically, compressed as one zstd frame
 *  at @p zstd_level (`zstd -d` gives the PGM/PPM back), or raw with @p zstd_level 0. Streamed
 *  out a chunk at a time, with the thread's kept compressor (image_zstd_keep) if it has one.
 *  @retval 0 ok @retval -ENOMEM @retval -errno */
int image_write_pnm(const struct hal_storage *st, const char *path, const uint8_t *pixels,
                    uint32_t width, uint32_t height, int channels, int zstd_level);
/** Keep a zstd compressor and its output chunk for this thread's image_write_pnm calls, so
 *  that writing a frame allocates nothing; image_zstd_release frees them (before the thread
 *  ends). @retval 0 @retval -ENOMEM */
int image_zstd_keep(void);
void image_zstd_release(void);
/** Read an 8-bit binary PGM or PPM, raw or zstd-compressed (told apart by the file's first bytes),
 *  into @p pixels as @p channels: a PGM read as 3 channels is repeated, a PPM read as grey is
 *  refused (a frame never changes what it says on the way in).
 *  @param why  out: what is wrong @retval 0 ok @retval -ENOENT no such file @retval -EINVAL */
int image_read_pnm(const char *path, uint8_t *pixels, size_t capacity, uint32_t *width,
                   uint32_t *height, int channels, char *why, size_t why_len);
/** Write a PFM (channels 1 or 3; NaN allowed) atomically. @retval 0 ok @retval -errno */
int image_write_pfm(const struct hal_storage *st, const char *path, const float *pixels,
                    uint32_t width, uint32_t height, int channels);

#endif
