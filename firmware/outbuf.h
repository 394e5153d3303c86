/* Buffered, atomic file output through the HAL storage: a fixed chunk, flushed as it fills. */
#ifndef OUTBUF_H
#define OUTBUF_H

#include "hal.h"

#include <stdint.h>
#include <string.h>

struct outbuf {
    const struct hal_storage *st;
    struct hal_file file;
    size_t used;
    int rc; /* first error; later calls do nothing */
};

/** Start an atomic write of @p path. @retval 0 or -errno */
int outbuf_open(struct outbuf *o, const struct hal_storage *st, const char *path);
/** Append bytes (errors are kept in o->rc). */
void outbuf_put(struct outbuf *o, const void *data, size_t len);
/** Append printf-formatted text. */
void outbuf_printf(struct outbuf *o, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/** Append @p v with @p decimals digits after the point, as printf's "%.*f" writes it (the same
 *  text: tests/test_ply.c) but without parsing a format (a mesh's text has millions of
 *  numbers); more than 9 decimals are 9. */
void outbuf_fixed(struct outbuf *o, double v, unsigned decimals);
/** Append @p v in decimal. */
void outbuf_u32(struct outbuf *o, uint32_t v);
/** Append a float, little-endian. */
void outbuf_f32le(struct outbuf *o, float f);
/** Put @p u little-endian at @p dst (outbuf_u32le's bytes; a record made whole, then appended
 *  at once). @retval dst + 4 */
static inline uint8_t *outbuf_u32le_at(uint8_t *dst, uint32_t u)
{
    for (int k = 0; k < 4; k++)
        dst[k] = (uint8_t)(u >> (8 * k));
    return dst + 4;
}
/** The same for float @p f. @retval dst + 4 */
static inline uint8_t *outbuf_f32le_at(uint8_t *dst, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof(u));
    return outbuf_u32le_at(dst, u);
}
/** Append a uint32, little-endian. */
void outbuf_u32le(struct outbuf *o, uint32_t v);
/** Flush and commit, or abort on any earlier error. @retval 0 or the first error */
int outbuf_close(struct outbuf *o);

#endif
